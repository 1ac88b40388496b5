"""PCMM element system (physics/pcmm/): creation rules, superposition, masses.

The paper's precision-test packings (Feng, Li & Oñate 2015, §3; 20 × 20 m):

| packing | δ (m) | particles (paper) | elements | Σ S_e/N_e ÷ union area |
| --- | --- | --- | --- | --- |
| regular R = 0.5 m | 0.5 | 400 (400) | 2888 (1444 triangles × 2) | 1.0000 |
| cross R = √3/3 m | 0.01 | 314 (389) | 1674 (558 triangles × 3) | 1.0000 |
| random R = 0.168–0.312 m | 0.3 | 1705 (1966) | 10265 (3963 triangles) | 0.9985 |
| the same at 89 %, overlapping, holes filled | 0.3 | 2006 (1966) | 12641 (5161 triangles) | 0.9992 |

The union area of the elements is measured independently of N_e: scan lines
0.005 m apart cut every triangle into an x-interval, the union of the intervals
of a line is exact, and the lengths are summed by the midpoint rule in y
(converged to 1e-5 relative on the random packing).
"""
import math

import numpy as np
import pytest

import tdem
from physics.pcmm import ElementSystem, check_rules
from tdem import pack

RHO = 2000.0


def union_area(x, triangles, h=0.005):
    """Area of the union of the triangles (scan lines h apart, midpoint rule in y)."""
    p = x[np.asarray(triangles)]                           # (E, 3, 2)
    ys = np.arange(p[..., 1].min() + 0.5 * h, p[..., 1].max(), h)
    k0 = np.searchsorted(ys, p[..., 1].min(axis=1), "left")
    k1 = np.searchsorted(ys, p[..., 1].max(axis=1), "right")
    cnt = np.maximum(k1 - k0, 0)
    e = np.repeat(np.arange(len(p)), cnt)
    line = np.repeat(k0, cnt) + np.arange(cnt.sum()) - np.repeat(np.cumsum(cnt) - cnt, cnt)
    y = ys[line][:, None]
    a = p[e]
    b = np.roll(a, -1, axis=1)
    crosses = (a[..., 1] <= y) != (b[..., 1] <= y)
    with np.errstate(divide="ignore", invalid="ignore"):
        xi = a[..., 0] + (y - a[..., 1]) * (b[..., 0] - a[..., 0]) / (b[..., 1] - a[..., 1])
    lo = np.where(crosses, xi, np.inf).min(axis=1)
    hi = np.where(crosses, xi, -np.inf).max(axis=1)
    keep = hi > lo
    # one long axis: line k occupies [k·L, k·L + L) so that the lines never mix
    offset = line[keep] * 3.0 * (np.ptp(x[:, 0]) + 1.0) - x[:, 0].min()
    s, t = lo[keep] + offset, hi[keep] + offset
    order = np.argsort(s, kind="stable")
    s, t = s[order], t[order]
    reach = np.concatenate([[-np.inf], np.maximum.accumulate(t)[:-1]])
    return float(np.sum(np.maximum(0.0, t - np.maximum(s, reach))) * h)


def deform(x, seed, shear=0.3, amplitude=0.4, wavelength=10.0):
    """A smooth random displacement field (six plane waves) plus a 30 % simple shear."""
    rng = np.random.default_rng(seed)
    y = x.copy()
    for _ in range(6):
        k = rng.normal(0.0, 2 * np.pi / wavelength, 2)
        phase = rng.uniform(0.0, 2 * np.pi)
        a = rng.normal(0.0, amplitude, 2)
        y += a[None, :] * np.sin(x @ k + phase)[:, None]
    y[:, 0] += shear * (x[:, 1] - x[:, 1].mean())
    return y


@pytest.fixture(scope="module")
def packings():
    return {
        "regular": (*pack.regular(20.0, 20.0, 0.5), 0.5),
        "cross": (*pack.cross(20.0, 20.0, math.sqrt(3.0) / 3.0), 0.01),
        "random": (*pack.random(20.0, 20.0, 0.168, 0.312, seed=0), 0.3),
        # the random model of the cases: the paper's count, overlapping, holes filled
        "dense": (*pack.random(20.0, 20.0, 0.168, 0.312, seed=0, target_fraction=0.89,
                               overlap_tol=0.7, edge_centres=True, pcmm_tolerance=0.3), 0.3),
    }


