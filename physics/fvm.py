"""Incremental finite-volume update of constant-stress triangles.

Feng, Li & Oñate (2015), §2.4, Eqs. 6–14, with the sign of Eq. 13 fixed as in
the project's physics notes (§3 and §4). The same element update serves the
PCMM elements (weight 1/N_e of the superposition rule) and the triangles of a
deformable block (weight 1, the stress lives on the element).

Conventions
-----------
- A triangle is (a, b, c), **counter-clockwise**. Edge k runs from vertex k to
  vertex k+1 (edge 0: a→b, edge 1: b→c, edge 2: c→a). For a counter-clockwise
  triangle the outward normal of an edge e = x_{k+1} − x_k is to its right:
  n·ΔL = m = (e_y, −e_x). The helpers work with m = n·ΔL (not normalised).
- Stress is **tension-positive**, stored as the 4-vector (σxx, σyy, σxy, σzz).
  Plane strain: εzz = 0 and σzz is tracked.
- Strain increments are tensor components (Δεxy = ½·Δγxy).

Equations
---------
- Eq. 6, velocity gradient by Gauss over the edges with edge-mean velocities:
  L_ij = ∂v_i/∂x_j = (1/S) Σ_k v̄_i^k n_j^k ΔL^k, v̄^k the mean of the edge's two
  end velocities, S the area. Exact for a linear velocity field.
- Eq. 7: Δε = sym(L)·Δt. Spin W = skew(L) = [[0, −w], [w, 0]],
  w = ½(L_yx − L_xy) the counter-clockwise spin rate.
- Eqs. 8–10, plane strain: Δθ = Δεxx + Δεyy,
  Δσ_ij = 2G·Δε_ij + (K − 2G/3)·Δθ·δ_ij (i, j in-plane), Δσzz = (K − 2G/3)·Δθ.
- Jaumann rotation, σ̇ = W·σ − σ·W (so that a stress carried by a rigidly
  rotating body rotates with it: σ = R σ₀ Rᵀ gives σ̇ = Ṙ Rᵀ σ − σ Ṙ Rᵀ with
  Ṙ Rᵀ = W). Over a step the stress is turned by the Hughes–Winget rotation
  σ ← R(φ)·σ·R(φ)ᵀ, tan(φ/2) = w·Δt/2 (φ = w·Δt to second order). To first order in Δt this is
  σ ← σ + (W·σ − σ·W)·Δt; unlike that forward-Euler form it keeps the
  invariants of σ exactly (the Euler form grows the deviator by the factor
  sqrt(1 + (2wΔt)²) each step: 90° in N steps inflates it by ≈ π²/(2N)).
  The in-plane mean stress and σzz are unchanged by the rotation.
- Update order for one step: σ ← R σ_old Rᵀ + Δσ(Δε), then the constitutive
  correction (Eq. 12, :func:`constitutive`: the identity for now, elastic).
- Eqs. 13–14, sign fixed: the force of the element on its node p is
  f_p = −(1/N_e)·σ·½·(n¹ΔL¹ + n²ΔL²), n¹, n² the outward unit normals of the two
  edges meeting at p. The three forces sum to zero (Σ_k n^k ΔL^k = 0 for a
  closed triangle), and a stretched element (σxx > 0) pulls its nodes inward.
  Equivalently f_p = ½·σ·m_opp/N_e with m_opp = n·ΔL of the edge opposite p:
  the constant-strain triangle's internal force −S·σ·∇N_p. Assembled over a
  mesh under a uniform σ the interior nodes get zero and a boundary node gets
  −½·σ·n·ΔL from each boundary edge it ends: minus the traction σ·n.

Nodal mixed discretization
--------------------------
Constant-strain triangles lock when they flow plastically at constant volume: each
element must keep its own area, about one volumetric constraint per degree of
freedom of a triangle mesh (two for the PCMM element system, which superposes both
diagonals of a square lattice), and a soil that must collapse stands. As FLAC does
for its zones (Marti & Cundall 1982) and FLAC3D for tetrahedra (nodal mixed
discretization), the volumetric part is taken through the nodes, with one
constraint per node:

- each node (particle) a averages the elements' volumetric strain increments,
  Δθ_a = Σ_e V_e Δθ_e / Σ_e V_e over the elements containing it, V_e the element's
  area (PCMM: its share k·S_e/N_e, k its multiplicity);
- an element's strain increment keeps its own deviatoric part and takes the mean
  of its three nodes' Δθ_a as its volumetric part (:func:`mixed_strain`), before
  the stress update and the material's correction;
- the in-plane mean stress of its nodal forces is likewise the mean over its nodes
  of their averages of the elements' mean stresses (:func:`mixed_stress`); the
  deviatoric part and σzz stay the element's.

Both averages are the same operator A, which is self-adjoint for the weights V_e,
so the forces do the work the stresses store: Σ V_e m_e (AΔθ)_e = Σ V_e (Am)_e
Δθ_e. A uniform strain rate is left as it is (a patch test passes), and so is every
element's deviatoric behaviour. ``Simulation(mixed_discretization=False)`` runs the
elements' own update (docs/pcmm.md compares the two).

Kernels
-------
The kernels take ``ti.types.ndarray`` arguments (compiled once per process, per
argument kind) with vector element types; ``ti.Vector.ndarray`` objects and
numpy arrays of the matching trailing shape are both accepted:

- ``pos``, ``vel``, ``force``: (V,) vectors of 2 f64 (numpy: (V, 2) float64);
- ``tri``: (T,) vectors of 3 i32 (numpy: (T, 3) int32), counter-clockwise;
- ``stress``: (T,) vectors of 4 f64 (σxx, σyy, σxy, σzz);
- ``weight``: (T,) f64, the factor 1/N_e of each element's nodal forces
  (1 for block triangles).

Nodal forces are *accumulated* into ``force`` (the caller zeroes it, or adds
contact and body forces to it, as it likes) with atomic adds: the sum at a node
is then taken in a thread-dependent order, so its last bits may vary from run to
run on several threads.
"""
import taichi as ti

