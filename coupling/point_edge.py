"""Point–edge contacts between particles and block boundary edges (Feng et al. §2.6,
Eqs. 17–24, as decided in the physics notes §5), and vertex–edge contacts between
blocks (§4: the boundary vertices of one block against the boundary edges of the
other, the same law).

Geometry: the boundary edge i→j of a block (counter-clockwise mesh, the block to
its left) has the unit tangent t = (x_j − x_i)/|x_j − x_i| and the outward normal
n = (t_y, −t_x). A particle p of radius R touches the edge when the projection
k of its centre falls on the edge, s = (x_p − x_i)·t/|x_j − x_i| ∈ [0, 1) (half
open, so that a particle above a node shared by two edges of a flat side touches
one of them, not both), and
its distance d = |(x_p − x_i)·n| < R. Weights w_i = 1 − s = d_jk/d_ij,
w_j = s = d_ik/d_ij.

Law (incremental springs in the edge frame, compression-positive F_n):
    Δd = [v_p − (w_i v_i + w_j v_j)]·Δt
    F_n ← F_n − K_n·(Δd·n),  F_s ← F_s − K_s·(Δd·t)
    A = 2R × 1 m. If −F_n ≥ T·A the contact breaks (F = 0); if
    |F_s| ≥ F_n·tan φ + C·A, F_s is capped there; after either, C = T = 0 for
    that contact (it stays frictional).
    The particle gets F = F_n·n + F_s·t, the nodes −w_i·F and −w_j·F: linear
    momentum is conserved exactly. The force acts at the particle centre (no
    moment), as in the paper.

A block vertex (no radius) touches one edge of the other block: of the edges it
has crossed, the one it has crossed least (so that a vertex sliding under a
block's corner meets its bottom, not its side), by less than
``VERTEX_DEPTH`` × A (−0.05·A < d < 0; deeper, it is taken as a vertex inside the
block, not at this edge), A its tributary length (half its two boundary edges),
which is also its contact area. Only an edge the vertex can have entered through
counts (the entrance rule of vertex–edge contacts): neither of the vertex's own
two boundary edges may point into the other block across that edge's line,
(x_nb − x_v)·n ≥ −``VERTEX_ENTRANCE``·|x_nb − x_v| for both neighbours x_nb
(a tolerance of sin 5.7° for edges lying flat on each other). Without it the
bottom corners of a block stacked corner over corner on another, shifted sideways
by a hair, cross the side edges of the block below by less than they cross its top
edge, and meet those side edges, with horizontal normals (what happened to such
stacks: docs/pcmm.md, section Blocks and point–edge contacts). A vertex meets an edge up to
``VERTEX_END`` × its length past either end (closed ends, unlike particles): a
block sitting corner over corner on another is held by the corner pairs of both
blocks, and a sideways jiggle of a few µm does not drop all of them at once and
restart their springs from zero (the stack would ratchet down at each jiggle).

Broad phase: every step the boundary edges of the coupled blocks are binned into a
uniform grid over their bounding box (:func:`bin_edges`; an edge goes into every cell
its bounding box, widened by the largest reach of a point — R of a particle, the
deepest crossing ``VERTEX_DEPTH`` × A of a vertex, plus ``VERTEX_END`` × its length
for vertices — overlaps), and each point tests only the edges of its own cell. Each
block's edges are listed once, however many couples reach them; a couple's rows
test only the edges of its own block. A point outside the grid touches no edge. The grid has at most ``GRID`` cells
a side (cell side ≥ twice the reach), the cell lists are sorted by edge index, so
that the result does not depend on the thread count.

A new contact starts with F_n = F_s = 0 (the springs are incremental); a contact
that slides over a node onto the adjacent edge keeps its force (turned into the
new edge's frame); a contact whose point leaves the edges is forgotten. Each coupled particle keeps up to
``SLOTS`` contacts (edge index, F_n, F_s, broken flag) carried from step to step.
"""
import math

import taichi as ti

from physics.validate import in_range, non_negative, positive
from tdem.core.launch import cached

SLOTS = 4
VERTEX_DEPTH = 0.05   # deepest vertex–edge penetration taken as a contact, × A
GRID = 64             # most cells per side of the broad-phase grid
G_X0, G_Y0, G_H, G_NX, G_NY, G_X1, G_Y1 = 0, 1, 2, 3, 4, 5, 6   # gpar entries
GPAR_SIZE = 8
VERTEX_ENTRANCE = 0.1  # entrance rule tolerance: sine of the angle a vertex's own edge may dip
VERTEX_END = 1e-3      # a vertex meets an edge up to this fraction of its length past its ends
# columns of the law table (one row per couple)
L_KN, L_KS, L_TAN, L_C, L_T = 0, 1, 2, 3, 4
LAW_WIDTH = 5


