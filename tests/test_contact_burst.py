"""contact_burst (Feng et al. §4.2): a TNT disc on soft rock. The quick preset's
first millisecond (the blast wave's passage below the charge and along the
surface) against the paper's Figs. 23-24; the whole 3.6 ms in the slow test."""
import numpy as np
import pytest

from cases import _common as common
from cases import contact_burst


@pytest.fixture(scope="module")
def first_ms(tmp_path_factory):
    return contact_burst.run("quick", out=tmp_path_factory.mktemp("burst"), duration=1.0e-3)


def test_pressure_decays_with_depth_as_in_the_paper(first_ms):
    """P4-P6 (0.3, 0.5, 0.7 m below the charge): the peaks fall with depth; the
    ratios P5/P4 and P6/P4 within 10 % of the paper's 0.681 and 0.511 (the paper's
    monitor positions are not given, so the values are compared as ratios)."""
    pk = first_ms["data"]["peak_pressure_Pa"]
    assert pk["P4"] > pk["P5"] > pk["P6"] > 0.0
    checks = common.checks_by_name(first_ms)
    for k in ("P5/P4", "P6/P4"):
        f = checks[f"{k}_peak_ratio"]
        assert f["value"] == pytest.approx(f["target"], rel=0.10), k
        assert f["pass"] is True
    assert checks["P5/P4_peak_ratio"]["target"] == pytest.approx(931.8 / 1369)


def test_p1_starts_moving_with_the_p_wave(first_ms):
    """P1 (x = 4.8 m) starts to move (|u_x| > 1 % of its maximum in the first
    millisecond) when a P-wave from the loaded surface arrives: after the one from
    the charge's edge (0.17 m out from its centre: 0.203 ms) and before the one from
    its contact point (0.258 ms), 5 % slack each way (measured 0.228 ms at the quick
    preset, 0.216 ms at the paper's: the expanding products load the surface out to
    the charge's edge). The paper's 0.46 ms is nearer the Rayleigh wave's 0.49 ms."""
    c = common.checks_by_name(first_ms)["P1_first_motion_vs_p_wave"]
    start = c["value"]
    assert start == first_ms["data"]["P1_first_motion_s"]
    p_wave = first_ms["data"]["P1_arrivals_s"]["p_wave"]
    edge = p_wave * (0.8 - 0.17) / 0.8
    assert c["tolerance"]["min"] == pytest.approx(0.95 * edge, rel=0.02)
    assert c["tolerance"]["max"] == pytest.approx(1.05 * p_wave, rel=1e-9)
    assert 0.95 * edge <= start <= 1.05 * p_wave
    assert c["pass"] is True


def test_linear_rise_start_is_the_foot_of_the_rise():
    """The start of a linear rise (the paper's reading of P1) on a synthetic record:
    at rest, a slow precursor (1 % of the peak), then a linear rise from 0.46 ms to a
    peak at 0.8 ms: the foot of the rise is found within 1 % of 0.46 ms, and the 1 %
    threshold (first motion) is earlier, in the precursor."""
    t = np.linspace(0.0, 1.0e-3, 2001)
    u = np.where(t > 0.2e-3, 0.01 * (t - 0.2e-3) / 0.26e-3, 0.0)
    u = np.where(t > 0.46e-3, 0.01 + (t - 0.46e-3) / 0.34e-3, u)
    u = np.where(t > 0.8e-3, 1.01, u)
    start = contact_burst.linear_rise_start(t, -u)      # a leftward displacement
    assert start == pytest.approx(0.46e-3 - 0.01 * 0.34e-3, rel=1e-3)
    assert start == pytest.approx(0.46e-3, rel=0.01)
    assert contact_burst.linear_rise_start(t, 0.0 * t) is None


def test_crater_reported_not_compared_before_3_6_ms(first_ms):
    """The paper's crater is at 3.6 ms; a run of 1 ms reports its crater beside the
    paper's without comparing it (pass None), and the summary follows the schema."""
    assert common.validate(first_ms) == []
    c = common.checks_by_name(first_ms)
    for name, target in (("crater_width", 1.4), ("crater_depth", 0.35)):
        assert c[name]["target"] == pytest.approx(target)
        assert c[name]["tolerance"] is None and c[name]["pass"] is None


