"""Block meshes whose triangles cover the same ground twice are refused, naming the
triangles: duplicated triangles (which would add their mass twice), edges shared by
more than two triangles, folded and overlapping triangles."""
import numpy as np
import pytest

import tdem
from tdem import mesh

MAT = tdem.Elastic(density=2000.0, young=1e7, poisson=0.25)


def _add(v, t):
    return tdem.Simulation(gravity=(0.0, 0.0)).add_block(v, t, material=MAT)


def _square():
    return mesh.rectangle(1.0, 1.0, 2, 2)     # 9 vertices, 8 triangles


def test_valid_meshes_are_accepted_with_their_mass():
    v, t = _square()
    b = _add(v, t)
    assert b.nodes()["mass"].sum() == pytest.approx(2000.0 * 1.0)
    v, t = mesh.rectangle(0.6, 0.3, 12, 6, pattern="cross")
    assert _add(v, t).nodes()["mass"].sum() == pytest.approx(2000.0 * 0.18)
    v, t = mesh.polygon([[0, 0], [1, 0], [1, 1], [0.5, 0.4], [0, 1]], 0.1)
    assert _add(v, t).nodes()["mass"].sum() == pytest.approx(2000.0 * 0.7)
    # a triangle that only touches the others along an edge (separate vertices on it)
    v, t = _square()
    v2 = np.vstack([v, [[0.0, 0.0], [0.5, 0.0], [0.25, -0.3]]])
    _add(v2, np.vstack([t, [[10, 9, 11]]]))


def test_duplicated_triangle():
    v, t = _square()
    with pytest.raises(tdem.InputError, match=r"triangles: triangles 3 and 8 are the same "
                                              r"triangle \(vertices \[1, 4, 5\]\)"):
        _add(v, np.vstack([t, t[3]]))
    # the same triangle with its vertices in another (still counter-clockwise) order
    with pytest.raises(tdem.InputError, match=r"triangles 3 and 8 are the same triangle"):
        _add(v, np.vstack([t, np.roll(t[3], 1)]))


def test_edge_shared_by_three_triangles():
    v, t = _square()
    v2 = np.vstack([v, [[0.25, -0.5], [0.25, 0.2]]])
    with pytest.raises(tdem.InputError, match=r"triangles: the edge \[0, 1\] is shared by "
                                              r"triangles 0, 8 and 9, more than two \(the "
                                              r"mesh is not manifold\)"):
        _add(v2, np.vstack([t, [[1, 0, 9], [0, 1, 10]]]))


def test_folded_triangle():
    v, t = _square()
    v2 = np.vstack([v, [[0.25, 0.2]]])
    with pytest.raises(tdem.InputError, match=r"triangles: triangles 0 and 8 overlap: they "
                                              r"lie on the same side of their common edge "
                                              r"\[0, 1\] \(the mesh folds over\)"):
        _add(v2, np.vstack([t, [[0, 1, 9]]]))


def test_overlapping_triangles_without_common_vertices():
    v, t = _square()
    # a loose triangle inside the square
    v2 = np.vstack([v, [[0.1, 0.1], [0.3, 0.1], [0.1, 0.3]]])
    with pytest.raises(tdem.InputError, match=r"triangles: triangles 0 \[0, 1, 4\] and 8 "
                                              r"\[9, 10, 11\] overlap \(their interiors "
                                              r"intersect\) \(and 1 more pairs\)"):
        _add(v2, np.vstack([t, [[9, 10, 11]]]))
    # two copies of a mesh with their own vertices, one on the other
    with pytest.raises(tdem.InputError, match=r"triangles 0 \[0, 1, 4\] and 8 \[9, 10, 13\] "
                                              r"overlap"):
        _add(np.vstack([v, v]), np.vstack([t, t + len(v)]))
