"""A disc on an inclined wall: rolling, sliding and rolling resistance (Jiang et al. 2005).

The slope is modelled by a horizontal wall (y = 0) and gravity rotated by θ,
g = 9.81·(sin θ, −cos θ), so "down the slope" is +x. The disc (uniform, I = ½mR²)
starts at rest, already pressed into the wall by its static weight overlap
u₀ = m g cos θ / k_n so that it does not bounce.

Closed forms (rigid-body mechanics with Coulomb friction μ):
- μ ≥ tan θ / 3: rolls without slipping, a = (2/3) g sin θ and ω R = −v;
- μ < tan θ / 3: slides, a = g (sin θ − μ cos θ), angular acceleration
  α R = 2 μ g cos θ (friction torque μ m g cos θ R over ½ m R²);
- rolling resistance Model 1 (Jiang, Yu & Harris 2005, wall: r̄ = 2R, B = 2δR, M₀ = F_n B/6):
  the disc holds while m g sin θ R ≤ M₀ = m g cos θ δ R/3, i.e. tan θ ≤ δ/3;
  above it rolls with a = (2/3) g (sin θ − (δ/3) cos θ).
"""
import math

import numpy as np
import pytest

import tdem

R, RHO, KN, G = 0.1, 1000.0, 1e6, 9.81
M = RHO * math.pi * R * R


def incline(theta, friction, rolling=None, until=1.0, local_damping=0.0, every=5):
    """Run the disc on a slope of angle ``theta`` (radians); returns (t, state) with
    state columns vx, vy, ω, x, y, rolling moment, normal force."""
    sim = tdem.Simulation(gravity=(G * math.sin(theta), -G * math.cos(theta)),
                          dt_fraction=0.1, local_damping=local_damping)
    law = tdem.LinearContact(kn=KN, ks=KN, friction=friction, rolling=rolling)
    u0 = M * G * math.cos(theta) / KN
    sim.add_particles([[0.0, R - u0]], R, density=RHO, contact=law)
    sim.add_wall((-20.0, 0.0), (20.0, 0.0), contact=law)

    def state(s):
        p = s.particles.numpy()
        c = s.contacts.numpy()
        mom, fn = (c["moment"][0], c["normal"][0]) if len(c["normal"]) else (np.nan, 0.0)
        return np.r_[p["velocity"][0], p["omega"][0], p["position"][0], mom, fn]

    sim.monitor("disc", state, every=every)
    sim.run(until=until)
    return sim.histories()["disc"]


def slope_of(t, y, after=0.1):
    k = t > after
    return np.polyfit(t[k], y[k], 1)[0]


@pytest.mark.parametrize("mu", [0.5, 0.2])   # tan 30°/3 = 0.192
def test_rolls_without_slipping_at_two_thirds_g_sin(mu):
    theta = math.radians(30.0)
    assert mu >= math.tan(theta) / 3
    t, s = incline(theta, mu)
    a = slope_of(t, s[:, 0])
    expected = 2.0 / 3.0 * G * math.sin(theta)          # 3.270 m/s²
    assert a == pytest.approx(expected, rel=0.02)
    # no slip: ω R = −v (clockwise spin while moving to +x)
    assert -slope_of(t, s[:, 2]) * R == pytest.approx(a, rel=0.01)
    assert abs(s[-1, 0] + s[-1, 2] * R) < 0.01 * s[-1, 0]
    # the disc stays on the slope (no bounce, no lift-off)
    assert np.abs(s[:, 1]).max() < 1e-6


@pytest.mark.parametrize("mu", [0.1, 0.18])
def test_slides_at_g_sin_minus_mu_cos(mu):
    theta = math.radians(30.0)
    assert mu < math.tan(theta) / 3
    t, s = incline(theta, mu)
    a = slope_of(t, s[:, 0])
    assert a == pytest.approx(G * (math.sin(theta) - mu * math.cos(theta)), rel=0.02)
    # spin driven by the sliding friction alone
    assert -slope_of(t, s[:, 2]) * R == pytest.approx(2 * mu * G * math.cos(theta), rel=0.02)
    # and it really slips: v + ωR grows
    assert s[-1, 0] + s[-1, 2] * R > 0.2


DELTA = 0.3   # threshold tan θ = δ/3 = 0.1


