"""Structured triangle meshes of rectangles, and mesh checks (numpy).

Conventions
-----------
- ``vertices`` (V, 2) float64, ``triangles`` (T, 3) int64 vertex indices, every
  triangle **counter-clockwise** (positive signed area).
- A boundary edge (a, b) is an edge used by exactly one triangle, oriented as in
  that triangle: the mesh lies to the *left* of a→b and the outward unit normal
  is to the *right*, n = (b_y − a_y, −(b_x − a_x)) / |b − a|. The boundary edges
  of a simply connected mesh then chain into one counter-clockwise loop.
- Lumped nodal masses of a block (physics notes §4): each triangle gives ρ·S/3
  to each of its nodes (unit thickness).
"""
import numpy as np

from physics.validate import positive as _positive

from .errors import InputError

PATTERNS = ("regular", "cross")


def _count(name, value):
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
        raise InputError(f"{name} must be an integer >= 1, got {value!r}")
    return int(value)


def rectangle(width, height, nx, ny, pattern="regular", origin=(0.0, 0.0)):
    """Structured mesh of the rectangle ``origin + [0, width] × [0, height]``.

    The rectangle is cut into nx × ny equal cells; grid node (i, j) (0 ≤ i ≤ nx,
    0 ≤ j ≤ ny) is vertex j·(nx + 1) + i.

    - ``"regular"``: each cell is split by its diagonal from the lower-left to the
      upper-right corner: 2·nx·ny triangles, (nx + 1)(ny + 1) vertices.
    - ``"cross"``: each cell gets a centre node (vertices (nx + 1)(ny + 1) + the
      cell index j·nx + i) and 4 triangles (bottom, right, top, left):
      4·nx·ny triangles, (nx + 1)(ny + 1) + nx·ny vertices.

    Returns ``(vertices (V, 2), triangles (T, 3))``, triangles counter-clockwise.
    """
    w = _positive("width", width)
    h = _positive("height", height)
    nx = _count("nx", nx)
    ny = _count("ny", ny)
    if pattern not in PATTERNS:
        raise InputError(f"pattern must be one of {PATTERNS}, got {pattern!r}")
    try:
        o = np.asarray(origin, dtype=float).reshape(2)
    except (TypeError, ValueError):
        raise InputError(f"origin must be a pair of numbers, got {origin!r}") from None
    if not np.all(np.isfinite(o)):
        raise InputError(f"origin must be a pair of finite numbers, got {origin!r}")
    xs = o[0] + w * np.arange(nx + 1) / nx
    ys = o[1] + h * np.arange(ny + 1) / ny
    gx, gy = np.meshgrid(xs, ys)
    verts = np.stack([gx.ravel(), gy.ravel()], axis=1)
    i, j = np.meshgrid(np.arange(nx), np.arange(ny))
    i, j = i.ravel(), j.ravel()
    p00 = j * (nx + 1) + i
    p10 = p00 + 1
    p01 = p00 + nx + 1
    p11 = p01 + 1
    if pattern == "regular":
        tris = np.stack([np.stack([p00, p10, p11], 1), np.stack([p00, p11, p01], 1)], 1)
    else:
        cx = 0.5 * (xs[:-1][i] + xs[1:][i])
        cy = 0.5 * (ys[:-1][j] + ys[1:][j])
        pc = len(verts) + np.arange(nx * ny)
        verts = np.concatenate([verts, np.stack([cx, cy], axis=1)])
        tris = np.stack([np.stack([p00, p10, pc], 1), np.stack([p10, p11, pc], 1),
                         np.stack([p11, p01, pc], 1), np.stack([p01, p00, pc], 1)], 1)
    return verts, tris.reshape(-1, 3).astype(np.int64)


def signed_areas(vertices, triangles):
    """Signed area of every triangle (> 0 counter-clockwise)."""
    p = np.asarray(vertices, dtype=float)[np.asarray(triangles)]
    u = p[:, 1] - p[:, 0]
    v = p[:, 2] - p[:, 0]
    return 0.5 * (u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0])


