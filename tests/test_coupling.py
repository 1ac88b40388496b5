"""Point–edge contacts between particles and blocks (Feng et al. §2.6)."""
import math

import numpy as np
import pytest

import tdem

G = 9.81


def _rotated_block(angle_deg, length=2.0, thick=0.2):
    """A rectangle whose top edge is inclined at ``angle_deg``; returns the mesh and
    the top-edge direction."""
    v, t = tdem.mesh.rectangle(length, thick, 10, 1, origin=(-0.5 * length, -thick))
    a = math.radians(angle_deg)
    rot = np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
    return v @ rot.T, t, rot @ np.array([1.0, 0.0]), rot @ np.array([0.0, 1.0])


def _disc_on(angle_deg, friction_angle, damping=0.0):
    v, t, tang, nrm = _rotated_block(angle_deg)
    sim = tdem.Simulation(gravity=(0.0, -G), local_damping=damping, dt_fraction=0.5)
    block = sim.add_block(v, t, material=tdem.Elastic(density=2500.0, young=1e8, poisson=0.25))
    block.fix(np.arange(len(v)), vx=0.0, vy=0.0)
    r = 0.05
    disc = sim.add_particles([nrm * r], r, density=2000.0,
                             contact=tdem.LinearContact(kn=1e7, friction=0.5))
    sim.couple(disc, block, tdem.PointEdge(kn=1e7, ks=1e7, friction_angle=friction_angle))
    return sim, block, tang, nrm


def test_disc_resting_on_a_block_carries_its_weight():
    sim, block, _, _ = _disc_on(0.0, 30.0, damping=0.7)
    sim.run(until=0.5)
    p = sim.particles.numpy()
    w = p["mass"][0] * G
    assert p["force"][0, 1] == pytest.approx(w, rel=5e-3)
    nd = block.nodes()
    # the block's supports carry its own weight and the disc's
    assert nd["reaction"][:, 1].sum() == pytest.approx(nd["mass"].sum() * G + w, rel=5e-3)
    # the block receives −F from the disc
    assert nd["force"][:, 1].sum() - 0.0 == pytest.approx(-w, rel=5e-3)


def test_disc_slides_down_a_30_degree_edge_at_the_coulomb_rate():
    sim, _, tang, _ = _disc_on(30.0, 20.0)
    sim.run(until=0.05)
    x0 = sim.particles.numpy()["position"][0] @ tang
    v0 = sim.particles.numpy()["velocity"][0] @ tang
    t0 = sim.time
    sim.run(until=0.45)
    p = sim.particles.numpy()
    dt = sim.time - t0
    # along the slope s = v0·t + a t²/2 (downhill is −tang)
    a = 2.0 * ((p["position"][0] @ tang) - x0 - v0 * dt) / dt ** 2
    want = -G * (math.sin(math.radians(30)) - math.cos(math.radians(30)) *
                 math.tan(math.radians(20)))
    assert a == pytest.approx(want, rel=0.02)


def test_disc_stays_on_a_15_degree_edge():
    sim, _, tang, _ = _disc_on(15.0, 20.0)
    sim.run(until=0.4)
    p = sim.particles.numpy()
    # it moves no more than the elastic give of the shear spring, m g sin θ / K_s
    give = p["mass"][0] * G * math.sin(math.radians(15)) / 1e7
    assert abs(p["position"][0] @ tang) < 3 * give   # (it oscillates on the spring)
    sim.run(until=0.8)
    assert abs(sim.particles.numpy()["position"][0] @ tang) < 3 * give


