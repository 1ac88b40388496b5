"""Linear spring contact of Cundall & Strack (1979).

Normal: F_n = k_n u_n (total form) plus a dashpot. Shear: incremental,
F_s <- F_s + k_s v_s Δt (C&S Eqs. 15–18), capped by the Coulomb limit
|F_s| <= F_n tan(phi_mu) + c (Eq. 19) with F_n the elastic normal force.
Damping: c_n = beta k_n, c_s = beta k_s (C&S Eq. 28; the shear dashpot is off
while sliding), or a normal dashpot from a coefficient of restitution e
(Miyata Eq. 17): c_n = 2 ln(1/e) sqrt(k_n m* / (pi^2 + ln^2 e)).

The contact lasts while the overlap is positive; the normal force is not clipped
at zero, so that a restitution-based dashpot gives exactly the restitution e of
Eq. 17. The kernel side is :meth:`LinearContact.force`.
"""
import taichi as ti

from tdem.core.errors import InputError

from .contact_law import ContactLaw, register_law, shear_spring_energy, spring_dashpot
from .validate import positive


@register_law
class LinearContact(ContactLaw):
    """Linear spring–dashpot contact with Coulomb friction.

    Parameters
    ----------
    kn, ks : float
        Normal and shear stiffness (N/m, per metre of thickness in 2D). ks may be 0.
    friction : float
        Friction coefficient tan(phi_mu) (not an angle).
    cohesion : float
        Cohesion c of the Coulomb limit, a force (N).
    restitution : float or None
        Coefficient of restitution e in (0, 1]: sets the normal dashpot (Miyata Eq. 17).
    damping_ratio : float
        beta of C&S contact damping (c = beta k). Combines with ``restitution``.
    rolling : RollingResistance or None
        Rolling resistance of Jiang et al. (2005).
    """

    params = ("kn", "ks", "friction", "cohesion", "damping_ratio", "_gamma")
    history = ("shear",)
    tangential = ("shear",)

    def __init__(self, *, kn, ks=None, friction=0.5, cohesion=0.0, restitution=None,
                 damping_ratio=0.0, rolling=None):
        self.kn = positive("kn", kn)
        if ks is None:
            ks = kn
        try:
            self.ks = float(ks)
        except (TypeError, ValueError):
            raise InputError(f"ks must be a number >= 0, got {ks!r}") from None
        if not self.ks >= 0.0 or self.ks == float("inf"):
            raise InputError(f"ks must be a number >= 0, got {ks!r}")
        self._set_common(friction, cohesion, restitution, damping_ratio, rolling)

    def critical_stiffness(self, radius, mass):
        return max(self.kn, self.ks)

    def critical_stiffnesses(self, radius, mass):
        return self.kn, self.ks

    @staticmethod
    @ti.func
    def force(q, u, vn, vt, meff, reff, dt, h):
        kn = q[0]
        return spring_dashpot(kn * u, kn, q[1], q[4], q[5], u, vn, vt, meff, q[2], q[3], dt, h)

    @staticmethod
    @ti.func
    def energy(q, u, reff, h, T: ti.template()):
        return 0.5 * q[0] * u * u + shear_spring_energy(h, q[1], T)

    @staticmethod
    @ti.func
    def stiffness(q, u, reff):
        return q[0]
