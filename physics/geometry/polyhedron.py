"""Overlap of two convex polyhedra (Chen's polyhedral DEM), in fixed-size local buffers.

The overlap O = A ∩ B of two convex bodies, each given by its vertices, its face planes
n·x <= d (outward unit normals) and its edges (two vertices, two faces), is a convex
polyhedron whose vertices are

- the vertices of A inside B, and of B inside A;
- the points where an edge of A crosses a face plane of B inside B, and the reverse.

Each such point carries the faces of A and of B it lies on (64-bit masks, within a
tolerance). The face of O on a face plane f is the convex polygon of the points that
lie on f, ordered by angle about its normal; from the faces follow exactly (round-off
apart) the overlap's volume and centroid (tetrahedra from an inner point) and the area
vectors: S_A, the sum over O's faces on A's surface (∂V/∂x_A, pointing out of A into
B), and S_B the same for B. A face that lies on both surfaces (two coplanar faces, as in
a column of aligned cubes) counts once in the volume and in neither S.

The contact normal from A to B is (S_A − S_B)/|S_A − S_B| (the two agree when no face
is shared) and |S| = |S_A − S_B|/2 its projected area: dV/dt = −|S| v_n.

A body is a *polyhedron* of the shape tables (:mod:`physics.polyhedron`: vertices and
planes turned by R and moved by t) or the *prism* of a mesh triangle (a, b, c): the
half-space behind the triangle's plane (away from the particle), cut by the three
planes through its edges normal to it and by a bottom plane at depth D: its overlap
with a particle is the part of the particle behind that triangle. Its face 0 is the
triangle's plane, so that S of that face alone is the projected area of the cut.

Nothing is allocated: at most :data:`MAXP` points per overlap and :data:`MAXFP` per face;
an overlap that needs more is reported (``status`` 2) and counted by the engine.
"""
import taichi as ti

from physics.geometry.ellipsoid import rotation
from physics.polyhedron import (MAX_FACES, MAX_VERTICES, PI_EDGES, PT_LENGTH, PT_NE,
                                PT_NF, PT_NV, PT_PLANES, PT_VERTS)

MAXP = 64        # points of one overlap polyhedron
MAXFP = 32       # points on one of its faces
POLY, PRISM = 0, 1

# the prism's edges: (vertex, vertex, face, face); vertices 0-2 the triangle, 3-5 below
_PRISM_EDGES = ((0, 1, 0, 2), (1, 2, 0, 3), (2, 0, 0, 4),
                (3, 4, 1, 2), (4, 5, 1, 3), (5, 3, 1, 4),
                (0, 3, 4, 2), (1, 4, 2, 3), (2, 5, 3, 4))


@ti.func
def load_poly(ptab: ti.template(), s, R, t):
    """(nv, nf, vertices (3·MAX_VERTICES), planes (4·MAX_FACES)) of shape s of the table
    turned by R and moved by t."""
    nv = ti.cast(ptab[s, PT_NV], ti.i32)
    nf = ti.cast(ptab[s, PT_NF], ti.i32)
    V = ti.Vector([0.0] * (3 * MAX_VERTICES))
    P = ti.Vector([0.0] * (4 * MAX_FACES))
    for k in range(nv):
        b = PT_VERTS + 3 * k
        v = t + R @ ti.Vector([ptab[s, b], ptab[s, b + 1], ptab[s, b + 2]])
        for c in ti.static(range(3)):
            V[3 * k + c] = v[c]
    for f in range(nf):
        b = PT_PLANES + 4 * f
        n = R @ ti.Vector([ptab[s, b], ptab[s, b + 1], ptab[s, b + 2]])
        for c in ti.static(range(3)):
            P[4 * f + c] = n[c]
        P[4 * f + 3] = ptab[s, b + 3] + n.dot(t)
    return nv, nf, V, P


