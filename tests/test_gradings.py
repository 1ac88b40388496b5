"""Gradings (tdem.grading): sieve curves and closed forms sampled by mass, 2D and 3D."""
import math

import numpy as np
import pytest

import tdem
from tdem.gradings import passing_of

SIZES = [0.5e-3, 1e-3, 2e-3, 4e-3]
PASSING = [10.0, 35.0, 80.0, 100.0]


@pytest.mark.parametrize("dim", [2, 3])
def test_a_sampled_sieve_curve_matches_it_by_mass(dim):
    """20,000 particles drawn from a sieve curve pass every sieve within 2 % of its
    percentage by mass (mass ∝ d³ for spheres, d² for discs of equal thickness);
    by number the same sample is far finer (a check that mass, not number, is
    matched)."""
    g = tdem.grading(SIZES, PASSING)
    r = g.sample(20000, seed=1, dim=dim)
    got = passing_of(r, SIZES, dim=dim)
    assert got == pytest.approx(PASSING, abs=2.0)
    by_number = [100.0 * np.mean(2 * r <= s) for s in SIZES]
    assert by_number[0] > PASSING[0] + 20.0
    assert r.min() >= 0.5 * g.d_min and r.max() <= 0.5 * g.d_max


def test_the_curve_between_sieves_is_linear_in_log_size():
    """Between sieves the mass passing is linear in log d (the semi-log sieve plot):
    half-way in log between 1 and 2 mm passes half-way between 35 and 80 %; below the
    first sieve the mass runs down to sizes[0]²/sizes[1] (0.25 mm)."""
    g = tdem.grading(SIZES, PASSING)
    assert g.passing(math.sqrt(2) * 1e-3) == pytest.approx(57.5)
    assert g.d_min == pytest.approx(0.25e-3)
    assert g.passing(0.25e-3) == pytest.approx(0.0)
    assert g.d(57.5) == pytest.approx(math.sqrt(2) * 1e-3)
    r = g.sample(20000, seed=2, dim=3)
    assert passing_of(r, [math.sqrt(2) * 1e-3], dim=3)[0] == pytest.approx(57.5, abs=2.0)


def test_lognormal_mass_median_and_spread():
    """A mass lognormal of d50 = 1 mm, σ = 0.4: the sample's mass median within 2 % of
    1 mm, and 84.1 % of the mass below d50·e^σ (one σ; cut at 3σ: the curve is
    renormalised over 99.73 % of the mass) within 2 % passing."""
    g = tdem.grading.lognormal(d50=1e-3, sigma=0.4)
    assert g.d(50) == pytest.approx(1e-3, rel=1e-3)
    r = g.sample(20000, seed=3, dim=3)
    d = np.sort(2 * r)
    m = np.cumsum(d ** 3) / np.sum(d ** 3)
    assert d[np.searchsorted(m, 0.5)] == pytest.approx(1e-3, rel=0.02)
    expect = (0.8413 - 0.00135) / (1 - 0.0027) * 100
    assert passing_of(r, [1e-3 * math.exp(0.4)], dim=3)[0] == pytest.approx(expect, abs=2.0)


def test_rosin_rammler_passes_63_percent_at_d63():
    """1 − 1/e of the mass passes d63 (renormalised over 0.1–99.9 %), within 2 % for
    100,000 discs: a wide grading, whose mass sits in few large particles."""
    g = tdem.grading.rosin_rammler(d63=2e-3, n=2.0)
    r = g.sample(100000, seed=4, dim=2)
    expect = (1 - math.exp(-1) - 0.001) / 0.998 * 100
    assert passing_of(r, [2e-3], dim=2)[0] == pytest.approx(expect, abs=2.0)


def test_uniform_by_number_is_what_the_packers_drew():
    """grading.uniform(dmin, dmax) draws diameters uniform by number: mean diameter
    (dmin + dmax)/2 within 1 %, and the fraction below the midpoint 1/2 within 0.02."""
    g = tdem.grading.uniform(1e-3, 3e-3, dim=2)
    d = 2 * g.sample(20000, seed=5, dim=2)
    assert d.mean() == pytest.approx(2e-3, rel=0.01)
    assert np.mean(d < 2e-3) == pytest.approx(0.5, abs=0.02)


def test_packers_draw_from_a_grading():
    """pack.random and pack.random3d with a grading: radii within its range, and the
    packing's sieve curve by mass within 5 % passing of the grading's (a packing of
    a few hundred particles is a small sample of the curve)."""
    g = tdem.grading([2e-3, 3e-3, 4e-3], [0.0, 50.0, 100.0])
    x, r = tdem.pack.random(0.1, 0.1, None, None, grading=g, seed=0, target_fraction=0.75)
    assert 2 * r.min() >= 2e-3 - 1e-12 and 2 * r.max() <= 4e-3 + 1e-12
    assert passing_of(r, [3e-3], dim=2)[0] == pytest.approx(50.0, abs=5.0)
    x3, r3 = tdem.pack.random3d((0, 0, 0), (0.03, 0.03, 0.03), None, None, grading=g,
                                seed=0, target_fraction=0.4)
    assert passing_of(r3, [3e-3], dim=3)[0] == pytest.approx(50.0, abs=8.0)


@pytest.mark.parametrize("args,word", [
    (([1e-3, 0.5e-3], [50, 100]), "increasing"),
    (([1e-3, 2e-3], [60, 50]), "non-decreasing"),
    (([1e-3, 2e-3], [50, 90]), "end at 100"),
    (([1e-3], [100]), "at least 2"),
    (([1e-3, 2e-3], [10, 100], 2e-3), "dmin"),
])
def test_bad_sieve_curves_are_named(args, word):
    with pytest.raises(tdem.InputError, match=word):
        tdem.grading(*args)


def test_bad_sampling_arguments_are_named():
    g = tdem.grading([1e-3, 2e-3], [0, 100])
    with pytest.raises(tdem.InputError, match="dim"):
        g.sample(10, dim=4)
    with pytest.raises(tdem.InputError, match="n must"):
        g.sample(-1)
    with pytest.raises(tdem.InputError, match="sigma"):
        tdem.grading.lognormal(1e-3, 0.0)
    with pytest.raises(tdem.InputError, match="grading"):
        tdem.pack.random(0.1, 0.1, None, None)
