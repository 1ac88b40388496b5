"""Servo-controlled walls hold a target force on a granular sample."""
import numpy as np
import pytest

import tdem


def _sample():
    law = tdem.LinearContact(kn=1e6, friction=0.5)
    sim = tdem.Simulation(gravity=(0.0, 0.0), local_damping=0.3)
    rng = np.random.default_rng(7)
    side = 12
    xy = (np.stack(np.meshgrid(np.arange(side), np.arange(side)), -1).reshape(-1, 2) + 0.5) * 0.021
    sim.add_particles(xy, rng.uniform(0.0085, 0.0105, len(xy)), density=2500.0, contact=law)
    w = side * 0.021
    walls = {"bottom": sim.add_wall((0.0, 0.0), (w, 0.0), contact=law),
             "right": sim.add_wall((w, 0.0), (w, 2 * w), contact=law),
             "left": sim.add_wall((0.0, 2 * w), (0.0, 0.0), contact=law),
             "top": sim.add_wall((w, w), (0.0, w), contact=law)}
    return sim, walls


def test_servo_wall_holds_its_target_through_lateral_compression():
    sim, walls = _sample()
    target = 2000.0                      # N per metre of thickness
    top = walls["top"].servo(force=target)
    assert np.allclose(top._row()[14:16], [0.0, -1.0])   # moves down, into the sample
    sim.monitor("top", lambda s: walls["top"].force[1], every=20)   # pushed up
    sim.run(until=0.4)
    t, f = sim.histories()["top"]
    settled = f[t > 0.3]
    assert settled.mean() == pytest.approx(target, rel=0.02)
    assert np.abs(settled - target).max() < 0.02 * target
    # squeeze the sample sideways: the servo moves the top wall and keeps the force
    y0 = walls["top"].endpoints[0, 1]
    walls["left"].velocity = (0.002, 0.0)
    walls["right"].velocity = (-0.002, 0.0)
    sim.run(until=1.4)
    t, f = sim.histories()["top"]
    late = f[t > 0.8]      # after the rearrangement the squeeze sets off (about 0.5-0.7 s)
    assert abs(walls["top"].endpoints[0, 1] - y0) > 1e-3
    assert late.mean() == pytest.approx(target, rel=0.02)
    assert np.abs(late - target).max() < 0.05 * target
    # switched off, the wall stops
    walls["top"].servo()
    assert np.allclose(walls["top"].velocity, 0.0)


def test_servo_arguments():
    sim, walls = _sample()
    with pytest.raises(tdem.InputError, match="relaxation"):
        walls["top"].servo(force=1.0, relaxation=2.0)
    with pytest.raises(tdem.InputError, match="force or stress"):
        walls["top"].servo(force=1.0, stress=2.0)
    with pytest.raises(tdem.InputError, match="direction"):
        walls["top"].servo(force=1.0, direction=(0.0, 0.0))
