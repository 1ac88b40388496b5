"""Continuum materials of PCMM particles and deformable blocks, and the
Mohr–Coulomb correction of Feng, Li & Oñate (2015), Eq. 12.

Sign conventions
----------------
Stress is **tension-positive**; pressure p = −(σxx + σyy + σzz)/3. Plane strain:
the stress of a particle is the vector s = (σxx, σyy, σxy, σzz), σzz tracked and
part of the yield check. Principal stresses are ordered σ1 ≤ σ2 ≤ σ3, so σ1 is
the most compressive one (the FLAC convention, which is also tension-positive).

Elastic constants: K = E/(3(1 − 2ν)), G = E/(2(1 + ν)); in principal axes
Δσ_i = α1 Δε_i + α2 (Δε_j + Δε_k) with α1 = K + 4G/3, α2 = K − 2G/3.
P-wave speed c_p = sqrt((K + 4G/3)/ρ).

Mohr–Coulomb with a tension cut-off (FLAC plane-strain return in principal stresses)
-------------------------------------------------------------------------------------
N_φ = (1 + sin φ)/(1 − sin φ), N_ψ = (1 + sin ψ)/(1 − sin ψ), T the tensile
strength (σt), c the cohesion.

- shear:   f_s = σ1 − σ3 N_φ + 2c sqrt(N_φ);   admissible f_s ≥ 0 (failure f_s < 0)
- tension: f_t = σ3 − T;                        admissible f_t ≤ 0 (failure f_t > 0)

(FLAC writes the tension function as T − σ3 ≥ 0; here f_t = σ3 − T, so a stress on
the surface has f = 0 for both and "inside" means f_s ≥ 0, f_t ≤ 0.) Uniaxial
compressive strength: σ_c = 2c sqrt(N_φ) = 2c cos φ/(1 − sin φ).

The tension cut-off cannot lie beyond the apex of the shear cone: when φ > 0 the
tensile strength is **capped** at T_max = c/tan φ (as FLAC does); ``tensile_strength``
keeps the value given and ``tension`` the one used. The same cap applies to the
residual values of brittle softening.

Domain split (FLAC): with α^P = sqrt(1 + N_φ²) + N_φ and σ^P = T N_φ − 2c sqrt(N_φ),
h = σ3 − T + α^P (σ1 − σ^P) is the diagonal between the shear and tension yield
lines in the (σ1, σ3) plane. A failing trial stress with h ≤ 0 returns in shear,
with h > 0 in tension:

- shear (plastic potential g_s = σ1 − σ3 N_ψ):
  λ_s = f_s(σ1, σ3)/[(α1 − α2 N_ψ) − (α2 − α1 N_ψ) N_φ],
  σ1 ← σ1 − λ_s (α1 − α2 N_ψ), σ2 ← σ2 − λ_s α2 (1 − N_ψ), σ3 ← σ3 − λ_s (α2 − α1 N_ψ)
  (λ_s < 0; the plastic principal strains are Δε1 = λ_s, Δε3 = −λ_s N_ψ);
- tension (potential g_t = −σ3):
  σ3 ← T, σ1 ← σ1 − (σ3 − T) α2/α1, σ2 ← σ2 − (σ3 − T) α2/α1.

Corners. FLAC's one-surface returns can leave the stress outside another part of the
composite surface (near the edges σ1 = σ2 or σ2 = σ3 of the cone, and near the apex
where shear and tension meet, or where two principal stresses exceed T). The
correction therefore works on the three principal values with their directions
fixed and all nine planes of the criterion written for every ordering (six shear
planes N_φ s_j − s_i − 2c sqrt(N_φ) ≤ 0, i ≠ j, and three tension planes
s_k − T ≤ 0). A return with the active planes A solves, for the multipliers
Δγ_a ≥ 0, the consistency conditions F_b(σᴵ − Σ_a Δγ_a D m_a) = 0 for every b in A
(D the elastic matrix in principal axes, m_a the flow direction of plane a: the
FLAC flow rules above). FLAC's choice (one plane, from h) is tried first; when its
result violates another plane by more than a relative 1e-12, the first admissible
active set (all Δγ ≥ 0, no plane violated) is taken, trying one plane, then two
(the cone edges, the shear–tension corner, two tension planes), then three (the
cone edge at the cut-off, the hydrostatic tension apex σ1 = σ2 = σ3 = T). When
FLAC's one-surface return is admissible — the ordinary case — the result is
exactly the FLAC result above.

Plastic shear strain increment (FLAC's shear hardening measure):
Δe^ps = sqrt(½ Σ_i (Δε_i^ps − Δε_m^ps)²), Δε_m^ps = (Σ_i Δε_i^ps)/3, summed over the
shear planes' plastic strains only (for the plain shear return this is FLAC's
sqrt(½(Δε1 − Δε_m)² + ½Δε_m² + ½(Δε3 − Δε_m)²)). A pure tension return gives 0.

Back to x–y: the in-plane principal directions do not change; with the in-plane
centre C = (σxx + σyy)/2, radius R = sqrt(((σxx − σyy)/2)² + σxy²) and
(cos 2θ, sin 2θ) = ((σxx − σyy)/2, σxy)/R (taken (1, 0) when R = 0), the new
in-plane principals (a ≤ b, a = C − R, b = C + R before the correction) give
σxx = C′ + R′ cos 2θ, σyy = C′ − R′ cos 2θ, σxy = R′ sin 2θ, C′ = (a′ + b′)/2,
R′ = (b′ − a′)/2; σzz is the third principal value, whatever its rank.

Material table
--------------
Every material packs into one row of ``MAT_WIDTH`` floats so that kernels can read
any material from one 2D array ``matp[M, col]``:

====  ==============================================================
0     type: 0 Elastic, 1 Mohr–Coulomb, 2 Fluid, 3 JWL
1     density ρ (kg/m³)
2     bulk modulus K (Pa)
3     shear modulus G (Pa) (0 for a Fluid)
4     cohesion c (Pa)                         (Mohr–Coulomb; Fluid: 1 with the
                                             equation of state; else 0)
5     tension cut-off T in use, capped (Pa)   (Mohr–Coulomb; Fluid: its tensile
                                             strength; else 0)
6     N_φ = (1 + sin φ)/(1 − sin φ)           (Mohr–Coulomb, else 1)
7     N_ψ = (1 + sin ψ)/(1 − sin ψ)           (Mohr–Coulomb, else 1)
8     brittle softening: 1 on, 0 off
9     residual cohesion c_r (Pa)               (used after first failure if brittle)
10    residual tension T_r in use, capped (Pa)
11    dynamic viscosity μ (Pa·s)              (Fluid, else 0)
12    linear artificial bulk viscosity b1      (Fluid, JWL; else 0)
13    quadratic artificial bulk viscosity b2   (Fluid, JWL; else 0)
14    √N_φ                                     (Mohr–Coulomb, else 0: columns 14–16
15    a_p = √(1 + N_φ²) + N_φ (FLAC's split)    are constants of the return mapping)
16    Δe^ps/Δγ of the shear return
====  ==============================================================

A JWL row uses columns 4–10 for A, B, R1, R2, ω, E0 (Pa) and D (m/s); its column 2
is ρ0·D², so that the signal speed sqrt(K/ρ0) the time step uses is the detonation
speed.

Artificial bulk viscosity (von Neumann–Richtmyer with a linear term, as in
hydrocodes): an element whose area shrinks (Δθ < 0) adds the pressure
q = ρ L |θ̇| (b1 c + b2 L |θ̇|), L = sqrt(S), c = sqrt((K + 4G/3)/ρ), to the stress
of its nodal forces for that step (not to the stress it keeps). It spreads a shock
over a few elements instead of letting it ring.
"""
import math