class PointEdge:
    """Point–edge contact law between particles (or block nodes) and block edges.

    Parameters
    ----------
    kn, ks : normal and shear stiffness K_n, K_s (N/m per metre of thickness).
        None: set when the contact is coupled, from the stiffer of the two sides:
        K_n = its Young's modulus E (a 2D contact over the particle's width is as
        stiff as E per metre of thickness), K_s = K_n/(2(1 + ν)). A plain disc
        (no material) counts with its contact law's k_n as its E (ν = 0.25).
    friction_angle : φ in degrees, [0, 90)
    cohesion : C (Pa), ≥ 0, acting on A = 2R
    tensile_strength : T (Pa), ≥ 0, acting on A = 2R
    """

    def __init__(self, kn=None, ks=None, friction_angle=20.0, cohesion=0.0,
                 tensile_strength=0.0):
        self.kn = None if kn is None else positive("kn", kn)
        self.ks = None if ks is None else non_negative("ks", ks)
        self.friction_angle = in_range("friction_angle", friction_angle, 0.0, 90.0,
                                       hi_open=True)
        self.cohesion = non_negative("cohesion", cohesion)
        self.tensile_strength = non_negative("tensile_strength", tensile_strength)

    def row(self, kn, ks):
        return [kn, ks, math.tan(math.radians(self.friction_angle)), self.cohesion,
                self.tensile_strength]

    def to_dict(self):
        return {"kn": self.kn, "ks": self.ks, "friction_angle": self.friction_angle,
                "cohesion": self.cohesion, "tensile_strength": self.tensile_strength}

    def __repr__(self):
        return "PointEdge(" + ", ".join(f"{k}={v!r}" for k, v in self.to_dict().items()) + ")"


