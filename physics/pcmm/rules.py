"""The element-creation rules of Feng, Li & Oñate (2015) as Taichi functions.

The rules themselves are stated in the docstring of :mod:`physics.pcmm`. Here:
the counter-clockwise, angularly pruned ring of a particle's Eq. 1 neighbours
(:func:`_ring`), the creation checks of one particle's elements (orientation,
Eqs. 1–3, :func:`_create`) and the probe count N_e of Eq. 4 (:func:`_cover` from
the Eq. 1 lists, :func:`_cover_incident` from the lists of the elements containing
each vertex). Each rule also returns its slack (``_*_slack``, :func:`_join`): how
far the particles involved may move before its answer can change, from which the
engine rebuilds the elements only where they can have changed
(:mod:`physics.pcmm.rebuild`). Both the standalone system
(:mod:`physics.pcmm.system`) and the engine's kernels call these functions.
"""
import math

import taichi as ti

from .layout import MAX_ELEMENTS, inc_element

MIN_GAP = math.pi / 6.0  # angular pruning threshold (30 deg)
COS_30 = math.sqrt(3.0) / 2.0
PROBE = (0.5, 0.3, 0.2)  # barycentric weights of the probe, vertices by increasing index


@ti.func
def _orient(a, b, p):
    """Twice the signed area of (a, b, p): > 0 when p is left of a→b."""
    return (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])


@ti.func
def _angle_ok(p, q, r):
    """Eq. 2 at vertex p of the triangle (p, q, r): |cos θ_p| ≤ cos 30°."""
    u = q - p
    v = r - p
    return ti.abs(u.dot(v)) <= COS_30 * ti.sqrt(u.dot(u) * v.dot(v))


@ti.func
def _ring(i, xi, m, pos: ti.template(), nbr: ti.template(), ring: ti.template(),
          ring_ang: ti.template()):
    """Counter-clockwise ring of the m neighbours nbr[i, :m] of particle i (at xi),
    angularly pruned (:mod:`physics.pcmm`); returns the number left in ring[i, :] and
    the ring's slack: a displacement (m) such that the same ring results while no
    particle involved moves farther than it (:func:`_angle_slack`, :func:`_dist_slack`
    of every comparison the sort and the pruning made)."""
    # counter-clockwise ring: insertion sort by (angle, index)
    dmin = 1e300
    for a in range(m):
        j = nbr[i, a]
        d = pos[j] - xi
        dmin = ti.min(dmin, d.norm())
        ang = ti.math.atan2(d[1], d[0])
        b = a
        while b > 0 and ring_ang[i, b - 1] > ang:
            ring[i, b] = ring[i, b - 1]
            ring_ang[i, b] = ring_ang[i, b - 1]
            b -= 1
        ring[i, b] = j
        ring_ang[i, b] = ang
    # the cyclic order holds while every adjacent gap keeps its sign
    amar = 2.0 * math.pi
    dmar = 1e300
    if m >= 2:
        for k in range(m):
            g = 0.0
            if k + 1 < m:
                g = ring_ang[i, k + 1] - ring_ang[i, k]
            else:
                g = ring_ang[i, 0] + 2.0 * math.pi - ring_ang[i, k]
            amar = ti.min(amar, g)
    # angular pruning: drop the farther of the closest adjacent pair while < 30 deg
    while m >= 2:
        kmin = 0
        gmin = 1e300
        g2 = 1e300
        for k in range(m):
            g = 0.0
            if k + 1 < m:
                g = ring_ang[i, k + 1] - ring_ang[i, k]
            else:
                g = ring_ang[i, 0] + 2.0 * math.pi - ring_ang[i, k]
            if g < gmin:
                g2 = gmin
                gmin = g
                kmin = k
            elif g < g2:
                g2 = g
        amar = ti.min(amar, ti.abs(gmin - MIN_GAP))
        if gmin >= MIN_GAP:
            break
        if m > 2:
            amar = ti.min(amar, g2 - gmin)
        k1 = (kmin + 1) % m
        ja = ring[i, kmin]
        jb = ring[i, k1]
        da = pos[ja] - xi
        db = pos[jb] - xi
        qa = da.dot(da)
        qb = db.dot(db)
        dmar = ti.min(dmar, 0.25 * ti.abs(ti.sqrt(qa) - ti.sqrt(qb)))
        drop = kmin
        if qb > qa or (qb == qa and jb > ja):
            drop = k1
        for k in range(drop, m - 1):
            ring[i, k] = ring[i, k + 1]
            ring_ang[i, k] = ring_ang[i, k + 1]
        m -= 1
    # a gap is a difference of two directions seen from i (each turns by at most
    # asin(2Δ/d)), a comparison of two gaps a difference of four
    slack = ti.min(dmar, _angle_slack(0.5 * amar, dmin))
    return m, slack


