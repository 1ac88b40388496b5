"""Geometry of a disc against a rigid segment (a wall, 2D).

The wall point nearest the disc centre x_i is the projection of x_i onto the
segment ab, clamped to its ends (so a disc meets the segment's end points too).
With d the vector from x_i to that point, the disc touches when |d| < R_i:
overlap u = R_i − |d|, normal n = d/|d| (from the disc to the wall, the wall being
"j", of infinite radius and mass), contact point x_c = x_i + (R_i − u/2) n. The
wall moves rigidly (translation v_w and spin ω_w about its centre c), so the
relative velocity is v_w + ω_w × (x_c − c) − v_i − ω_i a_i t.
"""
import taichi as ti

from .frame import perp


@ti.func
def closest_on_segment(x, a, b, inv_ll):
    """Closest point to x on segment ab; inv_ll = 1/|b − a|² (rotation keeps it)."""
    ab = b - a
    s = ti.math.clamp((x - a).dot(ab) * inv_ll, 0.0, 1.0)
    return a + s * ab


@ti.func
def overlap(xi, a, b, inv_ll):
    """(d = nearest wall point − x_i, |d|²); the disc touches when |d|² < R_i²."""
    d = closest_on_segment(xi, a, b, inv_ll) - xi
    return d, d.dot(d)


@ti.func
def kinematics(xi, d, d2, ri, vi, wi, vwall, wwall, centre):
    """For a touching disc: (u, n, t, a_i, contact point, wall velocity there,
    relative velocity of the wall against the disc at the contact point)."""
    dist = ti.sqrt(d2)
    u = ri - dist
    n = ti.Vector([1.0, 0.0])
    if dist > 0.0:
        n = d / dist
    t = perp(n)
    ai = ri - 0.5 * u
    xc = xi + ai * n
    vw = vwall + wwall * perp(xc - centre)
    vrel = vw - vi - wi * ai * t
    return u, n, t, ai, xc, vw, vrel
