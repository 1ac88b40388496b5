"""Geometry of superellipses (and discs) against each other and against segments (2D).

PHYSICS §7. A shape is (a, b, n) in its body frame, turned by the angle θ; a disc of
radius r is (r, r, 2). Its support function h(u) = ‖(a u'_x, b u'_y)‖_q, q = n/(n − 1),
u' = R(−θ) u, gives the support point p(u) = R(θ) ∇h(u') (the boundary point of outward
normal u, from the centre).

**Pair depth.** With d = x_j − x_i, the bodies overlap when

    δ = min over unit u(φ) of f(φ) = h_i(u) + h_j(−u) − u·d

is positive (the depth of the Minkowski difference); the minimiser is the contact
normal n (i → j). f′(φ) = t·(P_i − P_j) with P_i = x_i + p_i(u), P_j = x_j + p_j(−u)
and t = u rotated +90°, so the minimum is where the two support points face each
other along u. For apart bodies min f = −(their gap), so the same minimum is tracked
smoothly through the first touch. The 1-D minimisation is warm-started from the
normal angle stored in the contact's history (a bracket grown from it in steps that
double); a pair met for the first time is scanned at 16 angles first. Inside the
bracket a safeguarded false position (Illinois) solves f′ = 0 to 1e-13 rad (f64) or
1e-6 rad (f32); at most ``ITER_CAP`` evaluations, the pairs that stop short are
counted (never silent).

**Contact point and force.** The force acts at the midpoint c of P_i and P_j (the
disc convention: R − δ/2 from each centre for discs), so that the tangential force
keeps angular momentum; for the normal force the torque equals that at each body's
own support point, so the elastic normal force is conservative (∂δ/∂x_i = −n,
∂δ/∂θ_i = p_i × n by the envelope theorem).

**Curvature.** The radius of curvature at a support point, ρ = h + h″ (= t·dP/dφ),
exact for ellipses (ρ = a²b²/h³ with h in the body frame), by a central difference
elsewhere; it is capped at the bounding radius (a flat side has ρ = ∞), and Hertz's
R* = ρ_iρ_j/(ρ_i + ρ_j) uses the capped values.

**Segments (walls).** The face: the support point of the particle towards the wall,
u = −m (m the wall's unit normal on the particle's side), depth h(u) − m·(x − a), if
that point falls within the segment; else the segment's end point as a point of zero
size, by the same minimisation with h_j = 0.
"""
import taichi as ti
from taichi.lang import impl

from .frame import perp

ITER_CAP = 60       # evaluations of f′ for one contact (bracket and solve together)
SCAN = 16           # angles of the first scan of a new pair


@ti.func
def _tol():
    t = 1e-13
    if ti.static(impl.get_runtime().default_fp != ti.f64):
        t = 1e-6
    return t


@ti.func
def rot(v, c, s):
    """v turned by the angle of cosine c, sine s."""
    return ti.Vector([c * v[0] - s * v[1], s * v[0] + c * v[1]])


@ti.func
def support(shp, c, s, u):
    """(h(u), p(u)) of shape ``shp`` = (a, b, n) turned by (c, s) = (cos θ, sin θ),
    for a world unit direction u: the support function and the support point
    (world frame, from the centre)."""
    a = shp[0]
    b = shp[1]
    n = shp[2]
    ub = rot(u, c, -s)          # body frame
    h = 0.0
    pb = ti.Vector([0.0, 0.0])
    if n == 2.0:
        ax = a * ub[0]
        by = b * ub[1]
        h = ti.sqrt(ax * ax + by * by)
        pb = ti.Vector([a * ax, b * by]) / h
    else:
        q = n / (n - 1.0)
        ax = ti.abs(a * ub[0])
        by = ti.abs(b * ub[1])
        m = ti.max(ax, by)
        rx = ax / m
        ry = by / m
        sx = 0.0
        sy = 0.0
        if rx > 0.0:
            sx = ti.pow(rx, q)
        if ry > 0.0:
            sy = ti.pow(ry, q)
        ssum = sx + sy
        h = m * ti.pow(ssum, 1.0 / q)
        # ∇h = (a sgn(u_x) (|a u_x|/h)^(q−1), …); (|a u_x|/h)^(q−1) = (s_x / Σ)^(1/n)
        e = 1.0 / n
        px = 0.0
        py = 0.0
        if sx > 0.0:
            px = a * ti.math.sign(ub[0]) * ti.pow(sx / ssum, e)
        if sy > 0.0:
            py = b * ti.math.sign(ub[1]) * ti.pow(sy / ssum, e)
        pb = ti.Vector([px, py])
    return h, rot(pb, c, s)


@ti.func
def curvature_radius(shp, c, s, u, cap):
    """Radius of curvature of the boundary at its point of outward normal u, capped
    at ``cap`` (module docstring)."""
    a = shp[0]
    b = shp[1]
    rho = 0.0
    if shp[2] == 2.0:
        ub = rot(u, c, -s)
        ax = a * ub[0]
        by = b * ub[1]
        h = ti.sqrt(ax * ax + by * by)
        rho = (a * b) ** 2 / (h * h * h)
    else:
        eps = 1e-4
        t = perp(u)
        cp = ti.cos(eps)
        sp = ti.sin(eps)
        _, p1 = support(shp, c, s, cp * u + sp * t)
        _, p0 = support(shp, c, s, cp * u - sp * t)
        rho = t.dot(p1 - p0) / (2.0 * sp)
    return ti.math.clamp(rho, 1e-6 * cap, cap)


