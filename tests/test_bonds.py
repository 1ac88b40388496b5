"""Parallel bonds (Potyondy & Cundall 2004; tdem.bonds, physics.parallel_bond): the
bond's axial, bending and twisting stiffness against k̄ Ā, k̄_n Ī, k̄_s J̄; breaking in
tension and in shear at the strengths, recorded as cracks; the contact law taking
over; a closed energy account; bonds kept by checkpoints and outlets."""
import math

import numpy as np
import pytest

import tdem
from physics.parallel_bond import BP_AREA, BP_INERTIA, BP_KN_I, BP_KS_A, BP_KS_J

E = 1e8
R = 0.01
DT = 1e-6
LAW = tdem.LinearContact(kn=1e6, friction=0.5)


def _pair(dim=2, pb=None, gap=1e-6, **kw):
    sim = tdem.Simulation(gravity=(0.0,) * dim, progress=False, dt=DT, dim=dim, **kw)
    x = [[0.0, 0.0], [2 * R, 0.0]] if dim == 2 else [[0.0, 0.0, 0.0], [2 * R, 0.0, 0.0]]
    g = sim.add_particles(x, R, density=2500.0, contact=LAW)
    pb = pb or tdem.ParallelBond(young=E, stiffness_ratio=2.0)
    assert sim.bond(g, pb, gap=gap) == 1
    return sim, g


def _hold(sim, dim, v1=(0.0, 0.0, 0.0), w1=0.0):
    if dim == 2:
        sim.fix_particles([0], vx=0.0, vy=0.0, omega=0.0)
        sim.fix_particles([1], vx=v1[0], vy=v1[1], omega=w1)
    else:
        sim.fix_particles([0], vx=0.0, vy=0.0, vz=0.0, omega=(0.0, 0.0, 0.0))
        sim.fix_particles([1], vx=v1[0], vy=v1[1], vz=v1[2],
                          omega=w1 if np.ndim(w1) else (0.0, 0.0, 0.0))


@pytest.mark.parametrize("dim", [2, 3])
def test_axial_stiffness_is_kn_bar_times_area(dim):
    """Pulled apart at v: F̄_n = −k̄_n Ā u, k̄_n = Ē/(R_A + R_B), Ā = 2R̄ (2D, per metre)
    or πR̄² (3D); u the stretch at the step's start."""
    sim, _ = _pair(dim)
    v = 1e-3
    _hold(sim, dim, v1=(v, 0.0, 0.0))
    sim.run(steps=200)
    u = sim.particles.numpy()["position"][1, 0] - 2 * R - v * DT
    area = 2 * R if dim == 2 else math.pi * R * R
    fn = sim.bonds.numpy()["normal_force"][0]
    assert fn == pytest.approx(-E / (2 * R) * area * u, rel=1e-9)
    assert sim._a["bprop"].to_numpy()[0, BP_AREA] == pytest.approx(area, rel=1e-12)
    # the force on the pulled particle points back, its size the bond's
    f = sim.particles.numpy()["force"][1]
    assert f[0] == pytest.approx(fn, rel=1e-9) and abs(f[1]) < 1e-12 * abs(fn)


def test_bending_stiffness_2d():
    """The second disc turned in place at ω: the bending moment −k̄_n Ī θ (Ī = 2R̄³/3),
    the shear force −k̄_s Ā ωRt of the contact point's travel."""
    sim, _ = _pair(2)
    w = 0.5
    _hold(sim, 2, w1=w)
    steps = 400
    sim.run(steps=steps)
    b = sim.bonds.numpy()
    p = sim._a["bprop"].to_numpy()[0]
    # (the first step's bond update sees the spin before the fix sets it: steps − 1)
    theta = w * DT * (steps - 1)
    assert p[BP_INERTIA] == pytest.approx(2 * R ** 3 / 3, rel=1e-12)
    assert b["moment"][0] == pytest.approx(-p[BP_KN_I] * theta, rel=1e-9)
    # the contact point (R from the turning centre: the discs touch) moves along −y:
    # the shear force on the disc resists it, +y
    arm = R
    assert b["shear_force"][0, 1] == pytest.approx(p[BP_KS_A] * w * arm * DT * (steps - 1),
                                                   rel=1e-6)


