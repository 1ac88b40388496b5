"""Checkpoints: a loaded simulation continues bit for bit; an aborted run leaves one."""
import warnings

import h5py
import numpy as np
import pytest

import tdem
from tdem.io import read_monitors


def _pile(n=300, seed=1):
    """``n`` discs falling into a box under gravity, with friction (shear history)."""
    law = tdem.LinearContact(kn=1e5, friction=0.5, restitution=0.5)
    sim = tdem.Simulation(gravity=(0.0, -9.81))
    rng = np.random.default_rng(seed)
    side = int(np.ceil(np.sqrt(n)))
    xs = (np.arange(side) + 0.5) * 0.025
    pos = np.array([(x, y) for y in xs for x in xs])[:n] + rng.uniform(-2e-3, 2e-3, (n, 2))
    pos[:, 1] += 0.05
    sim.add_particles(pos, rng.uniform(0.009, 0.011, n), density=2500.0, contact=law)
    w = side * 0.025
    sim.add_wall((0.0, 0.0), (w, 0.0), contact=law)
    sim.add_wall((w, 0.0), (w, 1.0), contact=law)
    sim.add_wall((0.0, 1.0), (0.0, 0.0), contact=law)
    return sim


def _assert_same_contacts(a, b):
    assert a.keys() == b.keys()
    for k in a:
        np.testing.assert_array_equal(a[k], b[k], err_msg=k)


def test_restart_continues_bitwise(tmp_path):
    k_steps, m_steps = 1500, 1500
    sim = _pile()
    sim.run(steps=k_steps)
    at_save = sim.contacts.numpy()
    assert len(at_save["pairs"]) > 300
    assert np.count_nonzero(at_save["shear"]) > 100      # shear springs are loaded
    walls_at_save = np.array([w.force for w in sim.walls])
    time_at_save = sim.time
    sim.save(tmp_path / "run.h5")
    sim.run(steps=m_steps)

    sim2 = tdem.Simulation.load(tmp_path / "run.h5")
    assert (sim2.time, sim2.steps, sim2.n_particles) == (time_at_save, k_steps, 300)
    assert sim2.dt == sim.dt
    _assert_same_contacts(sim2.contacts.numpy(), at_save)
    np.testing.assert_array_equal(np.array([w.force for w in sim2.walls]), walls_at_save)
    sim2.run(steps=m_steps)

    a, b = sim.particles.numpy(), sim2.particles.numpy()
    for key in ("position", "velocity", "omega", "force", "torque", "displacement", "stress"):
        assert np.array_equal(a[key], b[key]), key
    assert sim2.time == sim.time and sim2.steps == sim.steps == k_steps + m_steps
    _assert_same_contacts(sim2.contacts.numpy(), sim.contacts.numpy())
    assert sim2.neighbour_builds == sim.neighbour_builds
    # wall forces are summed with atomic additions: equal up to the order of the sum
    np.testing.assert_allclose(np.array([w.force for w in sim2.walls]),
                               np.array([w.force for w in sim.walls]), rtol=1e-12, atol=0)
    ea, eb = sim.energy(), sim2.energy()
    for key in ea:
        assert ea[key] == pytest.approx(eb[key], rel=1e-12, abs=1e-15), key


def test_loaded_simulation_keeps_configuration(tmp_path):
    hm = tdem.HertzMindlin(young=1e8, poisson=0.3, friction=0.4, restitution=0.6,
                           rolling=tdem.RollingResistance(delta=0.3, model=2))
    lin = tdem.LinearContact(kn=2e5, ks=1e5, friction=0.3, damping_ratio=0.01)
    sim = tdem.Simulation(gravity=(0.5, -9.0), dt_fraction=0.15, local_damping=0.1,
                          global_damping=0.2, skin=0.003, check_interval=40)
    ga = sim.add_particles([[0.02 * i, 0.011] for i in range(5)], 0.01, density=2000.0,
                           contact=hm)
    gb = sim.add_particles([[0.02 * i + 0.01, 0.03] for i in range(4)], 0.008, density=3000.0,
                           contact=lin)
    sim.set_contact(ga, gb, lin)
    wall = sim.add_wall((-0.05, 0.0), (0.15, 0.0), contact=lin, velocity=(0.01, 0.0))
    sim.fix_particles([0, 1], vx=0.0, vy=[0.1, -0.1])
    with pytest.warns(UserWarning, match="omega"):
        sim.fix_particles([2], vx=None, omega=lambda t: 3.0 * t)
        sim.run(steps=120)
        sim.save(tmp_path / "cfg.h5")

    s2 = tdem.Simulation.load(tmp_path / "cfg.h5")
    assert s2.gravity.tolist() == [0.5, -9.0]
    assert (s2.dt_fraction, s2.local_damping, s2.global_damping, s2.skin, s2.check_interval) == \
        (0.15, 0.1, 0.2, 0.003, 40)
    assert s2.dt == sim.dt and s2.time == sim.time and s2.steps == 120
    assert [law.row() for law in s2._laws] == [law.row() for law in sim._laws]
    assert s2._pair_override == sim._pair_override
    assert [len(g) for g in s2._groups] == [5, 4]
    assert s2._groups[0].contact is s2._laws[0] and s2._groups[1].contact is s2._laws[1]
    np.testing.assert_array_equal(s2._groups[1].density, 3000.0)
    np.testing.assert_array_equal(s2.walls[0].endpoints, wall.endpoints)
    np.testing.assert_array_equal(s2.walls[0].velocity, [0.01, 0.0])
    fixed = s2._a["fix"].to_numpy()
    assert fixed.tolist()[:3] == [3, 3, 0]            # the function of time was not saved
    np.testing.assert_array_equal(s2._a["vfix"].to_numpy()[:2, :2], [[0.0, 0.1], [0.0, -0.1]])

    # the loaded simulation accepts more particles and runs on
    s2.add_particles([[0.05, 0.08]], 0.009, contact=lin)
    assert s2.n_particles == 10 and len(s2._groups) == 3
    s2.run(steps=50)
    p = s2.particles.numpy()
    assert np.isfinite(p["position"]).all()
    np.testing.assert_array_equal(p["velocity"][:2], [[0.0, 0.1], [0.0, -0.1]])


