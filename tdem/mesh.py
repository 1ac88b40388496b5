"""Triangle meshes: structured meshes of rectangles, Delaunay meshes of polygons, and
mesh checks (numpy).

Conventions
-----------
- ``vertices`` (V, 2) float64, ``triangles`` (T, 3) int64 vertex indices, every
  triangle **counter-clockwise** (positive signed area).
- A boundary edge (a, b) is an edge used by exactly one triangle, oriented as in
  that triangle: the mesh lies to the *left* of a→b and the outward unit normal
  is to the *right*, n = (b_y − a_y, −(b_x − a_x)) / ‖b − a‖. The boundary edges
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


def polygon(points, size):
    """Triangle mesh of the simple polygon ``points`` (M, 2) with edges about ``size``.

    Nodes: the polygon's corners, points every ≈ ``size`` along its sides, and a
    hexagonal lattice of spacing ``size`` inside, kept at least 0.5·size from the
    sides. Triangles: the Delaunay triangulation of these nodes (Qhull, through
    matplotlib) whose centroids lie inside the polygon; concave polygons are
    handled that way. Returns ``(vertices (V, 2), triangles (T, 3))``,
    counter-clockwise, checked by :func:`check_mesh`.
    """
    import matplotlib.path as mpath
    import matplotlib.tri as mtri

    h = _positive("size", size)
    try:
        p = np.asarray(points, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"points must be an array (M, 2) of numbers, got {points!r}") from None
    if p.ndim != 2 or p.shape[1] != 2 or len(p) < 3 or not np.isfinite(p).all():
        raise InputError(f"points must be a finite array (M, 2) with M >= 3, got shape "
                         f"{p.shape}")
    area2 = np.sum(p[:, 0] * np.roll(p[:, 1], -1) - np.roll(p[:, 0], -1) * p[:, 1])
    if abs(area2) <= 1e-12 * np.ptp(p, axis=0).max() ** 2:
        raise InputError("points: the polygon has no area")
    if area2 < 0:
        p = p[::-1]
    nodes = []
    for a, b in zip(p, np.roll(p, -1, axis=0)):
        k = max(1, int(np.ceil(np.linalg.norm(b - a) / h)))
        s = np.arange(k)[:, None] / k
        nodes.append(a + s * (b - a))
    boundary = np.concatenate(nodes)
    lo, hi = p.min(axis=0), p.max(axis=0)
    dy = h * np.sqrt(3.0) / 2.0
    ys = np.arange(lo[1], hi[1] + dy, dy)
    xs = []
    for j, y in enumerate(ys):
        x = np.arange(lo[0] + (0.5 * h if j % 2 else 0.0), hi[0] + h, h)
        xs.append(np.stack([x, np.full(len(x), y)], 1))
    grid = np.concatenate(xs)
    path = mpath.Path(p)
    keep = path.contains_points(grid)
    grid = grid[keep]
    # distance to the sides
    d = np.full(len(grid), np.inf)
    for a, b in zip(p, np.roll(p, -1, axis=0)):
        ab = b - a
        s = np.clip(((grid - a) @ ab) / (ab @ ab), 0.0, 1.0)
        d = np.minimum(d, np.linalg.norm(grid - (a + s[:, None] * ab), axis=1))
    grid = grid[d >= 0.5 * h]
    x = np.concatenate([boundary, grid])
    tri = mtri.Triangulation(x[:, 0], x[:, 1]).triangles.astype(np.int64)
    cent = x[tri].mean(axis=1)
    tri = tri[path.contains_points(cent)]
    sa = signed_areas(x, tri)
    tri[sa < 0] = tri[sa < 0][:, ::-1]
    # Qhull may close collinear side nodes with zero-area triangles: drop them
    tri = tri[np.abs(sa) > 1e-9 * h * h]
    used = np.unique(tri)
    remap = -np.ones(len(x), np.int64)
    remap[used] = np.arange(len(used))
    return check_mesh(x[used], remap[tri])


def signed_areas(vertices, triangles):
    """Signed area of every triangle (> 0 counter-clockwise)."""
    p = np.asarray(vertices, dtype=float)[np.asarray(triangles)]
    u = p[:, 1] - p[:, 0]
    v = p[:, 2] - p[:, 0]
    return 0.5 * (u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0])


def check_mesh(vertices, triangles, rtol=1e-10):
    """Check a block mesh; return ``(vertices (V, 2) float, triangles (T, 3) int64)``.

    Raises :class:`tdem.InputError` for a bad shape, a non-finite coordinate, an
    index out of range, a repeated vertex in a triangle, a triangle that is
    **degenerate** (|2S| ≤ rtol × its longest edge squared) or **inverted**
    (clockwise, S < 0), and triangles that are duplicated, share an edge with more
    than one other, or overlap (:func:`check_overlaps`); the message names the
    offending triangles.
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
    check_overlaps(x, t)
    return x, t


