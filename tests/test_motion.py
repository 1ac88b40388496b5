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
