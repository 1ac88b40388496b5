"""The stress pass of the PCMM elements (step 2) and the records the gather reads.

:func:`stresses`: per computed element, N_e (recounted only where it can have
changed), the stress update (Eqs. 6–12) and the record from which the gather
(:func:`physics.pcmm.gather`) makes the nodal forces (Eqs. 13–14). The records'
layout: :func:`_record`, :func:`_pack2`, :func:`_corner_force`.
:func:`equation_of_state`: the per-particle state of JWL products and of a Fluid
with an equation of state, and the stresses of their elements. The viscous and
bulk-viscosity terms (:func:`viscous_stress`, :func:`bulk_viscosity`) act on the
forces of the step only (the blocks share :func:`viscous_stress`).
"""
import taichi as ti

from tdem.core.launch import cached

from .. import fvm
from ..materials import (FLUID, JWL_D, JWL_OMEGA, JWL_TYPE, MAT_B1, MAT_B2, MAT_EOS,
                         MAT_FLUID_TAU, MAT_G, MAT_K, MAT_RHO, MAT_TYPE, MAT_VISC,
                         fluid_pressure, jwl_pressure, mc_correct_state, mixes, relax_shear)
from .layout import P_NEW, P_RECOUNT, P_SOFT, inc_element
from .rebuild import SLACK_FLOOR
from .rules import _cover_incident, _sorted3


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
             pmix: ti.types.ndarray(),
             dt: ti.f64, carry: ti.template(), eos: ti.template(), mixed: ti.template(),
             serial: ti.template()):
    """2. Per computed element: N_e (probe rule; recounted where the elements around
    it changed or its vertices' neighbourhoods moved farther than the count's slack,
    ``ebud``, the same bookkeeping as :func:`rebuild_elements`), σ_old (the element's
    own stress of last step if it existed and ``carry``, else the mean of its
    particles' stresses), Eqs. 6–11 with the Jaumann rotation (velocity gradient on
    the mid-step configuration, see :mod:`physics.blocks`), the constitutive
    correction (Eq. 12), and the record from which the gather makes the nodal
    forces with the weight 1/N_e (Eqs. 13–14, sign fixed; :func:`_record`), in the
    next place of the particle's run of records (``eidx``, :func:`record_slots`);
    the stress at the same place of ``sigc`` (:func:`copies`).

    ``mixed``: the nodal mixed discretization (:mod:`physics.fvm`) for the elements
    of the materials that take it (:func:`physics.materials.mixes`, Mohr–Coulomb): the volumetric part of each
    element's strain increment is the mean over its three particles of their
    averages Σ V_e Δθ_e / Σ V_e over the elements containing them (V_e = k S_e/N_e,
    the element's share of the area, k its multiplicity), and the in-plane mean
    stress of its nodal forces the same average of the elements' mean stresses
    (``pmix`` (N, 2) holds the particles' averages). The passes: (a) N_e, the
    kinematics and (Δθ, V) per record; (b) the particles' Δθ; (c) the stresses;
    (d) the particles' mean stresses; (e) the records. Until (e) the record lines
    ``efor[j]`` hold the passes' data."""
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
                if ti.static(mixed):
                    grad, de, area = _kinematics(a, b, c, pos, vel, dt)
                    efor[j] = ti.Vector([de[0], de[1], de[2], fvm.spin_rate(grad),
                                         ti.cast(jold, ti.f64), ti.cast(cover, ti.f64),
                                         de[0] + de[1],
                                         ti.cast(emult[a, s], ti.f64) * area / cover])
                else:
                    _element_stress(a, s, j, jold, cover, 0.0, pos, vel, pmat, matp, elem,
                                    ecnt, emult, esig, sigp, sigc, efor, ede, psig, pfail,
                                    elem_old, esig_old, ecnt_old, esrc, prb, dt, carry, eos,
                                    False)
                j += 1
    if ti.static(mixed):
        ti.loop_config(serialize=serial)
        for i in range(pmat.shape[0]):
            pmix[i] = ti.Vector([_particle_mean(i, 6, pmat, matp, inc, icnt, eidx, efor), 0.0])
        ti.loop_config(serialize=serial)
        for a in range(pmat.shape[0]):
            for s in range(ecnt[a]):
                if emult[a, s] > 0:
                    j = eidx[a, s]
                    r = efor[j]
                    theta = (pmix[a][0] + pmix[elem[a, s, 0]][0] + pmix[elem[a, s, 1]][0]) / 3.0
                    _element_stress(a, s, j, ti.cast(r[4], ti.i32), ti.cast(r[5], ti.i32),
                                    theta, pos, vel, pmat, matp, elem, ecnt, emult, esig, sigp,
                                    sigc, efor, ede, psig, pfail, elem_old, esig_old, ecnt_old,
                                    esrc, prb, dt, carry, eos, True)
        ti.loop_config(serialize=serial)
        for i in range(pmat.shape[0]):
            pmix[i][1] = _particle_mean(i, 6, pmat, matp, inc, icnt, eidx, efor)
        ti.loop_config(serialize=serial)
        for a in range(pmat.shape[0]):
            for s in range(ecnt[a]):
                if emult[a, s] > 0:
                    j = eidx[a, s]
                    r = efor[j]
                    b = elem[a, s, 0]
                    c = elem[a, s, 1]
                    mean = (pmix[a][1] + pmix[b][1] + pmix[c][1]) / 3.0
                    de = ti.Vector([r[0], r[1], r[2]])
                    area = r[7] * r[3] / ti.cast(emult[a, s], ti.f64)
                    flag = ti.cast(r[5], ti.i32)
                    _finish(a, s, j, b, c, pmat[a], sigc[j], r[4], flag, de, area,
                            ti.cast(r[3], ti.i32), matp, emult, efor, ede, dt, eos, True, mean)