def test_twisting_stiffness_3d():
    """The second sphere turned about the bond's axis: the twisting moment −k̄_s J̄ θ,
    no bending, no shear."""
    sim, _ = _pair(3)
    w = 0.5
    _hold(sim, 3, w1=np.array([w, 0.0, 0.0]))
    steps = 300
    sim.run(steps=steps)
    b = sim.bonds.numpy()
    p = sim._a["bprop"].to_numpy()[0]
    assert p[BP_KS_J] == pytest.approx(E / (2 * R) / 2.0 * math.pi * R ** 4 / 2, rel=1e-12)
    assert b["twist"][0, 0] == pytest.approx(-p[BP_KS_J] * w * DT * (steps - 1), rel=1e-9)
    assert np.abs(b["moment"][0]).max() < 1e-12 * abs(b["twist"][0, 0])
    assert np.abs(b["shear_force"][0]).max() < 1e-12


@pytest.mark.parametrize("dim", [2, 3])
def test_breaks_in_tension_at_the_tensile_strength(dim):
    """Pulled apart: σ = −F̄_n/Ā = Ē u/(2R) reaches σ̄_c at u = 2R σ̄_c/Ē; the bond breaks
    then (a tension crack at the contact point), the discs part without force."""
    sc = 2e5
    pb = tdem.ParallelBond(young=E, stiffness_ratio=2.0, tensile_strength=sc)
    sim, _ = _pair(dim, pb)
    v = 0.05
    _hold(sim, dim, v1=(v, 0.0, 0.0))
    sim.run(steps=1200)
    assert len(sim.bonds) == 0 and len(sim.cracks) == 1
    c = sim.cracks.numpy()
    u_break = 2 * R * sc / E
    # the first step whose start is stretched by u_break or more
    t_want = math.ceil(u_break / (v * DT) - 1e-9) * DT
    assert c["time"][0] == pytest.approx(t_want, abs=1.01 * DT)
    assert c["mode"][0] == 0
    assert c["normal"][0] == pytest.approx([1.0] + [0.0] * (dim - 1), abs=1e-12)
    assert c["position"][0][0] == pytest.approx(R + 0.5 * u_break, abs=2 * v * DT)
    assert np.abs(sim.particles.numpy()["force"]).max() == 0.0
    # the energy the bond held went to the dissipated account, which stays closed but
    # for the half step by which the booked work leads the stored energy (½ Δt F·v of
    # the last bonded step, which the account takes out while the force acts)
    e = sim.energy()
    area = 2 * R if dim == 2 else math.pi * R * R
    k = E / (2 * R) * area
    fb = c["normal_force"][0]
    assert e["dissipated"] == pytest.approx(0.5 * fb ** 2 / k, rel=1e-9)
    assert abs(e["integration_error"]) <= 0.5 * DT * abs(fb) * v * 1.01


def test_breaks_in_shear_at_the_cohesion():
    """Slid sideways: τ = |F̄_s|/Ā = k̄_s u_s reaches c̄ (no normal stress) at
    u_s = c̄/k̄_s; a shear crack."""
    coh = 1e5
    pb = tdem.ParallelBond(young=E, stiffness_ratio=2.0, cohesion=coh, friction_angle=30.0)
    sim, _ = _pair(2, pb)
    v = 0.05
    _hold(sim, 2, v1=(0.0, v, 0.0))
    sim.run(steps=1000)
    c = sim.cracks.numpy()
    assert len(c["time"]) == 1 and c["mode"][0] == 1
    ks = E / (2 * R) / 2.0
    t_want = coh / ks / v
    assert c["time"][0] == pytest.approx(t_want, rel=0.01)
    assert c["shear_force"][0] == pytest.approx(coh * 2 * R, rel=0.01)


def test_free_bonded_pair_keeps_its_energy_and_momentum():
    """Two bonded discs set spinning and stretching with no fixes: the momentum is
    kept to round-off and the energy account closes over many oscillations: the
    integration error below 2e-5 of the energy (the incremental shear spring turned
    with the pair each step is first-order in the turn; 4e-6 measured)."""
    sim, _ = _pair(2, local_damping=0.0)
    sim.run(steps=1)
    st = sim._download()
    st["vel"][1] = [0.02, 0.01]
    st["omega"][0] = 3.0
    sim._rebuild_from(st)
    sim.run(steps=20000)
    p = sim.particles.numpy()
    mom = (p["mass"][:, None] * p["velocity"]).sum(axis=0)
    assert mom == pytest.approx(p["mass"][1] * np.array([0.02, 0.01]), abs=1e-12)
    e = sim.energy()
    assert len(sim.bonds) == 1
    assert abs(e["integration_error"]) < 2e-5 * max(e["elastic"], e["kinetic"])