V2 = ti.types.vector(2, ti.f64)
V3I = ti.types.vector(3, ti.i32)
V4 = ti.types.vector(4, ti.f64)
M2 = ti.types.matrix(2, 2, ti.f64)


# ------------------------------------------------------------------ one triangle
@ti.func
def edge_normal(xa, xb):
    """n·ΔL of the edge a→b of a counter-clockwise triangle: (e_y, −e_x), e = xb − xa
    (outward, to the right of a→b; its length is the edge length)."""
    e = xb - xa
    return ti.Vector([e[1], -e[0]], dt=ti.f64)


@ti.func
def area(xa, xb, xc):
    """Signed area S of (a, b, c): > 0 when counter-clockwise."""
    u = xb - xa
    v = xc - xa
    return 0.5 * (u[0] * v[1] - u[1] * v[0])


@ti.func
def velocity_gradient(xa, xb, xc, va, vb, vc):
    """Eq. 6: L_ij = ∂v_i/∂x_j = (1/S) Σ_edges v̄_i n_j ΔL (2×2 matrix, row i, column j)."""
    s = area(xa, xb, xc)
    m0 = edge_normal(xa, xb)
    m1 = edge_normal(xb, xc)
    m2 = edge_normal(xc, xa)
    g = (0.5 * (va + vb)).outer_product(m0) + (0.5 * (vb + vc)).outer_product(m1) \
        + (0.5 * (vc + va)).outer_product(m2)
    return g / s


@ti.func
def strain_increment(grad, dt):
    """Eq. 7: Δε = sym(L)·Δt as (Δεxx, Δεyy, Δεxy), tensor shear component."""
    return ti.Vector([grad[0, 0] * dt, grad[1, 1] * dt,
                      0.5 * (grad[0, 1] + grad[1, 0]) * dt], dt=ti.f64)


@ti.func
def spin_rate(grad):
    """w of W = skew(L) = [[0, −w], [w, 0]]: w = ½(∂v_y/∂x − ∂v_x/∂y), counter-clockwise."""
    return 0.5 * (grad[1, 0] - grad[0, 1])


