"""A wet contact: a dry contact law with a pendular liquid bridge that forms where two
particles touch and ruptures beyond Lian's distance — a contact law with a range.

Between two discs or spheres the dry law (:class:`physics.linear.LinearContact` or
:class:`physics.hertz_mindlin.HertzMindlin`) acts while they overlap. When they first
touch, a bridge of the :class:`physics.liquid_bridge.LiquidBridge`'s volume forms
(the liquid on the grains' surfaces joins, as in LIGGGHTS's ``cohesion
easo/capillary`` and Yade's capillary law). From then on Willett et al.'s (2000)
force pulls the centres together, F₀ while they overlap and

    F(s) = F₀ / (1 + 2.1 Ŝ + 10 Ŝ²),   Ŝ = (s/2) sqrt(R/V),   F₀ = 2πRγ cos θ,

across a gap s, R = 2R* (the Derjaguin radius: 2R₁R₂/(R₁ + R₂) for two spheres, 2R_i
against a wall or mesh), until the gap exceeds Lian et al.'s (1993) rupture distance
s_rup = (1 + θ/2) V^(1/3), the law's range. Two particles that come within range
without touching are not joined (a bridge needs the liquid films to meet).

The Coulomb limit and the rolling resistance read the dry law's contact force (the
bridge pulls the grains together: the contact force that friction depends on grows by
what it pulls). The bridge's potential energy −U(s), U(s) = ∫_s^{s_rup} F, is in
``elastic``; the energy its forming releases, U at that step, is booked as dissipated,
so that the account stays closed (as for :meth:`tdem.Simulation.bond`'s bridges). In
2D a disc stands for a sphere of its radius in a layer of thickness 4R* (R₁ + R₂ for
equal discs; 4R_i against a wall): the force per metre is F/(4R*) = πγ cos θ while
they touch.

Against walls and meshes of this law the same holds, with R* = R_i: a particle that
touches one is wetted and held across the gap to the rupture distance. Give the walls
a dry law for no bridges to them.
"""
import math

import taichi as ti

from tdem.core.errors import InputError

from .contact_law import ContactLaw, is_registered, register_law
from .hertz_mindlin import HertzMindlin
from .linear import LinearContact
from .liquid_bridge import LiquidBridge, willett

DRY = (LinearContact, HertzMindlin)
NDRY = 6      # the dry laws' parameter columns


