"""Particle packings: regular lattices and dense random packings of discs.

Every function returns ``(positions, radii)``: float arrays of shapes (N, 2) and
(N,). Lengths are in metres.

- :func:`regular`: square lattice of touching discs (spacing 2R).
- :func:`cross`: hexagonal lattice of touching discs (rows R·√3 apart, every
  other row shifted by R), the "cross" packing of Feng, Li & Oñate (2015).
- :func:`random`: dense random packing, radii uniform in [rmin, rmax], in a
  rectangle or a polygon, by radius expansion with overlap relaxation.
- :func:`fill_holes`: discs added into the holes a packing's PCMM element cover
  leaves.
- 3D: :func:`lattice3d` (fcc or cubic centres), :func:`random3d` (a random packing of
  spheres in a box, by the same radius expansion with overlap relaxation).

The lattices put the outermost centres ``inset`` from the edges of the rectangle:
``inset = R`` (the default) keeps every disc inside it; ``inset = 0`` puts centres
on the edges, as the nodes of a structured mesh (the paper's 100 × 200 mm
specimens: 861 regular and 964 cross particles of R = 2.5 mm).
"""
import math

import numpy as np

from physics.validate import non_negative as _nonnegative
from physics.validate import positive as _positive

from .errors import InputError

# random packing: radius growth per sweep (from half size), momentum of the relaxation
_GROWTH = 0.002
_MOMENTUM = 0.85
# relative slack when counting how many lattice spacings fit in a length
_FIT_EPS = 1e-9


def _origin(origin):
    try:
        o = np.asarray(origin, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"origin must be two numbers, got {origin!r}") from None
    if o.shape != (2,) or not np.all(np.isfinite(o)):
        raise InputError(f"origin must be two finite numbers, got {origin!r}")
    return o


def _lattice_span(width, height, radius, inset):
    """The rectangle the centres must lie in, as (usable width, usable height, inset)."""
    width = _positive("width", width)
    height = _positive("height", height)
    radius = _positive("radius", radius)
    inset = radius if inset is None else float(inset)
    if not (inset >= 0.0 and math.isfinite(inset)):
        raise InputError(f"inset must be a number >= 0, got {inset!r}")
    if width < 2 * inset or height < 2 * inset:
        raise InputError(f"the rectangle {width} x {height} is smaller than twice the inset "
                         f"{inset} (width and height must be >= {2 * inset})")
    return width - 2 * inset, height - 2 * inset, radius, inset


def _count(length, spacing):
    """Number of points spaced ``spacing`` apart in [0, length] starting at 0."""
    return int(math.floor(length / spacing * (1 + _FIT_EPS) + _FIT_EPS)) + 1


def regular(width, height, radius, origin=(0.0, 0.0), inset=None):
    """Square lattice of touching discs of radius R (centre spacing 2R).

    Centres lie in the rectangle ``origin + [0, width] × [0, height]`` at least
    ``inset`` (default R) from its edges, starting from its lower-left corner;
    ordered row by row (x fastest). 20 × 20 m with R = 0.5 m gives 400 discs.
    """
    w, h, r, inset = _lattice_span(width, height, radius, inset)
    o = _origin(origin)
    nx, ny = _count(w, 2 * r), _count(h, 2 * r)
    x = o[0] + inset + 2 * r * np.arange(nx)
    y = o[1] + inset + 2 * r * np.arange(ny)
    xx, yy = np.meshgrid(x, y)
    pos = np.stack([xx.ravel(), yy.ravel()], axis=1)
    return pos, np.full(len(pos), r)


def cross(width, height, radius, origin=(0.0, 0.0), inset=None, fit=False):
    """Hexagonal lattice of touching discs of radius R.

    Rows run along x, R·√3 apart in y; in-row spacing 2R; odd rows are shifted by
    R. Centres lie in ``origin + [0, width] × [0, height]`` at least ``inset``
    (default R) from its edges; ordered row by row (x fastest). Each interior
    disc touches six others at 60° intervals.

    ``fit=True`` shrinks the two spacings to the span of the centres divided by
    the smallest whole number of spacings that covers it (row spacing ≤ R·√3,
    in-row spacing ≤ 2R), so that the first and last rows and the ends of the
    even rows lie on the span's edges; odd rows hold one centre less, at the
    midpoints of the even row's spacings. The discs then overlap slightly (every
    neighbour distance ≤ 2R). With ``inset=0`` this is the node layout of a
    structured cross-triangle mesh: 20 × 20 m with R = √3/3 m gives 21 rows of
    19 and 18 centres, 389 discs (Feng, Li & Oñate 2015, §3.1).
    """
    w, h, r, inset = _lattice_span(width, height, radius, inset)
    o = _origin(origin)
    dy = r * math.sqrt(3.0)
    if fit:
        return _cross_fit(w, h, r, inset, o, dy)
    rows = []
    for k in range(_count(h, dy)):
        shift = r * (k % 2)
        if shift > w * (1 + _FIT_EPS):
            continue
        n = _count(w - shift, 2 * r)
        x = o[0] + inset + shift + 2 * r * np.arange(n)
        rows.append(np.stack([x, np.full(n, o[1] + inset + k * dy)], axis=1))
    pos = np.concatenate(rows)
    return pos, np.full(len(pos), r)