def test_cohesive_contact_breaks_in_tension_at_t_times_a_then_stays_weak():
    v, t, _, _ = _rotated_block(0.0)
    sim = tdem.Simulation(gravity=(0.0, 0.0), dt=1e-5)
    block = sim.add_block(v, t, material=tdem.Elastic(density=2500.0, young=1e9, poisson=0.25))
    block.fix(np.arange(len(v)), vx=0.0, vy=0.0)
    r, T = 0.05, 1e4
    disc = sim.add_particles([[0.0, 0.9 * r]], r, density=2000.0,
                             contact=tdem.LinearContact(kn=1e7))
    sim.couple(disc, block, tdem.PointEdge(kn=1e7, ks=1e7, friction_angle=30.0,
                                           cohesion=2e4, tensile_strength=T))
    sim.fix_particles(disc.ids, vx=0.0, vy=0.01)      # pulled away slowly
    fmin = 0.0
    for _ in range(400):
        sim.run(steps=5)
        fy = sim.particles.numpy()["force"][0, 1]
        fmin = min(fmin, fy)
        if fmin < 0 and fy == 0.0:
            break
    # the largest pull equals T·A (A = 2R) to within one step's spring increment
    assert -fmin == pytest.approx(T * 2 * r, abs=1e7 * 0.01 * 1e-5 * 5 + 1e-9)
    assert sim.particles.numpy()["force"][0, 1] == 0.0
    assert int(sim._cont.a["psbroken"].to_numpy().max()) == 1
    # pushed back onto the edge, the broken contact carries no tension any more
    sim.fix_particles(disc.ids, vx=0.0, vy=-0.01)
    sim.run(steps=2000)
    sim.fix_particles(disc.ids, vx=0.0, vy=0.01)
    sim.run(steps=20)
    assert sim.particles.numpy()["force"][0, 1] >= 0.0


def test_particle_block_collision_conserves_momentum():
    v, t = tdem.mesh.rectangle(0.4, 0.2, 8, 4, pattern="cross")
    sim = tdem.Simulation(gravity=(0.0, 0.0), dt_fraction=0.2)
    block = sim.add_block(v, t, material=tdem.Elastic(density=1000.0, young=1e7, poisson=0.3))
    r = 0.03
    discs = sim.add_particles([[0.1, 0.3], [0.3, 0.26], [-0.1, 0.1]], r, density=1500.0,
                              contact=tdem.LinearContact(kn=1e6),
                              velocity=[[0.0, -2.0], [0.5, -1.5], [2.0, 0.3]])
    sim.couple(discs, block, tdem.PointEdge(kn=1e6, ks=1e6, friction_angle=25.0))

    def momentum():
        p = sim.particles.numpy(stress=False)
        nd = block.nodes()
        mv = np.concatenate([p["mass"][:, None] * p["velocity"],
                             nd["mass"][:, None] * nd["velocity"]])
        return mv.sum(axis=0), np.abs(mv).sum()

    p0, scale = momentum()
    sim.run(until=0.12)
    p1, _ = momentum()
    assert np.abs(p1 - p0).max() < 1e-10 * scale
    # the discs met the block: the block moves
    assert np.abs(block.nodes()["velocity"]).max() > 0.05


def test_couple_inputs():
    sim = tdem.Simulation()
    v, t = tdem.mesh.rectangle(1.0, 1.0, 2, 2)
    b = sim.add_block(v, t, material=tdem.Elastic())
    g = sim.add_particles([[0.5, 1.1]], 0.1, contact=tdem.LinearContact(kn=1e6))
    with pytest.raises(ValueError, match="law"):
        sim.couple(g, b, "spring")
    with pytest.raises(ValueError, match="friction_angle"):
        tdem.PointEdge(friction_angle=95)
    with pytest.raises(ValueError, match="a must be particles"):
        sim.couple([7], b, tdem.PointEdge())


def test_checkpoint_with_point_edge_contacts_restarts_exactly(tmp_path):
    sim, block, tang, _ = _disc_on(30.0, 20.0)
    sim.run(steps=300)
    sim.save(tmp_path / "c.h5")
    sim.run(steps=300)
    other = tdem.Simulation.load(tmp_path / "c.h5")
    other.run(steps=300)
    assert np.array_equal(sim.particles.numpy()["position"], other.particles.numpy()["position"])
    assert np.array_equal(block.nodes()["force"], other.blocks[0].nodes()["force"])