def test_save_before_any_step_and_constant_fixes_restart_exactly(tmp_path):
    sim = _pile(n=60, seed=4)
    sim.fix_particles([0, 5], vx=0.05, vy=0.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sim.save(tmp_path / "start.h5")
    sim.run(steps=400)
    s2 = tdem.Simulation.load(tmp_path / "start.h5")
    assert s2.steps == 0 and s2.time == 0.0
    s2.run(steps=400)
    for key in ("position", "velocity", "omega"):
        assert np.array_equal(sim.particles.numpy()[key], s2.particles.numpy()[key]), key


def test_not_a_checkpoint(tmp_path):
    with h5py.File(tmp_path / "other.h5", "w") as f:
        f["x"] = np.zeros(3)
    with pytest.raises(ValueError, match="not a tdem checkpoint"):
        tdem.Simulation.load(tmp_path / "other.h5")


def test_unstable_run_leaves_last_good_state(tmp_path):
    sim = _pile(n=100, seed=2)
    sim.monitor("kinetic", lambda s: s.energy()["kinetic"], every=50)
    out = sim.output(tmp_path, every=100)
    sim.run(steps=200)
    # two discs overlapping by 0.6 R with a contact of k Δt²/m = 2.8 (the step kept,
    # just below the critical step of the smallest disc, R = 0.009 m, with it): its
    # force would move each 1.7 R in one step (the larger index of the two is named)
    dt = sim.dt
    sim.dt = dt
    m = 2500.0 * np.pi * 0.009 ** 2
    stiff = tdem.LinearContact(kn=3.5 * m / dt ** 2)
    sim.add_particles([[0.1, 0.6], [0.114, 0.6]], 0.01, contact=stiff, velocity=(1e-3, 0.0))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)     # above the dense packing's step
        with pytest.raises(tdem.InstabilityError) as err:
            sim.run(steps=300)
    assert err.value.step == 201 and err.value.particle == 101
    assert sim.steps == 200

    assert (tmp_path / "last_good.h5").exists() and (tmp_path / "monitors.h5").exists()
    with h5py.File(tmp_path / "last_good.h5", "r") as f:
        assert f.attrs["abort_reason"] == "unstable"
    good = tdem.Simulation.load(tmp_path / "last_good.h5")
    assert good.steps == 200 and good.time == sim.time and good.n_particles == 102
    for key in ("position", "velocity", "omega"):
        assert np.array_equal(good.particles.numpy()[key], sim.particles.numpy()[key]), key
    assert good.particles.numpy()["velocity"][100, 0] == 1e-3

    hist = read_monitors(tmp_path / "monitors.h5")
    t, v = sim.histories()["kinetic"]
    assert len(t) == 4 and t[-1] == sim.time          # steps 50 ... 200, none after
    np.testing.assert_array_equal(hist["kinetic"][0], t)
    np.testing.assert_array_equal(hist["kinetic"][1], v)
    # the series lists no snapshot after the last good step
    assert [s for s, _ in out.snapshots] == [0, 100, 200]
    assert not (tmp_path / "particles_00003.vtu").exists()


def test_interrupted_run_flushes_output_and_keeps_a_consistent_state(tmp_path):
    """Ctrl-C during a run: the state goes back to the last checked step (never a half
    step), the monitors are flushed and last_good.h5 restarts exactly from it."""
    sim = _pile(n=100, seed=3)
    sim.check_interval = 40
    calls = []

    def interrupt_at_130(s):
        calls.append(s.steps)
        if s.steps == 130:
            raise KeyboardInterrupt
        return s.steps

    sim.monitor("steps", interrupt_at_130, every=10)
    sim.output(tmp_path, every=50)
    with pytest.raises(KeyboardInterrupt):
        sim.run(steps=300)
    assert sim.steps == 120                      # the last check before the interrupt
    assert sim.histories()["steps"][1].tolist() == list(range(10, 130, 10))
    with h5py.File(tmp_path / "last_good.h5", "r") as f:
        assert f.attrs["abort_reason"] == "interrupted"
    good = tdem.Simulation.load(tmp_path / "last_good.h5")
    assert good.steps == 120
    assert np.array_equal(good.particles.numpy()["position"], sim.particles.numpy()["position"])
    assert read_monitors(tmp_path / "monitors.h5")["steps"][1].tolist() == list(range(10, 130, 10))
    # both continue identically
    sim._monitors.clear()
    sim._output = None
    sim.run(steps=60)
    good.run(steps=60)
    assert np.array_equal(good.particles.numpy()["position"], sim.particles.numpy()["position"])
