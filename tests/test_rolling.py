"""Rolling resistance of Jiang, Yu & Harris (2005) at one contact (spec §2).

Two discs (or a disc and a wall) are held in place with a fixed normal overlap u,
so F_n = K_n u; one disc is spun at a prescribed ω, the relative rotation
θ_r = ∫(ω_i − ω_j) dt grows linearly and the couple follows the model:

- both models: elastic branch M = −K_m θ_r (on i), K_m = K_n B²/12, B = δ r̄,
  r̄ = 2 r_i r_j/(r_i + r_j) (2 r_i against a wall);
- Model 1: |M| ≤ M₀ = F_n B/6 (perfectly plastic), elastic unloading on reversal;
- Model 2: M drops to 0 once |θ_r| > θ_r⁰ = 2 F_n/(K_n B) and stays 0.
"""

import numpy as np
import pytest

import tdem

KN, U, DELTA = 1e6, 1e-3, 0.5
DT, DT_WALL = 4e-4, 1.5e-4   # the yield rotation is reached in 150 and 133 steps (w = 1 rad/s)
RI, RJ = 0.1, 0.05


def spin_pair(model, w, t_rev, until, wall=False, every=2):
    """Disc 0 spun at ω = w until t_rev, then at −w, against disc 1 (held, not
    spinning) or a wall. Returns (θ_r, M, F_n) at the recorded steps, θ_r the
    relative rotation the contact has accumulated in those steps."""
    dt = DT_WALL if wall else DT

    def omega(t):
        return w if t < t_rev - 1e-12 else -w

    sim = tdem.Simulation(gravity=(0.0, 0.0), dt=dt)
    law = tdem.LinearContact(kn=KN, ks=KN, friction=0.5,
                             rolling=tdem.RollingResistance(delta=DELTA, model=model))
    if wall:
        sim.add_particles([[0.0, RI - U]], RI, density=1000.0, contact=law)
        sim.add_wall((-1.0, 0.0), (1.0, 0.0), contact=law)
    else:
        sim.add_particles([[0.0, 0.0], [RI + RJ - U, 0.0]], [RI, RJ], density=1000.0,
                          contact=law)
        sim.fix_particles([1], vx=0.0, vy=0.0, omega=0.0)
    sim.fix_particles([0], vx=0.0, vy=0.0, omega=omega)

    def rec(s):
        c = s.contacts.numpy()
        assert len(c["normal"]) == 1
        return [c["moment"][0], c["normal"][0]]

    sim.monitor("c", rec, every=every)
    sim.run(until=until)
    t, h = sim.histories()["c"]
    steps = np.rint(t / dt).astype(int)
    # The prescribed spin is imposed at the end of each step (leapfrog): step n's forces
    # see ω = 0 for n = 0 and ω(t_{n-1}) after, so after s steps θ_r = dt Σ_{p<s-1} ω(p dt).
    w_seen = np.array([0.0] + [omega(p * dt) for p in range(steps.max())])
    theta = dt * np.cumsum(w_seen)[steps - 1]
    assert abs(sim.particles.numpy()["omega"][0]) == pytest.approx(w)
    return theta, h[:, 0], h[:, 1]


def reference(wall=False):
    rbar = 2 * RI if wall else 2 * RI * RJ / (RI + RJ)
    b = DELTA * rbar
    fn = KN * U
    return fn, KN * b * b / 12, fn * b / 6, 2 * fn / (KN * b)


@pytest.mark.parametrize("wall", [False, True])
def test_model1_elastic_then_perfectly_plastic(wall):
    fn_ref, km, m0, _ = reference(wall)
    w = 1.0
    theta_y = m0 / km                     # yield rotation: 0.06 rad (pair), 0.02 (wall)
    t_rev = 2.5 * theta_y / w
    theta, mom, fn = spin_pair(1, w, t_rev, until=2 * t_rev, wall=wall)
    assert fn == pytest.approx(np.full_like(fn, fn_ref), rel=1e-9)
    turn = int(np.argmax(theta))          # last record before the rotation reverses
    th, m = theta[:turn + 1], mom[:turn + 1]
    el = np.abs(m) < 0.9 * m0
    assert el.sum() > 20
    assert np.polyfit(th[el], m[el], 1)[0] == pytest.approx(-km, rel=0.01)  # resists i's spin
    plastic = th > 1.1 * theta_y
    assert m[plastic] == pytest.approx(np.full(plastic.sum(), -m0), rel=0.01)
    # on reversal it unloads elastically with the same stiffness, then yields at +M0
    th, m = theta[turn + 1:], mom[turn + 1:]
    el = np.abs(m) < 0.9 * m0
    assert el.sum() > 20
    assert np.polyfit(th[el], m[el], 1)[0] == pytest.approx(-km, rel=0.01)
    assert m[-1] == pytest.approx(m0, rel=0.01)
    assert np.abs(mom).max() <= m0 * (1 + 1e-12)