import numpy as np
import taichi as ti

from tdem.core.errors import InputError

from .validate import in_range, non_negative, positive

MAT_WIDTH = 17
# the columns of a material row (module docstring: the material table)
(MAT_TYPE, MAT_RHO, MAT_K, MAT_G, MAT_COH, MAT_TEN, MAT_NPHI, MAT_NPSI, MAT_BRITTLE,
 MAT_COH_R, MAT_TEN_R, MAT_VISC, MAT_B1, MAT_B2, MAT_SQ_NPHI, MAT_AP,
 MAT_DEPS) = range(MAT_WIDTH)
MAT_EOS = MAT_COH          # a Fluid row: 1 with the equation of state
MAT_FLUID_TAU = MAT_BRITTLE  # a Fluid row: the relaxation time of its shear stress
MAT_CELLS = MAT_SQ_NPHI    # a Fluid row: 1 with the pressure of Voronoi cells
# a JWL row's columns 4-10, and 14: 1 when its particles swell (JWL.swelling)
JWL_A, JWL_B, JWL_R1, JWL_R2, JWL_OMEGA, JWL_E0, JWL_D = range(4, 11)
JWL_SWELL = MAT_SQ_NPHI
ELASTIC, MOHR_COULOMB, FLUID, JWL_TYPE = 0, 1, 2, 3
NO_FAILURE, SHEAR_FAILURE, TENSION_FAILURE = 0, 1, 2


def _n_angle(deg):
    s = math.sin(math.radians(deg))
    return (1.0 + s) / (1.0 - s)


def _tension_cap(cohesion, friction_angle):
    """T_max = c/tan φ (infinite for φ = 0)."""
    if friction_angle == 0.0:
        return math.inf
    return cohesion / math.tan(math.radians(friction_angle))


class Material:
    """Base class of continuum materials: validation, derived moduli, table row."""

    bulk = 0.0
    shear = 0.0
    density = 0.0

    @property
    def p_wave_speed(self):
        """c_p = sqrt((K + 4G/3)/ρ) (m/s)."""
        return math.sqrt((self.bulk + 4.0 * self.shear / 3.0) / self.density)

    def row(self):
        raise NotImplementedError

    def _elastic(self, density, young, poisson):
        self.density = positive("density", density)
        self.young = positive("young", young)
        self.poisson = in_range("poisson", poisson, -1.0, 0.5, lo_open=True, hi_open=True)
        self.bulk = self.young / (3.0 * (1.0 - 2.0 * self.poisson))
        self.shear = self.young / (2.0 * (1.0 + self.poisson))

    def to_dict(self):
        d = {k: v for k, v in self.__dict__.items()
             if not k.startswith("_") and k in self._ARGS}
        d["type"] = type(self).__name__
        return d

    @staticmethod
    def from_dict(d):
        d = dict(d)
        kind = d.pop("type", None)
        classes = {"Elastic": Elastic, "MohrCoulomb": MohrCoulomb, "Fluid": Fluid,
                   "JWL": JWL}
        if kind not in classes:
            raise InputError(f"type must be one of {sorted(classes)}, got {kind!r}")
        if kind == "JWL":
            d.setdefault("swelling", False)    # written before the gas could swell
        return classes[kind](**d)

    def __repr__(self):
        args = ", ".join(f"{k}={v!r}" for k, v in self.to_dict().items() if k != "type")
        return f"{type(self).__name__}({args})"

    def __eq__(self, other):
        return type(self) is type(other) and self.to_dict() == other.to_dict()

    def __hash__(self):
        return hash(tuple(sorted(self.to_dict().items())))


