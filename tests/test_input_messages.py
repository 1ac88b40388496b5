"""Bad input refused with the argument named, and nothing half-built left behind."""
import numpy as np
import pytest

import tdem

LAW = tdem.LinearContact(kn=1e6)


def _two():
    sim = tdem.Simulation(gravity=(0.0, 0.0), dt=1e-4)
    sim.add_particles([[0.0, 0.0], [0.2, 0.0]], 0.05, contact=LAW)
    return sim


@pytest.mark.parametrize("call, match", [
    (lambda: tdem.Simulation(dt_fraction="x"), r"^dt_fraction must be a number, got 'x'"),
    (lambda: tdem.Simulation(local_damping="lots"), r"^local_damping must be a number >= 0"),
    (lambda: tdem.Simulation().add_particles([[0, 0]], "big", contact=LAW),
     r"^radius must be a number or one per particle \(1\), got 'big'"),
    (lambda: tdem.Simulation().add_particles([[0, 0], [1, 0]], 0.1, density=[1, 2, 3],
                                             contact=LAW),
     r"^density must be a number or one per particle \(2\), got shape \(3,\)"),
    (lambda: _two().fix_particles([0], vx="fast"), r"^vx must be None, a finite number"),
    (lambda: _two().monitor("m", len, every="often"), r"^every must be a whole number"),
])
def test_string_and_shape_mistakes_name_the_argument(call, match):
    with pytest.raises(tdem.InputError, match=match):
        call()


def test_a_monitor_returning_text_is_named():
    sim = _two()
    sim.monitor("label", lambda s: "hello", every=1)
    with pytest.raises(tdem.InputError, match=r"monitor 'label'.*number.*'hello'"):
        sim.run(steps=3)


def test_coincident_centres_are_refused_at_input():
    sim = tdem.Simulation()
    with pytest.raises(tdem.InputError, match=r"^positions: particles 1 and 2 have the same "
                                              r"centre \(0\.5, 0\.0\)"):
        sim.add_particles([[0.0, 0.0], [0.5, 0.0], [0.5, 0.0]], 0.1, contact=LAW)
    assert sim.n_particles == 0
    sim = _two()
    sim.run(steps=1)
    with pytest.raises(tdem.InputError, match=r"particles 1 and 2 have the same centre"):
        sim.add_particles([[0.2, 0.0]], 0.05, contact=LAW)
    assert sim.n_particles == 2


def test_a_refused_pcmm_addition_leaves_nothing_behind():
    sim = tdem.Simulation(gravity=(0.0, 0.0))
    with pytest.raises(tdem.InputError, match=r"^positions must be finite: row 1"):
        sim.add_particles([[0.0, 0.0], [np.nan, 0.0]], 0.05,
                          material=tdem.Elastic(density=2500.0, young=1e8, poisson=0.25))
    assert sim._slots == [] and sim._laws == [] and sim.n_particles == 0
    # the model still takes DEM particles and runs (it refused them before)
    sim.add_particles([[0.0, 0.0], [0.2, 0.0]], 0.05, contact=LAW,
                      velocity=[[1.0, 0.0], [0.0, 0.0]])
    sim.run(steps=10)
    assert sim.particles.numpy()["position"][0, 0] == pytest.approx(10 * sim.dt, rel=1e-12)


def test_a_pair_coupled_twice_is_refused():
    sim = _two()
    v = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]) + [0.0, -1.06]
    t = np.array([[0, 1, 2], [0, 2, 3]])
    mat = tdem.Elastic(density=2500.0, young=1e8, poisson=0.25)
    block = sim.add_block(v, t, material=mat)
    other = sim.add_block(v + [2.0, 0.0], t, material=mat)
    law = tdem.PointEdge(kn=1e6, ks=1e6)
    sim.couple([0, 1], block, law)
    with pytest.raises(tdem.InputError, match=r"^a: particles \[1\] are coupled to .* already"):
        sim.couple([1], block, law)
    sim.couple([1], other, law)                       # another block: fine
    sim.couple(block, other, law)
    with pytest.raises(tdem.InputError, match=r"^a: the blocks .* are coupled already"):
        sim.couple(other, block, law)
