"""Inputs that look right and are not: swapped positional material arguments and a
friction angle typed as a coefficient are refused, naming the argument."""
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