@ti.func
def _dist_slack(d, cut):
    """How far (m) each of two particles d apart may move before d crosses cut."""
    return 0.5 * ti.abs(d - cut)


@ti.func
def _angle_slack(theta, arm):
    """How far (m) the vertex and the ends of two arms at least ``arm`` long may move
    before the angle between the arms has changed by theta (each arm's direction
    turns by at most asin(2Δ/arm))."""
    return 0.5 * arm * ti.sin(0.5 * ti.min(theta, math.pi))


@ti.func
def _orient_slack(a, b, p):
    """How far (m) each of a, b and p may move before the sign of
    :func:`_orient` (a, b, p) can change: the largest Δ with
    4Δ² + 2Δ(|b − a| + |p − a|) < |orient| (the exact bound of the change of the
    cross product (b − a) × (p − a) when each point moves by at most Δ)."""
    S = (b - a).norm() + (p - a).norm()
    o = ti.abs(_orient(a, b, p))
    return 0.25 * (ti.sqrt(S * S + 4.0 * o) - S)


@ti.func
def _join(ok, slack, c, cslack):
    """The value and slack of (ok and c): all true, the smallest slack of them; else
    the largest slack of the false ones."""
    out = slack
    if ok and c:
        out = ti.min(slack, cslack)
    elif ok and not c:
        out = cslack
    elif (not ok) and not c:
        out = ti.max(slack, cslack)
    return ok and c, out


@ti.func
def _angle_ok_slack(p, q, r):
    """Eq. 2 at vertex p of the triangle (p, q, r) (:func:`_angle_ok`) and its slack:
    how far (m) the three may move before the answer can change."""
    u = q - p
    v = r - p
    lu = u.norm()
    lv = v.norm()
    cth = ti.math.clamp(u.dot(v) / (lu * lv), -1.0, 1.0)
    th = ti.acos(cth)
    margin = ti.min(ti.abs(th - math.pi / 6.0), ti.abs(th - 5.0 * math.pi / 6.0))
    return _angle_ok(p, q, r), _angle_slack(margin, ti.min(lu, lv))


@ti.func
def _create(a, m, xa, ra, tol, pos: ti.template(), rad: ti.template(), ring: ti.template(),
            elem: ti.template(), earea: ti.template()):
    """Elements of particle a (at xa, radius ra) from its ring of m neighbours, by the
    creation rules; stored in elem[a, :], earea[a, :]; returns their number and the
    slack of the rules (how far, m, every particle involved may move before one of
    the answers, created or not, can change)."""
    cnt = 0
    slack = 1e300
    if m >= 2:
        for k in range(m):
            b = ring[a, k]
            c = ring[a, (k + 1) % m]
            xb = pos[b]
            xc = pos[c]
            rb = rad[b]
            rc = rad[c]
            twice = _orient(xa, xb, xc)
            lab = (xb - xa).norm()
            lbc = (xc - xb).norm()
            lca = (xa - xc).norm()
            cab = ra + rb + tol
            cbc = rb + rc + tol
            cca = rc + ra + tol
            emin = 0.5 * (ra + rb + rc) / 3.0
            ok = True
            sl = 1e300
            ok, sl = _join(ok, sl, twice > 0.0, _orient_slack(xa, xb, xc))
            ok, sl = _join(ok, sl, lab <= cab, _dist_slack(lab, cab))
            ok, sl = _join(ok, sl, lbc <= cbc, _dist_slack(lbc, cbc))
            ok, sl = _join(ok, sl, lca <= cca, _dist_slack(lca, cca))
            ok, sl = _join(ok, sl, lab >= emin, _dist_slack(lab, emin))
            ok, sl = _join(ok, sl, lbc >= emin, _dist_slack(lbc, emin))
            ok, sl = _join(ok, sl, lca >= emin, _dist_slack(lca, emin))
            c1, s1 = _angle_ok_slack(xa, xb, xc)
            ok, sl = _join(ok, sl, c1, s1)
            c2, s2 = _angle_ok_slack(xb, xc, xa)
            ok, sl = _join(ok, sl, c2, s2)
            c3, s3 = _angle_ok_slack(xc, xa, xb)
            ok, sl = _join(ok, sl, c3, s3)
            slack = ti.min(slack, sl)
            if ok and cnt < MAX_ELEMENTS:
                elem[a, cnt, 0] = b
                elem[a, cnt, 1] = c
                earea[a, cnt] = 0.5 * twice
                cnt += 1
    # slots in increasing order of their first neighbour: the order (and so every sum
    # over a particle's elements) is a function of the element set, not of where the
    # ring was cut when it was built
    for t in range(1, cnt):
        k = t
        while k > 0 and elem[a, k - 1, 0] > elem[a, k, 0]:
            e0, e1, ar = elem[a, k, 0], elem[a, k, 1], earea[a, k]
            elem[a, k, 0] = elem[a, k - 1, 0]
            elem[a, k, 1] = elem[a, k - 1, 1]
            earea[a, k] = earea[a, k - 1]
            elem[a, k - 1, 0] = e0
            elem[a, k - 1, 1] = e1
            earea[a, k - 1] = ar
            k -= 1
    return cnt, slack


