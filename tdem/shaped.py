"""Contacts of shaped particles (superellipses, Miyata et al. 2002, §2.3) inside the step kernel.

The same stages as a disc contact (:func:`tdem.step.pair_contact`): geometry
(:mod:`physics.geometry.superellipse`: depth, normal, support points), kinematics at
the contact point, the law (:mod:`physics.contact_law`) on the tangent-plane velocity,
and the force and moments returned for the accumulation. A disc that meets a shaped
particle takes part as the shape (r, r, 2).

The contact point c is the midpoint of the two support points; the moment on each
body is (c − x) × f. History columns after the law's (see :data:`PAIR_TAIL`): the
normal angle of the last step (the warm start) and the pair's state (> 0: touching,
with the R* of its curvature radii; −1: tracked while apart; 0: not tracked).
Rolling resistance is a disc feature (refused for shapes when the model is built).
"""
import taichi as ti

from physics.contact_law import history_width, law_force, zero_history
from physics.geometry import superellipse as se
from physics.geometry.frame import perp, tangent_part, tangent_vector

from .neighbors import F_NONCONV, image
from .state import PROP_MASS, PROP_RADIUS


@ti.func
def cross(r, f):
    return r[0] * f[1] - r[1] * f[0]


@ti.func
def shape_of(s, r):
    """The (a, b, n) of a particle: its superellipse, or (r, r, 2) for a disc."""
    out = ti.Vector([r, r, 2.0])
    if s[2] > 0.0:
        out = ti.Vector([s[0], s[1], s[2]])
    return out


@ti.func
def shaped_pair(i, k, xi, vi, wi, mi, li, ci, sni, shi, rbi, pos: ti.template(),
                vel: ti.template(), omega: ti.template(), prop: ti.template(),
                plaw: ti.template(), turn: ti.template(), shp: ti.template(),
                lawp: ti.template(), lawpair: ti.template(), nbr: ti.template(),
                hist: ti.template(), cn: ti.template(), cs: ti.template(),
                flags: ti.template(), dt, detail, laws: ti.template(), per):
    """Contact in slot k of particle i (the owner) when either body has a shape
    (``ci``, ``sni``: the cosine and sine of i's angle; ``turn``: those of every
    particle); returns (f_i, M_i, M_j,
    dissipated energy), as :func:`tdem.step.pair_contact`."""
    R = ti.static(history_width(laws))
    PHI = ti.static(R + 4)
    ST = ti.static(R + 5)
    j = nbr[i, k]
    pj = prop[j]
    rbj = pj[PROP_RADIUS]
    shj = shape_of(shp[j], rbj)
    cj = turn[j][0]
    snj = turn[j][1]
    d = image(pos[j] - xi, per)        # j at its image nearest to i
    xj = xi + d
    h = hist[i, k]
    f = ti.Vector([0.0, 0.0])
    m_on_i = 0.0
    m_on_j = 0.0
    diss = 0.0
    u_out = -1.0
    # quick reject along the centre line: h_i(d̂) + h_j(−d̂) < |d| means apart (a pair
    # that touched at the last step goes straight to its warm-started minimisation)
    dist = d.norm()
    apart = dist >= rbi + rbj
    if not apart and dist > 0.0 and h[ST] <= 0.0:
        dh = d / dist
        hi, spi = se.support(shi, ci, sni, dh)
        hj, spj = se.support(shj, cj, snj, -dh)
        apart = hi + hj < dist
    if apart:
        if h[ST] != 0.0:
            h = zero_history(h)
            hist[i, k] = h
    else:
        tracked = h[ST] != 0.0
        phi0 = h[PHI]
        if not tracked:
            phi0 = ti.atan2(d[1], d[0])
        delta, n, p_i, p_j, phi, ok, rho_i, rho_j = se.pair_depth(shi, ci, sni, shj, cj, snj,
                                                                  d, phi0, tracked, False)
        if not ok:
            ti.atomic_add(flags[F_NONCONV], 1)
        u_out = delta
        if delta > 0.0:
            c = xi + 0.5 * (p_i + d + p_j)        # midpoint of P_i and P_j
            arm_i = c - xi
            arm_j = c - xj
            vrel = vel[j] + omega[j] * perp(arm_j) - vi - wi * perp(arm_i)
            vn = vrel.dot(n)
            L = lawpair[li, plaw[j]]
            mj = pj[PROP_MASS]
            # R* from the curvature radii, each capped at its body's bounding radius
            ri_c = ti.math.clamp(rho_i, 1e-6 * rbi, rbi)
            rj_c = ti.math.clamp(rho_j, 1e-6 * rbj, rbj)
            reff = ri_c * rj_c / (ri_c + rj_c)
            fn_el, fn, ft, kn, cnd, d1, h = law_force(
                laws, lawp, L, delta, vn, tangent_part(vrel, n), mi * mj / (mi + mj), reff,
                dt, h)
            f = -fn * n + tangent_vector(ft, n)
            m_on_i = cross(arm_i, f)
            m_on_j = -cross(arm_j, f)
            h[PHI] = phi
            h[ST] = reff
            diss = d1
            if detail:
                cn[i, k] = n
                cs[i, k] = ti.Vector([fn, ft[0], delta])
        else:
            h = zero_history(h)
            h[PHI] = phi
            h[ST] = -1.0
        hist[i, k] = h
    if detail:
        if u_out <= 0.0:
            cs[i, k] = ti.Vector([0.0, 0.0, u_out])
    return f, m_on_i, m_on_j, diss


