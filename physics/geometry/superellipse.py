"""Geometry of superellipses (and discs) against each other and against segments (2D).

Miyata et al. 2002, §2.3. A shape is (a, b, n) in its body frame, turned by the angle θ; a disc of
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
normal angle stored in the contact's history; a pair met for the first time is scanned
at 16 angles first. Newton's method on f′ = 0 with the analytic f″ = ρ_i + ρ_j − f
(ρ the curvature radii) is kept inside the bracket that the signs of f′ build up, with
a bisection where a step would leave it or not halve f′ (Numerical Recipes' rtsafe: the
flat sides of n > 2, where ρ → ∞, make f′ behave like a cube root there). It stops
when the two support points face each other within 1e-6 × the bodies' size (f64;
1e-4 in f32), or when the last step below is predicted to leave them so, or the step
is below 1e-13 rad; at most ``ITER_CAP`` evaluations, the pairs that stop short are
counted (never silent). Then a last step is taken without another evaluation, on
the cubic model of f with f‴ = ρ′_i + ρ′_j − f′ (ρ′ = dρ/dφ, analytic, from the
quantities the support function has already computed): φ moves by
dφ = −f′/f″ − f‴f′²/2f″³, f by its cubic model, the support points along their
paths to second order. The prediction: |dφ| ≤ 1e-3, f″ changing by at most a tenth
over dφ (the cubic model holds), and f‴dφ²/2, what Newton's step leaves in f′,
within the tolerance. A warm-started contact is then mostly done after its first
evaluation even where its normal turns by more than the tolerance each step, as on
flat faces, where f″ is large (evaluations per contact: benchmarks/RESULTS.md,
section Superellipses beside discs).

**Contact point and force.** The force acts at the midpoint c of P_i and P_j (the
disc convention: R − δ/2 from each centre for discs), so that the tangential force
keeps angular momentum; for the normal force the torque equals that at each body's
own support point, so the elastic normal force is conservative (∂δ/∂x_i = −n,
∂δ/∂θ_i = p_i × n by the envelope theorem).

**Curvature.** The radius of curvature at a support point, ρ = h + h″ (= t·dP/dφ),
analytic (ρ = a²b²/h³ for ellipses, h in the body frame; :func:`support_curv`); it
is capped at the bounding radius (a flat side has ρ = ∞), and Hertz's
R* = ρ_iρ_j/(ρ_i + ρ_j) uses the capped values.

**Segments (walls).** The face: the support point of the particle towards the wall,
u = −m (m the wall's unit normal on the particle's side), depth h(u) − m·(x − a), if
that point falls within the segment; else the segment's end point as a point of zero
size, by the same minimisation with h_j = 0.
"""
import taichi as ti
from taichi.lang import impl

from .frame import perp

ITER_CAP = 100      # evaluations of f′ for one contact (bracket and solve together)
SCAN = 16           # angles of the first scan of a new pair


@ti.func
def _tol():
    t = 1e-10
    if ti.static(impl.get_runtime().default_fp != ti.f64):
        t = 1e-5
    return t


@ti.func
def rot(v, c, s):
    """v turned by the angle of cosine c, sine s."""
    return ti.Vector([c * v[0] - s * v[1], s * v[0] + c * v[1]])


@ti.func
def support(shp, c, s, u):
    """(h(u), p(u)) of shape ``shp`` = (a, b, n) turned by (c, s) = (cos θ, sin θ),
    for a world unit direction u: the support function and the support point
    (world frame, from the centre); :func:`support_curv` without the curvature."""
    h, p, rho, drho = support_curv(shp, c, s, u)
    return h, p


@ti.func
def curvature_radius(shp, c, s, u, cap):
    """Radius of curvature of the boundary at its point of outward normal u, capped
    at ``cap`` (module docstring)."""
    h_unused, p_unused, rho, drho = support_curv(shp, c, s, u)
    return ti.math.clamp(rho, 1e-6 * cap, cap)


