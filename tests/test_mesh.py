"""Structured rectangle meshes and mesh checks (tdem/mesh.py).

Counts for the paper's 0.1 × 0.2 m uniaxial-compression sample (§3): the regular
pattern gives 2·nx·ny triangles, so 800 elements need nx·ny = 400, e.g.
nx = 20, ny = 20 (cells 5 × 10 mm) or nx = 10, ny = 40 (10 × 5 mm); square cells
cannot give 800 (nx = 10·√2). The cross pattern gives 4·nx·ny triangles: 1794 is
not a multiple of 4, so no structured cross mesh has the paper's count; the
nearest with square cells is nx = 15, ny = 30 (1800 triangles, 6.67 mm cells).
With 5 mm square cells (the PCMM regular packing's 21 × 41 = 861 nodes),
nx = 20, ny = 40 gives 1600 (regular) and 3200 (cross) triangles.
"""
import numpy as np
import pytest

from tdem import InputError, mesh


def loop_from_edges(edges):
    """Chain oriented edges into loops (lists of vertices)."""
    nxt = {}
    for a, b in edges:
        assert a not in nxt, "a vertex starts two boundary edges"
        nxt[int(a)] = int(b)
    loops = []
    seen = set()
    for start in nxt:
        if start in seen:
            continue
        loop = [start]
        seen.add(start)
        v = nxt[start]
        while v != start:
            loop.append(v)
            seen.add(v)
            v = nxt[v]
        loops.append(loop)
    return loops


@pytest.mark.parametrize("pattern, nx, ny, nv, nt", [
    ("regular", 20, 20, 441, 800),
    ("regular", 10, 40, 451, 800),
    ("cross", 15, 30, 16 * 31 + 450, 1800),
    ("cross", 20, 40, 861 + 800, 3200),
])
def test_counts_orientation_area(pattern, nx, ny, nv, nt):
    v, t = mesh.rectangle(0.1, 0.2, nx, ny, pattern, origin=(1.0, -2.0))
    assert v.shape == (nv, 2) and t.shape == (nt, 3)
    s = mesh.signed_areas(v, t)
    assert np.all(s > 0)
    assert s.sum() == pytest.approx(0.02, rel=1e-12)
    # every triangle of one pattern has the same area
    np.testing.assert_allclose(s, 0.02 / nt, rtol=1e-9)
    assert v[:, 0].min() == pytest.approx(1.0) and v[:, 0].max() == pytest.approx(1.1)
    assert v[:, 1].min() == pytest.approx(-2.0) and v[:, 1].max() == pytest.approx(-1.8)
    mesh.check_mesh(v, t)
    m = mesh.nodal_masses(v, t, 2500.0)
    assert m.sum() == pytest.approx(2500.0 * 0.02, rel=1e-12)


@pytest.mark.parametrize("pattern", ["regular", "cross"])
def test_boundary_is_one_ccw_loop(pattern):
    w, h, nx, ny = 0.3, 0.2, 6, 4
    v, t = mesh.rectangle(w, h, nx, ny, pattern)
    e = mesh.boundary_edges(t)
    assert len(e) == 2 * (nx + ny)
    loops = loop_from_edges(e)
    assert len(loops) == 1 and len(loops[0]) == 2 * (nx + ny)
    d = v[e[:, 1]] - v[e[:, 0]]
    assert np.linalg.norm(d, axis=1).sum() == pytest.approx(2 * (w + h), rel=1e-12)
    # counter-clockwise loop: shoelace area = rectangle area
    p = v[loops[0]]
    shoelace = 0.5 * np.sum(p[:, 0] * np.roll(p[:, 1], -1) - np.roll(p[:, 0], -1) * p[:, 1])
    assert shoelace == pytest.approx(w * h, rel=1e-12)
    # outward normal (d_y, -d_x) points away from the centre
    n = np.stack([d[:, 1], -d[:, 0]], axis=1)
    mid = 0.5 * (v[e[:, 0]] + v[e[:, 1]]) - [w / 2, h / 2]
    assert np.all(np.sum(n * mid, axis=1) > 0)
    bn = mesh.boundary_nodes(t)
    on_side = (np.isclose(v[:, 0], 0) | np.isclose(v[:, 0], w) | np.isclose(v[:, 1], 0)
               | np.isclose(v[:, 1], h))
    np.testing.assert_array_equal(bn, np.flatnonzero(on_side))


def test_check_mesh_rejects_inverted_and_degenerate():
    v, t = mesh.rectangle(1.0, 1.0, 2, 2)
    bad = t.copy()
    bad[5] = bad[5, ::-1]
    with pytest.raises(InputError, match=r"triangle 5 .*inverted"):
        mesh.check_mesh(v, bad)
    v2 = np.concatenate([v, [[0.25, 0.0]]])   # on the bottom edge, between 0 and 1
    deg = np.concatenate([t, [[0, 1, len(v)]]])
    with pytest.raises(InputError, match=rf"triangle {len(t)} .*degenerate"):
        mesh.check_mesh(v2, deg)
    rep = t.copy()
    rep[3, 2] = rep[3, 0]
    with pytest.raises(InputError, match=r"triangle 3 .*degenerate"):
        mesh.check_mesh(v, rep)
    with pytest.raises(InputError, match=r"triangle 0 .*outside"):
        mesh.check_mesh(v, t + 100)
    with pytest.raises(InputError):
        mesh.rectangle(1.0, 1.0, 0, 2)
    with pytest.raises(InputError):
        mesh.rectangle(1.0, 1.0, 2, 2, pattern="diamond")


@pytest.mark.parametrize("pts,area", [
    ([[0, 0], [1, 0], [1, 1], [0.5, 0.4], [0, 1]], 0.7),          # concave
    ([[0, 0], [0.6, 0.0], [0.6 + 0.02, 0.04], [0.02, 0.04]], 0.024),  # thin inclined plate
])
def test_polygon_mesh_covers_the_polygon(pts, area):
    v, t = mesh.polygon(pts, 0.02)
    s = mesh.signed_areas(v, t)
    assert s.min() > 0
    assert abs(s.sum() - area) < 1e-12
    # no sliver: every interior angle above 15 degrees
    p = v[t]
    e = np.roll(p, -1, axis=1) - p
    u, w = e, -np.roll(e, 1, axis=1)
    cos = np.einsum("eki,eki->ek", u, w) / (np.linalg.norm(u, axis=2) * np.linalg.norm(w, axis=2))
    assert np.degrees(np.arccos(np.clip(cos, -1, 1))).min() > 15.0
    # the boundary loop has the polygon's perimeter
    b = mesh.boundary_edges(t)
    q = np.asarray(pts, float)
    perim = np.linalg.norm(np.roll(q, -1, 0) - q, axis=1).sum()
    assert abs(np.linalg.norm(v[b[:, 1]] - v[b[:, 0]], axis=1).sum() - perim) < 1e-9


def test_polygon_mesh_bad_input():
    with pytest.raises(ValueError, match="size"):
        mesh.polygon([[0, 0], [1, 0], [0, 1]], -1.0)
    with pytest.raises(ValueError, match="points"):
        mesh.polygon([[0, 0], [1, 0]], 0.1)