@pytest.mark.parametrize("wall", [False, True])
def test_model2_elastic_then_brittle(wall):
    fn_ref, km, m0, theta0 = reference(wall)
    w = 1.0
    t_rev = 1.5 * theta0 / w
    theta, mom, fn = spin_pair(2, w, t_rev, until=4 * t_rev, wall=wall, every=1)
    assert fn == pytest.approx(np.full_like(fn, fn_ref), rel=1e-9)
    intact = np.nonzero(mom != 0.0)[0]
    el = np.abs(mom[intact]) < 0.9 * m0
    assert el.sum() > 20
    slope = np.polyfit(theta[intact][el], mom[intact][el], 1)[0]
    assert slope == pytest.approx(-km, rel=0.01)
    # it breaks once the rotation passes θ_r⁰ = 2 F_n/(K_n B), at a couple K_m θ_r⁰ = M0
    last = intact[-1]
    assert np.all(np.diff(intact) == 1)   # intact from the start until it breaks
    step = w * (DT_WALL if wall else DT)  # rotation per step: 0.67 % (pair), 0.75 % of θ_r⁰
    assert theta[last] - step <= theta0 < theta[last + 1] + step   # one step of slack
    assert theta[last + 1] == pytest.approx(theta0, rel=0.01)
    assert abs(mom[last]) == pytest.approx(m0, rel=0.01)
    # and stays broken: the rotation comes back through 0 and beyond, M stays 0
    assert np.all(mom[last + 1:] == 0.0)
    assert theta[-1] < -theta0


@pytest.mark.parametrize("model", [1, 2])
def test_energy_account_through_yield_and_break(model):
    """The driven disc does work on the contact (booked as boundary work); it goes
    into the rolling spring and into dissipation (plastic rolling; for Model 2 the
    spring's energy M₀²/(2 K_m) = 0.167 J released at the break). The total stays
    constant through yield, reversal and break (before the fix of the break booking
    it dropped by 0.167 J). Frictionless, so that only the couple works; dt = 1e-4 s
    because the account pairs the work of the prescribed spin at step n with the
    spring energy at t_n, an offset of ≈ M·ω·Δt/2 (3e-4 J here) that flips sign
    when the spin reverses."""
    fn_ref, km, m0, theta0 = reference()
    dt = 1e-4
    sim = tdem.Simulation(gravity=(0.0, 0.0), dt=dt)
    law = tdem.LinearContact(kn=KN, ks=KN, friction=0.0,
                             rolling=tdem.RollingResistance(delta=DELTA, model=model))
    sim.add_particles([[0.0, 0.0], [RI + RJ - U, 0.0]], [RI, RJ], density=1000.0, contact=law)
    sim.fix_particles([1], vx=0.0, vy=0.0, omega=0.0)
    t_rev = 1.5 * theta0
    sim.fix_particles([0], vx=0.0, vy=0.0, omega=lambda t: 1.0 if t < t_rev else -1.0)
    # the first step sets the spin impulsively (the mid-step kinetic energy of that
    # step is not ½Iω²): start the account after it
    sim.run(steps=2)
    e0 = sim.energy()
    sim.monitor("e", lambda s: [s.energy()["total"], s.contacts.numpy()["moment"][0]], every=10)
    sim.run(until=3 * t_rev)
    _, h = sim.histories()["e"]
    e1 = sim.energy()
    if model == 2:
        assert h[-1, 1] == 0.0                      # it did break
        assert e1["dissipated"] == pytest.approx(m0 ** 2 / (2 * km), rel=0.01)
    else:
        assert h[-1, 1] == pytest.approx(m0, rel=1e-9)
        # plastic work M₀ × plastic rotation: 0.03 rad before the reversal, then
        # 0.18 rad back of which 2 θ_y = 0.12 rad elastic, 0.06 rad plastic
        assert e1["dissipated"] == pytest.approx(m0 * (0.5 + 1.0) * theta0, rel=0.01)
    assert e1["boundary_work"] > 0.1
    released = m0 ** 2 / (2 * km)
    assert np.abs(h[:, 0] - e0["total"]).max() < 0.01 * released
