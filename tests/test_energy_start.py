"""sim.energy() before the first step is the energy of the state as given: kinetic
½ Σ m v² + ½ Σ ω·L (L = I ω for discs and spheres, R I_body Rᵀ ω for an ellipsoid),
gravitational −Σ m g·x, and their sum the total; nothing is integrated yet."""
import math

import numpy as np
import pytest

import tdem
from physics.shapes import quaternion_rotations

G = 9.81


def _check(sim, m, v, w, L, x, g):
    e = sim.energy()
    assert sim.steps == 0
    ke = 0.5 * np.sum(m * np.einsum("ij,ij->i", v, v)) + 0.5 * np.sum(
        w * L if np.ndim(w) == 1 else np.einsum("ij,ij->i", w, L))
    pe = -np.sum(m * (x @ np.asarray(g)))
    assert ke > 0.0
    assert e["kinetic"] == pytest.approx(ke, rel=1e-12)
    assert e["gravitational"] == pytest.approx(pe, rel=1e-12)
    assert e["total"] == pytest.approx(ke + pe, rel=1e-12)
    assert e["integration_error"] == 0.0


def test_discs_moving_and_spinning_at_t0():
    rng = np.random.default_rng(1)
    n, rho = 12, 2000.0
    x = np.stack([np.arange(n) * 0.05, rng.uniform(0.1, 0.2, n)], axis=1)
    r = rng.uniform(0.01, 0.02, n)
    v = rng.normal(0.0, 1.0, (n, 2))
    w = rng.normal(0.0, 20.0, n)
    sim = tdem.Simulation(gravity=(0.0, -G), progress=False)
    sim.add_particles(x, r, density=rho, contact=tdem.LinearContact(kn=1e5), velocity=v,
                      omega=w)
    m = rho * math.pi * r ** 2
    _check(sim, m, v, w, 0.5 * m * r ** 2 * w, x, (0.0, -G))


def test_spheres_moving_and_spinning_at_t0():
    rng = np.random.default_rng(2)
    n, rho = 10, 2500.0
    x = np.stack([np.arange(n) * 0.05, np.zeros(n), rng.uniform(0.1, 0.2, n)], axis=1)
    r = rng.uniform(0.01, 0.02, n)
    v = rng.normal(0.0, 1.0, (n, 3))
    w = rng.normal(0.0, 20.0, (n, 3))
    sim = tdem.Simulation(dim=3, gravity=(0.0, 0.0, -G), progress=False)
    sim.add_particles(x, r, density=rho, velocity=v, omega=w,
                      contact=tdem.HertzMindlin(young=1e7, poisson=0.3, friction=0.5))
    m = rho * 4.0 / 3.0 * math.pi * r ** 3
    _check(sim, m, v, w, (0.4 * m * r ** 2)[:, None] * w, x, (0.0, 0.0, -G))


def test_turned_ellipsoids_moving_and_spinning_at_t0():
    """ω·L with L = R diag(I1, I2, I3) Rᵀ ω, I_k = m/5 (sum of the other two semi-axes
    squared): not I ω² with a scalar I, the spin is not along a principal axis."""
    rng = np.random.default_rng(3)
    n, rho, semi = 6, 2500.0, np.array([0.012, 0.008, 0.005])
    x = np.stack([np.arange(n) * 0.05, np.zeros(n), np.full(n, 0.3)], axis=1)
    v = rng.normal(0.0, 1.0, (n, 3))
    w = rng.normal(0.0, 20.0, (n, 3))
    q = tdem.random_orientations(n, seed=4)
    sim = tdem.Simulation(dim=3, gravity=(0.0, 0.0, -G), progress=False)
    sim.add_particles(x, shape=tdem.Ellipsoid(*semi), density=rho, velocity=v, omega=w,
                      orientation=q,
                      contact=tdem.HertzMindlin(young=1e7, poisson=0.3, friction=0.5))
    m = np.full(n, rho * 4.0 / 3.0 * math.pi * np.prod(semi))
    a2 = semi ** 2
    body = np.array([a2[1] + a2[2], a2[0] + a2[2], a2[0] + a2[1]]) / 5.0
    rot = quaternion_rotations(q)
    L = np.einsum("nij,nj->ni", rot, m[:, None] * body * np.einsum("nji,nj->ni", rot, w))
    _check(sim, m, v, w, L, x, (0.0, 0.0, -G))
