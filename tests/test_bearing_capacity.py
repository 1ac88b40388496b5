"""Prandtl's collapse load of a smooth rigid strip footing on weightless soil
(cases/bearing_capacity.py): many elements flowing plastically together.

A rigid block pushed at 0.01 m/s through frictionless point–edge contacts into a
Mohr–Coulomb soil (c = 10 kPa, E = 10 MPa, ν = 0.3), the half-model right of the
centre line; q/c is the mean over a settlement of 0.08–0.10 b. Limit analysis:
N_c = 2 + π (φ = 0), (N_q − 1)·cot φ = 14.83 (φ = ψ = 20°). The discretisation
converges towards N_c from above, as h/b (docs/pcmm.md has the table over three
resolutions, packings and meshes); the tolerances below follow that table:

- PCMM square lattice, 6 spacings under the half-footing: q/c within −3 % / +12 %
  of 2 + π (measured +8.8 %); with each element's own volumetric strain (no mixed
  discretization) the soil locks: more than 1.2 × N_c at 4 spacings (measured
  1.74 × N_c; 1.31 × N_c at 10);
- slow (``pytest -m slow``): φ = ψ = 20° on the PCMM square lattice, 10 spacings
  under the half-footing, within 10 % of 14.83 (measured +2.7 %; the FVM mesh of
  one diagonal per cell reads +15 % there, +23 % at 6 cells); the finest
  resolution, 20 per half-width, within 5 % of 2 + π on the FVM mesh (measured
  +3.9 %) and on the PCMM square lattice (+3.5 %).
"""
import math

import pytest

from cases import bearing_capacity as bc

NC0 = 2.0 + math.pi


def test_prandtl_factors():
    assert bc.prandtl(0.0) == pytest.approx(5.1416, abs=1e-4)
    assert bc.prandtl(20.0) == pytest.approx(14.835, abs=1e-3)
    assert bc.prandtl(30.0) == pytest.approx(30.14, abs=1e-2)


def test_pcmm_tresca_soil_collapses_at_prandtl_load():
    r = bc.footing("regular", 6)
    assert 0.97 * NC0 < r["limit"] < 1.12 * NC0, r["limit"]


def test_pcmm_soil_without_mixed_discretization_locks():
    r = bc.footing("regular", 4, mixed=False)
    assert r["limit"] > 1.2 * NC0, r["limit"]


@pytest.mark.slow
def test_pcmm_frictional_soil_collapses_at_prandtl_load():
    r = bc.footing("regular", 10, 20.0)
    assert r["limit"] == pytest.approx(bc.prandtl(20.0), rel=0.10)


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["fvm", "regular"])
def test_finest_resolution_within_five_percent(kind):
    r = bc.footing(kind, 20)
    assert r["limit"] == pytest.approx(NC0, rel=0.05)
    assert r["limit"] > 0.97 * NC0


@pytest.mark.parametrize("kw,word", [({"models": ["hexagon"]}, "models"),
                                     ({"seeds": [1, 1]}, "seeds"),
                                     ({"seeds": []}, "seeds"),
                                     ({"seeds": [0.5]}, "seeds")])
def test_bad_models_and_seeds_are_named_before_anything_is_built(tmp_path, kw, word):
    import tdem
    out = tmp_path / "bc"
    with pytest.raises(tdem.InputError, match=word):
        bc.run("quick", out=out, **kw)
    assert not out.exists()