def check_mesh(vertices, triangles, rtol=1e-10):
    """Check a block mesh; return ``(vertices (V, 2) float, triangles (T, 3) int64)``.

    Raises :class:`tdem.InputError` for a bad shape, a non-finite coordinate, an
    index out of range, a repeated vertex in a triangle, or a triangle that is
    **degenerate** (|2S| ≤ rtol × its longest edge squared) or **inverted**
    (clockwise, S < 0); the message names the first offending triangle.
    """
    try:
        x = np.asarray(vertices, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"vertices must be an array (V, 2) of numbers, got {vertices!r}") \
            from None
    if x.ndim != 2 or x.shape[1] != 2 or len(x) < 3:
        raise InputError(f"vertices must be an array (V, 2) with V >= 3, got shape {x.shape}")
    if not np.all(np.isfinite(x)):
        k = int(np.argmax(~np.all(np.isfinite(x), axis=1)))
        raise InputError(f"vertices must be finite: vertex {k} is {x[k].tolist()}")
    t = np.asarray(triangles)
    if t.ndim != 2 or t.shape[1] != 3 or len(t) < 1 or not np.issubdtype(t.dtype, np.integer):
        raise InputError(f"triangles must be an integer array (T, 3) with T >= 1, "
                         f"got shape {t.shape} dtype {t.dtype}")
    t = t.astype(np.int64)
    bad = np.any((t < 0) | (t >= len(x)), axis=1)
    if bad.any():
        k = int(np.argmax(bad))
        raise InputError(f"triangle {k} {t[k].tolist()} has a vertex index outside "
                         f"[0, {len(x) - 1}]")
    rep = (t[:, 0] == t[:, 1]) | (t[:, 1] == t[:, 2]) | (t[:, 2] == t[:, 0])
    if rep.any():
        k = int(np.argmax(rep))
        raise InputError(f"triangle {k} {t[k].tolist()} is degenerate: a repeated vertex")
    s2 = 2.0 * signed_areas(x, t)
    p = x[t]
    edge2 = np.max(np.sum((np.roll(p, -1, axis=1) - p) ** 2, axis=2), axis=1)
    degenerate = np.abs(s2) <= rtol * edge2
    inverted = (s2 < 0) & ~degenerate
    if degenerate.any():
        k = int(np.argmax(degenerate))
        raise InputError(f"triangle {k} {t[k].tolist()} is degenerate: area {0.5 * s2[k]!r} "
                         f"for a longest edge of {np.sqrt(edge2[k])!r}")
    if inverted.any():
        k = int(np.argmax(inverted))
        raise InputError(f"triangle {k} {t[k].tolist()} is inverted (clockwise): "
                         f"area {0.5 * s2[k]!r}")
    return x, t


def boundary_edges(triangles):
    """Edges used by exactly one triangle, as an array (B, 2) of (a, b).

    Each keeps its triangle's orientation: for counter-clockwise triangles the mesh
    is to the left of a→b and the outward normal to the right. Ordered by
    triangle, then edge (a→b, b→c, c→a).
    """
    t = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    e = np.stack([t, np.roll(t, -1, axis=1)], axis=2).reshape(-1, 2)
    key = np.sort(e, axis=1)
    _, inv, cnt = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    return e[cnt[inv.ravel()] == 1]


def boundary_nodes(triangles):
    """Sorted indices of the vertices on a boundary edge."""
    return np.unique(boundary_edges(triangles))


def nodal_masses(vertices, triangles, density):
    """Lumped nodal masses ρ·S/3 summed over the triangles of each node (kg per m)."""
    rho = _positive("density", density)
    t = np.asarray(triangles, dtype=np.int64)
    s = signed_areas(vertices, t)
    m = np.zeros(len(vertices))
    np.add.at(m, t.ravel(), np.repeat(rho * s / 3.0, 3))
    return m