def _segments(length, spacing):
    """The smallest whole number (>= 1) of spacings of at most ``spacing`` that span
    ``length``."""
    return max(1, int(math.ceil(length / spacing * (1 - _FIT_EPS) - _FIT_EPS)))


def _cross_fit(w, h, r, inset, o, dy):
    ny = _segments(h, dy) if h > 0 else 0
    nx = _segments(w, 2 * r) if w > 0 else 0
    sy = h / ny if ny else 0.0
    sx = w / nx if nx else 0.0
    rows = []
    for k in range(ny + 1):
        if k % 2 == 0 or nx == 0:
            x = o[0] + inset + sx * np.arange(nx + 1)
        else:
            x = o[0] + inset + sx * (0.5 + np.arange(nx))
        rows.append(np.stack([x, np.full(len(x), o[1] + inset + k * sy)], axis=1))
    pos = np.concatenate(rows)
    return pos, np.full(len(pos), r)


# ----------------------------------------------------------------- random packing
def _region(width, height, origin, polygon):
    """Counter-clockwise vertices (M, 2) of the packing region."""
    if polygon is None:
        if width is None or height is None:
            raise InputError("width and height are required unless polygon is given")
        w = _positive("width", width)
        h = _positive("height", height)
        o = _origin(origin)
        return o + np.array([[0.0, 0.0], [w, 0.0], [w, h], [0.0, h]])
    if width is not None or height is not None:
        raise InputError("give either width and height or polygon, not both "
                         f"(width={width!r}, height={height!r})")
    try:
        p = np.asarray(polygon, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"polygon must be an (M, 2) array of vertices, got {polygon!r}") from None
    if p.ndim != 2 or p.shape[1] != 2 or len(p) < 3 or not np.all(np.isfinite(p)):
        raise InputError(f"polygon must be an (M, 2) array of M >= 3 finite vertices, "
                         f"got shape {p.shape}")
    area2 = np.sum(p[:, 0] * np.roll(p[:, 1], -1) - np.roll(p[:, 0], -1) * p[:, 1])
    if area2 == 0.0:
        raise InputError("polygon has zero area")
    return p if area2 > 0 else p[::-1].copy()


def _polygon_area(p):
    return 0.5 * np.sum(p[:, 0] * np.roll(p[:, 1], -1) - np.roll(p[:, 0], -1) * p[:, 1])


