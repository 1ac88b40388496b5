"""Sort-and-sweep broad phase (``Simulation(broad_phase="sweep")``).

The alternative to the cell grid of :mod:`tdem.neighbors` that Chen's polyhedral DEM
uses ("sorting the axis-aligned bounding boxes in three dimensions"), in the
incremental form of Cohen et al. (1995, I-COLLIDE) and of Yade's
``InsertionSortCollider``:

- each particle has a box, its centre ± (R + skin/2) along every axis (R its
  bounding radius); along each axis the 2n box ends are kept sorted, from one list
  build to the next;
- a build refreshes the ends' values and sorts each axis again by insertion, which
  costs O(n + swaps) since particles move less than a skin between builds;
- each swap is an event: where a box's lower end passes below another's upper end,
  the two boxes may have begun to overlap — if they overlap along every axis the
  pair enters the box-pair list (``spair``) of its lower index; where an upper end
  passes below a lower end, the boxes have parted — the pair leaves it.

The half lists are then the box pairs within R_i + R_j + skin, in partner order, with
the histories carried over: the very lists of the grid's build. What follows them
(reverse lists, candidate walls) is the grid's too
(:func:`tdem.neighbors.finish_build`), so the two broad phases give the same forces,
bit for bit; they differ only in how the candidates are found.

The sorting and the events run on one thread (each swap edits two particles' lists);
the first build, and any build after the arrays were reallocated or restored
(``flags[F_SWEEP]`` 0), makes the pair set afresh by a sweep along x, one particle
per thread, with the histories carried over like the grid's. Not with periodic axes
or PCMM/blocks (they use the grid's cells); :meth:`tdem.Simulation.__init__` says so.
"""
import taichi as ti

from .launch import cached
from .neighbors import (F_NEED, F_REBUILD, F_SWEEP, close_half_list, finish_build,
                        insert_partner)
from .state import PROP_RADIUS


@ti.func
def _end(pos: ti.template(), prop: ti.template(), e, a, half):
    """The value along axis a of box end e: particle e >> 1, its upper end if e & 1."""
    i = e >> 1
    r = prop[i][PROP_RADIUS] + half
    return pos[i][a] + ti.select((e & 1) == 1, r, -r)


@ti.func
def _boxes_overlap(pos: ti.template(), prop: ti.template(), i, j, skin, dim: ti.template()):
    """Whether the boxes of i and j overlap (touching counts) along every axis."""
    reach = prop[i][PROP_RADIUS] + prop[j][PROP_RADIUS] + skin
    ok = True
    for b in ti.static(range(dim)):
        if ti.abs(pos[i][b] - pos[j][b]) > reach:
            ok = False
    return ok


@ti.func
def _add_pair(spair: ti.template(), scnt: ti.template(), flags: ti.template(), i, j):
    """Pair (i, j) into the box-pair list of the lower index (kept sorted), unless it is
    there; a full list counts what it needed."""
    a = ti.min(i, j)
    b = ti.max(i, j)
    c = scnt[a]
    there = False
    for k in range(c):
        if spair[a, k] == b:
            there = True
    if not there:
        if c < spair.shape[1]:
            insert_partner(spair, a, c, b)
            scnt[a] = c + 1
        else:
            ti.atomic_max(flags[F_NEED], c + 1)


@ti.func
def _remove_pair(spair: ti.template(), scnt: ti.template(), i, j):
    """Pair (i, j) out of the box-pair list of the lower index (if there)."""
    a = ti.min(i, j)
    b = ti.max(i, j)
    c = scnt[a]
    at = -1
    for k in range(c):
        if spair[a, k] == b:
            at = k
    if at >= 0:
        for k in range(at, c - 1):
            spair[a, k] = spair[a, k + 1]
        spair[a, c - 1] = -1
        scnt[a] = c - 1