class Elastic(Material):
    """Linear isotropic elasticity (plane strain, σzz tracked).

    Parameters
    ----------
    density : ρ (kg/m³), > 0
    young : Young's modulus E (Pa), > 0
    poisson : Poisson's ratio ν in (−1, 0.5)

    K = E/(3(1 − 2ν)), G = E/(2(1 + ν)). ``mc_correct`` leaves the stress unchanged.
    """

    _ARGS = ("density", "young", "poisson")

    def __init__(self, *, density=2500.0, young=30e9, poisson=0.25):
        self._elastic(density, young, poisson)

    def row(self):
        return [float(ELASTIC), self.density, self.bulk, self.shear,
                0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]


class MohrCoulomb(Material):
    """Elastic–plastic Mohr–Coulomb with a tension cut-off (FLAC plane strain).

    Parameters
    ----------
    density, young, poisson : as :class:`Elastic`
    cohesion : c (Pa), ≥ 0
    friction_angle : φ in degrees, in [0, 90)
    tensile_strength : T (Pa), ≥ 0; capped at c/tan φ when φ > 0 (the value in use
        is ``tension``). Default None: the Mohr–Coulomb apex c/tan φ (the largest
        tension the envelope allows), and 0 when φ = 0 (as FLAC)
    dilation_angle : ψ in degrees, in [0, φ] (0: no plastic volume change)
    brittle : after a particle's first failure its c and T drop to the residual values
    residual_cohesion, residual_tensile_strength : c_r, T_r (Pa), ≥ 0, default 0;
        c_r ≤ c and T_r ≤ T

    Yield functions, flow rules and the return are in the module docstring.
    """

    _ARGS = ("density", "young", "poisson", "cohesion", "friction_angle",
             "tensile_strength", "dilation_angle", "brittle", "residual_cohesion",
             "residual_tensile_strength")

    def __init__(self, *, density=2500.0, young=30e9, poisson=0.25, cohesion=3e6,
                 friction_angle=40.0, tensile_strength=None, dilation_angle=0.0,
                 brittle=False, residual_cohesion=0.0, residual_tensile_strength=0.0):
        self._elastic(density, young, poisson)
        self.cohesion = non_negative("cohesion", cohesion)
        self.friction_angle = in_range("friction_angle", friction_angle, 0.0, 90.0,
                                       hi_open=True)
        if tensile_strength is None:
            tensile_strength = (_tension_cap(self.cohesion, self.friction_angle)
                                if self.friction_angle > 0.0 else 0.0)
        self.tensile_strength = non_negative("tensile_strength", tensile_strength)
        self.dilation_angle = in_range("dilation_angle", dilation_angle, 0.0,
                                       self.friction_angle)
        if isinstance(brittle, str) or brittle not in (0, 1):
            raise InputError(f"brittle must be True or False, got {brittle!r}")
        self.brittle = bool(brittle)
        self.residual_cohesion = in_range("residual_cohesion", residual_cohesion,
                                          0.0, self.cohesion)
        self.residual_tensile_strength = in_range(
            "residual_tensile_strength", residual_tensile_strength, 0.0,
            self.tensile_strength)
        if self.friction_angle == 0.0 and self.cohesion == 0.0:
            raise InputError("cohesion must be > 0 when friction_angle is 0 "
                             "(no shear strength at all), got cohesion=0")

    @property
    def n_phi(self):
        return _n_angle(self.friction_angle)

    @property
    def n_psi(self):
        return _n_angle(self.dilation_angle)

    @property
    def tension(self):
        """Tension cut-off in use: min(T, c/tan φ)."""
        return min(self.tensile_strength, _tension_cap(self.cohesion, self.friction_angle))

    @property
    def residual_tension(self):
        return min(self.residual_tensile_strength,
                   _tension_cap(self.residual_cohesion, self.friction_angle))

    @property
    def compressive_strength(self):
        """Uniaxial compressive strength 2c cos φ/(1 − sin φ) = 2c sqrt(N_φ)."""
        return 2.0 * self.cohesion * math.sqrt(self.n_phi)

    def row(self):
        return [float(MOHR_COULOMB), self.density, self.bulk, self.shear,
                self.cohesion, self.tension, self.n_phi, self.n_psi,
                1.0 if self.brittle else 0.0, self.residual_cohesion,
                self.residual_tension, 0.0, 0.0, 0.0] + self._return_constants()

    def _return_constants(self):
        """Columns 14–16, constants of the return mapping (``mc_correct_state``):
        √N_φ, FLAC's a_p = √(1 + N_φ²) + N_φ, and Δe^ps/Δγ of the shear return."""
        nphi, npsi = self.n_phi, self.n_psi
        mu = (npsi - 1.0) / 3.0
        return [math.sqrt(nphi), math.sqrt(1.0 + nphi * nphi) + nphi,
                math.sqrt(0.5 * ((1.0 + mu) * (1.0 + mu) + (npsi - mu) * (npsi - mu)
                                 + mu * mu))]


