"""The engine-side element system: candidates and the lazy rebuild.

These kernels run inside :class:`tdem.Simulation`'s step (in the order of Feng,
Li & Oñate 2015, §2):
:func:`candidates` after each neighbour-list build, the others every step from
:func:`physics.pcmm.update` before the stress pass (:mod:`physics.pcmm.stress`).
Particles of one PCMM body share a material slot ``pmat[i] >= 0`` (−1: a plain DEM
disc); elements join particles of one slot only.

In the order of a step: the displacements since the epoch began
(:func:`displacements`, 0), the element set the rules give, rebuilt only where it
can have changed (:func:`rebuild_elements`, 1; see "Rebuilt where something can
have changed" in :mod:`physics.pcmm`), the particles around which something
changed (:func:`mark_dirty`, 1a), the copies of each triangle and which one is
computed (:func:`copies`, 1b), the computed elements containing each particle
(:func:`incidence`, 1c) and where the records of the computed elements go
(:func:`record_slots`, 1d). :func:`sync_copies` brings every slot's stress up to
date before the host reads or saves them.
"""
import taichi as ti

from physics.materials import FLUID, JWL_SWELL, JWL_TYPE, MAT_CELLS, MAT_TYPE
from tdem.core.launch import cached
from tdem.core.layout import F_REBUILD

from .layout import (MAX_INCIDENT, P_BUILDS, P_BUILT, P_EPOCH, P_INC, P_NEED, P_NEW,
                     P_REBUILT, P_RECOUNT, P_SOFT, SCAN_BLOCK, inc_code)
from .rules import _create, _dist_slack, _ring

EPOCH_REBUILT = 0.01   # the epoch is renewed after a step that rebuilt this fraction
EPOCH_RECOUNT = 0.02   # ... or recounted N_e of this many elements per particle
REBUILT_CHANGED = 1    # prb: the particle rebuilt, and its Eq. 1 list or elements changed
REBUILT_SAME = 2       # prb: it rebuilt and found the same Eq. 1 list and elements
SLACK_FLOOR = 1e-9     # relative to the radius: slack below this counts as none


