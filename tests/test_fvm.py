"""Incremental FVM triangles (physics/fvm.py): stress update and nodal forces.

Material: E = 1 GPa, ν = 0.3 (K = E/(3(1 − 2ν)), G = E/(2(1 + ν))) unless said.

- Patch test (both mesh patterns, interior nodes jittered): v = L·x with a
  uniform L. Pure stretch: every triangle's stress equals plane-strain Hooke of
  the accumulated strain D·t to 1e-12 relative, σzz = (K − 2G/3)·θ. With a spin
  w (rotation w·t = 0.5 rad over 50 steps): every triangle equals the closed form
  of the update, σ_n = Σ_{m<n} R(m·wΔt)·(C:D Δt)·R(m·wΔt)ᵀ, to 1e-10 relative
  (measured 3e-15), and the exact solution of σ̇ = C:D + Wσ − σW within 2·w·Δt
  relative (measured 1.0·w·Δt = 1e-2: the update is first order, the rotation
  acts on the old stress).
- Rigid rotation by 90° in 200 steps of a body under σxx = S: at 45°
  σ = S·(½, ½, +½) (the sign of σxy checks the sense of the rotation), at 90°
  σyy = S, σxx = σxy = 0 to 1e-10·S (measured 3e-13), the invariants kept to
  1e-12 relative (the spin is integrated exactly over each step; the forward-Euler form σ + (Wσ − σW)Δt would
  inflate the deviator by ≈ π²/(2N) = 2.5 % here). An unstressed body gets
  < 1e-6·E (measured 3e-16·E).
- Nodal forces: the three forces of a triangle sum to zero (1e-12 relative);
  Σ_p f_p·(x_p − x̄) = −S·(σxx + σyy) (a stretched triangle pulls its nodes in);
  on a meshed rectangle under a uniform σ the assembled forces vanish at interior
  nodes and equal −½·σ·n·ΔL per boundary edge end, so the nodes of a side carry
  −σ·n·(side length): minus the traction (1e-12 relative).
- Bar 1 m × 0.1 m (40 × 4 cells), left end on rollers, right end pulled by
  F = 10 kN, lumped masses ρS/3, leapfrog with mass-proportional damping
  (0.3·ω₁, ω₁ the first axial mode), 100/ω₁ of simulated time (≈ 8000 steps):
  the static elongation is F·L/(E′·A), E′ = E/(1 − ν²) (plane strain, free
  lateral sides), within 1 % (measured +1.0e-4), every σxx = F/A within 1 %
  (measured ±1.1e-3), σyy ≈ 0, σzz = ν·(σxx + σyy) to 1e-9, and the lateral
  strain −ν/(1 − ν)·εxx within 1 % (measured 2e-7).
"""
import math

import numpy as np
import pytest

from tdem import backend, mesh  # tdem first: it imports physics in its order
from physics import fvm

E = 1.0e9
NU = 0.3
K = E / (3 * (1 - 2 * NU))
G = E / (2 * (1 + NU))
LAM = K - 2 * G / 3


@pytest.fixture(scope="module", autouse=True)
def taichi():
    backend.init()


def hooke(eps):
    """Plane-strain Hooke of the tensor strain (εxx, εyy, εxy): (σxx, σyy, σxy, σzz)."""
    th = eps[0] + eps[1]
    return np.array([2 * G * eps[0] + LAM * th, 2 * G * eps[1] + LAM * th,
                     2 * G * eps[2], LAM * th])


def jittered(pattern, nx=5, ny=4, w=1.0, h=0.8, amount=0.2, seed=1):
    v, t = mesh.rectangle(w, h, nx, ny, pattern)
    rng = np.random.default_rng(seed)
    inner = np.setdiff1d(np.arange(len(v)), mesh.boundary_nodes(t))
    v[inner] += rng.uniform(-amount, amount, (len(inner), 2)) * [w / nx, h / ny]
    mesh.check_mesh(v, t)
    return v, t.astype(np.int32)


def run_imposed(v, t, L, dt, n, stress=None, exact_positions=None):
    """n updates with the velocities v = L·x of the current positions."""
    pos = v.copy()
    st = np.zeros((len(t), 4)) if stress is None else stress.copy()
    w = np.ones(len(t))
    for k in range(n):
        vel = np.ascontiguousarray(pos @ L.T)
        f = np.zeros_like(pos)
        fvm.update_triangles(pos, vel, t, st, K, G, dt, w, f)
        pos = pos + dt * vel if exact_positions is None else exact_positions(k + 1)
    return st


