"""Bonds between particles: interactions that outlive contact (parallel bonds).

A bond list beside the contact lists: ``bpair`` (the two particles, indices now),
``bprop`` (its stiffnesses, cross-section, strengths: :mod:`physics.parallel_bond`'s
columns) and ``bstate`` (its forces and moments, and once broken its record: the
crack). They are engine arrays (:mod:`tdem.state`, owner ``bond``): a snapshot
restores ``bstate``, a checkpoint saves all three, growth and insertion carry them,
an outlet renumbers them. Each step, before the particles' step,
:func:`bond_forces` updates every intact bond from the particles' motion, breaks
those over their strength (recording the crack) and adds the forces and moments of
the others into ``bforce``, which the step adds to the contact forces (their work is
booked as the contacts').

Bonds do not cross periodic boundaries.
"""
import numpy as np
import taichi as ti

from physics.geometry.frame import moment, pack, spin_cross, vec_zero
from physics.liquid_bridge import willett
from physics.parallel_bond import (BP_AREA, BP_CAP_F0, BP_CAP_K, BP_COHESION, BP_D0,
                                   BP_INERTIA, BP_KN_A, BP_KN_I, BP_KS_A, BP_KS_J, BP_POLAR,
                                   BP_RBAR, BP_RUPTURE, BP_SIGMA_C, BP_TANPHI, BP_TYPE)

from .core.layout import PROP_RADIUS

# columns of a bond's state (``bstate``)
BS_FN = 0                  # normal force, compression positive (N; N/m in 2D)
BS_FS = 1                  # shear force on the second particle, 3 components
BS_MB = 4                  # bending moment on the second particle (2D: one component)
BS_MT = 7                  # twisting moment on the second particle (3D)
BS_BROKEN = 10             # 1 once broken
BS_TIME = 11               # the time it broke (s)
BS_MODE = 12               # 0 tension, 1 shear
BS_POINT = 13              # its contact point then (3)
BS_NORMAL = 16             # its normal then, from the first particle to the second (3)
BS_RELEASED = 19           # its elastic energy then (J; J/m in 2D)
BS_FN_BREAK = 20           # its normal force then
BS_FS_BREAK = 21           # the magnitude of its shear force then
BS_MADE = 22               # a liquid bridge: the energy its making released, U(s₀)
BS_POT = 23                # a liquid bridge: its potential energy −U(s) now
BS_WIDTH = 24              # (tdem.state's ``bstate`` width)



@ti.func
def _vec3(b, c0, dim: ti.template()):
    v = vec_zero(dim)
    for k in ti.static(range(dim)):
        v[k] = b[c0 + k]
    return v