@ti.func
def load_prism(a, b, c, front, depth):
    """(6, 5, vertices, planes) of the prism behind triangle abc: ``front`` the unit
    normal of the triangle's plane on the particle's side, ``depth`` its depth."""
    V = ti.Vector([0.0] * 18)
    P = ti.Vector([0.0] * 20)
    corners = ti.Matrix.rows([a, b, c])
    for k in ti.static(range(3)):
        for q in ti.static(range(3)):
            V[3 * k + q] = corners[k, q]
            V[9 + 3 * k + q] = corners[k, q] - depth * front[q]
    for q in ti.static(range(3)):
        P[q] = front[q]
        P[4 + q] = -front[q]
    P[3] = front.dot(a)
    P[7] = -front.dot(a) + depth
    for k in ti.static(range(3)):
        p = ti.Vector([corners[k, 0], corners[k, 1], corners[k, 2]])
        q2 = ti.Vector([corners[(k + 1) % 3, 0], corners[(k + 1) % 3, 1],
                        corners[(k + 1) % 3, 2]])
        o = ti.Vector([corners[(k + 2) % 3, 0], corners[(k + 2) % 3, 1],
                       corners[(k + 2) % 3, 2]])
        m = (q2 - p).cross(front).normalized()
        if m.dot(o - p) > 0.0:
            m = -m
        for q in ti.static(range(3)):
            P[8 + 4 * k + q] = m[q]
        P[8 + 4 * k + 3] = m.dot(p)
    return 6, 5, V, P


@ti.func
def _vec(V: ti.template(), k):
    return ti.Vector([V[3 * k], V[3 * k + 1], V[3 * k + 2]])


@ti.func
def _plane(P: ti.template(), f):
    return ti.Vector([P[4 * f], P[4 * f + 1], P[4 * f + 2]]), P[4 * f + 3]


@ti.func
def _edge(kind: ti.template(), pint: ti.template(), s, e):
    v0, v1, f0, f1 = 0, 0, 0, 0
    if ti.static(kind == POLY):
        b = PI_EDGES + 4 * e
        v0 = pint[s, b]
        v1 = pint[s, b + 1]
        f0 = pint[s, b + 2]
        f1 = pint[s, b + 3]
    else:
        table = ti.Vector([c for edge in ti.static(_PRISM_EDGES) for c in edge], dt=ti.i32)
        v0 = table[4 * e]
        v1 = table[4 * e + 1]
        f0 = table[4 * e + 2]
        f1 = table[4 * e + 3]
    return v0, v1, f0, f1


@ti.func
def _bit(f):
    return ti.cast(1, ti.i64) << ti.cast(f, ti.i64)


@ti.func
def _add(X: ti.template(), MA: ti.template(), MB: ti.template(), count: ti.template(),
         over: ti.template(), x, ma, mb, tol2):
    """Add point x with its face masks, merged with a point already there within
    sqrt(tol2)."""
    found = -1
    for q in range(count):
        if (_vec(X, q) - x).norm_sqr() <= tol2:
            found = q
            break
    if found >= 0:
        MA[found] |= ma
        MB[found] |= mb
    elif count < MAXP:
        for c in ti.static(range(3)):
            X[3 * count + c] = x[c]
        MA[count] = ma
        MB[count] = mb
        count += 1
    else:
        over = 1


@ti.func
def _inside(P: ti.template(), nf, x, tol, skip):
    """(inside all planes but ``skip`` within tol, mask of the planes x lies on)."""
    inside = True
    mask = ti.cast(0, ti.i64)
    for f in range(nf):
        if f != skip:
            n, d = _plane(P, f)
            s = n.dot(x) - d
            if s > tol:
                inside = False
                break
            if s >= -tol:
                mask |= _bit(f)
    return inside, mask


@ti.func
def _separated(PA: ti.template(), nfa, VB: ti.template(), nvb, tol):
    """Whether a face plane of A has every vertex of B outside (the extremal-projection
    reject)."""
    sep = False
    for f in range(nfa):
        n, d = _plane(PA, f)
        out = True
        for k in range(nvb):
            if n.dot(_vec(VB, k)) - d <= tol:
                out = False
                break
        if out:
            sep = True
            break
    return sep


