"""Analytic walls of 3D simulations: infinite planes and infinite cylinders
(:meth:`tdem.Simulation.add_plane`, :meth:`tdem.Simulation.add_cylinder`), LIGGGHTS'
``fix wall/gran ... primitive``.

A primitive is one row of the table ``prim`` (columns ``PR_*``): its kind, a point
(on the plane; on the cylinder's axis), a unit vector (the plane's normal, towards
the particles; the cylinder's axis), the cylinder's radius, its velocity (a
translation) and its contact law. Every sphere meets every primitive at every step
(no neighbour list: a model has a few of them), with its history in the dense
arrays ``phist``, ``pcn``, ``pcf``, ``pcs`` (particle × primitive, :mod:`tdem.state`).
The contact is that of a sphere against a mesh triangle's face
(:func:`tdem.step.mesh_contacts`): the same law (:func:`physics.contact_law.law_force_3d`,
R* = R_i, m* = m_i), tangential history, rolling resistance, energy booking and
force on the wall. The step compiles it only in models that have primitives
(its ``prims`` switch).

Geometry, with d the distance from the sphere's centre x to the surface on the
particles' side and n the unit normal from the centre to the wall:

- plane (point p, unit normal a): d = (x − p)·a, n = −a (a sphere behind the plane
  has d < 0 and is pushed back to the normal's side);
- cylinder (axis through p along the unit a, radius R), ρ = |r|, r = (x − p) −
  ((x − p)·a) a: inside d = R − ρ, n = r/ρ; outside d = ρ − R, n = −r/ρ.

The overlap is R_i − d, the contact point x + (R_i − overlap/2) n. Both kinds are
infinite (a cylinder has no ends: give it floors as planes).
"""
import math

import numpy as np
import taichi as ti

from physics.contact_law import (COL_REACH, get_columns, history_width, law_energy,
                                 law_force_3d, law_stiffness, put_columns, tangent_dim,
                                 zero_history)
from physics.geometry.frame import moment, spin_cross, tangent_part
from physics.rolling import rolling_couple_3d, rolling_energy_3d

from .core.layout import PROP_MASS, PROP_RADIUS
from .errors import InputError

# the columns of a primitive's row: kind, point, unit normal or axis, radius,
# velocity, law
PR_KIND, PR_PX, PR_NX, PR_RADIUS, PR_VX, PR_LAW = 0, 1, 4, 7, 8, 11
PRIM_WIDTH = 12
# the kinds
PLANE, CYLINDER_IN, CYLINDER_OUT = 1, 2, 3
KIND_NAMES = {PLANE: "plane", CYLINDER_IN: "cylinder", CYLINDER_OUT: "cylinder"}


def _vec3(name, value, unit=False):
    """``value`` as 3 finite numbers (refused naming ``name``); with ``unit``, not zero
    and returned divided by its norm."""
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        a = None
    if a is None or a.shape != (3,) or not np.isfinite(a).all():
        raise InputError(f"{name} must be three finite numbers (x, y, z), got {value!r}")
    if unit:
        norm = float(np.linalg.norm(a))
        if not norm > 0.0:
            raise InputError(f"{name} must not be zero, got {value!r}")
        a = a / norm
    return a


def plane_row(point, normal, law, velocity):
    """A plane's row of the table (checked, naming the argument)."""
    row = np.zeros(PRIM_WIDTH)
    row[PR_KIND] = PLANE
    row[PR_PX:PR_PX + 3] = _vec3("point", point)
    row[PR_NX:PR_NX + 3] = _vec3("normal", normal, unit=True)
    row[PR_VX:PR_VX + 3] = _vec3("velocity", velocity)
    row[PR_LAW] = law
    return row


def cylinder_row(center, axis, radius, inside, law, velocity):
    """A cylinder's row of the table (checked, naming the argument)."""
    row = np.zeros(PRIM_WIDTH)
    try:
        r = float(radius)
    except (TypeError, ValueError):
        r = float("nan")
    if not (math.isfinite(r) and r > 0.0):
        raise InputError(f"radius must be a finite number > 0, got {radius!r}")
    if not isinstance(inside, (bool, np.bool_)):
        raise InputError(f"inside must be True or False, got {inside!r}")
    row[PR_KIND] = CYLINDER_IN if inside else CYLINDER_OUT
    row[PR_PX:PR_PX + 3] = _vec3("center", center)
    row[PR_NX:PR_NX + 3] = _vec3("axis", axis, unit=True)
    row[PR_RADIUS] = r
    row[PR_VX:PR_VX + 3] = _vec3("velocity", velocity)
    row[PR_LAW] = law
    return row