def check_overlaps(vertices, triangles, rtol=1e-9):
    """Refuse triangles that cover the same ground twice, naming them
    (:class:`tdem.InputError`); the triangles must be counter-clockwise and not
    degenerate (:func:`check_mesh` calls this after checking that).

    - **duplicated**: two triangles with the same three vertices;
    - **non-manifold**: an edge shared by more than two triangles;
    - **folded**: two triangles on the same side of their common edge (they use it
      in the same direction);
    - **overlapping**: any two triangles whose interiors intersect (a separating-axis
      test on the pairs whose bounding boxes meet, found with a grid). Triangles
      that only touch (a common edge or vertex, a vertex on an edge) are fine; the
      tolerance is ``rtol`` × the longer edge of the pair.
    """
    x = np.asarray(vertices, dtype=float)
    t = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    nt = len(t)
    if nt < 2:
        return
    # duplicated triangles
    key = np.sort(t, axis=1)
    inv, cnt = _groups(key, len(x))
    if (cnt > 1).any():
        k = int(np.argmax(cnt[inv] > 1))
        same = np.flatnonzero(inv == inv[k])
        raise InputError(f"triangles: triangles {_names(same)} are the same triangle "
                         f"(vertices {key[k].tolist()}); a duplicated triangle counts its "
                         "mass twice")
    # edges: directed (a -> b as in the triangle) and undirected
    e = np.stack([t, np.roll(t, -1, axis=1)], axis=2).reshape(-1, 2)
    owner = np.repeat(np.arange(nt), 3)
    ekey = np.sort(e, axis=1)
    einv, ecnt = _groups(ekey, len(x))
    if (ecnt > 2).any():
        k = int(np.argmax(ecnt[einv] > 2))
        tris = owner[einv == einv[k]]
        raise InputError(f"triangles: the edge {ekey[k].tolist()} is shared by triangles "
                         f"{_names(tris)}, more than two (the mesh is not manifold)")
    dinv, dcnt = _groups(e, len(x))
    if (dcnt > 1).any():
        k = int(np.argmax(dcnt[dinv] > 1))
        tris = owner[dinv == dinv[k]]
        raise InputError(f"triangles: triangles {_names(tris)} overlap: they lie on the same "
                         f"side of their common edge {e[k].tolist()} (the mesh folds over)")
    pairs = _overlapping_pairs(x, t, rtol)
    if len(pairs):
        i, j = (int(v) for v in pairs[0])
        more = f" (and {len(pairs) - 1} more pairs)" if len(pairs) > 1 else ""
        raise InputError(f"triangles: triangles {i} {t[i].tolist()} and {j} {t[j].tolist()} "
                         f"overlap (their interiors intersect){more}")


def _groups(rows, base):
    """(group of each row, size of each group) for rows of vertex indices < base."""
    rows = np.asarray(rows, dtype=np.int64)
    if base ** rows.shape[1] < 2 ** 62:
        code = np.zeros(len(rows), np.int64)
        for c in range(rows.shape[1]):
            code = code * base + rows[:, c]
        _, inv, cnt = np.unique(code, return_inverse=True, return_counts=True)
    else:
        _, inv, cnt = np.unique(rows, axis=0, return_inverse=True, return_counts=True)
    return inv.ravel(), cnt