@ti.kernel
def bond_forces(pos: ti.types.ndarray(), vel: ti.types.ndarray(),
                omega: ti.types.ndarray(), prop: ti.types.ndarray(),
                bpair: ti.types.ndarray(), bprop: ti.types.ndarray(),
                bstate: ti.types.ndarray(), bforce: ti.types.ndarray(),
                dt: ti.f64, time: ti.f64, nbonds: ti.i32, dim: ti.template()):
    """Update every intact bond over the step from x_n, v_{n−1/2}, ω_{n−1/2}; break
    those over their strength; ``bforce`` = the sum of the others' forces and
    moments on each particle (zeroed first)."""
    for i in range(pos.shape[0]):
        bforce[i] = bforce[i] * 0.0
    for b in range(nbonds):
        i = bpair[b][0]
        j = bpair[b][1]
        s = bstate[b]
        if i >= 0 and s[BS_BROKEN] == 0.0 and bprop[b][BP_TYPE] == 1.0:
            # a liquid bridge (physics.liquid_bridge): Willett's force along the centres'
            # line, pulling them together; it ruptures beyond Lian's distance
            p = bprop[b]
            d = pos[j] - pos[i]
            dist = d.norm()
            n = d / dist
            ri = prop[i][PROP_RADIUS]
            rj = prop[j][PROP_RADIUS]
            gap = dist - ri - rj
            if gap > p[BP_RUPTURE]:
                bstate[b][BS_BROKEN] = 1.0
                bstate[b][BS_TIME] = time
                bstate[b][BS_MODE] = 2.0
                xc = pos[i] + n * (ri + 0.5 * gap)
                for k in ti.static(range(dim)):
                    bstate[b][BS_POINT + k] = xc[k]
                    bstate[b][BS_NORMAL + k] = n[k]
                bstate[b][BS_RELEASED] = 0.0
                bstate[b][BS_FN_BREAK] = bstate[b][BS_FN]
                bstate[b][BS_FS_BREAK] = 0.0
                bstate[b][BS_POT] = 0.0
            else:
                f, pot = willett(p[BP_CAP_F0], p[BP_CAP_K], p[BP_RUPTURE], gap)
                bstate[b][BS_FN] = -f
                bstate[b][BS_POT] = -pot          # bound: below the ruptured state
                fj = -f * n
                bforce[j] += pack(fj, moment(n * 0.0, fj), dim)
                bforce[i] += pack(-fj, moment(n * 0.0, fj), dim)
        elif i >= 0 and s[BS_BROKEN] == 0.0:
            p = bprop[b]
            d = pos[j] - pos[i]
            dist = d.norm()
            n = d / dist
            ri = prop[i][PROP_RADIUS]
            rj = prop[j][PROP_RADIUS]
            xc = pos[i] + n * (ri + 0.5 * (dist - ri - rj))
            vrel = (vel[j] + spin_cross(omega[j], xc - pos[j])) \
                - (vel[i] + spin_cross(omega[i], xc - pos[i]))
            vt = vrel - vrel.dot(n) * n
            fn = p[BP_KN_A] * (p[BP_D0] - dist)
            fs = _vec3(s, BS_FS, dim)
            fs = fs - fs.dot(n) * n - p[BP_KS_A] * vt * dt
            sig = -fn / p[BP_AREA]
            tau = fs.norm() / p[BP_AREA]
            energy = 0.5 * fn * fn / p[BP_KN_A]
            if p[BP_KS_A] > 0.0:
                energy += 0.5 * fs.dot(fs) / p[BP_KS_A]
            mb_store = vec_zero(3)
            mt_store = vec_zero(3)
            m_on_j = vec_zero(3)
            if ti.static(dim == 2):
                mb = s[BS_MB] - p[BP_KN_I] * (omega[j] - omega[i]) * dt
                sig += ti.abs(mb) * p[BP_RBAR] / p[BP_INERTIA]
                energy += 0.5 * mb * mb / p[BP_KN_I]
                mb_store[0] = mb
                m_on_j[0] = mb
            else:
                dw = (omega[j] - omega[i]) * dt
                dwn = dw.dot(n) * n
                mb = _vec3(s, BS_MB, 3)
                mb = mb - mb.dot(n) * n - p[BP_KN_I] * (dw - dwn)
                mt = _vec3(s, BS_MT, 3)
                mt = mt.dot(n) * n - p[BP_KS_J] * dwn
                sig += mb.norm() * p[BP_RBAR] / p[BP_INERTIA]
                tau += mt.norm() * p[BP_RBAR] / p[BP_POLAR]
                energy += 0.5 * mb.dot(mb) / p[BP_KN_I]
                if p[BP_KS_J] > 0.0:
                    energy += 0.5 * mt.dot(mt) / p[BP_KS_J]
                mb_store = mb
                mt_store = mt
                m_on_j = mb + mt
            strength = p[BP_COHESION] + fn / p[BP_AREA] * p[BP_TANPHI]
            mode = -1
            if sig >= p[BP_SIGMA_C]:
                mode = 0
            elif tau >= strength:
                mode = 1
            if mode >= 0:
                bstate[b][BS_BROKEN] = 1.0
                bstate[b][BS_TIME] = time
                bstate[b][BS_MODE] = ti.cast(mode, ti.f64)
                for k in ti.static(range(dim)):
                    bstate[b][BS_POINT + k] = xc[k]
                    bstate[b][BS_NORMAL + k] = n[k]
                bstate[b][BS_RELEASED] = energy
                bstate[b][BS_FN_BREAK] = fn
                bstate[b][BS_FS_BREAK] = fs.norm()
            else:
                bstate[b][BS_FN] = fn
                for k in ti.static(range(dim)):
                    bstate[b][BS_FS + k] = fs[k]
                for k in ti.static(range(3)):
                    bstate[b][BS_MB + k] = mb_store[k]
                    bstate[b][BS_MT + k] = mt_store[k]
                fj = fn * n + fs
                mj = moment(xc - pos[j], fj)
                mi = moment(xc - pos[i], -fj)
                if ti.static(dim == 2):
                    mj += m_on_j[0]
                    mi -= m_on_j[0]
                else:
                    mj += m_on_j
                    mi -= m_on_j
                bforce[j] += pack(fj, mj, dim)
                bforce[i] += pack(-fj, mi, dim)


