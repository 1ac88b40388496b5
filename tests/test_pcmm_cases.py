"""The PCMM precision cases (Feng, Li & Oñate 2015 §3) against their targets.

The default run checks the FVM block model and the regular and hexagonal ("cross")
PCMM lattices; the random packings (slower to build and to run) are in the slow
tests. Targets and tolerances are those of the case docstrings (CASES.md).
"""
import math

import pytest

from cases import uniaxial_compression, wave_bar


@pytest.fixture(scope="module")
def wave(tmp_path_factory):
    return wave_bar.run("quick", out=tmp_path_factory.mktemp("wave"),
                        models=["fvm", "regular", "cross"])


@pytest.mark.parametrize("model", ["fvm", "regular", "cross"])
def test_wave_bar_arrival_peak_velocity_and_stress(wave, model):
    m = wave["models"][model]
    # arrival at x = 10 m within 5 % of 10 m / c (c = sqrt(E/(rho (1 - nu^2))))
    assert m["arrival_rel_error"] <= 0.05
    # peak velocity within 10 % of the 10 m/s drive, peak stress within 10 % of rho c v
    assert abs(m["peak_velocity"]["value"] - 10.0) <= 1.0
    target = m["peak_stress"]["target"]
    assert target == pytest.approx(2500.0 * math.sqrt(30e9 / (2500.0 * (1 - 0.25 ** 2))) * 10.0)
    assert abs(m["peak_stress"]["value"] - target) <= 0.1 * target


@pytest.fixture(scope="module")
def uniaxial(tmp_path_factory):
    return uniaxial_compression.run("quick", out=tmp_path_factory.mktemp("uc"),
                                    models=["fvm", "fvm_cross", "regular", "cross"])


def test_uniaxial_elastic_slopes_agree_and_peaks_reach_the_mohr_coulomb_strength(uniaxial):
    slopes = [m["elastic_slope"]["value"] for m in uniaxial["models"].values()]
    mean = sum(slopes) / len(slopes)
    assert (max(slopes) - min(slopes)) / mean <= 0.10
    # plane-strain uniaxial modulus E / (1 - nu^2) = 32 GPa
    assert mean == pytest.approx(32e9, rel=0.05)
    strength = 2 * 3e6 * math.cos(math.radians(40)) / (1 - math.sin(math.radians(40)))
    for m in uniaxial["models"].values():
        assert abs(m["peak_stress"]["value"] - strength) <= 0.25 * strength


@pytest.mark.slow
def test_uniaxial_all_five_models(tmp_path):
    s = uniaxial_compression.run("quick", out=tmp_path)
    assert s["elastic_slope_pass"]
    assert all(m["peak_stress_pass"] for m in s["models"].values())


@pytest.mark.slow
@pytest.mark.xfail(reason="the random PCMM packing carries the wave about 20 % slow and at "
                          "less than half the stress (a known gap)", strict=False)
def test_wave_bar_random_model(tmp_path):
    s = wave_bar.run("quick", out=tmp_path, models=["random"])
    m = s["models"]["random"]
    assert m["peak_velocity_pass"]
    assert m["arrival_pass"] and m["peak_stress_pass"]