@ti.func
def _crossings(X: ti.template(), MA: ti.template(), MB: ti.template(), count: ti.template(),
               over: ti.template(), kind: ti.template(), pint: ti.template(), s, ne,
               V: ti.template(), Po: ti.template(), nfo, tol, tol2, swap: ti.template()):
    """Points where the edges of one body (vertices V) cross the planes Po of the other
    inside it; ``swap``: the edges are B's (masks exchanged)."""
    for e in range(ne):
        v0, v1, f0, f1 = _edge(kind, pint, s, e)
        p = _vec(V, v0)
        q = _vec(V, v1)
        for f in range(nfo):
            n, d = _plane(Po, f)
            sp = n.dot(p) - d
            sq = n.dot(q) - d
            if (sp < -tol and sq > tol) or (sp > tol and sq < -tol):
                x = p + (q - p) * (sp / (sp - sq))
                ins, mo = _inside(Po, nfo, x, tol, f)
                if ins:
                    own = _bit(f0) | _bit(f1)
                    mo |= _bit(f)
                    if ti.static(swap):
                        _add(X, MA, MB, count, over, x, mo, own, tol2)
                    else:
                        _add(X, MA, MB, count, over, x, own, mo, tol2)


@ti.func
def _corners(X: ti.template(), MA: ti.template(), MB: ti.template(), count: ti.template(),
             over: ti.template(), V: ti.template(), nv, P: ti.template(), nf,
             Po: ti.template(), nfo, tol, tol2, swap: ti.template()):
    """The vertices of one body (vertices V, planes P) inside the other (planes Po)."""
    for k in range(nv):
        x = _vec(V, k)
        ins, mo = _inside(Po, nfo, x, tol, -1)
        if ins:
            own = ti.cast(0, ti.i64)
            for f in range(nf):
                n, d = _plane(P, f)
                if ti.abs(n.dot(x) - d) <= tol:
                    own |= _bit(f)
            if ti.static(swap):
                _add(X, MA, MB, count, over, x, mo, own, tol2)
            else:
                _add(X, MA, MB, count, over, x, own, mo, tol2)


@ti.func
def _face(X: ti.template(), M: ti.template(), count, f, n, ref, over: ti.template()):
    """O's face on plane f (normal n): (area vector, volume of the cone from ``ref``,
    its first moment about ``ref``)."""
    idx = ti.Vector([0] * MAXFP)
    ang = ti.Vector([0.0] * MAXFP)
    m = 0
    for q in range(count):
        if M[q] & _bit(f):
            if m < MAXFP:
                idx[m] = q
                m += 1
            else:
                over = 1
    area = ti.Vector([0.0, 0.0, 0.0])
    vol = 0.0
    mom = ti.Vector([0.0, 0.0, 0.0])
    if m >= 3:
        c = ti.Vector([0.0, 0.0, 0.0])
        for k in range(m):
            c += _vec(X, idx[k])
        c /= m
        # a basis of the plane: u along the farthest point from c
        u = ti.Vector([0.0, 0.0, 0.0])
        for k in range(m):
            r = _vec(X, idx[k]) - c
            if r.norm_sqr() > u.norm_sqr():
                u = r
        u = u.normalized()
        w = n.cross(u)
        for k in range(m):
            r = _vec(X, idx[k]) - c
            ang[k] = ti.atan2(r.dot(w), r.dot(u))
        # insertion sort by angle
        for k in range(1, m):
            a = ang[k]
            i = idx[k]
            j = k - 1
            while j >= 0 and ang[j] > a:
                ang[j + 1] = ang[j]
                idx[j + 1] = idx[j]
                j -= 1
            ang[j + 1] = a
            idx[j + 1] = i
        h = c - ref
        for k in range(m):
            p = _vec(X, idx[k]) - c
            q = _vec(X, idx[(k + 1) % m]) - c
            cr = p.cross(q)
            area += 0.5 * cr
            v = h.dot(cr) / 6.0
            vol += v
            mom += v * 0.25 * (3.0 * h + p + q)
    return area, vol, mom


