"""The kernels of the block nodes: the leapfrog of free nodes and of rigid blocks,
and the dashpots of non-reflecting boundaries (on particles or block nodes).

:class:`tdem.continuum.Continuum` owns the arrays and launches these at its stages
(``integrate``, ``viscous_boundaries``); the integration is the damped leapfrog of
:mod:`tdem.integrate`, as for the particles in :func:`tdem.step.step`.
"""
import taichi as ti

from .finite import any_non_finite
from .integrate import damped_leapfrog
from .launch import cached
from .step import P_ALPHA, P_ALPHA_LOCAL, P_DT, P_GX, P_GY

RIGID_NODE = 8          # node flag: the node belongs to a free rigid block


@cached
@ti.kernel
def integrate_nodes(npos: ti.types.ndarray(), nvel: ti.types.ndarray(),
                    nmass: ti.types.ndarray(), nforce: ti.types.ndarray(),
                    nfix: ti.types.ndarray(), nvfix: ti.types.ndarray(),
                    nsize: ti.types.ndarray(), nreact: ti.types.ndarray(),
                    nwork: ti.types.ndarray(), nload: ti.types.ndarray(),
                    simp: ti.types.ndarray(), nflags: ti.types.ndarray(),
                    serial: ti.template()):
    """Block nodes, as the particles in :func:`tdem.step.step`: gravity, local and
    global damping, prescribed velocity components (``nreact`` = the force the
    constraint applies), applied loads (``nload``), leapfrog, the work of each force
    (``nwork``: the nodal forces, gravity, damping, the constraint, the load).
    nflags[0] = smallest index of a node with a non-finite state or moving more than
    half its size in one step."""
    dt = simp[P_DT]
    g = ti.Vector([simp[P_GX], simp[P_GY]])
    alpha = simp[P_ALPHA]
    alpha_l = simp[P_ALPHA_LOCAL]
    nv = npos.shape[0]
    ti.loop_config(serialize=True)
    for _ in range(1):
        nflags[0] = nv
    ti.loop_config(serialize=serial)
    for v in range(nv):
        if (nfix[v] & RIGID_NODE) == 0:   # nodes of rigid blocks move with their body
            m = nmass[v]
            v0 = nvel[v]
            fl = nload[v]
            f = nforce[v] + m * g + fl
            v1, fd = damped_leapfrog(v0, f, m, alpha, alpha_l, dt)
            # the reaction balances the physical forces only (damping is not one)
            vfree, fd_free = damped_leapfrog(v0, f, m, alpha, 0.0, dt)
            vdamp = v1
            fx = nfix[v]
            if fx & 1:
                v1[0] = nvfix[v][0]
            if fx & 2:
                v1[1] = nvfix[v][1]
            nreact[v] = m * (v1 - vfree) / dt
            vm = 0.5 * (v0 + v1)
            nwork[v] += ti.Vector([nforce[v].dot(vm) * dt, m * g.dot(vm) * dt,
                                   (fd - alpha * m * 0.5 * (v0 + vdamp)).dot(vm) * dt,
                                   m * (v1 - vdamp).dot(vm), fl.dot(vm) * dt, 0.0])
            x1 = npos[v] + v1 * dt
            nvel[v] = v1
            npos[v] = x1
            s = x1[0] + x1[1] + v1[0] + v1[1]
            bad = any_non_finite(x1) + any_non_finite(v1) > 0 or ti.abs(s) > 1e300
            if not bad:
                bad = v1.norm() * dt > 0.5 * nsize[v]
            if bad:
                ti.atomic_min(nflags[0], v)


