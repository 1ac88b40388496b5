"""Contacts of ellipsoids (3D, Miyata et al. 2002, §2.4) inside the step kernel.

The same stages as a sphere contact (:func:`tdem.step.pair_contact`): geometry
(:mod:`physics.geometry.ellipsoid`: depth and normal by Newton on the unit sphere,
warm-started from the last step's normal; support points), kinematics at the contact
point, the law on the tangent-plane velocity (its shear spring turned onto the
tangent plane), and the force and moments returned for the accumulation. A sphere
that meets an ellipsoid takes part as the ellipsoid (r, r, r).

The contact point c is the midpoint of the two support points; the moment on each
body is (c − x) × f. The history of a pair holds, after the law's columns, the
normal of the last step (the warm start) and the pair's state (> 0: touching, with
the R* of its curvature radii; −1: apart, the normal columns holding the direction
that separated them, where the next step's search starts: a pair that stays apart
is then ruled out by one evaluation, not two or more). A contact whose iteration
stops at the cap is counted in the status word (``flags[F_NONCONV]``, reported after
the run).

Against a mesh triangle (:func:`mesh_contact`): a face contact is exact — the
ellipsoid's deepest point towards the triangle's plane, x − M N/h(N) with N the
plane's normal on the ellipsoid's side, at depth h(N) − (x − a)·N, when it lies over
the triangle; otherwise the triangle's point q nearest to the centre in the
ellipsoid's own metric (the nearest point to the origin once the ellipsoid is mapped
to the unit sphere) is an edge or vertex contact, with the ellipsoid's normal at
the radial projection of q, n = M⁻¹(q − x) normalised, and the depth
h(n) − (q − x)·n of q below the tangent plane of that normal (exact for a sphere and
to first order in the depth otherwise).
"""
import taichi as ti

from physics.contact_law import history_width, law_force_3d, tangent_dim, zero_history
from physics.geometry import ellipsoid as el
from physics.geometry import sphere_triangle
from physics.geometry.frame import moment, tangent_part

from .neighbors import F_NONCONV, image
from .state import PROP_MASS, PROP_RADIUS

MAXIT = 40          # iteration cap of the depth search


@ti.func
def axes_of(s, r):
    """The semi-axes of a particle: its ellipsoid's, or (r, r, r) for a sphere."""
    out = ti.Vector([r, r, r])
    if s[3] > 0.0:
        out = ti.Vector([s[0], s[1], s[2]])
    return out


@ti.func
def frame_of(s, q):
    """The rotation of a particle (the identity for a sphere)."""
    rot = ti.Matrix.identity(float, 3)
    if s[3] > 0.0:
        rot = el.rotation(q)
    return rot


@ti.func
def shape_row(s, q, r):
    """A particle's shape matrix R diag(a², b², c²) Rᵀ (r² I for a sphere), its nine
    entries row by row (the step keeps them per particle: ``turn``)."""
    m = el.shape_matrix(frame_of(s, q), axes_of(s, r))
    return ti.Vector([m[0, 0], m[0, 1], m[0, 2], m[1, 0], m[1, 1], m[1, 2],
                      m[2, 0], m[2, 1], m[2, 2]])


@ti.func
def shape_of_row(v):
    """The shape matrix kept by :func:`shape_row`."""
    return ti.Matrix([[v[0], v[1], v[2]], [v[3], v[4], v[5]], [v[6], v[7], v[8]]])