@ti.func
def overlap(kind_a: ti.template(), sa, nva, nfa, nea, VA: ti.template(), PA: ti.template(),
            kind_b: ti.template(), sb, nvb, nfb, neb, VB: ti.template(), PB: ti.template(),
            pint: ti.template(), tol):
    """The overlap of bodies A and B (module docstring): (volume, centroid, S_A, S_B,
    area vector of B's face 0, status: 0 apart, 1 overlapping, 2 a buffer overflowed).
    ``tol`` is the length within which a point lies on a plane."""
    vol = 0.0
    cen = ti.Vector([0.0, 0.0, 0.0])
    sA = ti.Vector([0.0, 0.0, 0.0])
    sB = ti.Vector([0.0, 0.0, 0.0])
    sB0 = ti.Vector([0.0, 0.0, 0.0])
    status = 0
    if not (_separated(PA, nfa, VB, nvb, tol) or _separated(PB, nfb, VA, nva, tol)):
        X = ti.Vector([0.0] * (3 * MAXP))
        MA = ti.Vector([0] * MAXP, dt=ti.i64)
        MB = ti.Vector([0] * MAXP, dt=ti.i64)
        count = 0
        over = 0
        tol2 = (4.0 * tol) ** 2
        _corners(X, MA, MB, count, over, VA, nva, PA, nfa, PB, nfb, tol, tol2, False)
        _corners(X, MA, MB, count, over, VB, nvb, PB, nfb, PA, nfa, tol, tol2, True)
        _crossings(X, MA, MB, count, over, kind_a, pint, sa, nea, VA, PB, nfb, tol, tol2, False)
        _crossings(X, MA, MB, count, over, kind_b, pint, sb, neb, VB, PA, nfa, tol, tol2, True)
        if count >= 4:
            ref = ti.Vector([0.0, 0.0, 0.0])
            for q in range(count):
                ref += _vec(X, q)
            ref /= count
            mom = ti.Vector([0.0, 0.0, 0.0])
            for f in range(nfa):
                n, d = _plane(PA, f)
                a, v, m = _face(X, MA, count, f, n, ref, over)
                shared = False
                if v != 0.0:
                    for g in range(nfb):
                        nb, db = _plane(PB, g)
                        if nb.dot(n) > 1.0 - 1e-9 and ti.abs(db - d) <= tol:
                            shared = True
                    if not shared:
                        sA += a
                vol += v
                mom += m
            for g in range(nfb):
                nb, db = _plane(PB, g)
                shared = False
                for f in range(nfa):
                    n, d = _plane(PA, f)
                    if nb.dot(n) > 1.0 - 1e-9 and ti.abs(db - d) <= tol:
                        shared = True
                if not shared:
                    a, v, m = _face(X, MB, count, g, nb, ref, over)
                    sB += a
                    vol += v
                    mom += m
                    if g == 0:
                        sB0 = a
            if vol > 0.0:
                cen = ref + mom / vol
                status = 1
        if over != 0:
            status = 2
    return vol, cen, sA, sB, sB0, status


