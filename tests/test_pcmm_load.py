"""A loaded PCMM model reports its elements before its first step as the saved one
did: areas, N_e and weights (they were 0, 0 and 1 until the next rebuild)."""
import numpy as np
import pytest

import tdem


def test_elements_read_back_after_load_before_any_step(tmp_path):
    mat = tdem.MohrCoulomb(density=2500.0, young=1e9, poisson=0.25, cohesion=1e6,
                           friction_angle=30.0, tensile_strength=2e7)
    pos, rad = tdem.pack.regular(1.0, 0.6, 0.05)
    sim = tdem.Simulation(gravity=(0.0, -9.81), dt_fraction=0.5)
    sim.add_particles(pos, rad, material=mat, tolerance=0.05)
    sim.add_wall((-1.0, -0.05), (2.0, -0.05), contact=tdem.LinearContact(kn=1e9))
    sim.run(steps=50)
    before = sim.elements.numpy()
    sim.save(tmp_path / "c.h5")
    after = tdem.Simulation.load(tmp_path / "c.h5").elements.numpy()
    for key in ("triangles", "owner", "area", "n_cover", "weight", "stress", "stress_zz"):
        np.testing.assert_array_equal(after[key], before[key], err_msg=key)
    # the square lattice (spacing 0.1 m): every element 0.005 m², each point covered by
    # 4 of them, and the weighted areas add up to the hull of the centres, 0.9 x 0.5 m
    np.testing.assert_allclose(before["area"], 0.005, rtol=1e-12)
    assert np.all(before["n_cover"] == 4)
    assert np.sum(before["area"] * before["weight"]) == pytest.approx(0.45, rel=1e-12)