@cached
@ti.kernel
def point_edge(pos: ti.types.ndarray(), vel: ti.types.ndarray(), crad: ti.types.ndarray(),
               npos: ti.types.ndarray(), nvel: ti.types.ndarray(),
               cpart: ti.types.ndarray(), ccpl: ti.types.ndarray(),
               crange: ti.types.ndarray(), edges: ti.types.ndarray(),
               cnbr: ti.types.ndarray(),
               claw: ti.types.ndarray(), sedge: ti.types.ndarray(),
               sforce: ti.types.ndarray(), sbroken: ti.types.ndarray(),
               xforce: ti.types.ndarray(), nforce: ti.types.ndarray(),
               gpar: ti.types.ndarray(), gcnt: ti.types.ndarray(),
               gedge: ti.types.ndarray(), dt: ti.f64, serial: ti.template()):
    """Contacts of every coupled row q (point cpart[q] of ``pos``/``vel`` with the
    edges crange[ccpl[q]] of a block): forces added to ``xforce`` (the points) and
    ``nforce`` (the edges' nodes). Slots: sedge (edge or −1), sforce (F_n, F_s),
    sbroken.

    crad[q] > 0: a particle of that radius (contact while |d| < R, A = 2R);
    crad[q] = −A < 0: a block vertex of tributary length A (vertex–edge contact
    while it has crossed the edge, −0.05·A < d < 0, and could have entered through
    it: cnbr[q] are its two neighbours on its block's boundary, in ``pos``).
    gpar, gcnt, gedge: the broad-phase grid of :func:`bin_edges`."""
    gcap = gedge.shape[1]
    ti.loop_config(serialize=serial)
    for q in range(cpart.shape[0]):
        p = cpart[q]
        c = ccpl[q]
        x = pos[p]
        v = vel[p]
        R = crad[q]
        kn = claw[c, L_KN]
        ks = claw[c, L_KS]
        tanf = claw[c, L_TAN]
        # the cell of the point in the broad-phase grid (−1: outside, no edge near)
        cell = -1
        h = gpar[G_H]
        gx = ti.cast(ti.floor((x[0] - gpar[G_X0]) / h), ti.i32)
        gy = ti.cast(ti.floor((x[1] - gpar[G_Y0]) / h), ti.i32)
        nx = ti.cast(gpar[G_NX], ti.i32)
        if gx >= 0 and gy >= 0 and gx < nx and gy < ti.cast(gpar[G_NY], ti.i32):
            cell = gy * nx + gx
        ncand = 0
        if cell >= 0:
            ncand = ti.min(gcnt[cell], gcap)
        if ncand == 0 and sedge[q, 0] < 0:
            continue        # no edge near, no contact to forget (slots fill from 0)
        # the slots of the previous step, read before they are rewritten
        old_e = ti.Vector([sedge[q, k] for k in ti.static(range(SLOTS))])
        old_f = ti.Matrix([[sforce[q, k][0], sforce[q, k][1]] for k in ti.static(range(SLOTS))])
        old_b = ti.Vector([sbroken[q, k] for k in ti.static(range(SLOTS))])
        cnt = 0
        ftot = ti.Vector([0.0, 0.0])
        best = -1
        e_lo = crange[c, 0]
        e_hi = crange[c, 1]
        if R < 0.0:
            # a vertex meets one edge of a block: the one it has crossed least
            dbest = 1e300
            for kc in range(ncand):
                e = gedge[cell, kc]
                if e < e_lo or e >= e_hi:
                    continue
                xi = npos[edges[e, 0]]
                ev = npos[edges[e, 1]] - xi
                L = ev.norm()
                t = ev / L
                r = x - xi
                s = r.dot(t) / L
                n = ti.Vector([t[1], -t[0]])
                d = r.dot(n)
                if (s >= -VERTEX_END and s <= 1.0 + VERTEX_END and d < 0.0
                        and d > VERTEX_DEPTH * R and -d < dbest):
                    # entrance rule: the vertex's own edges do not cross this edge's line
                    ok = True
                    for k in ti.static(range(2)):
                        nb = cnbr[q, k]
                        if nb >= 0:
                            w = pos[nb] - x
                            if w.dot(n) < -VERTEX_ENTRANCE * w.norm():
                                ok = False
                    if ok:
                        dbest = -d
                        best = e
        for kc in range(ncand):
            e = gedge[cell, kc]
            if e < e_lo or e >= e_hi:
                continue
            a = edges[e, 0]
            b = edges[e, 1]
            xi = npos[a]
            xj = npos[b]
            ev = xj - xi
            L = ev.norm()
            t = ev / L
            n = ti.Vector([t[1], -t[0]])
            r = x - xi
            s = r.dot(t) / L
            d = r.dot(n)
            touch = False
            if R > 0.0:
                touch = ti.abs(d) < R and s >= 0.0 and s < 1.0
            else:
                touch = e == best
            if touch and cnt < SLOTS:
                fn = 0.0
                fs = 0.0
                broken = 0
                found = False
                for k in ti.static(range(SLOTS)):
                    if old_e[k] == e:
                        fn = old_f[k, 0]
                        fs = old_f[k, 1]
                        broken = old_b[k]
                        found = True
                if not found:
                    # a contact sliding over a node onto the next edge keeps its
                    # force, turned into the new edge's frame
                    for k in ti.static(range(SLOTS)):
                        o = old_e[k]
                        if not found and o >= 0:
                            if edges[o, 1] == a or edges[o, 0] == b:
                                to = npos[edges[o, 1]] - npos[edges[o, 0]]
                                to = to / to.norm()
                                no = ti.Vector([to[1], -to[0]])
                                fo = old_f[k, 0] * no + old_f[k, 1] * to
                                fn = fo.dot(n)
                                fs = fo.dot(t)
                                broken = old_b[k]
                                found = True
                wi = 1.0 - s
                wj = s
                dd = (v - (wi * nvel[a] + wj * nvel[b])) * dt
                fn -= kn * dd.dot(n)
                fs -= ks * dd.dot(t)
                area = 2.0 * R
                if R < 0.0:
                    area = -R
                coh = claw[c, L_C]
                ten = claw[c, L_T]
                if broken != 0:
                    coh = 0.0
                    ten = 0.0
                if -fn >= ten * area:
                    fn = 0.0
                    fs = 0.0
                    broken = 1
                else:
                    cap = fn * tanf + coh * area
                    if ti.abs(fs) >= cap:
                        fs = ti.math.sign(fs) * ti.max(cap, 0.0)
                        broken = 1
                f = fn * n + fs * t
                ftot += f
                ti.atomic_add(nforce[a][0], -wi * f[0])
                ti.atomic_add(nforce[a][1], -wi * f[1])
                ti.atomic_add(nforce[b][0], -wj * f[0])
                ti.atomic_add(nforce[b][1], -wj * f[1])
                sedge[q, cnt] = e
                sforce[q, cnt] = ti.Vector([fn, fs])
                sbroken[q, cnt] = broken
                cnt += 1
        for k in range(cnt, SLOTS):
            sedge[q, k] = -1
            sforce[q, k] = ti.Vector([0.0, 0.0])
            sbroken[q, k] = 0
        ti.atomic_add(xforce[p][0], ftot[0])
        ti.atomic_add(xforce[p][1], ftot[1])