@ti.func
def shaped_wall(xi, vi, wi, mi, thi, shi, rbi, a, b, inv_ll, vwall, wwall, centre, L, h,
                lawp: ti.template(), flags: ti.template(), dt, laws: ti.template()):
    """Contact of a shaped particle with the segment ab (a wall of translation velocity
    ``vwall``, spin ``wwall`` about ``centre``, law L) with history h. Returns (touching,
    f on i, M on i, n, F_n, F_s, depth, contact point, wall velocity there, h, dissipation).
    The face contact when the particle's support point faces the segment, else its
    nearer end point as a point of zero size."""
    ST = ti.static(history_width(laws) + 3)
    depth, n, p, inside, sp = se.face_depth(shi, thi, xi, a, b, inv_ll)
    pw = xi + p - depth * n              # the wall point facing the support point
    if not inside:
        e = a
        if sp > 1.0:
            e = b
        xp = e - xi
        depth = -1.0
        n = ti.Vector([1.0, 0.0])
        if xp.norm() < rbi:
            ok = True
            depth, n, p, ok = se.point_depth(shi, thi, xp, ti.atan2(xp[1], xp[0]))
            if not ok:
                ti.atomic_add(flags[F_NONCONV], 1)
        pw = e
    f = ti.Vector([0.0, 0.0])
    mi_ = 0.0
    fn = 0.0
    fs = 0.0
    diss = 0.0
    c = xi
    vw = vwall
    touching = depth > 0.0
    if touching:
        c = 0.5 * (xi + p + pw)
        arm = c - xi
        vw = vwall + wwall * perp(c - centre)
        vrel = vw - vi - wi * perp(arm)
        reff = se.curvature_radius(shi, ti.cos(thi), ti.sin(thi), n, rbi)
        fn_el, fn_, ft, kn, cnd, d1, h = law_force(
            laws, lawp, L, depth, vrel.dot(n), tangent_part(vrel, n), mi, reff, dt, h)
        f = -fn_ * n + tangent_vector(ft, n)
        mi_ = cross(arm, f)
        fn = fn_
        fs = ft[0]
        diss = d1
        h[ST] = reff
    elif h[ST] != 0.0:
        h = zero_history(h)
    return touching, f, mi_, n, fn, fs, depth, c, vw, h, diss
