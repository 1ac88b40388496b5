"""tdem.ensemble: one function over many parameter sets on Dask, gathered as a table.

The member is a disc dropped under gravity for a few steps: its height after N
leapfrog steps is y0 + N v0 dt − g dt² N(N+1)/2. On a local cluster and on a
scheduler and two workers started here as processes (TCP on 127.0.0.1), the
ensemble gives the serial results bit for bit; a member that raises is a row of the
table with its parameters and traceback while the others complete; a rerun with the
same folder runs only the members not done."""
import json
import os
import subprocess
import sys
import time
import uuid
from pathlib import Path

import numpy as np
import pytest

import tdem
from tdem.ensemble import member_key, members_of, worker_environment

distributed = pytest.importorskip("distributed",
                                  reason='Dask is an extra: pip install "tdem[sweep]"')

G = 9.81
ROOT = Path(__file__).resolve().parents[1]
MEMBERS = [{"height": 1.0, "steps": 20, "dt": 1e-3, "vy": 0.0},
           {"height": 2.0, "steps": 37, "dt": 2e-3, "vy": 0.5},
           {"height": 0.5, "steps": 11, "dt": 5e-4, "vy": -1.0},
           {"height": 3.0, "steps": 50, "dt": 1e-3, "vy": 2.0},
           {"height": 1.5, "steps": 25, "dt": 3e-3, "vy": 0.0}]


def drop(height, steps, dt, vy=0.0, calls=None):
    """A disc dropped from ``height`` at ``vy`` for ``steps`` steps of ``dt``; its
    height and velocity. With ``calls``, a file there counts the call."""
    if calls is not None:
        (Path(calls) / f"{height:g}_{steps}_{uuid.uuid4().hex}").write_text("")
    sim = tdem.Simulation(gravity=(0.0, -G), dt=dt, progress=False)
    sim.add_particles([[0.0, height]], radius=0.01, density=2500.0,
                      contact=tdem.LinearContact(kn=1e5), velocity=(0.0, vy))
    sim.run(steps=steps)
    p = sim.particles.numpy()
    return {"y": float(p["position"][0, 1]), "vy_end": float(p["velocity"][0, 1]),
            "pid": os.getpid()}


def closed_form(height, steps, dt, vy=0.0, **_):
    return height + steps * vy * dt - G * dt * dt * steps * (steps + 1) / 2.0


@pytest.fixture(scope="module")
def serial():
    """The members run one after the other in this process."""
    return [drop(**p) for p in MEMBERS]


def _assert_serial(rows, serial):
    assert [r["status"] for r in rows] == ["ok"] * len(MEMBERS)
    for p, r, s in zip(MEMBERS, rows, serial):
        assert {k: r[k] for k in p} == p                      # in the order of params
        assert r["y"] == s["y"] and r["vy_end"] == s["vy_end"]  # bit for bit
        assert r["y"] == pytest.approx(closed_form(**p), rel=1e-12, abs=1e-15)
        assert r["wall_s"] > 0.0 and r["error"] == ""


@pytest.fixture(scope="module")
def scheduler(tmp_path_factory):
    """A scheduler and two one-thread workers, each its own process (``dask
    scheduler`` / ``dask worker``) on 127.0.0.1; its address."""
    folder = tmp_path_factory.mktemp("dask")
    file = folder / "scheduler.json"
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        [str(ROOT), str(ROOT / "tests")] + [p for p in [os.environ.get("PYTHONPATH")] if p]))
    env.pop("TDEM_THREADS", None)          # the workers choose theirs
    log = open(folder / "log.txt", "w")
    procs = [subprocess.Popen([sys.executable, "-m", "dask", "scheduler", "--host",
                               "127.0.0.1", "--port", "0", "--no-dashboard",
                               "--scheduler-file", str(file)], env=env, stdout=log,
                              stderr=subprocess.STDOUT)]
    try:
        t0 = time.monotonic()
        while not file.exists() and time.monotonic() - t0 < 60:
            assert procs[0].poll() is None, (folder / "log.txt").read_text()
            time.sleep(0.2)
        address = json.loads(file.read_text())["address"]
        assert address.startswith("tcp://127.0.0.1:")
        for _ in range(2):
            procs.append(subprocess.Popen(
                [sys.executable, "-m", "dask", "worker", address, "--nthreads", "1",
                 "--no-nanny", "--no-dashboard", "--local-directory", str(folder)],
                env=env, stdout=log, stderr=subprocess.STDOUT))
        with distributed.Client(address, timeout="60s") as c:
            c.wait_for_workers(2, timeout=120)
        yield address
    finally:
        try:
            with distributed.Client(address, timeout="10s") as c:
                c.shutdown()                      # the scheduler and its workers
        except Exception:
            pass
        for p in procs:
            try:
                p.wait(timeout=30)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()
        log.close()


