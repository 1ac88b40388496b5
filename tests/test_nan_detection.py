"""NaN and infinity in the state stop the run with InstabilityError, although the
kernels are compiled with fast math (which folds `x != x` to False)."""
import math

import numpy as np
import pytest

import tdem


def _pair(precision="f64"):
    sim = tdem.Simulation(gravity=(0.0, 0.0), dt=1e-4, precision=precision, progress=False)
    sim.add_particles([[0.0, 0.0], [0.5, 0.0]], 0.1, contact=tdem.LinearContact(kn=1e6))
    return sim


@pytest.mark.parametrize("precision", ["f64", "f32"])
def test_prescribed_velocity_returning_nan_stops_the_run(precision):
    sim = _pair(precision)
    # NaN from t = 5e-3 (step 50 on): the step that applies it is found and named
    sim.fix_particles([0], vx=lambda t: math.nan if t >= 5e-3 - 1e-12 else 0.0)
    with pytest.raises(tdem.InstabilityError, match=r"particle 0 has position \[nan") as e:
        sim.run(steps=200)
    assert e.value.particle == 0
    assert e.value.step == 51
    # the last good state is kept
    assert sim.steps == 50
    assert np.isfinite(sim.particles.numpy()["position"]).all()


def test_infinite_prescribed_velocity_stops_the_run():
    sim = _pair()
    sim.fix_particles([1], vy=lambda t: math.inf if t > 2e-3 else 0.0)
    with pytest.raises(tdem.InstabilityError) as e:
        sim.run(steps=100)
    assert e.value.particle == 1


def test_nan_in_the_state_stops_the_run():
    sim = _pair()
    sim.run(steps=10)
    vel = sim._a["vel"].to_numpy()
    vel[1, 1] = np.nan
    sim._a["vel"].from_numpy(vel)
    with pytest.raises(tdem.InstabilityError, match="particle 1") as e:
        sim.run(steps=10)
    assert e.value.particle == 1


def test_nan_node_velocity_of_a_block_stops_the_run():
    v, t = tdem.mesh.rectangle(0.4, 0.2, 2, 1)
    sim = tdem.Simulation(gravity=(0.0, 0.0), dt=1e-5, progress=False)
    block = sim.add_block(v, t, material=tdem.Elastic(density=2500.0, young=1e7, poisson=0.25))
    block.fix([2], vx=lambda t: math.nan if t > 5e-5 else 0.0)
    with pytest.raises(tdem.InstabilityError, match="node 2 of block 0") as e:
        sim.run(steps=100)
    assert e.value.particle == -1
