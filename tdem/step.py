"""One time step of the DEM: the whole data flow in one kernel.

    forces at x_n (3D: wall contacts first, in a loop of their own, kept per
      particle in wacc; pair contacts from the neighbour lists; 2D wall contacts),
      summed per owner particle; the partner's share goes straight to its sum on
      one thread and within a CPU thread's chunk of particles, or stays in the
      pair's slot across chunks and on a GPU
      -> gather per particle (own sum + reverse slots: no atomics, fixed order)
      -> damping, prescribed velocities, leapfrog: v_{n+1/2}, x_{n+1}
      -> energy account at t_n, skin check (raises the rebuild flag)
      -> walls move

Conventions (Cundall & Strack 1979): n points from i to j, t = n rotated +90°, F_n is
compression-positive, the force on i is −F_n n + F_s t, ω × r = ω(−r_y, r_x).
Contact forces use x_n and the mid-step velocities v_{n−1/2} (C&S).
"""
import taichi as ti

from physics.contact_law import (COL_REACH, get_columns, history_width, law_energy, law_force,
                                 law_force_3d, law_stiffness, put_columns, tangent_dim,
                                 zero_history)
from physics.geometry import disc_disc, disc_segment, sphere_triangle
from physics.geometry import superellipse as se
from physics.geometry.frame import (moment, pack, spin_cross, spin_dot, spin_zero,
                                    tangent_part, tangent_vector, unpack, vec_zero)
from physics.rolling import (rolling_couple, rolling_couple_3d, rolling_energy,
                             rolling_energy_3d)

from .finite import any_non_finite, non_finite
from .integrate import _quat_mul, damped_leapfrog, free_rotation
from .launch import cached
from .neighbors import (F_BAD, F_FAST, F_PUSH, F_REBUILD, P_ALPHA, P_ALPHA_LOCAL, P_CHUNK,  # noqa: F401
                        P_DT, P_GX, P_GY, P_GZ, P_NWALLS, P_PLX, P_PLY, P_PLZ, P_PX0, P_PY0,
                        P_PZ0, P_SKIN, SIMP_SIZE, T_AX, T_BX, T_CX, T_DISP, T_LAW, T_MESH,
                        T_OX, T_SX, T_VX, T_WX, TRI_WIDTH, gravity, image, periodic_axes, slot_bits,
                        tri_vec)
from . import polyhedra3d, primitives, shaped3d
from .shaped import shape_of, shaped_pair, shaped_wall
from .state import PROP_INERTIA, PROP_MASS, PROP_RADIUS

# the columns of the wall array (W_*, a segment's row in 2D) are declared in
# tdem.core.layout (PCMM cells clip against the walls) and named here too
from .core.layout import (W_CX, W_CY, W_DISP, W_INVLL, W_LAW, W_OMEGA,  # noqa: F401
                          W_SERVO_ALPHA, W_SERVO_DX, W_SERVO_DY, W_SERVO_F, W_SERVO_K,
                          W_SERVO_VMAX, W_VX, W_VY, W_X0, W_X1, W_Y0, W_Y1, WALL_WIDTH)
# 3D: the wall table holds the triangles of the mesh walls (columns T_*, tdem.neighbors)

# the contact forces of a step may move a particle by at most this fraction of its
# radius (turn it by this many radians) from rest in one step; more is an instability
# (check_stability)
PUSH_LIMIT = 1.0
# a pair whose overlap exceeds this fraction of the smaller radius (the smaller's centre
# inside the other) has failed: the model is unstable (check_stability; DEM models only)
OVERLAP_LIMIT = 1.0


def wall_width(dim):
    """Columns of a row of the wall table: a segment (2D) or a mesh triangle (3D)."""
    return WALL_WIDTH if dim == 2 else TRI_WIDTH


# the step's ``shapes`` bits: superellipses (2D) or ellipsoids (3D); polyhedra (3D)
SHAPES_SMOOTH, SHAPES_POLY = 1, 2

# fixed-velocity bits (FIX_W: every spin component; FIX_VZ: 3D)
FIX_VX, FIX_VY, FIX_W, FIX_VZ = 1, 2, 4, 8


@ti.func
def pair_contact(i, k, xi, vi, wi, ri, mi, li, pos: ti.template(), vel: ti.template(),
                 omega: ti.template(), prop: ti.template(), plaw: ti.template(),
                 lawp: ti.template(), lawpair: ti.template(), nbr: ti.template(),
                 hist: ti.template(), cn: ti.template(), cs: ti.template(), dt,
                 detail, laws: ti.template(), per, ranged: ti.template()):
    """Contact in slot k of particle i (the owner, i < j) with partner j = nbr[i, k]:
    two discs (:func:`disc_pair`) or two spheres (:func:`sphere_pair`). xi, vi, wi,
    ri, mi, li are i's position, velocity, spin, radius, mass and law group; ``laws``
    the registered contact laws (:mod:`physics.contact_law`); ``per`` the periodic
    axes (j is taken at its image nearest to i); ``ranged`` (compile-time) whether a law
    of the model acts across a gap (its range, :mod:`physics.contact_law`).

    Updates the history and returns (f_i, M_i, M_j, dissipated energy). With
    ``detail`` also stores the normal, the scalar forces and the overlap (for
    output, stress and energy)."""
    f = xi * 0.0
    m_on_i = spin_zero(ti.static(xi.n))
    m_on_j = spin_zero(ti.static(xi.n))
    diss = 0.0
    if ti.static(xi.n == 2):
        f, m_on_i, m_on_j, diss = disc_pair(i, k, xi, vi, wi, ri, mi, li, pos, vel, omega,
                                            prop, plaw, lawp, lawpair, nbr, hist, cn, cs,
                                            dt, detail, laws, per, ranged)
    else:
        f, m_on_i, m_on_j, diss = sphere_pair(i, k, xi, vi, wi, ri, mi, li, pos, vel, omega,
                                              prop, plaw, lawp, lawpair, nbr, hist, cn, cs,
                                              dt, detail, laws, per, ranged)
    return f, m_on_i, m_on_j, diss


@ti.func
def sphere_pair(i, k, xi, vi, wi, ri, mi, li, pos: ti.template(), vel: ti.template(),
                omega: ti.template(), prop: ti.template(), plaw: ti.template(),
                lawp: ti.template(), lawpair: ti.template(), nbr: ti.template(),
                hist: ti.template(), cn: ti.template(), cs: ti.template(), dt,
                detail, laws: ti.template(), per, ranged: ti.template()):
    """:func:`pair_contact` of two spheres. The pair is tested on the squared distance
    first: of the listed pairs of a dense bed a third or more do not touch, and those
    cost a load of the partner's position and radius and no square root. The history
    holds the law's columns, then those of the rolling resistance when a law has one."""
    R = ti.static(history_width(laws, tangent_dim(3)))
    j = nbr[i, k]
    d = image(pos[j] - xi, per)
    r2 = d.dot(d)
    pj = prop[j]
    rj = pj[PROP_RADIUS]
    rs = ri + rj
    f = ti.Vector([0.0, 0.0, 0.0])
    m_on_i = ti.Vector([0.0, 0.0, 0.0])
    m_on_j = ti.Vector([0.0, 0.0, 0.0])
    diss = 0.0
    cut = rs
    L = 0
    if ti.static(ranged):
        # a law with a range acts across gaps below it
        L = lawpair[li, plaw[j]]
        cut = rs + lawp[L, COL_REACH]
    if r2 < cut * cut:
        dist = ti.sqrt(r2)
        u = rs - dist
        n = ti.Vector([1.0, 0.0, 0.0])      # (coincident centres)
        if dist > 0.0:
            n = d * (1.0 / dist)
        # the contact point's arms a = R − u/2 and the relative velocity of j's
        # contact point against i's: v_j − v_i − (a_j ω_j + a_i ω_i) × n
        ai = ri - 0.5 * u
        aj = rj - 0.5 * u
        vrel = vel[j] - vi - (aj * omega[j] + ai * wi).cross(n)
        vn = vrel.dot(n)
        if ti.static(not ranged):
            L = lawpair[li, plaw[j]]
        mj = pj[PROP_MASS]
        # R* = R_i R_j/(R_i + R_j) and m* = m_i m_j/(m_i + m_j) by one division
        inv = 1.0 / (rs * (mi + mj))
        reff = ri * rj * (mi + mj) * inv
        meff = mi * mj * rs * inv
        h = hist[i, k]
        fn_el, fn, ft, kn, cnd, d1, h = law_force_3d(
            laws, lawp, L, u, vn, vrel - vn * n, meff, reff, dt, h, n)
        f = -fn * n + ft
        # the moments (a n) × f of the contact force at each branch: n × f = n × F_t
        nxf = n.cross(ft)
        m_on_i = ai * nxf
        m_on_j = aj * nxf
        diss = d1
        if ti.static(h.n >= R + 7):
            # rolling resistance (the columns after the law's), while they touch
            touching = 1
            if ti.static(ranged):
                touching = u > 0.0
            if touching:
                m, m_tot, th, brk, d2 = rolling_couple_3d(
                    lawp, L, fn_el, kn, cnd, 2.0 * reff, wi - omega[j], n, dt,
                    get_columns(h, R, 3), get_columns(h, R + 3, 3), h[R + 6])
                h = put_columns(h, R, m)
                h = put_columns(h, R + 3, th)
                h[R + 6] = brk
                m_on_i += m_tot
                m_on_j -= m_tot
                diss += d2
            else:
                for c in ti.static(range(7)):
                    h[R + c] = 0.0
        hist[i, k] = h
        if detail:
            cn[i, k] = n
            cs[i, k] = ti.Vector([fn, ft.norm(), u])
    else:
        h = hist[i, k]
        if h.dot(h) != 0.0:
            hist[i, k] = zero_history(h)
        if detail:
            cs[i, k] = ti.Vector([0.0, 0.0, rs - ti.sqrt(r2)])
    return f, m_on_i, m_on_j, diss