@ti.func
def elastic_increment(de, K, G):
    """Eqs. 8–10, plane strain: (Δσxx, Δσyy, Δσxy, Δσzz) of the strain increment
    de = (Δεxx, Δεyy, Δεxy); Δθ = Δεxx + Δεyy, λ = K − 2G/3."""
    dtheta = de[0] + de[1]
    lam = K - 2.0 * G / 3.0
    return ti.Vector([2.0 * G * de[0] + lam * dtheta, 2.0 * G * de[1] + lam * dtheta,
                      2.0 * G * de[2], lam * dtheta], dt=ti.f64)


@ti.func
def jaumann_rotate(sig, w, dt):
    """Jaumann rotation over one step, σ ← R(φ)·σ·R(φ)ᵀ with tan(φ/2) = w·Δt/2 (the
    Hughes–Winget rotation, φ = w·Δt + O(Δt³)): the rate σ̇ = W·σ − σ·W integrated
    over the step (first order: σ + (Wσ − σW)Δt). With the velocity gradient taken on
    the mid-step configuration, a rigid rotation by θ per step gives w·Δt = 2 tan(θ/2)
    exactly, so φ = θ: the stress turns with the body, to round-off.

    With d = (σxx − σyy)/2 and τ = σxy, (d, τ) turns by 2φ; the mean (σxx + σyy)/2
    and σzz are unchanged.
    """
    # cos 2φ and sin 2φ from t = tan(φ/2) without trigonometric calls:
    # cos φ = (1 − t²)/(1 + t²), sin φ = 2t/(1 + t²)
    t = 0.5 * w * dt
    inv = 1.0 / (1.0 + t * t)
    c1 = (1.0 - t * t) * inv
    s1 = 2.0 * t * inv
    c = c1 * c1 - s1 * s1
    s = 2.0 * s1 * c1
    mean = 0.5 * (sig[0] + sig[1])
    d = 0.5 * (sig[0] - sig[1])
    tau = sig[2]
    d2 = c * d - s * tau
    tau2 = s * d + c * tau
    return ti.Vector([mean + d2, mean - d2, tau2, sig[3]], dt=ti.f64)


@ti.func
def constitutive(sig):
    """Constitutive correction of the trial stress (Eq. 12): the identity (elastic).

    This is the one place where a plastic return mapping (Mohr–Coulomb with a
    tension cut-off) will act on the stress before the nodal forces are computed.
    """
    return sig


@ti.func
def mid_step(a, b, c, pos: ti.template(), vel: ti.template(), dt):
    """Velocity gradient (Eq. 6) and signed area of the triangle of nodes a, b, c on
    the mid-step configuration x − ½Δt·v (x at step n, v at n − ½): a rigid rotation
    then has an exactly skew gradient, and Δθ·area is exactly the area change of the
    step (the area is quadratic in the positions). PCMM elements and block triangles
    both use it."""
    va, vb, vc = vel[a], vel[b], vel[c]
    h = 0.5 * dt
    ya, yb, yc = pos[a] - h * va, pos[b] - h * vb, pos[c] - h * vc
    return velocity_gradient(ya, yb, yc, va, vb, vc), area(ya, yb, yc)


@ti.func
def mixed_strain(de, theta):
    """The strain increment de = (Δεxx, Δεyy, Δεxy) with its volumetric part Δθ
    replaced by ``theta`` (the nodal mixed discretization: the mean over the
    element's nodes of their averaged Δθ); the deviatoric part is the element's."""
    h = 0.5 * (theta - de[0] - de[1])
    return ti.Vector([de[0] + h, de[1] + h, de[2]], dt=ti.f64)


@ti.func
def mixed_stress(sig, mean):
    """The stress 4-vector with its in-plane mean (σxx + σyy)/2 replaced by ``mean``
    (the mean over the element's nodes of their averaged in-plane mean stress):
    the stress of the nodal forces under the nodal mixed discretization."""
    h = mean - 0.5 * (sig[0] + sig[1])
    return ti.Vector([sig[0] + h, sig[1] + h, sig[2], sig[3]], dt=ti.f64)


