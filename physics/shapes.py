"""Particle shapes other than the disc (Miyata et al. 2002, §2.3): the host-side description.

A shape is a frozen description in the body frame. The engine keeps, per particle,
its parameters in the state array ``shp`` (a, b, n; n = 0 for a disc), its angle θ
(counter-clockwise, radians) in ``angle``, and its bounding radius as the particle's
radius (the neighbour grid and the skin rule use it unchanged). The contact geometry
of each shape pair is in :mod:`physics.geometry`.

Superellipse (Miyata et al. 2002, Eq. 34): |x/a|ⁿ + |y/b|ⁿ = 1, 2 ≤ n ≤ 10.

- area A = 4ab·Γ(1+1/n)²/Γ(1+2/n);
- polar moment of inertia per unit density
  J = (4/3)(a³b + ab³)·Γ(1+3/n)Γ(1+1/n)/Γ(1+4/n);
- support function h(u) = ‖(a·u_x, b·u_y)‖_q, q = n/(n − 1), and support point
  ∇h(u) (the boundary point of outward normal u);
- n = 2, a = b is a disc of radius a and gives the disc results;
- the bounding radius (the neighbour grid's) is the largest distance of a boundary
  point from the centre: max(a, b) for n = 2 only — for n > 2 the corners reach
  beyond it (Miyata et al. (2002) say max(a, b), which would miss contacts at the corners).
"""
import math

import numpy as np

from .validate import in_range, positive


class Superellipse:
    """A 2D superellipse |x/a|ⁿ + |y/b|ⁿ = 1 (semi-axes a, b in m; 2 ≤ n ≤ 10).

    Given to :meth:`tdem.Simulation.add_particles` as ``shape=`` (with ``angle=``
    in degrees, counter-clockwise, the body x axis against the global one)."""

    kind = "superellipse"

    def __init__(self, a, b, n=2.0):
        self.a = positive("a", a)
        self.b = positive("b", b)
        self.n = in_range("n", n, 2.0, 10.0)

    def __repr__(self):
        return f"Superellipse(a={self.a!r}, b={self.b!r}, n={self.n!r})"

    def __eq__(self, other):
        return isinstance(other, Superellipse) and (self.a, self.b, self.n) == (
            other.a, other.b, other.n)

    def __hash__(self):
        return hash((self.a, self.b, self.n))

    def to_dict(self):
        return {"kind": self.kind, "a": self.a, "b": self.b, "n": self.n}

    @property
    def area(self):
        """Area (m² per metre of thickness: m³/m)."""
        g = math.gamma
        n = self.n
        return 4.0 * self.a * self.b * g(1 + 1 / n) ** 2 / g(1 + 2 / n)

    @property
    def polar_moment(self):
        """Polar moment of the area about the centre, ∫(x² + y²) dA (m⁴); the inertia
        is density × this."""
        g = math.gamma
        a, b, n = self.a, self.b, self.n
        return 4.0 / 3.0 * (a ** 3 * b + a * b ** 3) * g(1 + 3 / n) * g(1 + 1 / n) / g(1 + 4 / n)

    @property
    def bounding_radius(self):
        """Radius of the smallest centred circle that holds the shape (m): the largest
        |p| over the boundary. It is max(a, b) only for n = 2: for n > 2 the corners
        reach beyond (a square of n = 4 to 2^(1/4) a). By a dense scan of the boundary,
        widened by 1e-6 (the scan's error is far below)."""
        if self.n == 2.0:
            return max(self.a, self.b)
        return float(np.linalg.norm(self.outline(200_000), axis=1).max()) * (1.0 + 1e-6)

    @property
    def inscribed_radius(self):
        """Radius of the largest centred circle inside the shape: min(a, b)."""
        return min(self.a, self.b)

    @property
    def row(self):
        """The engine's ``shp`` row (a, b, n)."""
        return (self.a, self.b, self.n)

    # -------------------------------------------------- geometry (numpy, body frame)
    def support(self, u):
        """(h(u), ∇h(u)) for unit directions ``u`` (…, 2) in the body frame: the
        support function and the boundary point of outward normal u."""
        u = np.asarray(u, dtype=float)
        q = self.n / (self.n - 1.0)
        ax = np.abs(self.a * u[..., 0])
        by = np.abs(self.b * u[..., 1])
        h = (ax ** q + by ** q) ** (1.0 / q)
        px = self.a * np.sign(u[..., 0]) * (ax / h) ** (q - 1.0)
        py = self.b * np.sign(u[..., 1]) * (by / h) ** (q - 1.0)
        return h, np.stack([px, py], axis=-1)

    def outline(self, m=64):
        """``m`` boundary points (m, 2) in the body frame, counter-clockwise, by the
        parametrisation of Miyata's Eq. 35 (denser at the corners for n > 2)."""
        t = np.linspace(0.0, 2.0 * math.pi, m, endpoint=False)
        c, s = np.cos(t), np.sin(t)
        e = 2.0 / self.n
        return np.stack([self.a * np.sign(c) * np.abs(c) ** e,
                         self.b * np.sign(s) * np.abs(s) ** e], axis=1)

    def placed(self, centres, angles, m=64):
        """Outlines (N, m, 2) of the shape at ``centres`` (N, 2) turned by ``angles``
        (N,, radians): :meth:`outline` in the world frame."""
        return np.asarray(centres, float)[:, None, :] + np.einsum(
            "nij,mj->nmi", rotation(np.asarray(angles, float)), self.outline(m))

    def support_world(self, u, angles):
        """Support points (N, 2), from the centres, for world unit directions ``u``
        (N, 2) of the shape turned by ``angles`` (N,, radians)."""
        R = rotation(np.asarray(angles, float))
        _, pb = self.support(np.einsum("nji,nj->ni", R, np.asarray(u, float)))
        return np.einsum("nij,nj->ni", R, pb)

    def inside(self, x):
        """Miyata's Eq. 34 at body-frame points ``x`` (…, 2): < 0 inside, > 0 outside."""
        x = np.asarray(x, dtype=float)
        return np.abs(x[..., 0] / self.a) ** self.n + np.abs(x[..., 1] / self.b) ** self.n - 1.0