@cached
@ti.kernel
def candidates(pos: ti.types.ndarray(), rad: ti.types.ndarray(), rcand: ti.types.ndarray(),
               rmax: ti.types.ndarray(), pmat: ti.types.ndarray(),
               mtol: ti.types.ndarray(), cand: ti.types.ndarray(), ccnt: ti.types.ndarray(),
               cell_count: ti.types.ndarray(), cell_start: ti.types.ndarray(),
               sorted_ids: ti.types.ndarray(), gridp: ti.types.ndarray(),
               gridn: ti.types.ndarray(), flags: ti.types.ndarray(),
               pflags: ti.types.ndarray(), builds: ti.i32, skin: ti.f64, reach: ti.i32):
    """Verlet candidates of Eq. 1: every j of the same body with
    d_ij < R_i + R_j + δ + skin, sorted by index, from the engine's cell grid;
    ``rad`` the radii the rules see (a swelling JWL particle's grows, :func:`swell`),
    kept in ``rcand`` as they were at this build.

    Runs only when the engine has rebuilt its lists since the candidates were made
    (``flags[builds] != pflags[P_BUILDS]``): between builds no particle moves more
    than half the skin, less its rule radius's growth (:func:`swell`), so every
    pair within the Eq. 1 distance stays listed. ``reach``: how many cells to
    search on each side (the Eq. 1 cut-off plus the skin can exceed the engine's
    cell side), widened where the rule radii have grown (``rmax[0]``, the largest
    grown rule radius, by :func:`swell`).
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
            rcand[i] = ri
            reach_i = reach
            if rmax[0] > 0.0:
                reach_i = ti.max(reach, ti.cast(ti.ceil((ri + rmax[0] + mtol[m] + skin)
                                                        / gridp[2]), ti.i32))
            cx = ti.math.clamp(ti.cast(ti.floor((xi[0] - gridp[0]) / gridp[2]), ti.i32), 0, nx - 1)
            cy = ti.math.clamp(ti.cast(ti.floor((xi[1] - gridp[1]) / gridp[2]), ti.i32), 0, ny - 1)
            cnt = 0
            for ccy in range(ti.max(cy - reach_i, 0), ti.min(cy + reach_i + 1, ny)):
                for ccx in range(ti.max(cx - reach_i, 0), ti.min(cx + reach_i + 1, nx)):
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
def swell(pmat: ti.types.ndarray(), matp: ti.types.ndarray(), rad: ti.types.ndarray(),
          rrule: ti.types.ndarray(), rcand: ti.types.ndarray(), rmax: ti.types.ndarray(),
          mtol: ti.types.ndarray(), pjwl: ti.types.ndarray(), cand: ti.types.ndarray(),
          ccnt: ti.types.ndarray(),
          pbud: ti.types.ndarray(), pos: ti.types.ndarray(), xref: ti.types.ndarray(),
          flags: ti.types.ndarray(), skin: ti.f64, serial: ti.template()):
    """The end of a step: the rule radius of each swelling JWL particle
    (:class:`physics.materials.JWL`), s·R0 + δ(s − 1)/2 with s = sqrt(max(V, 1)),
    V its relative volume (``pjwl`` column 0; ``rad`` the radii R0, ``mtol`` δ):
    the Eq. 1 cut-off R_i + R_j + δ of two particles that expanded alike by s is
    then s times the first, so a uniform expansion keeps every Eq. 1 pair. A
    particle whose rule radius changed, and every candidate of it, rebuild their
    elements at the next step
    (``pbud`` = −1: the slacks of the rules knew the old radius). A particle whose
    displacement since the neighbour lists were built (``xref``) plus its rule
    radius's growth since the candidates were made (``rcand``) exceeds half the skin
    asks for a new build (``flags[F_REBUILD]``): a pair left out of the candidates
    was then at least R_i + R_j + δ + skin apart, and each has since closed at most
    half the skin on it. ``rmax[0]``: the largest grown rule radius (0 while none
    has grown), for the candidates' reach."""
    ti.loop_config(serialize=serial)
    for i in range(pmat.shape[0]):
        M = pmat[i]
        if M >= 0:
            if ti.cast(matp[M, MAT_TYPE], ti.i32) == JWL_TYPE and matp[M, JWL_SWELL] > 0.0:
                sc = ti.sqrt(ti.max(pjwl[i][0], 1.0))
                r = sc * rad[i] + 0.5 * (sc - 1.0) * mtol[M]
                if r != rrule[i]:
                    rrule[i] = r
                    pbud[i] = -1.0
                    for q in range(ccnt[i]):
                        pbud[cand[i, q]] = -1.0
                if r > rad[i]:
                    ti.atomic_max(rmax[0], r)
                if (pos[i] - xref[i]).norm() + (r - rcand[i]) > 0.5 * skin:
                    flags[F_REBUILD] = 1


@cached
@ti.kernel
def rebuild_elements(pos: ti.types.ndarray(), rad: ti.types.ndarray(),
                     pmat: ti.types.ndarray(), matp: ti.types.ndarray(),
                     mtol: ti.types.ndarray(),
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
                rs = 1e300
                cs = 1e300
                ne = 0
                if not (ti.cast(matp[m, MAT_TYPE], ti.i32) == FLUID and matp[m, MAT_CELLS] > 0.0):
                    # (a Fluid of Voronoi cells makes no elements: physics.pcmm.cells)
                    r, rs0 = _ring(i, xi, cnt, pos, nbr, ring, rang)
                    rs = rs0
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
                                inc[i, cnt] = inc_code(o, s, _corner(
                                    o, elem[o, s, 0], elem[o, s, 1], i))
                                wt += emult[o, s]
                            cnt += 1
                if cnt > MAX_INCIDENT:
                    ti.atomic_max(pflags[P_INC], cnt)
                    cnt = MAX_INCIDENT
            icnt[i] = cnt
            iwt[i] = wt