@ti.func
def _slope(si, ci, sni, sj, cj, snj, d, phi, point: ti.template()):
    """(f(φ), f′(φ), u, p_i, p_j) of the pair function (module docstring); ``point``:
    body j is a point (h_j = 0)."""
    u = ti.Vector([ti.cos(phi), ti.sin(phi)])
    hi, pi = support(si, ci, sni, u)
    hj = 0.0
    pj = ti.Vector([0.0, 0.0])
    if ti.static(not point):
        hj, pj = support(sj, cj, snj, -u)
    f = hi + hj - u.dot(d)
    g = perp(u).dot(pi - pj - d)
    return f, g, u, pi, pj


@ti.func
def pair_depth(si, ti_, sj, tj, d, phi0, warm, point: ti.template()):
    """Minimum of the pair function near φ0 (``warm``: the normal angle of the last
    step, else a scan of SCAN angles picks the start). ``si``/``sj`` the shapes, ``ti_``/
    ``tj`` their angles, d = x_j − x_i. Returns (δ, n, p_i, p_j, φ, converged)."""
    ci = ti.cos(ti_)
    sni = ti.sin(ti_)
    cj = ti.cos(tj)
    snj = ti.sin(tj)
    tol = _tol()
    phi = phi0
    step = 1e-3
    if not warm:
        best = 1e300
        for k in range(SCAN):
            a = phi0 + 6.283185307179586 * k / SCAN
            f, _, _, _, _ = _slope(si, ci, sni, sj, cj, snj, d, a, point)
            if f < best:
                best = f
                phi = a
        step = 6.283185307179586 / SCAN
    # bracket: g(lo) < 0 < g(hi), grown from φ downhill
    f, g, u, pi, pj = _slope(si, ci, sni, sj, cj, snj, d, phi, point)
    lo = phi
    hi = phi
    glo = g
    ghi = g
    evals = 1
    done = False
    scale = ti.max(si[0], si[1])
    if ti.static(not point):
        scale += ti.max(sj[0], sj[1])
    if ti.abs(g) <= tol * scale:
        done = True
    elif g < 0.0:
        # the minimum lies at larger φ
        while evals < ITER_CAP and ghi < 0.0:
            lo = hi
            glo = ghi
            hi = lo + step
            step *= 2.0
            _, ghi, _, _, _ = _slope(si, ci, sni, sj, cj, snj, d, hi, point)
            evals += 1
    else:
        while evals < ITER_CAP and glo > 0.0:
            hi = lo
            ghi = glo
            lo = hi - step
            step *= 2.0
            _, glo, _, _, _ = _slope(si, ci, sni, sj, cj, snj, d, lo, point)
            evals += 1
    if not done:
        # Illinois false position on g = 0 within [lo, hi]
        side = 0
        while evals < ITER_CAP and hi - lo > tol:
            x = lo
            if ghi != glo:
                x = (lo * ghi - hi * glo) / (ghi - glo)
            if not (lo < x < hi):
                x = 0.5 * (lo + hi)
            _, gx, _, _, _ = _slope(si, ci, sni, sj, cj, snj, d, x, point)
            evals += 1
            if gx == 0.0:
                lo = x
                hi = x
            elif gx < 0.0:
                lo = x
                glo = gx
                if side == -1:
                    ghi *= 0.5
                side = -1
            else:
                hi = x
                ghi = gx
                if side == 1:
                    glo *= 0.5
                side = 1
        phi = 0.5 * (lo + hi)
        f, g, u, pi, pj = _slope(si, ci, sni, sj, cj, snj, d, phi, point)
        done = hi - lo <= tol
    # keep the stored angle in (−π, π]
    phi = ti.atan2(u[1], u[0])
    return f, u, pi, pj, phi, done


@ti.func
def point_depth(s, th, xp, phi0):
    """Depth of the point x_p (relative to the centre) inside shape ``s`` turned by
    ``th``: the pair function with h_j = 0. Returns (δ, n, p, converged)."""
    f, u, p, _, _, ok = pair_depth(s, th, s, 0.0, xp, phi0, False, True)
    return f, u, p, ok


@ti.func
def face_depth(s, th, x, a, b, inv_ll):
    """Face contact of shape ``s`` at x (angle th) with the segment ab: (δ, n, p,
    inside) with n the normal from the particle to the wall, p its support point
    (from the centre) and ``inside`` whether p faces the segment (not its ends)."""
    ab = b - a
    m = perp(ab) * ti.sqrt(inv_ll)
    if m.dot(x - a) < 0.0:
        m = -m
    n = -m
    h, p = support(s, ti.cos(th), ti.sin(th), n)
    depth = h - m.dot(x - a)
    sp = (x + p - a).dot(ab) * inv_ll
    return depth, n, p, 0.0 <= sp <= 1.0, sp
