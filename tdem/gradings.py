"""Particle size distributions by mass: sieve curves, lognormal, Rosin–Rammler, uniform.

A soil's grading is its sieve curve: the percentage of the mass that passes each
sieve (finer than the size). :func:`grading` makes one from a sieve curve,
``grading.lognormal``, ``grading.rosin_rammler`` and ``grading.uniform`` from the
usual closed forms; :meth:`Grading.sample` draws particle radii whose *mass*
follows the curve, in 3D (spheres: mass ∝ d³) or 2D (discs of equal thickness:
mass ∝ d²). The packers take one (``tdem.pack.random(..., grading=g)``,
``tdem.pack.random3d(..., grading=g)``).

How. A grading is held as its mass passing P(d) on a grid of sizes, linear in
log d between grid points (the sieve curve drawn on its usual semi-log axes; the
closed forms on 2048 points). Within a cell of the grid the mass is spread evenly
in u = ln d, so the number of particles per unit u goes as e^{−k u} (k = 3 or 2):
a cell is chosen with the probability of its number of particles,
ΔP/Δu · (e^{−k u₀} − e^{−k u₁})/k, and u inside it by the inverse of that
exponential. Drawing by number this way reproduces the mass curve exactly in
expectation (``tests/test_gradings.py``: within 2 % passing at every sieve for
samples of 20,000 particles, 2D and 3D).

``passing_of(radii, sizes, dim)`` gives a sample's sieve curve (percent passing by
mass), for checks and plots.
"""
import math

import numpy as np

from .errors import InputError

__all__ = ["Grading", "grading", "passing_of"]

_GRID = 2048


def _dim(dim):
    if dim not in (2, 3) or isinstance(dim, bool):
        raise InputError(f"dim must be 2 (discs of equal thickness) or 3 (spheres), "
                         f"got {dim!r}")
    return int(dim)


def _positive(name, v):
    try:
        x = float(v)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a number > 0, got {v!r}") from None
    if isinstance(v, bool) or not (math.isfinite(x) and x > 0.0):
        raise InputError(f"{name} must be a number > 0, got {v!r}")
    return x


class Grading:
    """A particle size distribution by mass: sizes (diameters, m) and the fraction
    of the mass finer than each (0 at the smallest, 1 at the largest), linear in
    log d between them. Made by :func:`grading` and its closed forms."""

    def __init__(self, sizes, passing, label="grading"):
        d = np.asarray(sizes, float)
        p = np.asarray(passing, float)
        self._u = np.log(d)
        self._p = p
        self.label = label

    @property
    def d_min(self):
        """The smallest diameter drawn (m)."""
        return float(np.exp(self._u[0]))

    @property
    def d_max(self):
        """The largest diameter drawn (m)."""
        return float(np.exp(self._u[-1]))

    @property
    def r_min(self):
        return 0.5 * self.d_min

    @property
    def r_max(self):
        return 0.5 * self.d_max

    def to_dict(self):
        """The grading as plain numbers (a checkpoint's): its table and label."""
        return {"sizes": np.exp(self._u).tolist(), "fraction": self._p.tolist(),
                "label": self.label}

    @classmethod
    def from_dict(cls, d):
        return cls(d["sizes"], d["fraction"], d.get("label", "grading"))

    def passing(self, d):
        """Percent of the mass finer than the diameter(s) ``d`` (m)."""
        u = np.log(np.maximum(np.asarray(d, float), 1e-300))
        return 100.0 * np.interp(u, self._u, self._p, left=0.0, right=1.0)

    def d(self, percent):
        """The diameter (m) that ``percent`` of the mass passes (d50: ``g.d(50)``)."""
        q = float(percent) / 100.0
        if not 0.0 <= q <= 1.0:
            raise InputError(f"percent must lie in [0, 100], got {percent!r}")
        # P is non-decreasing: invert on its rising part
        keep = np.concatenate([[True], np.diff(self._p) > 0.0])
        return float(np.exp(np.interp(q, self._p[keep], self._u[keep])))

    def sample(self, n, seed=0, dim=3, rng=None):
        """``n`` radii (m) whose mass follows the grading: spheres (``dim=3``) or
        discs of equal thickness (``dim=2``). ``rng`` (a numpy Generator) instead
        of ``seed`` continues a stream."""
        k = _dim(dim)
        if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 0:
            raise InputError(f"n must be an integer >= 0, got {n!r}")
        rng = np.random.default_rng(seed) if rng is None else rng
        u0, u1 = self._u[:-1], self._u[1:]
        du = u1 - u0
        dp = np.diff(self._p)
        w = np.where(dp > 0.0, dp / np.where(du > 0, du, 1.0)
                     * (np.exp(-k * u0) - np.exp(-k * u1)) / k, 0.0)
        if not w.sum() > 0.0:
            raise InputError(f"{self.label}: no mass to draw from")
        cell = rng.choice(len(w), size=int(n), p=w / w.sum())
        xi = rng.random(int(n))
        a, b = u0[cell], du[cell]
        u = a - np.log1p(-xi * (-np.expm1(-k * b))) / k
        return 0.5 * np.exp(u)

    def __repr__(self):
        return (f"<tdem.Grading {self.label}: d {self.d_min:.4g}–{self.d_max:.4g} m, "
                f"d50 {self.d(50):.4g} m>")


