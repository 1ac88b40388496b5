"""Rolling resistance of Jiang, Yu & Harris (2005) at one contact.

Two discs (or a disc and a wall) are held in place with a fixed normal overlap u,
so F_n = K_n u; one disc is spun at a prescribed ω, the relative rotation
θ_r = ∫(ω_i − ω_j) dt grows linearly and the couple follows the model:

- both models: elastic branch M = −K_m θ_r (on i), K_m = K_n B²/12, B = δ r̄,
  r̄ = 2 r_i r_j/(r_i + r_j) (2 r_i against a wall);
- Model 1: |M| ≤ M₀ = F_n B/6 (perfectly plastic), elastic unloading on reversal;
- Model 2 (Eq. 36 as written): M = −K_m θ_r while |θ_r| <= θ_r⁰ = 2 F_n/(K_n B), 0
  above, so the couple comes back when the rotation returns; with
  ``permanent_break=True`` it stays 0 once it has dropped;
- θ_r counts from the moment the rolling model is switched on (Jiang: θ_r = 0 ↔ M = 0):
  a contact that rolled while the model was off starts from M = 0.
"""

import numpy as np
import pytest

import tdem

KN, U, DELTA = 1e6, 1e-3, 0.5
DT, DT_WALL = 4e-4, 1.5e-4   # the yield rotation is reached in 150 and 133 steps (w = 1 rad/s)
RI, RJ = 0.1, 0.05


def spin_pair(model, w, t_rev, until, wall=False, every=2, permanent=False):
    """Disc 0 spun at ω = w until t_rev, then at −w, against disc 1 (held, not
    spinning) or a wall. Returns (θ_r, M, F_n) at the recorded steps, θ_r the
    relative rotation the contact has accumulated in those steps."""
    dt = DT_WALL if wall else DT

    def omega(t):
        return w if t < t_rev - 1e-12 else -w

    sim = tdem.Simulation(gravity=(0.0, 0.0), dt=dt)
    law = tdem.LinearContact(kn=KN, ks=KN, friction=0.5,
                             rolling=tdem.RollingResistance(delta=DELTA, model=model,
                                                            permanent_break=permanent))
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
def test_model2_permanent_break(wall):
    fn_ref, km, m0, theta0 = reference(wall)
    w = 1.0
    t_rev = 1.5 * theta0 / w
    theta, mom, fn = spin_pair(2, w, t_rev, until=4 * t_rev, wall=wall, every=1,
                               permanent=True)
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


@pytest.mark.parametrize("wall", [False, True])
def test_model2_is_eq36_as_written(wall):
    """Eq. 36 read as a function of θ_r: the couple is −K_m θ_r inside |θ_r| <= θ_r⁰
    and zero outside, on the way out (+θ_r⁰), back (the couple returns below θ_r⁰),
    through zero and out again past −θ_r⁰."""
    fn_ref, km, m0, theta0 = reference(wall)
    w = 1.0
    t_rev = 1.5 * theta0 / w
    theta, mom, fn = spin_pair(2, w, t_rev, until=4 * t_rev, wall=wall, every=1)
    step = w * (DT_WALL if wall else DT)
    inside = np.abs(theta) < theta0 - 1.5 * step
    outside = np.abs(theta) > theta0 + 1.5 * step
    assert inside.sum() > 200 and outside.sum() > 100
    assert mom[inside] == pytest.approx(-km * theta[inside], rel=1e-9, abs=1e-3 * m0)
    assert np.all(mom[outside] == 0.0)
    # it was out, came back (a couple after the first drop) and went out the other way
    first_out = np.argmax(outside)
    back = inside & (np.arange(len(theta)) > first_out)
    assert back.sum() > 200
    assert theta.min() < -theta0 and mom[-1] == 0.0