# ------------------------------------------------------------------ patch test
@pytest.mark.parametrize("pattern", ["regular", "cross"])
def test_patch_pure_stretch_is_hooke(pattern):
    v, t = jittered(pattern)
    rng = np.random.default_rng(7)
    a = rng.normal(0, 1e-3, (2, 2))
    D = 0.5 * (a + a.T)
    dt, n = 0.1, 10
    st = run_imposed(v, t, D, dt, n)
    eps = np.array([D[0, 0], D[1, 1], D[0, 1]]) * dt * n
    expect = hooke(eps)
    scale = np.abs(expect).max()
    assert np.abs(st - expect).max() <= 1e-12 * scale
    np.testing.assert_allclose(st[:, 3], LAM * (eps[0] + eps[1]), rtol=1e-12)


def _deviator(s):
    return 0.5 * (s[..., 0] - s[..., 1]) + 1j * s[..., 2]


@pytest.mark.parametrize("pattern", ["regular", "cross"])
def test_patch_stretch_and_spin(pattern):
    v, t = jittered(pattern, seed=2)
    rng = np.random.default_rng(8)
    a = rng.normal(0, 2e-2, (2, 2))
    D = 0.5 * (a + a.T)
    w = 0.5
    L = D + np.array([[0.0, -w], [w, 0.0]])
    dt, n = 0.02, 50
    st = run_imposed(v, t, L, dt, n)
    A = hooke(np.array([D[0, 0], D[1, 1], D[0, 1]]))     # stress rate C:D
    za = _deviator(A)
    q = np.exp(2j * 2.0 * np.arctan(0.5 * w * dt))   # Hughes–Winget angle per step
    z_discrete = za * dt * (q ** n - 1) / (q - 1)
    z_exact = za * (np.exp(2j * w * n * dt) - 1) / (2j * w)
    mean = 0.5 * (A[0] + A[1]) * n * dt
    scale = np.abs(A).max() * n * dt
    z = _deviator(st)
    assert np.abs(z - z_discrete).max() <= 1e-10 * scale
    np.testing.assert_allclose(0.5 * (st[:, 0] + st[:, 1]), mean, rtol=1e-10, atol=1e-10 * scale)
    np.testing.assert_allclose(st[:, 3], A[3] * n * dt, rtol=1e-10)
    assert A[3] * n * dt == pytest.approx(LAM * (D[0, 0] + D[1, 1]) * n * dt, rel=1e-12)
    assert np.abs(z - z_exact).max() <= 2 * w * dt * np.abs(z_exact)


