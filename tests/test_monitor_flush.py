"""Monitor histories reach monitors.h5 while the run goes on (at most about a second
of wall-clock time behind) and whenever a run stops: a process killed with SIGKILL
leaves the records up to the kill; an unstable run keeps the records of its last
segment up to the last good step."""
import math
import os
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest

import tdem
from tdem.io import read_monitors

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def _steps_in(path):
    import h5py
    try:
        with h5py.File(path, "r") as f:
            return f["y/step"][()]
    except (OSError, KeyError):
        return None


@pytest.mark.skipif(sys.platform == "win32", reason="SIGKILL")
@pytest.mark.parametrize("flush_interval", [0.0, None])
def test_sigkill_leaves_the_records_up_to_the_kill(tmp_path, flush_interval):
    out = tmp_path / "out"
    log = tmp_path / "recorded.txt"
    setting = "" if flush_interval is None else f"o.flush_interval = {flush_interval}"
    code = textwrap.dedent(f"""
        import time
        import tdem
        sim = tdem.Simulation(gravity=(0.0, -9.81), dt=1e-4, progress=False)
        sim.add_particles([[0.0, 0.0]], 0.1, contact=tdem.LinearContact(kn=1e6))
        sim.fix_particles([0], vx=0.0, vy=0.0)
        log = open({str(log)!r}, "w")
        def y(s):
            time.sleep(0.01)      # about 100 records a second at most
            log.write(f"{{s.steps}}\\n")
            log.flush()
            return s.time
        sim.monitor("y", y, every=10)
        o = sim.output({str(out)!r}, every=10 ** 6, contacts=False, walls=False)
        {setting}
        sim.run(steps=10 ** 7)
        """)
    p = subprocess.Popen([sys.executable, "-c", code], cwd=ROOT, stdout=subprocess.DEVNULL,
                         stderr=subprocess.DEVNULL)
    h5 = out / "monitors.h5"
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline:
            steps = _steps_in(h5) if h5.exists() else None
            if steps is not None and len(steps) >= 150:
                break
            assert p.poll() is None, "the child stopped"
            time.sleep(0.2)
        else:
            pytest.fail("monitors.h5 did not receive 150 records in 120 s of running")
    finally:
        p.send_signal(signal.SIGKILL)
        p.wait()
    recorded = [int(s) for s in log.read_text().split()]
    steps = _steps_in(h5)
    times, values = read_monitors(h5)["y"]
    # a contiguous run of records from the first, up to (close to) the kill
    np.testing.assert_array_equal(steps, 10 * np.arange(1, len(steps) + 1))
    np.testing.assert_allclose(values, steps * 1e-4, rtol=1e-12)
    lost = len(recorded) - len(steps)
    # flush_interval 0: every record is written as it comes (the last one may be in
    # flight); by default, at most about one second behind (about 100 records here)
    assert 0 <= lost <= (1 if flush_interval == 0.0 else 150), (len(recorded), len(steps))


@pytest.mark.filterwarnings("ignore:save. the prescribed vx")
def test_instability_keeps_the_records_of_the_last_segment(tmp_path):
    sim = tdem.Simulation(gravity=(0.0, 0.0), dt=1e-4, check_interval=100, progress=False)
    sim.add_particles([[0.0, 0.0], [0.5, 0.0]], 0.1, contact=tdem.LinearContact(kn=1e6))
    # NaN from step 251 on: steps 201..250 of the failing segment are good
    sim.fix_particles([0], vx=lambda t: math.nan if t >= 0.025 - 1e-12 else 0.0)
    sim.monitor("t", lambda s: s.time, every=10)
    sim.output(tmp_path, every=50, contacts=False, walls=False)
    with pytest.raises(tdem.InstabilityError) as e:
        sim.run(steps=1000)
    assert e.value.step == 251 and sim.steps == 250
    t, v = sim.histories()["t"]
    np.testing.assert_allclose(t, 1e-4 * np.arange(10, 251, 10), rtol=1e-12)
    ft, fv = read_monitors(tmp_path / "monitors.h5")["t"]
    np.testing.assert_allclose(ft, 1e-4 * np.arange(10, 251, 10), rtol=1e-12)
    # the snapshots of the failing segment (steps 250) are written again as well
    assert [s for s, _ in sim._output.snapshots] == [0, 50, 100, 150, 200, 250]


def test_a_monitor_that_raises_still_leaves_the_records_before(tmp_path):
    sim = tdem.Simulation(gravity=(0.0, 0.0), dt=1e-4, progress=False)
    sim.add_particles([[0.0, 0.0]], 0.1, contact=tdem.LinearContact(kn=1e6))

    def fn(s):
        if s.steps > 300:
            raise RuntimeError("monitor broke")
        return s.steps

    sim.monitor("n", fn, every=100)
    o = sim.output(tmp_path, every=10 ** 6, contacts=False, walls=False)
    o.flush_interval = 3600.0       # no periodic writes: only the stop writes the file
    with pytest.raises(RuntimeError, match="monitor broke"):
        sim.run(steps=1000)
    t, v = read_monitors(tmp_path / "monitors.h5")["n"]
    np.testing.assert_array_equal(v, [100, 200, 300])