def rotation(theta):
    """2×2 rotation matrices for angles ``theta`` (radians), shape (…, 2, 2)."""
    c, s = np.cos(theta), np.sin(theta)
    return np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)


def quaternion_rotations(q):
    """(N, 3, 3) body-to-world rotation matrices of unit quaternions q (N, 4), (w, x, y, z)."""
    q = np.asarray(q, dtype=float).reshape(-1, 4)
    w, x, y, z = q.T
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
    ], 1)


def support_depth(si, xi, ti, sj, xj, tj, m=4096):
    """Penetration depth of two shapes by a scan of the normal angle at ``m`` angles,
    refined around the best by Brent's method (a reference for tests, independent of
    the engine's iteration): (δ, unit normal from i to j)."""
    from scipy.optimize import minimize_scalar

    d = np.asarray(xj, float) - np.asarray(xi, float)

    def f(phi):
        phi = np.atleast_1d(phi)
        u = np.stack([np.cos(phi), np.sin(phi)], 1)
        hi, _ = si.support(u @ rotation(ti))
        hj, _ = sj.support(-u @ rotation(tj))
        return hi + hj - u @ d

    phi = np.linspace(0.0, 2.0 * math.pi, m, endpoint=False)
    k = int(np.argmin(f(phi)))
    step = phi[1] - phi[0]
    r = minimize_scalar(lambda p: float(f(p)[0]), bounds=(phi[k] - step, phi[k] + step),
                        method="bounded", options={"xatol": 1e-13})
    best = r.x if r.fun < f(phi[k])[0] else phi[k]
    return float(f(best)[0]), np.array([math.cos(best), math.sin(best)])