def test_charge_carries_the_papers_mass(first_ms):
    """The charge is its particles' elements (Eq. 5: mass ρ0 × their area, energy E0
    × it): the lattice's centres lie within the radius whose cover is nearest the
    paper's π·0.15² m², and the simulation's charge has that area (the cover's count
    of squares and half squares, exactly) within 2 % of the paper's; the particles
    inside the charge's outline (centres within 0.15 − r_e) covered 74 % of it."""
    area = first_ms["data"]["charge_initial_volume_m2"]
    r_e = contact_burst.PRESETS["quick"]["charge_particle"]
    cut = contact_burst.charge_cut(r_e)
    assert area == pytest.approx(contact_burst.lattice_cover(r_e, cut), rel=1e-9)
    assert area == pytest.approx(np.pi * 0.15 ** 2, rel=0.02)
    assert first_ms["data"]["particles"]["charge"] == 197
    assert contact_burst.lattice_cover(r_e, 0.15 - r_e) == pytest.approx(0.052, rel=1e-9)


def test_lattice_cover_of_a_square_cluster():
    """The cover of a 3 × 3 block of lattice points (2 × 2 squares) is 4 squares;
    with a corner point removed, 3.5."""
    r_e = 0.01
    # a cut radius that takes the 3 × 3 block around the origin: distance sqrt(2)·2 r_e
    assert contact_burst.lattice_cover(r_e, 2 * r_e * 2 ** 0.5) == pytest.approx(16 * r_e ** 2)
    # the plus sign of 5 points: 4 squares with 3 corners each -> 4 half squares
    assert contact_burst.lattice_cover(r_e, 2 * r_e) == pytest.approx(8 * r_e ** 2)


def test_charge_products_expand_and_convert_energy(first_ms):
    """The swelling products (``tdem.JWL``) keep their elements as they expand and
    give up most of their energy in the first millisecond (measured 65 %, at
    relative volumes up to 108; without swelling their elements broke at V ≈ 1.4–2.5
    and 75 % of the energy was still inside at 3.6 ms)."""
    ch = first_ms["data"]["charge"]
    assert ch["max_relative_volume"] > 10.0
    assert 0.5 < 1.0 - ch["energy_left_fraction"] < 1.0


def _energy_bound(s):
    """Kinetic energy + energy dissipated so far ≤ the energy the charge gave up
    (the viscous boundaries only take energy away)."""
    e = s["data"]["energy_J_per_m"]
    converted = 7.0e9 * s["data"]["charge_initial_volume_m2"] - e["explosive"]
    assert converted > 0.0
    assert e["kinetic"] + e["dissipated"] <= 1.02 * converted


def test_no_energy_from_nowhere_in_the_first_millisecond(first_ms):
    """Failing rock near the surface loses its elements while compressed; the
    contact law then takes over without a force jump (before that fix the rock's
    kinetic energy grew past the charge's whole output by 1 ms)."""
    _energy_bound(first_ms)


@pytest.mark.slow
def test_whole_run_crater_and_energy(tmp_path):
    """3.6 ms: a crater wider than the charge; still no energy from nowhere. (The
    measured crater is compared with the paper's 1.4 m x 0.35 m in summary.json
    and docs/cases.md.) Its depth is not checked here: at the quick preset's 8 cm
    particles the surface under the charge sinks by less than a particle (measured
    0.03 m, 0.51 m wide; 0.12 m and 1.46 m before the equation of state's energy
    account was made consistent); the paper preset's crater is 0.26 m deep
    (docs/validation)."""
    s = contact_burst.run("quick", out=tmp_path)
    _energy_bound(s)
    c = common.checks_by_name(s)
    assert c["crater_width"]["value"] > 2 * contact_burst.CHARGE_RADIUS
    assert c["crater_depth"]["value"] > 0.0


