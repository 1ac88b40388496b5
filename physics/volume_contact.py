"""Chen's overlap-volume contact for convex polyhedra (Chen's polyhedral DEM).

Normal: F_n = E·V/l_c, V the volume of the overlap polyhedron of the two undeformed
bodies and l_c = 2 l_i l_j/(l_i + l_j) their characteristic length (l = V_body^(1/3);
against a mesh wall l_c = l_i, the wall standing in for a body of the particle's size),
so that a column of equal cubes carries sound at sqrt(E/ρ). The force acts at the
overlap's centroid along the normal of its area vectors (:mod:`physics.geometry.polyhedron`).
Damping ∝ dV/dt, its coefficient from a restitution coefficient; tangential: the
incremental 3D Cundall–Strack spring k_s = ``shear_ratio`` · k_n with the Coulomb limit.

The engine gives the law the overlap as a length, u = V/l_c², its rate
u̇ = (dV/dt)/l_c² = |S| v_n/l_c² (|S| the projected area of the overlap, v_n the
approach velocity along n) and l_c in place of the effective radius, so that the law is
a linear spring–dashpot on u with k_n = E·l_c: F_n = E·l_c·u = E·V/l_c. Two cubes of
edge L face to face overlapping by δ have V = L²δ, l_c = L, u = δ: a linear contact of
stiffness E·L, whose restitution is exactly the one asked (Miyata Eq. 17). The stored
energy is that of the spring on u, ½ E l_c u² (exact for face-to-face contacts; the
force E·V/l_c is not the gradient of an energy when the projected area changes).

The restitution asked is met by face-to-face contacts (|S| = l_c²). A contact of
smaller projected area (an edge, a vertex, a sphere's cap) is damped less: its
damping ratio is that of a face contact times sqrt(|S|)/l_c, so it rebounds more.
"""
import math

import taichi as ti

from .contact_law import ContactLaw, register_law, shear_spring_energy, spring_dashpot
from .validate import positive


@register_law
class VolumeContact(ContactLaw):
    """Overlap-volume contact of polyhedra: F_n = E·V/l_c (module docstring).

    Parameters
    ----------
    young : float
        E (Pa): the normal force per unit overlap volume and inverse characteristic length.
    friction : float
        Friction coefficient tan(φ_μ).
    restitution : float or None
        Coefficient of restitution e in (0, 1]: the normal dashpot on dV/dt.
    shear_ratio : float
        k_s/k_n of the tangential spring (default 1).
    cohesion, damping_ratio : float
        As in :class:`tdem.LinearContact`.
    """

    params = ("young", "shear_ratio", "friction", "cohesion", "damping_ratio", "_gamma")
    history = ("shear",)
    tangential = ("shear",)

    def __init__(self, *, young, friction=0.5, restitution=None, shear_ratio=1.0,
                 cohesion=0.0, damping_ratio=0.0):
        self.young = positive("young", young)
        self.shear_ratio = positive("shear_ratio", shear_ratio)
        self._set_common(friction, cohesion, restitution, damping_ratio, None)

    def critical_stiffness(self, radius, mass):
        # the stiffness against a displacement is E·|S|/l_c, with |S| <= π R² (R the
        # bounding radius) and l_c taken >= R/2 (a cube has l = 1.15 R; shapes flatter
        # than l = R/2 need a smaller step than this gives)
        return self.young * 2.0 * math.pi * radius

    def critical_stiffnesses(self, radius, mass):
        k = self.critical_stiffness(radius, mass)
        return k, k * self.shear_ratio

    @staticmethod
    @ti.func
    def force(q, u, vn, vt, meff, reff, dt, h):
        kn = q[0] * reff
        return spring_dashpot(kn * u, kn, q[1] * kn, q[4], q[5], u, vn, vt, meff, q[2], q[3],
                              dt, h)

    @staticmethod
    @ti.func
    def energy(q, u, reff, h, T: ti.template()):
        kn = q[0] * reff
        return 0.5 * kn * u * u + shear_spring_energy(h, q[1] * kn, T)

    @staticmethod
    @ti.func
    def stiffness(q, u, reff):
        return q[0] * reff