# --------------------------------------------------------------- host entry (tests)
@ti.kernel
def _overlap_pair(ptab: ti.types.ndarray(), pint: ti.types.ndarray(),
                  x: ti.types.ndarray(), q: ti.types.ndarray(), out: ti.types.ndarray()):
    for _ in range(1):
        Ra = rotation(ti.Vector([q[0, c] for c in ti.static(range(4))]))
        Rb = rotation(ti.Vector([q[1, c] for c in ti.static(range(4))]))
        ta = ti.Vector([x[0, c] for c in ti.static(range(3))])
        tb = ti.Vector([x[1, c] for c in ti.static(range(3))])
        nva, nfa, VA, PA = load_poly(ptab, 0, Ra, ta)
        nvb, nfb, VB, PB = load_poly(ptab, 1, Rb, tb)
        nea = ti.cast(ptab[0, PT_NE], ti.i32)
        neb = ti.cast(ptab[1, PT_NE], ti.i32)
        tol = 1e-9 * (ptab[0, PT_LENGTH] + ptab[1, PT_LENGTH])
        vol, cen, sA, sB, sB0, status = overlap(POLY, 0, nva, nfa, nea, VA, PA, POLY, 1, nvb,
                                                 nfb, neb, VB, PB, pint, tol)
        vals = ti.Vector([vol, cen[0], cen[1], cen[2], sA[0], sA[1], sA[2], sB[0], sB[1],
                          sB[2], ti.cast(status, ti.f64)])
        for c in ti.static(range(11)):
            out[c] = vals[c]


@ti.kernel
def _overlap_prism(ptab: ti.types.ndarray(), pint: ti.types.ndarray(),
                   x: ti.types.ndarray(), q: ti.types.ndarray(), tri: ti.types.ndarray(),
                   depth: ti.f64, out: ti.types.ndarray()):
    for _ in range(1):
        Ra = rotation(ti.Vector([q[0, c] for c in ti.static(range(4))]))
        ta = ti.Vector([x[0, c] for c in ti.static(range(3))])
        nva, nfa, VA, PA = load_poly(ptab, 0, Ra, ta)
        nea = ti.cast(ptab[0, PT_NE], ti.i32)
        a = ti.Vector([tri[0, c] for c in ti.static(range(3))])
        b = ti.Vector([tri[1, c] for c in ti.static(range(3))])
        c3 = ti.Vector([tri[2, c] for c in ti.static(range(3))])
        nf = (b - a).cross(c3 - a).normalized()
        if (ta - a).dot(nf) < 0.0:
            nf = -nf
        nvb, nfb, VB, PB = load_prism(a, b, c3, nf, depth)
        tol = 1e-9 * ptab[0, PT_LENGTH]
        vol, cen, sA, sB, sB0, status = overlap(POLY, 0, nva, nfa, nea, VA, PA, PRISM, 0, nvb,
                                                 nfb, 9, VB, PB, pint, tol)
        vals = ti.Vector([vol, cen[0], cen[1], cen[2], sA[0], sA[1], sA[2], sB0[0], sB0[1],
                          sB0[2], ti.cast(status, ti.f64)])
        for c in ti.static(range(11)):
            out[c] = vals[c]


def overlap_of(shape_a, x_a, q_a, shape_b, x_b, q_b):
    """The overlap of two placed polyhedra, computed by the engine's function:
    {"volume", "centroid", "s_a", "s_b", "status"} (host entry for tests and checks)."""
    import numpy as np

    from tdem.core.backend import init
    init()
    rows = [shape_a.table_rows(), shape_b.table_rows()]
    out = np.zeros(11)
    _overlap_pair(np.stack([r[0] for r in rows]), np.stack([r[1] for r in rows]),
                  np.array([x_a, x_b], float), np.array([q_a, q_b], float), out)
    return {"volume": out[0], "centroid": out[1:4], "s_a": out[4:7], "s_b": out[7:10],
            "status": int(out[10])}


def prism_overlap_of(shape, x, q, triangle, depth):
    """The part of a placed polyhedron behind triangle (3, 3) (the side away from its
    centroid), down to ``depth``: {"volume", "centroid", "s_a", "cut" (the area vector
    of the cut on the triangle's plane), "status"}."""
    import numpy as np

    from tdem.core.backend import init
    init()
    f, i = shape.table_rows()
    out = np.zeros(11)
    _overlap_prism(f[None], i[None], np.array([x], float), np.array([q], float),
                   np.asarray(triangle, float), float(depth), out)
    return {"volume": out[0], "centroid": out[1:4], "s_a": out[4:7], "cut": out[7:10],
            "status": int(out[10])}