@ti.func
def _col3(prim: ti.template(), p, c: ti.template()):
    return ti.Vector([prim[p, c], prim[p, c + 1], prim[p, c + 2]])


@ti.func
def geometry(prim: ti.template(), p, xi):
    """(d, n): the distance from the point xi to primitive p's surface on the
    particles' side, and the unit normal from xi towards the wall (module docstring)."""
    kind = ti.cast(prim[p, PR_KIND], ti.i32)
    o = _col3(prim, p, PR_PX)
    a = _col3(prim, p, PR_NX)
    dist = (xi - o).dot(a)
    n = -a
    if kind != PLANE:
        d = xi - o
        r = d - d.dot(a) * a
        rho = r.norm()
        e = a.cross(ti.Vector([1.0, 0.0, 0.0]))      # (a centre on the axis)
        if ti.abs(a[0]) > 0.9:
            e = a.cross(ti.Vector([0.0, 1.0, 0.0]))
        e = e.normalized()
        if rho > 0.0:
            e = r / rho
        if kind == CYLINDER_IN:
            dist = prim[p, PR_RADIUS] - rho
            n = e
        else:
            dist = rho - prim[p, PR_RADIUS]
            n = -e
    return dist, n


@ti.func
def wall_law(laws: ti.template(), lawp: ti.template(), L, depth, vn, vt, mass, reff, ri,
             omega_rel, arm, dt, h, n, ranged: ti.template()):
    """3D: the contact law of a sphere against a wall (a mesh face,
    :func:`tdem.step.mesh_contacts`, or a primitive) and the wall's rolling resistance (r̄ = 2 R_i, Jiang Eq. 11b), in
    contact only (a law with a range zeroes the rolling columns across a gap).
    ``omega_rel``: the sphere's spin less the wall's; ``arm``: from the centre to the
    contact point. Returns (force on the sphere, its moment, the rolling couple, the
    normal force, the tangential force, the law's dissipation, the rolling's
    dissipation, the history)."""
    T = ti.static(tangent_dim(3))
    RW = ti.static(history_width(laws, T))
    fn_el, fn, ft, kn, cnd, d1, h = law_force_3d(laws, lawp, L, depth, vn, vt, mass, reff,
                                                 dt, h, n)
    f = -fn * n + ft
    mi = moment(arm, f)
    m_roll = ti.Vector([0.0, 0.0, 0.0])
    d2 = 0.0
    if ti.static(h.n >= RW + 7):
        touching = 1
        if ti.static(ranged):
            touching = depth > 0.0
        if touching:
            m, m_roll1, th, brk, d2r = rolling_couple_3d(
                lawp, L, fn_el, kn, cnd, 2.0 * ri, omega_rel, n, dt,
                get_columns(h, RW, 3), get_columns(h, RW + 3, 3), h[RW + 6])
            m_roll = m_roll1
            h = put_columns(h, RW, m)
            h = put_columns(h, RW + 3, th)
            h[RW + 6] = brk
            mi += m_roll
            d2 = d2r
        else:
            for c7 in ti.static(range(7)):
                h[RW + c7] = 0.0
    return f, mi, m_roll, fn, ft, d1, d2, h