def _block_on_incline(angle_deg, damping=0.0, rigid=False):
    a = math.radians(angle_deg)
    rot = np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
    vb, tb = tdem.mesh.rectangle(3.0, 0.2, 15, 1, origin=(-1.5, -0.2))
    vt, tt = tdem.mesh.rectangle(0.2, 0.2, 2, 2, pattern="cross", origin=(0.33, 0.0))
    sim = tdem.Simulation(gravity=(0.0, -G), dt_fraction=0.5, local_damping=damping)
    mat = tdem.Elastic(density=2500.0, young=1e9, poisson=0.25)
    base = sim.add_block(vb @ rot.T, tb, material=mat)
    base.fix(np.arange(len(vb)), vx=0.0, vy=0.0)
    top = sim.add_block(vt @ rot.T, tt, material=mat, rigid=rigid)
    sim.couple(top, base, tdem.PointEdge(friction_angle=25.0))
    return sim, top, rot @ np.array([1.0, 0.0])


def _centre(block, tang):
    nd = block.nodes()
    return (nd["mass"] @ nd["position"]) / nd["mass"].sum() @ tang


def test_block_rests_on_a_block_inclined_below_its_friction_angle():
    # a little local damping lets its elastic vibrations die (undamped, they make the
    # contacts' normal forces oscillate and the block ratchets down slowly)
    sim, top, tang = _block_on_incline(20.0, damping=0.1)
    x0 = _centre(top, tang)
    sim.run(until=0.3)
    x1 = _centre(top, tang)
    sim.run(until=0.6)
    x2 = _centre(top, tang)
    # it settles on the springs (a small give), then does not move
    assert abs(x1 - x0) < 1e-4
    assert abs(x2 - x1) < 2e-5


@pytest.mark.parametrize("rigid", [False, True])
def test_block_slides_on_a_block_inclined_above_its_friction_angle(rigid):
    sim, top, tang = _block_on_incline(30.0, rigid=rigid)
    sim.run(until=0.05)
    x0 = _centre(top, tang)
    nd = top.nodes()
    v0 = (nd["mass"] @ nd["velocity"]) / nd["mass"].sum() @ tang
    t0 = sim.time
    sim.run(until=0.35)
    dt = sim.time - t0
    acc = 2.0 * (_centre(top, tang) - x0 - v0 * dt) / dt ** 2
    want = -G * (math.sin(math.radians(30)) - math.cos(math.radians(30)) *
                 math.tan(math.radians(25)))
    assert acc == pytest.approx(want, rel=0.03)


@pytest.mark.parametrize("rigid", [False, True])
def test_block_block_collision_conserves_momentum(rigid):
    va, ta = tdem.mesh.rectangle(0.2, 0.2, 2, 2, pattern="cross")
    vb, tb = tdem.mesh.rectangle(0.2, 0.2, 2, 2, pattern="cross", origin=(0.201, 0.05))
    sim = tdem.Simulation(gravity=(0.0, 0.0), dt_fraction=0.5)
    mat = tdem.Elastic(density=1000.0, young=1e7, poisson=0.3)
    a = sim.add_block(va, ta, material=mat, velocity=(1.0, 0.1), rigid=rigid)
    b = sim.add_block(vb, tb, material=mat, velocity=(-0.5, 0.0))
    sim.couple(a, b, tdem.PointEdge(friction_angle=25.0))

    def momentum():
        mv = np.concatenate([o.nodes()["mass"][:, None] * o.nodes()["velocity"]
                             for o in (a, b)])
        return mv.sum(axis=0), np.abs(mv).sum()

    p0, scale = momentum()
    sim.run(until=0.05)
    p1, _ = momentum()
    assert np.abs(p1 - p0).max() < 1e-10 * scale
    # they met: b now moves right
    assert (b.nodes()["mass"] @ b.nodes()["velocity"][:, 0]) > 0.0


