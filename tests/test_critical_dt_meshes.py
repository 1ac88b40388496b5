"""The critical time step of a 3D model counts the laws of its mesh walls (each
triangle's law column, not a 2D wall's)."""
import math

import numpy as np
import pytest

import tdem


def test_a_stiffer_mesh_law_sets_the_critical_step():
    soft = tdem.LinearContact(kn=1e3, friction=0.3)
    stiff = tdem.LinearContact(kn=1e7, friction=0.3)
    sim = tdem.Simulation(dim=3, progress=False)
    sim.add_particles([[0.0, 0.0, 0.05]], 0.01, density=2500.0, contact=soft)
    alone = sim.critical_dt()
    v, t = tdem.surfaces.plane((0.0, 0.0, 0.0), (0.0, 0.0, 1.0), 1.0)
    sim.add_mesh(v, t, contact=stiff)
    m = 2500.0 * 4.0 / 3.0 * math.pi * 0.01 ** 3
    assert alone == pytest.approx(2 * math.sqrt(m / 1e3), rel=1e-12)
    assert sim.critical_dt() == pytest.approx(2 * math.sqrt(m / 1e7), rel=1e-12)
    sim.run(steps=2)
    assert np.isfinite(sim.particles.numpy()["position"]).all()
