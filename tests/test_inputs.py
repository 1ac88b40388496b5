"""Bad input (docs/api.md, its rules for input): a ValueError
(tdem.InputError) whose message names the argument and the bad value; nothing
half-built is left behind; an unstable run raises tdem.InstabilityError naming the
step, the time and the particle, and keeps the last good state."""
import math

import numpy as np
import pytest

import tdem

LAW = tdem.LinearContact(kn=1e6)


def raises(match):
    return pytest.raises(ValueError, match=match)


def test_input_error_is_a_value_error():
    assert issubclass(tdem.InputError, ValueError)
    with pytest.raises(tdem.InputError):
        tdem.LinearContact(kn=-1.0)


# -- particles -------------------------------------------------------------
@pytest.mark.parametrize("bad", [0.0, -0.1])
def test_radius_not_positive(bad):
    sim = tdem.Simulation()
    with raises(rf"radius.*particle 1.*{bad}"):
        sim.add_particles([[0, 0], [1, 0]], [0.1, bad], contact=LAW)


def test_radius_nan():
    sim = tdem.Simulation()
    with raises(r"radius.*nan"):
        sim.add_particles([[0, 0]], float("nan"), contact=LAW)


@pytest.mark.parametrize("bad", [0.0, -2500.0])
def test_density_not_positive(bad):
    sim = tdem.Simulation()
    with raises(rf"density.*{bad}"):
        sim.add_particles([[0, 0]], 0.1, density=bad, contact=LAW)


@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_positions_not_finite(bad):
    sim = tdem.Simulation()
    with raises(rf"positions.*row 1.*{bad}"):
        sim.add_particles([[0, 0], [bad, 1.0]], 0.1, contact=LAW)


@pytest.mark.parametrize("shape", [(3, 3), (3,), (2, 2, 2)])
def test_positions_wrong_shape(shape):
    sim = tdem.Simulation()
    with raises(rf"positions.*shape.*{re_shape(shape)}"):
        sim.add_particles(np.zeros(shape), 0.1, contact=LAW)


def re_shape(shape):
    return r"\(" + r", ".join(str(k) for k in shape) + (r",\)" if len(shape) == 1 else r"\)")


def test_radius_wrong_length():
    sim = tdem.Simulation()
    with raises(r"radius.*\(3\).*shape \(2,\)"):
        sim.add_particles(np.zeros((3, 2)) + [[0, 0], [1, 0], [2, 0]], [0.1, 0.2], contact=LAW)


def test_velocity_wrong_shape_and_nan():
    sim = tdem.Simulation()
    with raises(r"velocity.*\(3, 2\).*shape \(2, 2\)"):
        sim.add_particles([[0, 0], [1, 0], [2, 0]], 0.1, contact=LAW, velocity=np.zeros((2, 2)))
    with raises(r"velocity.*nan"):
        sim.add_particles([[0, 0]], 0.1, contact=LAW, velocity=[np.nan, 0.0])


def test_contact_missing_or_wrong_type():
    sim = tdem.Simulation()
    with raises(r"contact"):
        sim.add_particles([[0, 0]], 0.1)
    with raises(r"contact.*'steel'"):
        sim.add_particles([[0, 0]], 0.1, contact="steel")


# -- contact laws ----------------------------------------------------------
@pytest.mark.parametrize("bad", [0.0, -1e6, float("nan")])
def test_stiffness_not_positive(bad):
    with raises(rf"kn.*{bad}"):
        tdem.LinearContact(kn=bad)


def test_shear_stiffness_negative():
    with raises(r"ks.*-5"):
        tdem.LinearContact(kn=1e6, ks=-5.0)


@pytest.mark.parametrize("bad", [0.0, -70e9])
def test_young_not_positive(bad):
    with raises(rf"young.*{bad}"):
        tdem.HertzMindlin(young=bad, poisson=0.2)


@pytest.mark.parametrize("bad", [0.5, -1.0, 0.7, -1.5])
def test_poisson_outside_open_interval(bad):
    with raises(rf"poisson.*\(-1.0, 0.5\).*{bad}"):
        tdem.HertzMindlin(young=70e9, poisson=bad)


@pytest.mark.parametrize("ok", [0.49, -0.99, 0.0])
def test_poisson_inside_is_accepted(ok):
    assert tdem.HertzMindlin(young=70e9, poisson=ok).poisson == ok


@pytest.mark.parametrize("law", ["linear", "hertz"])
@pytest.mark.parametrize("bad", [-0.1, float("nan")])
def test_friction_coefficient_negative(law, bad):
    """The DEM laws take a friction coefficient tan φ_μ; the contract's "friction
    angle outside [0, 90)" is a coefficient outside [0, ∞) here."""
    with raises(rf"friction.*{bad}"):
        if law == "linear":
            tdem.LinearContact(kn=1e6, friction=bad)
        else:
            tdem.HertzMindlin(young=70e9, poisson=0.2, friction=bad)


