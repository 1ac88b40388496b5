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