def test_bonds_survive_checkpoints_and_outlets(tmp_path):
    """A row of bonded spheres pulled apart at one end breaks one by one; a checkpoint
    taken midway continues bit for bit; an outlet that takes a particle drops its
    intact bonds and keeps the others (renumbered) and the cracks."""
    def model():
        sim = tdem.Simulation(dim=3, gravity=(0.0, 0.0, 0.0), progress=False, dt=DT)
        x = np.zeros((6, 3))
        x[:, 0] = np.arange(6) * 2 * R
        g = sim.add_particles(x, R, density=2500.0, contact=LAW)
        pb = tdem.ParallelBond(young=E, stiffness_ratio=2.0, tensile_strength=1e5)
        assert sim.bond(g, pb, gap=1e-6) == 5
        sim.fix_particles([0], vx=0.0, vy=0.0, vz=0.0)
        sim.fix_particles([5], vx=0.2, vy=0.0, vz=0.0)
        return sim

    ref = model()
    ref.run(steps=300)
    path = tmp_path / "b.h5"
    ref.save(path)
    ref.run(steps=900)
    back = tdem.Simulation.load(path)
    back.run(steps=900)
    np.testing.assert_array_equal(ref.particles.numpy()["position"],
                                  back.particles.numpy()["position"])
    assert len(ref.cracks) == len(back.cracks) >= 1
    np.testing.assert_array_equal(ref.cracks.numpy()["time"], back.cracks.numpy()["time"])
    intact = ref.bonds.numpy()["pairs"]
    # an outlet around particle 2
    x2 = ref.particles.numpy()["position"][2]
    out = ref.remove_in(sphere=(x2, 0.5 * R))
    ref.run(steps=1)
    assert out.count == 1
    after = ref.bonds.numpy()["pairs"]
    want = [(i - (i > 2), j - (j > 2)) for i, j in intact if 2 not in (i, j)]
    assert sorted(map(tuple, after.tolist())) == sorted(want)
    assert len(ref.cracks) == len(back.cracks)


def test_bad_bond_input_is_named():
    sim = tdem.Simulation(progress=False)
    g = sim.add_particles([[0.0, 0.0], [0.02, 0.0]], R, contact=LAW)
    with pytest.raises(tdem.InputError, match="ParallelBond"):
        sim.bond(g, LAW)
    with pytest.raises(tdem.InputError, match="young"):
        tdem.ParallelBond(young=-1.0)
    with pytest.raises(tdem.InputError, match="friction_angle"):
        tdem.ParallelBond(young=1e9, friction_angle=95.0)
    with pytest.raises(tdem.InputError, match="gap"):
        sim.bond(g, tdem.ParallelBond(young=1e9), gap=-1.0)
    assert sim.bond(g, tdem.ParallelBond(young=1e9), gap=0.0) == 1   # touching: bonded
    with pytest.raises(tdem.InputError, match="periodic"):
        sim.periodic(x=(-1.0, 1.0))
    s2 = tdem.Simulation(progress=False)
    e = s2.add_particles([[0.0, 0.0], [0.05, 0.0]], contact=LAW,
                         shape=tdem.Superellipse(0.02, 0.01, 4))
    with pytest.raises(tdem.InputError, match="shaped"):
        s2.bond(e, tdem.ParallelBond(young=1e9), gap=0.02)


