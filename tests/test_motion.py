"""Walls and meshes moved by functions of time (machinery): vibration, rotation about
any axis through any point, checked against the integrals of the prescribed
velocities; the force a vibrating plate gives a resting sphere."""
import math

import numpy as np
import pytest

import tdem


def _sim3d(dt=1e-5):
    sim = tdem.Simulation(dim=3, gravity=(0.0, 0.0, 0.0), dt=dt)
    law = tdem.LinearContact(kn=1e5, ks=0.0, friction=0.0)
    sim.add_particles([[5.0, 5.0, 5.0]], 0.01, density=2500.0, contact=law)
    return sim, law


def test_a_vibrating_plate_follows_its_displacement():
    """A plane mesh vibrated along z with amplitude 1 mm at 50 Hz: after 13 ms its
    centre has moved A sin(2π f t) (the step integrates the velocity at its start:
    within 2 % of A), and a quarter period later again."""
    sim, law = _sim3d()
    v, t = tdem.surfaces.plane((0, 0, 0), (0, 0, 1), 1.0)
    m = sim.add_mesh(v, t, contact=law)
    A, f = 1e-3, 50.0
    m.motion(velocity=tdem.motion.vibration(A, f, (0, 0, 1)))
    z0 = m.center[2]
    for T in (0.013, 0.018):
        sim.run(until=T)
        assert m.center[2] - z0 == pytest.approx(A * math.sin(2 * math.pi * f * sim.time),
                                                 abs=0.02 * A)
        assert m.triangles[:, :, 2] == pytest.approx(m.center[2], abs=1e-12)


def test_a_drum_turns_about_an_axis_through_a_point():
    """A mesh turned about the x axis through (0, 0, 1) at ω(t) = 2t rad/s (a ramp):
    at t = 0.5 s it has turned by ∫ω dt = 0.25 rad, each corner on its circle about
    the axis (radius kept to 1e-9, angle within 1e-4 rad: each step turns by ω at
    its start, T·Δt = 5e-5 rad short)."""
    sim, law = _sim3d(dt=1e-4)
    v, t = tdem.surfaces.plane((0, 0, 0), (0, 0, 1), 0.5)
    m = sim.add_mesh(v, t, contact=law)
    before = m.triangles.reshape(-1, 3).copy()
    m.motion(angular_velocity=lambda s: (2.0 * s, 0.0, 0.0), center=(0.0, 0.0, 1.0))
    sim.run(until=0.5)
    after = m.triangles.reshape(-1, 3)
    rel0 = before[:, 1:] - np.array([0.0, 1.0])
    rel1 = after[:, 1:] - np.array([0.0, 1.0])
    assert np.linalg.norm(rel1, axis=1) == pytest.approx(np.linalg.norm(rel0, axis=1),
                                                         abs=1e-9)
    turned = np.arctan2(rel1[:, 1], rel1[:, 0]) - np.arctan2(rel0[:, 1], rel0[:, 0])
    turned = (turned + np.pi) % (2 * np.pi) - np.pi
    assert turned == pytest.approx(np.full(len(turned), sim.time ** 2), abs=1e-4)
    assert after[:, 0] == pytest.approx(before[:, 0], abs=1e-12)
    m.motion()                       # stops it
    sim.run(steps=10)
    assert m.triangles.reshape(-1, 3) == pytest.approx(after, abs=1e-12)


def test_a_segment_wall_accelerates_as_its_velocity_function_says():
    """2D: a wall given vx(t) = 0.2 t has moved 0.1 t² (within 0.5 %) at t = 0.4 s."""
    sim = tdem.Simulation(gravity=(0.0, 0.0), dt=1e-4)
    law = tdem.LinearContact(kn=1e5, ks=0.0, friction=0.0)
    sim.add_particles([[5.0, 5.0]], 0.01, density=2500.0, contact=law)
    w = sim.add_wall((0.0, 0.0), (0.0, 1.0), contact=law)
    x0 = w.center[0]
    w.motion(velocity=lambda t: (0.2 * t, 0.0))
    sim.run(until=0.4)
    assert w.center[0] - x0 == pytest.approx(0.1 * sim.time ** 2, rel=5e-3)