def _signed_distance(x, poly):
    """Signed distance of points x (N, 2) to the boundary of the polygon (positive
    inside) and the unit vector pointing into the polygon at the nearest point."""
    a = poly
    b = np.roll(poly, -1, axis=0)
    ab = b - a                                             # (M, 2)
    ax = x[:, None, :] - a[None, :, :]                     # (N, M, 2)
    t = np.clip(np.einsum("nmk,mk->nm", ax, ab) / np.einsum("mk,mk->m", ab, ab), 0.0, 1.0)
    near = a[None] + t[..., None] * ab[None]               # (N, M, 2)
    diff = x[:, None, :] - near
    dist = np.sqrt(np.einsum("nmk,nmk->nm", diff, diff))
    k = np.argmin(dist, axis=1)
    idx = np.arange(len(x))
    d = dist[idx, k]
    # even-odd rule for the inside test
    y0, y1 = a[None, :, 1], b[None, :, 1]
    xs = x[:, 0:1]
    ys = x[:, 1:2]
    crosses = (y0 > ys) != (y1 > ys)
    with np.errstate(divide="ignore", invalid="ignore"):
        xint = a[None, :, 0] + (ys - y0) * (b[None, :, 0] - a[None, :, 0]) / (y1 - y0)
    inside = (np.sum(crosses & (xs < xint), axis=1) % 2) == 1
    sign = np.where(inside, 1.0, -1.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        u = diff[idx, k] / d[:, None]
    # a point exactly on the boundary: step along the inward edge normal
    edge = ab[k] / np.linalg.norm(ab[k], axis=1)[:, None]
    inward_normal = np.stack([-edge[:, 1], edge[:, 0]], axis=1)
    u = np.where((d > 0)[:, None], u * sign[:, None], inward_normal)
    return sign * d, u


def _pairs(x, cut, h):
    """All pairs (i < j) closer than ``cut`` (a scalar), by a cell grid of side h >= cut.
    The occupied cells are found in the sorted cell keys, so memory is O(N) however
    far apart the points lie."""
    lo = x.min(axis=0)
    c = np.floor((x - lo) / h).astype(np.int64)
    nx, ny = c.max(axis=0) + 1
    cell = c[:, 0] * ny + c[:, 1]
    order = np.argsort(cell, kind="stable")
    skey = cell[order]
    idx_i, idx_j = [], []
    for ox, oy in ((0, 0), (1, -1), (1, 0), (1, 1), (0, 1)):
        cx, cy = c[:, 0] + ox, c[:, 1] + oy
        ok = (cx < nx) & (cy >= 0) & (cy < ny)
        i = np.nonzero(ok)[0]
        oc = cx[ok] * ny + cy[ok]
        start = np.searchsorted(skey, oc, "left")
        m = np.searchsorted(skey, oc, "right") - start
        rep_i = np.repeat(i, m)
        first = np.repeat(start, m)
        within = np.arange(len(rep_i)) - np.repeat(np.cumsum(m) - m, m)
        j = order[first + within]
        keep = j > rep_i if (ox, oy) == (0, 0) else np.ones(len(j), bool)
        idx_i.append(rep_i[keep])
        idx_j.append(j[keep])
    i = np.concatenate(idx_i)
    j = np.concatenate(idx_j)
    d = x[j] - x[i]
    close = np.einsum("nk,nk->n", d, d) < cut * cut
    i, j = i[close], j[close]
    swap = i > j
    i[swap], j[swap] = j[swap], i[swap]
    return i, j


def random(width, height, rmin=None, rmax=None, seed=0, target_fraction=0.8,
           origin=(0.0, 0.0), polygon=None, overlap_tol=1e-3, max_iter=20000,
           edge_centres=False, pcmm_tolerance=None, grading=None, edge_radius=None):
    """Dense random packing of discs with radii uniform in [rmin, rmax], or drawn
    from ``grading`` (a :func:`tdem.grading`: its mass curve for discs of equal
    thickness; rmin and rmax are then its range and are left out).

    The region is the rectangle ``origin + [0, width] × [0, height]``, or the
    simple polygon ``polygon`` (M, 2) (then width and height must be None). Every
    disc lies inside the region.

    Radii are drawn until the discs' total area reaches ``target_fraction`` × the
    region's area (this fixes N). Centres start uniformly at random in the region;
    the radii are then grown from half their size to full size while overlaps are
    relaxed, and relaxation continues until no overlap (pair or boundary) exceeds
    ``overlap_tol`` × rmin. A relaxation sweep pushes each overlapping pair apart
    by half the overlap each and each disc back inside the region, and moves the
    discs by these pushes plus 0.85 × their previous motion (heavy-ball momentum,
    reset whenever the motion opposes the pushes).

    The discs are listed as the lattices list theirs: in rows one mean diameter
    high, from the bottom up, x increasing along a row (see :func:`_in_rows`).
    Deterministic for a given ``seed``. ``target_fraction`` must lie in (0, 0.95];
    random packings jam near 0.82–0.84, and a fraction that cannot be reached
    raises :class:`tdem.InputError` after ``max_iter`` sweeps.

    Denser than jamming, the discs must overlap: raise ``overlap_tol`` (the largest
    overlap left, relative to ``rmin``) with the fraction. PCMM particles may
    overlap (the elements carry their interaction, and the contact law counts from
    the initial overlap), and a PCMM body needs the density: at 0.8 the voids
    between the discs leave holes in the element cover that soften the body. The
    relaxation stops as soon as no overlap exceeds ``overlap_tol``, so a tighter one
    gives more even overlaps where it can be reached. Measurements (jamming, counts,
    times, overlaps and element cover by seed): docs/pcmm.md, section Random
    packings: measurements.

    ``edge_centres=True`` first lines the boundary with discs whose centres lie on
    it, as the boundary nodes of a mesh: a disc on every vertex, and along each
    edge discs with radii drawn from the same range, as many as fit in a row of
    touching discs, then spread evenly to the edge's length (gaps below 2·rmax
    divided by their number). These discs stay where they are (they are listed
    first); the others are packed inside the region as above and kept clear of
    them. The area fraction then counts the part of each boundary disc inside the
    region (half a disc on an edge, the corner's angle on a vertex). Default off:
    the packing and its random stream are unchanged. ``edge_radius`` (m, with
    ``edge_centres``) gives the boundary discs that one radius instead of drawn ones,
    so that the packing's sides are flush: the tops of the discs along its top edge
    lie on one line (a footing set on it touches them all at once; drawn radii leave
    a relief of rmax − rmin).

    ``pcmm_tolerance=δ`` (the Eq. 1 tolerance of the PCMM material the discs are
    for) then fills the holes that the PCMM element cover of that δ leaves
    (:func:`fill_holes`; with ``edge_centres`` also at the boundary, whose discs'
    elements reach it): a few pores of a random packing are wider than the
    elements' rules bridge, and the body is softer and its stress off around them
    (measurements: docs/pcmm.md, section Random packings: measurements).
    """
    rmin, rmax, draw = _radii_source(rmin, rmax, grading, 2)
    overlap_tol = _positive("overlap_tol", overlap_tol)
    if pcmm_tolerance is not None:
        pcmm_tolerance = _nonnegative("pcmm_tolerance", pcmm_tolerance)
    tf = float(target_fraction)
    if not (0.0 < tf <= 0.95):
        raise InputError(f"target_fraction must lie in (0, 0.95], got {target_fraction!r}")
    poly = _region(width, height, origin, polygon)
    area = _polygon_area(poly)
    bb_lo, bb_hi = poly.min(axis=0), poly.max(axis=0)
    if np.min(bb_hi - bb_lo) < 2 * rmax:
        raise InputError(f"the region ({(bb_hi - bb_lo).tolist()} m across) is too small "
                         f"for discs of rmax={rmax!r}")
    rng = np.random.default_rng(seed)

    if edge_radius is not None:
        edge_radius = _positive("edge_radius", edge_radius)
        if not edge_centres:
            raise InputError(f"edge_radius={edge_radius!r} needs edge_centres=True (it is "
                             "the radius of the discs centred on the boundary)")
    if edge_centres:
        xb, rb, inside_area = _edge_discs(poly, rmin, rmax, rng, edge_radius)
    else:
        xb, rb, inside_area = np.zeros((0, 2)), np.zeros(0), 0.0
    nb = len(xb)
    target_area = tf * area - inside_area
    if target_area <= 0.0:
        raise InputError(f"the boundary discs alone cover more than target_fraction="
                         f"{target_fraction!r} of the region")

    # radii until the target area is reached
    mean_area = math.pi * (rmin * rmin + rmin * rmax + rmax * rmax) / 3.0
    est = min(int(target_area / mean_area * 1.1) + 16, 1_000_000)
    r = draw(rng, est)
    while np.sum(np.pi * r * r) < target_area:
        r = np.concatenate([r, draw(rng, est)])
    n = int(np.searchsorted(np.cumsum(np.pi * r * r), target_area)) + 1
    r = r[:n]

    # centres uniform in the region (rejection from the bounding box)
    x = np.zeros((0, 2))
    while len(x) < n:
        cand = rng.uniform(bb_lo, bb_hi, (2 * (n - len(x)) + 16, 2))
        sd, _ = _signed_distance(cand, poly)
        x = np.concatenate([x, cand[sd > 0]])
    x = x[:n]
    if nb:
        x = np.concatenate([xb, x])
        r = np.concatenate([rb, r])
        n = len(r)
    free = np.arange(n) >= nb           # the boundary discs do not move

    tol = overlap_tol * rmin
    skin = 0.5 * rmin
    h = 2 * rmax + skin
    scale = 0.5
    vel = np.zeros((n, 2))
    x_ref = None
    worst = np.inf
    for _ in range(int(max_iter)):
        if x_ref is None or np.max(np.sum((x - x_ref) ** 2, axis=1)) > (0.5 * skin) ** 2:
            i, j = _pairs(x, 2 * rmax + skin, h)
            if nb:
                both = ~free[i] & ~free[j]
                i, j = i[~both], j[~both]
            near_edge = np.nonzero((_signed_distance(x, poly)[0] < rmax + skin) & free)[0]
            x_ref = x.copy()
        rs = scale * r
        if nb:
            rs[:nb] = r[:nb]
        push, worst = _pair_push(x, rs, i, j, free)
        if len(near_edge):
            sd, inward = _signed_distance(x[near_edge], poly)
            pen = rs[near_edge] - sd
            out = pen > 0
            if out.any():
                worst = max(worst, float(pen[out].max()))
                push[near_edge[out]] += pen[out][:, None] * inward[out]
        if scale == 1.0 and worst <= tol:
            if pcmm_tolerance is not None:
                x, r = _fill(x, r, poly, pcmm_tolerance, rmin, rmax, overlap_tol,
                             not edge_centres)
            return _in_rows(x, r, nb)
        x, vel = _heavy_ball(x, vel, push)
        scale = min(1.0, scale + _GROWTH)
    raise _unreached(target_fraction, overlap_tol, max_iter, worst)


def _pair_push(x, rs, i, j, free=None):
    """The relaxation's pushes of a sweep: each overlapping pair (i, j) of radii ``rs``
    pushed apart by half its overlap each, all of it to a free particle against a
    fixed one (``free`` False: not moved); returns (push (N, dim), largest overlap)."""
    n, dim = x.shape
    d = x[j] - x[i]
    dist = np.sqrt(np.einsum("nk,nk->n", d, d))
    ov = rs[i] + rs[j] - dist
    hit = ov > 0
    push = np.zeros((n, dim))
    worst = 0.0
    if hit.any():
        worst = float(ov[hit].max())
        share = 0.5 if free is None else np.where(free[i[hit]] & free[j[hit]], 0.5, 1.0)
        s = (share * ov[hit] / np.maximum(dist[hit], 1e-300))[:, None] * d[hit]
        for k in range(dim):
            push[:, k] += np.bincount(j[hit], s[:, k], minlength=n) - np.bincount(
                i[hit], s[:, k], minlength=n)
        if free is not None:
            push[~free] = 0.0
    return push, worst


def _heavy_ball(x, vel, push):
    """One sweep of the heavy-ball relaxation, restarted when the motion turns against
    the push: the new (x, vel)."""
    if np.sum(push * vel) < 0.0:
        vel[:] = 0.0
    vel = _MOMENTUM * vel + push
    return x + vel, vel


def _unreached(target_fraction, overlap_tol, max_iter, worst):
    return InputError(f"target_fraction={target_fraction!r} could not be reached with "
                      f"overlaps of at most overlap_tol={overlap_tol!r} x rmin in {max_iter} "
                      f"sweeps (largest overlap {worst:.3g} m); lower it or raise "
                      f"overlap_tol")


def _radii_source(rmin, rmax, grading, dim):
    """(rmin, rmax, draw(rng, n)) of a packer: radii uniform in [rmin, rmax], or
    drawn from ``grading`` (its range then rmin and rmax, which must be left out)."""
    if grading is None:
        if rmin is None or rmax is None:
            raise InputError("give rmin and rmax, or a grading (tdem.grading), got "
                             f"rmin={rmin!r}, rmax={rmax!r}, grading=None")
        rmin, rmax = _radius_range(rmin, rmax)
        return rmin, rmax, lambda rng, n: rng.uniform(rmin, rmax, n)
    from .gradings import Grading
    if not isinstance(grading, Grading):
        raise InputError(f"grading must be a tdem.grading(...), got {grading!r}")
    if rmin is not None or rmax is not None:
        raise InputError(f"give rmin and rmax or a grading, not both: got rmin={rmin!r}, "
                         f"rmax={rmax!r} with {grading!r}")
    return grading.r_min, grading.r_max, lambda rng, n: grading.sample(n, rng=rng, dim=dim)


def _radius_range(rmin, rmax):
    rmin = _positive("rmin", rmin)
    rmax = _positive("rmax", rmax)
    if rmax < rmin:
        raise InputError(f"rmax must be >= rmin, got rmin={rmin!r}, rmax={rmax!r}")
    return rmin, rmax


def fill_holes(positions, radii, tolerance, rmin, rmax, width=None, height=None,
               origin=(0.0, 0.0), polygon=None, overlap_tol=0.7, border=False, rounds=5):
    """Discs added into the holes of the PCMM element cover of a packing.

    The elements of the discs (:class:`physics.pcmm.ElementSystem`, Eqs. 1–3 with
    the tolerance δ = ``tolerance``) are laid on a grid of points rmin/4 apart over
    the region (the rectangle ``origin + [0, width] × [0, height]`` or the polygon);
    at the uncovered points the clearance to the nearest disc is measured, and where
    a disc of radius in [rmin, rmax] fits inside the region with an overlap of at
    most ``overlap_tol`` × rmin, one is put, largest clearance first, one per hole
    (new discs at least 2·rmax apart), its radius clearance + ½·overlap_tol·rmin
    clipped to the range. A hole is an uncovered point with covered points on
    both sides of it along x and along y; ``border=True`` counts every uncovered
    point of the region, also the strip between the outermost discs and the
    boundary (what a packing with discs centred on the boundary, whose elements
    reach it, wants: :func:`random` with ``edge_centres`` does so). Repeated, at
    most ``rounds`` times, until no hole takes a disc. The discs given are not
    moved; the added ones follow them (:func:`random` with ``pcmm_tolerance`` lists
    its discs in rows again after it). Returns (positions, radii)."""
    try:
        x = np.array(positions, dtype=float)
        r = np.array(radii, dtype=float)
    except (TypeError, ValueError):
        raise InputError("positions and radii must be numbers") from None
    if x.ndim != 2 or x.shape[1] != 2:
        raise InputError(f"positions must have shape (N, 2), got shape {x.shape}")
    if r.shape not in ((), (len(x),)):
        raise InputError(f"radii must be a number or {len(x)} numbers, got shape {r.shape}")
    r = np.broadcast_to(r, (len(x),)).copy()
    rmin, rmax = _radius_range(rmin, rmax)
    tolerance = _nonnegative("tolerance", tolerance)
    overlap_tol = _positive("overlap_tol", overlap_tol)
    if not (isinstance(rounds, (int, np.integer)) and rounds >= 1):
        raise InputError(f"rounds must be a whole number >= 1, got {rounds!r}")
    poly = _region(width, height, origin, polygon)
    x, r = _fill(x, r, poly, tolerance, rmin, rmax, overlap_tol, not border, rounds)
    return x, r


def _fill(x, r, poly, tolerance, rmin, rmax, overlap_tol, enclosed, rounds=5):
    """:func:`fill_holes` on the region ``poly``; returns (x, r)."""
    from physics.pcmm import ElementSystem       # the rules of the elements
    h = 0.25 * rmin
    for _ in range(int(rounds)):
        tri = ElementSystem(x, r, tolerance).build().numpy()["triangles"]
        q = _uncovered(x, tri, poly, h, enclosed)
        if len(q) == 0:
            break
        sd, _ = _signed_distance(q, poly)
        q, sd = q[sd >= rmin], sd[sd >= rmin]
        clear = _clearance(q, x, r, 2.0 * rmax)
        rr = np.clip(clear + 0.5 * overlap_tol * rmin, rmin, rmax)
        fits = (clear >= (1.0 - overlap_tol) * rmin) & (sd >= rr)
        order = np.flatnonzero(fits)[np.argsort(-clear[fits], kind="stable")]
        new, taken = [], {}                 # taken: grid cell (side 2 rmax) -> new discs
        cells = np.floor(q / (2.0 * rmax)).astype(np.int64)
        for k in order:
            cx, cy = cells[k]
            near = (m for ox in (-1, 0, 1) for oy in (-1, 0, 1)
                    for m in taken.get((cx + ox, cy + oy), ()))
            if all((q[k, 0] - q[m, 0]) ** 2 + (q[k, 1] - q[m, 1]) ** 2 >= (2 * rmax) ** 2
                   for m in near):
                new.append(k)
                taken.setdefault((cx, cy), []).append(k)
        if not new:
            break
        x = np.concatenate([x, q[new]])
        r = np.concatenate([r, rr[new]])
    return x, r


def _uncovered(x, tri, poly, h, enclosed):
    """The points of a grid of spacing h over the region's bounding box that lie
    inside the region and in no triangle (T, 3) of the points x; if ``enclosed``,
    only those with covered points on both sides along both grid directions."""
    lo, hi = poly.min(axis=0), poly.max(axis=0)
    nx, ny = (np.ceil((hi - lo) / h).astype(np.int64) + 1)
    covered = np.zeros((nx, ny), bool)
    tri = np.asarray(tri, dtype=np.int64).reshape(-1, 3)
    for c0 in range(0, len(tri), 5000):           # (bounded memory)
        p = x[tri[c0:c0 + 5000]]                                # (T, 3, 2)
        b0 = np.maximum(np.floor((p.min(axis=1) - lo) / h).astype(np.int64), 0)
        b1 = np.minimum(np.ceil((p.max(axis=1) - lo) / h).astype(np.int64), [nx - 1, ny - 1])
        span = np.maximum(b1 - b0 + 1, 0)
        cnt = span[:, 0] * span[:, 1]
        t = np.repeat(np.arange(len(p)), cnt)
        k = np.arange(cnt.sum()) - np.repeat(np.cumsum(cnt) - cnt, cnt)
        gx = b0[t, 0] + k // span[t, 1]
        gy = b0[t, 1] + k % span[t, 1]
        g = lo + np.stack([gx, gy], axis=1) * h
        a, b, c = p[t, 0], p[t, 1], p[t, 2]
        d1, d2, d3 = _side(a, b, g), _side(b, c, g), _side(c, a, g)
        inside = ((d1 >= 0) & (d2 >= 0) & (d3 >= 0)) | ((d1 <= 0) & (d2 <= 0) & (d3 <= 0))
        covered[gx[inside], gy[inside]] = True
    hole = ~covered
    if enclosed:
        # covered points on all four sides along the grid lines (the strip between
        # the outermost discs and the boundary is open towards the boundary)
        for axis in (0, 1):
            for flip in (False, True):
                c = np.flip(covered, axis) if flip else covered
                seen = np.maximum.accumulate(c, axis=axis)
                seen = np.flip(seen, axis) if flip else seen
                hole &= seen
    gx, gy = np.nonzero(hole)
    g = lo + np.stack([gx, gy], axis=1) * h
    sd, _ = _signed_distance(g, poly)
    return g[sd > 0]


def _side(u, v, w):
    """Twice the signed area of the triangles (u, v, w), row by row."""
    return (v[:, 0] - u[:, 0]) * (w[:, 1] - u[:, 1]) - (v[:, 1] - u[:, 1]) * (w[:, 0] - u[:, 0])


def _clearance(q, x, r, h):
    """Distance from each point q to the nearest disc surface among the discs in the
    3 × 3 cells of side h around it (h where there is none)."""
    out = np.full(len(q), float(h))
    if len(q) == 0 or len(x) == 0:
        return out
    lo = np.minimum(x.min(axis=0), q.min(axis=0))
    cx = np.floor((x - lo) / h).astype(np.int64)
    cq = np.floor((q - lo) / h).astype(np.int64)
    ny = int(max(cx[:, 1].max(), cq[:, 1].max())) + 3
    key = (cx[:, 0] + 1) * ny + (cx[:, 1] + 1)
    order = np.argsort(key, kind="stable")
    skey = key[order]
    for ox in (-1, 0, 1):
        for oy in (-1, 0, 1):
            k = (cq[:, 0] + 1 + ox) * ny + (cq[:, 1] + 1 + oy)
            first = np.searchsorted(skey, k, "left")
            m = np.searchsorted(skey, k, "right") - first
            pt = np.repeat(np.arange(len(q)), m)
            disc = order[np.repeat(first, m) + np.arange(m.sum())
                         - np.repeat(np.cumsum(m) - m, m)]
            d = np.hypot(q[pt, 0] - x[disc, 0], q[pt, 1] - x[disc, 1]) - r[disc]
            np.minimum.at(out, pt, d)
    return out


def _in_rows(x, r, nb):
    """x and r with the discs after the first ``nb`` reordered into rows one mean
    diameter high, bottom to top, x increasing along each row. Discs close in space
    are then close in the arrays, as in the lattices: the kernels go over each
    particle's neighbours, and how well the memory caches serve them depends on it
    (in random order a PCMM step takes about 1.6 times as long)."""
    if len(r) - nb < 2:
        return x, r
    y = x[nb:, 1]
    row = np.floor((y - y.min()) / (2.0 * r[nb:].mean()))
    keep = np.concatenate([np.arange(nb), nb + np.lexsort((x[nb:, 0], row))])
    return x[keep], r[keep]


def _edge_discs(poly, rmin, rmax, rng, radius=None):
    """Discs centred on the boundary of ``poly``: one on each vertex, and along each
    edge as many as fit in a row of touching discs between the two vertex discs,
    spread evenly to the edge's length; radii drawn from [rmin, rmax], or all
    ``radius``. Returns (centres, radii, the discs' area inside the polygon)."""
    m = len(poly)

    def draw(k=None):
        if radius is not None:
            return float(radius) if k is None else np.full(k, float(radius))
        return rng.uniform(rmin, rmax) if k is None else rng.uniform(rmin, rmax, k)

    rv = draw(m)
    xs, rs = [], []
    inside = 0.0
    for k in range(m):
        a, b = poly[k], poly[(k + 1) % m]
        e_in, e_out = poly[k - 1] - a, b - a
        ang = math.atan2(e_in[0] * e_out[1] - e_in[1] * e_out[0], float(e_in @ e_out))
        ang = ang if ang > 0 else ang + 2 * math.pi       # interior angle at vertex a
        inside += 0.5 * ang * rv[k] ** 2
        xs.append(a[None])
        rs.append(rv[k:k + 1])
        length = float(np.linalg.norm(b - a))
        r_end = rv[(k + 1) % m]
        ri = []
        span = rv[k] + r_end
        while True:
            new = draw()
            if span + 2 * new > length:
                break
            ri.append(new)
            span += 2 * new
        if span > length:
            raise InputError(f"a polygon edge of length {length:.3g} m is too short for "
                             f"discs centred on both its ends")
        if ri:
            ri = np.asarray(ri)
            # centre distances from a: r_a + r_1, then r_i + r_{i+1}, spread to the length
            t = rv[k] + np.cumsum(np.concatenate([[0.0], ri[:-1] + ri[1:]])) + ri[0]
            t = t * (length / span)
            xs.append(a + t[:, None] * (b - a) / length)
            rs.append(ri)
            inside += 0.5 * math.pi * float(np.sum(ri * ri))
    return np.concatenate(xs), np.concatenate(rs), inside


def largest_overlap(positions, radii, among=None):
    """The largest overlap of two discs relative to the smaller radius, and the pair:
    (u / min(R_i, R_j), i, j), (0.0, -1, -1) when none touch; ``among`` (a boolean
    mask): only pairs with at least one disc in it."""
    x = np.asarray(positions, dtype=float)
    x = x.reshape(-1, x.shape[-1] if x.ndim == 2 and x.shape[-1] == 3 else 2)
    r = np.asarray(radii, dtype=float).reshape(-1)
    if len(x) < 2:
        return 0.0, -1, -1
    h = 2.0 * float(r.max())
    if x.shape[1] == 3:
        from scipy.spatial import cKDTree

        ij = cKDTree(x).query_pairs(h, output_type="ndarray")
        i, j = ij[:, 0], ij[:, 1]
    else:
        i, j = _pairs(x, h, h)
    if among is not None:
        keep = among[i] | among[j]
        i, j = i[keep], j[keep]
    rel = (r[i] + r[j] - np.linalg.norm(x[j] - x[i], axis=1)) / np.minimum(r[i], r[j])
    if rel.size == 0 or rel.max() <= 0.0:
        return 0.0, -1, -1
    k = int(np.argmax(rel))
    return float(rel[k]), int(i[k]), int(j[k])


def random_orientations(n, seed=0):
    """(n, 4) unit quaternions (w, x, y, z) uniformly distributed over the rotations
    (Shoemake 1992), for ``add_particles(..., orientation=)`` in 3D."""
    n = int(n)
    if n < 0:
        raise InputError(f"n must be >= 0, got {n!r}")
    rng = np.random.default_rng(seed)
    u1, u2, u3 = rng.random((3, n))
    a, b = np.sqrt(1.0 - u1), np.sqrt(u1)
    return np.stack([b * np.cos(2 * np.pi * u3), a * np.sin(2 * np.pi * u2),
                     a * np.cos(2 * np.pi * u2), b * np.sin(2 * np.pi * u3)], axis=1)


def lattice3d(lower, upper, radius, kind="fcc"):
    """Centres of touching spheres of ``radius`` on a ``"fcc"`` or ``"cubic"`` lattice
    filling the box [lower + radius, upper − radius] (3D)."""
    lo = np.asarray(lower, dtype=float).reshape(3) + radius
    hi = np.asarray(upper, dtype=float).reshape(3) - radius
    if not np.all(hi >= lo):
        raise InputError(f"upper must exceed lower by at least a diameter on every axis, got "
                         f"lower={lower!r}, upper={upper!r}, radius={radius!r}")
    if kind == "cubic":
        cell, basis = 2.0 * radius, np.zeros((1, 3))
    elif kind == "fcc":
        cell = 2.0 * math.sqrt(2.0) * radius
        basis = np.array([[0, 0, 0], [0.5, 0.5, 0], [0.5, 0, 0.5], [0, 0.5, 0.5]])
    else:
        raise InputError(f"kind must be 'fcc' or 'cubic', got {kind!r}")
    n = np.floor((hi - lo) / cell).astype(int) + 1
    ijk = np.stack(np.meshgrid(*[np.arange(k) for k in n], indexing="ij"), -1).reshape(-1, 3)
    pts = ((ijk[:, None, :] + basis[None]) * cell).reshape(-1, 3) + lo
    return pts[np.all(pts <= hi + 1e-12 * cell, axis=1)]


def random3d(lower, upper, rmin=None, rmax=None, seed=0, target_fraction=0.5,
             overlap_tol=1e-3, max_iter=20000, grading=None):
    """Random packing of spheres with radii uniform in [rmin, rmax] (or drawn from
    ``grading``, a :func:`tdem.grading`, by its mass curve; rmin and rmax left out) in the box
    [lower, upper] (3D), as :func:`random` packs discs: radii drawn until the spheres'
    volume reaches ``target_fraction`` × the box's, centres uniform in the box, the
    radii grown from half size while overlaps (pairs, and spheres against the box's
    faces) are relaxed by heavy-ball sweeps, until no overlap exceeds ``overlap_tol``
    × rmin. Returns (positions (N, 3), radii (N,)), listed from the bottom up (by z);
    deterministic for a ``seed``.

    ``target_fraction`` must lie in (0, 0.62]: random packings of spheres jam near
    0.64, less against walls (how fast and how far it packs: docs/guide.md, section
    Random packings of spheres: measurements); a fraction it cannot reach raises
    :class:`tdem.InputError` after ``max_iter`` sweeps, naming the largest overlap
    left. Such a packing is at rest, its spheres barely touching: settle it under
    gravity or compress it for a bed (as PFC's ``ball distribute`` and Yade's
    ``makeCloud`` are used)."""
    from scipy.spatial import cKDTree
    rmin, rmax, draw = _radii_source(rmin, rmax, grading, 3)
    overlap_tol = _positive("overlap_tol", overlap_tol)
    tf = float(target_fraction)
    if not (0.0 < tf <= 0.62):
        raise InputError(f"target_fraction must lie in (0, 0.62], got {target_fraction!r}")
    try:
        lo = np.asarray(lower, dtype=float).reshape(3)
        hi = np.asarray(upper, dtype=float).reshape(3)
    except (TypeError, ValueError):
        raise InputError(f"lower and upper must be 3 numbers each, got lower={lower!r}, "
                         f"upper={upper!r}") from None
    if not (np.all(np.isfinite([lo, hi])) and np.all(hi - lo >= 2 * rmax)):
        raise InputError(f"upper must exceed lower by at least 2 rmax on every axis, got "
                         f"lower={lower!r}, upper={upper!r}, rmax={rmax!r}")
    volume = float(np.prod(hi - lo))
    rng = np.random.default_rng(seed)
    sphere = 4.0 / 3.0 * math.pi
    mean_vol = sphere * (rmax ** 4 - rmin ** 4) / (4.0 * (rmax - rmin)) if rmax > rmin \
        else sphere * rmin ** 3
    est = min(int(tf * volume / mean_vol * 1.1) + 16, 1_000_000)
    r = draw(rng, est)
    while np.sum(sphere * r ** 3) < tf * volume:
        r = np.concatenate([r, draw(rng, est)])
    n = int(np.searchsorted(np.cumsum(sphere * r ** 3), tf * volume)) + 1
    r = r[:n]
    x = rng.uniform(lo + rmin, hi - rmin, (n, 3))
    tol = overlap_tol * rmin
    skin = 0.5 * rmin
    scale = 0.5
    vel = np.zeros((n, 3))
    x_ref = None
    worst = np.inf
    for _ in range(int(max_iter)):
        if x_ref is None or np.max(np.sum((x - x_ref) ** 2, axis=1)) > (0.5 * skin) ** 2:
            pairs = cKDTree(x).query_pairs(2 * rmax + skin, output_type="ndarray")
            i, j = pairs[:, 0], pairs[:, 1]
            x_ref = x.copy()
        rs = scale * r
        push, worst = _pair_push(x, rs, i, j)
        # the box's faces: back inside by the penetration
        below = rs[:, None] - (x - lo)
        above = rs[:, None] - (hi - x)
        worst = max(worst, float(below.max()), float(above.max()))
        push += np.maximum(below, 0.0) - np.maximum(above, 0.0)
        if scale == 1.0 and worst <= tol:
            order = np.lexsort((x[:, 0], x[:, 1], x[:, 2]))
            return x[order], r[order]
        x, vel = _heavy_ball(x, vel, push)
        scale = min(1.0, scale + _GROWTH)
    raise _unreached(target_fraction, overlap_tol, max_iter, worst)

