"""The parallel bond of Potyondy & Cundall (2004), "A bonded-particle model for rock",
Int. J. Rock Mech. Min. Sci. 41:1329–1364 (PFC's ``linearpbond``).

A bond is a cemented patch between two particles, acting in parallel with their contact
law: a disc of radius R̄ = λ min(R_A, R_B) (in 2D a rectangle 2R̄ wide, 1 m thick)
centred on the contact plane, with normal and shear stiffnesses per area
k̄_n = Ē / (R_A + R_B) and k̄_s = k̄_n / κ̄ (Ē the bond's modulus, κ̄ the stiffness
ratio). Its cross-section: area Ā = 2R̄ (2D), πR̄² (3D); moment of inertia
Ī = 2R̄³/3 (2D), πR̄⁴/4 (3D); polar J̄ = πR̄⁴/2 (3D).

Forces on particle B (the bond's second particle), compression positive:
F̄_n = k̄_n Ā (d₀ − d) along −n (n from A to B, d the centres' distance, d₀ at
bonding: the total form, exact under any rotation of the pair); the shear force,
bending and twisting moments incrementally (P&C Eqs. 10–12):
ΔF̄_s = −k̄_s Ā Δu_s, ΔM̄_b = −k̄_n Ī Δθ_b, ΔM̄_t = −k̄_s J̄ Δθ_t, with Δu_s the
tangential relative displacement of the contact point over the step and Δθ the
relative rotation (bending: its part normal to n; twisting: along n, 3D only). The
shear force and bending moment are turned with the contact plane each step (their
parts along n removed).

The largest stresses on the cross-section (P&C Eq. 13, β̄ = 1):
σ_max = −F̄_n/Ā + |M̄_b| R̄/Ī (tension positive), τ_max = |F̄_s|/Ā + |M̄_t| R̄/J̄.
The bond breaks in tension when σ_max ≥ σ̄_c, in shear when τ_max ≥ τ̄_c =
c̄ + (F̄_n/Ā) tan φ̄ (PFC 5's shear strength: compression raises it). Its elastic
energy ½F̄_n²/(k̄_nĀ) + ½|F̄_s|²/(k̄_sĀ) + ½|M̄_b|²/(k̄_nĪ) + ½|M̄_t|²/(k̄_sJ̄) is the
account's; at a break it is released (booked as dissipated).
"""
import math

import numpy as np

from tdem.core.errors import InputError

from .validate import non_negative, positive

# columns of a bond's properties (tdem.bonds: ``bprop``)
BP_KN_A, BP_KS_A, BP_KN_I, BP_KS_J = 0, 1, 2, 3
BP_D0, BP_RBAR, BP_AREA, BP_INERTIA, BP_POLAR = 4, 5, 6, 7, 8
BP_SIGMA_C, BP_COHESION, BP_TANPHI = 9, 10, 11
# the kind of bond (0 a parallel bond, 1 a liquid bridge: physics.liquid_bridge) and a
# liquid bridge's numbers
BP_TYPE = 12
BP_CAP_F0, BP_CAP_K, BP_RUPTURE = 13, 14, 15
BP_WIDTH = 16


class ParallelBond:
    """A parallel bond (Potyondy & Cundall 2004): ``young`` Ē (Pa), ``stiffness_ratio``
    κ̄ = k̄_n/k̄_s, ``tensile_strength`` σ̄_c (Pa), ``cohesion`` c̄ (Pa),
    ``friction_angle`` φ̄ (degrees), ``radius_multiplier`` λ̄ (the bond's radius over
    the smaller particle's)."""

    def __init__(self, young, stiffness_ratio=1.0, tensile_strength=math.inf,
                 cohesion=math.inf, friction_angle=0.0, radius_multiplier=1.0):
        self.young = positive("young", young)
        self.stiffness_ratio = positive("stiffness_ratio", stiffness_ratio)
        self.tensile_strength = _strength("tensile_strength", tensile_strength)
        self.cohesion = _strength("cohesion", cohesion)
        phi = non_negative("friction_angle", friction_angle)
        if phi >= 90.0:
            raise InputError(f"friction_angle must lie in [0, 90) degrees, got "
                             f"{friction_angle!r}")
        self.friction_angle = phi
        self.radius_multiplier = positive("radius_multiplier", radius_multiplier)

    def properties(self, ra, rb, d0, dim):
        """(B, BP_WIDTH) rows of bonds between particles of radii ``ra``, ``rb`` whose
        centres are ``d0`` apart."""
        ra, rb, d0 = (np.asarray(x, float) for x in (ra, rb, d0))
        kn = self.young / (ra + rb)
        ks = kn / self.stiffness_ratio
        rbar = self.radius_multiplier * np.minimum(ra, rb)
        if dim == 2:
            area, inertia, polar = 2.0 * rbar, 2.0 * rbar ** 3 / 3.0, np.zeros_like(rbar)
        else:
            area = math.pi * rbar ** 2
            inertia = math.pi * rbar ** 4 / 4.0
            polar = 2.0 * inertia
        out = np.zeros((len(ra), BP_WIDTH))
        out[:, BP_KN_A] = kn * area
        out[:, BP_KS_A] = ks * area
        out[:, BP_KN_I] = kn * inertia
        out[:, BP_KS_J] = ks * polar
        out[:, BP_D0] = d0
        out[:, BP_RBAR] = rbar
        out[:, BP_AREA] = area
        out[:, BP_INERTIA] = inertia
        out[:, BP_POLAR] = polar
        out[:, BP_SIGMA_C] = min(self.tensile_strength, 1e300)
        out[:, BP_COHESION] = min(self.cohesion, 1e300)
        out[:, BP_TANPHI] = math.tan(math.radians(self.friction_angle))
        return out

    def to_dict(self):
        return {"young": self.young, "stiffness_ratio": self.stiffness_ratio,
                "tensile_strength": self.tensile_strength, "cohesion": self.cohesion,
                "friction_angle": self.friction_angle,
                "radius_multiplier": self.radius_multiplier}

    @classmethod
    def from_dict(cls, d):
        return cls(**d)

    def __repr__(self):
        return (f"ParallelBond(young={self.young:g}, stiffness_ratio={self.stiffness_ratio:g}, "
                f"tensile_strength={self.tensile_strength:g}, cohesion={self.cohesion:g}, "
                f"friction_angle={self.friction_angle:g}, "
                f"radius_multiplier={self.radius_multiplier:g})")


def _strength(name, v):
    try:
        x = float(v)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a positive number (Pa) or math.inf, got {v!r}") \
            from None
    if not x > 0.0:
        raise InputError(f"{name} must be a positive number (Pa) or math.inf, got {v!r}")
    return x
