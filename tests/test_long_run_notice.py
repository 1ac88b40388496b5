"""A run estimated to take long says so on stderr, before most of it has run: its
time step, its number of steps and the estimated wall time; short runs say nothing."""
import re

import numpy as np
import pytest

import tdem
from tdem import runner

NOTICE = re.compile(r"tdem: a long run: (\d+) steps of dt = ([0-9.e+-]+) s \(([0-9.e+-]+) s "
                    r"of simulated time, to t = ([0-9.e+-]+) s\), about (.+) of wall time at "
                    r"([0-9.e+-]+) steps/s \((\d+) particles and nodes\)")


def _model():
    sim = tdem.Simulation(gravity=(0.0, -9.81), check_interval=20, progress=None)
    xs = (np.arange(12) + 0.5) * 0.02
    sim.add_particles(np.array([(x, y) for y in xs for x in xs]), 0.009,
                      contact=tdem.LinearContact(kn=1e6))
    sim.add_wall((0.0, 0.0), (0.24, 0.0), contact=tdem.LinearContact(kn=1e6))
    return sim


def test_a_long_run_is_announced_with_its_dt_and_steps(monkeypatch, capsys):
    sim = _model()
    sim.run(steps=40)                        # compiled; the notice measures the rate
    capsys.readouterr()
    # every run is "long" here: the notice comes after the rate is measured
    monkeypatch.setattr(runner, "ANNOUNCE_SECONDS", 0.0)
    monkeypatch.setattr(runner, "ANNOUNCE_MEASURE", 0.0)
    t0, dt = sim.time, sim.dt
    sim.run(until=t0 + 3000 * dt + 0.5 * dt)
    err = capsys.readouterr().err
    found = NOTICE.findall(err)
    assert len(found) == 1, err
    steps, dt_text, span, until, wall, rate, bodies = found[0]
    assert int(steps) == 3001 == sim.steps - 40
    assert float(dt_text) == pytest.approx(dt, rel=1e-5)
    assert float(span) == pytest.approx(3001 * dt, rel=1e-5)
    assert float(until) == pytest.approx(sim.time, rel=1e-5)
    assert int(bodies) == 144
    assert float(rate) > 0.0 and wall.endswith("s")


def test_a_short_run_says_nothing_and_progress_false_silences(monkeypatch, capsys):
    sim = _model()
    sim.run(steps=40)
    capsys.readouterr()
    sim.run(steps=400)                        # well under 30 s
    assert "long run" not in capsys.readouterr().err
    monkeypatch.setattr(runner, "ANNOUNCE_SECONDS", 0.0)
    monkeypatch.setattr(runner, "ANNOUNCE_MEASURE", 0.0)
    sim.progress = False
    sim.run(steps=400)
    assert "long run" not in capsys.readouterr().err


def test_durations_read_well():
    assert [runner._duration(s) for s in (4.2, 89.6, 200.0, 7260.0)] == \
        ["4 s", "90 s", "3 min 20 s", "2 h 01 min"]