def test_rigid_block_falls_freely_and_keeps_its_shape():
    v, t = tdem.mesh.rectangle(0.3, 0.1, 3, 1)
    sim = tdem.Simulation(gravity=(0.0, -G), dt=1e-4)
    b = sim.add_block(v, t, material=tdem.Elastic(density=2500.0, young=1e9, poisson=0.25), rigid=True,
                      velocity=(1.0, 0.0))
    sim.run(steps=1000)
    nd = b.nodes()
    tt = sim.time
    # leapfrog from rest: Σ g·k·dt² = ½ g t (t + dt)
    assert np.allclose(nd["displacement"][:, 1], -0.5 * G * tt * (tt + 1e-4), rtol=1e-9)
    assert np.allclose(nd["displacement"][:, 0], 1.0 * tt, rtol=1e-9)
    assert np.allclose(nd["velocity"][:, 1], -G * tt, rtol=1e-9)


def test_point_edge_contacts_are_written_for_paraview(tmp_path):
    import meshio
    sim, block, _, _ = _disc_on(0.0, 30.0, damping=0.7)
    sim.output(tmp_path / "o", every=500)
    sim.run(steps=1000)
    c = sim.point_edge_contacts()
    assert len(c["normal"]) == 1
    m = meshio.read(tmp_path / "o" / "couplings_00002.vtu")
    assert m.cells_dict["line"].shape == (1, 2)
    w = sim.particles.numpy()["mass"][0] * G
    assert m.cell_data["normal_force"][0][0] == pytest.approx(w, rel=0.05)
    assert (tmp_path / "o" / "couplings.pvd").exists()
    assert (tmp_path / "o" / "blocks.pvd").exists()


def test_cohesive_contact_sheared_caps_then_loses_its_cohesion():
    v, t, _, _ = _rotated_block(0.0)
    sim = tdem.Simulation(gravity=(0.0, -G), dt=2e-5)
    block = sim.add_block(v, t, material=tdem.Elastic(density=2500.0, young=1e8, poisson=0.25))
    block.fix(np.arange(len(v)), vx=0.0, vy=0.0)
    r, C, phi = 0.05, 2e3, 30.0
    disc = sim.add_particles([[0.03, r]], r, density=2000.0, contact=tdem.LinearContact(kn=1e7))
    sim.couple(disc, block, tdem.PointEdge(kn=1e7, ks=1e7, friction_angle=phi,
                                           cohesion=C, tensile_strength=1e4))
    sim.fix_particles(disc.ids, vx=0.0, vy=0.0)
    sim.run(steps=10)
    sim.fix_particles(disc.ids, vx=0.0, vy=-0.001)      # press it in: F_n = K_n·δ
    sim.run(steps=500)
    fn = sim.particles.numpy()["force"][0, 1]
    sim.fix_particles(disc.ids, vx=0.002, vy=0.0)       # then shear it
    fs = []
    for _ in range(300):
        sim.run(steps=10)
        fs.append(-sim.particles.numpy()["force"][0, 0])
    fs = np.array(fs)
    tan = math.tan(math.radians(phi))
    assert fn > 0
    assert fs.max() == pytest.approx(fn * tan + C * 2 * r, rel=0.01)
    assert fs[-1] == pytest.approx(fn * tan, rel=0.01)