@ti.func
def _particle_mean(i, k, pmat: ti.template(), matp: ti.template(), inc: ti.template(),
                   icnt: ti.template(), eidx: ti.template(), efor: ti.template()):
    """Σ V_e q_e / Σ V_e over the elements containing particle i, q_e in column k of
    their record lines and V_e in column 7 (:func:`stresses`, mixed); 0 for a
    particle of a material that does not mix (:func:`physics.materials.mixes`), or
    in no element."""
    out = 0.0
    M = pmat[i]
    if M >= 0:
        if mixes(matp, M):
            num = 0.0
            den = 0.0
            for q in range(icnt[i]):
                o, sl = inc_element(inc[i, q])
                r = efor[eidx[o, sl]]
                num += r[7] * r[k]
                den += r[7]
            if den > 0.0:
                out = num / den
    return out


@ti.func
def _element_stress(a, s, j, jold, cover, theta, pos: ti.template(), vel: ti.template(),
                    pmat: ti.template(), matp: ti.template(), elem: ti.template(),
                    ecnt: ti.template(), emult: ti.template(), esig: ti.template(),
                    sigp: ti.template(), sigc: ti.template(), efor: ti.template(),
                    ede: ti.template(), psig: ti.template(), pfail: ti.template(),
                    elem_old: ti.template(), esig_old: ti.template(),
                    ecnt_old: ti.template(), esrc: ti.template(), prb: ti.template(), dt,
                    carry: ti.template(), eos: ti.template(), mixed: ti.template()):
    """The stress update of the element in a's slot s (record j; ``jold`` last step's
    record of the slot, ``cover`` its N_e): Eqs. 6–12, into ``sigc[j]``. Not
    ``mixed``: the record follows (:func:`_finish`). ``mixed``: the strain
    increment's volumetric part is ``theta`` (for a material that mixes), and ``efor[j]`` keeps (Δε, N_e, Δe^ps, flag, in-plane mean stress of the
    forces, V_e) for the passes that follow (:func:`stresses`)."""
    b = elem[a, s, 0]
    c = elem[a, s, 1]
    de = ti.Vector([0.0, 0.0, 0.0])
    spin = 0.0
    area = 0.0
    M = pmat[a]
    if ti.static(mixed):
        # the kinematics of pass (a), kept in the record line
        r = efor[j]
        de = ti.Vector([r[0], r[1], r[2]])
        spin = r[3]
        area = r[7] * r[5] / ti.cast(emult[a, s], ti.f64)
        if mixes(matp, M):
            de = fvm.mixed_strain(de, theta)
    else:
        grad, de0, area0 = _kinematics(a, b, c, pos, vel, dt)
        de = de0
        area = area0
        spin = fvm.spin_rate(grad)
    kind = ti.cast(matp[M, MAT_TYPE], ti.i32)
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
        sig = fvm.jaumann_rotate(sig, spin, dt) + fvm.elastic_increment(
            de, matp[M, MAT_K], matp[M, MAT_G])
        if kind == FLUID:
            sig = relax_shear(sig, matp[M, MAT_FLUID_TAU], dt)
        failed = 0
        if pfail[a] + pfail[b] + pfail[c] > 0:
            failed = 1
        sig, eps, flag = mc_correct_state(sig, matp, M, failed)
    sigc[j] = sig
    if ti.static(mixed):
        sf = _force_stress(matp, M, sig, de, dt, area)
        efor[j] = ti.Vector([de[0], de[1], de[2], ti.cast(cover, ti.f64), eps,
                             ti.cast(flag, ti.f64), 0.5 * (sf[0] + sf[1]),
                             ti.cast(emult[a, s], ti.f64) * area / cover])
    else:
        _finish(a, s, j, b, c, M, sig, eps, flag, de, area, cover, matp, emult, efor, ede,
                dt, eos, False, 0.0)