class Fluid(Material):
    """Water-like material (Feng et al. §4.3): G = 0, bulk modulus K.

    Parameters
    ----------
    density : ρ0 (kg/m³), > 0, the density at zero pressure
    bulk_modulus : K (Pa), > 0 (the paper: 2 GPa; a case may lower it to a weakly
        compressible value, c = sqrt(K/ρ0) ≥ 10 × the largest flow speed)
    viscosity : dynamic viscosity μ (Pa·s), ≥ 0: the stress 2μ·dev(D) on the
        element forces of each step (not accumulated)
    linear_viscosity, quadratic_viscosity : artificial bulk viscosity b1, b2 ≥ 0
        (dimensionless; module docstring; 0 = off)
    tensile_strength : only with ``equation_of_state``: the largest tension
        (negative pressure) the fluid carries, Pa, ≥ 0 (default 0)
    equation_of_state : False (default): the pressure is the elements'
        incremental stress of Eqs. 6–11 with G = 0, as for the solids (each
        element carries its own stress from step to step; a new element starts
        from the mean of its particles' stresses). True: the pressure is a state
        of the particles, p = max(K·(1/V − 1), −tensile_strength), V the relative
        volume each particle carries (changed by a third of Σ_e (S_e/N_e)·ΔS_e
        over the elements containing it, divided by its initial volume M_i/ρ0:
        the JWL bookkeeping of :func:`physics.pcmm.equation_of_state`, the mean
        of that sum over the step's elements and over those that pushed over
        it); an element pushes with the
        mean pressure of its three particles, plus the viscous stress and q.
    shear_modulus : G_s (Pa), ≥ 0 and below K (default 0); with
        ``relaxation_time`` > 0 it makes a Maxwell fluid (below). Incremental
        pressure only.
    relaxation_time : τ (s), ≥ 0; > 0 whenever ``shear_modulus`` is.
    voronoi : False (default): the pressure of the elements (above). True: the
        body makes no elements; each particle's pressure is K·max(A0/A − 1, 0) from
        the area A of its Voronoi cell among the particles of its body (cut by the
        walls and by a disc of 2.5 × the body's mean radius), A0 = m/ρ0, the
        masses ρ0 × the cells of the initial packing (:mod:`physics.pcmm.cells`);
        ``viscosity`` acts between neighbouring cells, μ Σ (l/d)(v_j − v_i), and
        the artificial bulk viscosities on each shrinking cell as on an element.
        Not with ``equation_of_state``, ``tensile_strength`` or a shear modulus.

    Model choices
    -------------
    - Contacts between water particles: two particles of one Fluid body that are
      Eq. 1 neighbours never meet through the contact law; they repel through the
      core force of :func:`physics.pcmm.fluid_core_force`, K·max(0, 0.75·(R_i +
      R_j) − d), a function of their distance only. With G = 0 the triangles
      resist only area changes, so two particles of one triangle can approach
      each other at constant area until the Eq. 2 angle check deletes it, and the
      contact law would then switch on a large force in one step. The core force
      does no work unless two particles overlap by a quarter of their radii, far
      beyond the water's compression (p/K < 1 %), so it leaves the pressure alone.
    - Packing: the elements' water (incremental pressure) comes to rest on a
      square lattice; on a hexagonal lattice or a random packing the elements do
      not hold it still (zero-energy modes of the G = 0 triangles, triangles of a
      random packing that do not tile the body), and the equation of state creeps
      even on the square lattice. ``voronoi=True`` is the option for water packed
      otherwise: the Voronoi cells tile every packing.
    - Maxwell fluid (``shear_modulus`` G_s > 0 with ``relaxation_time`` τ > 0):
      the triangles carry a shear stress 2G_s·dev(Δε) whose deviatoric part
      relaxes by exp(−Δt/τ) every step (the mean stress is kept), so that over
      times shorter than τ the lattice's zero-energy modes meet a shear stiffness
      and at rest the stress relaxes to the hydrostatic one. Over times longer
      than τ it flows with the viscosity η = G_s·τ: it suits a slow, viscous body
      or a reservoir at rest, not water that must both rest and flow on a
      hexagonal packing.

    measurements: docs/pcmm.md
    """

    _ARGS = ("density", "bulk_modulus", "viscosity", "linear_viscosity",
             "quadratic_viscosity", "tensile_strength", "equation_of_state",
             "shear_modulus", "relaxation_time", "voronoi")

    def __init__(self, *, density=1000.0, bulk_modulus=2e9, viscosity=0.0,
                 linear_viscosity=0.0, quadratic_viscosity=0.0, tensile_strength=0.0,
                 equation_of_state=False, shear_modulus=0.0, relaxation_time=0.0,
                 voronoi=False):
        self.density = positive("density", density)
        self.bulk_modulus = positive("bulk_modulus", bulk_modulus)
        self.viscosity = non_negative("viscosity", viscosity)
        self.linear_viscosity = non_negative("linear_viscosity", linear_viscosity)
        self.quadratic_viscosity = non_negative("quadratic_viscosity", quadratic_viscosity)
        self.tensile_strength = non_negative("tensile_strength", tensile_strength)
        if equation_of_state not in (True, False):
            raise InputError(f"equation_of_state must be True or False, got "
                             f"{equation_of_state!r}")
        self.equation_of_state = bool(equation_of_state)
        self.shear_modulus = non_negative("shear_modulus", shear_modulus)
        self.relaxation_time = non_negative("relaxation_time", relaxation_time)
        if self.shear_modulus > 0.0 and self.equation_of_state:
            raise InputError("shear_modulus needs the elements' incremental stress: it "
                             "cannot be used with equation_of_state=True")
        if self.shear_modulus > 0.0 and self.relaxation_time == 0.0:
            raise InputError(f"shear_modulus={shear_modulus!r} needs a relaxation_time > 0 "
                             f"(without one the water would be an elastic solid)")
        if self.shear_modulus >= self.bulk_modulus:
            raise InputError(f"shear_modulus must be below bulk_modulus={bulk_modulus!r}, "
                             f"got {shear_modulus!r}")
        if voronoi not in (True, False):
            raise InputError(f"voronoi must be True or False, got {voronoi!r}")
        self.voronoi = bool(voronoi)
        if self.voronoi:
            for name in ("tensile_strength", "shear_modulus", "relaxation_time"):
                if getattr(self, name) != 0.0:
                    raise InputError(f"{name}={getattr(self, name)!r} is an option of the "
                                     f"elements' pressure: it cannot be used with voronoi=True")
            if self.equation_of_state:
                raise InputError("voronoi=True is an equation of state of its own (the cells' "
                                 "areas): it cannot be used with equation_of_state=True")
        self.bulk = self.bulk_modulus
        self.shear = self.shear_modulus

    def pressure(self, V):
        """Equation of state p(V) of ``equation_of_state=True`` (numpy)."""
        V = np.asarray(V, dtype=float)
        return np.maximum(self.bulk * (1.0 / V - 1.0), -self.tensile_strength)

    def row(self):
        # column 4: 1 with the equation of state; column 5 (the tension cut-off of
        # a Mohr–Coulomb row) the fluid's tensile strength
        return [float(FLUID), self.density, self.bulk, self.shear,
                1.0 if self.equation_of_state else 0.0, self.tensile_strength, 1.0, 1.0,
                self.relaxation_time, 0.0, 0.0, self.viscosity,
                self.linear_viscosity, self.quadratic_viscosity,
                1.0 if self.voronoi else 0.0, 0.0, 0.0]


