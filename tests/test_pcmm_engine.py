"""PCMM particles and blocks inside the simulation's time step: patch tests, rigid
rotation, momentum with elements deleted and created, the element set equal to the
rules' at every check, DEM contact between bodies that share no element."""
import numpy as np
import pytest

import tdem
from physics.pcmm import ElementSystem, check_rules

E, NU, RHO = 30e9, 0.25, 2500.0
K = E / (3 * (1 - 2 * NU))
G = E / (2 * (1 + NU))


def packing(kind):
    if kind == "regular":
        return tdem.pack.regular(1.0, 0.6, 0.05) + (0.05,)
    if kind == "cross":
        return tdem.pack.cross(1.0, 0.6, 0.05) + (0.001,)
    return tdem.pack.random(1.0, 0.6, 0.03, 0.05, seed=3, target_fraction=0.72) + (0.04,)


def hooke(exx, eyy):
    lam = K - 2 * G / 3
    return np.array([lam * (exx + eyy) + 2 * G * exx, lam * (exx + eyy) + 2 * G * eyy,
                     lam * (exx + eyy)])


def _stretched(kind, lxx, lyy, steps):
    """A body whose particles all move with v = L·x0, L = diag(lxx, lyy)."""
    pos, rad, tol = packing(kind)
    sim = tdem.Simulation(gravity=(0.0, 0.0), dt_fraction=0.5)
    v0 = pos * np.array([lxx, lyy])
    g = sim.add_particles(pos, rad, material=tdem.Elastic(density=RHO, young=E, poisson=NU), tolerance=tol,
                          velocity=v0)
    sim.fix_particles(g.ids, vx=v0[:, 0], vy=v0[:, 1])
    sim.run(steps=steps)
    return sim


def _strain_sum(l, dt, steps):
    # the gradient on the mid-step configuration x0·(1 + (k + ½)·dt·l)
    k = np.arange(steps)
    return float(np.sum(l * dt / (1.0 + (k - 0.5) * dt * l)))


@pytest.mark.parametrize("kind", ["regular", "cross", "random"])
def test_patch_uniform_stretch_gives_hooke(kind):
    lxx, lyy, steps = 2.0, -0.7, 40
    sim = _stretched(kind, lxx, lyy, steps)
    p = sim.particles.numpy()
    inside = p["elements"] > 0
    assert inside.sum() > 0.8 * len(inside)
    dt = sim.dt
    want = hooke(_strain_sum(lxx, dt, steps), _strain_sum(lyy, dt, steps))
    s = p["stress"][inside]
    scale = np.abs(want).max()
    assert np.abs(s[:, 0, 0] - want[0]).max() < 1e-6 * scale
    assert np.abs(s[:, 1, 1] - want[1]).max() < 1e-6 * scale
    assert np.abs(s[:, 0, 1]).max() < 1e-6 * scale
    assert np.abs(p["stress_zz"][inside] - want[2]).max() < 1e-6 * scale
    # the particle strain: the sum of the increments (carried to the particles in
    # f32, so 1e-6 relative)
    ex, ey = _strain_sum(lxx, dt, steps), _strain_sum(lyy, dt, steps)
    e = p["strain"][inside]
    assert np.abs(e[:, 0] - ex).max() < 1e-6 * abs(ex)
    assert np.abs(e[:, 1] - ey).max() < 1e-6 * abs(ex)
    assert np.abs(e[:, 2]).max() < 1e-6 * abs(ex)
    # particles in no element carry no stress
    assert np.all(p["stress"][~inside] == 0.0)


