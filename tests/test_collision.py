"""Two discs head-on with the linear law (C&S): contact duration, restitution."""
import math

import numpy as np
import pytest

import tdem


def collide(restitution=None, dt_fraction=0.01, kn=1e6, r=0.1, rho=1000.0, v=0.5):
    sim = tdem.Simulation(gravity=(0.0, 0.0), dt_fraction=dt_fraction)
    law = tdem.LinearContact(kn=kn, ks=kn, friction=0.5, restitution=restitution)
    sim.add_particles([[0.0, 0.0], [2 * r + 0.01, 0.0]], r, density=rho, contact=law,
                      velocity=[[v, 0.0], [-v, 0.0]])
    sim.monitor("overlap", lambda s: 2 * r - np.diff(s.particles.numpy()["position"][:, 0])[0],
                every=1)
    sim.run(until=0.1)
    t, u = sim.histories()["overlap"]
    vel = sim.particles.numpy()["velocity"]
    return rho * math.pi * r * r, t, u, vel


def crossings(t, u):
    """Times where u changes sign, by linear interpolation."""
    k = np.nonzero(np.sign(u[1:]) != np.sign(u[:-1]))[0]
    return t[k] - u[k] * (t[k + 1] - t[k]) / (u[k + 1] - u[k])


def test_contact_duration_and_elastic_restitution():
    m, t, u, vel = collide()
    ts = crossings(t, u)
    assert len(ts) == 2
    expected = math.pi * math.sqrt((m / 2) / 1e6)
    assert ts[1] - ts[0] == pytest.approx(expected, rel=0.01)
    e = (vel[1, 0] - vel[0, 0]) / (2 * 0.5)
    assert e == pytest.approx(1.0, abs=0.005)
    assert abs(vel[:, 0].sum()) < 1e-12  # momentum


def test_restitution_half():
    *_, vel = collide(restitution=0.5)
    e = (vel[1, 0] - vel[0, 0]) / (2 * 0.5)
    assert e == pytest.approx(0.5, rel=0.03)