@ti.func
def _cover(v0, v1, v2, pos: ti.template(), nbr: ti.template(), nbr_cnt: ti.template(),
           elem: ti.template(), ecnt: ti.template()):
    """N_e of the element with vertices v0 < v1 < v2: how many elements (copies
    included) strictly contain its probe point."""
    p = PROBE[0] * pos[v0] + PROBE[1] * pos[v1] + PROBE[2] * pos[v2]
    verts = ti.Vector([v0, v1, v2])
    count = 0
    for t in ti.static(range(3)):
        v = verts[t]
        for q in range(nbr_cnt[v] + 1):
            o = v
            if q > 0:
                o = nbr[v, q - 1]
            xo = pos[o]
            for s2 in range(ecnt[o]):
                e1 = elem[o, s2, 0]
                e2 = elem[o, s2, 1]
                take = _has(o, e1, e2, v)
                for u in ti.static(range(t)):
                    take = take and not _has(o, e1, e2, verts[u])
                if take:
                    x1 = pos[e1]
                    x2 = pos[e2]
                    if _orient(xo, x1, p) > 0.0 and _orient(x1, x2, p) > 0.0 and \
                            _orient(x2, xo, p) > 0.0:
                        count += 1
    return count


@ti.func
def _sorted3(v0, v1, v2):
    """The three indices in increasing order."""
    if v0 > v1:
        v0, v1 = v1, v0
    if v1 > v2:
        v1, v2 = v2, v1
    if v0 > v1:
        v0, v1 = v1, v0
    return v0, v1, v2


@ti.func
def _has(o, e1, e2, v):
    return o == v or e1 == v or e2 == v


@ti.func
def _cover_incident(v0, v1, v2, pos: ti.template(), elem: ti.template(),
                    inc: ti.template(), icnt: ti.template(), emult: ti.template()):
    """:func:`_cover` from the lists of the elements containing each vertex, and its
    slack: how far (m) every particle involved may move before one of the
    inside/outside answers can change (:func:`_orient_slack` of the deciding edges:
    all three for a probe inside, the farthest failing one for a probe outside)."""
    p = PROBE[0] * pos[v0] + PROBE[1] * pos[v1] + PROBE[2] * pos[v2]
    verts = ti.Vector([v0, v1, v2])
    count = 0
    slack = 1e300
    for t in ti.static(range(3)):
        v = verts[t]
        for q in range(icnt[v]):
            code = inc[v, q]
            o, s2 = inc_element(code)
            e1 = elem[o, s2, 0]
            e2 = elem[o, s2, 1]
            take = True
            m = emult[o, s2]
            for u in ti.static(range(t)):
                take = take and not _has(o, e1, e2, verts[u])
            if take:
                xo = pos[o]
                x1 = pos[e1]
                x2 = pos[e2]
                ok = True
                sl = 1e300
                ok, sl = _join(ok, sl, _orient(xo, x1, p) > 0.0, _orient_slack(xo, x1, p))
                ok, sl = _join(ok, sl, _orient(x1, x2, p) > 0.0, _orient_slack(x1, x2, p))
                ok, sl = _join(ok, sl, _orient(x2, xo, p) > 0.0, _orient_slack(x2, xo, p))
                slack = ti.min(slack, sl)
                if ok:
                    count += m
    return count, slack
