"""Geometry of two discs (2D) or spheres (3D) — the pair contact of Cundall & Strack (1979).

Discs i and j of radii R_i, R_j at x_i, x_j touch when the overlap
u = R_i + R_j − |x_j − x_i| is positive. The normal is n = (x_j − x_i)/|x_j − x_i|;
the contact point lies at R_i − u/2 from i's centre along n and R_j − u/2 from j's
along −n (the branch lengths); the relative velocity of j's contact point against
i's is v_j − v_i − (ω_j a_j + ω_i a_i) t with t = n rotated +90° (in 3D
v_j + ω_j × (−a_j n) − v_i − ω_i × (a_i n)).
"""
import taichi as ti

from .frame import perp, spin_cross


@ti.func
def overlap(xi, xj, ri, rj):
    """(d = x_j − x_i, |d|, u = R_i + R_j − |d|)."""
    d = xj - xi
    dist = d.norm()
    return d, dist, ri + rj - dist


@ti.func
def kinematics(d, dist, u, ri, rj, vi, vj, wi, wj):
    """For touching discs with (offset) overlap u: (n, t, a_i, a_j, relative velocity
    of j's contact point against i's); t is n rotated +90° in 2D and 0 in 3D.
    Coincident centres take n = (1, 0[, 0])."""
    n = d * 0.0
    n[0] = 1.0
    if dist > 0.0:
        n = d * (1.0 / dist)
    ai = ri - 0.5 * u
    aj = rj - 0.5 * u
    t = n * 0.0
    vrel = n * 0.0
    if ti.static(d.n == 2):
        t = perp(n)
        vrel = vj - vi - (wj * aj + wi * ai) * t
    else:
        vrel = vj - vi - spin_cross(wj, aj * n) - spin_cross(wi, ai * n)
    return n, t, ai, aj, vrel
