"""A pendular liquid bridge between two particles (wet granular matter).

The capillary force of a bridge of liquid volume V, surface tension γ and contact angle
θ between spheres of radii R_1, R_2 at a gap s: Willett, Adams, Johnson & Seville (2000),
"Capillary bridges between two spherical bodies", Langmuir 16:9396, Eq. 12 (their closed
form for equal spheres, with R the Derjaguin radius 2R_1R_2/(R_1 + R_2) for unequal ones):

    F(s) = 2πRγ cos θ / (1 + 2.1 Ŝ + 10 Ŝ²),   Ŝ = (s/2) sqrt(R/V)   (s ≥ 0),

F(0) for touching or overlapping particles (the contact law carries the repulsion). The
bridge ruptures at the distance of Lian, Thornton & Adams (1993), J. Colloid Interface
Sci. 161:138: s_rup = (1 + θ/2) V^(1/3) (θ in radians).

A bridge is made by :meth:`tdem.Simulation.bond` (between particles within the gap
given, as a film of liquid joins touching grains) and kept in the bond list
(:mod:`tdem.bonds`) until it ruptures. Its force pulls the two centres together along
their line. U(s) = ∫_s^{s_rup} F ds' (closed form below) is the work that separates
it: its potential energy is −U(s) (bound, below the ruptured state), in the energy
account's ``elastic``; the energy its making releases, U(s₀), is booked as dissipated,
so that the account stays closed.

In 2D a disc stands for a sphere of its radius in a layer one sphere thick: the force
per metre of thickness is F / (R_1 + R_2).
"""
import math

import numpy as np
import taichi as ti

from tdem.core.errors import InputError

from .parallel_bond import BP_CAP_F0, BP_CAP_K, BP_D0, BP_RUPTURE, BP_TYPE, BP_WIDTH
from .validate import non_negative, positive

A1, A2 = 2.1, 10.0                       # Willett's Eq. 12
_Q = math.sqrt(4.0 * A2 - A1 * A1)


@ti.func
def bridge_g(x):
    """G(x) = (2/q) atan((2·A2 x + A1)/q), the integral of 1/(1 + A1 x + A2 x²)."""
    return 2.0 / _Q * ti.atan2(2.0 * A2 * x + A1, _Q)


@ti.func
def willett(f0, k, s_rup, gap):
    """(F, U) of a bridge at the gap ``gap`` (≤ s_rup; negative: overlapping): Willett's
    F = F₀/(1 + A1 x + A2 x²), x = k·max(gap, 0), k = (1/2) sqrt(R/V), and the work
    U = ∫_gap^{s_rup} F that separates it (:func:`potential`)."""
    x = k * ti.max(gap, 0.0)
    f = f0 / (1.0 + A1 * x + A2 * x * x)
    u = f0 / k * (bridge_g(k * s_rup) - bridge_g(x)) + f0 * ti.max(-gap, 0.0)
    return f, u


class LiquidBridge:
    """A pendular liquid bridge: ``volume`` V (m³), ``surface_tension`` γ (N/m),
    ``contact_angle`` θ (degrees)."""

    def __init__(self, volume, surface_tension=0.072, contact_angle=0.0):
        self.volume = positive("volume", volume)
        self.surface_tension = positive("surface_tension", surface_tension)
        th = non_negative("contact_angle", contact_angle)
        if th >= 90.0:
            raise InputError(f"contact_angle must lie in [0, 90) degrees (a wetting "
                             f"liquid), got {contact_angle!r}")
        self.contact_angle = th

    @property
    def rupture_distance(self):
        """Lian et al.'s (1993) s_rup = (1 + θ/2) V^(1/3) (m)."""
        return (1.0 + 0.5 * math.radians(self.contact_angle)) * self.volume ** (1.0 / 3.0)

    def bridge_force(self, gap, r1, r2):
        """Willett's F (N) at the gap(s) ``gap`` (m) between spheres of radii r1, r2;
        0 beyond the rupture distance."""
        g = np.asarray(gap, float)
        rr = 2.0 * r1 * r2 / (r1 + r2)
        s_hat = 0.5 * np.maximum(g, 0.0) * math.sqrt(rr / self.volume)
        f = 2.0 * math.pi * rr * self.surface_tension * math.cos(
            math.radians(self.contact_angle)) / (1.0 + A1 * s_hat + A2 * s_hat ** 2)
        return np.where(g > self.rupture_distance, 0.0, f)

    def properties(self, ra, rb, d0, dim):
        """(B, BP_WIDTH) rows of bridges between particles of radii ``ra``, ``rb`` whose
        centres are ``d0`` apart (:mod:`tdem.bonds`)."""
        ra, rb, d0 = (np.asarray(x, float) for x in (ra, rb, d0))
        rr = 2.0 * ra * rb / (ra + rb)
        f0 = 2.0 * math.pi * rr * self.surface_tension * math.cos(
            math.radians(self.contact_angle))
        if dim == 2:
            f0 = f0 / (ra + rb)
        out = np.zeros((len(ra), BP_WIDTH))
        out[:, BP_TYPE] = 1.0
        out[:, BP_D0] = d0
        out[:, BP_CAP_F0] = f0
        out[:, BP_CAP_K] = 0.5 * np.sqrt(rr / self.volume)
        out[:, BP_RUPTURE] = self.rupture_distance
        return out

    def to_dict(self):
        return {"volume": self.volume, "surface_tension": self.surface_tension,
                "contact_angle": self.contact_angle}

    @classmethod
    def from_dict(cls, d):
        return cls(**d)

    def __repr__(self):
        return (f"LiquidBridge(volume={self.volume:g}, surface_tension="
                f"{self.surface_tension:g}, contact_angle={self.contact_angle:g})")


def potential(s, f0, k, s_rup):
    """U(s) = ∫_s^{s_rup} F ds' of a bridge (numpy): for s ≥ 0, (F₀/k)[G(k s_rup) −
    G(k s)] with G(x) = (2/q) atan((2·10 x + 2.1)/q), q = sqrt(40 − 2.1²); below 0 the
    constant F₀ over the overlap added."""
    s = np.asarray(s, float)
    g = lambda x: 2.0 / _Q * np.arctan((2.0 * A2 * x + A1) / _Q)      # noqa: E731
    sp = np.maximum(s, 0.0)
    u = f0 / k * (g(k * s_rup) - g(k * sp)) + f0 * np.maximum(-s, 0.0)
    return np.where(s > s_rup, 0.0, u)
