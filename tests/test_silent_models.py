"""Models that would run without doing what they seem to say so when built (after
the first step, when the PCMM elements are made): a body whose tolerance makes no
element (a square lattice's diagonals are 2√2 R apart, 0.828 R more than two
radii: Eq. 1 needs tolerance >= 0.828 R for them), and element water on a
hexagonal lattice (it carries 40–60 % of ρgh; Fluid(voronoi=True) carries it)."""
import math
import warnings

import numpy as np
import pytest

import tdem

R = 0.01


def _square_body(tolerance):
    sim = tdem.Simulation(gravity=(0.0, -9.81), progress=False)
    pos, r = tdem.pack.regular(0.2, 0.2, R)
    sim.add_particles(pos, r, material=tdem.Elastic(density=2000.0, young=1e7, poisson=0.25),
                      tolerance=tolerance)
    return sim


def test_a_tolerance_below_the_diagonals_makes_no_element_and_says_so():
    sim = _square_body(0.5 * R)
    # the message names the tolerance the diagonals need: (2√2 − 2) R = 0.828 R
    with pytest.warns(RuntimeWarning, match=r"made 0 elements.*it runs as loose discs.*"
                                            r"tolerance >= 0\.008284 m \(0\.828 R\)"):
        sim.run(steps=2)
    assert len(sim.elements.numpy()["triangles"]) == 0


def test_a_tolerance_above_the_diagonals_makes_elements_silently():
    sim = _square_body(0.9 * R)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        sim.run(steps=2)
    # each square of the 10 × 10 lattice cut by a diagonal at least: >= 2 × 81 triangles
    assert len(sim.elements.numpy()["triangles"]) >= 162


def _hex_water(voronoi):
    water = tdem.Fluid(density=1000.0, bulk_modulus=2e6, voronoi=voronoi)
    sim = tdem.Simulation(gravity=(0.0, -9.81), progress=False)
    pos = np.array([(2 * R * i + (R if j % 2 else 0.0), j * math.sqrt(3) * R)
                    for j in range(10) for i in range(10)])
    sim.add_particles(pos, R, material=water, tolerance=0.2 * R)
    sim.add_wall((-0.05, -R), (0.25, -R), contact=tdem.LinearContact(kn=2e6))
    return sim


def test_element_water_on_a_hexagonal_lattice_says_to_use_voronoi():
    sim = _hex_water(False)
    with pytest.warns(RuntimeWarning, match=r"Fluid \(100 particles, (\d+) elements\).*"
                                            r"40–60 % of the hydrostatic pressure.*"
                                            r"voronoi=True") as rec:
        sim.run(steps=2)
    made = len(sim.elements.numpy()["triangles"])
    assert made >= 2 * 81                        # the lattice's triangles, at least
    assert any(f"100 particles, {made} elements" in str(w.message) for w in rec)


def test_voronoi_water_on_a_hexagonal_lattice_is_silent():
    sim = _hex_water(True)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        sim.run(steps=2)
    assert sim.steps == 2