def elastic_offset(theta):
    """Static down-slope displacement of the centre with the shear spring (F = m g sin θ)
    and the rolling spring K_m = K_n B²/12 (moment F·R): x_s = F (1/k_s + R²/K_m)."""
    km = KN * (DELTA * 2 * R) ** 2 / 12
    return M * G * math.sin(theta) * (1.0 / KN + R * R / km)


def test_rolling_resistance_holds_below_threshold_undamped():
    """tan θ = 0.45 δ/3, no damping: the sudden load makes the disc oscillate
    elastically about its static offset x_s (a step response: between 0 and 2 x_s);
    the rolling couple peaks at 2 × 0.45 M₀ < M₀, so it never yields and the disc
    does not roll. Without rolling resistance it would travel (1/3) g sin θ t² ≈ 0.05 m."""
    theta = math.atan(0.45 * DELTA / 3)
    t, s = incline(theta, 0.5, tdem.RollingResistance(delta=DELTA, model=1), until=1.5, every=2)
    xs = elastic_offset(theta)
    x = s[:, 3]
    assert x.max() < 2.05 * xs          # 2 x_s ≈ 0.7 mm
    assert x.min() > -0.05 * xs
    assert np.mean(x[t > 0.5]) == pytest.approx(xs, rel=0.05)
    m0 = s[:, 6] * DELTA * 2 * R / 6
    assert np.nanmax(np.abs(s[:, 5]) / m0) < 0.95   # stays elastic (≈ 0.90)


def test_rolling_resistance_holds_just_below_threshold():
    """tan θ = 0.9 δ/3 with local damping (which leaves equilibria unchanged): the
    disc comes to rest and the couple carries the whole slope moment,
    |M| = m g sin θ (R − u/2) = 0.9 M₀ (lever arm R − u/2 of the contact point).
    The sudden load overshoots, so the couple touches M₀ for a moment and the disc
    ends 13 % beyond its elastic offset x_s (≈ 1 mm), then holds."""
    theta = math.atan(0.9 * DELTA / 3)
    t, s = incline(theta, 0.5, tdem.RollingResistance(delta=DELTA, model=1), until=2.0,
                   local_damping=0.7, every=10)
    assert abs(s[-1, 0]) < 1e-6 and abs(s[-1, 2]) * R < 1e-6
    assert s[-1, 3] < 2.0 * elastic_offset(theta)
    fn = s[-1, 6]
    assert fn == pytest.approx(M * G * math.cos(theta), rel=1e-3)
    u = fn / KN
    assert abs(s[-1, 5]) == pytest.approx(M * G * math.sin(theta) * (R - u / 2), rel=0.005)
    assert abs(s[-1, 5]) / (fn * DELTA * 2 * R / 6) == pytest.approx(0.9, rel=0.005)


@pytest.mark.parametrize("ratio", [1.5, 1.1])
def test_rolling_resistance_rolls_above_threshold(ratio):
    """tan θ = ratio·δ/3: the couple saturates at M₀ and the disc rolls with
    a = (2/3) g (sin θ − (δ/3) cos θ). Near the threshold that difference is small
    and the lever arm of the contact point, a_c = R − u/2 (u = 3e-4 m), shifts it by
    1.5 % at ratio 1.1, so the reference keeps a_c:
    a = g (sin θ − (δ/3) cos θ R/a_c) / (1 + R²/(2 a_c²))."""
    theta = math.atan(ratio * DELTA / 3)
    t, s = incline(theta, 0.5, tdem.RollingResistance(delta=DELTA, model=1), until=1.5)
    a = slope_of(t, s[:, 0], after=0.3)
    textbook = 2.0 / 3.0 * G * (math.sin(theta) - DELTA / 3 * math.cos(theta))
    ac = R - 0.5 * M * G * math.cos(theta) / KN
    expected = G * (math.sin(theta) - DELTA / 3 * math.cos(theta) * R / ac) / (1 + 0.5 * (R / ac) ** 2)
    assert expected == pytest.approx(textbook, rel=0.02)
    assert a == pytest.approx(expected, rel=0.02)
    assert -slope_of(t, s[:, 2], after=0.3) * ac == pytest.approx(expected, rel=0.02)
    m0 = s[-1, 6] * DELTA * 2 * R / 6
    assert abs(s[-1, 5]) == pytest.approx(m0, rel=1e-6)
