"""PCMM element system: triangles created from particle contacts.

Feng, Li & Oñate (2015), §2.2–2.3, with the gaps closed as in the project's
physics notes (§3). Positions x_i and radii R_i are given; δ is the contact-search
tolerance of the material.

Rules
-----
- **Neighbours** (Eq. 1): i and j are neighbours if d_ij ≤ R_i + R_j + δ.
- **Angular pruning** (§2.2, Fig. 4): a particle's neighbours are sorted
  counter-clockwise by position angle atan2(y_j − y_A, x_j − x_A) (ties by
  index). While two adjacent neighbours, the last and the first included, are
  less than 30° apart, the farther one of the pair is dropped (equal distances:
  the higher index). The pair handled first is the one with the smallest gap
  (first in the order on ties), so the result does not depend on where the
  circle is cut. Afterwards all gaps are ≥ 30°: at most 12 neighbours remain.
- **Creation**: particle A creates the triangle (A, i, i+1) for each pair of
  consecutive pruned neighbours (the last and the first included) when
    * it is counter-clockwise (the sector from i to i+1 is less than 180°; a wider
      sector is an open side of a boundary particle and creates nothing),
    * all three pairs satisfy Eq. 1,
    * every interior angle θ satisfies 30° ≤ θ ≤ 150° (Eq. 2), tested as
      |cos θ| ≤ cos 30°,
    * every edge d satisfies d ≥ 0.5·(R_1 + R_2 + R_3)/3 (Eq. 3).
  The pairs of one particle's ring are distinct and at most one of them spans
  more than 180°, so a particle never creates the same triangle twice; a
  triangle may however be created by each of its three vertices.

Storage (copies)
----------------
Each particle A stores the elements it created in its own slots
(``elem[A, s] = (i, i+1)``, s < ``ecnt[A]`` ≤ 12, in increasing order of i); the
element is (A, i, i+1), counter-clockwise. The element list is the union of all
slots, ordered by owner then slot, **copies included**: a triangle created by k of
its vertices appears k times. Every sum over elements below runs over this list.

Superposition (Eq. 4)
---------------------
N_e = the number of elements (copies included, e itself included) whose interior
strictly contains the probe point of e: the point with barycentric weights
(0.5, 0.3, 0.2) on e's vertices taken in increasing particle index. Copies of a
triangle get the same N_e. An element that covers the probe shares a vertex with
e, so only elements owned by e's vertices or by their Eq. 1 neighbours are tested
(an element (o, i, j) containing v has o = v or o a neighbour of v); an element
incident to several vertices of e is counted once, from the first of them. With
the weight w_e = 1/N_e, Σ_e w_e S_e is the area of the union of the elements
wherever every point of an element is covered as many times as its probe: exactly
on the square and hexagonal lattices, to 0.15 % on the paper's random packing.

Masses (Eq. 5)
--------------
M_i = Σ_{e ∋ i} ρ·S_e/(3·N_e) over the elements containing i; a particle in no
element gets ρ·π·R_i². Σ_i M_i = ρ·Σ_e S_e/N_e.

Rebuilt where something can have changed
-----------------------------------------
Inside a simulation (:func:`update`) the element set, N_e and the bookkeeping
that follows from them are recomputed only where they can have changed, and the
set stays exactly the one the rules give. Every answer a rule gives has a slack:
the distance each particle involved may move before the answer can change (a
distance against its cut-off: half the margin; an angle: the turn of the arms,
``_angle_slack``; the sign of an orientation or of a probe against an edge: the
exact bound of the change of a cross product, ``_orient_slack``). A particle's
Eq. 1 list, ring and elements depend on it and its candidates only; N_e of an
element on its vertices' Eq. 1 neighbourhoods. The rules are unchanged by a
translation, so what is tracked is each particle's displacement u since the
epoch began *relative to the particle whose rules they are*: with u measured from
the epoch's start, a particle built when the largest relative u around it was W
keeps its elements while the largest relative u around it stays below
slack − W. When the engine rebuilds its neighbour lists, a particle's new
candidates (beyond the Eq. 1 cut-off until then, by the engine's skin) add their
own slack. An epoch begins, everything rebuilt, at the first steps and after a
restore. As the u grow the budgets loosen, so after a step that had to rebuild many
particles or recount many N_e the epoch is renewed without a rebuild: each budget
is lowered by the relative u around it and the u restart from zero. A particle
that rebuilds and finds the same Eq. 1 list and elements (most of them: a
particle near a threshold rebuilds often, and the answers seldom flip) changes
nothing around it; only a change marks its neighbourhood for the bookkeeping.

Arrays
------
Everything lives in ``ti.ndarray`` objects passed to the module-level kernels
(compiled once per process). Fixed-capacity slots: the Eq. 1 neighbour list of
a particle holds ``cap`` entries; a particle with more counts in ``flags`` and is
never written past (:class:`ElementSystem` grows ``cap`` and rebuilds). Results
do not depend on the number of threads: neighbour lists are sorted by index and
every sum runs in a fixed order.
"""
import math

import numpy as np
import taichi as ti

from tdem import backend
from tdem.errors import CapacityError, InputError
from tdem.launch import cached

from .. import fvm
from ..contact_law import zero_history
from ..materials import FLUID, JWL_TYPE, fluid_pressure, jwl_pressure, mc_correct_state
from ..validate import positive

MAX_ELEMENTS = 12        # elements a particle can create (pruned gaps are >= 30 deg)
MAX_CAPACITY = 1024      # largest Eq. 1 neighbour capacity ElementSystem grows to
MIN_GAP = math.pi / 6.0  # angular pruning threshold (30 deg)
COS_30 = math.sqrt(3.0) / 2.0
PROBE = (0.5, 0.3, 0.2)  # barycentric weights of the probe, vertices by increasing index

# indices in the int status array ``flags``
F_NEED = 0               # largest number of Eq. 1 neighbours of any particle
F_OVER = 1               # number of particles whose neighbour list overflowed
FLAGS_SIZE = 4


# ------------------------------------------------------------------ kernels
@ti.func
def _cell(x, gridp: ti.template(), nx: ti.i32, ny: ti.i32):
    cx = ti.cast(ti.floor((x[0] - gridp[0]) / gridp[2]), ti.i32)
    cy = ti.cast(ti.floor((x[1] - gridp[1]) / gridp[2]), ti.i32)
    return ti.math.clamp(cx, 0, nx - 1), ti.math.clamp(cy, 0, ny - 1)


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
    angularly pruned (module docstring); returns the number left in ring[i, :] and
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