@ti.func
def stress_dot(sig, m):
    """σ·m for the stress 4-vector σ and an in-plane vector m."""
    return ti.Vector([sig[0] * m[0] + sig[2] * m[1], sig[2] * m[0] + sig[1] * m[1]],
                     dt=ti.f64)


@ti.func
def nodal_forces(sig, xa, xb, xc, weight):
    """Eqs. 13–14 (sign fixed): forces of the element on its nodes a, b, c,
    f_p = −weight·σ·½·(n¹ΔL¹ + n²ΔL²) over the two edges meeting at p."""
    m0 = edge_normal(xa, xb)
    m1 = edge_normal(xb, xc)
    m2 = edge_normal(xc, xa)
    h = -0.5 * weight
    fa = h * stress_dot(sig, m2 + m0)
    fb = h * stress_dot(sig, m0 + m1)
    fc = h * stress_dot(sig, m1 + m2)
    return fa, fb, fc


@ti.func
def corner_force(sig, xu, xv, weight):
    """Eqs. 13–14 for one node: the force of the element on the corner whose
    opposite edge runs u → v (u, v the next two corners, counter-clockwise),
    f = weight·½·σ·m_opp with m_opp = n·ΔL of that edge (the sum of those of the two
    edges meeting at the corner). The three corners' forces are those of
    :func:`nodal_forces`."""
    return 0.5 * weight * stress_dot(sig, edge_normal(xu, xv))


# ------------------------------------------------------------------ kernels
@ti.kernel
def update_triangles(pos: ti.types.ndarray(dtype=V2, ndim=1),
                     vel: ti.types.ndarray(dtype=V2, ndim=1),
                     tri: ti.types.ndarray(dtype=V3I, ndim=1),
                     stress: ti.types.ndarray(dtype=V4, ndim=1),
                     K: ti.f64, G: ti.f64, dt: ti.f64,
                     weight: ti.types.ndarray(dtype=ti.f64, ndim=1),
                     force: ti.types.ndarray(dtype=V2, ndim=1)):
    """One step of every triangle: stress from its own old stress, then nodal forces.

    σ_new = constitutive(R(wΔt)·σ_old·R(wΔt)ᵀ + Δσ(sym(L)Δt)) with L of Eq. 6 taken
    on the given positions and velocities; ``stress`` is overwritten with σ_new and
    the forces of Eqs. 13–14 (with σ_new, on the same positions, times ``weight``)
    are added to ``force``. K, G: elastic bulk and shear moduli (Pa).
    """
    for e in range(tri.shape[0]):
        t = tri[e]
        xa, xb, xc = pos[t[0]], pos[t[1]], pos[t[2]]
        grad = velocity_gradient(xa, xb, xc, vel[t[0]], vel[t[1]], vel[t[2]])
        de = strain_increment(grad, dt)
        sig = jaumann_rotate(stress[e], spin_rate(grad), dt) + elastic_increment(de, K, G)
        sig = constitutive(sig)
        stress[e] = sig
        fa, fb, fc = nodal_forces(sig, xa, xb, xc, weight[e])
        force[t[0]] += fa
        force[t[1]] += fb
        force[t[2]] += fc


@ti.kernel
def element_forces(pos: ti.types.ndarray(dtype=V2, ndim=1),
                   tri: ti.types.ndarray(dtype=V3I, ndim=1),
                   stress: ti.types.ndarray(dtype=V4, ndim=1),
                   weight: ti.types.ndarray(dtype=ti.f64, ndim=1),
                   force: ti.types.ndarray(dtype=V2, ndim=1)):
    """Nodal forces (Eqs. 13–14) of the given element stresses, added to ``force``;
    the stresses are not changed."""
    for e in range(tri.shape[0]):
        t = tri[e]
        fa, fb, fc = nodal_forces(stress[e], pos[t[0]], pos[t[1]], pos[t[2]], weight[e])
        force[t[0]] += fa
        force[t[1]] += fb
        force[t[2]] += fc