class JWL(Material):
    """Detonation products of a high explosive, Jones–Wilkins–Lee (Feng et al. Eq. 25):

        p = A (1 − ω/(R1 V)) e^(−R1 V) + B (1 − ω/(R2 V)) e^(−R2 V) + ω E/V,

    V = ρ0/ρ the relative volume and E the internal energy per unit initial volume
    (Pa), both tracked per particle (:func:`physics.pcmm.equation_of_state`): V from
    the volume changes of its elements, dE = −(p + q) dV with q the artificial bulk
    viscosity and p the mean of the pressures before and after the step's change.
    G = 0: a particle's stress is −p·I.

    Programmed burn: :meth:`tdem.Simulation.detonate` gives each particle its
    lighting time t_l = t0 + |x − x_det|/D; its pressure is F·p with the burn
    fraction F = min(1, (t − t_l)·D/(3R)) for t ≥ t_l (0 before: the front crosses
    one particle diameter and a half), R the particle radius.

    Swelling (``swelling=True``, the default): the radius a particle's element
    rules see (Eqs. 1–3) grows with the volume its gas fills, s·R0 + δ(s − 1)/2
    with s = sqrt(max(V, 1)), so that the Eq. 1 cut-off R_i + R_j + δ of two
    particles that expanded alike grows as their distance does: the products'
    triangles stay joined as the gas expands and keep pushing on what confines
    it. Without it a triangle of the gas breaks once an edge exceeds R_i + R_j +
    δ: on a square lattice with δ = R the diagonals go at V = 1.125 of a uniform
    expansion, and from then on the gas pushes only through the contact law of
    its particles, which does not depend on V. The contact radius, the
    mass and the burn fraction keep R0. The rule radius of each particle is
    updated at the end of every step from its V (:func:`physics.pcmm.swell`): a
    particle whose rule radius changed rebuilds its elements, and one whose
    displacement plus growth since the neighbour lists were built exceeds half
    the skin asks for a new build, so the Eq. 1 candidates stay complete.

    Parameters
    ----------
    A, B : Pa, > 0;  R1, R2 : > 0;  omega : ω > 0;  E0 : initial internal energy per
    unit volume (Pa), > 0;  density : ρ0 (kg/m³), > 0;  D : detonation speed (m/s), > 0
    linear_viscosity, quadratic_viscosity : artificial bulk viscosity b1, b2 ≥ 0
        (module docstring), default 0.06 and 1.5 (the usual hydrocode values)
    swelling : True (default) or False, above

    The time step uses D as the signal speed (the column K = ρ0 D²), and the
    default contact stiffness of its particles (contact law against other bodies)
    is ρ0 D².
    """

    _ARGS = ("A", "B", "R1", "R2", "omega", "E0", "density", "D", "linear_viscosity",
             "quadratic_viscosity", "swelling")

    def __init__(self, *, A, B, R1, R2, omega, E0, density, D, linear_viscosity=0.06,
                 quadratic_viscosity=1.5, swelling=True):
        self.A = positive("A", A)
        self.B = positive("B", B)
        self.R1 = positive("R1", R1)
        self.R2 = positive("R2", R2)
        self.omega = positive("omega", omega)
        self.E0 = positive("E0", E0)
        self.density = positive("density", density)
        self.D = positive("D", D)
        self.linear_viscosity = non_negative("linear_viscosity", linear_viscosity)
        self.quadratic_viscosity = non_negative("quadratic_viscosity", quadratic_viscosity)
        if swelling not in (True, False):
            raise InputError(f"swelling must be True or False, got {swelling!r}")
        self.swelling = bool(swelling)
        self.bulk = self.density * self.D ** 2
        self.shear = 0.0
        self.young = self.bulk

    @classmethod
    def tnt(cls, **kw):
        """TNT: A = 371.2 GPa, B = 3.2 GPa, R1 = 4.2, R2 = 0.95, ω = 0.3 (Feng et al.);
        ρ0 = 1630 kg/m³, E0 = 7.0 GPa, D = 6930 m/s (the standard values the paper
        leaves out). Keyword arguments override any of them."""
        args = dict(A=371.2e9, B=3.2e9, R1=4.2, R2=0.95, omega=0.3, E0=7.0e9,
                    density=1630.0, D=6930.0)
        args.update(kw)
        return cls(**args)

    def pressure(self, V, E):
        """Eq. 25 at relative volume V and internal energy E per unit initial volume."""
        V = np.asarray(V, dtype=float)
        E = np.asarray(E, dtype=float)
        p = (self.A * (1.0 - self.omega / (self.R1 * V)) * np.exp(-self.R1 * V)
             + self.B * (1.0 - self.omega / (self.R2 * V)) * np.exp(-self.R2 * V)
             + self.omega * E / V)
        return p if p.ndim else float(p)

    def row(self):
        return [float(JWL_TYPE), self.density, self.bulk, 0.0,
                self.A, self.B, self.R1, self.R2, self.omega, self.E0, self.D, 0.0,
                self.linear_viscosity, self.quadratic_viscosity,
                1.0 if self.swelling else 0.0, 0.0, 0.0]


