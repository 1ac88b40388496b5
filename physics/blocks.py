"""Deformable blocks: triangle meshes with fixed connectivity (the CDEM's blocks).

A block is the element model the paper compares every PCMM model against: the
same incremental FVM update as the PCMM elements (:mod:`physics.fvm`, Eqs. 6–14)
with no superposition (weight 1), the stress living on the element, and lumped
nodal masses ρ·S/3. Elastic, Mohr–Coulomb and Fluid materials
(:mod:`physics.materials`) apply; brittle softening acts per element.

Time integration: at step n the nodes are at x_n and move at v_{n−1/2}, the
velocities that brought them from x_{n−1}. The velocity gradient (Eq. 6) is taken
on the mid-step configuration x_n − ½Δt·v_{n−1/2}, halfway through that motion
(central difference, second order): for a rigid rotation the chord velocities
then have an exactly skew gradient (the Cayley transform of the rotation), so a
rigidly rotating body gets no strain at all, whatever the step. The nodal forces
(Eqs. 13–14) use the current configuration x_n. PCMM elements do the same.

Arrays (all blocks of a simulation concatenated; node indices are global):

- ``tri`` (T,) 3 × i32, counter-clockwise; ``tmat`` (T,) i32 material row;
- ``tsig`` (T,) 4 × f64 stress (σxx, σyy, σxy, σzz), tension-positive;
- ``tstate`` (T,) 4 × f64: plastic shear strain, failed (0/1), −, −;
- ``tfor`` (T,) 6 × f64: the element's forces on its three nodes of this step;
- ``inc_start`` (V + 1,) / ``inc`` (3T,) i32: for node v, the entries
  ``inc[inc_start[v]:inc_start[v + 1]]`` = 3·t + corner of the triangles it belongs
  to, so that nodal forces are gathered without atomics in a fixed order.
"""
import numpy as np
import taichi as ti

from tdem.core.launch import cached

from . import fvm
from .materials import MAT_G, MAT_K, mc_correct_state, mixes
from .pcmm import viscous_stress