@pytest.mark.parametrize("law", ["linear", "hertz"])
@pytest.mark.parametrize("bad", [0.0, -0.5, 1.5])
def test_restitution_outside_zero_one(law, bad):
    with raises(rf"restitution.*\(0, 1\].*{bad}"):
        if law == "linear":
            tdem.LinearContact(kn=1e6, restitution=bad)
        else:
            tdem.HertzMindlin(young=70e9, poisson=0.2, restitution=bad)


def test_restitution_one_is_elastic():
    assert tdem.LinearContact(kn=1e6, restitution=1.0).restitution == 1.0


@pytest.mark.parametrize("name", ["cohesion", "damping_ratio"])
def test_other_law_parameters_negative(name):
    with raises(rf"{name}.*-1"):
        tdem.LinearContact(kn=1e6, **{name: -1.0})


def test_rolling_resistance_parameters():
    with raises(r"delta.*-0.4"):
        tdem.RollingResistance(delta=-0.4)
    with raises(r"model.*3"):
        tdem.RollingResistance(delta=0.4, model=3)


# -- simulation and time step ---------------------------------------------
@pytest.mark.parametrize("kw,match", [
    (dict(dt=-1e-4), r"dt.*-0.0001"),
    (dict(dt=0.0), r"dt.*0.0"),
    (dict(dt_fraction=1.5), r"dt_fraction.*1.5"),
    (dict(dt_fraction=0.0), r"dt_fraction.*0.0"),
    (dict(local_damping=1.0), r"local_damping.*1.0"),
    (dict(global_damping=-1.0), r"global_damping.*-1.0"),
    (dict(precision="f16"), r"precision.*f16"),
])
def test_simulation_arguments(kw, match):
    with raises(match):
        tdem.Simulation(**kw)


def _one_disc(**kw):
    sim = tdem.Simulation(gravity=(0.0, 0.0), **kw)
    sim.add_particles([[0, 0]], 0.1, density=1000.0, contact=LAW)
    return sim


def test_dt_above_critical_rejected_when_set():
    sim = _one_disc()
    crit = 2 * math.sqrt(1000.0 * math.pi * 0.01 / 1e6)        # 2 sqrt(m/k) = 0.01121 s
    assert sim.critical_dt() == pytest.approx(crit, rel=1e-12)
    with raises(r"dt=0.0113.*critical"):
        sim.dt = 0.0113
    assert sim.dt == pytest.approx(0.2 * crit)                   # unchanged
    sim.dt = 0.0112                                              # just below: accepted
    assert sim.dt == 0.0112


def test_dt_from_constructor_checked_at_run():
    """dt=... given before any particle exists can only be checked when the run starts."""
    sim = _one_disc(dt=0.05)
    with raises(r"dt=0.05.*critical"):
        sim.run(steps=1)
    assert sim.steps == 0 and sim.time == 0.0


def test_dt_rechecked_when_a_stiffer_law_arrives():
    sim = _one_disc(dt=0.01)
    sim.run(steps=2)
    sim.add_wall((-1, -0.2), (1, -0.2), contact=tdem.LinearContact(kn=1e8))
    with raises(r"dt=0.01.*critical"):
        sim.run(steps=1)
    assert sim.steps == 2


def test_wall_and_fix_arguments():
    sim = _one_disc()
    with raises(r"p1.*p0"):
        sim.add_wall((0.0, 0.0), (0.0, 0.0), contact=LAW)
    with raises(r"p0.*nan"):
        sim.add_wall((0.0, np.nan), (1.0, 0.0), contact=LAW)
    with raises(r"ids.*\[5\]"):
        sim.fix_particles([5], vx=0.0)
    with raises(r"vx.*nan"):
        sim.fix_particles([0], vx=np.nan)
    with raises(r"until.*steps"):
        sim.run(until=1.0, steps=10)
    with raises(r"steps.*-1"):
        sim.run(steps=-1)


# -- nothing half-built ----------------------------------------------------
@pytest.mark.parametrize("built", [False, True])
def test_failed_add_leaves_nothing_behind(built):
    sim = tdem.Simulation(gravity=(0.0, -9.81))
    sim.add_particles([[0.0, 0.1], [0.3, 0.1]], 0.1, density=1000.0, contact=LAW)
    sim.add_wall((-1.0, 0.0), (1.0, 0.0), contact=LAW)
    if built:
        sim.run(steps=10)
    before = sim.particles.numpy()
    dt = sim.dt
    stiff = tdem.LinearContact(kn=1e12)
    bad_calls = [
        dict(positions=[[2.0, 0.1], [np.nan, 0.1]], radius=0.1),
        dict(positions=[[2.0, 0.1], [2.3, 0.1]], radius=[0.1, -0.1]),
        dict(positions=[[2.0, 0.1], [2.3, 0.1]], radius=0.1, density=0.0),
        dict(positions=[[2.0, 0.1], [2.3, 0.1]], radius=0.1, velocity=np.zeros((3, 2))),
    ]
    for kw in bad_calls:
        with pytest.raises(ValueError):
            sim.add_particles(contact=stiff, **kw)
        assert sim.n_particles == 2
        assert len(sim.particles) == 2
    after = sim.particles.numpy()
    for k in ("position", "velocity", "radius", "mass"):
        np.testing.assert_array_equal(after[k], before[k])
    # the failed calls did not change the time step (the stiff law is not in use)
    assert sim.dt == dt
    # a valid add afterwards works, and the run goes on
    g = sim.add_particles([[0.6, 0.1]], 0.1, density=1000.0, contact=LAW)
    assert list(g.ids) == [2] and sim.n_particles == 3
    steps = sim.steps
    sim.run(steps=20)
    assert sim.steps == steps + 20
    p = sim.particles.numpy()
    assert p["position"].shape == (3, 2) and np.isfinite(p["position"]).all()
    assert p["mass"][2] == pytest.approx(1000.0 * math.pi * 0.01)