@ti.func
def _root(x, k):
    """x^(1/k) for x > 0: by square roots where k is 2, 4 or 8 (the powers of n = 3, 4,
    5, 8, 9; n = 4 is the common square-ish superellipse; measurements:
    benchmarks/RESULTS.md, section Superellipses beside discs), else by a logarithm
    and an exponential."""
    out = 0.0
    if k == 2.0:
        out = ti.sqrt(x)
    elif k == 4.0:
        out = ti.sqrt(ti.sqrt(x))
    elif k == 8.0:
        out = ti.sqrt(ti.sqrt(ti.sqrt(x)))
    else:
        out = ti.exp(ti.log(x) / k)
    return out


@ti.func
def support_curv(shp, c, s, u):
    """(h(u), p(u), ρ(u), ρ′(u)): the support function, the support point (world frame,
    from the centre), the radius of curvature there, ρ = tᵀ∇²h t, and its derivative
    dρ/dφ along the boundary's normal angle. For n = 2, ρ = a²b²/h³; else, with
    A = |a u'_x|, B = |b u'_y|, S = A^q + B^q,
    ρ = (q − 1) S^(1/q − 2) A^(q − 2) B^(q − 2) (B² a/b + A² b/a)² (from the Hessian of
    h), infinite (returned as 1e30, with ρ′ = 0) on the flat points of n > 2 where A or
    B is 0."""
    a = shp[0]
    b = shp[1]
    n = shp[2]
    ub = rot(u, c, -s)
    h = 0.0
    pb = ti.Vector([0.0, 0.0])
    rho = 1e30
    drho = 0.0
    if n == 2.0:
        ax = a * ub[0]
        by = b * ub[1]
        h = ti.sqrt(ax * ax + by * by)
        pb = ti.Vector([a * ax, b * by]) / h
        rho = (a * b) ** 2 / (h * h * h)
        # dρ/dψ = −3ρ h′/h, h′ = p·t (t the tangent, u turned +90°)
        drho = -3.0 * rho * (pb[1] * ub[0] - pb[0] * ub[1]) / h
    else:
        # with the larger of A = |a u'_x|, B = |b u'_y| as the scale, r = smaller/larger
        # and q = n/(n − 1) = 1 + 1/(n − 1): with t = r^(1/(n−1)), r^q = r t, S = 1 + r t,
        # h = larger·S^(1/q) = larger·S·S^(−1/n), and the support point's components
        # are a or b times S^(−1/n) and t S^(−1/n) (two logarithms, two exponentials;
        # square roots where 1/n or 1/(n − 1) is 1/2, 1/4 or 1/8: _root)
        q = n / (n - 1.0)
        A = ti.abs(a * ub[0])
        B = ti.abs(b * ub[1])
        big = ti.max(A, B)
        r = ti.min(A, B) / big
        t = 0.0
        if r > 0.0:
            t = _root(r, n - 1.0)
        sr = r * t
        ssum = 1.0 + sr
        fb = 1.0 / _root(ssum, n)
        h = big * ssum * fb
        fs = t * fb
        fx = fb
        fy = fs
        if A < B:
            fx = fs
            fy = fb
        pb = ti.Vector([a * ti.math.sign(ub[0]) * fx, b * ti.math.sign(ub[1]) * fy])
        if r > 0.0:
            # ρ = (q − 1) h s_x s_y / Σ² · w² / (A² B²), the s scaled by the larger
            w = B * B * a / b + A * A * b / a
            rho = (q - 1.0) * h * sr / (ssum * ssum) * w * w / (A * A * B * B)
            # dρ/dψ (ψ the body-frame angle of u) from d ln of each factor:
            # d ln A = −u_y/u_x, d ln B = u_x/u_y, d ln(r^q) = q d ln(min/max),
            # d ln h = h′/h with h′ = p·t (no further logarithms or exponentials)
            dla = -ub[1] / ub[0]
            dlb = ub[0] / ub[1]
            dlsr = q * (dla - dlb)
            if A > B:
                dlsr = -dlsr
            dlw = 2.0 * (B * B * a / b * dlb + A * A * b / a * dla) / w
            dlh = (pb[1] * ub[0] - pb[0] * ub[1]) / h
            drho = rho * (dlh + (1.0 - 2.0 * sr / ssum) * dlsr + 2.0 * dlw
                          - 2.0 * dla - 2.0 * dlb)
    return h, rot(pb, c, s), rho, drho


