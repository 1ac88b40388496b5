"""Packings (tdem.pack): lattice counts and spacing, random packing density,
overlaps, determinism and input errors.

The paper's precision tests (Feng, Li & Oñate 2015, §3) use a 20 × 20 m square:
regular R = 0.5 m (400 particles: reproduced), cross R = √3/3 m (paper: 389; a
hexagonal lattice of touching discs inside the square holds 314, 368 with centres
on the edges), random R = 0.168–0.312 m (paper: 1966, which would cover 92 % of
the square with radii uniform in that range, more than a random packing of discs
can; at the packing fraction 0.8 the square holds about 1710).
"""
import math
import time
import warnings

import numpy as np
import pytest

import tdem
from tdem import pack


def _min_gap(x, r):
    """Smallest d_ij − R_i − R_j over all pairs (negative: overlap)."""
    d = np.linalg.norm(x[:, None] - x[None], axis=2) - r[:, None] - r[None]
    np.fill_diagonal(d, np.inf)
    return d.min()


def test_regular_lattice():
    x, r = pack.regular(20.0, 20.0, 0.5)
    assert len(x) == 400 and np.all(r == 0.5)
    assert x.min() == pytest.approx(0.5) and x.max() == pytest.approx(19.5)
    assert _min_gap(x, r) == pytest.approx(0.0, abs=1e-12)       # touching, spacing 2R
    d = np.linalg.norm(x[:, None] - x[None], axis=2)
    touching = np.sum(np.abs(d - 1.0) < 1e-9, axis=1)
    assert touching.max() == 4 and np.sum(touching == 4) == 18 * 18
    # the paper's 100 × 200 mm specimen, centres on the edges: 21 × 41 = 861 particles
    x2, _ = pack.regular(0.1, 0.2, 0.0025, inset=0.0)
    assert len(x2) == 861
    x3, _ = pack.regular(20.0, 20.0, 0.5, origin=(-3.0, 7.0))
    np.testing.assert_allclose(x3, x + [-3.0, 7.0])


def test_cross_lattice():
    R = math.sqrt(3.0) / 3.0
    x, r = pack.cross(20.0, 20.0, R)
    assert len(x) == 314                                          # paper: 389
    assert np.all(x >= R - 1e-12) and np.all(x <= 20.0 - R + 1e-12)
    assert _min_gap(x, r) == pytest.approx(0.0, abs=1e-12)
    d = np.linalg.norm(x[:, None] - x[None], axis=2)
    np.fill_diagonal(d, np.inf)
    touching = np.abs(d - 2 * R) < 1e-9
    assert touching.sum(axis=1).max() == 6
    # an interior disc sees its six neighbours at 60 degree intervals
    i = int(np.argmin(np.linalg.norm(x - 10.0, axis=1)))
    v = x[touching[i]] - x[i]
    ang = np.sort(np.degrees(np.arctan2(v[:, 1], v[:, 0])))
    np.testing.assert_allclose(np.diff(ang), 60.0, atol=1e-9)
    assert len(pack.cross(20.0, 20.0, R, inset=0.0)[0]) == 368
    # the paper's 100 × 200 mm specimen, centres on the edges: 964 particles
    assert len(pack.cross(0.1, 0.2, 0.0025, inset=0.0)[0]) == 964


def test_random_paper_packing():
    """R = 0.168–0.312 m in 20 × 20 m at the default fraction 0.8."""
    t0 = time.perf_counter()
    x, r = pack.random(20.0, 20.0, 0.168, 0.312, seed=0)
    elapsed = time.perf_counter() - t0
    assert elapsed < 30.0
    fraction = np.sum(np.pi * r ** 2) / 400.0
    assert 0.800 <= fraction <= 0.801
    assert 1680 <= len(x) <= 1740
    assert r.min() >= 0.168 and r.max() <= 0.312
    assert _min_gap(x, r) > -1e-3 * 0.168                          # overlaps below tolerance
    assert np.all(x - r[:, None] > -1e-3 * 0.168)                 # inside the square
    assert np.all(x + r[:, None] < 20.0 + 1e-3 * 0.168)
    # radii uniform in [rmin, rmax]: mean and spread of a uniform law
    assert r.mean() == pytest.approx(0.24, abs=0.005)
    assert r.std() == pytest.approx(0.144 / math.sqrt(12.0), rel=0.05)