def passing_of(radii, sizes, dim=3):
    """Percent of the mass of particles of ``radii`` finer than each of ``sizes``
    (diameters, m): a sample's sieve curve, mass ∝ d³ (``dim=3``) or d² (2D)."""
    k = _dim(dim)
    d = 2.0 * np.asarray(radii, float)
    m = d ** k
    total = m.sum()
    if not total > 0.0:
        raise InputError("radii: no particles to sieve")
    s = np.asarray(sizes, float)
    return np.array([100.0 * m[d <= x].sum() / total for x in np.atleast_1d(s)])


def grading(sizes, passing, dmin=None):
    """A grading from a sieve curve: ``sizes`` the sieves' openings (m, increasing)
    and ``passing`` the percent of the mass passing each (non-decreasing, the last
    100). The mass below the smallest sieve (``passing[0]`` %) is spread down to
    ``dmin`` (default: one more interval of the first one's ratio,
    sizes[0]² / sizes[1]); a curve starting at 0 % starts there."""
    try:
        d = np.asarray(sizes, float).ravel()
        p = np.asarray(passing, float).ravel()
    except (TypeError, ValueError):
        raise InputError(f"sizes and passing must be numbers, got sizes={sizes!r}, "
                         f"passing={passing!r}") from None
    if len(d) != len(p) or len(d) < 2:
        raise InputError(f"sizes and passing must have the same length, at least 2, got "
                         f"{len(d)} and {len(p)}")
    if not (np.all(np.isfinite(d)) and np.all(d > 0) and np.all(np.diff(d) > 0)):
        raise InputError(f"sizes must be positive and increasing, got {sizes!r}")
    if not (np.all(np.isfinite(p)) and p[0] >= 0 and np.all(np.diff(p) >= 0)):
        raise InputError(f"passing must be non-decreasing percentages from >= 0, got "
                         f"{passing!r}")
    if abs(p[-1] - 100.0) > 1e-9:
        raise InputError(f"passing must end at 100 (percent through the largest sieve), "
                         f"got {passing!r}")
    if p[0] > 0.0:
        lo = d[0] * d[0] / d[1] if dmin is None else _positive("dmin", dmin)
        if lo >= d[0]:
            raise InputError(f"dmin must be below the smallest sieve {d[0]!r}, got {dmin!r}")
        d = np.concatenate([[lo], d])
        p = np.concatenate([[0.0], p])
    return Grading(d, p / 100.0, label="sieve curve")


def _closed(label, lo, hi, cdf):
    d = np.exp(np.linspace(math.log(lo), math.log(hi), _GRID + 1))
    p = cdf(d)
    p = (p - p[0]) / (p[-1] - p[0])
    return Grading(d, p, label=label)


def lognormal(d50, sigma, cut=3.0):
    """Mass lognormal in d: ln d normal about ln ``d50`` (the mass median, m) with the
    standard deviation ``sigma``, cut at ±``cut`` sigma (3: 0.27 % of the mass left
    out)."""
    d50 = _positive("d50", d50)
    sigma = _positive("sigma", sigma)
    cut = _positive("cut", cut)
    from scipy.special import ndtr
    return _closed(f"lognormal d50 {d50:g} m, sigma {sigma:g}", d50 * math.exp(-cut * sigma),
                   d50 * math.exp(cut * sigma),
                   lambda d: ndtr((np.log(d) - math.log(d50)) / sigma))


def rosin_rammler(d63, n, lo=0.001, hi=0.999):
    """Rosin–Rammler (Weibull) by mass: P(d) = 1 − exp(−(d/``d63``)^``n``), between the
    sizes passing ``lo`` and ``hi`` of the mass."""
    d63 = _positive("d63", d63)
    n = _positive("n", n)
    if not 0.0 < lo < hi < 1.0:
        raise InputError(f"lo and hi must satisfy 0 < lo < hi < 1, got {lo!r}, {hi!r}")

    def size(q):
        return d63 * (-math.log1p(-q)) ** (1.0 / n)
    return _closed(f"Rosin-Rammler d63 {d63:g} m, n {n:g}", size(lo), size(hi),
                   lambda d: -np.expm1(-(d / d63) ** n))


def uniform(dmin, dmax, dim=3):
    """Diameters uniform *by number* in [``dmin``, ``dmax``] (what the packers draw
    without a grading), as a mass curve for spheres (``dim=3``) or discs (2D):
    P(d) = (d^{k+1} − dmin^{k+1})/(dmax^{k+1} − dmin^{k+1})."""
    lo, hi = _positive("dmin", dmin), _positive("dmax", dmax)
    k = _dim(dim)
    if hi <= lo:
        raise InputError(f"dmax must exceed dmin, got dmin={dmin!r}, dmax={dmax!r}")
    return _closed(f"uniform by number {lo:g}-{hi:g} m", lo, hi, lambda d: d ** (k + 1))


grading.lognormal = lognormal
grading.rosin_rammler = rosin_rammler
grading.uniform = uniform