@pytest.mark.parametrize("mode", ["shear", "tension"])
def test_patch_mohr_coulomb_state_reaches_the_particles(mode):
    """A uniform stretch beyond the strength of a Mohr–Coulomb body: the particles'
    stress, plastic shear strain and failure mark are those of the correction applied
    step by step to the same strain increments (stress to 1e-9, the plastic strain,
    carried to the particles in f32, to 1e-6). Pure shear (εyy = −εxx) fails in
    shear; isotropic tension of a body with a high cohesion fails at the tension
    cut-off with no plastic shear strain, and is still marked failed."""
    from test_materials import correct
    lxx, lyy, coh, ten = (2.0, -2.0, 1e6, 2e7) if mode == "shear" else (2.0, 2.0, 1e8, 1e6)
    mat = tdem.MohrCoulomb(density=RHO, young=E, poisson=NU, cohesion=coh, friction_angle=30.0,
                           tensile_strength=ten)
    pos, rad, tol = packing("regular")
    sim = tdem.Simulation(gravity=(0.0, 0.0), dt_fraction=0.5)
    v0 = pos * np.array([lxx, lyy])
    g = sim.add_particles(pos, rad, material=mat, tolerance=tol, velocity=v0)
    sim.fix_particles(g.ids, vx=v0[:, 0], vy=v0[:, 1])
    steps = 40
    sim.run(steps=steps)
    dt = sim.dt
    sig = np.zeros(4)
    eps = 0.0
    failed = False
    for k in range(steps):
        dx = lxx * dt / (1.0 + (k - 0.5) * dt * lxx)
        dy = lyy * dt / (1.0 + (k - 0.5) * dt * lyy)
        h = hooke(dx, dy)
        out, e, f = correct([mat], sig + np.array([h[0], h[1], 0.0, h[2]]))
        sig, eps, failed = out[0], eps + e[0], failed or f[0] > 0
    p = sim.particles.numpy()
    inside = p["elements"] > 0
    assert inside.sum() > 0.8 * len(inside)
    assert failed
    assert np.all(p["failed"][inside])
    scale = np.abs(sig).max()
    s = p["stress"][inside]
    assert np.abs(s[:, 0, 0] - sig[0]).max() < 1e-9 * scale
    assert np.abs(s[:, 1, 1] - sig[1]).max() < 1e-9 * scale
    assert np.abs(p["stress_zz"][inside] - sig[3]).max() < 1e-9 * scale
    if mode == "shear":
        assert eps > 1e-4
        assert np.abs(p["plastic_strain"][inside] - eps).max() < 1e-6 * eps
    else:
        assert eps == 0.0
        assert np.all(p["plastic_strain"][inside] == 0.0)


def _rotate(points, c, ang):
    ca, sa = np.cos(ang), np.sin(ang)
    d = points - c
    return c + np.stack([ca * d[:, 0] - sa * d[:, 1], sa * d[:, 0] + ca * d[:, 1]], 1)


@pytest.mark.parametrize("kind", ["regular", "random"])
def test_rigid_rotation_90_degrees(kind):
    """Stretch, hold, then turn the body rigidly by 90°: with no stress before the
    turn, none after (< 1e-6·E); a stressed body has σxx and σyy swapped."""
    pos, rad, tol = packing(kind)
    c = pos.mean(axis=0)
    sim = tdem.Simulation(gravity=(0.0, 0.0), dt_fraction=0.5)
    g = sim.add_particles(pos, rad, material=tdem.Elastic(density=RHO, young=E, poisson=NU), tolerance=tol)
    dt = sim.dt
    nturn = 300
    w = 0.5 * np.pi / (nturn * dt)

    def chord(t, comp):
        # velocity that takes the exact rotated positions at t to those at t + dt
        k = round(t / dt)
        a0 = w * dt * min(max(k - 20, 0), nturn)
        a1 = w * dt * min(max(k + 1 - 20, 0), nturn)
        return (_rotate(pos, c, a1) - _rotate(pos, c, a0))[:, comp] / dt

    sim.fix_particles(g.ids, vx=lambda t: chord(t, 0), vy=lambda t: chord(t, 1))
    sim.run(steps=nturn + 20)
    p = sim.particles.numpy()
    assert np.allclose(p["position"], _rotate(pos, c, 0.5 * np.pi), atol=1e-9)
    assert np.abs(p["stress"]).max() < 1e-6 * E
    assert np.abs(p["stress_zz"]).max() < 1e-6 * E