def test_random_above_jamming_overlaps_by_at_most_overlap_tol():
    """0.89 of the area (the count of the paper's random model) with overlaps of at
    most overlap_tol x rmin: the disc area, and every pair's overlap, checked."""
    rmin, rmax, tol = 0.168, 0.312, 0.7
    x, r = pack.random(8.0, 8.0, rmin, rmax, seed=2, target_fraction=0.89,
                       overlap_tol=tol)
    assert np.sum(np.pi * r * r) / 64.0 == pytest.approx(0.89, abs=0.01)
    d = np.linalg.norm(x[:, None] - x[None], axis=2)
    ov = (r[:, None] + r[None] - d)[np.triu_indices(len(r), 1)]
    assert ov.max() <= tol * rmin * (1 + 1e-9)
    assert ov.max() >= 0.1 * rmin           # denser than jamming: they do overlap
    assert np.all(x - r[:, None] >= -tol * rmin * (1 + 1e-9))
    assert np.all(x + r[:, None] <= 8.0 + tol * rmin * (1 + 1e-9))


def test_random_is_deterministic_for_a_seed():
    a = pack.random(4.0, 3.0, 0.1, 0.2, seed=3, target_fraction=0.75)
    b = pack.random(4.0, 3.0, 0.1, 0.2, seed=3, target_fraction=0.75)
    c = pack.random(4.0, 3.0, 0.1, 0.2, seed=4, target_fraction=0.75)
    np.testing.assert_array_equal(a[0], b[0])
    np.testing.assert_array_equal(a[1], b[1])
    assert len(a[1]) != len(c[1]) or not np.array_equal(a[0], c[0])


def test_random_lists_discs_in_rows():
    """Rows one mean diameter high, bottom to top, x increasing along a row; so
    touching discs lie close in the arrays: the median index distance of touching
    pairs is below the discs of one row (about 2·20/(2·0.24) = 83 here), where the
    order of the relaxation would put it near N/3 = 570."""
    x, r = pack.random(20.0, 20.0, 0.168, 0.312, seed=0)
    row = np.floor((x[:, 1] - x[:, 1].min()) / (2.0 * r.mean()))
    assert np.all(np.diff(row) >= 0)
    same = np.diff(row) == 0
    assert np.all(np.diff(x[:, 0])[same] > 0)
    d = np.linalg.norm(x[:, None] - x[None], axis=2) - r[:, None] - r[None]
    i, j = np.nonzero(np.triu(d < 1e-3 * 0.168, 1))
    assert len(i) > len(x)
    assert np.median(j - i) < 83


def test_random_in_a_polygon():
    """An L-shaped region (area 6 m², a re-entrant corner), given clockwise."""
    poly = np.array([[0, 0], [0, 3], [1, 3], [1, 1], [4, 1], [4, 0]], dtype=float)
    x, r = pack.random(None, None, 0.05, 0.1, seed=1, target_fraction=0.75, polygon=poly)
    assert np.sum(np.pi * r ** 2) / 6.0 == pytest.approx(0.75, abs=0.005)
    tol = 1e-3 * 0.05
    assert _min_gap(x, r) > -tol
    # every disc inside the L: inside its bounding box and clear of the notch x > 1, y > 1
    assert np.all(x - r[:, None] > -tol)
    assert np.all(x[:, 0] + r < 4.0 + tol) and np.all(x[:, 1] + r < 3.0 + tol)
    gx, gy = 1.0 - x[:, 0], 1.0 - x[:, 1]
    to_notch = np.where((gx >= 0) & (gy >= 0), np.hypot(gx, gy), np.maximum(gx, gy))
    assert np.all(to_notch > r - tol)