def _synthetic_surface(width, depth, R=0.02, W=4.0, H=2.0, ejecta=True):
    """Discs on a square lattice filling the rock below y = H except a parabolic
    crater (width at the top, depth) at x = W/2, and a cloud of ejecta above the
    crater with a gap below it."""
    xs = np.arange(R, W, 2 * R)
    ys = np.arange(R, H, 2 * R)
    X, Y = np.meshgrid(xs, ys)
    x, y = X.ravel(), Y.ravel()
    u = 2 * (x - W / 2) / width
    surf = np.where(np.abs(u) < 1, H - depth * (1 - u * u), H)
    keep = y + R <= surf + 1e-9
    pts = np.column_stack([x[keep], y[keep]])
    if ejecta:
        # a stack of debris standing on the crater's floor at its centre, touching it
        floor = H - depth
        stack = np.column_stack([np.full(12, W / 2 + R), floor + R + 2 * R * np.arange(12)])
        pts = np.vstack([pts, stack])
        # and a crack one column wide, from the floor down to 0.5 m below it, beside it
        crack = (np.abs(pts[:, 0] - (W / 2 + 5 * R)) < R) & (pts[:, 1] > floor - 0.5) \
            & (pts[:, 1] < floor - 0.3)
        pts = pts[~crack]
        rng = np.random.default_rng(0)
        fly = np.column_stack([rng.uniform(W / 2 - width / 3, W / 2 + width / 3, 40),
                               rng.uniform(H + 0.2, H + 0.6, 40)])
        pts = np.vstack([pts, fly])
    return pts, np.full(len(pts), R)


@pytest.mark.parametrize("width,depth", [(1.4, 0.35), (0.8, 0.5), (2.2, 0.16)])
def test_crater_measure_on_a_synthetic_surface(width, depth):
    """A crater of known width at the top and depth, cut into a lattice of discs of
    R = 2 cm with ejecta flying above it, a stack of debris standing on its floor and
    a crack below the floor: the free-surface measure finds the depth
    within one diameter and the width within one diameter over the wall's slope (the
    surface is resolved to a diameter in height), the ejecta left out; an intact
    surface has no crater."""
    R = 0.02
    x, r = _synthetic_surface(width, depth, R)
    xs, top = contact_burst.surface_profile(x, r, 0.0, 4.0, 2 * R)
    w, d = contact_burst.crater_size(xs, top, 2.0, 2.0, R)
    # the measure's level is a radius below the surface: the parabola's width there;
    # the surface is known to a diameter in height, so the width to a diameter over
    # the crater wall's slope there
    u = (1 - R / depth) ** 0.5
    expect_w = width * u
    slope = 4 * depth * u / width
    assert w == pytest.approx(expect_w, abs=max(2 * R, 2 * R / slope))
    assert d == pytest.approx(depth, abs=2 * R)
    x, r = _synthetic_surface(width, depth, R, ejecta=False)
    x = x[x[:, 1] < 2.0 - 2 * depth]                # a flat rock, lower
    xs, top = contact_burst.surface_profile(x, r, 0.0, 4.0, 2 * R)
    assert contact_burst.crater_size(xs, top, top.max(), 2.0, R) == (0.0, 0.0)


def test_crater_edge_at_an_empty_column():
    """A column emptied to the bottom (every disc thrown out) at the crater's edge:
    the crossing is taken at the border of the empty column, not interpolated from
    −inf (which gave a NaN width). Flat surface at 2 m, columns of 4 cm, the crater
    0.4 m deep over x = 1.8–2.2 m, its left edge column empty."""
    xs = np.arange(0.02, 4.0, 0.04)
    top = np.full(len(xs), 2.0)
    inside = (xs > 1.8) & (xs < 2.2)
    top[inside] = 1.6
    top[np.flatnonzero(inside)[0]] = -np.inf
    w, d = contact_burst.crater_size(xs, top, 2.0, 2.0, 0.02)
    # left: the border of the empty column (1.80); right: between 2.18 (below)
    # and 2.22 (at 2.0), where the profile crosses 1.98: 2.18 + 0.04·0.38/0.4
    assert w == pytest.approx(2.218 - 1.80, abs=1e-9)
    assert d == pytest.approx(0.4, abs=1e-9)


def test_intact_surface_has_no_crater():
    R = 0.02
    x, r = _synthetic_surface(1.4, 0.35, R, ejecta=False)
    x = x[x[:, 1] < 2.0 - 2 * 0.35]                 # a flat rock, lower
    xs, top = contact_burst.surface_profile(x, r, 0.0, 4.0, 2 * R)
    assert contact_burst.crater_size(xs, top, top.max(), 2.0, R) == (0.0, 0.0)
