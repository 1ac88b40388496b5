"""Cell-grid neighbour search with a Verlet skin.

Particles are binned by a counting sort into square cells of side h >= the largest
pair cut-off (R_i + R_j + skin). Each particle keeps a *half* list (partners
j > i, sorted by j) in fixed-capacity slots, and a *reverse* list of the slots of
other particles that name it, so that pair forces are computed once per pair and
gathered without atomics, in a fixed order (results do not depend on the number
of threads).

Contact history (shear spring, rolling couple) lives in the half-list slots and is
carried over from the previous list whenever the pair is still listed.

The lists are rebuilt only when some particle has moved more than half the skin
since the last build; the integrator raises a flag on the device. On the GPU the
rebuild kernel is launched every step and does nothing unless the flag is up; on
the CPU the host reads the flag (shared memory, no transfer). The test is on the
displacement since the build, and the build comes before the next force evaluation:
a particle faster than half the skin per step has its lists made anew at every
step, so no pair within reach at the start of a step is missed, however fast. What
the lists cannot see is a pair crossed within one step (a particle moving more than
its radius in a step may pass through a thin neighbour or a wall): the status check
reports such a particle once (flags[F_FAST], Runner._status).

Each particle also lists its candidate walls (within R + skin); a wall that has
moved half the skin since the build raises the flag too, so relative motion never
exceeds the skin between builds.

Out-of-grid particles are clamped to the border cells: this keeps the search
exact (clamping never separates two cells by more than one), only slower, until
the host refits the grid at its next check.

Overflow of the slots is counted (flags[F_NEED]) and never written past; the
simulation grows the arrays and redoes the steps since its last check.
"""
import taichi as ti

from physics.contact_law import zero_history
from physics.geometry import sphere_triangle

from .launch import cached
from .state import PROP_RADIUS

# the columns of the status array ``flags`` (F_*) and of the parameter array ``simp``
# (P_*) are declared in tdem.core.layout (PCMM kernels share them) and named here too
from .core.layout import (F_BAD, F_BUILDS, F_FAST, F_NEED, F_NONCONV, F_PUSH,  # noqa: F401
                          F_REBUILD, F_SWEEP, F_TBIN_NEED, F_TBIN_TOTAL, F_WALL_NEED,
                          FLAGS_SIZE, P_ALPHA, P_ALPHA_LOCAL, P_CHUNK, P_DT, P_GX, P_GY, P_GZ,
                          P_NWALLS, P_PLX, P_PLY, P_PLZ, P_PX0, P_PY0, P_PZ0, P_SKIN,
                          SIMP_SIZE)


@ti.func
def gravity(simp: ti.template(), dim: ti.template()):
    """The gravity vector of the parameter array."""
    if ti.static(dim == 2):
        return ti.Vector([simp[P_GX], simp[P_GY]])
    else:
        return ti.Vector([simp[P_GX], simp[P_GY], simp[P_GZ]])


@ti.func
def periodic_axes(simp: ti.template(), dim: ti.template()):
    """(x0, Lx, y0, Ly[, z0, Lz]): the start and length of each axis's period, a length
    0 where the axis is not periodic."""
    if ti.static(dim == 2):
        return ti.Vector([simp[P_PX0], simp[P_PLX], simp[P_PY0], simp[P_PLY]])
    else:
        return ti.Vector([simp[P_PX0], simp[P_PLX], simp[P_PY0], simp[P_PLY], simp[P_PZ0],
                          simp[P_PLZ]])


# 3D: the columns of a mesh triangle's row of the wall table (tdem.step): vertices
# a, b, c, translation velocity, angular velocity, centre of rotation (the mesh's),
# law, displacement since the lists were built, mesh index, surface velocity (a
# conveyor belt: its part in the triangle's plane moves the contact point, not the
# triangle; checkpoints of 21 columns are read with it zero)
(T_AX, T_BX, T_CX, T_VX, T_WX, T_OX) = (0, 3, 6, 9, 12, 15)
T_LAW, T_DISP, T_MESH = 18, 19, 20
T_SX = 21
TRI_WIDTH = 24