@pytest.mark.parametrize("model", [1, 2])
@pytest.mark.parametrize("dim", [2, 3])
def test_rotation_counts_from_the_switch_on(model, dim):
    """A contact that rolled while the rolling resistance was off (as during a
    specimen's preparation) starts from M = 0 when the model is switched on: the
    couple is −K_m times the rotation since then (Jiang: θ_r = 0 corresponds to M = 0).
    Before the fix the rotation of the preparation counted in 2D, and a Model 2 contact
    started broken; in 3D a law given rolling resistance after the arrays were built
    had no rolling columns, and rolled on without a couple."""
    fn_ref, km, m0, theta0 = reference()
    w, dt = 1.0, DT
    sim = tdem.Simulation(dim=dim, gravity=(0.0,) * dim, dt=dt)
    law = tdem.LinearContact(kn=KN, ks=KN, friction=0.5)
    pos = np.array([[0.0, 0.0, 0.0], [RI + RJ - U, 0.0, 0.0]])[:, :dim]
    sim.add_particles(pos, [RI, RJ], density=1000.0, contact=law)
    held = dict(vx=0.0, vy=0.0) if dim == 2 else dict(vx=0.0, vy=0.0, vz=0.0)
    spin = (lambda x: x) if dim == 2 else (lambda x: (0.0, 0.0, x))
    sim.fix_particles([1], omega=spin(0.0), **held)
    sim.fix_particles([0], omega=spin(w), **held)
    sim.run(steps=400)                      # rolls 0.16 rad = 2.7 θ_r⁰ with the model off
    law.update(rolling=tdem.RollingResistance(delta=DELTA, model=model))
    sim.run(steps=60)                       # 0.024 rad since the switch: elastic in both
    c = sim.contacts.numpy()
    moment = c["moment"][0] if dim == 2 else c["moment"][0][2]
    # the first step after the switch sees the rotation of that step (ω held at w)
    assert moment == pytest.approx(-km * 60 * w * dt, rel=1e-6)
    assert c["normal"][0] == pytest.approx(fn_ref, rel=1e-9)


@pytest.mark.parametrize("model, permanent", [(1, False), (2, False), (2, True)])
def test_energy_account_through_yield_and_break(model, permanent):
    """The driven disc does work on the contact (booked as boundary work); it goes
    into the rolling spring and into dissipation (plastic rolling; for Model 2 the
    spring's energy M₀²/(2 K_m) = 0.167 J released at the break; read as Eq. 36 the
    couple drops at +θ_r⁰, comes back at +θ_r⁰ on the way back (−0.167 J booked as
    the spring takes its energy back) and drops again at −θ_r⁰). The total stays
    constant through yield, reversal and break (before the fix of the break booking
    it dropped by 0.167 J). Frictionless, so that only the couple works; dt = 1e-4 s
    because the account pairs the work of the prescribed spin at step n with the
    spring energy at t_n, an offset of ≈ M·ω·Δt/2 (3e-4 J here) that flips sign
    when the spin reverses."""
    fn_ref, km, m0, theta0 = reference()
    dt = 1e-4
    sim = tdem.Simulation(gravity=(0.0, 0.0), dt=dt)
    law = tdem.LinearContact(kn=KN, ks=KN, friction=0.0,
                             rolling=tdem.RollingResistance(delta=DELTA, model=model,
                                                            permanent_break=permanent))
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


@pytest.mark.parametrize("permanent", [False, True])
def test_model2_in_3d_returns_as_eq36_or_stays_broken(permanent):
    """The vector form in 3D: two spheres pressed together along x, one spun about z
    out past θ_r⁰ and back: inside |θ_r| <= θ_r⁰ the couple is −K_m θ_r (about z),
    outside zero; back inside it returns (Eq. 36) or stays zero (permanent break)."""
    fn_ref, km, m0, theta0 = reference()
    w, dt = 1.0, DT
    sim = tdem.Simulation(dim=3, gravity=(0.0, 0.0, 0.0), dt=dt)
    law = tdem.LinearContact(kn=KN, ks=KN, friction=0.5,
                             rolling=tdem.RollingResistance(delta=DELTA, model=2,
                                                            permanent_break=permanent))
    sim.add_particles([[0.0, 0.0, 0.0], [RI + RJ - U, 0.0, 0.0]], [RI, RJ],
                      density=1000.0, contact=law)
    sim.fix_particles([1], vx=0.0, vy=0.0, vz=0.0, omega=(0.0, 0.0, 0.0))
    sim.fix_particles([0], vx=0.0, vy=0.0, vz=0.0, omega=(0.0, 0.0, w))

    def couple():
        c = sim.contacts.numpy()
        return np.asarray(c["moment"][0], float)

    n_out = int(round(0.5 * theta0 / (w * dt)))
    sim.run(steps=n_out)                                  # θ_r = θ_r⁰/2: elastic
    m = couple()
    # (the first step sees ω = 0: the spin is imposed at the end of a step)
    assert m[2] == pytest.approx(-km * (n_out - 1) * w * dt, rel=1e-6)
    assert np.abs(m[:2]).max() < 1e-9 * m0
    sim.run(steps=2 * n_out)                              # θ_r = 1.5 θ_r⁰: dropped
    assert np.abs(couple()).max() == 0.0
    sim.fix_particles([0], vx=0.0, vy=0.0, vz=0.0, omega=(0.0, 0.0, -w))
    sim.run(steps=2 * n_out)                              # back to θ_r⁰/2
    m = couple()
    if permanent:
        assert np.abs(m).max() == 0.0
    else:
        assert m[2] == pytest.approx(-0.5 * km * theta0, rel=0.02)