@cached
@ti.kernel
def viscous_boundary(vel: ti.types.ndarray(), force: ti.types.ndarray(),
                     ids: ti.types.ndarray(), coef: ti.types.ndarray()):
    """Non-reflecting (Lysmer–Kuhlemeyer) boundary: on point ids[r] with outward unit
    normal n = coef[r, 0:2] and dashpots a_n = A·ρ·c_p, a_s = A·ρ·c_s in coef[r, 2:4],
    the traction −a_n (v·n) n − a_s (v·t) t is added to ``force``."""
    for r in range(ids.shape[0]):
        i = ids[r]
        n = ti.Vector([coef[r, 0], coef[r, 1]])
        t = ti.Vector([-n[1], n[0]])
        v = vel[i]
        f = -coef[r, 2] * v.dot(n) * n - coef[r, 3] * v.dot(t) * t
        ti.atomic_add(force[i][0], f[0])
        ti.atomic_add(force[i][1], f[1])


@cached
@ti.kernel
def integrate_rigid(npos: ti.types.ndarray(), nvel: ti.types.ndarray(),
                    nforce: ti.types.ndarray(), nmass: ti.types.ndarray(),
                    rbody: ti.types.ndarray(), rstate: ti.types.ndarray(),
                    rref: ti.types.ndarray(), rwork: ti.types.ndarray(),
                    nload: ti.types.ndarray(), simp: ti.types.ndarray()):
    """Rigid blocks: force and moment of their nodes' forces about the centre, plus
    gravity; local and global damping as for particles; leapfrog for the centre and
    the angle; the nodes are then placed rigidly, x = c + R(θ)·r₀, and given the
    rigid-body velocity v + ω × (x − c). ``nload``: loads applied to the nodes.
    ``rwork``: the work of the nodal forces, gravity, damping and loads, as ``nwork``
    of :func:`integrate_nodes`."""
    dt = simp[P_DT]
    g = ti.Vector([simp[P_GX], simp[P_GY]])
    alpha = simp[P_ALPHA]
    alpha_l = simp[P_ALPHA_LOCAL]
    ti.loop_config(serialize=True)
    for r in range(rbody.shape[0]):
        o = ti.cast(rbody[r, 0], ti.i32)
        k = ti.cast(rbody[r, 1], ti.i32)
        m = rbody[r, 2]
        inertia = rbody[r, 3]
        if k > 0:
            c = ti.Vector([rstate[r, 0], rstate[r, 1]])
            v0 = ti.Vector([rstate[r, 2], rstate[r, 3]])
            w0 = rstate[r, 5]
            fn = ti.Vector([0.0, 0.0])
            mom = 0.0
            fl = ti.Vector([0.0, 0.0])
            mload = 0.0
            for q in range(o, o + k):
                fq = nforce[q]
                lq = nload[q]
                d = npos[q] - c
                fn += fq
                mom += d[0] * fq[1] - d[1] * fq[0]
                fl += lq
                mload += d[0] * lq[1] - d[1] * lq[0]
            v1, fd = damped_leapfrog(v0, fn + fl + m * g, m, alpha, alpha_l, dt)
            w1, md = damped_leapfrog(w0, mom + mload, inertia, alpha, alpha_l, dt)
            vm = 0.5 * (v0 + v1)
            wm = 0.5 * (w0 + w1)
            w_damp = ((fd - alpha * m * vm).dot(vm) + (md - alpha * inertia * wm) * wm) * dt
            for c5 in ti.static(range(4)):
                rwork[r, c5] += ti.Vector([(fn.dot(vm) + mom * wm) * dt, m * g.dot(vm) * dt,
                                           w_damp, (fl.dot(vm) + mload * wm) * dt])[c5]
            c1 = c + v1 * dt
            th = rstate[r, 4] + w1 * dt
            cs = ti.cos(th)
            sn = ti.sin(th)
            for q in range(o, o + k):
                r0 = rref[q]
                d = ti.Vector([cs * r0[0] - sn * r0[1], sn * r0[0] + cs * r0[1]])
                npos[q] = c1 + d
                nvel[q] = v1 + w1 * ti.Vector([-d[1], d[0]])
            rstate[r, 0] = c1[0]
            rstate[r, 1] = c1[1]
            rstate[r, 2] = v1[0]
            rstate[r, 3] = v1[1]
            rstate[r, 4] = th
            rstate[r, 5] = w1