# -- instability -----------------------------------------------------------
def test_instability_named_and_last_good_state_kept():
    """Discs 3 and 4 overlap by 0.4 R at the one-contact critical step (dt_fraction =
    1, k Δt²/m = 4): their contact force would move each by 4 × 0.4 R = 1.6 R in the
    first step, which no stable step does. The run stops at step 1 naming the larger
    index of the two, and the state before that step is kept."""
    pos = np.array([[0.0, 0.0], [0.3, 0.0], [0.6, 0.0], [0.9, 0.0], [1.06, 0.0]])
    vel = np.zeros((5, 2))
    sim = tdem.Simulation(gravity=(0.0, -9.81), dt_fraction=1.0)
    sim.add_particles(pos, 0.1, density=1000.0, contact=LAW, velocity=vel)
    with pytest.raises(tdem.InstabilityError) as info:
        sim.run(steps=500)
    e = info.value
    assert e.step == 1 and e.particle == 4
    assert e.time == pytest.approx(sim.dt)
    assert "step 1" in str(e) and "particle 4" in str(e)
    assert sim.steps == 0 and sim.time == 0.0
    s = sim.particles.numpy()
    np.testing.assert_array_equal(s["position"], pos)
    np.testing.assert_array_equal(s["velocity"], vel)


def test_a_fast_disc_is_not_an_instability():
    """A disc thrown at 1e6 m/s moves 1e4 radii a step: it flies on (x = x0 + v t
    exactly, under gravity the leapfrog's y = −g Δt² N(N + 1)/2), and a warning names
    it once."""
    pos = np.array([[0.0, 0.0], [0.3, 0.0], [0.6, 0.0], [0.9, 0.0], [1.2, 0.0]])
    vel = np.zeros((5, 2))
    vel[3] = [1e6, 0.0]
    sim = tdem.Simulation(gravity=(0.0, -9.81), dt_fraction=0.1, check_interval=5)
    sim.add_particles(pos, 0.1, density=1000.0, contact=LAW, velocity=vel)
    dt = sim.dt
    with pytest.warns(RuntimeWarning, match=r"particle 3 moved more than its radius .*"
                                            r"speed .*: 1e\+06 m/s") as rec:
        sim.run(steps=20)
    assert sum("moved more than its radius" in str(w.message) for w in rec) == 1
    s = sim.particles.numpy()
    assert s["position"][3, 0] == pytest.approx(0.9 + 1e6 * 20 * dt, rel=1e-12)
    assert s["position"][3, 1] == pytest.approx(-9.81 * dt * dt * 20 * 21 / 2, rel=1e-12)


def test_free_fall_faster_than_a_radius_a_step_goes_on():
    """A disc falling from 40 m/s under gravity (dt = 1 ms, R = 0.05 m) passes R/Δt =
    50 m/s after (50 − 40)/(g Δt) = 1019.4 steps. It is in free flight: the run goes
    on to 5,000 steps (the limit of the engine was once |v| Δt > R/2), on the
    leapfrog's exact path y_N = −40 N Δt − g Δt² N(N + 1)/2, v_N = −40 − N g Δt,
    with one warning naming it and the speed it passed."""
    dt, g, N = 1e-3, 9.81, 5000
    pos = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]])
    vel = np.zeros((3, 2))
    vel[1] = [0.0, -40.0]
    sim = tdem.Simulation(gravity=(0.0, -g), dt=dt, check_interval=100)
    sim.add_particles(pos, 0.05, density=1000.0, contact=LAW, velocity=vel)
    with pytest.warns(RuntimeWarning, match=r"particle 1 moved more than its radius "
                                            r"\(0\.05 m\) in one step: faster than 50 m/s"):
        sim.run(until=N * dt)
    assert sim.steps == N
    s = sim.particles.numpy()
    assert s["velocity"][1, 1] == pytest.approx(-40.0 - N * g * dt, rel=1e-12)
    assert s["position"][1, 1] == pytest.approx(-40.0 * N * dt - g * dt * dt * N * (N + 1) / 2,
                                                rel=1e-12)
    # the others, from rest, stay below 50 m/s and fall the same way
    assert s["position"][0, 1] == pytest.approx(-g * dt * dt * N * (N + 1) / 2, rel=1e-12)