def geometric_potential_contact(si, xi, ti, sj, xj, tj):
    """The seed's contact detection (Miyata et al. 2002, Eqs. 35–42), kept as an optional
    cross-check of the engine's support-function depth: the boundary point of each body
    that minimises the other's shape function (Eq. 36, Brent's method as in the seed,
    from :func:`scipy.optimize.minimize_scalar`), the radii and centres of curvature
    there (Eqs. 39–41), and the overlap of the two circles of curvature (Eq. 42).
    Returns (δ, unit normal from C_i to C_j). Valid for small overlaps (the circles of
    curvature stand in for the bodies)."""
    from scipy.optimize import minimize_scalar

    xi, xj = np.asarray(xi, float), np.asarray(xj, float)
    Ri, Rj = rotation(ti), rotation(tj)

    def boundary(s, alpha):
        c, sn = math.cos(alpha), math.sin(alpha)
        e = 2.0 / s.n
        return np.array([s.a * math.copysign(abs(c) ** e, c), s.b * math.copysign(abs(sn) ** e, sn)])

    def best(sk, xk, Rk, so, xo, Ro):
        # minimise the other body's potential over the parameter of this body's boundary
        def pot(alpha):
            p = xk + Rk @ boundary(sk, alpha)
            return float(so.inside(Ro.T @ (p - xo)))
        grid = np.linspace(0.0, 2.0 * math.pi, 721)
        a0 = grid[int(np.argmin([pot(a) for a in grid]))]
        step = grid[1] - grid[0]
        r = minimize_scalar(pot, bracket=(a0 - step, a0, a0 + step), method="brent",
                            tol=1e-12)
        return boundary(sk, r.x)

    def curvature(s, p):
        # Eq. 39 with f = |x/a|^n + |y/b|^n − 1 (body frame), and the unit normal Eq. 40
        n, a, b = s.n, s.a, s.b
        x, y = p
        fx = n * np.sign(x) * abs(x) ** (n - 1) / a ** n
        fy = n * np.sign(y) * abs(y) ** (n - 1) / b ** n
        fxx = n * (n - 1) * abs(x) ** (n - 2) / a ** n
        fyy = n * (n - 1) * abs(y) ** (n - 2) / b ** n
        g = math.hypot(fx, fy)
        den = fxx * fy ** 2 + fyy * fx ** 2
        rho = g ** 3 / den if den > 0 else math.inf
        return rho, np.array([fx, fy]) / g

    pi_ = best(si, xi, Ri, sj, xj, Rj)
    pj_ = best(sj, xj, Rj, si, xi, Ri)
    rho_i, ni = curvature(si, pi_)
    rho_j, nj = curvature(sj, pj_)
    ci = xi + Ri @ (pi_ - rho_i * ni)     # Eq. 41, in global coordinates
    cj = xj + Rj @ (pj_ - rho_j * nj)
    dc = cj - ci
    d = float(np.linalg.norm(dc))
    return rho_i + rho_j - d, dc / d       # Eq. 42


class Ellipsoid:
    """A 3D ellipsoid x²/a² + y²/b² + z²/c² = 1 (semi-axes a, b, c in m along the body
    axes). Given to :meth:`tdem.Simulation.add_particles` as ``shape=`` in a 3D
    simulation, turned by ``orientation=`` (unit quaternions, body to world).

    Volume 4/3 π abc; principal moments of inertia m/5 (b² + c², a² + c², a² + b²);
    support function h(u) = sqrt(uᵀ M u), M = R diag(a², b², c²) Rᵀ, support point
    x + M u/h(u); Gaussian curvature at the point of normal u h(u)⁴/(a²b²c²) (the
    Hertz radius there is the geometric mean abc/h(u)², Miyata et al. 2002, §2.4)."""

    kind = "ellipsoid"

    def __init__(self, a, b, c):
        self.a = positive("a", a)
        self.b = positive("b", b)
        self.c = positive("c", c)

    def __repr__(self):
        return f"Ellipsoid(a={self.a!r}, b={self.b!r}, c={self.c!r})"

    def __eq__(self, other):
        return isinstance(other, Ellipsoid) and (self.a, self.b, self.c) == (
            other.a, other.b, other.c)

    def __hash__(self):
        return hash((self.a, self.b, self.c))

    def to_dict(self):
        return {"kind": self.kind, "a": self.a, "b": self.b, "c": self.c}

    @property
    def volume(self):
        return 4.0 / 3.0 * math.pi * self.a * self.b * self.c

    def inertia(self, mass):
        """Principal moments of inertia (kg m²) for ``mass``."""
        a2, b2, c2 = self.a ** 2, self.b ** 2, self.c ** 2
        return np.array([b2 + c2, a2 + c2, a2 + b2]) * mass / 5.0

    @property
    def bounding_radius(self):
        return max(self.a, self.b, self.c)

    @property
    def inscribed_radius(self):
        return min(self.a, self.b, self.c)


