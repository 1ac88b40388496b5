"""wet_column: the cohesive estimate's arithmetic, and (slow) the quick preset: a wet
column stands where a dry one slumps."""
import math

import pytest

from cases import wet_column as wc


def test_the_estimate():
    """Rumpf's σ_t = (1 − n)/π · k · 2πRγ/d² and Terzaghi's H_c = 4c/(ρ_b g)
    tan(45° + φ/2), c = σ_t tan φ, worked by hand for n = 0.5, k = 6."""
    sigma_t, c, h_c = wc.estimate(0.5, 6.0)
    f = 2 * math.pi * 1e-3 * 0.072
    assert sigma_t == pytest.approx(0.5 / math.pi * 6 * f / 4e-6, rel=1e-12)
    assert c == pytest.approx(sigma_t * math.tan(math.radians(25)), rel=1e-12)
    assert h_c == pytest.approx(4 * c / (1250 * 9.81) * math.tan(math.radians(57.5)),
                                rel=1e-12)


@pytest.mark.slow
def test_quick_preset(tmp_path):
    s = wc.main(["--preset", "quick", "--out", str(tmp_path)])
    assert s["pass"] is True