@ti.func
def wall_offset(wall: ti.template(), w, x):
    """From x to the nearest point of wall w: a segment (2D, clamped to its ends) or a
    mesh triangle (3D)."""
    d = x * 0.0
    if ti.static(x.n == 2):
        a = ti.Vector([wall[w, 0], wall[w, 1]])
        b = ti.Vector([wall[w, 2], wall[w, 3]])
        ab = b - a
        sp = ti.math.clamp((x - a).dot(ab) * wall[w, 10], 0.0, 1.0)
        d = a + sp * ab - x
    else:
        q, feat = sphere_triangle.closest_point(
            x, ti.Vector([wall[w, T_AX], wall[w, T_AX + 1], wall[w, T_AX + 2]]),
            ti.Vector([wall[w, T_BX], wall[w, T_BX + 1], wall[w, T_BX + 2]]),
            ti.Vector([wall[w, T_CX], wall[w, T_CX + 1], wall[w, T_CX + 2]]))
        d = q - x
    return d


@ti.func
def tri_vec(wall: ti.template(), w, c: ti.template()):
    """Columns c, c + 1, c + 2 of row w of the wall table (a corner, velocity, ... of a
    mesh triangle) as a 3-vector."""
    return ti.Vector([wall[w, c], wall[w, c + 1], wall[w, c + 2]])


@ti.func
def slot_bits(cap):
    """log2 of the slot capacity (always a power of two): a reverse-list entry packs
    (owner j, slot k) as j << bits | k."""
    b = 0
    while (1 << b) < cap:
        b += 1
    return b


@ti.func
def cell_of(x, gridp: ti.template(), gridn: ti.template()):
    """The cell (cx, cy[, cz]) of point x, as a vector: cells of side gridp[d + k] along
    axis k from the corner (gridp[0], … gridp[d − 1]), clamped to the grid of
    gridn[k] cells along axis k."""
    c = ti.Vector([0 for _ in ti.static(range(x.n))])
    for k in ti.static(range(x.n)):
        c[k] = ti.math.clamp(ti.cast(ti.floor((x[k] - gridp[k]) / gridp[x.n + k]), ti.i32),
                             0, gridn[k] - 1)
    return c


@ti.func
def cell_index(c, gridn: ti.template()):
    """The linear index of cell c (x fastest)."""
    idx = c[0] + gridn[0] * c[1]
    if ti.static(c.n == 3):
        idx += gridn[0] * gridn[1] * c[2]
    return idx


@ti.func
def image(d, per):
    """The nearest periodic image of the offset d: per = (x0, Lx, y0, Ly[, z0, Lz]), a
    length 0 where the axis is not periodic (contacts across the boundary
    are between images)."""
    for k in ti.static(range(d.n)):
        if per[2 * k + 1] > 0.0:
            d[k] -= per[2 * k + 1] * ti.round(d[k] / per[2 * k + 1])
    return d


@ti.func
def insert_partner(nbr: ti.template(), i, cnt, j):
    """Partner j into particle i's half list of ``cnt`` partners, kept sorted by index
    (nothing written past the capacity: the caller counts what was needed)."""
    if cnt < nbr.shape[1]:
        k = cnt
        while k > 0 and nbr[i, k - 1] > j:
            nbr[i, k] = nbr[i, k - 1]
            k -= 1
        nbr[i, k] = j


@ti.func
def close_half_list(i, cnt, nbr: ti.template(), ncnt: ti.template(), hist: ti.template(),
                    nbr_old: ti.template(), ncnt_old: ti.template(),
                    hist_old: ti.template()):
    """Particle i's new half list of ``cnt`` partners closed: its length (at most the
    capacity), each pair's history carried over from the old list (zero for a new
    pair), the free slots cleared."""
    cap = nbr.shape[1]
    m = ti.min(cnt, cap)
    ncnt[i] = m
    for k in range(m):
        j = nbr[i, k]
        h = zero_history(hist[i, k])
        for kk in range(ncnt_old[i]):
            if nbr_old[i, kk] == j:
                h = hist_old[i, kk]
        hist[i, k] = h
    for k in range(m, cap):
        nbr[i, k] = -1
        hist[i, k] = zero_history(hist[i, k])