def test_a_vibrating_plate_lifts_a_sphere_above_one_g():
    """A sphere resting on a plate vibrated at Γ = (2π f)² A / g = 2.5 leaves it
    (a bed is thrown when Γ > 1): its largest gap above the plate exceeds half the
    plate's amplitude; at Γ = 0.5 it rides the plate, its gap never more than 5 % of
    A."""
    for gamma, leaves in ((2.5, True), (0.5, False)):
        sim = tdem.Simulation(dim=3, gravity=(0.0, 0.0, -9.81), dt=5e-6)
        law = tdem.LinearContact(kn=1e4, ks=0.0, friction=0.0, restitution=0.5)
        g = sim.add_particles([[0.0, 0.0, 0.005]], 0.005, density=2500.0, contact=law)
        v, t = tdem.surfaces.plane((0, 0, 0), (0, 0, 1), 0.1)
        m = sim.add_mesh(v, t, contact=law)
        sim.run(until=0.05)                      # settle on the plate
        f = 30.0
        A = gamma * 9.81 / (2 * math.pi * f) ** 2
        # phase −π/2: the plate starts from rest (no velocity jump to kick the sphere)
        m.motion(velocity=tdem.motion.vibration(A, f, (0, 0, 1), phase=-math.pi / 2))
        gap = []
        for k in range(40):
            sim.run(until=0.05 + (k + 1) * 0.1 / 40)
            z = g.numpy()["position"][0, 2] if hasattr(g, "numpy") else \
                sim.particles.numpy()["position"][0, 2]
            gap.append(z - 0.005 - m.center[2])
        assert (max(gap) > 0.5 * A) == leaves, (gamma, max(gap), A)
        if not leaves:
            assert max(gap) < 0.05 * A + 1e-6


def test_bad_motions_are_named():
    sim, law = _sim3d()
    v, t = tdem.surfaces.plane((0, 0, 0), (0, 0, 1), 1.0)
    m = sim.add_mesh(v, t, contact=law)
    with pytest.raises(tdem.InputError, match="velocity"):
        m.motion(velocity=(1.0, 2.0))
    with pytest.raises(tdem.InputError, match="angular_velocity"):
        m.motion(angular_velocity=(0.0, float("nan"), 0.0))
    m.motion(velocity=lambda t: (0.0, 1.0))
    with pytest.raises(tdem.InputError, match="velocity as a function of time returned"):
        sim.run(steps=2)
    m.servo(force=1.0, direction=(0, 0, -1))
    with pytest.raises(tdem.InputError, match="servo"):
        m.motion(velocity=(0.0, 0.0, 1.0))
    with pytest.raises(tdem.InputError, match="frequency"):
        tdem.motion.vibration(1e-3, 0.0, (0, 0, 1))
    with pytest.raises(tdem.InputError, match="direction"):
        tdem.motion.vibration(1e-3, 10.0, (0, 0, 0))


def _on_belt(shape=None):
    sim = tdem.Simulation(dim=3, gravity=(0.0, 0.0, -9.81), dt=2e-5)
    law = tdem.LinearContact(kn=2e4, friction=0.5, restitution=0.3)
    if shape is None:
        g = sim.add_particles([[0.0, 0.0, 0.0049]], 0.005, density=2500.0, contact=law)
    else:
        g = sim.add_particles([[0.0, 0.0, 0.0049]], 0.005, density=2500.0, contact=law,
                              shape=shape)
    v, t = tdem.surfaces.plane((0, 0, 0), (0, 0, 1), 0.4, divisions=2)
    belt = sim.add_mesh(v, t, contact=law)
    return sim, g, belt


def test_a_ball_dropped_on_a_belt_rolls_at_two_sevenths_of_its_speed():
    """A sphere at rest put on a belt running at u = 0.5 m/s: friction at the contact
    accelerates it and spins it until it rolls without slipping; the angular momentum
    about the contact line is kept, so it ends at (2/7) u (within 2 %), rolling with
    ω_y R = v − u (the contact point moves with the belt); the belt itself does not move."""
    sim, g, belt = _on_belt()
    corners = belt.triangles.copy()
    belt.surface_velocity = (0.5, 0.0, 0.0)
    assert belt.surface_velocity == pytest.approx([0.5, 0.0, 0.0])
    sim.run(until=0.25)
    p = sim.particles.numpy()
    vx = p["velocity"][0, 0]
    assert vx == pytest.approx(2.0 / 7.0 * 0.5, rel=0.02)
    assert p["omega"][0, 1] * 0.005 == pytest.approx(vx - 0.5, rel=0.03)   # ω_y R = v − u
    assert belt.triangles == pytest.approx(corners, abs=1e-15)