@ti.func
def prim_contacts(i, vel: ti.template(), omega: ti.template(), prop: ti.template(), xi,
                  prim: ti.template(), ppart: ti.template(), row, lawp: ti.template(),
                  phist: ti.template(), pcn: ti.template(), pcf: ti.template(),
                  pcs: ti.template(), dt, laws: ti.template(), ranged: ti.template()):
    """3D: the contacts of sphere i (centre xi) with every primitive wall, as a sphere
    against a mesh face (:func:`tdem.step.mesh_contacts`). Returns (force, moment,
    dissipation, work of the walls) and adds what each primitive receives (force,
    moment about its point, a contact) to row ``row`` of ``ppart``. With ``ranged`` a
    law with a range acts across a gap below it."""
    ri = prop[i][PROP_RADIUS]
    diss = 0.0
    work = 0.0
    ftot = ti.Vector([0.0, 0.0, 0.0])
    mtot = ti.Vector([0.0, 0.0, 0.0])
    for p in range(prim.shape[0]):
        dist, n = geometry(prim, p, xi)
        depth = ri - dist
        L = ti.cast(prim[p, PR_LAW], ti.i32)
        reach = 0.0
        if ti.static(ranged):
            reach = lawp[L, COL_REACH]
        if depth > -reach:
            h = phist[i, p]
            point = xi + (ri - 0.5 * depth) * n
            arm = point - xi
            vw = _col3(prim, p, PR_VX)
            vrel = vw - vel[i] - spin_cross(omega[i], arm)
            vn = vrel.dot(n)
            f, mi, m_roll, fn, ft, d1, d2, h = wall_law(
                laws, lawp, L, depth, vn, tangent_part(vrel, n), prop[i][PROP_MASS], ri, ri,
                omega[i], arm, dt, h, n, ranged)
            diss += d2
            phist[i, p] = h
            pcn[i, p] = n
            pcf[i, p] = ti.Vector([f[0], f[1], f[2], mi[0], mi[1], mi[2]])
            pcs[i, p] = ti.Vector([fn, ft.norm(), depth])
            diss += d1
            work += f.dot(vw) * dt
            ftot += f
            mtot += mi
            tw = moment(point - _col3(prim, p, PR_PX), -f) - m_roll
            for k in ti.static(range(3)):
                ti.atomic_add(ppart[row, p][k], -f[k])
                ti.atomic_add(ppart[row, p][3 + k], tw[k])
            ti.atomic_add(ppart[row, p][6], 1.0)
        else:
            # a contact that has just ended (it touched in the last step: the history
            # is read only then, not for every particle and primitive apart)
            ended = pcs[i, p][2] > 0.0
            if ti.static(ranged):
                if not ended:
                    h = phist[i, p]
                    ended = h.dot(h) != 0.0
            if ended:
                phist[i, p] = zero_history(phist[i, p])
                pcf[i, p] = ti.Vector([0.0, 0.0, 0.0, 0.0, 0.0, 0.0])
                pcs[i, p] = ti.Vector([0.0, 0.0, ti.min(depth, 0.0)])
    return ftot, mtot, diss, work


@ti.func
def finish_step(prim: ti.template(), pforce: ti.template(), ppart: ti.template(), rows,
                dt):
    """After the particles' step (one thread): each primitive's force, its chunks'
    partial sums added in their order; then it translates by v Δt."""
    for p in range(prim.shape[0]):
        s = ppart[0, p]
        ppart[0, p] = s * 0.0
        for r in range(1, rows):
            s += ppart[r, p]
            ppart[r, p] = s * 0.0
        pforce[p] = s
        for k in ti.static(range(3)):
            prim[p, PR_PX + k] += prim[p, PR_VX + k] * dt


@ti.kernel
def set_velocity(prim: ti.types.ndarray(), p: ti.i32, vx: ti.f64, vy: ti.f64, vz: ti.f64):
    """Primitive p's velocity for the next step, from a motion given as a function of
    time (:meth:`tdem.handles.Primitive.motion`)."""
    for _ in range(1):
        prim[p, PR_VX] = vx
        prim[p, PR_VX + 1] = vy
        prim[p, PR_VX + 2] = vz


@ti.kernel
def elastic_energy(prop: ti.types.ndarray(), prim: ti.types.ndarray(),
                   phist: ti.types.ndarray(), pcs: ti.types.ndarray(),
                   lawp: ti.types.ndarray(), laws: ti.template()) -> ti.f64:
    """Energy stored in the springs (law and rolling) of the primitive walls' contacts
    (:func:`tdem.step.elastic_energy_sum` for the mesh walls')."""
    T = ti.static(tangent_dim(3))
    R = ti.static(history_width(laws, T))
    total = 0.0
    for i in range(phist.shape[0]):
        ri = prop[i][PROP_RADIUS]
        for p in range(prim.shape[0]):
            u = pcs[i, p][2]
            L = ti.cast(prim[p, PR_LAW], ti.i32)
            if u > 0.0 or u > -lawp[L, COL_REACH]:
                h = phist[i, p]
                total += law_energy(laws, lawp, L, u, ri, h, T)
                if u > 0.0:
                    if ti.static(h.n >= R + 7):
                        kn = law_stiffness(laws, lawp, L, u, ri)
                        total += rolling_energy_3d(lawp, L, kn, get_columns(h, R, 3),
                                                   2.0 * ri)
    return total