def mass_properties(rows, density, radius, dim=2, polyhedra=()):
    """(mass, inertia) per unit thickness of particles with host shape ``rows`` (N, 4)
    = (a, b, n, area), n = 0 for a disc of radius ``radius``; in 3D (``dim`` 3) of
    spheres: 4/3 π R³ ρ and 2/5 m R²; of ellipsoids (a, b, c, 1) and of polyhedra
    (I₁/m, I₂/m, I₃/m, −(k + 1)), k the index in ``polyhedra``."""
    rows = np.asarray(rows, dtype=float).reshape(-1, 4)
    rho = np.asarray(density, dtype=float)
    r = np.asarray(radius, dtype=float)
    if dim == 3:
        # spheres; an ellipsoid (flag in the 4th column) or a polyhedron has the mass of
        # its volume and, as its scalar inertia, the mean principal moment (the step
        # takes the principal moments from the shape row)
        ell = rows[:, 3] > 0
        poly = rows[:, 3] < 0
        a, b, c = rows[:, 0], rows[:, 1], rows[:, 2]
        vol = np.where(ell, 4.0 / 3.0 * np.pi * a * b * c, 4.0 / 3.0 * np.pi * r ** 3)
        if poly.any():
            vols = np.array([p.volume for p in polyhedra])
            vol = np.where(poly, vols[np.maximum(-rows[:, 3].astype(int) - 1, 0)], vol)
        m = rho * vol
        inertia = np.where(ell, m * (a * a + b * b + c * c) * 2.0 / 15.0, 0.4 * m * r ** 2)
        inertia = np.where(poly, m * (a + b + c) / 3.0, inertia)
        return m, inertia
    m = rho * np.pi * r ** 2
    inertia = 0.5 * m * r ** 2
    shaped = rows[:, 2] > 0
    if shaped.any():
        uniq, inv = np.unique(rows[shaped, :3], axis=0, return_inverse=True)
        area = np.array([Superellipse(*u).area for u in uniq])[inv.ravel()]
        polar = np.array([Superellipse(*u).polar_moment for u in uniq])[inv.ravel()]
        m = m.copy()
        inertia = inertia.copy()
        m[shaped] = rho[shaped] * area
        inertia[shaped] = rho[shaped] * polar
    return m, inertia


def _polyhedron(**kw):
    from .polyhedron import Polyhedron
    return Polyhedron(**kw)


def principal_inertia(rows, mass):
    """Principal moments (N, 3) of ellipsoids (rows (a, b, c, 1)) and polyhedra (rows
    (I₁/m, I₂/m, I₃/m, −(k + 1))) of masses ``mass`` (N,)."""
    rows = np.asarray(rows, dtype=float).reshape(-1, 4)
    m = np.asarray(mass, dtype=float)[:, None]
    a2, b2, c2 = rows[:, 0] ** 2, rows[:, 1] ** 2, rows[:, 2] ** 2
    ell = np.stack([b2 + c2, a2 + c2, a2 + b2], 1) * 0.2
    return np.where(rows[:, 3:4] > 0, ell, rows[:, :3]) * m


SHAPES = {"superellipse": Superellipse, "ellipsoid": Ellipsoid, "polyhedron": _polyhedron}


def from_dict(d):
    d = dict(d)
    return SHAPES[d.pop("kind")](**d)