@ti.func
def _eval(si, ci, sni, sj, cj, snj, d, phi, point: ti.template()):
    """(f, f′, f″, u, p_i, p_j, ρ_i, ρ_j, ρ′_i, ρ′_j) of the pair function at φ (module
    docstring): f″ = ρ_i + ρ_j − f, f‴ = ρ′_i + ρ′_j − f′; ``point``: body j is a point
    (h_j = 0, ρ_j = 0)."""
    u = ti.Vector([ti.cos(phi), ti.sin(phi)])
    hi, pi, ri, dri = support_curv(si, ci, sni, u)
    hj = 0.0
    pj = ti.Vector([0.0, 0.0])
    rj = 0.0
    drj = 0.0
    if ti.static(not point):
        hj, pj, rj, drj = support_curv(sj, cj, snj, -u)
    f = hi + hj - u.dot(d)
    g = perp(u).dot(pi - pj - d)
    return f, g, ri + rj - f, u, pi, pj, ri, rj, dri, drj


@ti.func
def _value(si, ci, sni, sj, cj, snj, d, phi, point: ti.template()):
    u = ti.Vector([ti.cos(phi), ti.sin(phi)])
    hi, pi = support(si, ci, sni, u)
    hj = 0.0
    if ti.static(not point):
        hj, pj = support(sj, cj, snj, -u)
    return hi + hj - u.dot(d)


@ti.func
def _settled(g, fpp, f3, gtol):
    """Whether the last Newton step, taken without another evaluation, leaves the
    support points facing each other within ``gtol``: already so, or the step
    dφ = −f′/f″ is short (|dφ| ≤ 1e-3, f″ changing by at most a tenth over it, so
    that the quadratic model holds) and what it leaves, f‴dφ²/2, is within ``gtol``."""
    ok = ti.abs(g) <= gtol
    if not ok and fpp > 0.0 and fpp < 1e29:
        dphi = -g / fpp
        ok = (ti.abs(dphi) <= 1e-3 and ti.abs(f3 * dphi) <= 0.1 * fpp
              and 0.5 * ti.abs(f3) * dphi * dphi <= gtol)
    return ok