@pytest.mark.parametrize("call, word", [
    (lambda: pack.regular(-1.0, 20.0, 0.5), "width"),
    (lambda: pack.regular(20.0, 0.0, 0.5), "height"),
    (lambda: pack.regular(20.0, 20.0, 0.0), "radius"),
    (lambda: pack.cross(20.0, 20.0, float("nan")), "radius"),
    (lambda: pack.cross(0.5, 20.0, 0.5), "width"),
    (lambda: pack.regular(20.0, 20.0, 0.5, inset=-1.0), "inset"),
    (lambda: pack.regular(20.0, 20.0, 0.5, origin=(0.0,)), "origin"),
    (lambda: pack.random(20.0, 20.0, 0.3, 0.2), "rmax"),
    (lambda: pack.random(20.0, 20.0, -0.1, 0.2), "rmin"),
    (lambda: pack.random(20.0, 20.0, 0.1, 0.2, target_fraction=0.96), "target_fraction"),
    (lambda: pack.random(0.3, 20.0, 0.1, 0.2), "rmax"),
    (lambda: pack.random(None, None, 0.1, 0.2, polygon=[[0, 0], [1, 1]]), "polygon"),
    (lambda: pack.random(20.0, 20.0, 0.1, 0.2, polygon=[[0, 0], [9, 0], [0, 9]]), "polygon"),
    (lambda: pack.random(None, 20.0, 0.1, 0.2), "width"),
])
def test_bad_input_names_the_argument(call, word):
    with pytest.raises(tdem.InputError, match=word):
        call()


def test_unreachable_fraction_raises():
    with pytest.raises(tdem.InputError, match="target_fraction"):
        pack.random(1.0, 1.0, 0.1, 0.12, target_fraction=0.85, max_iter=300)


def test_cross_fit_puts_the_rows_on_the_edges():
    """fit=True: the paper's 389-particle cross model of the 20 x 20 m square."""
    R = math.sqrt(3.0) / 3.0
    x, r = pack.cross(20.0, 20.0, R, inset=0.0, fit=True)
    assert len(x) == 389 and np.all(r == R)                     # 11 x 19 + 10 x 18
    assert x.min(axis=0) == pytest.approx([0.0, 0.0], abs=1e-12)
    assert x.max(axis=0) == pytest.approx([20.0, 20.0])
    np.testing.assert_allclose(np.unique(np.round(x[:, 1], 9)), np.arange(21.0), atol=1e-9)
    d = np.linalg.norm(x[:, None] - x[None], axis=2)
    np.fill_diagonal(d, np.inf)
    nearest = d.min(axis=1)
    assert nearest.max() <= 2 * R and nearest.min() == pytest.approx(20.0 / 18.0)
    # the default lattice is unchanged
    assert len(pack.cross(20.0, 20.0, R, inset=0.0)[0]) == 368


def test_random_edge_centres():
    W = H = 20.0
    x, r = pack.random(W, H, 0.336, 0.624, seed=0, edge_centres=True)
    on = (np.isclose(x[:, 0], 0.0) | np.isclose(x[:, 0], W)
          | np.isclose(x[:, 1], 0.0) | np.isclose(x[:, 1], H))
    nb = int(on.sum())
    assert nb > 0 and np.all(on[:nb]) and not on[nb:].any()    # boundary discs first
    for corner in ([0, 0], [W, 0], [W, H], [0, H]):
        assert np.any(np.all(np.isclose(x, corner), axis=1))
    assert np.all((r >= 0.336) & (r <= 0.624))
    # free discs inside, no overlap beyond the tolerance; boundary discs spread with
    # gaps below 2 rmax / (their number on an edge)
    assert np.all((x[nb:] - r[nb:, None] >= -1e-3 * 0.336) &
                  (x[nb:] + r[nb:, None] <= W + 1e-3 * 0.336))
    assert _min_gap(x, r) >= -1e-3 * 0.336
    d = np.linalg.norm(x[:nb, None] - x[None, :nb], axis=2) - r[:nb, None] - r[None, :nb]
    np.fill_diagonal(d, np.inf)
    assert d.min(axis=1).max() <= 0.1
    inside = np.sum(np.pi * r[nb:] ** 2) + 0.5 * np.pi * np.sum(r[:nb] ** 2)
    assert inside / (W * H) == pytest.approx(0.8, abs=0.02)
    x2, r2 = pack.random(W, H, 0.336, 0.624, seed=0, edge_centres=True)
    np.testing.assert_array_equal(x, x2)


