"""Geometry of ellipsoids (3D, Miyata et al. 2002, §2.4).

An ellipsoid of semi-axes (a, b, c) turned by the unit quaternion q (body to world,
rotation R) has the shape matrix M = R diag(a², b², c²) Rᵀ, the support function
h(u) = sqrt(uᵀ M u) and the support point x + M u / h(u) (its boundary point of
outward normal u). A sphere is the ellipsoid (r, r, r).

Two convex bodies i, j with d = x_j − x_i overlap along the unit direction n by
δ(n) = h_i(n) + h_j(n) − d·n (both bodies being centrally symmetric); the
penetration depth is the least δ over the unit sphere, attained at the contact
normal n (from i to j), and the bodies are apart when δ(n) < 0 for some n. It is
found by Newton's method on the sphere (a 2-variable projected Newton in the
tangent plane, :func:`penetration`), warm-started from the last step's normal. At
the normal the contact point is the midpoint of the support points
x_i + M_i n/h_i and x_j − M_j n/h_j. The Hertz radius of each body there is the
geometric mean of its principal radii of curvature, 1/sqrt(K) = abc/h(n)² (the
Gaussian curvature of an ellipsoid at the point of normal n is h⁴/(a²b²c²)); the
pair's R* = R_i R_j/(R_i + R_j) (Johnson's R_e = ½(AB)^(−1/2) when the principal
directions of the two bodies coincide).
"""
import taichi as ti


@ti.func
def rotation(q):
    """The rotation matrix (body to world) of the unit quaternion q = (w, x, y, z)."""
    w, x, y, z = q[0], q[1], q[2], q[3]
    return ti.Matrix([[1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - w * z), 2.0 * (x * z + w * y)],
                      [2.0 * (x * y + w * z), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - w * x)],
                      [2.0 * (x * z - w * y), 2.0 * (y * z + w * x), 1.0 - 2.0 * (x * x + y * y)]])


@ti.func
def shape_matrix(rot, abc):
    """M = R diag(a², b², c²) Rᵀ."""
    d = ti.Matrix([[abc[0] * abc[0], 0.0, 0.0], [0.0, abc[1] * abc[1], 0.0],
                   [0.0, 0.0, abc[2] * abc[2]]])
    return rot @ d @ rot.transpose()


@ti.func
def support(m, u):
    """(h(u), M u / h(u)): the support value and the support point's offset."""
    mu = m @ u
    h = ti.sqrt(u.dot(mu))
    return h, mu / h


@ti.func
def tangent_basis(n):
    """Two unit vectors normal to n and to each other."""
    a = ti.Vector([1.0, 0.0, 0.0])
    if ti.abs(n[0]) > 0.7:
        a = ti.Vector([0.0, 1.0, 0.0])
    t1 = (a - a.dot(n) * n).normalized()
    return t1, n.cross(t1)


@ti.func
def penetration(mi, mj, d, n0, tol, maxit: ti.template()):
    """The penetration depth of two centrally symmetric convex bodies of shape
    matrices mi, mj at offset d = x_j − x_i (module docstring), from the unit
    direction n0: (depth, n, status, h_i(n), h_j(n), M_i n/h_i, M_j n/h_j) with
    status 0 converged (|tangent gradient| <= tol), 1 apart (a separating direction
    was met: depth < 0 there), 2 stopped at ``maxit`` iterations. The support values
    and offsets at the returned n are those of :func:`support` (the last iterate's,
    not computed again)."""
    n = n0
    depth = 0.0
    status = 2
    hi = 1.0
    hj = 1.0
    oi = n0 * 0.0
    oj = n0 * 0.0
    for it in range(maxit):
        mni = mi @ n
        mnj = mj @ n
        hi = ti.sqrt(n.dot(mni))
        hj = ti.sqrt(n.dot(mnj))
        depth = hi + hj - d.dot(n)
        if depth < 0.0:
            status = 1
            break
        oi = mni / hi
        oj = mnj / hj
        g = oi + oj - d
        t1, t2 = tangent_basis(n)
        g1 = t1.dot(g)
        g2 = t2.dot(g)
        if ti.sqrt(g1 * g1 + g2 * g2) <= tol:
            status = 0
            break
        # the Riemannian Hessian in the basis (t1, t2): P H P − (n·g) P, with H the
        # Euclidean Hessian (M − (M n)(M n)ᵀ/h²)/h of each support function
        gn = n.dot(g)
        a11 = 0.0
        a12 = 0.0
        a22 = 0.0
        for k in ti.static(range(2)):
            m = mi
            mn = mni
            h = hi
            if ti.static(k == 1):
                m = mj
                mn = mnj
                h = hj
            p1 = t1.dot(mn)
            p2 = t2.dot(mn)
            a11 += (t1.dot(m @ t1) - p1 * p1 / (h * h)) / h
            a12 += (t1.dot(m @ t2) - p1 * p2 / (h * h)) / h
            a22 += (t2.dot(m @ t2) - p2 * p2 / (h * h)) / h
        a11 -= gn
        a22 -= gn
        det = a11 * a22 - a12 * a12
        s1 = 0.0
        s2 = 0.0
        if a11 > 0.0 and det > 0.0:
            s1 = -(a22 * g1 - a12 * g2) / det
            s2 = -(a11 * g2 - a12 * g1) / det
        else:
            # not convex here: a gradient step of the size the curvature allows
            lam = ti.max(ti.abs(a11) + ti.abs(a22), 1e-300)
            s1 = -g1 / lam
            s2 = -g2 / lam
        step = ti.sqrt(s1 * s1 + s2 * s2)
        if step > 0.5:          # at most about 30° a step
            s1 *= 0.5 / step
            s2 *= 0.5 / step
        n = (n + s1 * t1 + s2 * t2).normalized()
    if status == 2:
        # (the last step moved n after its support values were taken)
        hi, oi = support(mi, n)
        hj, oj = support(mj, n)
    return depth, n, status, hi, hj, oi, oj


@ti.func
def hertz_radius(abc, h):
    """The geometric mean radius of curvature abc/h² at the point of support value h."""
    return abc[0] * abc[1] * abc[2] / (h * h)
