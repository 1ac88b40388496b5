"""Global and local damping against their closed forms; Hertz–Mindlin impact."""
import math

import numpy as np
import pytest

import tdem


def test_global_damping_decays_exponentially():
    """C&S mass-proportional damping: dv/dt = −α v, so v = v0·exp(−α t) (the central
    difference gives ((1 − αΔt/2)/(1 + αΔt/2))^n, within 1e-4 of it here)."""
    alpha = 5.0
    sim = tdem.Simulation(gravity=(0.0, 0.0), global_damping=alpha, dt=1e-4)
    sim.add_particles([[0.0, 0.0]], 0.1, density=1000.0, contact=tdem.LinearContact(kn=1e6),
                      velocity=[[2.0, -1.0]])
    sim.run(until=0.5)
    v = sim.particles.numpy()["velocity"][0]
    np.testing.assert_allclose(v, np.array([2.0, -1.0]) * math.exp(-alpha * sim.time), rtol=1e-4)
    e = sim.energy()
    # the damping work is booked as dissipated energy
    ek0 = 0.5 * 1000.0 * math.pi * 0.01 * 5.0
    assert e["kinetic"] + e["dissipated"] == pytest.approx(ek0, rel=1e-3)


def test_local_damping_reduces_the_unbalanced_force():
    """Local non-viscous damping (Miyata Eq. 33): a body falling under gravity with
    F ∥ v accelerates at g(1 − α′)."""
    a = 0.3
    sim = tdem.Simulation(gravity=(0.0, -9.81), local_damping=a, dt=1e-4)
    sim.add_particles([[0.0, 0.0]], 0.1, density=1000.0, contact=tdem.LinearContact(kn=1e6),
                      velocity=[[0.0, -0.01]])
    sim.run(until=0.2)
    v = sim.particles.numpy()["velocity"][0]
    assert v[1] == pytest.approx(-0.01 - 9.81 * (1 - a) * sim.time, rel=1e-9)


def test_hertz_impact_duration_and_peak_overlap():
    """Hertz: the closed forms
    t_c = 2.8683 (m*² / (R* E*² v))^(1/5), δ_max = (15 m* v²/(16 E* √R*))^(2/5)."""
    young, nu, r, rho, v = 1e8, 0.3, 0.05, 2000.0, 1.0
    law = tdem.HertzMindlin(young=young, poisson=nu, friction=0.0)
    sim = tdem.Simulation(gravity=(0.0, 0.0), dt_fraction=0.02)
    sim.add_particles([[0.0, 0.0], [2 * r + 2e-3, 0.0]], r, density=rho, contact=law,
                      velocity=[[0.5 * v, 0.0], [-0.5 * v, 0.0]])
    sim.monitor("u", lambda s: 2 * r - np.diff(s.particles.numpy()["position"][:, 0])[0], every=1)
    sim.run(until=0.03)
    t, u = sim.histories()["u"]
    m = rho * math.pi * r * r
    mstar, rstar, estar = m / 2, r / 2, law.e_star
    k = np.nonzero(np.sign(u[1:]) != np.sign(u[:-1]))[0]
    tc = np.diff(t[k] - u[k] * (t[k + 1] - t[k]) / (u[k + 1] - u[k]))[0]
    assert tc == pytest.approx(2.8683 * (mstar ** 2 / (rstar * estar ** 2 * v)) ** 0.2, rel=0.01)
    umax = (15 * mstar * v ** 2 / (16 * estar * math.sqrt(rstar))) ** 0.4
    assert u.max() == pytest.approx(umax, rel=0.01)
    vel = sim.particles.numpy()["velocity"]
    assert vel[1, 0] - vel[0, 0] == pytest.approx(v, rel=0.005)