def test_a_belt_survives_a_checkpoint_and_old_ones_load(tmp_path):
    """The surface velocity is kept by a checkpoint; a checkpoint whose mesh rows have
    the 21 columns of before reads with a still surface."""
    import h5py
    sim, g, belt = _on_belt()
    belt.surface_velocity = (0.2, 0.1, 0.0)
    sim.run(steps=5)
    path = tmp_path / "belt.h5"
    sim.save(path)
    back = tdem.Simulation.load(path)
    assert back.meshes[0].surface_velocity == pytest.approx([0.2, 0.1, 0.0])
    with h5py.File(path, "r+") as f:
        for k in ("host/walls", "state/wall"):
            old = f[k][()][:, :21]
            del f[k]
            f.create_dataset(k, data=old)
    back = tdem.Simulation.load(path)
    assert back.meshes[0].surface_velocity == pytest.approx([0.0, 0.0, 0.0])
    back.run(steps=2)


def test_a_cube_on_a_belt_is_carried_at_its_speed():
    """A polyhedral cube (1 cm) resting flat on a belt at 0.3 m/s slides until
    friction (μ = 0.5) has brought it to the belt's speed, within u/(μ g) = 0.06 s,
    then rides with it: at 0.15 s it moves at 0.3 m/s within 3 %."""
    vol = tdem.VolumeContact(young=1e6, friction=0.5, restitution=0.3)
    sim = tdem.Simulation(dim=3, gravity=(0.0, 0.0, -9.81))
    v, t = tdem.surfaces.plane((0, 0, 0), (0, 0, 1), 0.3, divisions=2)
    belt = sim.add_mesh(v, t, contact=vol)
    sim.add_particles([[0.0, 0.0, 0.005]], shape=tdem.Polyhedron.cube(0.01), density=2500,
                      contact=vol)
    sim.run(until=0.02)                      # settle
    belt.surface_velocity = (0.3, 0.0, 0.0)
    sim.run(until=0.17)
    vel = sim.particles.numpy()["velocity"][0]
    assert vel[0] == pytest.approx(0.3, rel=0.03)
    assert abs(vel[1]) < 1e-3


def _drum(radius=0.1, length=0.06, segments=24):
    """A closed drum, axis z through the origin: the cylinder with both ends."""
    v, t = tdem.surfaces.cylinder((0.0, 0.0, -0.5 * length), radius, length,
                                  segments=segments, bottom=True)
    k = segments
    top = len(v)
    v = np.concatenate([v, [[0.0, 0.0, 0.5 * length]]])
    cap = np.array([[top, k + i, k + (i + 1) % k] for i in range(k)])
    a, b, c = v[cap[:, 0]], v[cap[:, 1]], v[cap[:, 2]]
    down = np.cross(b - a, c - a)[:, 2] > 0            # normals into the drum (−z)
    cap[down] = cap[down][:, ::-1]
    return v, np.concatenate([t, cap])


def _spinning_drum(omega=4.0, spin_up=0.05):
    sim = tdem.Simulation(dim=3, gravity=(0.0, -9.81, 0.0), local_damping=0.0,
                          progress=False)
    law = tdem.LinearContact(kn=2e4, friction=0.4, restitution=0.6)
    drum = sim.add_mesh(*_drum(), contact=law)
    rng = np.random.default_rng(2)
    g = np.stack(np.meshgrid(np.arange(-3, 4) * 0.021, np.arange(-4, 1) * 0.021,
                             np.arange(-1, 2) * 0.021, indexing="ij"), -1).reshape(-1, 3)
    sim.add_particles(g + rng.uniform(-1e-3, 1e-3, g.shape), 0.0095, density=2500.0,
                      contact=law)
    drum.motion(angular_velocity=tdem.motion.ramp((0.0, 0.0, omega), spin_up),
                center=(0.0, 0.0, 0.0))
    return sim, drum