@cached
@ti.kernel
def bin_edges(npos: ti.types.ndarray(), edges: ti.types.ndarray(), reach: ti.f64,
              hmin: ti.f64, end: ti.f64, gpar: ti.types.ndarray(), gcnt: ti.types.ndarray(),
              gedge: ti.types.ndarray(), need: ti.types.ndarray(), serial: ti.template()):
    """Broad phase (module docstring): the grid over the edges' bounding box widened
    by ``reach`` (cell side max(hmin, extent/GRID)), and the edges of every cell (an
    edge of length L widened by ``reach`` + ``end`` × L: the part past its ends where
    a vertex still meets it), sorted by index (gcnt[c] may exceed gedge's capacity:
    need[0] gets the largest count, the caller grows the lists and bins again)."""
    ne = edges.shape[0]
    ti.loop_config(serialize=True)
    for _ in range(1):
        gpar[G_X0] = 1e300
        gpar[G_Y0] = 1e300
        gpar[G_X1] = -1e300
        gpar[G_Y1] = -1e300
        need[0] = 0
    ti.loop_config(serialize=serial)
    for e in range(ne):
        xa = npos[edges[e, 0]]
        xb = npos[edges[e, 1]]
        w = reach + end * (xb - xa).norm()
        ti.atomic_min(gpar[G_X0], ti.min(xa[0], xb[0]) - w)
        ti.atomic_min(gpar[G_Y0], ti.min(xa[1], xb[1]) - w)
        ti.atomic_max(gpar[G_X1], ti.max(xa[0], xb[0]) + w)
        ti.atomic_max(gpar[G_Y1], ti.max(xa[1], xb[1]) + w)
    ti.loop_config(serialize=True)
    for _ in range(1):
        x0 = gpar[G_X0]
        y0 = gpar[G_Y0]
        ext = ti.max(gpar[G_X1] - x0, gpar[G_Y1] - y0)
        h = ti.max(hmin, ext / GRID) * (1.0 + 1e-9)
        gpar[G_H] = h
        gpar[G_NX] = ti.cast(ti.min(ti.floor((gpar[G_X1] - x0) / h) + 1, GRID), ti.f64)
        gpar[G_NY] = ti.cast(ti.min(ti.floor((gpar[G_Y1] - y0) / h) + 1, GRID), ti.f64)
    ti.loop_config(serialize=serial)
    for c in range(gcnt.shape[0]):
        gcnt[c] = 0
    cap = gedge.shape[1]
    ti.loop_config(serialize=serial)
    for e in range(ne):
        xa = npos[edges[e, 0]]
        xb = npos[edges[e, 1]]
        w = reach + end * (xb - xa).norm()
        h = gpar[G_H]
        nx = ti.cast(gpar[G_NX], ti.i32)
        ny = ti.cast(gpar[G_NY], ti.i32)
        i0 = ti.max(ti.cast(ti.floor((ti.min(xa[0], xb[0]) - w - gpar[G_X0]) / h), ti.i32), 0)
        i1 = ti.min(ti.cast(ti.floor((ti.max(xa[0], xb[0]) + w - gpar[G_X0]) / h), ti.i32),
                    nx - 1)
        j0 = ti.max(ti.cast(ti.floor((ti.min(xa[1], xb[1]) - w - gpar[G_Y0]) / h), ti.i32), 0)
        j1 = ti.min(ti.cast(ti.floor((ti.max(xa[1], xb[1]) + w - gpar[G_Y0]) / h), ti.i32),
                    ny - 1)
        for j in range(j0, j1 + 1):
            for i in range(i0, i1 + 1):
                c = j * nx + i
                k = ti.atomic_add(gcnt[c], 1)
                if k < cap:
                    gedge[c, k] = e
    ti.loop_config(serialize=serial)
    for c in range(gcnt.shape[0]):
        m = gcnt[c]
        if m > cap:
            ti.atomic_max(need[0], m)
            m = cap
        # insertion sort by edge index: the same lists on any number of threads
        for a in range(1, m):
            v = gedge[c, a]
            b = a
            while b > 0 and gedge[c, b - 1] > v:
                gedge[c, b] = gedge[c, b - 1]
                b -= 1
            gedge[c, b] = v