@ti.kernel
def bond_energy(bpair: ti.types.ndarray(), bprop: ti.types.ndarray(),
                bstate: ti.types.ndarray(), nbonds: ti.i32,
                out: ti.types.ndarray(), dim: ti.template()):
    """out = (elastic energy of the intact bonds, energy released by the broken)."""
    out[0] = 0.0
    out[1] = 0.0
    for b in range(nbonds):
        s = bstate[b]
        p = bprop[b]
        if p[BP_TYPE] == 1.0:
            # a liquid bridge: its potential, and the energy its making supplied
            out[0] += s[BS_POT]
            out[1] += s[BS_MADE]
        elif bpair[b][0] >= 0 and s[BS_BROKEN] == 0.0:
            e = 0.5 * s[BS_FN] * s[BS_FN] / p[BP_KN_A]
            if p[BP_KS_A] > 0.0:
                e += 0.5 * (s[BS_FS] ** 2 + s[BS_FS + 1] ** 2 + s[BS_FS + 2] ** 2) / p[BP_KS_A]
            e += 0.5 * (s[BS_MB] ** 2 + s[BS_MB + 1] ** 2 + s[BS_MB + 2] ** 2) / p[BP_KN_I]
            if ti.static(dim == 3):
                if p[BP_KS_J] > 0.0:
                    e += 0.5 * (s[BS_MT] ** 2 + s[BS_MT + 1] ** 2 + s[BS_MT + 2] ** 2) \
                        / p[BP_KS_J]
            out[0] += e
        elif s[BS_BROKEN] != 0.0:
            out[1] += s[BS_RELEASED]


def pairs_within(pos, radius, ids_a, ids_b, gap):
    """Pairs (i < j) of particles, i in ``ids_a`` and j in ``ids_b`` (or both in
    ``ids_a`` when ``ids_b`` is None), whose surfaces are at most ``gap`` apart
    (overlapping ones included)."""
    from scipy.spatial import cKDTree
    ids_a = np.asarray(ids_a, np.int64)
    rmax = float(radius.max())
    if ids_b is None:
        tree = cKDTree(pos[ids_a])
        cand = tree.query_pairs(2 * rmax + gap, output_type="ndarray")
        i, j = ids_a[cand[:, 0]], ids_a[cand[:, 1]]
    else:
        ids_b = np.asarray(ids_b, np.int64)
        ta, tb = cKDTree(pos[ids_a]), cKDTree(pos[ids_b])
        lists = ta.query_ball_tree(tb, 2 * rmax + gap)
        i = np.repeat(ids_a, [len(x) for x in lists])
        j = ids_b[np.concatenate([np.asarray(x, np.int64) for x in lists])] if len(i) else \
            np.zeros(0, np.int64)
        keep = i != j
        i, j = i[keep], j[keep]
    lo, hi = np.minimum(i, j), np.maximum(i, j)
    if len(lo):
        key = np.unique(np.stack([lo, hi], 1), axis=0)
        lo, hi = key[:, 0], key[:, 1]
    dist = np.linalg.norm(pos[hi] - pos[lo], axis=1)
    near = dist - radius[lo] - radius[hi] <= gap
    return lo[near], hi[near], dist[near]


class BondView:
    """``sim.bonds`` (intact) or ``sim.cracks`` (broken): ``.numpy()`` a dict of
    arrays, ``len()`` their number."""

    def __init__(self, sim, broken):
        self._sim = sim
        self._broken = broken

    def _rows(self):
        sim = self._sim
        if not sim._nbonds:
            return None, None, None
        if sim._built:
            pair = sim._a["bpair"].to_numpy()[:sim._nbonds]
            st = sim._a["bstate"].to_numpy()[:sim._nbonds]
        else:
            pair, st = sim._bond_host["bpair"], sim._bond_host["bstate"]
        sel = (st[:, BS_BROKEN] != 0.0) if self._broken else (
            (st[:, BS_BROKEN] == 0.0) & (pair[:, 0] >= 0))
        return pair[sel], st[sel], sel

    def __len__(self):
        pair, st, _ = self._rows()
        return 0 if pair is None else len(pair)

    def numpy(self):
        d = self._sim.dim
        pair, st, _ = self._rows()
        if pair is None:
            pair, st = np.zeros((0, 2), np.int64), np.zeros((0, BS_WIDTH))
        if self._broken:
            return {"time": st[:, BS_TIME].copy(), "position": st[:, BS_POINT:BS_POINT + d].copy(),
                    "normal": st[:, BS_NORMAL:BS_NORMAL + d].copy(),
                    "mode": st[:, BS_MODE].astype(np.int64),
                    "normal_force": st[:, BS_FN_BREAK].copy(),
                    "shear_force": st[:, BS_FS_BREAK].copy(),
                    "energy": st[:, BS_RELEASED].copy(),
                    "pairs": pair.astype(np.int64)}
        out = {"pairs": pair.astype(np.int64), "normal_force": st[:, BS_FN].copy(),
               "shear_force": st[:, BS_FS:BS_FS + d].copy()}
        if d == 2:
            out["moment"] = st[:, BS_MB].copy()
        else:
            out["moment"] = st[:, BS_MB:BS_MB + 3].copy()
            out["twist"] = st[:, BS_MT:BS_MT + 3].copy()
        return out