def test_prestressed_rotation_swaps_stresses():
    pos, rad, tol = packing("regular")
    c = pos.mean(axis=0)
    sim = tdem.Simulation(gravity=(0.0, 0.0), dt_fraction=0.5)
    g = sim.add_particles(pos, rad, material=tdem.Elastic(density=RHO, young=E, poisson=NU), tolerance=tol)
    dt = sim.dt
    nstretch, nturn = 10, 300
    w = 0.5 * np.pi / (nturn * dt)
    rate = 1e-5 / (nstretch * dt)       # 1e-5 strain in x over the stretch

    def xk(k):
        s = 1.0 + rate * dt * min(k, nstretch)
        base = c + (pos - c) * np.array([s, 1.0])
        return _rotate(base, c, w * dt * min(max(k - nstretch - 5, 0), nturn))

    def vel(t, comp):
        k = round(t / dt)
        return (xk(k + 1) - xk(k))[:, comp] / dt

    sim.fix_particles(g.ids, vx=lambda t: vel(t, 0), vy=lambda t: vel(t, 1))
    sim.run(steps=nstretch + 3)         # the stretch, then at rest (the step after a
    p = sim.particles.numpy()           # motion turns it into strain)
    inside = p["elements"] > 0
    before = p["stress"][inside].mean(axis=0)
    sim.run(steps=nturn + 5)
    after = sim.particles.numpy()["stress"][inside].mean(axis=0)
    assert before[0, 0] > 1e4                    # a real stress was built
    scale = abs(before[0, 0])
    assert abs(after[1, 1] - before[0, 0]) < 1e-6 * scale
    assert abs(after[0, 0] - before[1, 1]) < 1e-6 * scale
    assert abs(after[0, 1]) < 1e-6 * scale


def _soft_body(seed=1):
    pos, rad = tdem.pack.random(0.3, 0.3, 0.008, 0.012, seed=seed, target_fraction=0.72)
    rng = np.random.default_rng(seed)
    # converging (the body is squeezed, bounces and squeezes again) plus noise
    vel = rng.normal(0.0, 0.3, pos.shape) - 8.0 * (pos - pos.mean(axis=0))
    mat = tdem.Elastic(density=1000.0, young=2e4, poisson=0.25)
    sim = tdem.Simulation(gravity=(0.0, 0.0), dt_fraction=0.3)
    sim.add_particles(pos, rad, material=mat, tolerance=0.012, velocity=vel,
                      contact=tdem.LinearContact(kn=2e4, ks=2e4, friction=0.3))
    return sim, rad


def _momentum(sim):
    p = sim.particles.numpy(stress=False)
    mv = p["mass"][:, None] * p["velocity"]
    return mv.sum(axis=0), np.abs(mv).sum()