def test_a_drum_torque_balances_the_particles_angular_momentum():
    """A drum of spheres spun up by tdem.motion.ramp about its axis: it turns by the
    ramp's integral, and the torque it receives balances the particles' angular
    momentum about the axis, step by step: L(t) − L(0) = Σ (τ_gravity − M_drum) Δt,
    exact for the leapfrog (L of x_{n+1}, v_{n+1/2}; the moments of step n's forces
    at x_n), so to round-off."""
    sim, drum = _spinning_drum()
    n_steps = 600
    rec = []

    def record(s):
        p = s.particles.numpy()
        m, r = p["mass"], p["radius"]
        x, v, w = p["position"], p["velocity"], p["omega"]
        lz = float(np.sum(m * (x[:, 0] * v[:, 1] - x[:, 1] * v[:, 0])
                          + 0.4 * m * r * r * w[:, 2]))
        rec.append((lz, float(drum.torque[2]), float(np.sum(m * x[:, 0]) * -9.81)))
        return lz

    sim.run(steps=1)
    sim.monitor("L", record, every=1)
    record(sim)
    corners = drum.triangles.reshape(-1, 3)
    rim = np.flatnonzero(np.linalg.norm(corners[:, :2], axis=1) > 0.05)[:24]
    before = corners[rim, :2].copy()
    sim.run(steps=n_steps)
    dt = sim.dt
    lz = np.array([r[0] for r in rec])
    mz = np.array([r[1] for r in rec])
    tg = np.array([r[2] for r in rec])
    # step n's moments: the drum's of that step, gravity's at the positions before it
    impulse = np.cumsum((tg[:-1] - mz[1:]) * dt)
    scale = np.abs(lz).max()
    assert scale > 1e-4                                   # the bed was carried round
    np.testing.assert_allclose(lz[1:] - lz[0], impulse, rtol=0, atol=1e-9 * scale)
    # the drum turned by the ramp's integral (each step by ω at its start)
    after = drum.triangles.reshape(-1, 3)[rim, :2]
    turned = np.arctan2(after[:, 1], after[:, 0]) - np.arctan2(before[:, 1], before[:, 0])
    turned = (turned + np.pi) % (2 * np.pi) - np.pi
    t0, t1 = dt, sim.time
    ramp = tdem.motion.ramp((0.0, 0.0, 4.0), 0.05)
    steps = np.arange(t0, t1 - 0.5 * dt, dt)
    want = sum(ramp(t)[2] for t in steps) * dt
    assert turned == pytest.approx(np.full(24, want), abs=1e-9)


def test_a_drum_with_a_ramp_inserter_and_outlet_restarts_bit_for_bit(tmp_path):
    """A checkpoint of a model with a wall turned by a tdem.motion function, an
    inserter and an outlet continues exactly as the run it was taken from."""
    def model():
        sim, drum = _spinning_drum(omega=6.0, spin_up=0.1)
        law = sim._laws[0]
        sim.insert(box=((-0.05, 0.02, -0.02), (0.05, 0.07, 0.02)), per_s=400.0,
                   radius=0.006, density=2500.0, contact=law, velocity=(0.0, -0.5, 0.0),
                   until=0.12, seed=4)
        sim.remove_in(box=((-0.2, -0.2, -0.2), (0.2, -0.075, 0.2)))
        return sim, drum

    ref, drum = model()
    ref.run(until=0.05)
    path = tmp_path / "drum.h5"
    ref.save(path)
    ref.run(until=0.15)
    back = tdem.Simulation.load(path)
    back.run(until=0.15)
    a, b = ref.particles.numpy(), back.particles.numpy()
    np.testing.assert_array_equal(a["id"], b["id"])
    np.testing.assert_array_equal(a["position"], b["position"])
    np.testing.assert_array_equal(ref.meshes[0].triangles, back.meshes[0].triangles)
    assert ref._outlets[0].count == back._outlets[0].count > 0
    assert ref._inserters[0].count == back._inserters[0].count == 48


def test_a_motion_a_checkpoint_cannot_keep_is_named(tmp_path):
    """A wall turned by a plain Python function: saving says the loaded simulation
    keeps the velocity of now; the loaded wall indeed goes on at that constant."""
    sim, drum = _spinning_drum()
    drum.motion(angular_velocity=lambda t: (0.0, 0.0, 3.0 * t), center=(0.0, 0.0, 0.0))
    sim.run(steps=20)
    with pytest.warns(UserWarning, match="angular_velocity of mesh 0 is a function"):
        sim.save(tmp_path / "d.h5")
    back = tdem.Simulation.load(tmp_path / "d.h5")
    assert back._motions == {}