def test_bonds_and_cracks_in_the_output_series(tmp_path):
    """The series holds bonds.pvd (lines with their forces) and cracks.pvd (points
    with time and mode), readable back, matching sim.bonds and sim.cracks."""
    import meshio
    sc = 2e5
    pb = tdem.ParallelBond(young=E, stiffness_ratio=2.0, tensile_strength=sc)
    sim, _ = _pair(2, pb)
    sim.output(tmp_path, every=300, contacts=False)
    _hold(sim, 2, v1=(0.05, 0.0, 0.0))
    sim.run(steps=1200)                     # breaks at step 800 (u = 2R σ̄_c/Ē)
    assert (tmp_path / "bonds.pvd").exists() and (tmp_path / "cracks.pvd").exists()
    first = meshio.read(tmp_path / "bonds_00001.vtu")          # step 300: intact
    assert len(first.cells[0].data) == 1
    assert first.cell_data["normal_force"][0][0] < 0.0          # stretched: tension
    last = meshio.read(tmp_path / "cracks_00004.vtu")           # step 1200: broken
    c = sim.cracks.numpy()
    np.testing.assert_allclose(last.point_data["time"], c["time"])
    np.testing.assert_array_equal(last.point_data["mode"], c["mode"])
    assert len(c["time"]) == 1
    none = meshio.read(tmp_path / "bonds_00004.vtu")            # the placeholder
    assert none.cell_data["id"][0][0] == -1


def test_shear_stiffness_and_the_friction_term_of_the_shear_strength():
    """Slid sideways without turning: F̄_s = k̄_s Ā u_s to 1e-9. Pressed first by a
    normal stress σ and then slid: the bond breaks in shear when |F̄_s|/Ā reaches
    c̄ + σ tan φ̄, within one step's increment."""
    sim, _ = _pair(2)
    v = 1e-3
    _hold(sim, 2, v1=(0.0, v, 0.0))
    sim.run(steps=300)
    p = sim._a["bprop"].to_numpy()[0]
    fs = sim.bonds.numpy()["shear_force"][0]
    # the contact point travels at v/2 relative to... the second disc's centre moves at
    # v, the contact point with it (no spin): Δu_s = v Δt per step, from the 2nd step
    assert fs[1] == pytest.approx(-p[BP_KS_A] * v * DT * 299, rel=1e-9)
    # shear strength with a normal stress
    coh, phi = 1e5, 30.0
    pb = tdem.ParallelBond(young=E, stiffness_ratio=2.0, cohesion=coh, friction_angle=phi)
    sim, _ = _pair(2, pb)
    vc = 0.02                                     # pressed: σ = Ē u/(2R) grows
    vs = 0.05
    _hold(sim, 2, v1=(-vc, vs, 0.0))
    sim.run(steps=2000)
    c = sim.cracks.numpy()
    assert len(c["time"]) == 1 and c["mode"][0] == 1
    area = 2 * R
    sigma = c["normal_force"][0] / area
    tau = c["shear_force"][0] / area
    ks_area = E / (2 * R) / 2.0 * area
    step = ks_area * vs * DT / area                # one step's shear stress increment
    want = coh + sigma * math.tan(math.radians(phi))
    assert sigma > 0.1 * coh                       # the friction term matters
    assert want <= tau + 1e-9 * want and tau < want + 2.0 * step


def test_cantilever_of_bonded_discs_bends_as_euler_bernoulli():
    """A row of 21 bonded discs (R = 1 cm, 1 µm apart: only the bonds act), the first
    held still, a tip load F on the last: the tip deflection F L³/(3 Ē Ī) (Ī = 2R̄³/3
    per metre, L = 40 R) within 3 % once at rest, the shear part (F L/(k̄_s Ā) per
    bond length) added."""
    n, gap = 21, 1e-6
    x = np.zeros((n, 2))
    x[:, 0] = np.arange(n) * (2 * R + gap)
    sim = tdem.Simulation(gravity=(0.0, 0.0), local_damping=0.7, progress=False)
    g = sim.add_particles(x, R, density=2500.0, contact=LAW)
    pb = tdem.ParallelBond(young=E, stiffness_ratio=1.0)
    assert sim.bond(g, pb, gap=2 * gap) == n - 1
    sim.fix_particles([0], vx=0.0, vy=0.0, omega=0.0)
    force = -20.0                                        # N/m, down
    sim.apply_force([n - 1], fy=force)
    sim.run(until=1.0)
    tip = sim.particles.numpy()["displacement"][n - 1, 1]
    length = (n - 1) * (2 * R + gap)
    ei = E * 2 * R ** 3 / 3
    shear = abs(force) * (n - 1) / (E / (2 * R) * 2 * R)
    want = abs(force) * length ** 3 / (3 * ei) + shear
    assert abs(tip) == pytest.approx(want, rel=0.03)
    assert abs(tip) < 0.05 * length                       # small deflection
    # at rest: at its speed now the tip would move under 1 % of the deflection in 0.1 s
    assert np.abs(sim.particles.numpy()["velocity"]).max() * 0.1 < 0.01 * abs(want)