@pytest.mark.parametrize("chunks", [None, "4", "0"])
def test_momentum_conserved_while_elements_die_and_are_born(chunks, monkeypatch):
    """Also with the step's pair loop in 4 chunks and with a slot for every pair (the
    GPU's path), where pairs carried by elements are skipped across chunks."""
    if chunks is not None:
        monkeypatch.setenv("TDEM_CHUNKS", chunks)
    sim, rad = _soft_body()
    if chunks == "4" and not sim._serial():       # (several threads)
        assert tdem.backend.chunk_size(sim.n_particles, False) == -(-sim.n_particles // 4)
    p0, scale = _momentum(sim)
    seen = set()
    born = died = 0
    prev = None
    for _ in range(6):
        sim.run(steps=100)
        tri = sim.elements.numpy()["triangles"]
        cur = {tuple(sorted(t)) for t in tri}
        if prev is not None:
            born += len(cur - prev)
            died += len(prev - cur)
        prev = cur
        seen |= cur
        # the element set is exactly the one the rules give for these positions
        p = sim.particles.numpy(stress=False)
        x_now = p["position"] - sim.dt * p["velocity"]   # positions the elements were made on
        ref = ElementSystem(x_now, rad, 0.012).build().numpy()
        assert cur == {tuple(sorted(t)) for t in ref["triangles"]}
        assert check_rules(x_now, rad, 0.012, tri)["ok"].all()
    p1, _ = _momentum(sim)
    assert born > 50 and died > 50       # elements were deleted and created many times
    assert np.abs(p1 - p0).max() < 1e-10 * scale


@pytest.mark.filterwarnings("error::RuntimeWarning")
def test_candidate_slots_grow_and_steps_are_redone():
    """The PCMM candidate lists start too short (2 slots): the segment is restored from
    its snapshot, the lists grow and the steps are redone; positions, element stresses
    and particle stresses equal those of a run that started with enough slots. The
    energy account is not taken from the first step made with the short lists (its
    state is thrown away, and may not be finite): no warning of numpy's on the way."""
    def run(cap):
        sim, _ = _soft_body()
        sim.check_interval = 40
        sim._build()
        if cap is not None:
            sim._cont.capacity = cap
            sim._cont._alloc_lists()
        sim.run(steps=120)
        return sim

    small, ref = run(2), run(None)
    assert small._cont.capacity > 2
    a, b = small.particles.numpy(), ref.particles.numpy()
    np.testing.assert_allclose(a["position"], b["position"], rtol=0, atol=1e-12)
    scale = np.abs(b["stress"]).max()
    assert scale > 0
    np.testing.assert_allclose(a["stress"], b["stress"], rtol=0, atol=1e-9 * scale)
    ea, eb = small.elements.numpy(), ref.elements.numpy()
    assert len(ea["triangles"]) == len(eb["triangles"]) > 100
    np.testing.assert_allclose(ea["stress"], eb["stress"], rtol=0, atol=1e-9 * scale)


def test_bodies_that_share_no_element_collide_through_the_contact_law():
    """Two PCMM blocks of different materials meet head on: no elements join them,
    the contact law stops them from passing through each other, momentum holds."""
    mat_a = tdem.Elastic(density=1000.0, young=1e6, poisson=0.25)
    mat_b = tdem.Elastic(density=1000.0, young=1e6, poisson=0.25)
    law = tdem.LinearContact(kn=1e6, ks=1e6, friction=0.0)
    pa, ra = tdem.pack.regular(0.2, 0.2, 0.01)
    pb, rb = tdem.pack.regular(0.2, 0.2, 0.01, origin=(0.205, 0.0))
    sim = tdem.Simulation(gravity=(0.0, 0.0), dt_fraction=0.3)
    # (tolerance 0.9 R: a square lattice's diagonals need 0.828 R to make elements)
    a = sim.add_particles(pa, ra, material=mat_a, tolerance=0.009, contact=law,
                          velocity=(1.0, 0.0))
    b = sim.add_particles(pb, rb, material=mat_b, tolerance=0.009, contact=law,
                          velocity=(-1.0, 0.0))
    p0, scale = _momentum(sim)
    tri = sim.elements.numpy()["triangles"]
    sim.run(until=0.06)
    tri = sim.elements.numpy()["triangles"]
    ia, ib = set(a.ids.tolist()), set(b.ids.tolist())
    mixed = [t for t in tri if (set(t) & ia) and (set(t) & ib)]
    assert not mixed and len(tri) >= 2 * 2 * 9 * 9    # each body's 9 × 9 squares cut
    p = sim.particles.numpy()
    xa = p["position"][a.ids, 0].max()
    xb = p["position"][b.ids, 0].min()
    assert xb - xa > 0.01                # they did not pass through each other
    va = p["velocity"][a.ids, 0].mean()
    assert va < 0.0                       # body a bounced back
    p1, _ = _momentum(sim)
    assert np.abs(p1 - p0).max() < 1e-10 * scale


def test_block_patch_and_gravity_reaction():
    """An FVM block under gravity with its base fixed: the base reaction equals the
    weight (to round-off) once static; a uniform stretch gives Hooke's stress."""
    v, t = tdem.mesh.rectangle(2.0, 1.0, 8, 4, pattern="cross")
    sim = tdem.Simulation(gravity=(0.0, -9.81), local_damping=0.8, dt_fraction=0.5)
    mat = tdem.Elastic(density=RHO, young=E, poisson=NU)
    b = sim.add_block(v, t, material=mat)
    b.fix(b.nodes_in(ymax=1e-9), vx=0.0, vy=0.0)
    sim.run(steps=3000)
    nd = b.nodes()
    weight = RHO * 9.81 * 2.0
    assert abs(nd["reaction"][:, 1].sum() - weight) < 1e-6 * weight
    assert abs(nd["mass"].sum() - RHO * 2.0) < 1e-9 * RHO

    sim2 = tdem.Simulation(gravity=(0.0, 0.0), dt_fraction=0.5)
    b2 = sim2.add_block(v, t, material=mat, velocity=(0.0, 0.0))
    lxx, lyy = 1.0, 0.3
    b2.fix(np.arange(len(v)), vx=v[:, 0] * lxx, vy=v[:, 1] * lyy)
    sim2.run(steps=1)                     # first step: nodes at rest, then moving
    sim2.run(steps=30)
    dt = sim2.dt
    k = np.arange(30)
    exx = np.sum(lxx * dt / (1.0 + (k + 0.5) * dt * lxx))
    eyy = np.sum(lyy * dt / (1.0 + (k + 0.5) * dt * lyy))
    want = hooke(exx, eyy)
    s = b2.elements()["stress"]
    assert np.abs(s[:, 0, 0] - want[0]).max() < 1e-6 * abs(want[0])
    assert np.abs(s[:, 1, 1] - want[1]).max() < 1e-6 * abs(want[0])


def test_continuum_inputs():
    sim = tdem.Simulation()
    with pytest.raises(ValueError, match="material"):
        sim.add_particles([[0.0, 0.0]], 0.1, material="rock")
    with pytest.raises(ValueError, match="tolerance"):
        sim.add_particles([[0.0, 0.0]], 0.1, material=tdem.Elastic(), tolerance=-1.0)
    v, t = tdem.mesh.rectangle(1.0, 1.0, 2, 2)
    with pytest.raises(ValueError, match="inverted"):
        sim.add_block(v, t[:, ::-1], material=tdem.Elastic())
    with pytest.raises(ValueError, match="material"):
        sim.add_block(v, t, material=None)
    b = sim.add_block(v, t, material=tdem.Elastic())
    with pytest.raises(ValueError, match="nodes"):
        b.fix([100], vx=0.0)
    assert len(sim.blocks) == 1


def test_checkpoint_of_pcmm_and_block_restarts_exactly(tmp_path):
    """A model with a Mohr–Coulomb PCMM body resting on a fixed block: saved, loaded
    and run on, it gives the numbers of the run that was not interrupted."""
    def model():
        sim = tdem.Simulation(gravity=(0.0, -9.81), dt_fraction=0.4)
        soil = tdem.MohrCoulomb(density=2000.0, young=5e6, poisson=0.3, cohesion=2e3,
                                friction_angle=30.0, tensile_strength=1e3)
        pos, rad = tdem.pack.regular(0.4, 0.3, 0.01, origin=(0.0, 0.0))
        sim.add_particles(pos, rad, material=soil, tolerance=0.01)
        v, t = tdem.mesh.rectangle(0.4, 0.05, 8, 1, origin=(0.0, -0.05))
        b = sim.add_block(v, t, material=tdem.Elastic(density=2500.0, young=1e8, poisson=0.25))
        b.fix(b.nodes_in(ymax=-0.05 + 1e-9), vx=0.0, vy=0.0)
        sim.fix_particles(sim.particles_in(ymax=0.011), vx=0.0, vy=0.0)
        return sim, b

    ref, rb = model()
    ref.run(steps=60)
    path = tmp_path / "pcmm.h5"
    ref.save(path)
    ref.run(steps=60)
    sim = tdem.Simulation.load(path)
    sim.run(steps=60)
    a, c = ref.particles.numpy(), sim.particles.numpy()
    assert np.array_equal(a["position"], c["position"])
    assert np.array_equal(a["stress"], c["stress"])
    assert np.array_equal(a["plastic_strain"], c["plastic_strain"])
    assert np.array_equal(rb.nodes()["position"], sim.blocks[0].nodes()["position"])
    assert np.array_equal(rb.elements()["stress"], sim.blocks[0].elements()["stress"])
    assert np.abs(a["stress"]).max() > 0.0


def test_checkpoint_while_elements_die_and_are_born_restarts_exactly(tmp_path):
    """Saved while elements are deleted and created every few steps (the copies of a
    triangle keep their stresses lazily, see physics.pcmm.copies), loaded and run on:
    the numbers of the run that was not interrupted, element stresses included."""
    ref, _ = _soft_body(seed=3)
    ref.run(steps=150)
    before = {tuple(sorted(t)) for t in ref.elements.numpy()["triangles"]}
    path = tmp_path / "soft.h5"
    ref.save(path)
    ref.run(steps=150)
    after = {tuple(sorted(t)) for t in ref.elements.numpy()["triangles"]}
    assert len(after - before) > 20 and len(before - after) > 20
    sim = tdem.Simulation.load(path)
    sim.run(steps=150)
    a, c = ref.particles.numpy(), sim.particles.numpy()
    assert np.array_equal(a["position"], c["position"])
    assert np.array_equal(a["stress"], c["stress"])
    ea, ec = ref.elements.numpy(), sim.elements.numpy()
    assert np.array_equal(ea["triangles"], ec["triangles"])
    assert np.array_equal(ea["stress"], ec["stress"])
    assert np.abs(ea["stress"]).max() > 0.0


def test_contact_law_takes_over_from_a_dying_element_without_a_jump():
    """Two overlapping particles held still share an element with a third that is
    pulled away: when the element dies the contact law takes over counting from
    their overlap at that moment (no force, although they overlap by 2 mm), and then
    pushes back on any further overlap with k_n."""
    r, kn = 0.01, 1e6
    pos = np.array([[0.0, 0.0], [0.018, 0.0], [0.009, 0.0156]])
    sim = tdem.Simulation(gravity=(0.0, 0.0), dt_fraction=0.3, progress=False)
    sim.add_particles(pos, np.full(3, r), material=tdem.Elastic(density=1000.0, young=1e6, poisson=0.25),
                      tolerance=0.001, contact=tdem.LinearContact(kn=kn, ks=kn, friction=0.0))
    sim.fix_particles([0, 1], vx=0.0, vy=0.0)
    sim.fix_particles([2], vx=0.0, vy=5.0)
    sim.run(steps=2)
    assert len(sim.elements.numpy()["triangles"]) > 0
    assert np.abs(sim.particles.numpy()["force"][:2]).max() > 100.0   # the element pulls
    sim.run(steps=8)                          # particle 2 has left: the element is gone
    assert len(sim.elements.numpy()["triangles"]) == 0
    assert np.abs(sim.particles.numpy()["force"][:2]).max() == 0.0
    v, n = 0.01, 20
    sim.fix_particles([1], vx=-v, vy=0.0)
    sim.run(steps=n)
    c = sim.contacts.numpy()
    assert c["pairs"].tolist() == [[0, 1]]
    # the counted overlap is what was added since the takeover (the force of step n
    # is computed before its move), not the 2 mm they overlap in all
    assert c["overlap"][0] == pytest.approx((n - 1) * v * sim.dt, rel=1e-9)
    assert c["normal"][0] == pytest.approx(kn * c["overlap"][0], rel=1e-9)
    geo = 2 * r - np.linalg.norm(np.diff(sim.particles.numpy()["position"][:2], axis=0))
    assert geo > 0.0019
