"""bonded_rock: the bonded-particle model's trends (Potyondy & Cundall 2004) on the
quick sample: the uniaxial strength proportional to the bond strengths, the Brazilian
strength formula, the Brazilian test of bonded spheres, and the continua's curves read
beside them."""
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


def test_band_share_and_hondros_factor():
    """The share of a disc's area within ±aR of a diameter against a numerical
    quadrature, and Hondros' factor: 1 for a line load, (sin 2α − α)/sin α."""
    for a in (0.1, 0.25, 0.5, 1.0):
        x = np.linspace(-a, a, 20001)
        y = 2 * np.sqrt(np.clip(1 - x * x, 0, None))
        area = float(np.sum(0.5 * (y[1:] + y[:-1]) * np.diff(x)))
        assert br.band_share(a) == pytest.approx(area / math.pi, rel=1e-4)
    assert br.band_share(1.0) == pytest.approx(1.0, rel=1e-12)
    assert br.hondros(1e-6) == pytest.approx(1.0, abs=1e-9)
    assert br.hondros(math.radians(15)) == pytest.approx(
        (math.sin(math.radians(30)) - math.radians(15)) / math.sin(math.radians(15)),
        rel=1e-12)


def test_continuum_curves_read_from_a_folder(tmp_path):
    """``--curves``: the PCMM and FVM curves read from a folder's histories.h5 (as
    uniaxial_compression writes it); E and UCS of an elastic–perfectly plastic curve
    of slope 32 GPa and plateau 12.87 MPa come back as those numbers."""
    from cases import _common as common
    strain = np.linspace(0, 1.2e-3, 301)
    k, top = br.E_ROCK / (1 - br.NU ** 2), br.UCS_MC
    stress = np.minimum(k * strain, top)
    common.save_histories(tmp_path / "histories.h5",
                          {n: {"strain": strain, "stress": stress} for n in br.UC_MODELS})
    curves, origin = br.continuum_curves("quick", tmp_path, {}, source=tmp_path)
    assert set(curves) == set(br.UC_MODELS)
    for c in curves.values():
        assert c["ucs"] == pytest.approx(top, rel=1e-12)
        assert c["E"] == pytest.approx(k, rel=1e-9)
        assert c["elastic_slope"] == pytest.approx(k, rel=1e-9)
    assert origin["read"].endswith("histories.h5")


def test_brazilian_spheres_split_along_the_loaded_diameter():
    """The Brazilian disc of bonded spheres (D = 0.1 m, t = 0.05 m) splits in tension
    (P&C: the cracks most in tension) along its loaded diameter: most cracks lie in the
    band ±D/8 about it, which holds 0.315 of the disc's area. (Its σ_t over the bonded
    spheres' UCS, above the rock's T/UCS: the quick preset's check.)"""
    cfg = br.PRESETS["quick"]
    b = br.brazilian3d(cfg, {})
    assert b["cracks"] > 0
    assert b["tension_fraction"] > 0.5
    assert br.band_share(br.BAND) == pytest.approx(0.315, abs=1e-3)
    assert b["central_band"] > 0.5
    # σ_t = 2P/(πDt) of the recorded peak force
    assert b["sigma_t"] == pytest.approx(2 * b["P_max"] / (math.pi * br.DIAM * br.THICK3D),
                                         rel=1e-12)


@pytest.mark.slow
def test_quick_preset(tmp_path):
    s = br.main(["--preset", "quick", "--out", str(tmp_path)])
    assert s["pass"] is True