@ti.func
def disc_pair(i, k, xi, vi, wi, ri, mi, li, pos: ti.template(), vel: ti.template(),
              omega: ti.template(), prop: ti.template(), plaw: ti.template(),
              lawp: ti.template(), lawpair: ti.template(), nbr: ti.template(),
              hist: ti.template(), cn: ti.template(), cs: ti.template(), dt,
              detail, laws: ti.template(), per, ranged: ti.template()):
    """:func:`pair_contact` of two discs. The history vector holds the law's columns,
    the rolling couple, rotation and broken flag (from column R) and the overlap
    offset u0 (the last column)."""
    R = ti.static(history_width(laws))
    U0 = ti.static(R + 3)
    j = nbr[i, k]
    pj = prop[j]
    rj = pj[PROP_RADIUS]
    d, dist, u_geo = disc_disc.overlap(xi, xi + image(pos[j] - xi, per), ri, rj)
    # a pair that shared PCMM elements until recently counts its overlap from the
    # overlap it had when they stopped carrying it (hist[U0], recorded by
    # physics.pcmm.gather, lowered as the two separate): the contact law takes over
    # from the elements without a force jump (no energy from nowhere)
    h = hist[i, k]
    u0 = ti.min(h[U0], ti.max(u_geo, 0.0))
    u = u_geo - u0
    f = ti.Vector([0.0, 0.0])
    m_on_i = 0.0
    m_on_j = 0.0
    diss = 0.0
    live = u > 0.0
    L = 0
    if ti.static(ranged):
        # a law with a range acts across gaps below it
        L = lawpair[li, plaw[j]]
        live = u > -lawp[L, COL_REACH]
    if live:
        wj = omega[j]
        n, t, ai, aj, vrel = disc_disc.kinematics(d, dist, u, ri, rj, vi, vel[j], wi, wj)
        vn = vrel.dot(n)
        if ti.static(not ranged):
            L = lawpair[li, plaw[j]]
        mj = pj[PROP_MASS]
        # R* = R_i R_j/(R_i + R_j) and m* = m_i m_j/(m_i + m_j) by one division
        inv = 1.0 / ((ri + rj) * (mi + mj))
        reff = ri * rj * (mi + mj) * inv
        meff = mi * mj * (ri + rj) * inv
        fn_el, fn, ft, kn, cnd, d1, h = law_force(
            laws, lawp, L, u, vn, tangent_part(vrel, n), meff, reff, dt, h)
        fs_tot = ft[0]
        f = -fn * n + tangent_vector(ft, n)
        m_on_i = ai * fs_tot
        m_on_j = aj * fs_tot
        diss = d1
        touching = 1
        if ti.static(ranged):
            touching = u > 0.0
        if touching:
            m, m_tot, th, brk, d2 = rolling_couple(
                lawp, L, fn_el, kn, cnd, 2.0 * reff, wi - wj, dt, h[R], h[R + 1], h[R + 2])
            m_on_i += m_tot
            m_on_j -= m_tot
            h[R] = m
            h[R + 1] = th
            h[R + 2] = brk
            diss += d2
        else:
            h[R] = 0.0
            h[R + 1] = 0.0
            h[R + 2] = 0.0
        h[U0] = u0
        hist[i, k] = h
        if detail:
            cn[i, k] = n
            cs[i, k] = ti.Vector([fn, fs_tot, u])
    else:
        h = zero_history(h)
        h[U0] = u0
        hist[i, k] = h
        if detail:
            cs[i, k] = ti.Vector([0.0, 0.0, u])
    return f, m_on_i, m_on_j, diss


@ti.func
def wall_contacts(i, pos: ti.template(), vel: ti.template(), omega: ti.template(),
                  prop: ti.template(), wall: ti.template(), wpart: ti.template(), row,
                  lawp: ti.template(), wid: ti.template(), whist: ti.template(),
                  wcn: ti.template(), wcf: ti.template(), wcs: ti.template(), dt,
                  laws: ti.template(), angle: ti.template(), shp: ti.template(),
                  flags: ti.template(), shapes: ti.template(), ranged: ti.template()):
    """Contacts of particle i with its candidate walls (listed in its wall slots by the
    neighbour build). The wall is 'j', of infinite radius and mass; what it receives
    is added to its sum in row ``row`` of ``wpart`` (the chunk's). Returns
    (force on i, moment on i, dissipation, work done by the walls). The history holds
    the law's columns, then the rolling couple, rotation and broken flag. With
    ``ranged`` a law with a range acts across a gap below it."""
    R = ti.static(history_width(laws))
    xi = pos[i]
    ri = prop[i][PROP_RADIUS]
    diss = 0.0
    work = 0.0
    ftot = ti.Vector([0.0, 0.0])
    mtot = 0.0
    shaped = False
    if ti.static(shapes):
        shaped = shp[i][2] > 0.0
    for s in range(wid.shape[1]):
        w = wid[i, s]
        if w < 0:
            break
        a = ti.Vector([wall[w, W_X0], wall[w, W_Y0]])
        b = ti.Vector([wall[w, W_X1], wall[w, W_Y1]])
        d = ti.Vector([0.0, 0.0])
        d2 = 0.0
        if not shaped:
            d, d2 = disc_segment.overlap(xi, a, b, wall[w, W_INVLL])
        cut = ri
        if ti.static(ranged):
            cut = ri + lawp[ti.cast(wall[w, W_LAW], ti.i32), COL_REACH]
        if shaped:       # (False, a constant, in a model without shapes)
            c = ti.Vector([wall[w, W_CX], wall[w, W_CY]])
            touching, f, mi, n, fn, fs, u, xc, vw, h, d1 = shaped_wall(
                xi, vel[i], omega[i], prop[i][PROP_MASS], angle[i], shape_of(shp[i], ri), ri,
                a, b, wall[w, W_INVLL], ti.Vector([wall[w, W_VX], wall[w, W_VY]]),
                wall[w, W_OMEGA], c, ti.cast(wall[w, W_LAW], ti.i32), whist[i, s], lawp,
                flags, dt, laws)
            whist[i, s] = h
            if touching:
                wcn[i, s] = n
                wcf[i, s] = ti.Vector([f[0], f[1], mi, 0.0])
                wcs[i, s] = ti.Vector([fn, fs, u])
                diss += d1
                work += f.dot(vw) * dt
                ftot += f
                mtot += mi
                r = xc - c
                ti.atomic_add(wpart[row, w][0], -f[0])
                ti.atomic_add(wpart[row, w][1], -f[1])
                ti.atomic_add(wpart[row, w][2], r[0] * (-f[1]) - r[1] * (-f[0]))
                ti.atomic_add(wpart[row, w][3], 1.0)
            elif wcs[i, s][2] > 0.0:
                wcf[i, s] = ti.Vector([0.0, 0.0, 0.0, 0.0])
                wcs[i, s] = ti.Vector([0.0, 0.0, u])
        elif d2 < cut * cut:
            c = ti.Vector([wall[w, W_CX], wall[w, W_CY]])
            ww = wall[w, W_OMEGA]
            u, n, t, ai, xc, vw, vrel = disc_segment.kinematics(
                xi, d, d2, ri, vel[i], omega[i], ti.Vector([wall[w, W_VX], wall[w, W_VY]]),
                ww, c)
            vn = vrel.dot(n)
            L = ti.cast(wall[w, W_LAW], ti.i32)
            h = whist[i, s]
            fn_el, fn, ft, kn, cnd, d1, h = law_force(
                laws, lawp, L, u, vn, tangent_part(vrel, n), prop[i][PROP_MASS], ri, dt, h)
            fs_tot = ft[0]
            m_tot = 0.0
            d2r = 0.0
            touching = 1
            if ti.static(ranged):
                touching = u > 0.0
            if touching:
                m, m_tot1, th, brk, d2r1 = rolling_couple(
                    lawp, L, fn_el, kn, cnd, 2.0 * ri, omega[i] - ww, dt, h[R], h[R + 1],
                    h[R + 2])
                m_tot = m_tot1
                d2r = d2r1
                h[R] = m
                h[R + 1] = th
                h[R + 2] = brk
            else:
                h[R] = 0.0
                h[R + 1] = 0.0
                h[R + 2] = 0.0
            f = -fn * n + tangent_vector(ft, n)
            mi = ai * fs_tot + m_tot
            whist[i, s] = h
            wcn[i, s] = n
            wcf[i, s] = ti.Vector([f[0], f[1], mi, 0.0])
            wcs[i, s] = ti.Vector([fn, fs_tot, u])
            diss += d1 + d2r
            work += f.dot(vw) * dt
            ftot += f
            mtot += mi
            r = xc - c
            ti.atomic_add(wpart[row, w][0], -f[0])
            ti.atomic_add(wpart[row, w][1], -f[1])
            ti.atomic_add(wpart[row, w][2], r[0] * (-f[1]) - r[1] * (-f[0]) - m_tot)
            ti.atomic_add(wpart[row, w][3], 1.0)
        elif (whist[i, s][0] != 0.0 or wcs[i, s][2] > 0.0 or whist[i, s][R] != 0.0
              or (ranged and whist[i, s].dot(whist[i, s]) != 0.0)):
            whist[i, s] = zero_history(whist[i, s])
            wcf[i, s] = ti.Vector([0.0, 0.0, 0.0, 0.0])
            wcs[i, s] = ti.Vector([0.0, 0.0, ri - ti.sqrt(d2)])
    return ftot, mtot, diss, work