@ti.func
def jwl_pressure(matp: ti.template(), M, V, E):
    """Eq. 25 of the JWL row M at relative volume V and energy E (per initial volume)."""
    A, B, R1, R2, w = (matp[M, JWL_A], matp[M, JWL_B], matp[M, JWL_R1], matp[M, JWL_R2],
                       matp[M, JWL_OMEGA])
    return (A * (1.0 - w / (R1 * V)) * ti.exp(-R1 * V)
            + B * (1.0 - w / (R2 * V)) * ti.exp(-R2 * V) + w * E / V)


@ti.func
def fluid_pressure(matp: ti.template(), M, V):
    """Equation of state of the Fluid row M at relative volume V (:class:`Fluid`)."""
    return ti.max(matp[M, MAT_K] * (1.0 / V - 1.0), -matp[M, MAT_TEN])


# ------------------------------------------------------------------ kernel side
@ti.func
def _plane(k, nphi, npsi, sq, coh, ten):
    """Plane k of the composite criterion on unsorted principal values s (3,).

    k < 6: shear plane (i, j) = (k // 2, the k % 2-th other index):
    F = N_φ s_j − s_i − 2c sqrt(N_φ) ≤ 0, flow m_i = −1, m_j = N_ψ.
    k ≥ 6: tension plane F = s_(k−6) − T ≤ 0, flow m_(k−6) = 1.
    Returns (gradient n, constant, flow m): F = n·s + constant.
    """
    n = ti.Vector([0.0, 0.0, 0.0])
    m = ti.Vector([0.0, 0.0, 0.0])
    const = 0.0
    if k < 6:
        i = k // 2
        j = k % 2
        if j >= i:
            j += 1
        for q in ti.static(range(3)):
            if q == i:
                n[q] = -1.0
                m[q] = -1.0
            if q == j:
                n[q] = nphi
                m[q] = npsi
        const = -2.0 * coh * sq
    else:
        for q in ti.static(range(3)):
            if q == k - 6:
                n[q] = 1.0
                m[q] = 1.0
        const = -ten
    return n, const, m


@ti.func
def _dmul(v, a1, a2):
    """Elastic matrix in principal axes times v: α1 v_i + α2 (v_j + v_k)."""
    tr = v[0] + v[1] + v[2]
    return (a1 - a2) * v + a2 * tr * ti.Vector([1.0, 1.0, 1.0])


@ti.func
def _admissible(q, nphi, sq, coh, ten, tol):
    """Whether principal values q violate none of the nine planes by more than tol:
    the tension planes bind at the largest value, the shear planes at the pair
    (largest, smallest) (i ≠ j: when all three are equal any pair gives the same)."""
    smax = ti.max(q[0], ti.max(q[1], q[2]))
    smin = ti.min(q[0], ti.min(q[1], q[2]))
    return smax - ten <= tol and nphi * smax - smin - 2.0 * coh * sq <= tol


