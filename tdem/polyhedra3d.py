"""Contacts of convex polyhedra (3D, Chen's polyhedral DEM) inside the step kernel.

The same stages as a sphere contact (:func:`tdem.step.pair_contact`): the geometry of
the pair, the kinematics at the contact point, the law, the force and moments.

- Two polyhedra: their overlap polyhedron (:func:`physics.geometry.polyhedron.overlap`),
  its volume V, centroid (the contact point) and area vectors: the normal
  n = (S_A − S_B)/|S_A − S_B| from i to j and the projected area |S|.
- A polyhedron and a sphere: the sphere's centre against the polyhedron (inside: the
  nearest face plane; outside: the nearest point of its surface triangles), the depth u
  and normal of that point; V and |S| are those of the spherical cap of height u cut by
  the tangent plane, π u²(3r − u)/3 and π(2ru − u²) (exact on a face).
- A polyhedron and a mesh triangle: the part of the polyhedron behind the triangle, in
  the triangle's prism, with the triangle's normal and the area of the cut on its
  plane (forces of several triangles add up: the volume is additive).

The law (:class:`physics.volume_contact.VolumeContact`) is given the overlap as the
length u = V/l_c², its rate |S| v_n/l_c² (dV/dt/l_c²) and l_c in place of the radius;
the normal dashpot's dissipation is booked on the true approach velocity v_n.
A pair's history keeps, after the law's columns, the contact point (from x_i, for
output) and l_c (the elastic energy reads it); a wall contact keeps l_c after the law's
columns.
"""
import taichi as ti

from physics.contact_law import history_width, law_force_3d, tangent_dim, zero_history
from physics.geometry import polyhedron as ph
from physics.geometry import sphere_triangle
from physics.geometry.ellipsoid import rotation
from physics.geometry.frame import moment, tangent_part
from physics.polyhedron import PI_TRIS, PT_LENGTH, PT_NE, PT_NF, PT_NT, PT_PLANES, PT_VERTS

from .neighbors import (F_NONCONV, T_AX, T_BX, T_CX, T_LAW, T_OX, T_SX, T_VX, T_WX, image,
                        tri_vec)
from .state import PROP_MASS, PROP_RADIUS

PI = 3.141592653589793


@ti.func
def shape_id(s):
    """Index in the shape tables of a polyhedron's ``shp`` row (its 4th column −(id + 1))."""
    return ti.cast(-s[3], ti.i32) - 1


@ti.func
def principal_inertia(s, m):
    """Principal moments of inertia of a non-spherical particle of mass m: an ellipsoid
    (``shp`` (a, b, c, 1)) or a polyhedron (``shp`` (I₁/m, I₂/m, I₃/m, −(id + 1)))."""
    out = ti.Vector([s[0], s[1], s[2]]) * m
    if s[3] > 0.0:
        a2 = s[0] * s[0]
        b2 = s[1] * s[1]
        c2 = s[2] * s[2]
        out = ti.Vector([b2 + c2, a2 + c2, a2 + b2]) * (0.2 * m)
    return out


@ti.func
def _length(ptab: ti.template(), s, r):
    """Characteristic length of a particle: its polyhedron's V^(1/3), a sphere's
    (4/3 π r³)^(1/3)."""
    out = r * 1.6119919540164696
    if s[3] < 0.0:
        out = ptab[shape_id(s), PT_LENGTH]
    return out


@ti.func
def sphere_polyhedron(ptab: ti.template(), pint: ti.template(), sid, rot, xp, c, r):
    """A sphere (centre c, radius r) against polyhedron sid at xp turned by rot:
    (depth u, unit normal from the polyhedron to the sphere, contact point)."""
    nf = ti.cast(ptab[sid, PT_NF], ti.i32)
    best = -1e300
    nbest = ti.Vector([0.0, 0.0, 1.0])
    for f in range(nf):
        b = PT_PLANES + 4 * f
        n = rot @ ti.Vector([ptab[sid, b], ptab[sid, b + 1], ptab[sid, b + 2]])
        sd = n.dot(c - xp) - ptab[sid, b + 3]
        if sd > best:
            best = sd
            nbest = n
    depth = r - best
    n = nbest
    q = c - best * nbest
    if best > 0.0:
        # outside: the nearest point of the surface
        nt = ti.cast(ptab[sid, PT_NT], ti.i32)
        d2 = 1e300
        for t in range(nt):
            b = PI_TRIS + 3 * t
            p3 = ti.Matrix.zero(float, 3, 3)
            for k in ti.static(range(3)):
                v = pint[sid, b + k]
                vb = PT_VERTS + 3 * v
                w = xp + rot @ ti.Vector([ptab[sid, vb], ptab[sid, vb + 1], ptab[sid, vb + 2]])
                for m in ti.static(range(3)):
                    p3[k, m] = w[m]
            qt, feat = sphere_triangle.closest_point(
                c, ti.Vector([p3[0, 0], p3[0, 1], p3[0, 2]]),
                ti.Vector([p3[1, 0], p3[1, 1], p3[1, 2]]),
                ti.Vector([p3[2, 0], p3[2, 1], p3[2, 2]]))
            e2 = (c - qt).norm_sqr()
            if e2 < d2:
                d2 = e2
                q = qt
        dist = ti.sqrt(d2)
        depth = r - dist
        if dist > 0.0:
            n = (c - q) / dist
    return depth, n, q