@cached
@ti.kernel
def rebuild(pos: ti.types.ndarray(), prop: ti.types.ndarray(), xref: ti.types.ndarray(),
            nbr: ti.types.ndarray(), ncnt: ti.types.ndarray(), hist: ti.types.ndarray(),
            nbr_old: ti.types.ndarray(), ncnt_old: ti.types.ndarray(),
            hist_old: ti.types.ndarray(), rev: ti.types.ndarray(), rcnt: ti.types.ndarray(),
            skey: ti.types.ndarray(), sent: ti.types.ndarray(), srank: ti.types.ndarray(),
            spair: ti.types.ndarray(), scnt: ti.types.ndarray(),
            gridp: ti.types.ndarray(), gridn: ti.types.ndarray(), flags: ti.types.ndarray(),
            wall: ti.types.ndarray(), wid: ti.types.ndarray(), whist: ti.types.ndarray(),
            wid_old: ti.types.ndarray(), whist_old: ti.types.ndarray(), nwalls: ti.i32,
            skin: ti.f64, tbin_count: ti.types.ndarray(), tbin_start: ti.types.ndarray(),
            tbin_items: ti.types.ndarray(), dim: ti.template()):
    n = pos.shape[0]
    ne = 2 * n
    half = 0.5 * skin
    nx = gridn[0]
    ncell = nx * gridn[1]
    if ti.static(dim == 3):
        ncell *= gridn[2]
    nrows = ncell // nx
    # 1. the box ends' values now; the old lists kept (histories)
    for a, k in ti.ndrange(dim, ne):
        if flags[F_REBUILD] != 0:
            skey[a, k] = _end(pos, prop, sent[a, k], a, half)
    for i in range(n):
        if flags[F_REBUILD] != 0:
            ncnt_old[i] = ncnt[i]
            for k in range(nbr.shape[1]):
                nbr_old[i, k] = nbr[i, k]
                hist_old[i, k] = hist[i, k]
    # 2. each axis sorted again by insertion; the swaps are the events that add and
    #    remove box pairs (while the set is kept, flags[F_SWEEP] = 1)
    ti.loop_config(serialize=True)
    for a in range(dim):
        if flags[F_REBUILD] != 0:
            track = flags[F_SWEEP] != 0
            for k in range(1, ne):
                e = sent[a, k]
                v = skey[a, k]
                m = k - 1
                while m >= 0 and skey[a, m] > v:
                    f = sent[a, m]
                    if track and (e >> 1) != (f >> 1):
                        if (e & 1) == 0 and (f & 1) == 1:
                            # e's lower end below f's upper end: they may now overlap
                            if _boxes_overlap(pos, prop, e >> 1, f >> 1, skin, dim):
                                _add_pair(spair, scnt, flags, e >> 1, f >> 1)
                        elif (e & 1) == 1 and (f & 1) == 0:
                            # e's upper end below f's lower end: they have parted
                            _remove_pair(spair, scnt, e >> 1, f >> 1)
                    skey[a, m + 1] = skey[a, m]
                    sent[a, m + 1] = f
                    m -= 1
                skey[a, m + 1] = v
                sent[a, m + 1] = e
    # 3. a fresh box-pair set: the sweep along x, one particle per thread — the boxes
    #    whose lower end lies in i's box, and those that began before it and end inside
    #    or after it (at most one box width back)
    for k in range(ne):
        if flags[F_REBUILD] != 0 and flags[F_SWEEP] == 0:
            srank[sent[0, k]] = k
    for i in range(n):
        if flags[F_REBUILD] != 0 and flags[F_SWEEP] == 0:
            kmin = srank[2 * i]
            kmax = srank[2 * i + 1]
            cnt = 0
            for k in range(kmin + 1, kmax):
                e = sent[0, k]
                j = e >> 1
                if (e & 1) == 0 and j > i:
                    if _boxes_overlap(pos, prop, i, j, skin, dim):
                        insert_partner(spair, i, cnt, j)
                        cnt += 1
            # (the grid's cells are at least the widest box: 2 R_max + skin)
            lim = skey[0, kmin] - gridp[dim]
            q = kmin - 1
            while q >= 0 and skey[0, q] >= lim:
                e = sent[0, q]
                j = e >> 1
                if (e & 1) == 0 and j > i and srank[2 * j + 1] > kmin:
                    if _boxes_overlap(pos, prop, i, j, skin, dim):
                        insert_partner(spair, i, cnt, j)
                        cnt += 1
                q -= 1
            ti.atomic_max(flags[F_NEED], cnt)
            scnt[i] = ti.min(cnt, spair.shape[1])
            for k in range(scnt[i], spair.shape[1]):
                spair[i, k] = -1
    # 4. the half lists: the box pairs within R_i + R_j + skin (as the grid's), in
    #    partner order, histories carried over
    for i in range(n):
        if flags[F_REBUILD] != 0:
            xi = pos[i]
            ri = prop[i][PROP_RADIUS]
            cnt = 0
            for k in range(scnt[i]):
                j = spair[i, k]
                d = pos[j] - xi
                cut = ri + prop[j][PROP_RADIUS] + skin
                if d.dot(d) < cut * cut:
                    nbr[i, cnt] = j
                    cnt += 1
            close_half_list(i, cnt, nbr, ncnt, hist, nbr_old, ncnt_old, hist_old)
            xref[i] = xi
            rcnt[i] = 0
    ti.loop_config(serialize=True)
    for _ in range(1):
        if flags[F_REBUILD] != 0:
            flags[F_SWEEP] = 1
    # 5. reverse lists, candidate walls: as after the grid's build
    finish_build(pos, prop, nbr, ncnt, rev, rcnt, gridp, gridn, flags, wall, wid, whist,
                 wid_old, whist_old, nwalls, skin, tbin_count, tbin_start, tbin_items, ncell,
                 nx, nrows, dim, ti.Vector([0.0 for _ in ti.static(range(2 * dim))]))
