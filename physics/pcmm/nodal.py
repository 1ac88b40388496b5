"""The gather of the PCMM elements (step 3): what each particle takes from the
elements containing it.

:func:`gather` makes each particle's force from its elements' records
(:func:`physics.pcmm.stress._corner_force`), its stress and strain as the means of
theirs, and marks the engine's pair slots of its same-body Eq. 1 neighbours
(:func:`_set_skip`): a pair the elements carry meets through no contact law.
Same-body Fluid and JWL neighbours repel through :func:`fluid_core_force`.
"""
import taichi as ti

from tdem.core.launch import cached
from tdem.core.layout import PROP_RADIUS

from ..contact_law import PAIR_TAIL, zero_history
from ..materials import FLUID, JWL_TYPE, MAT_K, MAT_TYPE
from .layout import P_BUILT, P_NEW, inc_element
from .stress import _corner_force, _has_eos, _unpack2

FLUID_CORE = 0.75  # λ of fluid_core_force
CARRIED = -1.0     # a pair history's overlap entry while elements carry the pair (_set_skip)


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
                o, s = inc_element(code)
                j = eidx[o, s]
                r = efor[j]
                f += _corner_force(code & 3, o, j, r, pos, efor)
                ssum += ti.Vector([r[0], r[1], r[2], r[3]])
                dxx, dyy, dpad = _unpack2(r[5])
                dxy, ep, failed = _unpack2(r[6])
                dsum += ti.Vector([dxx, dyy, dxy])
                psum += ti.abs(ep)
                if failed:
                    hit = 1
            kind_i = ti.cast(matp[pmat[i], MAT_TYPE], ti.i32)
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
    entry (u0, the first column of contact_law.PAIR_TAIL) is CARRIED (< 0) then, an overlap ≥ 0 otherwise. A pair that elements
    stop carrying starts the contact law afresh, counting from its overlap now
    (:func:`tdem.step.pair_contact`), so that the law takes over without a jump."""
    cskip[i, k] = skip
    h = hist[i, k]
    u0 = ti.static(h.n - len(PAIR_TAIL) + PAIR_TAIL.index("u0"))
    if skip == 1:
        if h[u0] >= 0.0:
            h[u0] = CARRIED
            hist[i, k] = h
    elif h[u0] < 0.0:
        u = prop[i][PROP_RADIUS] + prop[j][PROP_RADIUS] - (pos[j] - pos[i]).norm()
        h = zero_history(h)
        h[u0] = ti.max(u, 0.0)
        hist[i, k] = h


@ti.func
def _shares_element(i, j, inc: ti.template(), icnt: ti.template(), elem: ti.template()):
    """Whether j is a corner of one of the (computed) elements containing i."""
    found = False
    for q in range(icnt[i]):
        code = inc[i, q]
        o, s = inc_element(code)
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
        out = -matp[M, MAT_K] * (dc - L) / L * d
    return out
