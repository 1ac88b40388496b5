"""The contact frame: normal and tangent-plane parts of a vector, for 2D and 3D.

In 2D the tangent plane of a contact is the line along t = n rotated +90°: a
tangent-plane vector has one component, its coordinate along t. In 3D it is the
plane normal to n, and a tangent-plane vector is kept with its three global
components (as LIGGGHTS and Yade keep the shear spring). The contact laws are
written on these vectors (:mod:`physics.contact_law`), so one law serves both.
"""
import taichi as ti


@ti.func
def perp(n):
    """n rotated by +90° (2D)."""
    return ti.Vector([-n[1], n[0]])


@ti.func
def tangent_part(v, n):
    """The tangent-plane part of v at a contact of normal n: ``[v·t]`` in 2D,
    ``v − (v·n) n`` in 3D."""
    if ti.static(n.n == 2):
        return ti.Vector([v.dot(perp(n))])
    else:
        return v - v.dot(n) * n


@ti.func
def tangent_vector(ft, n):
    """The vector of a tangent-plane quantity ``ft`` (``ft[0] t`` in 2D)."""
    if ti.static(n.n == 2):
        return ft[0] * perp(n)
    else:
        return ft


@ti.func
def spin_cross(w, r):
    """ω × r: the velocity of the point at r from the centre of a body spinning at ω
    (a scalar in 2D, ω(−r_y, r_x); a 3-vector in 3D)."""
    if ti.static(r.n == 2):
        return w * perp(r)
    else:
        return w.cross(r)


@ti.func
def moment(r, f):
    """r × f: the moment of the force f at r (a scalar in 2D, a 3-vector in 3D)."""
    if ti.static(r.n == 2):
        return r[0] * f[1] - r[1] * f[0]
    else:
        return r.cross(f)


@ti.func
def spin_dot(a, b, dim: ti.template()):
    """a·b of two spins or moments (scalars in 2D, 3-vectors in 3D)."""
    if ti.static(dim == 2):
        return a * b
    else:
        return a.dot(b)


@ti.func
def spin_zero(dim: ti.template()):
    """A zero spin or moment (0.0 in 2D, the zero 3-vector in 3D)."""
    if ti.static(dim == 2):
        return 0.0
    else:
        return ti.Vector([0.0, 0.0, 0.0])


@ti.func
def vec_zero(dim: ti.template()):
    """The zero vector of ``dim`` components."""
    return ti.Vector([0.0 for _ in ti.static(range(dim))])


@ti.func
def pack(f, m, dim: ti.template()):
    """(force, moment) as one vector of dim + spin components (3 in 2D, 6 in 3D)."""
    if ti.static(dim == 2):
        return ti.Vector([f[0], f[1], m])
    else:
        return ti.Vector([f[0], f[1], f[2], m[0], m[1], m[2]])


@ti.func
def unpack(a, dim: ti.template()):
    """The (force, moment) of a vector made by :func:`pack`."""
    if ti.static(dim == 2):
        return ti.Vector([a[0], a[1]]), a[2]
    else:
        return ti.Vector([a[0], a[1], a[2]]), ti.Vector([a[3], a[4], a[5]])