def test_random_edge_radius_makes_the_sides_flush():
    """edge_radius: every boundary disc of that one radius, so the top row's tops lie
    on one line (drawn radii leave a relief up to rmax − rmin), the inner discs still
    drawn from the range, the boundary's discs touching or nearly (as with drawn radii);
    without edge_centres it is refused, naming it."""
    W, H, rm = 20.0, 10.0, 0.48
    x, r = pack.random(W, H, 0.336, 0.624, seed=3, edge_centres=True, edge_radius=rm)
    on = (np.isclose(x[:, 0], 0.0) | np.isclose(x[:, 0], W)
          | np.isclose(x[:, 1], 0.0) | np.isclose(x[:, 1], H))
    nb = int(on.sum())
    assert nb > 0 and np.all(on[:nb]) and np.all(r[:nb] == rm)
    top = np.isclose(x[:nb, 1], H)
    assert np.ptp(x[:nb][top, 1] + r[:nb][top]) == 0.0
    assert np.all((r[nb:] >= 0.336) & (r[nb:] <= 0.624)) and np.ptp(r[nb:]) > 0.2
    d = np.diff(np.sort(x[:nb][top, 0]))
    assert d.max() <= 2 * rm + 2 * rm / top.sum() + 1e-12 and d.min() >= 2 * rm - 1e-12
    assert _min_gap(x, r) >= -1e-3 * 0.336
    _, r_drawn = pack.random(W, H, 0.336, 0.624, seed=3, edge_centres=True)
    assert np.ptp(r_drawn[:nb]) > 0.2
    with pytest.raises(tdem.InputError, match="edge_radius"):
        pack.random(W, H, 0.336, 0.624, edge_radius=rm)
    with pytest.raises(tdem.InputError, match="edge_radius"):
        pack.random(W, H, 0.336, 0.624, edge_centres=True, edge_radius=-1.0)


def _element_union(x, r, tol):
    from test_pcmm_elements import union_area
    from physics.pcmm import ElementSystem
    return union_area(x, ElementSystem(x, r, tol).build().numpy()["triangles"], h=0.01)


def test_fill_holes_puts_a_missing_lattice_disc_back():
    """A square lattice (R = 0.5, δ = R) with one disc taken out has a diamond-shaped
    hole in its element cover around the missing centre, clearance R there: one
    disc of radius R goes back exactly there and the cover is whole again."""
    x, r = pack.regular(10.0, 10.0, 0.5)
    k = int(np.argmin(np.hypot(x[:, 0] - 5.5, x[:, 1] - 5.5)))
    full = _element_union(x, r, 0.5)
    assert full == pytest.approx(81.0, rel=1e-4)                 # 9 x 9 m of centres
    xs, rs = np.delete(x, k, axis=0), np.delete(r, k)
    assert _element_union(xs, rs, 0.5) == pytest.approx(81.0 - 2.0, rel=1e-3)
    x2, r2 = pack.fill_holes(xs, rs, 0.5, 0.5, 0.5, 10.0, 10.0)
    assert len(x2) == len(x)
    np.testing.assert_array_equal(x2[:-1], xs)                   # the others stay
    np.testing.assert_allclose(x2[-1], [5.5, 5.5], atol=1e-12)
    assert r2[-1] == 0.5
    assert _element_union(x2, r2, 0.5) == pytest.approx(full, rel=1e-9)