@ti.func
def _nodal_mean(v, k, tfor: ti.template(), inc_start: ti.template(), inc: ti.template()):
    """Σ S_e q_e / Σ S_e over the triangles at node v, with (q_e, S_e) in columns
    k, 4 of ``tfor`` (0 where no stressed triangle meets the node)."""
    num = 0.0
    den = 0.0
    for q in range(inc_start[v], inc_start[v + 1]):
        r = tfor[inc[q] // 3]
        num += r[4] * r[k]
        den += r[4]
    out = 0.0
    if den > 0.0:
        out = num / den
    return out


@cached
@ti.kernel
def update(npos: ti.types.ndarray(), nvel: ti.types.ndarray(), tri: ti.types.ndarray(),
           tmat: ti.types.ndarray(), matp: ti.types.ndarray(), tsig: ti.types.ndarray(),
           tstate: ti.types.ndarray(), tfor: ti.types.ndarray(),
           inc_start: ti.types.ndarray(), inc: ti.types.ndarray(),
           nmix: ti.types.ndarray(), nforce: ti.types.ndarray(), dt: ti.f64,
           mixed: ti.template(), serial: ti.template()):
    """One step of every block triangle (stress and nodal forces), then the element
    forces gathered into ``nforce`` (overwritten). ``mixed``: the nodal mixed
    discretization (:mod:`physics.fvm`) for the materials that take it
    (:func:`physics.materials.mixes`), the volumetric strain increment and the
    in-plane mean stress of the nodal forces averaged through the nodes (not
    ``mixed``: each triangle's own). ``tfor`` holds each triangle's kinematics
    between the passes; ``nmix`` (V, 2) the nodal means."""
    if ti.static(mixed):
        # 1. kinematics: (Δθ, area) per triangle (area 0: not in the averages, a
        #    rigid block's triangle (material −1) or one of a material that does not mix)
        ti.loop_config(serialize=serial)
        for e in range(tri.shape[0]):
            out = ti.Vector([0.0, 0.0, 0.0, 0.0, 0.0, 0.0])
            if tmat[e] >= 0 and mixes(matp, ti.max(tmat[e], 0)):
                t = tri[e]
                grad, s = fvm.mid_step(t[0], t[1], t[2], npos, nvel, dt)
                de = fvm.strain_increment(grad, dt)
                out = ti.Vector([de[0] + de[1], 0.0, 0.0, 0.0, s, 0.0])
            tfor[e] = out
        # 2. the nodes' area-weighted volumetric strain increments
        ti.loop_config(serialize=serial)
        for v in range(nmix.shape[0]):
            nmix[v] = ti.Vector([_nodal_mean(v, 0, tfor, inc_start, inc), 0.0])
    # 3. stresses with the strain increment's volumetric part the mean of the nodes'
    ti.loop_config(serialize=serial)
    for e in range(tri.shape[0]):
        if tmat[e] >= 0:
            t = tri[e]
            grad, s = fvm.mid_step(t[0], t[1], t[2], npos, nvel, dt)
            de = fvm.strain_increment(grad, dt)
            M = tmat[e]
            if ti.static(mixed):
                if mixes(matp, M):
                    de = fvm.mixed_strain(de, (nmix[t[0]][0] + nmix[t[1]][0]
                                               + nmix[t[2]][0]) / 3.0)
            sig = fvm.jaumann_rotate(tsig[e], fvm.spin_rate(grad), dt) + fvm.elastic_increment(
                de, matp[M, MAT_K], matp[M, MAT_G])
            st = tstate[e]
            sig, eps, flag = mc_correct_state(sig, matp, M, ti.cast(st[1] > 0.0, ti.i32))
            tsig[e] = sig
            st[0] += eps
            if flag > 0:
                st[1] = 1.0
            tstate[e] = st
            sf = sig + viscous_stress(matp, M, de, dt)
            tfor[e] = ti.Vector([sf[0], sf[1], sf[2], sf[3], s, 0.5 * (sf[0] + sf[1])])
    if ti.static(mixed):
        # 4. the nodes' area-weighted in-plane mean stresses
        ti.loop_config(serialize=serial)
        for v in range(nmix.shape[0]):
            nmix[v][1] = _nodal_mean(v, 5, tfor, inc_start, inc)
    # 5. nodal forces of each triangle, its in-plane mean stress the mean of the nodes'
    ti.loop_config(serialize=serial)
    for e in range(tri.shape[0]):
        if tmat[e] >= 0:
            t = tri[e]
            r = tfor[e]
            sf = ti.Vector([r[0], r[1], r[2], r[3]])
            if ti.static(mixed):
                if mixes(matp, tmat[e]):
                    sf = fvm.mixed_stress(sf, (nmix[t[0]][1] + nmix[t[1]][1]
                                               + nmix[t[2]][1]) / 3.0)
            fa, fb, fc = fvm.nodal_forces(sf, npos[t[0]], npos[t[1]], npos[t[2]], 1.0)
            tfor[e] = ti.Vector([fa[0], fa[1], fb[0], fb[1], fc[0], fc[1]])
    # 6. gathered per node in a fixed order
    ti.loop_config(serialize=serial)
    for v in range(nforce.shape[0]):
        f = ti.Vector([0.0, 0.0])
        for q in range(inc_start[v], inc_start[v + 1]):
            code = inc[q]
            e = code // 3
            c = code - 3 * e
            fe = tfor[e]
            f += ti.Vector([fe[2 * c], fe[2 * c + 1]])
        nforce[v] = f


def incidence(triangles, n_nodes):
    """(inc_start, inc) of the module docstring for triangles (T, 3)."""
    t = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    node = t.ravel()
    code = np.arange(node.size)          # 3·t + corner
    order = np.argsort(node, kind="stable")
    counts = np.bincount(node, minlength=n_nodes)
    start = np.zeros(n_nodes + 1, np.int64)
    start[1:] = np.cumsum(counts)
    return start.astype(np.int32), code[order].astype(np.int32)


def altitudes(vertices, triangles):
    """Smallest altitude 2S/longest edge of each triangle (the time-step length)."""
    x = np.asarray(vertices, dtype=float)
    t = np.asarray(triangles, dtype=np.int64)
    p = x[t]
    e = np.roll(p, -1, axis=1) - p
    length = np.linalg.norm(e, axis=2)
    area = 0.5 * np.abs(e[:, 0, 0] * e[:, 1, 1] - e[:, 0, 1] * e[:, 1, 0])
    return 2.0 * area / length.max(axis=1)