# ------------------------------------------------------------------ rigid rotation
@pytest.mark.parametrize("S", [1.0e6, 0.0])
def test_rigid_rotation(S):
    v, t = jittered("cross", nx=3, ny=2, w=0.3, h=0.2, seed=3)
    n = 200
    omega = 0.5 * math.pi           # 90° in 1 s
    dt = 1.0 / n
    # spin whose Hughes–Winget angle is exactly omega·dt (what the chord velocities of
    # an exact rotation give on the mid-step configuration)
    w_hw = 2.0 * math.tan(0.5 * omega * dt) / dt
    W = np.array([[0.0, -w_hw], [w_hw, 0.0]])

    def rotated(k):
        c, s = math.cos(omega * k * dt), math.sin(omega * k * dt)
        return np.ascontiguousarray(v @ np.array([[c, -s], [s, c]]).T)

    s0 = np.zeros((len(t), 4))
    s0[:, 0] = S
    s0[:, 3] = NU * S
    half = run_imposed(v, t, W, dt, n // 2, stress=s0, exact_positions=rotated)
    if S > 0:
        # 45° counter-clockwise: R σ Rᵀ = S·(½, ½, +½) (the sign of σxy fixes the sense)
        np.testing.assert_allclose(half[:, :3], 0.5 * S, rtol=1e-10)
    st = run_imposed(rotated(n // 2), t, W, dt, n - n // 2, stress=half,
                     exact_positions=lambda k: rotated(n // 2 + k))
    if S > 0:
        assert np.abs(st[:, 0]).max() <= 1e-10 * S
        assert np.abs(st[:, 1] - S).max() <= 1e-10 * S
        assert np.abs(st[:, 2]).max() <= 1e-10 * S
        np.testing.assert_allclose(st[:, 3], NU * S, rtol=1e-12)
        tr = st[:, 0] + st[:, 1]
        det = st[:, 0] * st[:, 1] - st[:, 2] ** 2
        np.testing.assert_allclose(tr, S, rtol=1e-12)
        assert np.abs(det).max() <= 1e-10 * S * S
    else:
        assert np.abs(st).max() < 1e-6 * E


# ------------------------------------------------------------------ nodal forces
def _ccw_triangles(rng, nt):
    """nt random counter-clockwise triangles in [-1, 1]², as (nt, 3, 2) corners."""
    p = rng.uniform(-1, 1, (nt, 3, 2))
    u = p[:, 1] - p[:, 0]
    v = p[:, 2] - p[:, 0]
    cw = u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0] < 0
    p[cw] = p[cw][:, ::-1]
    return p


def test_triangle_forces_balance_and_pull_inward():
    rng = np.random.default_rng(4)
    nt = 200
    p = _ccw_triangles(rng, nt)
    pos = np.ascontiguousarray(p.reshape(-1, 2))
    tri = np.arange(3 * nt, dtype=np.int32).reshape(nt, 3)
    sig = rng.normal(0, 1e6, (nt, 4))
    f = np.zeros_like(pos)
    fvm.element_forces(pos, tri, sig, np.ones(nt), f)
    f = f.reshape(nt, 3, 2)
    size = np.abs(sig[:, :3]).max(axis=1) * np.linalg.norm(p - p.mean(1, keepdims=True),
                                                           axis=2).max(axis=1)
    assert np.all(np.abs(f.sum(axis=1)).max(axis=1) <= 1e-12 * size)
    area = np.abs(mesh.signed_areas(pos, tri))
    virt = np.einsum("tpi,tpi->t", f, p - p.mean(axis=1, keepdims=True))
    np.testing.assert_allclose(virt, -area * (sig[:, 0] + sig[:, 1]), rtol=1e-9,
                               atol=1e-12 * np.abs(area * sig[:, :2].sum(1)).max())
    # a stretched right triangle (σxx > 0): the node at x = 1 is pulled back to -x
    pos1 = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
    f1 = np.zeros_like(pos1)
    fvm.element_forces(pos1, np.array([[0, 1, 2]], np.int32), np.array([[1.0, 0, 0, 0]]),
                       np.array([0.5]), f1)
    np.testing.assert_allclose(f1, [[0.25, 0.0], [-0.25, 0.0], [0.0, 0.0]], atol=1e-15)


def test_corner_force_is_the_nodal_force_of_its_corner():
    """One corner's force from the edge opposite it (what the PCMM gather uses) equals
    that corner's force of nodal_forces, for random counter-clockwise triangles."""
    import taichi as ti
    backend.init()
    rng = np.random.default_rng(7)
    nt = 100
    p = _ccw_triangles(rng, nt)
    sig = rng.normal(0, 1e6, (nt, 4))
    w = rng.uniform(0.1, 1.0, nt)
    out = np.zeros((nt, 2, 3, 2))

    @ti.kernel
    def both(p: ti.types.ndarray(), sig: ti.types.ndarray(), w: ti.types.ndarray(),
             out: ti.types.ndarray()):
        for t in range(p.shape[0]):
            x = [ti.Vector([p[t, k, 0], p[t, k, 1]]) for k in ti.static(range(3))]
            s = ti.Vector([sig[t, 0], sig[t, 1], sig[t, 2], sig[t, 3]])
            fa, fb, fc = fvm.nodal_forces(s, x[0], x[1], x[2], w[t])
            for k in ti.static(range(3)):
                f = fa
                if ti.static(k == 1):
                    f = fb
                elif ti.static(k == 2):
                    f = fc
                g = fvm.corner_force(s, x[(k + 1) % 3], x[(k + 2) % 3], w[t])
                for d in ti.static(range(2)):
                    out[t, 0, k, d] = f[d]
                    out[t, 1, k, d] = g[d]

    both(p, sig, w, out)
    scale = np.abs(out[:, 0]).max()
    assert scale > 1e4
    np.testing.assert_allclose(out[:, 1], out[:, 0], rtol=0, atol=1e-14 * scale)


@pytest.mark.parametrize("pattern", ["regular", "cross"])
def test_uniform_stress_gives_boundary_tractions(pattern):
    w, h = 1.0, 0.8
    v, t = jittered(pattern, w=w, h=h, seed=5)
    sig = np.array([3.0e6, -1.0e6, 2.0e6, 0.5e6])
    s = np.array([[sig[0], sig[2]], [sig[2], sig[1]]])
    f = np.zeros_like(v)
    fvm.element_forces(v, t, np.tile(sig, (len(t), 1)), np.ones(len(t)), f)
    expect = np.zeros_like(v)
    e = mesh.boundary_edges(t)
    d = v[e[:, 1]] - v[e[:, 0]]
    m = np.stack([d[:, 1], -d[:, 0]], axis=1)           # outward n·ΔL
    half = -0.5 * m @ s.T
    np.add.at(expect, e[:, 0], half)
    np.add.at(expect, e[:, 1], half)
    scale = np.abs(sig).max() * max(w, h)
    assert np.abs(f - expect).max() <= 1e-12 * scale
    for side, n, length in [(np.isclose(v[:, 0], w), [1, 0], h), (np.isclose(v[:, 0], 0), [-1, 0], h),
                            (np.isclose(v[:, 1], h), [0, 1], w), (np.isclose(v[:, 1], 0), [0, -1], w)]:
        total = f[side].sum(axis=0)
        assert np.abs(total + s @ np.array(n, float) * length).max() <= 1e-12 * scale


# ------------------------------------------------------------------ bar
def test_bar_static_elongation():
    length, height, rho, force = 1.0, 0.1, 2000.0, 1.0e4
    nx, ny = 40, 4
    v, t = mesh.rectangle(length, height, nx, ny, "regular")
    t = t.astype(np.int32)
    mass = mesh.nodal_masses(v, t, rho)
    left = np.isclose(v[:, 0], 0.0)
    pin = np.flatnonzero(left & np.isclose(v[:, 1], 0.0))
    right = np.flatnonzero(np.isclose(v[:, 0], length))
    fext = np.zeros_like(v)
    fext[right, 0] = force / ny
    fext[right[np.isclose(v[right, 1], 0) | np.isclose(v[right, 1], height)], 0] *= 0.5
    assert fext[:, 0].sum() == pytest.approx(force)
    e_plane = E / (1 - NU ** 2)
    cp = math.sqrt((K + 4 * G / 3) / rho)
    altitude = (length / nx) / math.sqrt(2)
    dt = 0.5 * altitude / cp
    omega1 = 0.5 * math.pi * math.sqrt(e_plane / rho) / length
    # mass-proportional damping, 15 % of critical for the first axial mode (heavier
    # damping over-damps the slow lateral/bending modes and delays the static state)
    alpha = 0.3 * omega1
    pos = v.copy()
    vel = np.zeros_like(v)
    st = np.zeros((len(t), 4))
    wgt = np.ones(len(t))
    nsteps = int(round(100.0 / omega1 / dt))
    a1, a2 = 1 - 0.5 * alpha * dt, 1 / (1 + 0.5 * alpha * dt)
    for _ in range(nsteps):
        f = fext.copy()
        fvm.update_triangles(pos, vel, t, st, K, G, dt, wgt, f)
        vel = (vel * a1 + dt * f / mass[:, None]) * a2
        vel[left, 0] = 0.0
        vel[pin, 1] = 0.0
        pos = pos + dt * vel
    u = pos - v
    expect = force * length / (e_plane * height)
    elong = u[right, 0].mean()
    assert elong == pytest.approx(expect, rel=1e-2)
    assert np.abs(vel).max() / omega1 < 1e-3 * expect          # at rest
    sxx = force / height
    np.testing.assert_allclose(st[:, 0], sxx, rtol=1e-2)
    assert np.abs(st[:, 1]).max() < 1e-2 * sxx
    np.testing.assert_allclose(st[:, 3], NU * st[:, 0] + NU * st[:, 1], rtol=1e-9,
                               atol=1e-9 * sxx)
    top = np.isclose(v[:, 1], height)
    lateral = (u[top, 1] - u[np.isclose(v[:, 1], 0.0), 1]).mean() / height
    assert lateral == pytest.approx(-NU / (1 - NU) * expect / length, rel=1e-2)
    print(f'bar: elongation {elong:.6e} vs {expect:.6e} (rel {elong / expect - 1:+.2e}), '
          f'{nsteps} steps, max |v|/omega1 = {np.abs(vel).max() / omega1:.2e} m, '
          f'sxx {st[:, 0].min() / sxx - 1:+.1e}..{st[:, 0].max() / sxx - 1:+.1e}, '
          f'lateral {lateral / (-NU / (1 - NU) * expect / length) - 1:+.2e}')