@ti.func
def _cap(u, r):
    """(volume, base area) of the cap of height u of a sphere of radius r."""
    h = ti.min(u, 2.0 * r)
    vol = PI * h * h * (3.0 * r - h) / 3.0
    area = PI * r * r
    if h < r:
        area = PI * (2.0 * r * h - h * h)
    return vol, area


@ti.func
def poly_pair(i, k, xi, vi, wi, mi, li, pos: ti.template(), vel: ti.template(),
              omega: ti.template(), prop: ti.template(), plaw: ti.template(),
              angle: ti.template(), shp: ti.template(), lawp: ti.template(),
              lawpair: ti.template(), nbr: ti.template(), hist: ti.template(),
              cn: ti.template(), cs: ti.template(), flags: ti.template(), dt,
              detail, laws: ti.template(), per, ptab: ti.template(),
              pint: ti.template()):
    """Contact in slot k of particle i (the owner) when either body is a polyhedron;
    returns (f_i, M_i, M_j, dissipated energy), as :func:`tdem.step.pair_contact`."""
    R = ti.static(history_width(laws, tangent_dim(3)))
    ST = ti.static(R + 3)
    j = nbr[i, k]
    pj = prop[j]
    si = shp[i]
    sj = shp[j]
    d = image(pos[j] - xi, per)
    vol = 0.0
    c = ti.Vector([0.0, 0.0, 0.0])
    n = ti.Vector([0.0, 0.0, 1.0])
    area = 0.0
    status = 0
    lc = 0.0
    if si[3] < 0.0 and sj[3] < 0.0:
        sa = shape_id(si)
        sb = shape_id(sj)
        nva, nfa, VA, PA = ph.load_poly(ptab, sa, rotation(angle[i]), ti.Vector([0.0, 0.0, 0.0]))
        nvb, nfb, VB, PB = ph.load_poly(ptab, sb, rotation(angle[j]), d)
        la = ptab[sa, PT_LENGTH]
        lb = ptab[sb, PT_LENGTH]
        lc = 2.0 * la * lb / (la + lb)
        vol, c, s_a, s_b, s_b0, status = ph.overlap(
            ph.POLY, sa, nva, nfa, ti.cast(ptab[sa, PT_NE], ti.i32), VA, PA,
            ph.POLY, sb, nvb, nfb, ti.cast(ptab[sb, PT_NE], ti.i32), VB, PB, pint,
            1e-9 * (la + lb))
        sv = 0.5 * (s_a - s_b)
        area = sv.norm()
        if area > 0.0:
            n = sv / area
        if status == 2:
            ti.atomic_add(flags[F_NONCONV], 1)
    else:
        # a sphere and a polyhedron
        ip = si[3] < 0.0
        sid = shape_id(si)
        rot = rotation(angle[i])
        xp = ti.Vector([0.0, 0.0, 0.0])
        xs = d
        r = pj[PROP_RADIUS]
        if not ip:
            sid = shape_id(sj)
            rot = rotation(angle[j])
            xp = d
            xs = ti.Vector([0.0, 0.0, 0.0])
            r = prop[i][PROP_RADIUS]
        u, nps, q = sphere_polyhedron(ptab, pint, sid, rot, xp, xs, r)
        if u > 0.0:
            vol, area = _cap(u, r)
            c = 0.5 * (q + xs - r * nps)
            n = nps
            if not ip:
                n = -nps
            status = 1
        lp = ptab[sid, PT_LENGTH]
        ls = r * 1.6119919540164696
        lc = 2.0 * lp * ls / (lp + ls)
    f = ti.Vector([0.0, 0.0, 0.0])
    m_on_i = ti.Vector([0.0, 0.0, 0.0])
    m_on_j = ti.Vector([0.0, 0.0, 0.0])
    diss = 0.0
    h = hist[i, k]
    if status != 0 and vol > 0.0:
        ri_arm = c
        rj_arm = c - d
        vrel = vel[j] + omega[j].cross(rj_arm) - vi - wi.cross(ri_arm)
        vn = vrel.dot(n)
        L = lawpair[li, plaw[j]]
        mj = pj[PROP_MASS]
        l2 = lc * lc
        u = vol / l2
        un = vn * area / l2
        fn_el, fn, ft, kn, cnd, d1, h = law_force_3d(
            laws, lawp, L, u, un, tangent_part(vrel, n), mi * mj / (mi + mj), lc, dt, h, n)
        f = -fn * n + ft
        m_on_i = moment(ri_arm, f)
        m_on_j = moment(rj_arm, -f)
        # the dashpot works on the approach velocity v_n, not on u̇
        diss = d1 + cnd * un * (vn - un) * dt
        for q in ti.static(range(3)):
            h[R + q] = c[q]              # the contact point from x_i (output)
        h[ST] = lc
        hist[i, k] = h
        if detail:
            cn[i, k] = n
            cs[i, k] = ti.Vector([fn, ft.norm(), u])
    else:
        if h[ST] != 0.0:
            hist[i, k] = zero_history(h)
        if detail:
            cs[i, k] = ti.Vector([0.0, 0.0, 0.0])
    return f, m_on_i, m_on_j, diss


