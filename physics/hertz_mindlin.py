"""Hertz–Mindlin contact (Miyata et al. 2002, Eqs. 24–31).

Normal force N = (4/3) E* sqrt(R*) u_n^(3/2) (Eq. 24) with tangent stiffness
k_n = 2 E* sqrt(R* u_n) (Eq. 27); tangential stiffness k_s = 8 G* a with
a = (3 N R*/(4 E*))^(1/3) = sqrt(R* u_n), the "linear pressure-dependent" model of
Eq. 31, used incrementally as in the linear law, with the Coulomb limit.

Two bodies of the same material: 1/E* = 2(1 − ν²)/E, 1/G* = 2(2 − ν)/G with
G = E/(2(1 + ν)); R* = R_i R_j/(R_i + R_j) (R_i against a wall). Miyata's Eq. 26
prints R* = 2R_iR_j/(R_i+R_j) and Eq. 25 (1 − ν)²: we use the standard Hertz
forms, which go with the 4/3 prefactor. The sphere formula is used for discs, as
2D DEM codes commonly do.

A restitution coefficient e sets a normal dashpot c_n = γ sqrt(m* k_n) on the current
tangent stiffness (Tsuji, Tanaka & Ishida 1992: the damping grows as u^(1/4)). The
restitution of such a contact depends on γ alone, not on the impact speed, but not
as for a linear spring: Miyata's Eq. 17, γ = 2 ln(1/e)/sqrt(π² + ln² e), gives
e = 0.466 where 0.5 is asked. The exact γ is sqrt(5/6) times it (Antypov & Elliott
2011; the factor LIGGGHTS uses): :func:`hertz_damping`, checked in the tests against
the dimensionless contact x'' = −x^(3/2) − γ sqrt(3/2) x^(1/4) x' solved numerically.
"""
import math

import numpy as np
import taichi as ti

from .contact_law import ContactLaw, register_law, shear_spring_energy, spring_dashpot
from .validate import in_range, positive


@register_law
class HertzMindlin(ContactLaw):
    """Non-linear Hertz normal contact with Mindlin tangential stiffness."""

    params = ("e_star", "g_star", "friction", "cohesion", "damping_ratio", "_gamma")
    history = ("shear",)
    tangential = ("shear",)
    hertzian = True

    def __init__(self, *, young, poisson, friction=0.5, restitution=None, cohesion=0.0,
                 damping_ratio=0.0, rolling=None):
        self.young = positive("young", young)
        self.poisson = in_range("poisson", poisson, -1.0, 0.5, lo_open=True, hi_open=True)
        self._set_common(friction, cohesion, restitution, damping_ratio, rolling)
        if self.restitution is not None and self.restitution < 1.0:
            self._gamma = hertz_damping(self.restitution)

    @property
    def e_star(self):
        return self.young / (2.0 * (1.0 - self.poisson ** 2))

    @property
    def g_star(self):
        g = self.young / (2.0 * (1.0 + self.poisson))
        return g / (2.0 * (2.0 - self.poisson))

    @staticmethod
    @ti.func
    def force(q, u, vn, vt, meff, reff, dt, h):
        # Hertz (Miyata Eqs. 24, 27, 31): a = sqrt(R* u)
        a = ti.sqrt(reff * u)
        return spring_dashpot(4.0 / 3.0 * q[0] * a * u, 2.0 * q[0] * a, 8.0 * q[1] * a,
                              q[4], q[5], u, vn, vt, meff, q[2], q[3], dt, h)

    @staticmethod
    @ti.func
    def energy(q, u, reff, h, T: ti.template()):
        a = ti.sqrt(reff * u)
        return 0.4 * (4.0 / 3.0 * q[0] * a * u) * u + shear_spring_energy(h, 8.0 * q[1] * a, T)

    @staticmethod
    @ti.func
    def stiffness(q, u, reff):
        return 2.0 * q[0] * ti.sqrt(reff * u)

    def critical_stiffness(self, radius, mass):
        """Tangent stiffness at an overlap of 5 % of the radius (a conservative bound)."""
        kn, ks = self.critical_stiffnesses(radius, mass)
        return np.maximum(kn, ks)

    def critical_stiffnesses(self, radius, mass):
        a = (0.5 * 0.05) ** 0.5 * np.asarray(radius, dtype=float)   # sqrt(R* u), R* = R/2
        return 2.0 * self.e_star * a, 8.0 * self.g_star * a



def hertz_damping(e):
    """The dashpot γ of c_n = γ sqrt(m* k_n) that gives a Hertz contact the restitution
    e in (0, 1) (module docstring)."""
    le = math.log(1.0 / e)
    return 2.0 * math.sqrt(5.0 / 6.0) * le / math.sqrt(math.pi ** 2 + le ** 2)