class WetContact(ContactLaw):
    """A dry contact law (``dry``: a :class:`LinearContact` or :class:`HertzMindlin`)
    with a pendular liquid bridge (``bridge``: a :class:`LiquidBridge`) formed at
    contact and kept to its rupture distance (module docstring)."""

    params = ("dry_kind", "bridge_force", "inv_volume", "rupture") + tuple(
        f"dry_{k}" for k in range(NDRY))
    history = ("shear", "wet")
    tangential = ("shear",)
    range = "rupture"

    def __init__(self, dry, bridge):
        if type(dry) not in DRY:
            raise InputError(f"WetContact: dry must be a tdem.LinearContact or "
                             f"tdem.HertzMindlin, got {dry!r}")
        if not isinstance(bridge, LiquidBridge):
            raise InputError(f"WetContact: bridge must be a tdem.LiquidBridge, got {bridge!r}")
        if not is_registered(WetContact):
            register_law(WetContact)
        self.dry = dry
        self.bridge = bridge
        self.rolling = dry.rolling

    @property
    def hertzian(self):
        return self.dry.hertzian

    @property
    def dry_kind(self):
        return float(DRY.index(type(self.dry)))

    @property
    def bridge_force(self):
        """2πγ cos θ: F₀ = this × R (R the Derjaguin radius 2R*)."""
        b = self.bridge
        return 2.0 * math.pi * b.surface_tension * math.cos(math.radians(b.contact_angle))

    @property
    def inv_volume(self):
        return 1.0 / self.bridge.volume

    @property
    def rupture(self):
        return self.bridge.rupture_distance

    def values(self):
        return [self.dry_kind, self.bridge_force, self.inv_volume, self.rupture] \
            + self.dry.values()

    def critical_stiffness(self, radius, mass):
        return self.dry.critical_stiffness(radius, mass)

    def critical_stiffnesses(self, radius, mass):
        return self.dry.critical_stiffnesses(radius, mass)

    def update(self, **params):
        """Change the dry law's parameters or the bridge's (``volume``,
        ``surface_tension``, ``contact_angle``); nothing changes if a value is bad."""
        keys = ("volume", "surface_tension", "contact_angle")
        wet = {k: params.pop(k) for k in keys if k in params}
        bridge = self.bridge
        if wet:
            bridge = LiquidBridge(**{**bridge.to_dict(), **wet})
        if params:
            dry = type(self.dry).from_dict(self.dry.to_dict())
            dry.update(**params)
            self.dry = dry
        self.bridge = bridge
        self.rolling = self.dry.rolling
        return self

    def to_dict(self):
        return {"type": "WetContact", "dry": self.dry.to_dict(),
                "bridge": self.bridge.to_dict()}

    @classmethod
    def _from_parts(cls, d):
        return cls(ContactLaw.from_dict(d["dry"]), LiquidBridge.from_dict(d["bridge"]))

    def __repr__(self):
        return f"WetContact(dry={self.dry!r}, bridge={self.bridge!r})"

    # ------------------------------------------------------------------ kernels
    @staticmethod
    @ti.func
    def _dry_params(q):
        return ti.Vector([q[4 + c] for c in ti.static(range(NDRY))])

    @staticmethod
    @ti.func
    def _bridge(q, u, reff, T: ti.template()):
        """(F, U) of the bridge at overlap u (gap −u); per metre in 2D (T = 1)."""
        rd = 2.0 * reff
        f0 = q[1] * rd
        k = 0.5 * ti.sqrt(rd * q[2])
        f, pot = willett(f0, k, q[3], -u)
        if ti.static(T == 1):
            f /= 4.0 * reff
            pot /= 4.0 * reff
        return f, pot

    @staticmethod
    @ti.func
    def force(q, u, vn, vt, meff, reff, dt, h):
        T = ti.static(vt.n)
        fn_el = 0.0
        fn = 0.0
        ft = vt * 0.0
        kn = 0.0
        cn = 0.0
        diss = 0.0
        hout = h
        if u > 0.0:
            qd = WetContact._dry_params(q)
            if q[0] == 0.0:
                fn_el, fn, ft, kn, cn, diss, hout = LinearContact.force(
                    qd, u, vn, vt, meff, reff, dt, h)
            else:
                fn_el, fn, ft, kn, cn, diss, hout = HertzMindlin.force(
                    qd, u, vn, vt, meff, reff, dt, h)
            if h[T] == 0.0:
                # the bridge forms: the energy its forming releases is booked
                hout[T] = 1.0
                f, pot = WetContact._bridge(q, u, reff, T)
                diss += pot
        else:
            # apart: no spring; the bridge (if formed) holds
            for c in ti.static(range(T)):
                hout[c] = 0.0
        if hout[T] != 0.0:
            f, pot = WetContact._bridge(q, u, reff, T)
            fn -= f
        return fn_el, fn, ft, kn, cn, diss, hout

    @staticmethod
    @ti.func
    def energy(q, u, reff, h, T: ti.template()):
        e = 0.0
        if u > 0.0:
            qd = WetContact._dry_params(q)
            if q[0] == 0.0:
                e = LinearContact.energy(qd, u, reff, h, T)
            else:
                e = HertzMindlin.energy(qd, u, reff, h, T)
        if h[T] != 0.0:
            f, pot = WetContact._bridge(q, u, reff, T)
            e -= pot
        return e

    @staticmethod
    @ti.func
    def stiffness(q, u, reff):
        kn = 0.0
        if u > 0.0:
            qd = WetContact._dry_params(q)
            if q[0] == 0.0:
                kn = LinearContact.stiffness(qd, u, reff)
            else:
                kn = HertzMindlin.stiffness(qd, u, reff)
        return kn