@ti.func
def _mesh_geometry(xi, ri, shaped, mat, abc, wall: ti.template(), w, reach):
    """(live, depth, n from the particle to the wall, contact point, feature,
    Hertz radius) of a sphere (radius ri) or an ellipsoid (``shaped``: shape matrix
    ``mat``, semi-axes ``abc``) against mesh triangle w; live: the depth is above
    −``reach`` (0, or the range of a law that acts across a gap)."""
    a = tri_vec(wall, w, T_AX)
    b = tri_vec(wall, w, T_BX)
    c = tri_vec(wall, w, T_CX)
    depth = 0.0
    n = ti.Vector([0.0, 0.0, -1.0])
    point = xi
    feat = 0
    radius = ri
    if shaped:
        depth, n, point, feat, radius = shaped3d.mesh_contact(xi, mat, abc, a, b, c)
    else:
        q, f = sphere_triangle.closest_point(xi, a, b, c)
        feat = f
        d = q - xi
        dist = d.norm()
        depth = ri - dist
        if dist > 0.0:
            n = d / dist
        point = xi + (ri - 0.5 * depth) * n
    return depth > -reach, depth, n, point, feat, radius


@ti.func
def _wall_reach(wall: ti.template(), lawp: ti.template(), w, ranged: ti.template()):
    """The range of mesh triangle w's law (0 unless ``ranged``)."""
    r = 0.0
    if ti.static(ranged):
        r = lawp[ti.cast(wall[w, T_LAW], ti.i32), COL_REACH]
    return r


@ti.func
def mesh_contacts(i, pos: ti.template(), vel: ti.template(), omega: ti.template(),
                  prop: ti.template(), wall: ti.template(), wpart: ti.template(), row,
                  lawp: ti.template(), wid: ti.template(), whist: ti.template(),
                  wcn: ti.template(), wcf: ti.template(), wcs: ti.template(), dt,
                  laws: ti.template(), shaped, mat, abc, ranged: ti.template()):
    """3D: contacts of particle i (a sphere, or an ellipsoid when ``shaped``: shape
    matrix ``mat``, semi-axes ``abc``) with its candidate mesh triangles (wall slots),
    by the nearest point of each triangle (:mod:`physics.geometry.sphere_triangle`,
    :func:`tdem.shaped3d.mesh_contact`). Of the triangles of one mesh that it touches,
    face contacts are kept and edge or vertex contacts dropped (they lie on a face's
    border), and of several edge or vertex contacts at one point the first is kept:
    a particle on the seams of a flat or convex surface feels one plane. A contact that
    moves to a neighbouring triangle of the same mesh takes its shear spring along.
    Returns (force, moment, dissipation, work of the walls) and adds what the walls
    receive to ``wpart`` as :func:`wall_contacts`.
    An ellipsoid's wall history keeps its Hertz radius after the law's columns. With
    ``ranged`` a law with a range acts across a gap below it (a face within range
    counts as a face contact)."""
    T = ti.static(tangent_dim(3))
    RW = ti.static(history_width(laws, T))
    xi = pos[i]
    ri = prop[i][PROP_RADIUS]
    capw = wid.shape[1]
    diss = 0.0
    work = 0.0
    ftot = ti.Vector([0.0, 0.0, 0.0])
    mtot = ti.Vector([0.0, 0.0, 0.0])
    # meshes (by index) with a face contact; a small fixed set is enough: a particle
    # touches faces of few meshes at once (more are counted as having none: their
    # edge contacts are then kept)
    faced = ti.Vector([-1, -1, -1, -1])
    nfaced = 0
    for s in range(capw):
        w = wid[i, s]
        if w < 0:
            break
        touch, depth, n, point, feat, radius = _mesh_geometry(xi, ri, shaped, mat, abc, wall, w,
                                                              _wall_reach(wall, lawp, w, ranged))
        if touch and feat == sphere_triangle.FACE and nfaced < 4:
            faced[nfaced] = ti.cast(wall[w, T_MESH], ti.i32)
            nfaced += 1
    for s in range(capw):
        w = wid[i, s]
        if w < 0:
            break
        live, depth, n, point, feat, radius = _mesh_geometry(xi, ri, shaped, mat, abc, wall, w,
                                                             _wall_reach(wall, lawp, w, ranged))
        mesh = ti.cast(wall[w, T_MESH], ti.i32)
        if live and feat != sphere_triangle.FACE:
            for k in ti.static(range(4)):
                if faced[k] == mesh:
                    live = False
            for s2 in range(s):
                w2 = wid[i, s2]
                if ti.cast(wall[w2, T_MESH], ti.i32) == mesh:
                    t2, u2, n2, p2, f2, r2 = _mesh_geometry(
                        xi, ri, shaped, mat, abc, wall, w2, _wall_reach(wall, lawp, w2, ranged))
                    if t2 and f2 != sphere_triangle.FACE and (p2 - point).norm() <= 1e-9 * ri:
                        live = False
        h = whist[i, s]
        if live:
            if get_first(h, T) == 0.0:
                # a new contact: a spring of this mesh that stopped touching takes over
                for s2 in range(capw):
                    w2 = wid[i, s2]
                    if w2 >= 0 and s2 != s and ti.cast(wall[w2, T_MESH], ti.i32) == mesh:
                        h2 = whist[i, s2]
                        if get_first(h2, T) != 0.0:
                            t2, u2, n2, p2, f2, r2 = _mesh_geometry(
                                xi, ri, shaped, mat, abc, wall, w2,
                                _wall_reach(wall, lawp, w2, ranged))
                            if not (t2 and f2 == sphere_triangle.FACE):
                                h = h2
                                whist[i, s2] = zero_history(h2)
            arm = point - xi
            c = tri_vec(wall, w, T_OX)
            vw = tri_vec(wall, w, T_VX) + spin_cross(tri_vec(wall, w, T_WX), point - c) \
                + tangent_part(tri_vec(wall, w, T_SX), n)       # a belt's surface
            vrel = vw - vel[i] - spin_cross(omega[i], arm)
            vn = vrel.dot(n)
            L = ti.cast(wall[w, T_LAW], ti.i32)
            f, mi, m_roll, fn, ft, d1, d2, h = primitives.wall_law(
                laws, lawp, L, depth, vn, tangent_part(vrel, n), prop[i][PROP_MASS], radius,
                ri, omega[i] - tri_vec(wall, w, T_WX), arm, dt, h, n, ranged)
            diss += d2
            if ti.static(RW < h.n < RW + 7):
                h[RW] = radius
            whist[i, s] = h
            wcn[i, s] = n
            wcf[i, s] = pack(f, mi, 3)
            wcs[i, s] = ti.Vector([fn, ft.norm(), depth])
            diss += d1
            work += f.dot(vw) * dt
            ftot += f
            mtot += mi
            tw = moment(point - c, -f) - m_roll
            for k in ti.static(range(3)):
                ti.atomic_add(wpart[row, w][k], -f[k])
                ti.atomic_add(wpart[row, w][3 + k], tw[k])
            ti.atomic_add(wpart[row, w][6], 1.0)
        elif (get_first(h, T) != 0.0 or wcs[i, s][2] > 0.0
              or (ranged and h.dot(h) != 0.0)):
            whist[i, s] = zero_history(h)
            wcf[i, s] = ti.Vector([0.0, 0.0, 0.0, 0.0, 0.0, 0.0])
            wcs[i, s] = ti.Vector([0.0, 0.0, ti.min(depth, 0.0)])
    return ftot, mtot, diss, work