@ti.func
def _kinematics(a, b, c, pos: ti.template(), vel: ti.template(), dt):
    """Velocity gradient (Eq. 6), strain increment (Eq. 7) and area of the element
    (a, b, c) on the mid-step configuration x − ½Δt·v: Δθ·area is then exactly the
    area change of the step (:func:`physics.fvm.mid_step`)."""
    grad, area = fvm.mid_step(a, b, c, pos, vel, dt)
    return grad, fvm.strain_increment(grad, dt), area


@ti.func
def _force_stress(matp: ti.template(), M, sig, de, dt, area):
    """The stress of an element's nodal forces: its stress, with the viscous stress
    and the artificial bulk viscosity (a material with an equation of state: the
    stress, which :func:`equation_of_state` replaces)."""
    sf = sig
    if not _has_eos(matp, M):
        q = bulk_viscosity(matp, M, de, dt, area)
        sf = sig + viscous_stress(matp, M, de, dt) + ti.Vector([-q, -q, 0.0, 0.0])
    return sf


@ti.func
def _finish(a, s, j, b, c, M, sig, eps, flag, de, area, cover, matp: ti.template(),
            emult: ti.template(), efor: ti.template(), ede: ti.template(), dt,
            eos: ti.template(), mixed: ti.template(), mean):
    """The end of step 2 for element (a, s) with its corrected stress: the state
    the equation of state reads (``ede``), the stress of its nodal forces
    (artificial bulk viscosity and viscous stress included; ``mixed``: its in-plane
    mean replaced by ``mean``) and the gather's record (``efor``), from which the
    gather makes the forces."""
    q = bulk_viscosity(matp, M, de, dt, area)
    if ti.static(eos):
        ede[a, s] = ti.Vector([de[0], de[1], de[2], eps, ti.cast(flag, ti.f64),
                               area / cover, q * (de[0] + de[1])])
    sf = sig
    wf = 0.0
    if not _has_eos(matp, M):
        sf = _force_stress(matp, M, sig, de, dt, area)
        if ti.static(mixed):
            if mixes(matp, M):
                sf = fvm.mixed_stress(sf, mean)
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
                      time: ti.f64, first: ti.i32, serial: ti.template()):
    """2j. Particles with an equation of state (JWL, or a Fluid with
    ``equation_of_state``): the state at x_n. A particle's volume changes by a third
    of the mean of two sums of (S_e/N_e) ΔS_e, ΔS_e the area change of the last step:
    over this step's elements (Δθ_e of the stress pass) and over the elements that
    pushed over the last step (:func:`eos_volumes`, kept in column 5); where an
    element was created or deleted by the rules between the two, or its N_e
    changed, the two differ. The mean, with the energy change below, keeps kinetic
    (at half steps) plus internal energy: the half-step kinetic energy takes the
    work of each step's forces over half of the motion before and half of the
    motion after them. JWL: the energy changes by −(p̄ + q) ΔVol, p̄ the mean of
    the pressures before and after the change (implicit in the energy, solved in
    closed form: p_JWL is linear in E), p = F·p_JWL(V, E) with F the programmed
    burn fraction. Fluid: p(V) of :class:`physics.materials.Fluid` (a state
    function: deleting or creating elements does not change it). At a run's first
    step there is no last step's set: this step's sums alone.
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
                    o, sl = inc_element(code)
                    d = ede[o, sl]
                    mw = ti.cast(emult[o, sl], ti.f64)
                    thsum += mw * d[5] * (d[0] + d[1])
                    qsum += mw * d[5] * d[6]
                js = pjwl[i]
                V0 = js[4]
                if first == 0:
                    thsum = 0.5 * (thsum + js[5])
                dv = thsum / (3.0 * V0)
                V = js[0] + dv
                if ti.cast(matp[M, MAT_TYPE], ti.i32) == JWL_TYPE:
                    F = 0.0
                    if time >= js[2]:
                        F = ti.min(1.0, (time - js[2]) * matp[M, JWL_D] / (3.0 * rad[i]))
                    # E' = E − (½(p + F·p_JWL(V', E')) + q) ΔV, p_JWL = a(V) + ω E / V
                    a0 = F * jwl_pressure(matp, M, V, 0.0)
                    E = ((js[1] - 0.5 * (js[3] + a0) * dv - qsum / (3.0 * V0))
                         / (1.0 + 0.5 * F * matp[M, JWL_OMEGA] * dv / V))
                    p = F * jwl_pressure(matp, M, V, E)
                    pjwl[i] = ti.Vector([V, E, js[2], p, V0, js[5]])
                else:
                    pjwl[i] = ti.Vector([V, js[1], js[2], fluid_pressure(matp, M, V), V0, js[5]])
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
def eos_volumes(pmat: ti.types.ndarray(), matp: ti.types.ndarray(), pos: ti.types.ndarray(),
                vel: ti.types.ndarray(), elem: ti.types.ndarray(), emult: ti.types.ndarray(),
                inc: ti.types.ndarray(), icnt: ti.types.ndarray(), ncov: ti.types.ndarray(),
                pjwl: ti.types.ndarray(), dt: ti.f64, serial: ti.template()):
    """The end of a step: for each particle with an equation of state, Σ_e (S_e/N_e)
    ΔS_e over the elements containing it that pushed over the step (their weights
    as the forces had them), ΔS_e = S_e(x_{n+1}) − S_e(x_{n+1} − Δt·v_{n+1/2})
    exactly; kept in column 5 of ``pjwl`` for :func:`equation_of_state`."""
    ti.loop_config(serialize=serial)
    for i in range(pmat.shape[0]):
        M = pmat[i]
        if M >= 0:
            if _has_eos(matp, M):
                acc = 0.0
                for k in range(icnt[i]):
                    code = inc[i, k]
                    o, sl = inc_element(code)
                    b = elem[o, sl, 0]
                    c = elem[o, sl, 1]
                    xa, xb, xc = pos[o], pos[b], pos[c]
                    da = fvm.area(xa, xb, xc) - fvm.area(xa - dt * vel[o], xb - dt * vel[b],
                                                         xc - dt * vel[c])
                    acc += ti.cast(emult[o, sl], ti.f64) / ncov[o, sl] * da
                js = pjwl[i]
                pjwl[i] = ti.Vector([js[0], js[1], js[2], js[3], js[4], acc])


@ti.func
def bulk_viscosity(matp: ti.template(), M, de, dt, area):
    """Pressure q ≥ 0 of the artificial bulk viscosity of columns 12–13 (module
    docstring of :mod:`physics.materials`), for a shrinking element only."""
    q = 0.0
    th = de[0] + de[1]
    b1 = matp[M, MAT_B1]
    b2 = matp[M, MAT_B2]
    if th < 0.0 and b1 + b2 > 0.0:
        L = ti.sqrt(ti.abs(area))
        rate = -th / dt
        rho = matp[M, MAT_RHO]
        c = ti.sqrt((matp[M, MAT_K] + 4.0 * matp[M, MAT_G] / 3.0) / rho)
        q = rho * L * rate * (b1 * c + b2 * L * rate)
    return q


@ti.func
def _has_eos(matp: ti.template(), M):
    """Whether material row M keeps its pressure per particle: JWL, or a Fluid with
    ``equation_of_state`` (column 4 = 1)."""
    kind = ti.cast(matp[M, MAT_TYPE], ti.i32)
    return kind == JWL_TYPE or (kind == FLUID and matp[M, MAT_EOS] > 0.0)


@ti.func
def viscous_stress(matp: ti.template(), M, de, dt):
    """Viscous stress 2μ·dev(D) of a Fluid row (μ in column 11), D = Δε/Δt in plane
    strain (D_zz = 0); zero for other materials. Not accumulated: it acts on the
    forces of the step only."""
    mu = matp[M, MAT_VISC]
    out = ti.Vector([0.0, 0.0, 0.0, 0.0])
    if mu > 0.0:
        tr = (de[0] + de[1]) / 3.0
        out = 2.0 * mu / dt * ti.Vector([de[0] - tr, de[1] - tr, de[2], -tr])
    return out