@ti.func
def _first_admissible(p, nphi, npsi, sq, coh, ten, a1, a2, tol):
    """The first admissible active set (all Δγ ≥ 0, no plane violated by more than
    tol) in the order: one plane (0–8), two planes, three planes, each
    lexicographically; the planes' gradients n_k, D m_k and values F_k(p) are
    tabulated once. For a set S: Σ_{c∈S} (n_b·D m_c) Δγ_c = F_b(p) for every b in S
    (dependent planes, |det| ≤ 1e-10 × the product of the rows' sizes, fail); the
    principals are then p − Σ Δγ_c D m_c. Returns (ok, act, nact, Δγ, principals)."""
    N = ti.Matrix.zero(ti.f64, 9, 3)
    Dm = ti.Matrix.zero(ti.f64, 9, 3)
    F = ti.Vector.zero(ti.f64, 9)
    for k in ti.static(range(9)):
        nk, ck, mk = _plane(k, nphi, npsi, sq, coh, ten)
        dk = _dmul(mk, a1, a2)
        for j in ti.static(range(3)):
            N[k, j] = nk[j]
            Dm[k, j] = dk[j]
        F[k] = nk.dot(p) + ck
    ok = 0
    act = ti.Vector([0, 0, 0])
    nact = 1
    g = ti.Vector([0.0, 0.0, 0.0])
    q = p
    for a in ti.static(range(9)):
        if ok == 0:
            da = ti.Vector([Dm[a, 0], Dm[a, 1], Dm[a, 2]])
            A = N[a, 0] * da[0] + N[a, 1] * da[1] + N[a, 2] * da[2]
            if A != 0.0:
                ga = F[a] / A
                if ga >= 0.0:
                    qa = p - ga * da
                    if _admissible(qa, nphi, sq, coh, ten, tol):
                        ok = 1
                        act = ti.Vector([a, 0, 0])
                        g = ti.Vector([ga, 0.0, 0.0])
                        q = qa
    for a in range(9):
        if ok != 0:
            break
        for b in range(a + 1, 9):
            if ok == 0:
                na = ti.Vector([N[a, 0], N[a, 1], N[a, 2]])
                nb = ti.Vector([N[b, 0], N[b, 1], N[b, 2]])
                da = ti.Vector([Dm[a, 0], Dm[a, 1], Dm[a, 2]])
                db = ti.Vector([Dm[b, 0], Dm[b, 1], Dm[b, 2]])
                A00 = na.dot(da)
                A01 = na.dot(db)
                A10 = nb.dot(da)
                A11 = nb.dot(db)
                det = A00 * A11 - A01 * A10
                size = (ti.abs(A00) + ti.abs(A01)) * (ti.abs(A10) + ti.abs(A11))
                if ti.abs(det) > 1e-10 * size:
                    g0 = (A11 * F[a] - A01 * F[b]) / det
                    g1 = (A00 * F[b] - A10 * F[a]) / det
                    if g0 >= 0.0 and g1 >= 0.0:
                        qa = p - g0 * da - g1 * db
                        if _admissible(qa, nphi, sq, coh, ten, tol):
                            ok = 1
                            act = ti.Vector([a, b, 0])
                            nact = 2
                            g = ti.Vector([g0, g1, 0.0])
                            q = qa
    for a in range(9):
        if ok != 0:
            break
        for b in range(a + 1, 9):
            if ok != 0:
                break
            for c in range(b + 1, 9):
                if ok == 0:
                    na = ti.Vector([N[a, 0], N[a, 1], N[a, 2]])
                    nb = ti.Vector([N[b, 0], N[b, 1], N[b, 2]])
                    nc = ti.Vector([N[c, 0], N[c, 1], N[c, 2]])
                    da = ti.Vector([Dm[a, 0], Dm[a, 1], Dm[a, 2]])
                    db = ti.Vector([Dm[b, 0], Dm[b, 1], Dm[b, 2]])
                    dc = ti.Vector([Dm[c, 0], Dm[c, 1], Dm[c, 2]])
                    A = ti.Matrix([[na.dot(da), na.dot(db), na.dot(dc)],
                                   [nb.dot(da), nb.dot(db), nb.dot(dc)],
                                   [nc.dot(da), nc.dot(db), nc.dot(dc)]])
                    size = 1.0
                    for r in ti.static(range(3)):
                        size *= ti.abs(A[r, 0]) + ti.abs(A[r, 1]) + ti.abs(A[r, 2])
                    det = A.determinant()
                    if ti.abs(det) > 1e-10 * size:
                        g3 = A.inverse() @ ti.Vector([F[a], F[b], F[c]])
                        if g3[0] >= 0.0 and g3[1] >= 0.0 and g3[2] >= 0.0:
                            q3 = p - g3[0] * da - g3[1] * db - g3[2] * dc
                            if _admissible(q3, nphi, sq, coh, ten, tol):
                                ok = 1
                                act = ti.Vector([a, b, c])
                                nact = 3
                                g = g3
                                q = q3
    return ok, act, nact, g, q


@ti.func
def relax_shear(s, tau, dt):
    """A Fluid's stress (σxx, σyy, σxy, σzz) with its deviatoric part relaxed over a
    step by exp(−Δt/τ) (a Maxwell fluid, :class:`Fluid` ``relaxation_time``); the
    mean stress is kept; τ = 0: unchanged (bitwise)."""
    out = s
    if tau > 0.0:
        p = (s[0] + s[1] + s[3]) / 3.0
        f = ti.exp(-dt / tau)
        out = ti.Vector([p + f * (s[0] - p), p + f * (s[1] - p), f * s[2], p + f * (s[3] - p)])
    return out


@ti.func
def mixes(matp: ti.template(), M):
    """Whether the elements of material row M take the nodal mixed discretization
    (:mod:`physics.fvm`): Mohr–Coulomb, whose plastic flow at constant volume locks
    constant-strain triangles. Elastic rows keep their own update (no flow to lock
    at the Poisson's ratios of rock and soil), and so do fluids and the materials
    with an equation of state (which carry their pressure per particle)."""
    return ti.cast(matp[M, MAT_TYPE], ti.i32) == MOHR_COULOMB