@cached
@ti.kernel
def rebuild(pos: ti.types.ndarray(), prop: ti.types.ndarray(), xref: ti.types.ndarray(),
            nbr: ti.types.ndarray(), ncnt: ti.types.ndarray(), hist: ti.types.ndarray(),
            nbr_old: ti.types.ndarray(), ncnt_old: ti.types.ndarray(),
            hist_old: ti.types.ndarray(), rev: ti.types.ndarray(), rcnt: ti.types.ndarray(),
            cell_count: ti.types.ndarray(), cell_start: ti.types.ndarray(),
            sorted_ids: ti.types.ndarray(), pcell: ti.types.ndarray(),
            gridp: ti.types.ndarray(), gridn: ti.types.ndarray(), flags: ti.types.ndarray(),
            wall: ti.types.ndarray(), wid: ti.types.ndarray(), whist: ti.types.ndarray(),
            wid_old: ti.types.ndarray(), whist_old: ti.types.ndarray(), nwalls: ti.i32,
            skin: ti.f64, simp: ti.types.ndarray(), tbin_count: ti.types.ndarray(),
            tbin_start: ti.types.ndarray(), tbin_items: ti.types.ndarray(),
            dim: ti.template()):
    n = pos.shape[0]
    cap = nbr.shape[1]
    nx = gridn[0]
    ny = gridn[1]
    # periodic axes (their cells tile the period exactly; tdem.runner._fit_grid)
    per = periodic_axes(simp, dim)
    ncell = nx * ny
    if ti.static(dim == 3):
        ncell *= gridn[2]
    nrows = ncell // nx
    # 1. keep the old lists (for the history), clear the cell counts
    for i in range(n):
        if flags[F_REBUILD] != 0:
            ncnt_old[i] = ncnt[i]
            for k in range(cap):
                nbr_old[i, k] = nbr[i, k]
                hist_old[i, k] = hist[i, k]
    for c in range(ncell):
        if flags[F_REBUILD] != 0:
            cell_count[c] = 0
    # 2. count particles per cell
    for i in range(n):
        if flags[F_REBUILD] != 0:
            c = cell_index(cell_of(pos[i], gridp, gridn), gridn)
            pcell[i] = c
            ti.atomic_add(cell_count[c], 1)
    # 3. exclusive prefix sum: rows in parallel, then row offsets serially
    for r in range(nrows):
        if flags[F_REBUILD] != 0:
            s = 0
            for cx in range(nx):
                c = r * nx + cx
                cell_start[c] = s
                s += cell_count[c]
            cell_start[ncell + r] = s  # row totals stored past the cells
    ti.loop_config(serialize=True)
    for r in range(nrows):
        if flags[F_REBUILD] != 0:
            if r == 0:
                gridn[3] = 0
            tot = cell_start[ncell + r]
            cell_start[ncell + r] = gridn[3]
            gridn[3] += tot
    for c in range(ncell):
        if flags[F_REBUILD] != 0:
            cell_start[c] += cell_start[ncell + c // nx]
            cell_count[c] = 0
    # 4. scatter particles into cell order
    for i in range(n):
        if flags[F_REBUILD] != 0:
            c = pcell[i]
            slot = ti.atomic_add(cell_count[c], 1)
            sorted_ids[cell_start[c] + slot] = i
    # 5. half lists, sorted by partner index, with the history carried over
    for i in range(n):
        if flags[F_REBUILD] != 0:
            xi = pos[i]
            ri = prop[i][PROP_RADIUS]
            ci = cell_of(xi, gridp, gridn)
            cnt = 0
            for off in ti.static(ti.grouped(ti.ndrange(*([(-1, 2)] * dim)))):
                if True:
                    cc = ci + off
                    inside = True
                    for ax in ti.static(range(dim)):
                        if per[2 * ax + 1] > 0.0:
                            cc[ax] = (cc[ax] + gridn[ax]) % gridn[ax]
                        if cc[ax] < 0 or cc[ax] >= gridn[ax]:
                            inside = False
                    if inside:
                        c = cell_index(cc, gridn)
                        for s in range(cell_start[c], cell_start[c] + cell_count[c]):
                            j = sorted_ids[s]
                            if j != i:
                                d = image(pos[j] - xi, per)
                                cut = ri + prop[j][PROP_RADIUS] + skin
                                if d.dot(d) < cut * cut and j > i:
                                    insert_partner(nbr, i, cnt, j)
                                    cnt += 1
            # (the partners below i are counted by the reverse lists, finish_build)
            ti.atomic_max(flags[F_NEED], cnt)
            close_half_list(i, cnt, nbr, ncnt, hist, nbr_old, ncnt_old, hist_old)
            xref[i] = xi
            rcnt[i] = 0
    # 6.-8. reverse lists, the mesh triangles' bins, candidate walls
    finish_build(pos, prop, nbr, ncnt, rev, rcnt, gridp, gridn, flags, wall, wid, whist,
                 wid_old, whist_old, nwalls, skin, tbin_count, tbin_start, tbin_items, ncell,
                 nx, nrows, dim, per)


@ti.func
def finish_build(pos: ti.template(), prop: ti.template(), nbr: ti.template(),
                 ncnt: ti.template(), rev: ti.template(), rcnt: ti.template(),
                 gridp: ti.template(), gridn: ti.template(), flags: ti.template(),
                 wall: ti.template(), wid: ti.template(), whist: ti.template(),
                 wid_old: ti.template(), whist_old: ti.template(), nwalls, skin,
                 tbin_count: ti.template(), tbin_start: ti.template(),
                 tbin_items: ti.template(), ncell, nx, nrows, dim: ti.template(), per):
    """The part of a list build that follows the half lists, whichever broad phase made
    them (this grid's or :mod:`tdem.sweep`): the reverse lists, the mesh triangles'
    bins (3D), each particle's candidate walls; then the flag lowered. ``rcnt`` must
    be zero on entry. ``per``: the periodic axes (:func:`periodic_axes`).

    Walls are not periodic: a particle that crosses a periodic side before the next
    build is put back by a period, among other walls than those near where it was.
    So a particle within a skin of a periodic side also takes the walls near its
    image across that side (and across both sides at a corner): its candidates are
    then right on either side of the crossing (those of the side it is not on lie
    farther than its reach)."""
    n = pos.shape[0]
    cap = nbr.shape[1]
    # 6. reverse lists (who names me), then sorted for a fixed summation order
    for j in range(n):
        if flags[F_REBUILD] != 0:
            for k in range(ncnt[j]):
                i = nbr[j, k]
                r = ti.atomic_add(rcnt[i], 1)
                if r < cap:
                    rev[i, r] = (j << slot_bits(cap)) | k
    for i in range(n):
        if flags[F_REBUILD] != 0:
            ti.atomic_max(flags[F_NEED], rcnt[i])
            m = ti.min(rcnt[i], cap)
            rcnt[i] = m
            for a in range(1, m):
                v = rev[i, a]
                b = a
                while b > 0 and rev[i, b - 1] > v:
                    rev[i, b] = rev[i, b - 1]
                    b -= 1
                rev[i, b] = v
    # 7. 3D: the mesh triangles binned into the cells (the broad phase): each triangle
    #    in every cell its bounding box, widened by a cell (>= R + skin), reaches
    if ti.static(dim == 3):
        bin_triangles(wall, nwalls, gridp, gridn, ncell, nx, nrows, flags, tbin_count,
                      tbin_start, tbin_items)
    # 8. candidate walls (within R + skin), sorted by wall index, history carried over:
    #    in 3D the triangles of the particle's cell (all of them if the bins overflowed);
    #    near a periodic side, also those of its image across it (docstring)
    for i in range(n):
        if flags[F_REBUILD] != 0:
            capw = wid.shape[1]
            for s in range(capw):
                wid_old[i, s] = wid[i, s]
                whist_old[i, s] = whist[i, s]
            cut = prop[i][PROP_RADIUS] + skin
            cnt = 0
            binned = False
            if ti.static(dim == 3):
                binned = flags[F_TBIN_TOTAL] <= tbin_items.shape[0]
            for img in range(3 ** dim):
                use, xi = periodic_image(pos[i], img, per, skin)
                if use:
                    cnt = list_walls_near(i, xi, cut, cnt, img != 0, wall, wid, whist,
                                          wid_old, whist_old, nwalls, binned, gridp, gridn,
                                          tbin_start, tbin_count, tbin_items)
            ti.atomic_max(flags[F_WALL_NEED], cnt)
            for s in range(cnt, capw):
                wid[i, s] = -1
                whist[i, s] = zero_history(whist[i, s])
    ti.loop_config(serialize=True)
    for w in range(nwalls):
        if flags[F_REBUILD] != 0:
            wall[w, ti.static(11 if dim == 2 else T_DISP)] = 0.0
    ti.loop_config(serialize=True)
    for _ in range(1):
        if flags[F_REBUILD] != 0:
            flags[F_BUILDS] += 1
            flags[F_REBUILD] = 0




@ti.func
def periodic_image(x, img, per, margin):
    """Image ``img`` of point x (a base-3 digit per axis: 0 x itself, 1 one period up,
    2 one period down) and whether it is wanted: every shifted axis periodic and x
    within ``margin`` of the side it would cross to get there."""
    use = True
    code = img
    for ax in ti.static(range(x.n)):
        digit = code % 3
        code //= 3
        if digit != 0:
            x0 = per[2 * ax]
            span = per[2 * ax + 1]
            if span <= 0.0:
                use = False
            elif digit == 1:
                use = use and x[ax] - x0 < margin
                x[ax] += span
            else:
                use = use and x0 + span - x[ax] < margin
                x[ax] -= span
    return use, x


@ti.func
def list_walls_near(i, xi, cut, cnt, dedupe, wall: ti.template(), wid: ti.template(),
                    whist: ti.template(), wid_old: ti.template(), whist_old: ti.template(),
                    nwalls, binned, gridp: ti.template(), gridn: ti.template(),
                    tbin_start: ti.template(), tbin_count: ti.template(),
                    tbin_items: ti.template()):
    """Add to particle i's candidate walls (``cnt`` listed so far) those within
    ``cut`` of the point xi, in wall order, each with its history of the last list;
    in 3D from the triangles binned in xi's cell when ``binned``. ``dedupe``: skip
    walls already listed (a second point of the same particle). Returns the count,
    which goes on past the slots when they are short (the host then grows them)."""
    capw = wid.shape[1]
    first = 0
    last = nwalls
    if ti.static(xi.n == 3):
        if binned:
            c = cell_index(cell_of(xi, gridp, gridn), gridn)
            first = tbin_start[c]
            last = first + tbin_count[c]
    for e in range(first, last):
        w = e
        if ti.static(xi.n == 3):
            if binned:
                w = tbin_items[e]
        d = wall_offset(wall, w, xi)
        if d.dot(d) < cut * cut:
            listed = False
            if dedupe:
                for s in range(ti.min(cnt, capw)):
                    if wid[i, s] == w:
                        listed = True
            if not listed:
                if cnt < capw:
                    h = zero_history(whist[i, 0])
                    for s in range(capw):
                        if wid_old[i, s] == w:
                            h = whist_old[i, s]
                    # insertion by wall index (a fixed order whatever the bins')
                    k = cnt
                    while k > 0 and wid[i, k - 1] > w:
                        wid[i, k] = wid[i, k - 1]
                        whist[i, k] = whist[i, k - 1]
                        k -= 1
                    wid[i, k] = w
                    whist[i, k] = h
                cnt += 1
    return cnt


@ti.func
def bin_triangles(wall: ti.template(), nwalls, gridp: ti.template(), gridn: ti.template(),
                  ncell, nx, nrows, flags: ti.template(), tbin_count: ti.template(),
                  tbin_start: ti.template(), tbin_items: ti.template()):
    """Counting sort of the mesh triangles into the cells their bounding boxes, widened
    by one cell on every side, overlap (clamped to the grid like the particles); a
    particle then looks only at its own cell's list. flags[F_TBIN_TOTAL] is the
    number of entries; more than the bins hold leaves them unfilled (the build then
    looks at every triangle) and raises flags[F_TBIN_NEED] for the host to grow them."""
    for c in range(ncell):
        if flags[F_REBUILD] != 0:
            tbin_count[c] = 0
    for w in range(nwalls):
        if flags[F_REBUILD] != 0:
            lo, hi = _triangle_cells(wall, w, gridp, gridn)
            for cz in range(lo[2], hi[2] + 1):
                for cy in range(lo[1], hi[1] + 1):
                    for cx in range(lo[0], hi[0] + 1):
                        ti.atomic_add(tbin_count[cell_index(ti.Vector([cx, cy, cz]), gridn)], 1)
    for r in range(nrows):
        if flags[F_REBUILD] != 0:
            s = 0
            for cx in range(nx):
                c = r * nx + cx
                tbin_start[c] = s
                s += tbin_count[c]
            tbin_start[ncell + r] = s
    ti.loop_config(serialize=True)
    for r in range(nrows):
        if flags[F_REBUILD] != 0:
            if r == 0:
                flags[F_TBIN_TOTAL] = 0
            tot = tbin_start[ncell + r]
            tbin_start[ncell + r] = flags[F_TBIN_TOTAL]
            flags[F_TBIN_TOTAL] += tot
    ti.loop_config(serialize=True)
    for _k in range(1):
        if flags[F_REBUILD] != 0 and flags[F_TBIN_TOTAL] > tbin_items.shape[0]:
            ti.atomic_max(flags[F_TBIN_NEED], flags[F_TBIN_TOTAL])
    for c in range(ncell):
        if flags[F_REBUILD] != 0 and flags[F_TBIN_TOTAL] <= tbin_items.shape[0]:
            tbin_start[c] += tbin_start[ncell + c // nx]
            tbin_count[c] = 0
    for w in range(nwalls):
        if flags[F_REBUILD] != 0 and flags[F_TBIN_TOTAL] <= tbin_items.shape[0]:
            lo, hi = _triangle_cells(wall, w, gridp, gridn)
            for cz in range(lo[2], hi[2] + 1):
                for cy in range(lo[1], hi[1] + 1):
                    for cx in range(lo[0], hi[0] + 1):
                        c = cell_index(ti.Vector([cx, cy, cz]), gridn)
                        slot = ti.atomic_add(tbin_count[c], 1)
                        tbin_items[tbin_start[c] + slot] = w


@ti.func
def _triangle_cells(wall: ti.template(), w, gridp: ti.template(), gridn: ti.template()):
    """The lower and upper cells (inclusive) of triangle w's bounding box widened by
    one cell, clamped to the grid."""
    a = ti.Vector([wall[w, T_AX], wall[w, T_AX + 1], wall[w, T_AX + 2]])
    b = ti.Vector([wall[w, T_BX], wall[w, T_BX + 1], wall[w, T_BX + 2]])
    c = ti.Vector([wall[w, T_CX], wall[w, T_CX + 1], wall[w, T_CX + 2]])
    lo = cell_of(ti.min(a, b, c), gridp, gridn)
    hi = cell_of(ti.max(a, b, c), gridp, gridn)
    for k in ti.static(range(3)):
        lo[k] = ti.max(lo[k] - 1, 0)
        hi[k] = ti.min(hi[k] + 1, gridn[k] - 1)
    return lo, hi


@ti.kernel
def bounds(pos: ti.types.ndarray(), prop: ti.types.ndarray(), out: ti.types.ndarray(),
           dim: ti.template()):
    """out = (lower corner, upper corner, rmax) over finite positions: (xmin, ymin,
    xmax, ymax, rmax) in 2D."""
    for k in ti.static(range(dim)):
        out[k] = 1e300
        out[dim + k] = -1e300
    out[2 * dim] = 0.0
    for i in range(pos.shape[0]):
        x = pos[i]
        if ti.abs(x).max() < 1e200:
            for k in ti.static(range(dim)):
                ti.atomic_min(out[k], x[k])
                ti.atomic_max(out[dim + k], x[k])
        ti.atomic_max(out[2 * dim], prop[i][PROP_RADIUS])
