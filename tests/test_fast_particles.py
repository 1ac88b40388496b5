"""Fast particles are not unstable (free flight, ejecta, jets).

A particle that moves more than half the skin since the neighbour lists were built
has them made again before the next force evaluation, however fast it goes: no
contact within reach at the start of a step is missed. One that moves more than its
radius in a step could cross a thin neighbour or a wall within that step: a warning
names it once, and the run goes on. Instability is a non-finite state, forces that
would move a particle more than its radius in one step, or an overlap past half the
radius (tests/test_inputs.py, tests/test_stable_dt.py)."""
import math
import warnings

import pytest

import tdem

G = 9.81


def test_drop_from_50_m_onto_a_soft_floor_falls_freely():
    """A disc (R = 0.1 m) dropped from 50 m above a floor of k_n = 2e3 N/m at the
    default step (0.079 s: 31 m/s × Δt is 25 radii): the free fall is the leapfrog's
    exact y_N = y0 − g Δt² N(N + 1)/2 to the last step above the floor, and the run
    says once that the disc moves more than its radius a step."""
    soft = tdem.LinearContact(kn=2e3)
    sim = tdem.Simulation(gravity=(0.0, -G), progress=False)
    sim.add_particles([[0.0, 50.0]], 0.1, density=2500.0, contact=soft)
    sim.add_wall((-5.0, 0.0), (5.0, 0.0), contact=soft)
    dt = sim.dt
    # the last step whose end is a radius above the floor
    n = max(k for k in range(1000) if 50.0 - G * dt * dt * k * (k + 1) / 2 > 0.1)
    assert n * dt * G * dt > 0.1          # faster than a radius a step before the floor
    with pytest.warns(RuntimeWarning, match=r"particle 0 moved more than its radius "
                                            r"\(0\.1 m\) in one step") as rec:
        sim.run(steps=n)
    assert sum("moved more than its radius" in str(w.message) for w in rec) == 1
    p = sim.particles.numpy()
    assert p["position"][0, 1] == pytest.approx(50.0 - G * dt * dt * n * (n + 1) / 2,
                                                rel=1e-12)
    assert p["velocity"][0, 1] == pytest.approx(-G * dt * n, rel=1e-12)


def test_a_disc_faster_than_the_skin_still_meets_its_neighbour():
    """A disc moving 0.25 R a step (more than half the skin, 0.2 R) hits an equal disc
    at rest head on (linear spring, no damping, peak overlap 0.44 R): the lists are
    built at every step of its approach, the contact is found, the momentum is kept
    to round-off and the velocities are exchanged (the leapfrog's error over a
    contact of 5.5 steps: 2.1 %, within 3 %)."""
    R, rho, kn = 0.01, 2500.0, 1e5
    law = tdem.LinearContact(kn=kn, friction=0.0)
    sim = tdem.Simulation(gravity=(0.0, 0.0), progress=False)
    m = rho * math.pi * R * R
    dt = 0.4 * math.sqrt(m / kn)
    sim.dt = dt
    v = 0.25 * R / dt
    sim.add_particles([[0.0, 0.0], [0.3, 0.0]], R, density=rho, contact=law,
                      velocity=[[v, 0.0], [0.0, 0.0]])
    approach = int((0.3 - 2 * R) / (v * dt))
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)       # nothing to say
        sim.run(steps=approach - 2)
        builds = sim.neighbour_builds
        sim.run(steps=40)
    assert builds >= approach - 3                # every step while it flies
    p = sim.particles.numpy()["velocity"][:, 0]
    assert p.sum() == pytest.approx(v, rel=1e-12)
    assert p[1] == pytest.approx(v, rel=0.03)
    assert abs(p[0]) < 0.03 * v