@ti.func
def mesh_contacts(i, pos: ti.template(), vel: ti.template(), omega: ti.template(),
                  prop: ti.template(), angle: ti.template(), shp: ti.template(),
                  wall: ti.template(), wpart: ti.template(), row, lawp: ti.template(),
                  wid: ti.template(), whist: ti.template(), wcn: ti.template(),
                  wcf: ti.template(), wcs: ti.template(), flags: ti.template(), dt,
                  laws: ti.template(), ptab: ti.template(), pint: ti.template()):
    """Contacts of polyhedron i with its candidate mesh triangles: for each, the part of
    the polyhedron behind the triangle (its prism, as deep as the particle's bounding
    diameter), with the triangle's normal, the area of the cut, l_c = l_i. Returns
    (force, moment, dissipation, work of the walls) as :func:`tdem.step.mesh_contacts`."""
    RW = ti.static(history_width(laws, tangent_dim(3)))
    xi = pos[i]
    si = shp[i]
    sid = shape_id(si)
    ri = prop[i][PROP_RADIUS]
    mi = prop[i][PROP_MASS]
    lc = ptab[sid, PT_LENGTH]
    l2 = lc * lc
    nva, nfa, VA, PA = ph.load_poly(ptab, sid, rotation(angle[i]), xi)
    nea = ti.cast(ptab[sid, PT_NE], ti.i32)
    tol = 1e-9 * lc
    diss = 0.0
    work = 0.0
    ftot = ti.Vector([0.0, 0.0, 0.0])
    mtot = ti.Vector([0.0, 0.0, 0.0])
    for s in range(wid.shape[1]):
        w = wid[i, s]
        if w < 0:
            break
        a = tri_vec(wall, w, T_AX)
        b = tri_vec(wall, w, T_BX)
        c3 = tri_vec(wall, w, T_CX)
        nf = (b - a).cross(c3 - a).normalized()
        if (xi - a).dot(nf) < 0.0:
            nf = -nf
        vol = 0.0
        cen = xi
        cut = ti.Vector([0.0, 0.0, 0.0])
        status = 0
        if (xi - a).dot(nf) < ri:
            nvb, nfb, VB, PB = ph.load_prism(a, b, c3, nf, 2.0 * ri)
            vol, cen, s_a, s_b, cut, status = ph.overlap(
                ph.POLY, sid, nva, nfa, nea, VA, PA, ph.PRISM, 0, nvb, nfb, 9, VB, PB, pint, tol)
            if status == 2:
                ti.atomic_add(flags[F_NONCONV], 1)
        h = whist[i, s]
        if status != 0 and vol > 0.0:
            n = -nf
            arm = cen - xi
            o = tri_vec(wall, w, T_OX)
            vw = tri_vec(wall, w, T_VX) + tri_vec(wall, w, T_WX).cross(cen - o) \
                + tangent_part(tri_vec(wall, w, T_SX), n)       # a belt's surface
            vrel = vw - vel[i] - omega[i].cross(arm)
            vn = vrel.dot(n)
            u = vol / l2
            un = vn * cut.norm() / l2
            L = ti.cast(wall[w, T_LAW], ti.i32)
            fn_el, fn, ft, kn, cnd, d1, h = law_force_3d(
                laws, lawp, L, u, un, tangent_part(vrel, n), mi, lc, dt, h, n)
            f = -fn * n + ft
            mo = moment(arm, f)
            if ti.static(h.n > RW):
                h[RW] = lc
            whist[i, s] = h
            wcn[i, s] = n
            wcf[i, s] = ti.Vector([f[0], f[1], f[2], mo[0], mo[1], mo[2]])
            wcs[i, s] = ti.Vector([fn, ft.norm(), u])
            diss += d1 + cnd * un * (vn - un) * dt
            work += f.dot(vw) * dt
            ftot += f
            mtot += mo
            tw = moment(cen - o, -f)
            for q in ti.static(range(3)):
                ti.atomic_add(wpart[row, w][q], -f[q])
                ti.atomic_add(wpart[row, w][3 + q], tw[q])
            ti.atomic_add(wpart[row, w][6], 1.0)
        elif h.dot(h) != 0.0 or wcs[i, s][2] > 0.0:
            whist[i, s] = zero_history(h)
            wcf[i, s] = ti.Vector([0.0, 0.0, 0.0, 0.0, 0.0, 0.0])
            wcs[i, s] = ti.Vector([0.0, 0.0, 0.0])
    return ftot, mtot, diss, work
