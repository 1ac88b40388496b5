"""Inputs that look right and are not: swapped positional material arguments and a
friction angle typed as a coefficient are refused, naming the argument."""
import math

import pytest

import tdem


@pytest.mark.parametrize("cls, args", [
    (tdem.Elastic, (7800.0, 210e9, 0.3)),
    (tdem.MohrCoulomb, (2500.0, 30e9, 0.25)),
    (tdem.Fluid, (1000.0, 2e9)),
    (tdem.LinearContact, (1e6,)),
    (tdem.HertzMindlin, (70e9, 0.2)),
])
def test_material_and_law_arguments_are_keywords(cls, args):
    # Elastic(210e9, 7800, 0.3) (modulus and density swapped) was accepted
    with pytest.raises(TypeError, match="positional argument"):
        cls(*args)


def test_keywords_give_the_same_material():
    m = tdem.Elastic(density=7800.0, young=210e9, poisson=0.3)
    assert (m.density, m.young, m.poisson) == (7800.0, 210e9, 0.3)


@pytest.mark.parametrize("law", [tdem.LinearContact, tdem.HertzMindlin])
def test_friction_in_degrees_is_refused(law):
    kw = {"kn": 1e6} if law is tdem.LinearContact else {"young": 1e9, "poisson": 0.25}
    with pytest.raises(tdem.InputError, match=r"^friction is the coefficient mu = tan\(phi\), "
                                              r"at most 10, got 30 .*0\.577"):
        law(friction=30, **kw)
    assert law(friction=10.0, **kw).friction == 10.0


def test_mohr_coulomb_tension_defaults_to_its_apex():
    # it was 1 MPa whatever the cohesion: with c = 1 kPa the attribute read 1 MPa
    m = tdem.MohrCoulomb(density=2000.0, young=1e7, poisson=0.3, cohesion=1e3,
                         friction_angle=30.0)
    apex = 1e3 / math.tan(math.radians(30.0))
    assert m.tensile_strength == pytest.approx(apex, rel=1e-15)
    assert m.tension == pytest.approx(apex, rel=1e-15)
    clay = tdem.MohrCoulomb(density=2000.0, young=1e7, poisson=0.45, cohesion=20e3,
                            friction_angle=0.0)
    assert clay.tensile_strength == 0.0 and clay.tension == 0.0


def test_large_initial_overlaps_warn_with_the_largest():
    law = tdem.LinearContact(kn=1e6)
    sim = tdem.Simulation()
    with pytest.warns(RuntimeWarning, match=r"^positions: particles 1 and 2 start overlapping "
                                            r"by 25% of the smaller radius"):
        # discs 1 and 2 overlap by 0.025 m of R = 0.1; 0 and 1 by 5 % (no warning alone)
        sim.add_particles([[0.0, 0.0], [0.195, 0.0], [0.37, 0.0]], 0.1, contact=law)
    with pytest.warns(RuntimeWarning, match=r"particles 2 and 3 start overlapping by 50%"):
        sim.add_particles([[0.37, 0.15]], 0.1, contact=law)       # against one already there
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        sim.add_particles([[1.0, 1.0], [1.195, 1.0]], 0.1, contact=law)   # 5 %: no warning