def test_bonded_bar_carries_its_wave_at_sqrt_e_over_rho():
    """A bar of 200 bonded discs in a row, its end given a smooth velocity pulse: the
    pulse's peak travels at sqrt(E_eff/ρ_eff), E_eff = Ē (the bond's axial stiffness
    Ē Ā/(2R) over the section 2R, times the spacing 2R), ρ_eff = ρ π R²/(2R)² (the
    discs' mass over the bar's), within 3 %."""
    n = 200
    x = np.zeros((n, 2))
    x[:, 0] = np.arange(n) * 2 * R
    sim = tdem.Simulation(gravity=(0.0, 0.0), local_damping=0.0, progress=False)
    g = sim.add_particles(x, R, density=2500.0, contact=LAW)
    sim.bond(g, tdem.ParallelBond(young=E, stiffness_ratio=1.0), gap=1e-9)
    c = math.sqrt(E / (2500.0 * math.pi / 4))
    width = 20 * 2 * R / c                                # the pulse spans 20 discs

    def vx(t):
        return 0.01 * math.sin(math.pi * t / width) ** 2 if t < width else 0.0
    sim.fix_particles([0], vx=vx, vy=0.0, omega=0.0)
    stations = [50, 150]
    seen = {k: [] for k in stations}
    dt = sim.dt
    while sim.time < width + 170 * 2 * R / c:
        sim.run(steps=5)
        v = sim.particles.numpy()["velocity"][:, 0]
        for k in stations:
            seen[k].append((sim.time, v[k]))
    peaks = [max(seen[k], key=lambda r: r[1])[0] for k in stations]
    speed = (stations[1] - stations[0]) * 2 * R / (peaks[1] - peaks[0])
    assert speed == pytest.approx(c, rel=0.03)
    assert 5 * dt < 0.05 * (peaks[1] - peaks[0])          # the sampling is fine enough


def test_work_account_closes_with_bonds():
    """Bonded discs set moving: the work of every force (the bonds' with the contacts')
    adds up to the change of the kinetic energy to round-off."""
    sim = tdem.Simulation(gravity=(0.0, 0.0), progress=False, dt=DT, local_damping=0.0)
    g = sim.add_particles([[0.0, 0.0], [2 * R, 0.0]], R, density=2500.0, contact=LAW,
                          velocity=[[0.0, 0.0], [0.02, 0.01]], omega=[3.0, 0.0])
    sim.bond(g, tdem.ParallelBond(young=E, stiffness_ratio=2.0), gap=1e-6)
    sim.run(steps=5000)
    w = sim.work()
    assert abs(w["residual"]) < 1e-12 * max(abs(w["contacts"]), w["kinetic_change"], 1e-30)
    assert abs(w["contacts"]) > 0.0


def test_bonds_between_two_groups_and_after_a_run():
    """other=: only pairs with one particle in each group; bonds made after a run join
    the arrays (the state carried) and act from the next step."""
    sim = tdem.Simulation(gravity=(0.0, 0.0), progress=False, dt=DT)
    x = np.zeros((4, 2))
    x[:, 0] = np.arange(4) * 2 * R
    a = sim.add_particles(x[:2], R, density=2500.0, contact=LAW)
    b = sim.add_particles(x[2:], R, density=2500.0, contact=LAW)
    pb = tdem.ParallelBond(young=E, stiffness_ratio=2.0)
    sim.run(steps=5)
    assert sim.bond(a, pb, other=b, gap=1e-6) == 1           # only 1–2 across the groups
    assert sim.bonds.numpy()["pairs"].tolist() == [[1, 2]]
    sim.fix_particles([0, 1], vx=0.0, vy=0.0, omega=0.0)
    sim.fix_particles([2, 3], vx=1e-3, vy=0.0, omega=0.0)
    sim.run(steps=100)
    u = sim.particles.numpy()["position"][2, 0] - 4 * R - 1e-3 * DT
    assert sim.bonds.numpy()["normal_force"][0] == pytest.approx(-E * u, rel=1e-9)
    assert sim.bond(a, pb, gap=1e-6) == 1                    # 0–1 added to the list
    assert len(sim.bonds) == 2