@ti.kernel
def bin_particles(pos: ti.types.ndarray(), gridp: ti.types.ndarray(),
                  gridn: ti.types.ndarray(), cell_count: ti.types.ndarray(),
                  cell_start: ti.types.ndarray(), sorted_ids: ti.types.ndarray(),
                  pcell: ti.types.ndarray()):
    """Counting sort of the particles into the cells of the grid.

    gridp = (x0, y0, h): lower-left corner and cell side; gridn = (nx, ny).
    ``cell_start`` holds nx·ny + ny entries (row totals are kept past the cells).
    """
    n = pos.shape[0]
    nx = gridn[0]
    ny = gridn[1]
    ncell = nx * ny
    for c in range(ncell):
        cell_count[c] = 0
    for i in range(n):
        cx, cy = _cell(pos[i], gridp, nx, ny)
        c = cy * nx + cx
        pcell[i] = c
        ti.atomic_add(cell_count[c], 1)
    # exclusive prefix sum: rows in parallel, then the row offsets serially
    for r in range(ny):
        s = 0
        for cx in range(nx):
            c = r * nx + cx
            cell_start[c] = s
            s += cell_count[c]
        cell_start[ncell + r] = s
    ti.loop_config(serialize=True)
    for _ in range(1):
        s = 0
        for r in range(ny):
            tot = cell_start[ncell + r]
            cell_start[ncell + r] = s
            s += tot
    for c in range(ncell):
        cell_start[c] += cell_start[ncell + c // nx]
        cell_count[c] = 0
    for i in range(n):
        c = pcell[i]
        k = ti.atomic_add(cell_count[c], 1)
        sorted_ids[cell_start[c] + k] = i


@ti.kernel
def find_neighbours(pos: ti.types.ndarray(), rad: ti.types.ndarray(), tol: ti.f64,
                    gridp: ti.types.ndarray(), gridn: ti.types.ndarray(),
                    cell_count: ti.types.ndarray(), cell_start: ti.types.ndarray(),
                    sorted_ids: ti.types.ndarray(), nbr: ti.types.ndarray(),
                    nbr_cnt: ti.types.ndarray(), ring: ti.types.ndarray(),
                    ring_ang: ti.types.ndarray(), ring_cnt: ti.types.ndarray(),
                    flags: ti.types.ndarray()):
    """Eq. 1 neighbour lists (sorted by index) and the pruned angular rings.

    nbr[i, :nbr_cnt[i]]: every j with d_ij ≤ R_i + R_j + δ, increasing j (the list
    is symmetric: j lists i). ring[i, :ring_cnt[i]]: the neighbours left after the
    angular pruning, counter-clockwise; ring_ang holds their angles (radians,
    in (−π, π]). The grid cell side must be ≥ 2·max R + δ.
    """
    n = pos.shape[0]
    cap = nbr.shape[1]
    nx = gridn[0]
    ny = gridn[1]
    for i in range(n):
        xi = pos[i]
        ri = rad[i]
        cx, cy = _cell(xi, gridp, nx, ny)
        cnt = 0
        for dy in ti.static(range(-1, 2)):
            for dx in ti.static(range(-1, 2)):
                ccx = cx + dx
                ccy = cy + dy
                if 0 <= ccx < nx and 0 <= ccy < ny:
                    c = ccy * nx + ccx
                    for s in range(cell_start[c], cell_start[c] + cell_count[c]):
                        j = sorted_ids[s]
                        if j != i:
                            d = pos[j] - xi
                            cut = ri + rad[j] + tol
                            if d.dot(d) <= cut * cut:
                                if cnt < cap:
                                    k = cnt
                                    while k > 0 and nbr[i, k - 1] > j:
                                        nbr[i, k] = nbr[i, k - 1]
                                        k -= 1
                                    nbr[i, k] = j
                                cnt += 1
        ti.atomic_max(flags[F_NEED], cnt)
        if cnt > cap:
            ti.atomic_add(flags[F_OVER], 1)
        m = ti.min(cnt, cap)
        nbr_cnt[i] = m
        for k in range(m, cap):
            nbr[i, k] = -1
        m, _ = _ring(i, xi, m, pos, nbr, ring, ring_ang)
        ring_cnt[i] = m
        for k in range(m, cap):
            ring[i, k] = -1


@ti.kernel
def create_elements(pos: ti.types.ndarray(), rad: ti.types.ndarray(), tol: ti.f64,
                    ring: ti.types.ndarray(), ring_cnt: ti.types.ndarray(),
                    elem: ti.types.ndarray(), ecnt: ti.types.ndarray(),
                    earea: ti.types.ndarray()):
    """Elements (A, i, i+1) of consecutive ring neighbours that pass the creation
    rules: elem[A, s, 0:2] = (i, i+1), earea[A, s] = area S_e, s < ecnt[A]."""
    n = pos.shape[0]
    for a in range(n):
        cnt, _ = _create(a, ring_cnt[a], pos[a], rad[a], tol, pos, rad, ring, elem, earea)
        ecnt[a] = cnt
        for s in range(cnt, MAX_ELEMENTS):
            elem[a, s, 0] = -1
            elem[a, s, 1] = -1
            earea[a, s] = 0.0


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


@ti.kernel
def count_cover(pos: ti.types.ndarray(), nbr: ti.types.ndarray(), nbr_cnt: ti.types.ndarray(),
                elem: ti.types.ndarray(), ecnt: ti.types.ndarray(),
                ncover: ti.types.ndarray()):
    """N_e of every element: how many elements (copies included) strictly contain
    its probe point (weights 0.5, 0.3, 0.2 on the vertices by increasing index)."""
    n = pos.shape[0]
    for a in range(n):
        for s in range(ecnt[a]):
            v0, v1, v2 = _sorted3(a, elem[a, s, 0], elem[a, s, 1])
            count = _cover(v0, v1, v2, pos, nbr, nbr_cnt, elem, ecnt)
            ncover[a, s] = count
        for s in range(ecnt[a], MAX_ELEMENTS):
            ncover[a, s] = 0


@ti.kernel
def element_masses(rad: ti.types.ndarray(), density: ti.f64, nbr: ti.types.ndarray(),
                   nbr_cnt: ti.types.ndarray(), elem: ti.types.ndarray(),
                   ecnt: ti.types.ndarray(), earea: ti.types.ndarray(),
                   ncover: ti.types.ndarray(), mass: ti.types.ndarray()):
    """Eq. 5: M_i = Σ_{e ∋ i} ρ S_e / (3 N_e); ρ π R_i² for a particle in no element.

    Gathered per particle from the elements of i and of its Eq. 1 neighbours, in
    list order (a fixed summation order)."""
    n = rad.shape[0]
    for i in range(n):
        m = 0.0
        k = 0
        for q in range(nbr_cnt[i] + 1):
            o = i
            if q > 0:
                o = nbr[i, q - 1]
            for s in range(ecnt[o]):
                if _has(o, elem[o, s, 0], elem[o, s, 1], i):
                    m += density * earea[o, s] / (3.0 * ncover[o, s])
                    k += 1
        if k == 0:
            m = density * math.pi * rad[i] * rad[i]
        mass[i] = m


# ------------------------------------------------------------------ host side
def _positions(positions, n=None):
    try:
        p = np.asarray(positions, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"positions must be numbers, got {positions!r}") from None
    want = "(N, 2)" if n is None else f"({n}, 2)"
    if p.ndim != 2 or p.shape[1] != 2 or (n is not None and p.shape[0] != n):
        raise InputError(f"positions must have shape {want}, got shape {p.shape}")
    bad = ~np.isfinite(p).all(axis=1)
    if bad.any():
        k = int(np.argmax(bad))
        raise InputError(f"positions must be finite: row {k} is {p[k].tolist()}")
    return np.ascontiguousarray(p)


class ElementSystem:
    """The PCMM element system of a set of particles (see the module docstring).

    Parameters
    ----------
    positions : (N, 2) array of particle centres (m)
    radii : float or (N,) array of radii (m), > 0
    tolerance : δ of Eq. 1 (m), ≥ 0
    capacity : initial slots of a particle's Eq. 1 neighbour list; grown (powers
        of two, up to MAX_CAPACITY) when a build overflows it
    arch : Taichi architecture ('cpu' or 'gpu') when Taichi is not yet initialised

    ``build()`` (re)creates the elements for the current positions;
    ``build(positions)`` moves the particles first. ``numpy()`` returns the element
    list, ``masses(density)`` the particle masses of Eq. 5. The device arrays are
    in ``arrays`` (see :meth:`numpy` for their meaning).
    """

    def __init__(self, positions, radii, tolerance, capacity=32, arch=None):
        backend.init(arch)
        pos = _positions(positions)
        n = len(pos)
        if n == 0:
            raise InputError("positions must hold at least one particle, got none")
        try:
            r = np.asarray(radii, dtype=float)
        except (TypeError, ValueError):
            r = None
        if r is None or r.shape not in ((), (n,)):
            raise InputError(f"radii must be a number or an array of {n} numbers, "
                             f"got {radii!r}")
        r = np.broadcast_to(r, (n,)).copy()
        bad = ~(np.isfinite(r) & (r > 0))
        if bad.any():
            k = int(np.argmax(bad))
            raise InputError(f"radii must be positive: radius {k} is {r[k]!r}")
        try:
            tol = float(tolerance)
        except (TypeError, ValueError):
            raise InputError(f"tolerance must be a number >= 0, got {tolerance!r}") from None
        if not (tol >= 0.0 and math.isfinite(tol)):
            raise InputError(f"tolerance must be a number >= 0, got {tolerance!r}")
        if int(capacity) < 1:
            raise InputError(f"capacity must be >= 1, got {capacity!r}")
        self.n = n
        self.tolerance = tol
        self.capacity = 1 << (int(capacity) - 1).bit_length()
        self.neighbour_need = 0
        self._radii = r
        self._pos = pos
        self.arrays = {}
        self._allocate()
        self.arrays["rad"].from_numpy(r)
        self._built = False

    # ------------------------------------------------------------- arrays
    def _allocate(self):
        n, cap = self.n, self.capacity
        a = self.arrays
        if "pos" not in a:
            a["pos"] = ti.Vector.ndarray(2, ti.f64, (n,))
            a["rad"] = ti.ndarray(ti.f64, (n,))
            a["elem"] = ti.ndarray(ti.i32, (n, MAX_ELEMENTS, 2))
            a["ecnt"] = ti.ndarray(ti.i32, (n,))
            a["earea"] = ti.ndarray(ti.f64, (n, MAX_ELEMENTS))
            a["ncover"] = ti.ndarray(ti.i32, (n, MAX_ELEMENTS))
            a["flags"] = ti.ndarray(ti.i32, (FLAGS_SIZE,))
            a["sorted"] = ti.ndarray(ti.i32, (n,))
            a["pcell"] = ti.ndarray(ti.i32, (n,))
            a["gridp"] = ti.ndarray(ti.f64, (3,))
            a["gridn"] = ti.ndarray(ti.i32, (2,))
            a["mass"] = ti.ndarray(ti.f64, (n,))
        a["nbr"] = ti.ndarray(ti.i32, (n, cap))
        a["nbr_cnt"] = ti.ndarray(ti.i32, (n,))
        a["ring"] = ti.ndarray(ti.i32, (n, cap))
        a["ring_ang"] = ti.ndarray(ti.f64, (n, cap))
        a["ring_cnt"] = ti.ndarray(ti.i32, (n,))

    def _fit_grid(self):
        """Cell side h = 2·max R + δ (the largest Eq. 1 cut-off) over the particles'
        bounding box, coarsened if the box would need more than 4N + 1024 cells."""
        h = 2.0 * float(self._radii.max()) + self.tolerance
        lo = self._pos.min(axis=0) - h
        span = self._pos.max(axis=0) + h - lo
        nx, ny = (np.floor(span / h).astype(np.int64) + 1)
        while nx * ny > 4 * self.n + 1024:
            h *= 1.5
            nx, ny = (np.floor(span / h).astype(np.int64) + 1)
        a = self.arrays
        ncell = int(nx * ny)
        if "cell_count" not in a or a["cell_count"].shape[0] < ncell or \
                a["cell_start"].shape[0] < ncell + int(ny):
            a["cell_count"] = ti.ndarray(ti.i32, (ncell,))
            a["cell_start"] = ti.ndarray(ti.i32, (ncell + int(ny),))
        a["gridp"].from_numpy(np.array([lo[0], lo[1], h]))
        a["gridn"].from_numpy(np.array([nx, ny], dtype=np.int32))

    # ------------------------------------------------------------- build
    def build(self, positions=None):
        """Create the element system for the current (or the given) positions."""
        if positions is not None:
            self._pos = _positions(positions, self.n)
        a = self.arrays
        a["pos"].from_numpy(self._pos)
        self._fit_grid()
        bin_particles(a["pos"], a["gridp"], a["gridn"], a["cell_count"], a["cell_start"],
                      a["sorted"], a["pcell"])
        while True:
            a["flags"].from_numpy(np.zeros(FLAGS_SIZE, np.int32))
            find_neighbours(a["pos"], a["rad"], self.tolerance, a["gridp"], a["gridn"],
                            a["cell_count"], a["cell_start"], a["sorted"], a["nbr"],
                            a["nbr_cnt"], a["ring"], a["ring_ang"], a["ring_cnt"],
                            a["flags"])
            flags = a["flags"].to_numpy()
            self.neighbour_need = int(flags[F_NEED])
            if flags[F_OVER] == 0:
                break
            need = 1 << (self.neighbour_need - 1).bit_length()
            if need > MAX_CAPACITY:
                raise CapacityError(f"a particle has {self.neighbour_need} Eq. 1 neighbours, "
                                    f"more than MAX_CAPACITY={MAX_CAPACITY}: is the "
                                    f"tolerance ({self.tolerance} m) far larger than the radii?")
            self.capacity = need
            self._allocate()
        create_elements(a["pos"], a["rad"], self.tolerance, a["ring"], a["ring_cnt"],
                        a["elem"], a["ecnt"], a["earea"])
        count_cover(a["pos"], a["nbr"], a["nbr_cnt"], a["elem"], a["ecnt"], a["ncover"])
        self._built = True
        return self

    def _require_built(self):
        if not self._built:
            self.build()

    # ------------------------------------------------------------- results
    def numpy(self):
        """The element list (union of the particles' slots, copies included, ordered
        by owner then slot) as a dict of numpy arrays:

        - ``triangles`` (E, 3): particle indices (owner, i, i+1), counter-clockwise;
        - ``owner`` (E,): the particle that created the element (= triangles[:, 0]);
        - ``area`` (E,): S_e (m²);
        - ``n_cover`` (E,): N_e of the superposition rule;
        - ``weight`` (E,): 1/N_e, the factor of the element's nodal forces (Eq. 14).
        """
        self._require_built()
        a = self.arrays
        ecnt = a["ecnt"].to_numpy()
        owner = np.repeat(np.arange(self.n), ecnt)
        slot = np.arange(len(owner)) - np.repeat(np.cumsum(ecnt) - ecnt, ecnt)
        elem = a["elem"].to_numpy()[owner, slot]
        ncov = a["ncover"].to_numpy()[owner, slot]
        return {
            "triangles": np.column_stack([owner, elem]).astype(np.int64),
            "owner": owner.astype(np.int64),
            "area": a["earea"].to_numpy()[owner, slot],
            "n_cover": ncov.astype(np.int64),
            "weight": 1.0 / ncov,
        }

    def neighbours(self):
        """Eq. 1 neighbour lists and pruned rings, as lists of index arrays."""
        self._require_built()
        a = self.arrays
        nbr, nc = a["nbr"].to_numpy(), a["nbr_cnt"].to_numpy()
        ring, rc = a["ring"].to_numpy(), a["ring_cnt"].to_numpy()
        return ([nbr[i, :nc[i]] for i in range(self.n)],
                [ring[i, :rc[i]] for i in range(self.n)])

    def masses(self, density):
        """Particle masses of Eq. 5 for the density ρ (kg/m³), per metre of thickness."""
        rho = positive("density", density)
        self._require_built()
        a = self.arrays
        element_masses(a["rad"], rho, a["nbr"], a["nbr_cnt"], a["elem"], a["ecnt"],
                       a["earea"], a["ncover"], a["mass"])
        return a["mass"].to_numpy()


def check_rules(positions, radii, tolerance, triangles, rtol=1e-9):
    """Check the creation rules on given triangles (numpy, independent of the kernels).

    Returns a dict of boolean arrays (E,), True where the rule holds:
    ``orientation`` (counter-clockwise, non-degenerate), ``contact`` (Eq. 1 for the
    three pairs), ``angle`` (Eq. 2: every interior angle in [30°, 150°]), ``edge``
    (Eq. 3: every edge ≥ 0.5 × the mean radius), and ``ok`` (all of them). Bounds
    are relaxed by ``rtol`` (relative) for round-off.
    """
    x = np.asarray(positions, dtype=float)
    t = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    r = np.broadcast_to(np.asarray(radii, dtype=float), (len(x),))
    p = x[t]                                   # (E, 3, 2)
    rr = r[t]                                  # (E, 3)
    e = np.roll(p, -1, axis=1) - p             # edge k: vertex k -> k+1
    length = np.linalg.norm(e, axis=2)
    cut = rr + np.roll(rr, -1, axis=1) + tolerance
    contact = np.all(length <= cut * (1 + rtol), axis=1)
    edge = np.all(length >= 0.5 * rr.mean(axis=1)[:, None] * (1 - rtol), axis=1)
    cross = e[:, 0, 0] * e[:, 1, 1] - e[:, 0, 1] * e[:, 1, 0]
    orientation = cross > 0
    # interior angle at vertex k between edges k (outgoing) and k-1 (incoming, reversed)
    u = e
    v = -np.roll(e, 1, axis=1)
    cosang = np.einsum("eki,eki->ek", u, v) / np.maximum(
        length * np.roll(length, 1, axis=1), 1e-300)
    ang = np.degrees(np.arccos(np.clip(cosang, -1.0, 1.0)))
    angle = np.all((ang >= 30.0 * (1 - rtol)) & (ang <= 150.0 * (1 + rtol)), axis=1)
    ok = contact & edge & orientation & angle
    return {"orientation": orientation, "contact": contact, "angle": angle, "edge": edge,
            "ok": ok}


# ------------------------------------------------------- coupled to the time step
# The kernels below run inside :class:`tdem.Simulation`'s step (spec §3 order):
# :func:`candidates` after each neighbour-list build, :func:`update` every step
# before the contact forces. Particles of one PCMM body share a material slot
# ``pmat[i] >= 0`` (−1: a plain DEM disc); elements join particles of one slot only.

# indices in the int status array ``pflags``
P_NEED = 0       # largest number of Eq. 1 candidates of any particle
P_BUILDS = 1     # engine list build the candidates were made from (−1: none yet)
P_INC = 2        # largest number of elements containing one particle
P_EPOCH = 3      # the P_BUILDS value the current epoch began at (rebuild_elements)
P_NEW = 4        # 1: this step begins an epoch
P_REBUILT = 5    # particles that rebuilt their elements this step
P_RECOUNT = 6    # elements whose N_e was recounted this step
P_BUILT = 7      # 1: the candidates were rebuilt this step (the engine rebuilt its lists)
P_SOFT = 8       # 1: this step renews the epoch (displacements)
PFLAGS_SIZE = 9
PFLAGS_INIT = (0, -1, 0, 0, 1, 0, 0, 0, 0)
EPOCH_REBUILT = 0.01   # the epoch is renewed after a step that rebuilt this fraction
EPOCH_RECOUNT = 0.02   # ... or recounted N_e of this many elements per particle
FLUID_CORE = 0.75  # λ of fluid_core_force
CARRIED = -1.0     # a pair history's overlap entry while elements carry the pair (_set_skip)
MAX_INCIDENT = 64  # slots of a particle's list of the elements containing it
SCAN_BLOCK = 1024  # particles per block of the prefix sum of record_slots


@cached
@ti.kernel
def candidates(pos: ti.types.ndarray(), rad: ti.types.ndarray(), pmat: ti.types.ndarray(),
               mtol: ti.types.ndarray(), cand: ti.types.ndarray(), ccnt: ti.types.ndarray(),
               cell_count: ti.types.ndarray(), cell_start: ti.types.ndarray(),
               sorted_ids: ti.types.ndarray(), gridp: ti.types.ndarray(),
               gridn: ti.types.ndarray(), flags: ti.types.ndarray(),
               pflags: ti.types.ndarray(), builds: ti.i32, skin: ti.f64, reach: ti.i32):
    """Verlet candidates of Eq. 1: every j of the same body with
    d_ij < R_i + R_j + δ + skin, sorted by index, from the engine's cell grid.

    Runs only when the engine has rebuilt its lists since the candidates were made
    (``flags[builds] != pflags[P_BUILDS]``): between builds no particle moves more
    than half the skin, so every pair within the Eq. 1 distance stays listed.
    ``reach``: how many cells to search on each side (the Eq. 1 cut-off plus the
    skin can exceed the engine's cell side).
    """
    n = pos.shape[0]
    cap = cand.shape[1]
    nx = gridn[0]
    ny = gridn[1]
    for i in range(n):
        if flags[builds] != pflags[P_BUILDS] and pmat[i] >= 0:
            m = pmat[i]
            xi = pos[i]
            ri = rad[i]
            cx = ti.math.clamp(ti.cast(ti.floor((xi[0] - gridp[0]) / gridp[2]), ti.i32), 0, nx - 1)
            cy = ti.math.clamp(ti.cast(ti.floor((xi[1] - gridp[1]) / gridp[2]), ti.i32), 0, ny - 1)
            cnt = 0
            for ccy in range(ti.max(cy - reach, 0), ti.min(cy + reach + 1, ny)):
                for ccx in range(ti.max(cx - reach, 0), ti.min(cx + reach + 1, nx)):
                    c = ccy * nx + ccx
                    for s in range(cell_start[c], cell_start[c] + cell_count[c]):
                        j = sorted_ids[s]
                        if j != i and pmat[j] == m:
                            d = pos[j] - xi
                            cut = ri + rad[j] + mtol[m] + skin
                            if d.dot(d) < cut * cut:
                                if cnt < cap:
                                    k = cnt
                                    while k > 0 and cand[i, k - 1] > j:
                                        cand[i, k] = cand[i, k - 1]
                                        k -= 1
                                    cand[i, k] = j
                                cnt += 1
            ccnt[i] = ti.min(cnt, cap)
            ti.atomic_max(pflags[P_NEED], cnt)
    ti.loop_config(serialize=True)
    for _ in range(1):
        pflags[P_BUILDS] = flags[builds]


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
            o = code >> 6
            s2 = (code >> 2) & 15
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


@ti.func
def _creates(o, x, y, elem: ti.template(), ecnt: ti.template()):
    """The slot in which particle o created the element (o, x, y) (same orientation),
    −1 if it did not."""
    found = -1
    for s in range(ecnt[o]):
        if elem[o, s, 0] == x and elem[o, s, 1] == y:
            found = s
    return found


@ti.func
def _corner(o, e1, e2, i):
    """Which vertex of the element (o, e1, e2) particle i is (0, 1, 2), −1 if none."""
    c = -1
    if o == i:
        c = 0
    elif e1 == i:
        c = 1
    elif e2 == i:
        c = 2
    return c


REBUILT_CHANGED = 1  # prb: the particle rebuilt, and its Eq. 1 list or elements changed
REBUILT_SAME = 2     # prb: it rebuilt and found the same Eq. 1 list and elements
SLACK_FLOOR = 1e-9   # relative to the radius: slack below this counts as none


@cached
@ti.kernel
def displacements(pos: ti.types.ndarray(), pmat: ti.types.ndarray(),
                  xref: ti.types.ndarray(), pu: ti.types.ndarray(),
                  pflags: ti.types.ndarray(), full: ti.i32, serial: ti.template()):
    """0. u_i = x_i − x_ref,i, the displacement of each particle since the epoch
    began. An epoch begins with everything rebuilt (x_ref = x) at the first step and
    after a restore. The budgets of the rules' slacks bound the *relative*
    displacements since a particle was built (``pbud``) or an element counted
    (``ebud``) by the relative u then plus the relative u now, so they loosen as the
    u grow. After a step in which many particles rebuilt or many elements were
    recounted (``EPOCH_REBUILT``, ``EPOCH_RECOUNT``) the next step renews the epoch
    instead (``P_SOFT``), with no rebuild: each budget is lowered by the relative u
    around it then (|r(t) − r(t_b)| ≤ |r(t) − r(t_e)| + |r(t_e)| + |r(t_b)|; a
    particle built or an element counted at the renewal keeps its whole slack) by
    :func:`rebuild_elements` and :func:`stresses`, and x_ref = x by
    :func:`mark_dirty`. ``P_BUILT``: the candidates were rebuilt this step."""
    n = pos.shape[0]
    ti.loop_config(serialize=True)
    for _ in range(1):
        new = 1 if full != 0 else 0
        soft = 0
        if new == 0 and (pflags[P_REBUILT] > EPOCH_REBUILT * n or
                         pflags[P_RECOUNT] > EPOCH_RECOUNT * n):
            soft = 1
        pflags[P_NEW] = new
        pflags[P_SOFT] = soft
        pflags[P_BUILT] = 1 if pflags[P_EPOCH] != pflags[P_BUILDS] else 0
        pflags[P_EPOCH] = pflags[P_BUILDS]
        pflags[P_REBUILT] = 0
        pflags[P_RECOUNT] = 0
    ti.loop_config(serialize=serial)
    for i in range(n):
        if pmat[i] >= 0:
            if pflags[P_NEW] != 0:
                xref[i] = pos[i]
                pu[i] = ti.Vector([0.0, 0.0])
            else:
                pu[i] = pos[i] - xref[i]


@ti.func
def _stress_of(i, s, sig: ti.template(), eidx: ti.template(), esig: ti.template(),
               emult: ti.template(), ecopy: ti.template()):
    """The stress of the element in i's slot s by the map of the stress pass that
    wrote ``sig`` (``emult``, ``ecopy``, ``eidx`` as that pass left them): the
    computed copy's (i's slot itself, or the slot ``ecopy`` names), which lies in
    ``sig`` at the record index ``eidx`` of that slot; ``esig`` where that index is
    −1 (see :func:`copies`)."""
    o, so = i, s
    if emult[i, s] == 0:
        code = ecopy[i, s]
        o, so = code >> 4, code & 15
    j = eidx[o, so]
    out = ti.Vector([0.0, 0.0, 0.0, 0.0])
    if j >= 0:
        out = sig[j]
    else:
        out = esig[o, so]
    return out


@cached
@ti.kernel
def rebuild_elements(pos: ti.types.ndarray(), rad: ti.types.ndarray(),
                     pmat: ti.types.ndarray(), mtol: ti.types.ndarray(),
                     cand: ti.types.ndarray(), ccnt: ti.types.ndarray(),
                     nbr: ti.types.ndarray(), ncnt: ti.types.ndarray(),
                     ring: ti.types.ndarray(), rang: ti.types.ndarray(),
                     elem: ti.types.ndarray(), ecnt: ti.types.ndarray(),
                     earea: ti.types.ndarray(), esig: ti.types.ndarray(),
                     sigp: ti.types.ndarray(), eidx: ti.types.ndarray(),
                     elem_old: ti.types.ndarray(), esig_old: ti.types.ndarray(),
                     ecnt_old: ti.types.ndarray(), esrc: ti.types.ndarray(),
                     emult: ti.types.ndarray(), ecopy: ti.types.ndarray(),
                     pu: ti.types.ndarray(), pbud: ti.types.ndarray(),
                     prb: ti.types.ndarray(), pflags: ti.types.ndarray(),
                     serial: ti.template()):
    """1. The element set the rules give now, rebuilt only where it can have changed.

    A particle's Eq. 1 list, ring and elements depend on the positions of the
    particle and its candidates only. When they are built, every comparison the rules
    made has a slack (the rules' ``_slack`` helpers): while no particle involved has
    moved farther than it since, every answer is the same, and so is the element
    set. With u the distances moved since the epoch began, a particle built when the
    largest u around it was W keeps its elements while the largest u around it stays
    below slack − W (``pbud``; |x(t) − x(t_b)| ≤ u(t) + u(t_b)); otherwise, and at the
    start of an epoch, it rebuilds (``prb`` ≠ 0: ``REBUILT_SAME`` when its Eq. 1 list
    and elements came out as they were, the usual case of a particle near one of
    the rules' thresholds, else ``REBUILT_CHANGED``). A rebuilt particle keeps its last
    elements and their stresses in the ``_old`` arrays and points each new slot at
    the old slot of the same element (``esrc``, −1 for a new one); the stresses
    come from last step's stress pass (``sigp``, :func:`_stress_of`; nothing writes
    ``esig`` or ``eidx`` here).
    """
    new = pflags[P_NEW] != 0
    built = pflags[P_BUILT] != 0
    soft = pflags[P_SOFT] != 0
    ti.loop_config(serialize=serial)
    for i in range(pos.shape[0]):
        m = pmat[i]
        prb[i] = 0
        if m >= 0:
            # the largest relative u: one square root (monotone and correctly
            # rounded: the root of the largest square is the largest root)
            umax2 = 0.0
            ui = pu[i]
            for q in range(ccnt[i]):
                umax2 = ti.max(umax2, (pu[cand[i, q]] - ui).norm_sqr())
            umax = ti.sqrt(umax2)
            if built and not new:
                # new candidates: the particles not listed before stayed beyond the
                # Eq. 1 cut-off until now (the engine's skin); from now on each keeps
                # its own slack (both lists sorted)
                xi = pos[i]
                k = 0
                for q in range(ccnt[i]):
                    j = cand[i, q]
                    while k < ncnt[i] and nbr[i, k] < j:
                        k += 1
                    if not (k < ncnt[i] and nbr[i, k] == j):
                        d = (pos[j] - xi).norm()
                        cut = rad[i] + rad[j] + mtol[m]
                        if d <= cut:      # (the skin was just exceeded: it came in)
                            pbud[i] = -1.0
                        else:
                            pbud[i] = ti.min(pbud[i], _dist_slack(d, cut) - (pu[j] - ui).norm()
                                             - SLACK_FLOOR * rad[i])
            if new or umax >= pbud[i]:
                if not new:
                    ti.atomic_add(pflags[P_REBUILT], 1)
                xi = pos[i]
                ri = rad[i]
                tol = mtol[m]
                slack = 1e300
                cnt = 0
                same = not new      # the same Eq. 1 list and elements as before
                for q in range(ccnt[i]):
                    j = cand[i, q]
                    d = (pos[j] - xi).norm()
                    cut = ri + rad[j] + tol
                    slack = ti.min(slack, _dist_slack(d, cut))
                    if d <= cut:
                        if cnt >= ncnt[i] or nbr[i, cnt] != j:
                            same = False
                        nbr[i, cnt] = j
                        cnt += 1
                if cnt != ncnt[i]:
                    same = False
                ncnt[i] = cnt
                ecnt_old[i] = ecnt[i]
                for s in range(ecnt[i]):
                    elem_old[i, s, 0] = elem[i, s, 0]
                    elem_old[i, s, 1] = elem[i, s, 1]
                    esig_old[i, s] = _stress_of(i, s, sigp, eidx, esig, emult, ecopy)
                r, rs = _ring(i, xi, cnt, pos, nbr, ring, rang)
                ne, cs = _create(i, r, xi, ri, tol, pos, rad, ring, elem, earea)
                ecnt[i] = ne
                for s in range(ne):
                    src = -1
                    for so in range(ecnt_old[i]):
                        if elem_old[i, so, 0] == elem[i, s, 0] and \
                                elem_old[i, so, 1] == elem[i, s, 1]:
                            src = so
                    esrc[i, s] = src
                    if src != s:
                        same = False
                if ne != ecnt_old[i]:
                    same = False
                prb[i] = REBUILT_SAME if same else REBUILT_CHANGED
                slack = ti.min(slack, ti.min(rs, cs))
                pbud[i] = slack - (0.0 if soft else umax) - SLACK_FLOOR * ri
            elif soft:
                pbud[i] -= umax
        else:
            ncnt[i] = 0
            ecnt[i] = 0


@cached
@ti.kernel
def mark_dirty(pmat: ti.types.ndarray(), nbr: ti.types.ndarray(), ncnt: ti.types.ndarray(),
               pu: ti.types.ndarray(), prb: ti.types.ndarray(), pdirty: ti.types.ndarray(),
               unb: ti.types.ndarray(), pstate: ti.types.ndarray(), pfail: ti.types.ndarray(),
               pos: ti.types.ndarray(), xref: ti.types.ndarray(), pflags: ti.types.ndarray(),
               serial: ti.template()):
    """1a. ``pdirty``: the Eq. 1 list or the elements of the particle or of one of
    its Eq. 1 neighbours changed (``REBUILT_CHANGED``; every vertex of an element
    containing i is one of them, and the lists are exact every step, so the
    multiplicities, the copies and the list of elements containing i can only have
    changed there);
    ``unb``: the largest u over the particle and its Eq. 1 neighbours; ``pfail``:
    the particle has failed (``pstate[i][1]``, compact for the stress pass); in a
    step that renews the epoch (``P_SOFT``, see :func:`displacements`), x_ref = x."""
    ti.loop_config(serialize=serial)
    for i in range(pmat.shape[0]):
        d = 1 if prb[i] == REBUILT_CHANGED else 0
        u2 = 0.0
        pfail[i] = 1 if pstate[i][1] > 0.0 else 0
        if pmat[i] >= 0:
            ui = pu[i]
            for q in range(ncnt[i]):
                j = nbr[i, q]
                if prb[j] == REBUILT_CHANGED:
                    d = 1
                u2 = ti.max(u2, (pu[j] - ui).norm_sqr())
        pdirty[i] = d
        unb[i] = ti.sqrt(u2)    # the largest distance (the square root is monotonic)
        if pflags[P_SOFT] != 0:
            xref[i] = pos[i]    # the renewed epoch (u is read no more this step)


@cached
@ti.kernel
def copies(pmat: ti.types.ndarray(), elem: ti.types.ndarray(), ecnt: ti.types.ndarray(),
           emult: ti.types.ndarray(), ecopy: ti.types.ndarray(), pdirty: ti.types.ndarray(),
           prb: ti.types.ndarray(), esig: ti.types.ndarray(), sigp: ti.types.ndarray(),
           eidx: ti.types.ndarray(), ecomp: ti.types.ndarray(), serial: ti.template()):
    """1b. Copies: a triangle created by k of its vertices is computed once, by the
    copy of the lowest-index creator, with multiplicity k (``emult``; 0 for the other
    copies, whose ``ecopy`` = owner << 4 | slot of the computed copy). Copies have the
    same N_e, stress and forces, so every sum over elements weights the computed copy
    by k. Only where something changed (``pdirty``).

    Where the stresses are: the stress pass writes those of the computed copies in
    record order (``sigc``, index ``eidx`` of the slot; last step's are ``sigp``),
    so that it reads and writes them in sequence. ``esig`` (per slot) is brought up
    to date only where it is read: here, by last step's map and before the map
    changes, for every slot of the particles that kept their elements but whose map
    can change (dirty ones), whose ``eidx`` then becomes −1 (the stress pass reads
    ``esig`` there: a slot that becomes the computed copy, and the neighbours of a
    rebuilt particle in :func:`_carried`); by :func:`rebuild_elements` for a
    rebuilt particle's old slots (``esig_old``); by :func:`sync_copies` for all,
    before the host reads or saves them. The first loop reads the map, the second
    changes it and counts each particle's computed elements (``ecomp``, for
    :func:`record_slots`)."""
    ti.loop_config(serialize=serial)
    for a in range(pmat.shape[0]):
        if pdirty[a] != 0 and prb[a] == 0:
            for s in range(ecnt[a]):
                esig[a, s] = _stress_of(a, s, sigp, eidx, esig, emult, ecopy)
    ti.loop_config(serialize=serial)
    for a in range(pmat.shape[0]):
        if pdirty[a] != 0:
            for s in range(ecnt[a]):
                eidx[a, s] = -1
            k_comp = 0
            for s in range(ecnt[a]):
                b = elem[a, s, 0]
                c = elem[a, s, 1]
                mult = 1
                owner = a
                slot = s
                sb = _creates(b, c, a, elem, ecnt)
                if sb >= 0:
                    mult += 1
                    if b < owner:
                        owner = b
                        slot = sb
                sc = _creates(c, a, b, elem, ecnt)
                if sc >= 0:
                    mult += 1
                    if c < owner:
                        owner = c
                        slot = sc
                emult[a, s] = mult if owner == a else 0
                if owner == a:
                    k_comp += 1
                ecopy[a, s] = (owner << 4) | slot
            ecomp[a] = k_comp


@ti.kernel
def sync_copies(ecnt: ti.types.ndarray(), emult: ti.types.ndarray(), ecopy: ti.types.ndarray(),
                esig: ti.types.ndarray(), sigc: ti.types.ndarray(), eidx: ti.types.ndarray()):
    """Every slot's ``esig`` from the last stress pass (before the host reads or saves
    the element stresses; see :func:`copies`). A slot whose ``eidx`` is −1 keeps its
    own, and the slots read are not written: one loop."""
    for a in range(ecnt.shape[0]):
        for s in range(ecnt[a]):
            esig[a, s] = _stress_of(a, s, sigc, eidx, esig, emult, ecopy)


@cached
@ti.kernel
def record_slots(ecomp: ti.types.ndarray(), ebase: ti.types.ndarray(),
                 eoff: ti.types.ndarray(), serial: ti.template()):
    """1d. Where the records of the computed elements go (:func:`_record`): one run
    per particle, in particle order, the run of particle a from ``ebase[a]`` on, in
    slot order (the stress pass writes each slot's place to ``eidx``). The gather
    reads the records of the elements around a particle; packed so, they lie close
    together in memory for neighbouring particles, instead of one fixed-capacity
    block per particle with the used slots scattered in it (the gather then takes
    about half the time on a random packing). ``ebase`` is the exclusive prefix sum
    of the particles' counts of computed elements (``ecomp``, see :func:`copies`),
    made by blocks of SCAN_BLOCK particles (``eoff``: the blocks' offsets)."""
    n = ecomp.shape[0]
    nb = (n + SCAN_BLOCK - 1) // SCAN_BLOCK
    ti.loop_config(serialize=serial)
    for blk in range(nb):
        run = 0
        for a in range(blk * SCAN_BLOCK, ti.min((blk + 1) * SCAN_BLOCK, n)):
            ebase[a] = run
            run += ecomp[a]
        eoff[blk + 1] = run
    ti.loop_config(serialize=True)
    for _ in range(1):
        eoff[0] = 0
        for blk in range(nb):
            eoff[blk + 1] += eoff[blk]
    ti.loop_config(serialize=serial)
    for a in range(n):
        ebase[a] += eoff[a // SCAN_BLOCK]


@cached
@ti.kernel
def incidence(pmat: ti.types.ndarray(), nbr: ti.types.ndarray(), ncnt: ti.types.ndarray(),
              elem: ti.types.ndarray(), ecnt: ti.types.ndarray(), emult: ti.types.ndarray(),
              inc: ti.types.ndarray(), icnt: ti.types.ndarray(), iwt: ti.types.ndarray(),
              pdirty: ti.types.ndarray(), pflags: ti.types.ndarray(), serial: ti.template()):
    """1c. The computed elements containing each particle (owner << 6 | slot << 2 |
    which corner the particle is; the owner is the particle or one of its Eq. 1
    neighbours) and the sum of their multiplicities (``iwt``: the number of
    elements containing it, copies included), where something changed."""
    ti.loop_config(serialize=serial)
    for i in range(pmat.shape[0]):
        if pdirty[i] != 0:
            cnt = 0
            wt = 0
            if pmat[i] >= 0:
                for q in range(ncnt[i] + 1):
                    o = i
                    if q > 0:
                        o = nbr[i, q - 1]
                    for s in range(ecnt[o]):
                        if emult[o, s] > 0 and _corner(o, elem[o, s, 0], elem[o, s, 1], i) >= 0:
                            if cnt < MAX_INCIDENT:
                                inc[i, cnt] = (o << 6) | (s << 2) | _corner(
                                    o, elem[o, s, 0], elem[o, s, 1], i)
                                wt += emult[o, s]
                            cnt += 1
                if cnt > MAX_INCIDENT:
                    ti.atomic_max(pflags[P_INC], cnt)
                    cnt = MAX_INCIDENT
            icnt[i] = cnt
            iwt[i] = wt


LOW32 = 0xFFFFFFFF          # the low 32 bits of an i64


@ti.func
def _pack2(x, y, mark):
    """x and y rounded to f32, side by side in the bits of one f64 slot; mark ≠ 0
    sets the top bit, the sign of y, which must then be ≥ 0 (integer operations:
    fast math need not keep the sign of a zero)."""
    lo = ti.cast(ti.bit_cast(ti.cast(x, ti.f32), ti.i32), ti.i64) & ti.i64(LOW32)
    hi = ti.cast(ti.bit_cast(ti.cast(y, ti.f32), ti.i32), ti.i64) << 32
    if mark != 0:
        hi = hi | (ti.cast(1, ti.i64) << 63)
    return ti.bit_cast(lo | hi, ti.f64)


@ti.func
def _unpack2(v):
    """x and y (as f64) of :func:`_pack2`, and whether the top bit is set."""
    bits = ti.bit_cast(v, ti.i64)
    lo = ti.bit_cast(ti.cast(bits & ti.i64(LOW32), ti.i32), ti.f32)
    hi = ti.bit_cast(ti.cast(bits >> 32, ti.i32), ti.f32)
    return ti.cast(lo, ti.f64), ti.cast(hi, ti.f64), bits < 0


@ti.func
def _record(efor: ti.template(), j, sig, sf, wf, de, eps, flag, mult, b, c):
    """What the gather reads of the computed element (a, b, c): one 64-byte line per
    element (``efor[j]``, j = ``eidx[a, s]``, see :func:`record_slots`; the records
    lie side by side), weighted by the multiplicity w: the stress (0–3); the weight
    1/N_e of the nodal forces (4; 0 for an element whose forces another pass
    writes); rounded to f32 and packed two to a slot (:func:`_pack2`), the strain
    increment (5: xx, yy; 6: xy) and the plastic shear strain increment (6, ≥ 0,
    marked for a failed element); in the bits of slot 7, the corners b (bits 0–30)
    and c (32–62), and in bit 31 whether the stress of the nodal forces ``sf`` is
    not the stress (viscous stress, bulk viscosity), which then fills a second line
    in the upper half of the array (``efor[C + j]``, C = half its size; xx, yy, xy).
    The gather makes each corner's force from these and the positions of the other
    two corners (:func:`_corner_force`), without looking the element up."""
    w = ti.cast(mult, ti.f64)
    ws = w * sig
    d01 = _pack2(w * de[0], w * de[1], 0)
    d2e = _pack2(w * de[2], ti.abs(w * eps), flag)
    bits = ti.cast(b, ti.i64) | (ti.cast(c, ti.i64) << 32)
    if sf[0] != sig[0] or sf[1] != sig[1] or sf[2] != sig[2]:
        bits = bits | (ti.cast(1, ti.i64) << 31)
        efor[efor.shape[0] // 2 + j] = ti.Vector([w * sf[0], w * sf[1], w * sf[2], 0.0, 0.0,
                                                  0.0, 0.0, 0.0])
    efor[j] = ti.Vector([ws[0], ws[1], ws[2], ws[3], wf, d01, d2e, ti.bit_cast(bits, ti.f64)])


@ti.func
def _corner_force(k, o, j, r, pos: ti.template(), efor: ti.template()):
    """The force of the element (o, b, c) (counter-clockwise, created by o) on its
    corner k from its record line r = ``efor[j]`` (:func:`_record`, which holds b and
    c): :func:`physics.fvm.corner_force` with the stress of the forces (times the
    multiplicity), the weight 1/N_e and the positions of the other two corners."""
    bits = ti.bit_cast(r[7], ti.i64)
    b = ti.cast(bits & ti.i64(0x7FFFFFFF), ti.i32)
    c = ti.cast(bits >> 32, ti.i32)
    u, v = b, c
    if k == 1:
        u, v = c, o
    elif k == 2:
        u, v = o, b
    sf = ti.Vector([r[0], r[1], r[2], 0.0])
    if (bits >> 31) & 1 != 0:
        r2 = efor[efor.shape[0] // 2 + j]
        sf = ti.Vector([r2[0], r2[1], r2[2], 0.0])
    return fvm.corner_force(sf, pos[u], pos[v], r[4])


@ti.func
def _carried(a, b, c, s, jold, elem: ti.template(), ecnt: ti.template(), esig: ti.template(),
             sigp: ti.template(), elem_old: ti.template(), esig_old: ti.template(),
             ecnt_old: ti.template(), esrc: ti.template(), prb: ti.template()):
    """Last step's stress of the element (a, b, c) in a's slot s, if it existed: a's
    own slot when a kept its elements (at last step's record index ``jold`` of the
    slot, or in ``esig`` where that is −1, see :func:`copies`), else the old slot
    ``esrc`` points at, else the copy of b or c (their old lists when they rebuilt;
    otherwise ``esig``, brought up to date there because they are dirty, and not
    written by the stress pass). Returns (stress, found)."""
    out = ti.Vector([0.0, 0.0, 0.0, 0.0])
    found = False
    if prb[a] == 0:
        if jold >= 0:
            out = sigp[jold]
        else:
            out = esig[a, s]
        found = True
    elif esrc[a, s] >= 0:
        out = esig_old[a, esrc[a, s]]
        found = True
    else:
        for t in ti.static(range(1, 3)):
            o, u, w = b, c, a
            if ti.static(t == 2):
                o, u, w = c, a, b
            if not found:
                if prb[o] != 0:
                    for so in range(ecnt_old[o]):
                        if elem_old[o, so, 0] == u and elem_old[o, so, 1] == w:
                            out = esig_old[o, so]
                            found = True
                else:
                    for so in range(ecnt[o]):
                        if elem[o, so, 0] == u and elem[o, so, 1] == w:
                            out = esig[o, so]
                            found = True
    return out, found


@cached
@ti.kernel
def stresses(pos: ti.types.ndarray(), vel: ti.types.ndarray(), pmat: ti.types.ndarray(),
             matp: ti.types.ndarray(), elem: ti.types.ndarray(), ecnt: ti.types.ndarray(),
             emult: ti.types.ndarray(), inc: ti.types.ndarray(), icnt: ti.types.ndarray(),
             ncov: ti.types.ndarray(), ebud: ti.types.ndarray(), esig: ti.types.ndarray(),
             sigp: ti.types.ndarray(), sigc: ti.types.ndarray(),
             efor: ti.types.ndarray(), ede: ti.types.ndarray(), psig: ti.types.ndarray(),
             pfail: ti.types.ndarray(), rad: ti.types.ndarray(),
             elem_old: ti.types.ndarray(), esig_old: ti.types.ndarray(),
             ecnt_old: ti.types.ndarray(), esrc: ti.types.ndarray(), prb: ti.types.ndarray(),
             pdirty: ti.types.ndarray(), unb: ti.types.ndarray(), pu: ti.types.ndarray(),
             pflags: ti.types.ndarray(), ebase: ti.types.ndarray(), eidx: ti.types.ndarray(),
             dt: ti.f64, carry: ti.template(), eos: ti.template(), serial: ti.template()):
    """2. Per computed element: N_e (probe rule; recounted where the elements around
    it changed or its vertices' neighbourhoods moved farther than the count's slack,
    ``ebud``, the same bookkeeping as :func:`rebuild_elements`), σ_old (the element's
    own stress of last step if it existed and ``carry``, else the mean of its
    particles' stresses), Eqs. 6–11 with the Jaumann rotation (velocity gradient on
    the mid-step configuration, see :mod:`physics.blocks`), the constitutive
    correction (Eq. 12), and the record from which the gather makes the nodal
    forces with the weight 1/N_e (Eqs. 13–14, sign fixed; :func:`_record`), in the
    next place of the particle's run of records (``eidx``, :func:`record_slots`);
    the stress at the same place of ``sigc`` (:func:`copies`)."""
    new = pflags[P_NEW] != 0
    soft = pflags[P_SOFT] != 0
    ti.loop_config(serialize=serial)
    for a in range(pmat.shape[0]):
        j = ebase[a]
        for s in range(ecnt[a]):
            if emult[a, s] > 0:
                jold = eidx[a, s]
                eidx[a, s] = j
                b = elem[a, s, 0]
                c = elem[a, s, 1]
                v0, v1, v2 = _sorted3(a, b, c)
                # uw, or where it already says the count stands (the usual case) an
                # upper bound of it: v1 and v2 are Eq. 1 neighbours of v0, so their
                # u relative to v0 are at most unb[v0] (bitwise: the same roots)
                eb = ebud[a, s]
                need = new or pdirty[v0] + pdirty[v1] + pdirty[v2] > 0
                uw = unb[v0] + ti.max(unb[v1], unb[v2])
                if need or soft or uw >= eb:
                    u0 = pu[v0]
                    uw = ti.max(unb[v0], ti.max(unb[v1] + (pu[v1] - u0).norm(),
                                                unb[v2] + (pu[v2] - u0).norm()))
                cover = ncov[a, s]
                if need or uw >= eb:
                    cv, sl = _cover_incident(v0, v1, v2, pos, elem, inc, icnt, emult)
                    cover = cv
                    ncov[a, s] = cv
                    if not new:
                        ti.atomic_add(pflags[P_RECOUNT], 1)
                    ebud[a, s] = sl - (0.0 if soft else uw) - SLACK_FLOOR * rad[a]
                elif soft:
                    ebud[a, s] -= uw
                grad, de, area = _kinematics(a, b, c, pos, vel, dt)
                M = pmat[a]
                kind = ti.cast(matp[M, 0], ti.i32)
                sig = ti.Vector([0.0, 0.0, 0.0, 0.0])
                eps = 0.0
                flag = 0
                if kind != JWL_TYPE:
                    # (a JWL element takes the mean of its particles' pressures: the
                    # particles carry the equation of state, see the gather below)
                    found = False
                    if ti.static(carry):
                        sig, found = _carried(a, b, c, s, jold, elem, ecnt, esig, sigp,
                                              elem_old, esig_old, ecnt_old, esrc, prb)
                    if not found:
                        sig = (psig[a] + psig[b] + psig[c]) / 3.0
                    sig = fvm.jaumann_rotate(sig, fvm.spin_rate(grad), dt) + fvm.elastic_increment(
                        de, matp[M, 2], matp[M, 3])
                    failed = 0
                    if pfail[a] + pfail[b] + pfail[c] > 0:
                        failed = 1
                    sig, eps, flag = mc_correct_state(sig, matp, M, failed)
                sigc[j] = sig
                _finish(a, s, j, b, c, M, sig, eps, flag, de, area, cover, matp, emult,
                        efor, ede, dt, eos)
                j += 1


@ti.func
def _kinematics(a, b, c, pos: ti.template(), vel: ti.template(), dt):
    """Velocity gradient (Eq. 6), strain increment (Eq. 7) and area of the element
    (a, b, c) on the mid-step configuration x − ½Δt·v: Δθ·area is then exactly the
    area change of the step (the area is quadratic in the positions)."""
    va, vb, vc = vel[a], vel[b], vel[c]
    h = 0.5 * dt
    ya, yb, yc = pos[a] - h * va, pos[b] - h * vb, pos[c] - h * vc
    grad = fvm.velocity_gradient(ya, yb, yc, va, vb, vc)
    return grad, fvm.strain_increment(grad, dt), fvm.area(ya, yb, yc)


@ti.func
def _finish(a, s, j, b, c, M, sig, eps, flag, de, area, cover, matp: ti.template(),
            emult: ti.template(), efor: ti.template(), ede: ti.template(), dt,
            eos: ti.template()):
    """The end of step 2 for element (a, s) with its corrected stress: the state
    the equation of state reads (``ede``), the stress of its nodal forces
    (artificial bulk viscosity and viscous stress included) and the gather's record
    (``efor``), from which the gather makes the forces."""
    q = bulk_viscosity(matp, M, de, dt, area)
    if ti.static(eos):
        ede[a, s] = ti.Vector([de[0], de[1], de[2], eps, ti.cast(flag, ti.f64),
                               area / cover, q * (de[0] + de[1])])
    sf = sig
    wf = 0.0
    if not _has_eos(matp, M):
        sf = sig + viscous_stress(matp, M, de, dt) + ti.Vector([-q, -q, 0.0, 0.0])
        wf = 1.0 / cover
    _record(efor, j, sig, sf, wf, de, eps, flag, emult[a, s], b, c)


@cached
@ti.kernel
def equation_of_state(pmat: ti.types.ndarray(), matp: ti.types.ndarray(),
                      rad: ti.types.ndarray(), pos: ti.types.ndarray(),
                      elem: ti.types.ndarray(), ecnt: ti.types.ndarray(),
                      emult: ti.types.ndarray(), inc: ti.types.ndarray(),
                      icnt: ti.types.ndarray(), ncov: ti.types.ndarray(),
                      sigc: ti.types.ndarray(), efor: ti.types.ndarray(),
                      eidx: ti.types.ndarray(),
                      ede: ti.types.ndarray(), pjwl: ti.types.ndarray(), dt: ti.f64,
                      time: ti.f64, serial: ti.template()):
    """2j. Particles with an equation of state (JWL, or a Fluid with
    ``equation_of_state``): the state at x_n. A particle's volume changes by a third
    of Σ_e (S_e/N_e) Δθ_e over its elements (so that Σ_i p_i ΔVol_i is the elements'
    pressure work exactly). JWL: its energy changes by −(p + q) ΔVol with the p its
    elements pushed with over that change (last step's, so that the energy lost is
    exactly the work the forces did), p = F·p_JWL(V, E) with F the programmed burn
    fraction. Fluid: p(V) of :class:`physics.materials.Fluid` (a state function:
    deleting or creating elements does not change it).
    2k. Their elements: the mean pressure of their particles, the viscous stress
    2μ·dev(D) (Fluid) and the artificial bulk viscosity q (forces only)."""
    n = pmat.shape[0]
    ti.loop_config(serialize=serial)
    for i in range(n):
        M = pmat[i]
        if M >= 0:
            if _has_eos(matp, M):
                thsum = 0.0
                qsum = 0.0
                for k in range(icnt[i]):
                    code = inc[i, k]
                    o = code >> 6
                    sl = (code >> 2) & 15
                    d = ede[o, sl]
                    mw = ti.cast(emult[o, sl], ti.f64)
                    thsum += mw * d[5] * (d[0] + d[1])
                    qsum += mw * d[5] * d[6]
                js = pjwl[i]
                V0 = js[4]
                V = js[0] + thsum / (3.0 * V0)
                if ti.cast(matp[M, 0], ti.i32) == JWL_TYPE:
                    F = 0.0
                    if time >= js[2]:
                        F = ti.min(1.0, (time - js[2]) * matp[M, 10] / (3.0 * rad[i]))
                    E = js[1] - (js[3] * thsum + qsum) / (3.0 * V0)
                    p = F * jwl_pressure(matp, M, V, E)
                    pjwl[i] = ti.Vector([V, E, js[2], p, V0])
                else:
                    pjwl[i] = ti.Vector([V, js[1], js[2], fluid_pressure(matp, M, V), V0])
    ti.loop_config(serialize=serial)
    for a in range(n):
        for s in range(ecnt[a]):
            if emult[a, s] > 0:
                M = pmat[a]
                if _has_eos(matp, M):
                    b = elem[a, s, 0]
                    c = elem[a, s, 1]
                    pm = (pjwl[a][3] + pjwl[b][3] + pjwl[c][3]) / 3.0
                    sig = ti.Vector([-pm, -pm, 0.0, -pm])
                    sigc[eidx[a, s]] = sig
                    d = ede[a, s]
                    de = ti.Vector([d[0], d[1], d[2]])
                    q = 0.0
                    if d[0] + d[1] < 0.0:
                        q = d[6] / (d[0] + d[1])
                    sf = sig + viscous_stress(matp, M, de, dt) + ti.Vector([-q, -q, 0.0, 0.0])
                    _record(efor, eidx[a, s], sig, sf, 1.0 / ncov[a, s], de, d[3],
                            ti.cast(d[4], ti.i32), emult[a, s], b, c)


@cached
@ti.kernel
def gather(pos: ti.types.ndarray(), rad: ti.types.ndarray(), pmat: ti.types.ndarray(),
           matp: ti.types.ndarray(), nbr: ti.types.ndarray(), ncnt: ti.types.ndarray(),
           elem: ti.types.ndarray(), inc: ti.types.ndarray(), icnt: ti.types.ndarray(),
           iwt: ti.types.ndarray(), efor: ti.types.ndarray(), eidx: ti.types.ndarray(),
           psig: ti.types.ndarray(),
           peps: ti.types.ndarray(), pstate: ti.types.ndarray(), xforce: ti.types.ndarray(),
           pjwl: ti.types.ndarray(), enbr: ti.types.ndarray(), encnt: ti.types.ndarray(),
           cskip: ti.types.ndarray(), hist: ti.types.ndarray(), prop: ti.types.ndarray(),
           pdirty: ti.types.ndarray(), pflags: ti.types.ndarray(), first: ti.i32,
           jwl: ti.template(), serial: ti.template()):
    """3. Per particle (gathered, no atomics): force of its elements → xforce (each
    made from the element's record and the positions of its other two corners,
    :func:`_corner_force`),
    stress = mean of its elements' σ (zero in none), strain and plastic shear
    strain += the means of the increments; the engine's pair slots (``cskip``,
    rewritten where the elements around the particle changed, at the start of an
    epoch and at the first two steps): 1 for two particles that are corners of a
    common element (no DEM contact: the element carries their interaction; when it
    stops doing so, :func:`_set_skip` records their overlap in the pair's history,
    from which the contact law counts, see :func:`tdem.step.pair_contact`), and for
    same-body Fluid or JWL neighbours (:func:`fluid_core_force`); 2, at the first
    step only, for the other same-body Eq. 1 neighbours (the contact law starts from
    their initial overlap: a touching pair left out of the elements by the angular
    pruning does not push apart). All other touching pairs — sharing no element,
    whether in elements or not, same body or not — meet through the contact law, so
    that particles cannot pass through each other."""
    new = pflags[P_NEW] != 0
    built = pflags[P_BUILT] != 0
    ti.loop_config(serialize=serial)
    for i in range(pmat.shape[0]):
        redo = new or built or pdirty[i] != 0
        if pmat[i] >= 0:
            f = ti.Vector([0.0, 0.0])
            ssum = ti.Vector([0.0, 0.0, 0.0, 0.0])
            dsum = ti.Vector([0.0, 0.0, 0.0])
            psum = 0.0
            hit = 0
            cnt = ti.cast(iwt[i], ti.f64)
            for q in range(icnt[i]):
                code = inc[i, q]
                o = code >> 6
                s = (code >> 2) & 15
                j = eidx[o, s]
                r = efor[j]
                f += _corner_force(code & 3, o, j, r, pos, efor)
                ssum += ti.Vector([r[0], r[1], r[2], r[3]])
                dxx, dyy, _ = _unpack2(r[5])
                dxy, ep, failed = _unpack2(r[6])
                dsum += ti.Vector([dxx, dyy, dxy])
                psum += ti.abs(ep)
                if failed:
                    hit = 1
            kind_i = ti.cast(matp[pmat[i], 0], ti.i32)
            fluid = kind_i == FLUID or kind_i == JWL_TYPE
            if redo:
                # pair slots of same-body Eq. 1 neighbours (both lists sorted)
                q = 0
                for k in range(encnt[i]):
                    j = enbr[i, k]
                    skip = 0
                    while q < ncnt[i] and nbr[i, q] < j:
                        q += 1
                    if q < ncnt[i] and nbr[i, q] == j:
                        if fluid or _shares_element(i, j, inc, icnt, elem):
                            skip = 1
                        elif first != 0:
                            skip = 2
                    _set_skip(i, k, j, skip, pos, prop, cskip, hist)
            if fluid:
                # Fluid and JWL products: same-body Eq. 1 neighbours never meet through
                # the contact law (no friction between fluid particles, and no force
                # jump when an element between them goes); they repel through the core
                # force of fluid_core_force, a function of their distance only
                xi = pos[i]
                for q2 in range(ncnt[i]):
                    j = nbr[i, q2]
                    f += fluid_core_force(matp, pmat[i], xi, pos[j], rad[i] + rad[j])
            xforce[i] = f
            st = pstate[i]
            if cnt > 0.0:
                inv = 1.0 / cnt
                psig[i] = ssum * inv
                peps[i] += dsum * inv
                st[0] += psum * inv
            else:
                psig[i] = ti.Vector([0.0, 0.0, 0.0, 0.0])
            M = pmat[i]
            if ti.static(jwl):
                if _has_eos(matp, M):
                    p = pjwl[i][3]
                    psig[i] = ti.Vector([-p, -p, 0.0, -p])
            if hit == 1:
                st[1] = 1.0
            st[2] = cnt
            pstate[i] = st
        else:
            xforce[i] = ti.Vector([0.0, 0.0])
            if redo:
                for k in range(encnt[i]):
                    _set_skip(i, k, enbr[i, k], 0, pos, prop, cskip, hist)


@ti.func
def _set_skip(i, k, j, skip, pos: ti.template(), prop: ti.template(), cskip: ti.template(),
              hist: ti.template()):
    """Pair slot k of i (partner j) takes the mark ``skip`` (see :func:`gather`). The
    pair's history says whether elements carried it at the last mark: its overlap
    entry (u0, the last column) is CARRIED (< 0) then, an overlap ≥ 0 otherwise. A pair that elements
    stop carrying starts the contact law afresh, counting from its overlap now
    (:func:`tdem.step.pair_contact`), so that the law takes over without a jump."""
    cskip[i, k] = skip
    h = hist[i, k]
    u0 = ti.static(h.n - 1)
    if skip == 1:
        if h[u0] >= 0.0:
            h[u0] = CARRIED
            hist[i, k] = h
    elif h[u0] < 0.0:
        u = prop[i][0] + prop[j][0] - (pos[j] - pos[i]).norm()
        h = zero_history(h)
        h[u0] = ti.max(u, 0.0)
        hist[i, k] = h


def update(a, e, dt, time, first, full, carry, eos, serial):
    """One PCMM step (spec §3, steps 1–5 and Eqs. 15–16) for the particles of x_n
    moving at v_{n−1/2}, in the order the data flows. ``a``: the continuum's arrays
    (:class:`tdem.continuum.Continuum`), ``e``: the engine's (positions, velocities,
    pair lists and slots). ``first``: the first step of the run; ``full``: rebuild
    everything (first step, after a restore); ``carry``: an element that existed
    last step continues from its own stress; ``eos``: there are particles with an
    equation of state.

    pstate[i] = (plastic shear strain, failed (0/1), elements containing i, −).
    """
    full = int(bool(full) or bool(first))
    a["sigp"], a["sigc"] = a["sigc"], a["sigp"]       # last step's stresses, this step's
    displacements(e["pos"], a["pmat"], a["xref"], a["pu"], a["pflags"], full, serial)
    rebuild_elements(e["pos"], a["rad"], a["pmat"], a["mtol"], a["cand"], a["ccnt"],
                     a["nbr"], a["ncnt"], a["ring"], a["rang"], a["elem"], a["ecnt"],
                     a["earea"], a["esig"], a["sigp"], a["eidx"], a["elem_old"], a["esig_old"],
                     a["ecnt_old"],
                     a["esrc"], a["emult"], a["ecopy"], a["pu"], a["pbud"], a["prb"],
                     a["pflags"], serial)
    mark_dirty(a["pmat"], a["nbr"], a["ncnt"], a["pu"], a["prb"], a["pdirty"], a["unb"],
               a["pstate"], a["pfail"], e["pos"], a["xref"], a["pflags"], serial)
    copies(a["pmat"], a["elem"], a["ecnt"], a["emult"], a["ecopy"], a["pdirty"], a["prb"],
           a["esig"], a["sigp"], a["eidx"], a["ecomp"], serial)
    incidence(a["pmat"], a["nbr"], a["ncnt"], a["elem"], a["ecnt"], a["emult"], a["pinc"],
              a["picnt"], a["piwt"], a["pdirty"], a["pflags"], serial)
    record_slots(a["ecomp"], a["ebase"], a["eoff"], serial)
    stresses(e["pos"], e["vel"], a["pmat"], a["matp"], a["elem"], a["ecnt"], a["emult"],
             a["pinc"], a["picnt"], a["ncov"], a["ebud"], a["esig"], a["sigp"], a["sigc"],
             a["efor"], a["ede"],
             a["psig"], a["pfail"], a["rad"], a["elem_old"], a["esig_old"], a["ecnt_old"],
             a["esrc"], a["prb"], a["pdirty"], a["unb"], a["pu"], a["pflags"], a["ebase"],
             a["eidx"], dt, carry, eos, serial)
    if eos:
        equation_of_state(a["pmat"], a["matp"], a["rad"], e["pos"], a["elem"], a["ecnt"],
                          a["emult"], a["pinc"], a["picnt"], a["ncov"], a["sigc"],
                          a["efor"], a["eidx"], a["ede"], a["pjwl"], dt, time, serial)
    gather(e["pos"], a["rad"], a["pmat"], a["matp"], a["nbr"], a["ncnt"], a["elem"],
           a["pinc"], a["picnt"], a["piwt"], a["efor"], a["eidx"], a["psig"], a["peps"],
           a["pstate"],
           a["xforce"], a["pjwl"], e["nbr"], e["ncnt"], e["cskip"], e["hist"], e["prop"],
           a["pdirty"], a["pflags"], int(first), eos, serial)


@ti.func
def bulk_viscosity(matp: ti.template(), M, de, dt, area):
    """Pressure q ≥ 0 of the artificial bulk viscosity of columns 12–13 (module
    docstring of :mod:`physics.materials`), for a shrinking element only."""
    q = 0.0
    th = de[0] + de[1]
    b1 = matp[M, 12]
    b2 = matp[M, 13]
    if th < 0.0 and b1 + b2 > 0.0:
        L = ti.sqrt(ti.abs(area))
        rate = -th / dt
        rho = matp[M, 1]
        c = ti.sqrt((matp[M, 2] + 4.0 * matp[M, 3] / 3.0) / rho)
        q = rho * L * rate * (b1 * c + b2 * L * rate)
    return q


@ti.func
def _has_eos(matp: ti.template(), M):
    """Whether material row M keeps its pressure per particle: JWL, or a Fluid with
    ``equation_of_state`` (column 4 = 1)."""
    kind = ti.cast(matp[M, 0], ti.i32)
    return kind == JWL_TYPE or (kind == FLUID and matp[M, 4] > 0.0)


@ti.func
def _shares_element(i, j, inc: ti.template(), icnt: ti.template(), elem: ti.template()):
    """Whether j is a corner of one of the (computed) elements containing i."""
    found = False
    for q in range(icnt[i]):
        code = inc[i, q]
        o = code >> 6
        s = (code >> 2) & 15
        if o == j or elem[o, s, 0] == j or elem[o, s, 1] == j:
            found = True
    return found


@ti.func
def fluid_core_force(matp: ti.template(), M, xi, xj, rsum):
    """Force on particle i (at xi) from a same-body Fluid or JWL neighbour j (at xj):
    a linear repulsive core, K·max(0, λ·(R_i + R_j) − d) along the line of centres,
    λ = FLUID_CORE (K of row M as a stiffness per metre of thickness). It stands in
    for the contact law between water particles (:class:`physics.materials.Fluid`)
    and between detonation products (K = ρ0 D² of a JWL row):
    zero unless the two overlap by more than (1 − λ) of their radii, far beyond any
    compression the water's pressure gives (p/K < 1 %), and a function of their
    distance only, so it has a potential and cannot jump when elements come and go."""
    d = xj - xi
    L = d.norm()
    dc = FLUID_CORE * rsum
    out = ti.Vector([0.0, 0.0])
    if L < dc and L > 0.0:
        out = -matp[M, 2] * (dc - L) / L * d
    return out


@ti.func
def viscous_stress(matp: ti.template(), M, de, dt):
    """Viscous stress 2μ·dev(D) of a Fluid row (μ in column 11), D = Δε/Δt in plane
    strain (D_zz = 0); zero for other materials. Not accumulated: it acts on the
    forces of the step only."""
    mu = matp[M, 11]
    out = ti.Vector([0.0, 0.0, 0.0, 0.0])
    if mu > 0.0:
        tr = (de[0] + de[1]) / 3.0
        out = 2.0 * mu / dt * ti.Vector([de[0] - tr, de[1] - tr, de[2], -tr])
    return out