@ti.func
def get_first(h, T: ti.template()):
    """|first T columns|² of a history (the shear spring): zero for a fresh contact."""
    e = 0.0
    for c in ti.static(range(T)):
        e += h[c] * h[c]
    return e


@ti.func
def servo_velocity(wall: ti.template(), wforce: ti.template(), w, dt):
    """Velocity of a servo-controlled wall (PFC-style): it moves along its direction d
    by relaxation × (target − measured force)/(contacts × k) per step, so that with
    relaxation < 1 the force converges without overshoot; |v| <= the speed limit.
    The measured force is the compression the wall receives along −d."""
    d = ti.Vector([wall[w, W_SERVO_DX], wall[w, W_SERVO_DY]])
    fw = wforce[w]
    measured = -(fw[0] * d[0] + fw[1] * d[1])
    k = wall[w, W_SERVO_K] * ti.max(fw[3], 1.0)
    v = wall[w, W_SERVO_ALPHA] * (wall[w, W_SERVO_F] - measured) / (k * dt)
    vmax = wall[w, W_SERVO_VMAX]
    v = ti.math.clamp(v, -vmax, vmax)
    return v * d[0], v * d[1]


@ti.func
def walls_3d(i, pos: ti.template(), vel: ti.template(), omega: ti.template(),
             prop: ti.template(), angle: ti.template(), turn: ti.template(), shp: ti.template(),
             wall: ti.template(), wpart: ti.template(), row, lawp: ti.template(),
             wid: ti.template(), whist: ti.template(), wcn: ti.template(), wcf: ti.template(),
             wcs: ti.template(), flags: ti.template(), dt, laws: ti.template(),
             ptab: ti.template(), pint: ti.template(), prim: ti.template(),
             ppart: ti.template(), phist: ti.template(), pcn: ti.template(),
             pcf: ti.template(), pcs: ti.template(), ranged: ti.template(),
             prims: ti.template(), shapes: ti.template()):
    """3D: particle i's contacts with its candidate mesh triangles (a polyhedron's by
    :func:`tdem.polyhedra3d.mesh_contacts`, a sphere's or an ellipsoid's by
    :func:`mesh_contacts`) and with the primitive walls. Returns (force, moment,
    dissipation, work of the walls)."""
    xi = pos[i]
    ri = prop[i][PROP_RADIUS]
    fw = ti.Vector([0.0, 0.0, 0.0])
    mw = ti.Vector([0.0, 0.0, 0.0])
    dw = 0.0
    work = 0.0
    shi = ti.Vector([0.0, 0.0, 0.0])
    ishaped = False
    mati = ti.Matrix.identity(float, 3)
    if ti.static(shapes & SHAPES_SMOOTH):
        shi = shaped3d.axes_of(shp[i], ri)
        mati = shaped3d.shape_of_row(turn[i])
        ishaped = shp[i][3] > 0.0
    ipoly = False
    if ti.static(shapes & SHAPES_POLY):
        ipoly = shp[i][3] < 0.0
    if ti.static(shapes & SHAPES_POLY):
        if ipoly:
            fw, mw, dw, work = polyhedra3d.mesh_contacts(
                i, pos, vel, omega, prop, angle, shp, wall, wpart, row, lawp, wid,
                whist, wcn, wcf, wcs, flags, dt, laws, ptab, pint)
    if not ipoly:
        fw, mw, dw, work = mesh_contacts(i, pos, vel, omega, prop, wall, wpart,
                                         row, lawp, wid, whist, wcn, wcf, wcs, dt,
                                         laws, ishaped, mati, shi, ranged)
    if ti.static(prims):
        # (spheres only: shaped particles are refused with primitives)
        fp, mp, dp, wp = primitives.prim_contacts(
            i, vel, omega, prop, xi, prim, ppart, row, lawp, phist, pcn, pcf,
            pcs, dt, laws, ranged)
        fw += fp
        mw += mp
        dw += dp
        work += wp
    return fw, mw, dw, work


@ti.func
def _chunk_span(it, n, csz, sp, chunk: ti.template()):
    """Iteration ``it`` of the step's loops over chunks of ``csz`` particles, spread
    over 2**sp iterations each (only the first does work): its particles [lo, end)
    and, with ``chunk``, its row of the walls' partial sums (0 without)."""
    lo = (it >> sp) * csz
    row = 0
    if ti.static(chunk):
        row = it >> sp
    end = ti.min(n, lo + csz)
    if it & ((1 << sp) - 1) != 0:
        end = lo
    return lo, end, row