# -- liquid bridges ----------------------------------------------------------
def _bridged(dim, lb, r=1e-3):
    sim = tdem.Simulation(gravity=(0.0,) * dim, progress=False, dt=1e-6, dim=dim,
                          local_damping=0.0)
    x = [[0.0] * dim, [2 * r] + [0.0] * (dim - 1)]
    g = sim.add_particles(x, r, density=2500.0, contact=tdem.LinearContact(kn=1e4))
    assert sim.bond(g, lb, gap=1e-9) == 1
    _hold(sim, dim, v1=(0.02, 0.0, 0.0))
    return sim


@pytest.mark.parametrize("dim", [2, 3])
def test_liquid_bridge_force_is_willetts_and_it_ruptures_at_lians_distance(dim):
    """Two touching spheres (discs in 2D: a layer of spheres, force per metre F/(2R))
    pulled apart at 0.02 m/s: the bridge pulls with Willett's F(s) = 2πRγ cos θ/(1 +
    2.1 Ŝ + 10 Ŝ²), Ŝ = (s/2)sqrt(R/V), at every gap (to 1e-9), and ruptures at the first
    step whose gap exceeds Lian's (1 + θ/2) V^(1/3)."""
    r = 1e-3
    lb = tdem.LiquidBridge(volume=2e-12, surface_tension=0.072, contact_angle=20.0)
    s_rup = (1 + 0.5 * math.radians(20.0)) * 2e-12 ** (1 / 3)
    assert lb.rupture_distance == pytest.approx(s_rup, rel=1e-12)
    sim = _bridged(dim, lb, r)
    v, dt = 0.02, sim.dt
    per = 1.0 if dim == 3 else 1.0 / (2 * r)
    for _ in range(6):
        sim.run(steps=1000)
        gap = sim.particles.numpy()["position"][1, 0] - 2 * r - v * dt     # at x_n
        fn = sim.bonds.numpy()["normal_force"]
        assert fn[0] == pytest.approx(-lb.bridge_force(gap, r, r) * per, rel=1e-9)
        assert -fn[0] == pytest.approx(
            per * 2 * math.pi * r * 0.072 * math.cos(math.radians(20.0))
            / (1 + 2.1 * (gap / 2) * math.sqrt(r / 2e-12)
               + 10 * ((gap / 2) * math.sqrt(r / 2e-12)) ** 2), rel=1e-9)
    steps = int(math.ceil(s_rup / (v * dt))) + 50
    sim.run(steps=steps)
    assert len(sim.bonds) == 0
    c = sim.cracks.numpy()
    assert c["mode"][0] == 2
    # the first step that starts with the gap beyond s_rup (the gap grows v Δt a step)
    t_want = (math.floor(s_rup / (v * dt) + 1e-9) + 1) * dt
    assert c["time"][0] == pytest.approx(t_want, abs=1.01 * dt)
    assert np.abs(sim.particles.numpy()["force"]).max() == 0.0


def test_liquid_bridge_energy_account_closes():
    """The work done pulling the bridge apart is U(s₀) = ∫ F ds (its potential energy
    −U(s) rises to 0 at rupture; its making released U(s₀), booked as dissipated): the
    account closes to the Riemann sum's error (below 1e-3 of U(s₀))."""
    r = 1e-3
    lb = tdem.LiquidBridge(volume=2e-12)
    sim = _bridged(3, lb, r)
    sim.run(steps=1)
    e0 = sim.energy()
    u0 = -e0["elastic"]                    # bound: the potential energy is −U(s)
    from physics.liquid_bridge import potential
    f0 = 2 * math.pi * r * 0.072
    k = 0.5 * math.sqrt(r / 2e-12)
    assert u0 == pytest.approx(float(potential(0.0, f0, k, lb.rupture_distance)),
                               rel=1e-3)
    sim.run(steps=int(lb.rupture_distance / (0.02 * sim.dt)) + 100)
    e = sim.energy()
    assert len(sim.bonds) == 0 and e["elastic"] == pytest.approx(0.0, abs=1e-15)
    # the pull's work: the bridge's potential and the pulled sphere's kinetic energy
    assert e["boundary_work"] - e["kinetic"] == pytest.approx(u0, rel=2e-3)
    assert abs(e["integration_error"]) < 1e-3 * u0