def _names(idx):
    idx = [int(i) for i in idx]
    return ", ".join(map(str, idx[:-1])) + f" and {idx[-1]}" if len(idx) > 1 else str(idx[0])


def _candidate_pairs(lo, hi):
    """Pairs (i < j) of boxes [lo, hi] that may meet: those sharing a grid cell."""
    nt = len(lo)
    ext = np.max(hi - lo, axis=1)
    h = float(np.median(ext))
    if not h > 0:
        h = float(ext.max()) or 1.0
    origin = lo.min(axis=0)
    while True:
        c0 = np.floor((lo - origin) / h).astype(np.int64)
        c1 = np.floor((hi - origin) / h).astype(np.int64)
        span = c1 - c0 + 1
        ncell = span[:, 0] * span[:, 1]
        if ncell.sum() <= 16 * nt + 1024:
            break
        h *= 2.0
    total = int(ncell.sum())
    tri = np.repeat(np.arange(nt), ncell)
    local = np.arange(total) - np.repeat(np.cumsum(ncell) - ncell, ncell)
    cx = c0[tri, 0] + local % span[tri, 0]
    cy = c0[tri, 1] + local // span[tri, 0]
    cell = cx * (int(c1[:, 1].max()) + 1) + cy
    order = np.argsort(cell, kind="stable")
    cell, tri = cell[order], tri[order]
    start = np.flatnonzero(np.r_[True, cell[1:] != cell[:-1]])
    size = np.diff(np.r_[start, total])
    group_end = np.repeat(start + size, size)
    npart = group_end - 1 - np.arange(total)            # partners after each entry
    p = np.repeat(np.arange(total), npart)
    q = p + 1 + (np.arange(len(p)) - np.repeat(np.cumsum(npart) - npart, npart))
    a, b = tri[p], tri[q]
    # a pair of boxes sharing several cells is kept in one of them: the cell of the
    # corner max(lower-left cells), which both boxes cover
    cp, cq = cx[order][p], cy[order][p]
    keep = (cp == np.maximum(c0[a, 0], c0[b, 0])) & (cq == np.maximum(c0[a, 1], c0[b, 1]))
    a, b = a[keep], b[keep]
    return np.stack([np.minimum(a, b), np.maximum(a, b)], axis=1)


def _overlapping_pairs(x, t, rtol, chunk=200000):
    p = x[t]                                           # (T, 3, 2)
    lo, hi = p.min(axis=1), p.max(axis=1)
    cand = _candidate_pairs(lo, hi)
    if len(cand) == 0:
        return cand
    edge = np.roll(p, -1, axis=1) - p                   # (T, 3, 2)
    elen = np.linalg.norm(edge, axis=2)
    normal = np.stack([-edge[:, :, 1], edge[:, :, 0]], axis=2) / elen[:, :, None]
    longest = elen.max(axis=1)
    found = []
    for s in range(0, len(cand), chunk):
        i, j = cand[s:s + chunk, 0], cand[s:s + chunk, 1]
        tol = rtol * np.maximum(longest[i], longest[j])
        meet = np.all((np.minimum(hi[i], hi[j]) - np.maximum(lo[i], lo[j])) > tol[:, None],
                      axis=1)
        i, j, tol = i[meet], j[meet], tol[meet]
        if len(i) == 0:
            continue
        axes = np.concatenate([normal[i], normal[j]], axis=1)          # (P, 6, 2)
        pa = np.einsum("pak,pvk->pav", axes, p[i])                     # (P, 6, 3)
        pb = np.einsum("pak,pvk->pav", axes, p[j])
        gap = np.minimum(pa.max(axis=2), pb.max(axis=2)) - np.maximum(pa.min(axis=2),
                                                                      pb.min(axis=2))
        hit = np.all(gap > tol[:, None], axis=1)
        found.append(np.stack([i[hit], j[hit]], axis=1))
    if not found:
        return np.zeros((0, 2), np.int64)
    found = np.concatenate(found)
    return found[np.lexsort((found[:, 1], found[:, 0]))]


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