@ti.func
def mc_correct_state(s, matp: ti.template(), M, failed):
    """Mohr–Coulomb + tension cut-off correction of a trial stress (module docstring).

    s: trial stress (σxx, σyy, σxy, σzz), tension-positive; M: row of ``matp``;
    failed: nonzero when the particle has failed before (brittle softening then uses
    the residual c_r, T_r of columns 9–10).
    Returns (corrected stress, plastic shear strain increment Δe^ps ≥ 0, flag:
    0 no failure, 1 shear (a shear plane is active, alone or at a corner with the
    cut-off), 2 tension only). Elastic and Fluid rows return s unchanged. A kernel
    doing brittle softening marks the particle failed once flag > 0.
    A stress inside the surface is returned unchanged (bitwise).
    """
    out = s
    eps = 0.0
    flag = NO_FAILURE
    kind = ti.cast(matp[M, MAT_TYPE], ti.i32)
    if kind == MOHR_COULOMB:
        K = matp[M, MAT_K]
        G = matp[M, MAT_G]
        coh = matp[M, MAT_COH]
        ten = matp[M, MAT_TEN]
        if failed != 0 and matp[M, MAT_BRITTLE] != 0.0:
            coh = matp[M, MAT_COH_R]
            ten = matp[M, MAT_TEN_R]
        nphi = matp[M, MAT_NPHI]
        npsi = matp[M, MAT_NPSI]
        sq = matp[M, MAT_SQ_NPHI]
        a1 = K + 4.0 * G / 3.0
        a2 = K - 2.0 * G / 3.0
        # in-plane principal values a ≤ b, direction (cos 2θ, sin 2θ) of b
        cen = 0.5 * (s[0] + s[1])
        d = 0.5 * (s[0] - s[1])
        rad = ti.sqrt(d * d + s[2] * s[2])
        p = ti.Vector([cen - rad, cen + rad, s[3]])
        # sorted: i1 (most compressive), i3 (most tensile)
        i1 = 0
        i3 = 1
        s1 = p[0]
        s3 = p[1]
        if p[2] < p[0]:
            i1 = 2
            s1 = p[2]
        elif p[2] > p[1]:
            i3 = 2
            s3 = p[2]
        fs = s1 - s3 * nphi + 2.0 * coh * sq
        ft = s3 - ten
        if fs < 0.0 or ft > 0.0:
            scale = ti.abs(p[0]) + ti.abs(p[1]) + ti.abs(p[2]) + coh + ten
            tol = 1e-12 * scale
            # FLAC's domain split
            ap = matp[M, MAT_AP]
            sp = ten * nphi - 2.0 * coh * sq
            h = s3 - ten + ap * (s1 - sp)
            # FLAC's one-plane return, in closed form: Δγ = F/(n·D m), q = p − Δγ D m
            # with D m = (α1 − α2) m + α2 (Σ m) (1, 1, 1)
            g1 = 0.0
            d1 = 0.0       # (D m) at i1, i3 and the third value
            d3 = 0.0
            d2 = 0.0
            shear = h <= 0.0 and fs < 0.0
            if shear:
                # plane (i1, i3): F = N_φ s_i3 − s_i1 − 2c√N_φ = −f_s, m_i1 = −1, m_i3 = N_ψ
                d2 = a2 * (npsi - 1.0)
                d1 = d2 - (a1 - a2)
                d3 = d2 + (a1 - a2) * npsi
                g1 = -fs / (nphi * d3 - d1)
                # Δe^ps = Δγ·sqrt(½ |m − mean(m)|²), m = (−1, N_ψ, 0) by rank
                eps = g1 * matp[M, MAT_DEPS]
                flag = SHEAR_FAILURE
            else:
                # tension plane i3: F = s_i3 − T, m_i3 = 1
                d1 = a2
                d2 = a2
                d3 = a1
                g1 = ft / a1
                flag = TENSION_FAILURE
            q = ti.Vector([0.0, 0.0, 0.0])
            for k in ti.static(range(3)):
                dk = d2
                if k == i1:
                    dk = d1
                elif k == i3:
                    dk = d3
                q[k] = p[k] - g1 * dk
            ok = 0
            if g1 >= 0.0 and _admissible(q, nphi, sq, coh, ten, tol):
                ok = 1
            # FLAC's return not admissible (near a corner or the apex of the surface):
            # the first admissible active set, by size
            if ok == 0:
                ok2, act, nact, g, q2 = _first_admissible(p, nphi, npsi, sq, coh, ten, a1,
                                                          a2, tol)
                if ok2 == 0:         # none found (not expected): keep FLAC's return
                    eps = ti.abs(eps)
                else:
                    q = q2
                    # plastic strains of the shear planes, failure type
                    eps_s = ti.Vector([0.0, 0.0, 0.0])
                    shear_part = 0
                    for c in ti.static(range(3)):
                        if c < nact:
                            nc, kc, mc = _plane(act[c], nphi, npsi, sq, coh, ten)
                            if act[c] < 6:
                                eps_s += g[c] * mc
                                shear_part = 1
                    em = (eps_s[0] + eps_s[1] + eps_s[2]) / 3.0
                    dev = eps_s - em * ti.Vector([1.0, 1.0, 1.0])
                    eps = ti.sqrt(0.5 * dev.dot(dev))
                    flag = TENSION_FAILURE
                    if shear_part == 1:
                        flag = SHEAR_FAILURE
            # back to x–y
            c2 = 1.0
            s2 = 0.0
            if rad > 0.0:
                c2 = d / rad
                s2 = s[2] / rad
            cn = 0.5 * (q[0] + q[1])
            rn = 0.5 * (q[1] - q[0])
            out = ti.Vector([cn + rn * c2, cn - rn * c2, rn * s2, q[2]])
    return out, eps, flag


@ti.func
def mc_correct(s, matp: ti.template(), M):
    """:func:`mc_correct_state` with the peak strength (no softening)."""
    return mc_correct_state(s, matp, M, 0)