def test_random_pcmm_tolerance_closes_the_element_cover():
    """The paper's random model (R = 0.168-0.312 m, δ = 0.3 m, 20 x 20 m, 0.89 with
    overlaps up to 0.7 rmin, centres on the edges; seed 0): its element cover has
    holes over 1.2 % of the square; with pcmm_tolerance=0.3 a few discs (11) go into
    them, the cover reaches 99.95 %, and the packing keeps its radius range, overlap
    bound and region."""
    rmin, rmax, tol = 0.168, 0.312, 0.7
    kw = dict(seed=0, target_fraction=0.89, overlap_tol=tol, edge_centres=True)
    x0, r0 = pack.random(20.0, 20.0, rmin, rmax, **kw)
    x, r = pack.random(20.0, 20.0, rmin, rmax, pcmm_tolerance=0.3, **kw)
    assert _element_union(x0, r0, 0.3) < 0.99 * 400.0
    assert _element_union(x, r, 0.3) >= 0.9995 * 400.0
    assert 1 <= len(r) - len(r0) <= 0.01 * len(r0)
    assert np.all((r >= rmin) & (r <= rmax))
    d = np.linalg.norm(x[:, None] - x[None], axis=2)
    ov = (r[:, None] + r[None] - d)[np.triu_indices(len(r), 1)]
    assert ov.max() <= tol * rmin * (1 + 1e-9)
    assert np.all((x >= -1e-12) & (x <= 20.0 + 1e-12))
    # the added discs lie inside the square
    old = {tuple(p) for p in np.round(x0, 12)}
    added = np.array([p for p in np.round(x, 12) if tuple(p) not in old])
    ra = r[[tuple(p) not in old for p in np.round(x, 12)]]
    assert len(added) == len(r) - len(r0)
    assert np.all((added - ra[:, None] >= 0.0) & (added + ra[:, None] <= 20.0))


@pytest.mark.parametrize("call, word", [
    (lambda: pack.fill_holes([[0.0, 0.0, 0.0]], 0.1, 0.1, 0.1, 0.2, 1.0, 1.0), "positions"),
    (lambda: pack.fill_holes([[0.5, 0.5]], [0.1, 0.1], 0.1, 0.1, 0.2, 1.0, 1.0), "radii"),
    (lambda: pack.fill_holes([[0.5, 0.5]], 0.1, -0.1, 0.1, 0.2, 1.0, 1.0), "tolerance"),
    (lambda: pack.fill_holes([[0.5, 0.5]], 0.1, 0.1, 0.3, 0.2, 1.0, 1.0), "rmax"),
    (lambda: pack.random(2.0, 2.0, 0.1, 0.2, pcmm_tolerance=float("nan")), "pcmm_tolerance"),
    (lambda: pack.fill_holes([[0.5, 0.5]], 0.1, 0.1, 0.1, 0.2, 1.0, 1.0, rounds=0), "rounds"),
])
def test_fill_holes_bad_input_names_the_argument(call, word):
    with pytest.raises(tdem.InputError, match=word):
        call()


def test_fill_holes_leaves_the_border_strip_unless_asked():
    """Without discs centred on the boundary the element cover stops at the
    outermost centres, about a radius inside: that strip is no hole (default), and
    ``border=True`` fills it too (a slice of the wave_bar's random packing)."""
    rmin, rmax, delta = 0.0139, 0.0423, 0.05
    x, r = pack.random(4.0, 0.6, rmin, rmax, seed=0, target_fraction=0.86, overlap_tol=0.7)
    xa, ra = pack.fill_holes(x, r, delta, rmin, rmax, 4.0, 0.6)
    xb, rb = pack.fill_holes(x, r, delta, rmin, rmax, 4.0, 0.6, border=True)
    na, nb = len(ra) - len(r), len(rb) - len(r)
    assert nb > 3 * na
    added = xb[len(r):]
    wall = np.minimum(np.minimum(added[:, 0], 4.0 - added[:, 0]),
                      np.minimum(added[:, 1], 0.6 - added[:, 1]))
    assert np.mean(wall < 2 * rmax) > 0.7              # most of them along the walls
    # the default fills holes inside the cover: the cover grows, the border stays
    assert _element_union(xa, ra, delta) >= _element_union(x, r, delta)