@pytest.fixture(scope="module")
def systems(packings):
    return {k: ElementSystem(x, r, tol).build() for k, (x, r, tol) in packings.items()}


# ------------------------------------------------------------ small clusters
def _polygon_cluster(k, side=1.0):
    """k particles on a regular k-gon, neighbours touching; δ reaches every pair."""
    ang = 2 * np.pi * np.arange(k) / k
    rc = side / (2 * np.sin(np.pi / k))
    x = rc * np.stack([np.cos(ang), np.sin(ang)], axis=1)
    diam = np.max(np.linalg.norm(x[:, None] - x[None], axis=2))
    area = 0.5 * k * rc * rc * np.sin(2 * np.pi / k)
    return x, 0.5 * side, diam - side + 1e-6, area


@pytest.mark.parametrize("k, n_elements", [(3, 3), (4, 8), (5, 15)])
def test_paper_clusters(k, n_elements):
    """Fig. 5: a cluster of k mutually touching particles is covered k times."""
    x, r, tol, area = _polygon_cluster(k)
    es = ElementSystem(x, r, tol).build()
    d = es.numpy()
    assert len(d["triangles"]) == n_elements
    assert np.all(d["n_cover"] == k)
    assert np.sum(d["area"] * d["weight"]) == pytest.approx(area, rel=1e-12)
    np.testing.assert_allclose(es.masses(RHO), RHO * area / k, rtol=1e-12)
    # each particle stores its own elements, counter-clockwise
    assert np.all(np.bincount(d["owner"]) == n_elements // k)
    assert check_rules(x, r, tol, d["triangles"])["ok"].all()


def test_isolated_particle_gets_its_disc_mass():
    x = np.array([[0.0, 0.0], [1.0, 0.0], [0.5, math.sqrt(3) / 2], [10.0, 0.0]])
    es = ElementSystem(x, 0.5, 0.01).build()
    m = es.masses(RHO)
    tri = 0.5 * math.sqrt(3) / 2
    np.testing.assert_allclose(m[:3], RHO * tri / 3, rtol=1e-12)
    assert m[3] == pytest.approx(RHO * math.pi * 0.25, rel=1e-12)


def test_pruning_drops_the_farther_neighbour():
    """Neighbours at 0°, 20° (farther) and 90°: the 20° one is dropped."""
    x = np.array([[0.0, 0.0], [1.0, 0.0], [1.2 * math.cos(math.radians(20)),
                                           1.2 * math.sin(math.radians(20))], [0.0, 1.0]])
    es = ElementSystem(x, 0.5, 0.45).build()
    nbr, ring = es.neighbours()
    assert list(nbr[0]) == [1, 2, 3]
    assert list(ring[0]) == [1, 3]
    assert [1, 3] in es.numpy()["triangles"][:, 1:].tolist()


# ------------------------------------------------------------ the paper's packings
def test_counts(packings, systems):
    n = {k: len(v[0]) for k, v in packings.items()}
    assert n["regular"] == 400                      # paper 400
    assert n["cross"] == 314                        # paper 389 (see tests/test_pack.py)
    assert 1680 <= n["random"] <= 1740              # paper 1966 (see tests/test_pack.py)
    e = {k: s.numpy() for k, s in systems.items()}
    # regular: each of the 19 × 19 squares holds its 4 triangles, each created twice
    assert len(e["regular"]["area"]) == 8 * 19 * 19
    assert np.all(e["regular"]["n_cover"] == 4)
    # cross: every equilateral triangle created by its three vertices
    distinct = {tuple(sorted(t)) for t in e["cross"]["triangles"].tolist()}
    assert len(e["cross"]["area"]) == 3 * len(distinct) == 1674
    assert np.all(e["cross"]["n_cover"] == 3)
    assert 5.5 * n["random"] < len(e["random"]["area"]) < 6.5 * n["random"]


@pytest.mark.parametrize("name", ["regular", "cross", "random", "dense"])
def test_superposition_and_masses(packings, systems, name):
    """Σ_e S_e/N_e = union area of the elements, Σ M_i = ρ × union area (2 %;
    measured 0.9985 on the random packing, 0.9992 on the dense one)."""
    x, r, tol = packings[name]
    d = systems[name].numpy()
    union = union_area(x, d["triangles"])
    ratio = np.sum(d["area"] * d["weight"]) / union
    assert ratio == pytest.approx(1.0, abs=0.02)
    if name in ("regular", "cross"):
        assert ratio == pytest.approx(1.0, abs=1e-12)
    m = systems[name].masses(RHO)
    assert np.sum(m) / (RHO * union) == pytest.approx(1.0, abs=0.02)
    assert np.all(m > 0)


@pytest.mark.parametrize("name", ["regular", "cross", "random", "dense"])
def test_rules_hold_before_and_after_large_deformation(packings, systems, name):
    x, r, tol = packings[name]
    d = systems[name].numpy()
    assert check_rules(x, r, tol, d["triangles"])["ok"].all()
    for seed in range(3):
        y = deform(x, seed)
        dd = ElementSystem(y, r, tol).build().numpy()
        assert len(dd["area"]) > 0
        res = check_rules(y, r, tol, dd["triangles"])
        assert res["ok"].all(), {k: int((~v).sum()) for k, v in res.items()}
        # the superposition stays close (measured 0.969–1.009 on these fields)
        ratio = np.sum(dd["area"] * dd["weight"]) / union_area(y, dd["triangles"])
        assert ratio == pytest.approx(1.0, abs=0.05)


# ------------------------------------------------------------ against a reference
def _reference_elements(x, r, tol):
    """The creation rules in plain numpy, particle by particle (each particle's
    elements in increasing order of the first neighbour, the kernels' slot order)."""
    d2 = np.sum((x[None, :, :] - x[:, None, :]) ** 2, axis=2)
    cut = r[:, None] + r[None, :] + tol
    nb = d2 <= cut * cut
    np.fill_diagonal(nb, False)
    out = []
    for a in range(len(x)):
        js = np.nonzero(nb[a])[0]
        v = x[js] - x[a]
        ang = np.arctan2(v[:, 1], v[:, 0])
        order = np.lexsort((js, ang))
        js, ang = list(js[order]), list(ang[order])
        while len(js) >= 2:
            gaps = np.diff(np.append(ang, ang[0] + 2 * np.pi))
            k = int(np.argmin(gaps))
            if gaps[k] >= np.pi / 6:
                break
            k1 = (k + 1) % len(js)
            qa, qb = d2[a, js[k]], d2[a, js[k1]]
            drop = k1 if (qb > qa or (qb == qa and js[k1] > js[k])) else k
            del js[drop], ang[drop]
        m = len(js)
        cand = [(a, js[k], js[(k + 1) % m]) for k in range(m)] if m >= 2 else []
        if cand:
            ok = check_rules(x, r, tol, cand, rtol=0.0)["ok"]
            # a particle's elements in increasing order of the first neighbour
            out += sorted((c for c, o in zip(cand, ok) if o), key=lambda c: c[1])
    return np.array(out, dtype=np.int64).reshape(-1, 3)


def _reference_cover(x, triangles, sample):
    """N_e by brute force: every element sharing a particle with e (the spec's rule,
    Feng, Li & Oñate 2015, §2: in an unfolded element system only these can cover e's probe;
    the deformed packing below folds elements over others that share no particle
    with them, which the rule leaves out) tested against the probe of e."""
    t = np.asarray(triangles)
    p = x[t]
    out = []
    for e in sample:
        v = np.sort(t[e])
        q = 0.5 * x[v[0]] + 0.3 * x[v[1]] + 0.2 * x[v[2]]
        inside = np.isin(t, v).any(axis=1)
        for k in range(3):
            a, b = p[:, k], p[:, (k + 1) % 3]
            inside &= (b[:, 0] - a[:, 0]) * (q[1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (
                q[0] - a[:, 0]) > 0
        out.append(int(inside.sum()))
    return np.array(out)


@pytest.mark.parametrize("deformed", [False, True])
def test_kernels_match_a_numpy_reference(packings, deformed):
    x, r, tol = packings["random"]
    if deformed:
        x = deform(x, 7)
    d = ElementSystem(x, r, tol).build().numpy()
    np.testing.assert_array_equal(d["triangles"], _reference_elements(x, r, tol))
    sample = np.random.default_rng(0).choice(len(d["area"]), 400, replace=False)
    np.testing.assert_array_equal(d["n_cover"][sample],
                                  _reference_cover(x, d["triangles"], sample))
    s = d["triangles"]
    twice = ((x[s[:, 1], 0] - x[s[:, 0], 0]) * (x[s[:, 2], 1] - x[s[:, 0], 1])
             - (x[s[:, 1], 1] - x[s[:, 0], 1]) * (x[s[:, 2], 0] - x[s[:, 0], 0]))
    np.testing.assert_allclose(d["area"], 0.5 * twice, rtol=1e-12)


def test_small_capacity_grows_to_the_same_result(packings):
    x, r, tol = packings["random"]
    small = ElementSystem(x, r, tol, capacity=2).build()
    ref = ElementSystem(x, r, tol).build()
    assert small.capacity >= small.neighbour_need > 2
    a, b = small.numpy(), ref.numpy()
    for k in a:
        np.testing.assert_array_equal(a[k], b[k])
    np.testing.assert_array_equal(small.masses(RHO), ref.masses(RHO))


def test_rebuild_with_new_positions(packings):
    x, r, tol = packings["regular"]
    es = ElementSystem(x, r, tol).build()
    y = deform(x, 1)
    np.testing.assert_array_equal(es.build(y).numpy()["triangles"],
                                  ElementSystem(y, r, tol).build().numpy()["triangles"])


def test_check_rules_flags_each_violation():
    x = np.array([[0.0, 0.0], [1.0, 0.0], [0.5, 0.8],      # fine
                  [3.0, 0.0], [4.0, 0.0], [3.5, 0.1],      # angles 11°, 11°, 158°
                  [6.0, 0.0], [9.0, 0.0], [7.5, 1.0],      # too far apart
                  [0.0, 5.0], [0.1, 5.0], [0.05, 5.08]])   # edges < 0.5 × mean R
    tri = [[0, 1, 2], [3, 4, 5], [6, 7, 8], [9, 10, 11], [0, 2, 1]]
    res = check_rules(x, 0.5, 0.2, tri)
    assert res["ok"].tolist() == [True, False, False, False, False]
    assert res["angle"].tolist() == [True, False, True, True, True]
    assert res["contact"].tolist() == [True, True, False, True, True]
    assert res["edge"].tolist() == [True, True, True, False, True]
    assert res["orientation"].tolist() == [True, True, True, True, False]


@pytest.mark.parametrize("kwargs, word", [
    (dict(positions=[[0.0, 0.0], [1.0]], radii=0.5, tolerance=0.1), "positions"),
    (dict(positions=[[0.0, np.nan]], radii=0.5, tolerance=0.1), "positions"),
    (dict(positions=np.zeros((0, 2)), radii=0.5, tolerance=0.1), "positions"),
    (dict(positions=[[0.0, 0.0], [1.0, 0.0]], radii=[0.5, 0.0], tolerance=0.1), "radii"),
    (dict(positions=[[0.0, 0.0], [1.0, 0.0]], radii=[0.5], tolerance=0.1), "radii"),
    (dict(positions=[[0.0, 0.0]], radii=0.5, tolerance=-0.1), "tolerance"),
    (dict(positions=[[0.0, 0.0]], radii=0.5, tolerance=0.1, capacity=0), "capacity"),
])
def test_bad_input(kwargs, word):
    with pytest.raises(tdem.InputError, match=word):
        ElementSystem(**kwargs)


def test_bad_density_and_positions_on_rebuild():
    es = ElementSystem([[0.0, 0.0], [1.0, 0.0]], 0.5, 0.1)
    with pytest.raises(tdem.InputError, match="density"):
        es.masses(-1.0)
    with pytest.raises(tdem.InputError, match="positions"):
        es.build(np.zeros((3, 2)))