def _plate_hits_disc(dy, speed=0.5, r=0.025, duration=0.12):
    """A kinematic plate 0.6 m x 0.04 m inclined at 60° (the soil-cutting blade, its
    front face towards +x, its cutting edge at the origin), every node driven at
    ``speed`` along +x, hits a free disc (R = 2.5 cm, wider than the plate is thick)
    at rest 1 cm ahead of the cutting edge and ``dy`` above it; no gravity. Returns
    the disc's largest speed."""
    a = math.radians(60.0)
    u = np.array([-math.cos(a), math.sin(a)])       # along the plate, up and back
    n = np.array([math.sin(a), math.cos(a)])        # outward normal of the front face
    c = np.array([[0.0, 0.0], 0.6 * u, 0.6 * u - 0.04 * n, -0.04 * n])
    v, t = tdem.mesh.polygon(c, 0.0113)
    sim = tdem.Simulation(gravity=(0.0, 0.0), dt_fraction=0.5, local_damping=0.0,
                          progress=False)
    # the plate is kinematic: a soft material keeps the time step of the disc
    plate = sim.add_block(v, t, material=tdem.Elastic(density=7800.0, young=1e7, poisson=0.3))
    plate.fix(np.arange(len(v)), vx=speed, vy=0.0)
    disc = sim.add_particles([[r + 0.01, dy]], r, density=1750.0,
                             contact=tdem.LinearContact(kn=1e7))
    sim.couple(disc, plate, tdem.PointEdge(kn=1e7, friction_angle=20.0))
    vmax = 0.0
    for k in range(int(round(duration / 0.002))):
        sim.run(until=(k + 1) * 0.002)
        vmax = max(vmax, float(np.hypot(*sim.particles.numpy()["velocity"][0])))
    return vmax


def test_disc_hit_by_a_driven_plate_on_its_face_bounces_at_the_elastic_speed():
    # elastic normal bounce off the face (normal n = (sin 60°, cos 60°)) and the disc
    # carried along the face by friction (tan 20° · 2 V sin 60° > V cos 60°, it
    # sticks): |v| = V·sqrt((2 sin 60°)² + cos² 60°) = 1.803 V
    V = 0.5
    want = V * math.sqrt((2 * math.sin(math.radians(60))) ** 2 + math.cos(math.radians(60)) ** 2)
    assert _plate_hits_disc(0.03, V) == pytest.approx(want, rel=0.02)


@pytest.mark.parametrize("dy", [-0.03, 0.0, 0.005])
def test_disc_passing_a_driven_plate_corner_gains_no_energy(dy):
    # at the cutting edge (a corner with the particle wider than the plate's end) the
    # contacts switch edges; in the plate's frame a passive contact cannot raise the
    # disc's kinetic energy, |v − V| ≤ V, so |v| ≤ 2 V
    V = 0.5
    assert _plate_hits_disc(dy, V) <= 2.0 * V * 1.01


def test_stacked_rigid_blocks_pushed_sideways_stay_on_each_other():
    # six 10 cm concrete blocks stacked corner over corner on a fixed slab (the
    # water_blocks columns), released under gravity; the third one pushed sideways
    # at V = 5 cm/s. Its bottom corners then lie a hair beyond the side edges of the
    # block below, crossing them by less than its top edge: by the entrance rule
    # they still meet that top edge (without it they met the side edges, with
    # horizontal normals, and the four upper blocks fell through the second at g·t:
    # 12 mm in 0.05 s). Bounds: the stack settles by at most twice (sudden load) its
    # static give with one K_n spring per joint, 2·Σ_k k·m·g/K_n = 42·m·g/K_n =
    # 33 µm; a passive stack cannot make a block faster than the push, and its
    # kinetic energy stays below ½·m·V² plus the work of gravity over the settlement.
    V, kn, a = 0.05, 3e8, 0.1
    sim = tdem.Simulation(gravity=(0.0, -G), dt=9.4e-5, local_damping=0.0, progress=False)
    concrete = tdem.Elastic(density=2400.0, young=30e9, poisson=0.2)
    fv, ft = tdem.mesh.rectangle(1.0, 0.1, 1, 1, origin=(-0.5, -0.1))
    floor = sim.add_block(fv, ft, material=concrete, rigid=True)
    floor.fix(np.arange(len(fv)), vx=0.0, vy=0.0)
    blocks = []
    for r in range(6):
        v = np.array([[0.0, 0.0], [a, 0.0], [a, a], [0.0, a]]) + [0.0, r * a]
        blocks.append(sim.add_block(v, np.array([[0, 1, 2], [0, 2, 3]]), material=concrete,
                                    rigid=True, velocity=(V if r == 2 else 0.0, 0.0)))
    law = tdem.PointEdge(kn=kn, ks=kn / 2.4, friction_angle=25.0)
    for k, b in enumerate(blocks):
        sim.couple(b, floor, law)
        for o in blocks[k + 1:]:
            sim.couple(b, o, law)
    m = 2400.0 * a * a

    def state():
        nd = [b.nodes() for b in blocks]
        y = np.array([n["position"][:, 1].mean() for n in nd])
        v = np.array([n["velocity"].mean(axis=0) for n in nd])
        return y, v

    y0, _ = state()
    for k in range(25):
        sim.run(until=0.002 * (k + 1))
        y, v = state()
        sink = y0 - y
        assert np.all(sink < 42.0 * m * G / kn), (sim.time, sink)
        assert np.abs(v).max() < V, (sim.time, v)
        assert 0.5 * m * (v ** 2).sum() < 0.5 * m * V ** 2 + m * G * sink.sum(), sim.time