def test_local_cluster_gives_the_serial_results_bit_for_bit(serial, tmp_path):
    t0 = time.perf_counter()
    res = tdem.ensemble(drop, MEMBERS, workers=2, out=tmp_path, progress=False)
    wall = time.perf_counter() - t0
    _assert_serial(res.rows, serial)
    assert len({r["pid"] for r in res.rows} - {os.getpid()}) >= 1   # run elsewhere
    print(f"local cluster, 2 workers: {len(res)} members in {wall:.1f} s, y = "
          + ", ".join(f"{r['y']:.15g}" for r in res.rows))
    # the table, on disk
    import h5py
    with h5py.File(tmp_path / "results.h5", "r") as f:
        assert json.loads(f.attrs["columns"]) == ["height", "steps", "dt", "vy", "y",
                                                  "vy_end", "pid", "wall_s", "status",
                                                  "error"]
        np.testing.assert_array_equal(f["y"][:], [s["y"] for s in serial])
        assert [s.decode() for s in f["status"][:]] == ["ok"] * len(MEMBERS)
    lines = (tmp_path / "results.csv").read_text().splitlines()
    assert lines[0] == "height,steps,dt,vy,y,vy_end,pid,wall_s,status,error"
    assert [float(line.split(",")[4]) for line in lines[1:]] == [s["y"] for s in serial]
    assert len(list((tmp_path / "members").glob("*.json"))) == len(MEMBERS)


