"""bonded_rock: the bonded-particle model's trends (Potyondy & Cundall 2004) on the
quick sample: the uniaxial strength proportional to the bond strengths, and the
Brazilian strength formula."""
import math

import numpy as np
import pytest

from cases import bonded_rock as br


def test_ucs_is_proportional_to_the_bond_strengths():
    cfg = br.PRESETS["quick"]
    base = br.uniaxial(cfg, {})
    strong = br.uniaxial(cfg, {}, scale_strength=2.0)
    assert strong["ucs"] / base["ucs"] == pytest.approx(2.0, rel=0.05)
    # the elastic part is the bonds' and contacts' stiffness, not their strength
    assert strong["E"] / base["E"] == pytest.approx(1.0, rel=0.05)
    # a sample of 30 GPa bonds and contacts: E within 20 % of the plane-strain 32 GPa
    assert base["E"] == pytest.approx(br.E_ROCK / (1 - br.NU ** 2), rel=0.2)
    assert base["cracks"] > 0 and base["tension_fraction"] > 0.9


def test_brazilian_strength_formula():
    """σ_t = 2P/(πD): a peak force of 1 kN/m on the 0.1 m disc is 6.37 kPa."""
    p = 1e3
    assert 2 * p / (math.pi * br.DIAM) == pytest.approx(6366.2, rel=1e-4)
    np.testing.assert_allclose(br.UCS_MC, 12.87e6, rtol=1e-3)


@pytest.mark.slow
def test_quick_preset(tmp_path):
    s = br.main(["--preset", "quick", "--out", str(tmp_path)])
    assert s["pass"] is True