@ti.func
def ellipsoid_pair(i, k, xi, vi, wi, mi, li, mati, abci, pos: ti.template(),
                   vel: ti.template(), omega: ti.template(), prop: ti.template(),
                   plaw: ti.template(), turn: ti.template(), shp: ti.template(),
                   lawp: ti.template(), lawpair: ti.template(), nbr: ti.template(),
                   hist: ti.template(), cn: ti.template(), cs: ti.template(),
                   flags: ti.template(), dt, detail, laws: ti.template(),
                   per):
    """Contact in slot k of particle i (the owner) when either body is an ellipsoid
    (``mati``: i's shape matrix, ``abci`` its semi-axes; ``turn`` every particle's
    shape matrix, :func:`shape_row`); returns (f_i, M_i, M_j, dissipated energy), as
    :func:`tdem.step.pair_contact`."""
    R = ti.static(history_width(laws, tangent_dim(3)))
    NC = ti.static(R)          # the last normal: columns NC … NC + 2
    ST = ti.static(R + 3)      # the state
    j = nbr[i, k]
    pj = prop[j]
    sj = shp[j]
    abcj = axes_of(sj, pj[PROP_RADIUS])
    d = image(pos[j] - xi, per)
    dist = d.norm()
    h = hist[i, k]
    f = ti.Vector([0.0, 0.0, 0.0])
    m_on_i = ti.Vector([0.0, 0.0, 0.0])
    m_on_j = ti.Vector([0.0, 0.0, 0.0])
    diss = 0.0
    u = -1.0
    status = 1
    n = d * 0.0
    hi = 1.0
    hj = 1.0
    pi = d * 0.0        # the support points' offsets from x_i and x_j
    pjo = d * 0.0
    # bodies whose bounding spheres are apart cannot touch: no penetration search.
    # A step that records every pair's gap for output searches them too, but treats
    # their history as any other step does (a search's direction kept from an output
    # step would start the next search elsewhere: results would depend, at round-off,
    # on where a run was cut into segments)
    far = dist >= abci.max() + abcj.max()
    search = not far or detail != 0
    matj = ti.Matrix.zero(float, 3, 3)
    if search:
        matj = shape_of_row(turn[j])
        if not far:
            # nor can bodies whose extents along the line of centres do not meet
            # (h_i + h_j < |d| along d/|d|, h(u) = sqrt(uᵀ M u))
            far = ti.sqrt(d.dot(mati @ d)) + ti.sqrt(d.dot(matj @ d)) < dist * dist
            search = not far or detail != 0
    if search:
        n0 = ti.Vector([h[NC], h[NC + 1], h[NC + 2]])
        if h[ST] == 0.0 or n0.dot(d) <= 0.0:
            n0 = d / ti.max(dist, 1e-300)
        tol = 1e-10 * (abci.max() + abcj.max())
        u, n, status, hi, hj, pi, pjo = el.penetration(mati, matj, d, n0, tol, MAXIT)
        if status == 2 and not far:
            ti.atomic_add(flags[F_NONCONV], 1)
    if status != 1 and u > 0.0 and not far:
        c = 0.5 * (pi + d - pjo)            # from x_i; j's support point is x_j − M_j n/h_j
        ri_arm = c
        rj_arm = c - d
        vrel = vel[j] + omega[j].cross(rj_arm) - vi - wi.cross(ri_arm)
        vn = vrel.dot(n)
        L = lawpair[li, plaw[j]]
        mj = pj[PROP_MASS]
        rgi = el.hertz_radius(abci, hi)
        rgj = el.hertz_radius(abcj, hj)
        reff = rgi * rgj / (rgi + rgj)
        fn_el, fn, ft, kn, cnd, d1, h = law_force_3d(
            laws, lawp, L, u, vn, tangent_part(vrel, n), mi * mj / (mi + mj), reff, dt, h, n)
        f = -fn * n + ft
        m_on_i = moment(ri_arm, f)
        m_on_j = moment(rj_arm, -f)
        diss = d1
        h[NC] = n[0]
        h[NC + 1] = n[1]
        h[NC + 2] = n[2]
        h[ST] = reff
        hist[i, k] = h
        if detail:
            cn[i, k] = n
            cs[i, k] = ti.Vector([fn, ft.norm(), u])
    elif status == 1 and not far:
        # apart along n: kept for the next step's start (written when it changed)
        if h[ST] >= 0.0 or h[NC] != n[0] or h[NC + 1] != n[1] or h[NC + 2] != n[2]:
            h = zero_history(h)
            h[NC] = n[0]
            h[NC + 1] = n[1]
            h[NC + 2] = n[2]
            h[ST] = -1.0
            hist[i, k] = h
        if detail:
            cs[i, k] = ti.Vector([0.0, 0.0, ti.min(u, 0.0)])
    else:
        if h[ST] != 0.0:
            hist[i, k] = zero_history(h)
        if detail:
            cs[i, k] = ti.Vector([0.0, 0.0, ti.min(u, 0.0)])
    return f, m_on_i, m_on_j, diss


@ti.func
def mesh_contact(xi, mat, abc, a, b, c):
    """An ellipsoid (shape matrix ``mat``, semi-axes ``abc``, centre ``xi``) against
    the triangle abc (module docstring): (depth, n from the particle to the wall,
    contact point, feature: sphere_triangle.FACE, EDGE or VERTEX, Hertz radius)."""
    nf = (b - a).cross(c - a).normalized()
    side = 1.0
    if (xi - a).dot(nf) < 0.0:
        side = -1.0
    big_n = side * nf                        # the plane's normal on the ellipsoid's side
    hn, off = el.support(mat, big_n)
    p = xi - off                             # the deepest point towards the plane
    depth = hn - (xi - a).dot(big_n)
    q, feat = sphere_triangle.closest_point(p - ((p - a).dot(nf)) * nf, a, b, c)
    n = -big_n
    point = p + 0.5 * depth * big_n
    radius = el.hertz_radius(abc, hn)
    if feat != sphere_triangle.FACE:
        # the nearest point in the ellipsoid's metric: map to the unit sphere
        rot_inv = mat.inverse()
        lin = ti.Matrix.zero(float, 3, 3)
        # (x − c)ᵀ M⁻¹ (x − c) = |L (x − c)|² with L from the Cholesky factor; the
        # closest point in that metric is the closest point of the mapped triangle
        lin = _cholesky_t(rot_inv)
        qs, feat2 = sphere_triangle.closest_point(ti.Vector([0.0, 0.0, 0.0]), lin @ (a - xi),
                                                  lin @ (b - xi), lin @ (c - xi))
        feat = feat2
        if feat2 == sphere_triangle.FACE:
            feat = sphere_triangle.EDGE      # (the face was ruled out above)
        q = xi + lin.inverse() @ qs
        n = (rot_inv @ (q - xi)).normalized()
        h2, off2 = el.support(mat, n)
        depth = h2 - (q - xi).dot(n)
        point = q - 0.5 * depth * n
        radius = el.hertz_radius(abc, h2)
    return depth, n, point, feat, radius


@ti.func
def _cholesky_t(m):
    """Lᵀ of the Cholesky factor m = L Lᵀ of a symmetric positive definite 3 × 3
    matrix, so that xᵀ m x = |Lᵀ x|²."""
    l00 = ti.sqrt(m[0, 0])
    l10 = m[1, 0] / l00
    l20 = m[2, 0] / l00
    l11 = ti.sqrt(m[1, 1] - l10 * l10)
    l21 = (m[2, 1] - l20 * l10) / l11
    l22 = ti.sqrt(m[2, 2] - l20 * l20 - l21 * l21)
    return ti.Matrix([[l00, l10, l20], [0.0, l11, l21], [0.0, 0.0, l22]])