@cached
@ti.kernel
def step(pos: ti.types.ndarray(), vel: ti.types.ndarray(), omega: ti.types.ndarray(),
         angle: ti.types.ndarray(), turn: ti.types.ndarray(), shp: ti.types.ndarray(),
         prop: ti.types.ndarray(), plaw: ti.types.ndarray(), fix: ti.types.ndarray(),
         vfix: ti.types.ndarray(), force: ti.types.ndarray(), torque: ti.types.ndarray(),
         xref: ti.types.ndarray(), pos0: ti.types.ndarray(), facc: ti.types.ndarray(),
         wacc: ti.types.ndarray(),
         eacc: ti.types.ndarray(),
         estate: ti.types.ndarray(), ework: ti.types.ndarray(),
         nbr: ti.types.ndarray(), ncnt: ti.types.ndarray(), hist: ti.types.ndarray(),
         cn: ti.types.ndarray(), cf: ti.types.ndarray(), cs: ti.types.ndarray(),
         rev: ti.types.ndarray(), rcnt: ti.types.ndarray(),
         wall: ti.types.ndarray(), wforce: ti.types.ndarray(), wpart: ti.types.ndarray(),
         wid: ti.types.ndarray(), whist: ti.types.ndarray(), wcn: ti.types.ndarray(),
         wcf: ti.types.ndarray(), wcs: ti.types.ndarray(),
         lawp: ti.types.ndarray(), lawpair: ti.types.ndarray(), flags: ti.types.ndarray(),
         simp: ti.types.ndarray(), xforce: ti.types.ndarray(), cskip: ti.types.ndarray(),
         fext: ti.types.ndarray(), lmom: ti.types.ndarray(), ptab: ti.types.ndarray(),
         pint: ti.types.ndarray(), bforce: ti.types.ndarray(), prim: ti.types.ndarray(),
         pforce: ti.types.ndarray(), ppart: ti.types.ndarray(), phist: ti.types.ndarray(),
         pcn: ti.types.ndarray(), pcf: ti.types.ndarray(), pcs: ti.types.ndarray(),
         serial: ti.template(),
         chunk: ti.template(), loads: ti.template(), bonds: ti.template(),
         ranged: ti.template(), prims: ti.template(), periodic: ti.template(), detail: ti.i32, continuum: ti.template(), laws: ti.template(),
         shapes: ti.template(), dim: ti.template()):
    """One step. ``detail`` (1 or 0) also stores what only output reads: per-contact
    normals, scalar forces and overlaps, particle forces, and the kinetic and
    gravitational energy at t_n. The host asks for it on the last step before
    anything looks at the state. It is a value, not a compile-time switch: every step
    runs the same machine code, so that a run's numbers do not depend on where it was
    cut into segments (two compiled variants of the step round differently under
    fast math, and a segment's last step is a detail step).

    ``continuum`` (compile-time): PCMM particles are present. Their element forces
    of this step (``xforce``, from :func:`physics.pcmm.update`) join the contact
    forces, and pair slots marked in ``cskip`` (particles that share an element)
    have no DEM contact.

    ``serial`` (compile-time): every loop on one thread. ``chunk`` (compile-time):
    the pair loop in chunks, each one thread's serial loop (1. below).

    ``loads`` (compile-time): applied forces and moments (``fext``, from
    :meth:`tdem.Simulation.apply_force`) act on the particles.

    ``bonds`` (compile-time): the bonds' forces and moments of this step (``bforce``,
    from :func:`tdem.bonds.bond_forces`) join the contact forces (their work is the
    contacts').

    ``ranged`` (compile-time): a contact law of the model has a range, so that pairs of
    discs or spheres apart by less than it are evaluated too (:mod:`physics.contact_law`).

    ``prims`` (compile-time, 3D): the model has primitive walls (planes, cylinders:
    the table ``prim``, their contacts' arrays ``phist``, ``pcn``, ``pcf``, ``pcs``,
    their forces ``pforce``, :mod:`tdem.primitives`); every sphere meets each of them.

    ``periodic`` (compile-time): the model has a periodic axis (pairs are then taken at
    their nearest images and positions wrapped, simp[P_PX0 ...]); without one the
    checks compile away.

    ``dim`` (compile-time): 2 (discs, superellipses, PCMM, segment walls) or 3 (spheres
    and mesh walls); spins and moments are scalars in 2D and 3-vectors in 3D.

    ``shapes`` (compile-time): 0 without shaped particles, else bits: SHAPES_SMOOTH
    (superellipses in 2D, ellipsoids in 3D), SHAPES_POLY (polyhedra, 3D; their tables
    ``ptab``, ``pint``, :mod:`physics.polyhedron`)."""
    n = pos.shape[0]
    cap = nbr.shape[1]
    bits = slot_bits(cap)
    dt = simp[P_DT]
    nw = ti.cast(simp[P_NWALLS], ti.i32)
    g = gravity(simp, dim)
    alpha = simp[P_ALPHA]
    alpha_l = simp[P_ALPHA_LOCAL]
    damped = alpha != 0.0 or alpha_l != 0.0
    half_skin2 = (0.5 * simp[P_SKIN]) ** 2
    per = ti.Vector([0.0] * (2 * dim))      # (no periodic axis: the checks compile away)
    if ti.static(periodic):
        per = periodic_axes(simp, dim)

    if ti.static(shapes and dim == 2):
        # each angle's cosine and sine once, for all the pairs it takes part in
        ti.loop_config(serialize=serial)
        for i in range(n):
            turn[i] = ti.Vector([ti.cos(angle[i]), ti.sin(angle[i])])
    if ti.static(dim == 3 and (shapes & SHAPES_SMOOTH)):
        # each particle's shape matrix once, likewise
        ti.loop_config(serialize=serial)
        for i in range(n):
            turn[i] = shaped3d.shape_row(shp[i], angle[i], prop[i][PROP_RADIUS])

    # 1. contact forces at x_n: each pair once, by its owner (the lower index). On one
    #    thread the partner's share goes straight into its sum; in parallel it is kept
    #    in the slot and gathered in 2. (no atomics, a fixed summation order). With
    #    ``chunk`` (CPU threads) each chunk of simp[P_CHUNK] particles is one thread's
    #    serial loop: a partner in the same chunk gets its share at once, one in a
    #    later chunk through the slot. Otherwise each particle is its own chunk.
    #    (Taichi's CPU tasks take at least 512 iterations of a parallel loop, so a
    #    loop over a dozen chunks would run on one thread: the loop gives each of
    #    several chunks 2^sp iterations, the first of which does its work.)
    csz = 1
    sp = 0
    if ti.static(chunk):
        csz = ti.cast(simp[P_CHUNK], ti.i32)
        if csz < 1:
            csz = n     # (not set: one chunk, the one-thread order)
        if csz < n:
            sp = 10
    if ti.static(dim == 3):
        # 3D: the wall contacts first, in a loop of their own (the same chunks), kept
        # in wacc for the particles that have candidate walls (or primitives) and added
        # in the pair loop below as if computed there. Few particles touch walls; kept
        # out of the pair loop, their code does not slow it down
        ti.loop_config(serialize=serial)
        for it in range(((n + csz - 1) // csz) << sp):
            lo, end, row = _chunk_span(it, n, csz, sp, chunk)
            for i in range(lo, end):
                if ti.static(prims) or wid[i, 0] >= 0:
                    fw, mw, dw, work = walls_3d(
                        i, pos, vel, omega, prop, angle, turn, shp, wall, wpart, row, lawp, wid,
                        whist, wcn, wcf, wcs, flags, dt, laws, ptab, pint, prim, ppart, phist,
                        pcn, pcf, pcs, ranged, prims, shapes)
                    wacc[i] = ti.Vector([fw[0], fw[1], fw[2], mw[0], mw[1], mw[2], dw, work])
    ti.loop_config(serialize=serial)
    for it in range(((n + csz - 1) // csz) << sp):
        lo, end, row = _chunk_span(it, n, csz, sp, chunk)
        for i in range(lo, end):
            f = vec_zero(dim)
            tq = spin_zero(dim)
            diss = 0.0
            xi = pos[i]
            vi = vel[i]
            wi = omega[i]
            pi = prop[i]
            li = plaw[i]
            shi = ti.Vector([0.0, 0.0, 0.0])
            ishaped = False
            cthi = 1.0
            sthi = 0.0
            mati = ti.Matrix.identity(float, 3)
            if ti.static(shapes and dim == 2):
                cthi = turn[i][0]
                sthi = turn[i][1]
                shi = shape_of(shp[i], pi[PROP_RADIUS])
                ishaped = shp[i][2] > 0.0
            ipoly = False
            if ti.static(dim == 3 and (shapes & SHAPES_SMOOTH)):
                # an ellipsoid's semi-axes and shape matrix (a sphere's: r, r, r)
                shi = shaped3d.axes_of(shp[i], pi[PROP_RADIUS])
                mati = shaped3d.shape_of_row(turn[i])
                ishaped = shp[i][3] > 0.0
            if ti.static(dim == 3 and (shapes & SHAPES_POLY)):
                ipoly = shp[i][3] < 0.0
            for k in range(ncnt[i]):
                fk = vec_zero(dim)
                mk = spin_zero(dim)
                mjk = spin_zero(dim)
                dk = 0.0
                skip = 0
                if ti.static(continuum):
                    skip = cskip[i, k]
                if skip == 1:
                    # the elements carry this pair (its history is kept by
                    # physics.pcmm.gather)
                    if detail:
                        cs[i, k] = ti.Vector([0.0, 0.0, 0.0])
                else:
                    if ti.static(continuum):
                        if skip == 2:
                            # a same-body pair at the start: the contact law counts from now
                            j = nbr[i, k]
                            u = pi[PROP_RADIUS] + prop[j][PROP_RADIUS] - (pos[j] - xi).norm()
                            h0 = hist[i, k]
                            h0[ti.static(history_width(laws) + 3)] = ti.max(u, 0.0)
                            hist[i, k] = h0
                    shaped = False
                    if ti.static(shapes and dim == 2):
                        shaped = ishaped or shp[nbr[i, k]][2] > 0.0
                    if ti.static(shapes and dim == 3):
                        # by the kinds of the two: a polyhedron, an ellipsoid, two spheres
                        done = False
                        if ti.static(shapes & SHAPES_POLY):
                            if ipoly or shp[nbr[i, k]][3] < 0.0:
                                fk, mk, mjk, dk = polyhedra3d.poly_pair(
                                    i, k, xi, vi, wi, pi[PROP_MASS], li, pos, vel, omega, prop,
                                    plaw, angle, shp, lawp, lawpair, nbr, hist, cn, cs, flags, dt,
                                    detail, laws, per, ptab, pint)
                                done = True
                        if ti.static(shapes & SHAPES_SMOOTH):
                            if not done and (ishaped or shp[nbr[i, k]][3] > 0.0):
                                fk, mk, mjk, dk = shaped3d.ellipsoid_pair(
                                    i, k, xi, vi, wi, pi[PROP_MASS], li, mati, shi, pos, vel,
                                    omega, prop, plaw, turn, shp, lawp, lawpair, nbr, hist, cn, cs,
                                    flags, dt, detail, laws, per)
                                done = True
                        if not done:
                            fk, mk, mjk, dk = pair_contact(
                                i, k, xi, vi, wi, pi[PROP_RADIUS], pi[PROP_MASS], li, pos, vel,
                                omega, prop, plaw, lawp, lawpair, nbr, hist, cn, cs, dt, detail,
                                laws, per, ranged)
                    elif ti.static(shapes):
                        if shaped:
                            fk, mk, mjk, dk = shaped_pair(
                                i, k, xi, vi, wi, pi[PROP_MASS], li, cthi, sthi, shi,
                                pi[PROP_RADIUS], pos, vel, omega, prop, plaw, turn, shp, lawp,
                                lawpair, nbr, hist, cn, cs, flags, dt, detail, laws, per)
                        else:
                            fk, mk, mjk, dk = pair_contact(
                                i, k, xi, vi, wi, pi[PROP_RADIUS], pi[PROP_MASS], li, pos, vel,
                                omega, prop, plaw, lawp, lawpair, nbr, hist, cn, cs, dt, detail,
                                laws, per, ranged)
                    else:
                        fk, mk, mjk, dk = pair_contact(
                            i, k, xi, vi, wi, pi[PROP_RADIUS], pi[PROP_MASS], li, pos, vel, omega,
                            prop, plaw, lawp, lawpair, nbr, hist, cn, cs, dt, detail, laws, per,
                            ranged)
                f += fk
                tq += mk
                diss += dk
                if ti.static(serial):
                    if skip != 1:
                        j = nbr[i, k]
                        facc[j] += pack(-fk, mjk, dim)
                elif ti.static(chunk):
                    if skip != 1:
                        j = nbr[i, k]
                        if j < end:
                            facc[j] = facc[j] + pack(-fk, mjk, dim)
                        elif not detail:
                            cf[i, k] = pack(fk, mjk, dim)
                if detail:
                    cf[i, k] = pack(fk, mjk, dim)
                elif ti.static(not serial and not chunk):
                    if skip != 1:      # (a carried pair's share is not read, see 2.)
                        cf[i, k] = pack(fk, mjk, dim)
            fw = vec_zero(dim)
            mw = spin_zero(dim)
            dw = 0.0
            work = 0.0
            if ti.static(dim == 2):
                fw, mw, dw, work = wall_contacts(i, pos, vel, omega, prop, wall, wpart, row,
                                                 lawp, wid, whist, wcn, wcf, wcs, dt, laws, angle,
                                                 shp, flags, shapes, ranged)
            else:
                # (computed in the wall loop above)
                if ti.static(prims) or wid[i, 0] >= 0:
                    wa = wacc[i]
                    fw = ti.Vector([wa[0], wa[1], wa[2]])
                    mw = ti.Vector([wa[3], wa[4], wa[5]])
                    dw = wa[6]
                    work = wa[7]
            own = pack(f + fw, tq + mw, dim)
            if ti.static(serial or chunk):
                facc[i] = facc[i] + own
            else:
                facc[i] = own
            if diss != 0.0 or dw != 0.0 or work != 0.0:
                eacc[i] = eacc[i] + ti.Vector([diss + dw, work])

    # 2. gather the partners' share, damp, integrate (leapfrog), skin check
    ti.loop_config(serialize=serial)
    for i in range(n):
        a = facc[i]
        f, tq = unpack(a, dim)
        # the sums start from zero at every step on either path (the one-thread path
        # adds into them), whichever path the next step takes
        facc[i] = a * 0.0
        if ti.static(not serial):
            lo_i = 0        # the first particle of i's chunk
            if ti.static(chunk):
                lo_i = i // csz * csz
            for r in range(rcnt[i]):
                flat = rev[i, r]
                j = flat >> bits
                k = flat & (cap - 1)
                carried = False
                if ti.static(continuum):
                    carried = cskip[j, k] == 1
                if ti.static(chunk):
                    carried = carried or j >= lo_i     # added in 1.
                if not carried:
                    cfk, cmk = unpack(cf[j, k], dim)
                    f -= cfk
                    tq += cmk
        if ti.static(bonds):
            fb, mb = unpack(bforce[i], dim)
            f += fb
            tq += mb
        fx_cont = vec_zero(dim)
        if ti.static(continuum):
            fx_cont = xforce[i]
        fc = f
        f += fx_cont
        tc = tq
        fa = vec_zero(dim)
        ma = spin_zero(dim)
        if ti.static(loads):
            fa, ma = unpack(fext[i], dim)
            f += fa
            tq += ma
        m = prop[i][PROP_MASS]
        inertia = prop[i][PROP_INERTIA]
        v0 = vel[i]
        w0 = omega[i]
        ftot = f + m * g
        # local and global damping, central differences (tdem.integrate); without
        # damping the same numbers by the plain leapfrog
        v1 = v0 + ftot / m * dt
        w1 = w0 + tq / inertia * dt
        fd = vec_zero(dim)
        md = spin_zero(dim)
        if damped:
            v1, fd = damped_leapfrog(v0, ftot, m, alpha, alpha_l, dt)
            w1, md = damped_leapfrog(w0, tq, inertia, alpha, alpha_l, dt)
        q1 = angle[i]
        ell = False
        lmid = w0 * 0.0
        lfree = w0 * 0.0
        if ti.static(shapes and dim == 3):
            # an ellipsoid: the angular momentum at the half steps (world frame),
            # the orientation by the splitting of tdem.integrate.free_rotation
            si = shp[i]
            if si[3] != 0.0:
                ell = True
                inertia3 = polyhedra3d.principal_inertia(si, m)
                l1, ml = damped_leapfrog(lmom[i], tq, 1.0, alpha, alpha_l, dt)
                md = ml
                lmid = 0.5 * (lmom[i] + l1)
                lfree = l1
                q1, w1 = free_rotation(q1, l1, inertia3, shaped3d.el.rotation(q1), dt)
                lmom[i] = l1
        vfree = v1
        wfree = w1
        fx = fix[i]
        if fx != 0:
            vf, wf = unpack(vfix[i], dim)
            if fx & FIX_VX:
                v1[0] = vf[0]
            if fx & FIX_VY:
                v1[1] = vf[1]
            if ti.static(dim == 3):
                if fx & FIX_VZ:
                    v1[2] = vf[2]
            if fx & FIX_W:
                w1 = wf
                if ti.static(shapes and dim == 3):
                    if ell:
                        q1 = turn_quaternion(angle[i], wf * dt)
                        rot = shaped3d.el.rotation(q1)
                        lmom[i] = rot @ (polyhedra3d.principal_inertia(shp[i], m)
                                         * (rot.transpose() @ wf))
        # the work of each force over the step, F·(v_{n-1/2} + v_{n+1/2})/2 Δt: with
        # the leapfrog's m(v_{n+1/2} − v_{n−1/2}) = ΣF Δt their sum is the change of
        # ½ m v² at the half steps, exactly (round-off apart). The damping force is
        # F_d − α m (v_{n−1/2} + v_free)/2 (tdem.integrate), the constraint's impulse
        # m (v_{n+1/2} − v_free); for the rotation of an ellipsoid or a polyhedron the
        # same in its angular momentum, M_d − α (L_{n−1/2} + L_free)/2 and L_{n+1/2} −
        # L_free. Contact dissipation and the walls' work were booked in 1.
        vm = 0.5 * (v0 + v1)
        wm = 0.5 * (w0 + w1)
        x0 = pos[i]
        # (the columns that stay zero, as damping and fixes in a model without them,
        # are not written)
        ework[i][0] += (fc.dot(vm) + spin_dot(tc, wm, dim)) * dt
        ework[i][2] += m * g.dot(vm) * dt
        if ti.static(continuum):
            ework[i][1] += fx_cont.dot(vm) * dt
        if ti.static(loads):
            ework[i][5] += (fa.dot(vm) + spin_dot(ma, wm, dim)) * dt
        if damped or fx != 0:
            m_damp = md - alpha * inertia * 0.5 * (w0 + wfree)
            j_fix = inertia * (w1 - wfree)
            if ti.static(shapes and dim == 3):
                if ell:
                    m_damp = md - alpha * lmid
                    j_fix = lmom[i] - lfree
            w_damp = ((fd - alpha * m * 0.5 * (v0 + vfree)).dot(vm)
                      + spin_dot(m_damp, wm, dim)) * dt
            w_fix = m * (v1 - vfree).dot(vm) + spin_dot(j_fix, wm, dim)
            ework[i][3] += w_damp
            ework[i][4] += w_fix
            eacc[i] += ti.Vector([-w_damp, w_fix])
        if detail:
            force[i] = fc + fx_cont
            torque[i] = tc
            rot_ke = 0.5 * inertia * spin_dot(wm, wm, dim)
            if ell:
                rot_ke = 0.5 * spin_dot(wm, lmid, dim)
            estate[i] = ti.Vector([0.5 * m * vm.dot(vm) + rot_ke, -m * g.dot(x0)])
        x1 = x0 + v1 * dt
        # periodic axes: back into [x0, x0 + L), with the references the displacement
        # and the skin check count from
        shift = vec_zero(dim)
        moved = False
        for ax in ti.static(range(dim)):
            if per[2 * ax + 1] > 0.0:
                shift[ax] = per[2 * ax + 1] * ti.floor((x1[ax] - per[2 * ax]) / per[2 * ax + 1])
                if shift[ax] != 0.0:
                    moved = True
        if moved:
            x1 -= shift
            xref[i] -= shift
            pos0[i] -= shift
        vel[i] = v1
        omega[i] = w1
        pos[i] = x1
        if ti.static(dim == 2):
            angle[i] += w1 * dt
        elif ell:
            angle[i] = q1
        else:
            angle[i] = turn_quaternion(angle[i], w1 * dt)
        dx = x1 - xref[i]
        if dx.dot(dx) > half_skin2:
            flags[F_REBUILD] = 1
        # a step longer than the radius: said once by the host (Runner._status)
        r_i = prop[i][PROP_RADIUS]
        if v1.dot(v1) * dt * dt > r_i * r_i:
            ti.atomic_max(flags[F_FAST], i + 1)
        # forces that would move the particle more than PUSH_LIMIT radii (turn it more
        # than PUSH_LIMIT rad) in one step from rest: unstable (check_stability)
        fp = fc + fx_cont
        if (fp.norm() * dt * dt > PUSH_LIMIT * r_i * m
                or ti.sqrt(spin_dot(tc, tc, dim)) * dt * dt > PUSH_LIMIT * inertia):
            ti.atomic_max(flags[F_PUSH], i + 1)

    # 3. each wall's force: its chunks' partial sums added in their order (a fixed
    #    order, whichever thread ran a chunk). Then the walls move: servo walls first
    #    set their speed from the force they received, then rotation about their
    #    centre and translation; a wall that has moved half the skin since the lists
    #    were built asks for a rebuild
    rows = 1
    if ti.static(chunk):
        rows = (n + csz - 1) // csz
    ti.loop_config(serialize=serial or chunk)
    for w in range(nw):
        s = wpart[0, w]
        wpart[0, w] = s * 0.0
        for r in range(1, rows):
            s += wpart[r, w]
            wpart[r, w] = s * 0.0
        wforce[w] = s
    if ti.static(dim == 3):
        # (on one thread in the same serial task: a parallel loop over a few walls
        # costs more to launch than to run)
        ti.loop_config(serialize=serial)
        for w in range(nw):
            move_triangle(wall, w, dt, simp[P_SKIN], flags)
    if ti.static(prims):
        # the primitives' forces and motion (a few: one thread)
        ti.loop_config(serialize=True)
        for _ in range(1):
            primitives.finish_step(prim, pforce, ppart, rows, dt)
    if ti.static(dim == 2):
        ti.loop_config(serialize=True)
        for w in range(nw):
            if wall[w, W_SERVO_K] > 0.0:
                wall[w, W_VX], wall[w, W_VY] = servo_velocity(wall, wforce, w, dt)
            c = ti.Vector([wall[w, W_CX], wall[w, W_CY]])
            v = ti.Vector([wall[w, W_VX], wall[w, W_VY]])
            ang = wall[w, W_OMEGA] * dt
            arm = ti.max((ti.Vector([wall[w, W_X0], wall[w, W_Y0]]) - c).norm(),
                         (ti.Vector([wall[w, W_X1], wall[w, W_Y1]]) - c).norm())
            wall[w, W_DISP] += (v.norm() + ti.abs(wall[w, W_OMEGA]) * arm) * dt
            if wall[w, W_DISP] > 0.5 * simp[P_SKIN]:
                flags[F_REBUILD] = 1
            rot = ti.Matrix([[ti.cos(ang), -ti.sin(ang)], [ti.sin(ang), ti.cos(ang)]])
            p0 = c + v * dt + rot @ (ti.Vector([wall[w, W_X0], wall[w, W_Y0]]) - c)
            p1 = c + v * dt + rot @ (ti.Vector([wall[w, W_X1], wall[w, W_Y1]]) - c)
            wall[w, W_X0] = p0[0]
            wall[w, W_Y0] = p0[1]
            wall[w, W_X1] = p1[0]
            wall[w, W_Y1] = p1[1]
            wall[w, W_CX] = c[0] + v[0] * dt
            wall[w, W_CY] = c[1] + v[1] * dt


@ti.func
def turn_quaternion(q, phi):
    """The unit quaternion q (w, x, y, z) turned by the rotation vector phi (world
    frame): exp(phi/2) ⊗ q, renormalised."""
    a2 = phi.dot(phi)
    c = 1.0
    s = 0.5
    if a2 < 1e-6:
        # a step's turn is small: cos(a/2) and sin(a/2)/a by their series, exact to
        # round-off for a < 1e-3 (the next terms are below 4e-23 and 2e-24)
        c = 1.0 - a2 * (0.125 - a2 / 384.0)
        s = 0.5 - a2 * (1.0 / 48.0 - a2 / 3840.0)
    else:
        a = ti.sqrt(a2)
        c = ti.cos(0.5 * a)
        s = ti.sin(0.5 * a) / a
    r = _quat_mul(ti.Vector([c, s * phi[0], s * phi[1], s * phi[2]]), q)
    # |r|² = 1 + e with e at round-off (q and dq are unit): 1/|r| = 1 − e/2 to
    # round-off; a larger e (a quaternion given off unit) is divided out exactly
    e = r.dot(r) - 1.0
    if ti.abs(e) < 1e-8:
        r *= 1.0 - 0.5 * e
    else:
        r /= ti.sqrt(1.0 + e)
    return r


@ti.func
def rotation_matrix(phi):
    """The rotation by the vector phi (Rodrigues)."""
    a = phi.norm()
    m = ti.Matrix.identity(float, 3)
    if a > 0.0:
        k = phi / a
        kx = ti.Matrix([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
        m += ti.sin(a) * kx + (1.0 - ti.cos(a)) * kx @ kx
    return m


@ti.func
def move_triangle(wall: ti.template(), w, dt, skin, flags: ti.template()):
    """3D: mesh triangle w turns about its mesh's centre by ω Δt and translates by
    v Δt; one that has moved half the skin since the lists were built asks for a
    rebuild."""
    if True:
        v = tri_vec(wall, w, T_VX)
        om = tri_vec(wall, w, T_WX)
        c = tri_vec(wall, w, T_OX)
        if v.dot(v) > 0.0 or om.dot(om) > 0.0:
            rot = rotation_matrix(om * dt)
            arm = 0.0
            for corner in ti.static((T_AX, T_BX, T_CX)):
                p = tri_vec(wall, w, corner)
                arm = ti.max(arm, (p - c).norm())
                p = c + v * dt + rot @ (p - c)
                for k in ti.static(range(3)):
                    wall[w, corner + k] = p[k]
            for k in ti.static(range(3)):
                wall[w, T_OX + k] = c[k] + v[k] * dt
            wall[w, T_DISP] += (v.norm() + om.norm() * arm) * dt
            if wall[w, T_DISP] > 0.5 * skin:
                flags[F_REBUILD] = 1


# a mesh's servo control (tdem.handles.Mesh.servo): a row per servo-controlled mesh
(MS_FIRST, MS_COUNT, MS_K, MS_F, MS_DX, MS_DY, MS_DZ, MS_ALPHA, MS_VMAX) = range(9)
MS_WIDTH = 9


@cached
@ti.kernel
def servo_meshes(wall: ti.types.ndarray(), wforce: ti.types.ndarray(),
                 mservo: ti.types.ndarray(), dt: ti.f64):
    """3D: the velocity of each servo-controlled mesh for the next step, from the force
    its triangles received in this one, as :func:`servo_velocity` does for a segment:
    relaxation × (target − measured)/(contacts × k) per step along its direction d,
    the measured force the compression it receives along −d, |v| <= the speed limit.
    (One thread: a few meshes; launched after the step only in models with a servo.)"""
    ti.loop_config(serialize=True)
    for m in range(mservo.shape[0]):
        first = ti.cast(mservo[m, MS_FIRST], ti.i32)
        count = ti.cast(mservo[m, MS_COUNT], ti.i32)
        d = ti.Vector([mservo[m, MS_DX], mservo[m, MS_DY], mservo[m, MS_DZ]])
        f = ti.Vector([0.0, 0.0, 0.0])
        contacts = 0.0
        for w in range(first, first + count):
            fw = wforce[w]
            f += ti.Vector([fw[0], fw[1], fw[2]])
            contacts += fw[6]
        measured = -f.dot(d)
        k = mservo[m, MS_K] * ti.max(contacts, 1.0)
        v = mservo[m, MS_ALPHA] * (mservo[m, MS_F] - measured) / (k * dt)
        vmax = mservo[m, MS_VMAX]
        v = ti.math.clamp(v, -vmax, vmax)
        for w in range(first, first + count):
            for c in ti.static(range(3)):
                wall[w, T_VX + c] = v * d[c]


@cached
@ti.kernel
def set_motion(wall: ti.types.ndarray(), first: ti.i32, count: ti.i32, set_v: ti.i32,
               set_w: ti.i32, vx: ti.f64, vy: ti.f64, vz: ti.f64, wx: ti.f64, wy: ti.f64,
               wz: ti.f64, dim: ti.template()):
    """The velocity and angular velocity of the wall rows ``first`` .. ``first + count``
    (a segment in 2D: (vx, vy) and wz; a mesh's triangles in 3D) for the next step,
    from a motion given as functions of time (``Wall.motion``, ``Mesh.motion``); the
    step moves the rows by them, as it does constant ones."""
    for w in range(first, first + count):
        if ti.static(dim == 2):
            if set_v:
                wall[w, W_VX] = vx
                wall[w, W_VY] = vy
            if set_w:
                wall[w, W_OMEGA] = wz
        else:
            if set_v:
                wall[w, T_VX] = vx
                wall[w, T_VX + 1] = vy
                wall[w, T_VX + 2] = vz
            if set_w:
                wall[w, T_WX] = wx
                wall[w, T_WX + 1] = wy
                wall[w, T_WX + 2] = wz


@ti.kernel
def largest_overlap_ratio(cs: ti.types.ndarray(), nbr: ti.types.ndarray(),
                          ncnt: ti.types.ndarray(), wcs: ti.types.ndarray(),
                          wid: ti.types.ndarray(), prop: ti.types.ndarray()) -> ti.f64:
    """The largest overlap over the smaller radius among the contacts of the last
    recording step (the overlaps ``cs`` and ``wcs`` hold; a wall counts with the
    particle's radius): read after a run by Runner._warn_stiffened. One thread, a
    fixed order."""
    out = 0.0
    ti.loop_config(serialize=True)
    for i in range(nbr.shape[0]):
        ri = prop[i][PROP_RADIUS]
        for k in range(ncnt[i]):
            u = cs[i, k][2]
            if u > 0.0:
                out = ti.max(out, u / ti.min(ri, prop[nbr[i, k]][PROP_RADIUS]))
        for k in range(wid.shape[1]):
            if wid[i, k] >= 0 and wcs[i, k][2] > 0.0:
                out = ti.max(out, wcs[i, k][2] / ri)
    return out


@ti.kernel
def check_stability(pos: ti.types.ndarray(), vel: ti.types.ndarray(),
                    omega: ti.types.ndarray(), prop: ti.types.ndarray(),
                    nbr: ti.types.ndarray(), ncnt: ti.types.ndarray(), cs: ti.types.ndarray(),
                    flags: ti.types.ndarray(), dt: ti.f64, overlap_limit: ti.f64,
                    dim: ti.template()):
    """The status of the last step (its forces and overlaps are those of a recording
    step: the last of a segment, every step of a replay).

    flags[F_BAD] = smallest index of an unstable particle: a non-finite state; or,
    with ``overlap_limit`` > 0, a pair overlapping by more than that fraction of the
    smaller radius (the smaller one's centre inside the other: past what a contact
    holds; the owner of the pair's slot is named); or
    the particle the steps since the last check found pushed too hard (flags[F_PUSH],
    then cleared): contact and element forces that would move it more than
    PUSH_LIMIT × its radius in one step from rest, |F| Δt²/m > R (or turn it by more
    than PUSH_LIMIT rad, |M| Δt²/I > 1). A stable integration of a contact never does
    (its force is k δ with k Δt²/m < 4 and δ a fraction of R); a step far above the
    stable one makes it grow without bound.

    A particle moving more than its radius in one step is not unstable (free flight,
    ejecta, a jet): the step raises flags[F_FAST] for it, and the host says so once."""
    n = pos.shape[0]
    flags[F_BAD] = n
    for i in range(n):
        x = pos[i]
        v = vel[i]
        w = omega[i]
        s = x.sum() + v.sum()
        nw = 0
        if ti.static(dim == 2):
            s += w
            nw = non_finite(w)
        else:
            s += w.sum()
            nw = any_non_finite(w)
        # a bit test: under fast math, `s != s` is folded to False (tdem.finite)
        bad = any_non_finite(x) + any_non_finite(v) + nw > 0 or ti.abs(s) > 1e300
        ri = prop[i][PROP_RADIUS]
        if not bad and overlap_limit > 0.0:
            for k in range(ncnt[i]):
                if cs[i, k][2] > overlap_limit * ti.min(ri, prop[nbr[i, k]][PROP_RADIUS]):
                    bad = True
        if bad:
            ti.atomic_min(flags[F_BAD], i)
    ti.loop_config(serialize=True)
    for _ in range(1):
        if flags[F_PUSH] > 0:
            ti.atomic_min(flags[F_BAD], flags[F_PUSH] - 1)
        flags[F_PUSH] = 0


@ti.kernel
def elastic_energy_sum(pos: ti.types.ndarray(), prop: ti.types.ndarray(),
                       plaw: ti.types.ndarray(), nbr: ti.types.ndarray(),
                       ncnt: ti.types.ndarray(), hist: ti.types.ndarray(),
                       cs: ti.types.ndarray(), wall: ti.types.ndarray(),
                       wid: ti.types.ndarray(), whist: ti.types.ndarray(),
                       wcs: ti.types.ndarray(), lawp: ti.types.ndarray(),
                       lawpair: ti.types.ndarray(), laws: ti.template(),
                       dim: ti.template()) -> ti.f64:
    """Energy stored in the springs of every contact (law and rolling)."""
    T = ti.static(tangent_dim(dim))
    R = ti.static(history_width(laws, T))
    ST = ti.static(R + 5)            # a shaped contact's state: its R* while touching
    WST = ti.static(R + 3)
    total = 0.0
    for i in range(pos.shape[0]):
        ri = prop[i][PROP_RADIUS]
        for k in range(ncnt[i]):
            u = cs[i, k][2]
            j = nbr[i, k]
            L = lawpair[plaw[i], plaw[j]]
            # (a law with a range stores energy across a gap too)
            if u > 0.0 or u > -lawp[L, COL_REACH]:
                rj = prop[j][PROP_RADIUS]
                h = hist[i, k]
                reff = ri * rj / (ri + rj)
                if ti.static(dim == 2):
                    if h[ST] > 0.0:
                        reff = h[ST]
                elif ti.static(h.n == R + 4):
                    if h[R + 3] > 0.0:       # an ellipsoid pair's R* (tdem.shaped3d)
                        reff = h[R + 3]
                total += law_energy(laws, lawp, L, u, reff, h, T)
                if u > 0.0:           # (the rolling spring acts while they touch)
                    if ti.static(dim == 2):
                        kn = law_stiffness(laws, lawp, L, u, reff)
                        total += rolling_energy(lawp, L, kn, h[R], 2.0 * ri * rj / (ri + rj))
                    elif ti.static(h.n >= R + 7):
                        kn = law_stiffness(laws, lawp, L, u, reff)
                        total += rolling_energy_3d(lawp, L, kn, get_columns(h, R, 3),
                                                   2.0 * ri * rj / (ri + rj))
        for s in range(wid.shape[1]):
            w = wid[i, s]
            if w >= 0:
                u = wcs[i, s][2]
                L = ti.cast(wall[w, ti.static(W_LAW if dim == 2 else T_LAW)], ti.i32)
                if u > 0.0 or u > -lawp[L, COL_REACH]:
                    h = whist[i, s]
                    reff = ri
                    if ti.static(dim == 2):
                        if h[WST] > 0.0:
                            reff = h[WST]
                    elif ti.static(h.n == R + 1):
                        if h[R] > 0.0:           # an ellipsoid's Hertz radius
                            reff = h[R]
                    total += law_energy(laws, lawp, L, u, reff, h, T)
                    if u > 0.0:
                        if ti.static(dim == 2):
                            kn = law_stiffness(laws, lawp, L, u, reff)
                            total += rolling_energy(lawp, L, kn, h[R], 2.0 * ri)
                        elif ti.static(h.n >= R + 7):
                            kn = law_stiffness(laws, lawp, L, u, reff)
                            total += rolling_energy_3d(lawp, L, kn, get_columns(h, R, 3),
                                                       2.0 * ri)
    return total


@ti.kernel
def particle_stress(prop: ti.types.ndarray(), angle: ti.types.ndarray(),
                    shp: ti.types.ndarray(), nbr: ti.types.ndarray(),
                    ncnt: ti.types.ndarray(), cn: ti.types.ndarray(), cf: ti.types.ndarray(),
                    cs: ti.types.ndarray(), rev: ti.types.ndarray(), rcnt: ti.types.ndarray(),
                    wid: ti.types.ndarray(), wcn: ti.types.ndarray(), wcf: ti.types.ndarray(),
                    wcs: ti.types.ndarray(), out: ti.types.ndarray()):
    """Average stress of each particle, σ = (1/A) Σ_c sym(r_c ⊗ f_c), tension-positive,
    r_c from the centre to the contact point (for a disc (R − u/2) n; for a shape its
    support point towards the contact less u/2 along n), A the disc's or shape's area."""
    cap = nbr.shape[1]
    bits = slot_bits(cap)
    for i in range(prop.shape[0]):
        ri = prop[i][PROP_RADIUS]
        si = shp[i]
        shaped = si[2] > 0.0
        ci = ti.cos(angle[i])
        sni = ti.sin(angle[i])
        area = ti.math.pi * ri * ri
        if shaped:
            area = si[3]
        s = ti.Matrix([[0.0, 0.0], [0.0, 0.0]])
        for k in range(ncnt[i]):
            u = cs[i, k][2]
            if u > 0.0 or cs[i, k][0] != 0.0:      # (a law with a range: across a gap)
                c = cf[i, k]
                n = cn[i, k]
                s += _arm(shaped, si, ci, sni, ri, n, u).outer_product(ti.Vector([c[0], c[1]]))
        for r in range(rcnt[i]):
            flat = rev[i, r]
            j = flat >> bits
            k = flat & (cap - 1)
            u = cs[j, k][2]
            if u > 0.0 or cs[j, k][0] != 0.0:
                c = cf[j, k]
                # the normal from i is −n, the force on i −f_owner
                s -= _arm(shaped, si, ci, sni, ri, -cn[j, k], u).outer_product(
                    ti.Vector([c[0], c[1]]))
        for q in range(wid.shape[1]):
            if wid[i, q] >= 0 and (wcs[i, q][2] > 0.0 or wcs[i, q][0] != 0.0):
                u = wcs[i, q][2]
                c = wcf[i, q]
                s += _arm(shaped, si, ci, sni, ri, wcn[i, q], u).outer_product(
                    ti.Vector([c[0], c[1]]))
        s = 0.5 * (s + s.transpose()) / area
        out[i, 0] = s[0, 0]
        out[i, 1] = s[1, 1]
        out[i, 2] = s[0, 1]


@ti.func
def _arm(shaped, si, ci, sni, ri, n, u):
    """From a particle's centre to its contact of normal n (outward) and overlap u."""
    arm = (ri - 0.5 * u) * n
    if shaped:
        h, p = se.support(ti.Vector([si[0], si[1], si[2]]), ci, sni, n)
        arm = p - 0.5 * u * n
    return arm