def test_checkpoint_before_version_4_restores_its_vertex_edge_contacts(tmp_path):
    """Before version 4 a checkpoint's contact slots named the edges of a copy of
    each block's boundary per couple; such a file (made here from a version-4 one,
    the slots turned into that layout) loads with the same contacts and continues
    bit for bit as the version-4 file does."""
    import h5py
    sim = tdem.Simulation(gravity=(0.0, -G), dt=9.4e-5, local_damping=0.0, progress=False)
    concrete = tdem.Elastic(density=2400.0, young=30e9, poisson=0.2)
    fv, ft = tdem.mesh.rectangle(1.0, 0.1, 1, 1, origin=(-0.5, -0.1))
    floor = sim.add_block(fv, ft, material=concrete, rigid=True)
    floor.fix(np.arange(len(fv)), vx=0.0, vy=0.0)
    blocks = [sim.add_block(np.array([[0.0, 0.0], [0.1, 0.0], [0.1, 0.1], [0.0, 0.1]])
                            + [0.02 * r, 0.1 * r], np.array([[0, 1, 2], [0, 2, 3]]),
                            material=concrete, rigid=True) for r in range(4)]
    law = tdem.PointEdge(kn=3e8, ks=1e8, friction_angle=25.0)
    for k, b in enumerate(blocks):
        sim.couple(b, floor, law)
        for o in blocks[k + 1:]:
            sim.couple(b, o, law)
    sim.run(steps=200)
    sim.save(tmp_path / "v4.h5")
    a = sim._cont.a
    new = a["vsedge"].to_numpy()
    cpl = a["vcpl"].to_numpy()
    per = sim._cont._old_edges["v"]
    start = np.concatenate([[0], np.cumsum([len(e) for e in per])])
    old = new.copy()
    for q, k in zip(*np.nonzero(new >= 0)):
        c = cpl[q]
        old[q, k] = start[c] + int(np.flatnonzero(per[c] == new[q, k])[0])
    assert np.any(old != new) and np.count_nonzero(new >= 0) >= 4
    import shutil
    shutil.copy(tmp_path / "v4.h5", tmp_path / "v3.h5")
    with h5py.File(tmp_path / "v3.h5", "r+") as f:
        f["continuum/vsedge"][...] = old
        f.attrs["version"] = 3
    one = tdem.Simulation.load(tmp_path / "v4.h5")
    two = tdem.Simulation.load(tmp_path / "v3.h5")
    assert np.array_equal(two._cont.a["vsedge"].to_numpy(), new)
    one.run(steps=200)
    two.run(steps=200)
    for b1, b2 in zip(one.blocks, two.blocks):
        assert np.array_equal(b1.nodes()["position"], b2.nodes()["position"])
        assert np.array_equal(b1.nodes()["force"], b2.nodes()["force"])