def test_scheduler_and_workers_over_tcp_give_the_serial_results(serial, scheduler):
    t0 = time.perf_counter()
    res = tdem.ensemble(drop, MEMBERS, client=scheduler, progress=False)
    print(f"dask scheduler + 2 dask workers: {len(res)} members in "
          f"{time.perf_counter() - t0:.1f} s")
    _assert_serial(res.rows, serial)
    assert len({r["pid"] for r in res.rows}) == 2 and os.getpid() not in {
        r["pid"] for r in res.rows}
    # each worker set its threads before its first simulation
    with distributed.Client(scheduler) as c:
        env = c.run(lambda: os.environ.get("TDEM_THREADS"))
    assert sorted(env.values()) == [str(max(1, (os.cpu_count() or 1) // 2))] * 2


def test_a_member_that_raises_is_reported_and_the_others_complete(serial, scheduler,
                                                                  tmp_path):
    bad = {"height": 1.0, "steps": 20, "dt": -1e-3, "vy": 0.0}     # dt < 0: InputError
    params = MEMBERS[:2] + [bad] + MEMBERS[2:]
    with pytest.warns(RuntimeWarning, match=r"1 of 6 members raised; the first, .*'dt': "
                                            r"-0\.001.*InputError: dt"):
        res = tdem.ensemble(drop, params, client=scheduler, out=tmp_path, progress=False)
    assert [r["status"] for r in res.rows] == ["ok", "ok", "error", "ok", "ok", "ok"]
    err = res.rows[2]
    assert {k: err[k] for k in bad} == bad and "y" not in err
    assert "Traceback" in err["error"] and "InputError: dt" in err["error"]
    assert res.errors == [err]
    _assert_serial(res.rows[:2] + res.rows[3:], serial)
    lines = (tmp_path / "results.csv").read_text().splitlines()
    import csv
    table = list(csv.DictReader(lines))
    assert len(table) == 6 and table[2]["status"] == "error" and table[2]["y"] == ""
    assert float(table[2]["dt"]) == -1e-3 and "InputError: dt" in table[2]["error"]


def test_a_rerun_runs_only_the_members_not_done(serial, scheduler, tmp_path):
    calls = tmp_path / "calls"
    calls.mkdir()
    out = tmp_path / "ens"
    first = [dict(p, calls=str(calls)) for p in MEMBERS[:3]]
    with distributed.Client(scheduler) as client:
        a = tdem.ensemble(drop, first, client=client, out=out, progress=False)
        assert len(list(calls.iterdir())) == 3
        # an interrupted run: one member's file lost
        (out / "members" / f"{member_key(first[1])}.json").unlink()
        everything = [dict(p, calls=str(calls)) for p in MEMBERS]
        seen = []
        b = tdem.ensemble(drop, everything, client=client, out=out, progress=False,
                          on_result=seen.append)
    assert len(list(calls.iterdir())) == 3 + 3            # member 1 again, 3 and 4 new
    assert sorted(r["height"] for r in seen) == [1.5, 2.0, 3.0]
    assert b.rows[0] == a.rows[0] and b.rows[2] == a.rows[2]   # read back, wall time too
    assert [r["y"] for r in b.rows] == [s["y"] for s in serial]
    assert len(list((out / "members").glob("*.json"))) == 5
    assert len((out / "results.csv").read_text().splitlines()) == 1 + 5


def test_params_grid_keys_and_worker_environment():
    g = tdem.ensemble.grid(a=[1, 2, 3], b=[0.5, 0.25], c="x")
    assert len(g) == 6 and g[1] == {"a": 1, "b": 0.25, "c": "x"}
    assert members_of({"a": [1, 2, 3], "b": [0.5, 0.25], "c": "x"}) == g
    assert member_key({"a": 1, "b": 0.5}) == member_key({"b": 0.5, "a": 1})
    assert member_key({"a": 1, "b": 0.5}) != member_key({"a": 1, "b": 0.5000000000000001})
    assert member_key({"a": np.float64(0.1)}) == member_key({"a": 0.1})
    # a worker's threads and GPU: the cores over its machine's workers, GPU by index
    assert worker_environment(3, 4, cores=16, gpus=2, environ={}) == {
        "TDEM_THREADS": "4", "CUDA_VISIBLE_DEVICES": "1"}
    assert worker_environment(0, 4, cores=2, gpus=0, environ={}) == {"TDEM_THREADS": "1"}
    assert worker_environment(1, 2, cores=8, gpus=2,
                              environ={"TDEM_THREADS": "3",
                                       "CUDA_VISIBLE_DEVICES": "0"}) == {}


def test_bad_arguments_are_refused_naming_them(tmp_path):
    with pytest.raises(tdem.InputError, match="fn must be callable.*42"):
        tdem.ensemble(42, MEMBERS)
    with pytest.raises(tdem.InputError, match="params must be a list of dicts.*'abc'"):
        tdem.ensemble(drop, "abc")
    with pytest.raises(tdem.InputError, match=r"params\[1\] must be a dict.*5"):
        tdem.ensemble(drop, [MEMBERS[0], 5])
    with pytest.raises(tdem.InputError, match="params has no members"):
        tdem.ensemble(drop, [])
    with pytest.raises(tdem.InputError, match="grid: steps has no values"):
        tdem.ensemble(drop, {"height": [1.0], "steps": []})
    with pytest.raises(tdem.InputError, match=r"params\[0\]: 'status' is a column"):
        tdem.ensemble(drop, [{"status": 1}])
    blocker = tmp_path / "a_file"
    blocker.write_text("")
    with pytest.raises(tdem.InputError, match="out: cannot write to .*a_file"):
        tdem.ensemble(drop, MEMBERS, out=blocker / "sub")
    with pytest.raises(tdem.InputError, match="client must be a dask.distributed Client.*3"):
        tdem.ensemble(drop, MEMBERS, client=3)
    with pytest.raises(tdem.InputError, match="workers: only with client=None"):
        tdem.ensemble(drop, MEMBERS, client="tcp://127.0.0.1:1", workers=2)