def test_fill_holes_in_a_polygon():
    """The L-shaped region of test_random_in_a_polygon at 0.75 (its voids leave
    holes in the element cover of δ = 0.05): the filled packing covers more of it,
    every added disc lies inside the L and overlaps no disc by more than
    overlap_tol x rmin."""
    poly = np.array([[0, 0], [0, 3], [1, 3], [1, 1], [4, 1], [4, 0]], dtype=float)
    rmin, rmax, delta, tol = 0.05, 0.1, 0.05, 0.5
    x, r = pack.random(None, None, rmin, rmax, seed=1, target_fraction=0.75, polygon=poly)
    x2, r2 = pack.fill_holes(x, r, delta, rmin, rmax, polygon=poly, overlap_tol=tol)
    added, ra = x2[len(x):], r2[len(x):]
    assert len(added) >= 5
    np.testing.assert_array_equal(x2[:len(x)], x)
    assert np.all((ra >= rmin) & (ra <= rmax))
    assert _element_union(x2, r2, delta) > _element_union(x, r, delta) + 0.05
    d = np.linalg.norm(added[:, None] - x2[None], axis=2) - ra[:, None] - r2[None]
    d[np.arange(len(added)), len(x) + np.arange(len(added))] = np.inf
    assert d.min() >= -tol * rmin * (1 + 1e-9)
    assert np.all(added - ra[:, None] >= -1e-12)
    assert np.all(added[:, 0] + ra <= 4.0 + 1e-12) and np.all(added[:, 1] + ra <= 3.0 + 1e-12)
    gx, gy = 1.0 - added[:, 0], 1.0 - added[:, 1]
    to_notch = np.where((gx >= 0) & (gy >= 0), np.hypot(gx, gy), np.maximum(gx, gy))
    assert np.all(to_notch >= ra - 1e-12)


def test_random3d_packs_spheres_in_a_box_to_the_fraction_asked():
    """Spheres of radii in [4, 6] mm in a 0.1 m cube at 0.5: the volume fraction
    reached within one sphere of the target, every sphere inside the box and no two
    overlapping by more than overlap_tol × rmin, listed from the bottom up, the same
    for the same seed; a 3D simulation takes it without an overlap warning."""
    from scipy.spatial import cKDTree
    lo, hi, rmin, rmax = np.zeros(3), np.full(3, 0.1), 0.004, 0.006
    x, r = pack.random3d(lo, hi, rmin, rmax, seed=1, target_fraction=0.5)
    vol = 4.0 / 3.0 * np.pi * r ** 3
    assert 0.5 * 1e-3 <= vol.sum() <= 0.5 * 1e-3 + vol.max()
    assert r.min() >= rmin and r.max() <= rmax
    tol = 1e-3 * rmin
    assert np.all(x - r[:, None] >= lo - tol) and np.all(x + r[:, None] <= hi + tol)
    i, j = cKDTree(x).query_pairs(2 * rmax, output_type="ndarray").T
    gap = np.linalg.norm(x[i] - x[j], axis=1) - r[i] - r[j]
    assert gap.min() >= -tol
    assert np.all(np.diff(x[:, 2]) >= 0)
    x2, r2 = pack.random3d(lo, hi, rmin, rmax, seed=1, target_fraction=0.5)
    np.testing.assert_array_equal(x, x2)
    np.testing.assert_array_equal(r, r2)
    sim = tdem.Simulation(dim=3, progress=False)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sim.add_particles(x, r, density=2500.0,
                          contact=tdem.HertzMindlin(young=1e7, poisson=0.3))
    assert sim.n_particles == len(r)


def test_random3d_input_is_checked():
    with pytest.raises(tdem.InputError, match="target_fraction must lie in"):
        pack.random3d((0, 0, 0), (0.1, 0.1, 0.1), 0.004, 0.006, target_fraction=0.7)
    with pytest.raises(tdem.InputError, match="at least 2 rmax"):
        pack.random3d((0, 0, 0), (0.1, 0.1, 0.01), 0.004, 0.006)
    with pytest.raises(tdem.InputError, match="could not be reached"):
        pack.random3d((0, 0, 0), (0.05, 0.05, 0.05), 0.004, 0.006, target_fraction=0.6,
                      max_iter=300)