@ti.func
def pair_depth(si, ci, sni, sj, cj, snj, d, phi0, warm, point: ti.template()):
    """Minimum of the pair function near φ0 (``warm``: the normal angle of the last
    step, else a scan of SCAN angles picks the start). ``si``/``sj`` the shapes, (``ci``,
    ``sni``) and (``cj``, ``snj``) the cosines and sines of their angles, d = x_j − x_i. Newton's method on f′ = 0 with f″ = ρ_i + ρ_j − f,
    kept inside the bracket [lo, hi] that the signs of f′ build up (a bisection where a
    step would leave it or f″ ≤ 0), each step at most 0.3 rad. Returns (δ, n, p_i, p_j,
    φ, converged, ρ_i, ρ_j)."""
    tol = _tol()
    phi = phi0
    if not warm:
        best = 1e300
        for k in range(SCAN):
            a = phi0 + 6.283185307179586 * k / SCAN
            fa = _value(si, ci, sni, sj, cj, snj, d, a, point)
            if fa < best:
                best = fa
                phi = a
    lo = -1e30
    hi = 1e30
    f, g, fpp, u, pi, pj, ri, rj, dri, drj = _eval(si, ci, sni, sj, cj, snj, d, phi, point)
    scale = ti.max(si[0], si[1])
    if ti.static(not point):
        scale += ti.max(sj[0], sj[1])
    gtol = 1e-6 * scale                # the support points face each other to this
    if ti.static(impl.get_runtime().default_fp != ti.f64):
        gtol = 1e-4 * scale
    done = _settled(g, fpp, dri + drj - g, gtol)
    dx = 0.3
    dxold = 0.3
    free = 0.01
    it = 0
    while it < ITER_CAP and not done:
        it += 1
        if g < 0.0:
            lo = phi
        else:
            hi = phi
        bracket = lo > -1e29 and hi < 1e29
        new = phi
        finite = fpp > 0.0 and fpp < 1e29
        newton_ok = finite
        if bracket and newton_ok:
            newton_ok = ti.abs(2.0 * g) <= ti.abs(dxold * fpp)    # halves at least (rtsafe)
        if bracket and (not newton_ok or not (lo < phi - g / fpp < hi)):
            dxold = dx
            dx = 0.5 * (hi - lo)
            new = lo + dx
        elif not bracket:
            # downhill until f′ changes sign: Newton's step where it is one (clamped),
            # else a step that doubles each time
            step = -free * ti.math.sign(g)
            free *= 2.0
            if newton_ok and ti.abs(g) > 1e-12 * fpp:
                step = ti.math.clamp(-g / fpp, -0.3, 0.3)
            dxold = dx
            dx = step
            new = phi + step
        else:
            dxold = dx
            dx = -g / fpp
            new = phi + dx
        phi = new
        f, g, fpp, u, pi, pj, ri, rj, dri, drj = _eval(si, ci, sni, sj, cj, snj, d, phi, point)
        if _settled(g, fpp, dri + drj - g, gtol) or (bracket and ti.abs(dx) <= tol * 1e-3):
            done = True
    if done and fpp > 0.0 and fpp < 1e29 and ti.abs(g) < 1e-3 * fpp:
        # the last step without another evaluation, on the cubic model of f: φ moves by
        # dφ = −f′/f″ − f‴(f′/f″)²/2f″ (Newton's step and its second-order term),
        # f by f′dφ + f″dφ²/2 + f‴dφ³/6, the support points along their paths to second
        # order (dP_i/dφ = ρ_i t, d²P_i/dφ² = ρ′_i t − ρ_i u; P_j the same at −u);
        # what is left in f′ is below f‴dφ²/2, within the stop's tolerance (_settled)
        f3 = dri + drj - g
        dn = -g / fpp
        dphi = dn - 0.5 * f3 * dn * dn / fpp
        t = perp(u)
        h2 = 0.5 * dphi * dphi
        pi += (ri * dphi + dri * h2) * t - ri * h2 * u
        pj -= (rj * dphi + drj * h2) * t - rj * h2 * u
        f += dphi * (g + dphi * (0.5 * fpp + f3 * dphi / 6.0))
        # (|dφ| ≤ 1e-3 rad: cos and sin of dφ by their series to dφ⁴, round-off)
        u = (1.0 - h2 + h2 * h2 / 6.0) * u + dphi * (1.0 - h2 / 3.0) * t
        u /= u.norm()
        phi += dphi
    # keep the stored angle in (−π, π]
    phi -= 6.283185307179586 * ti.round(phi / 6.283185307179586)
    return f, u, pi, pj, phi, done, ri, rj


@ti.func
def point_depth(s, th, xp, phi0):
    """Depth of the point x_p (relative to the centre) inside shape ``s`` turned by
    ``th``: the pair function with h_j = 0. Returns (δ, n, p, converged)."""
    f, u, p, pj, phi, ok, ri, rj = pair_depth(s, ti.cos(th), ti.sin(th), s, 1.0, 0.0, xp,
                                              phi0, False, True)
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
