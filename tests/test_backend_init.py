"""Taichi is initialised once per process: arch="gpu" without a GPU falls back to the
CPU with a warning, and a later simulation asking for another thread count or
architecture is refused instead of re-initialising Taichi (which would free the
arrays of every simulation made before). Each test runs in a child process, which
initialises Taichi itself."""
import os
import subprocess
import sys
import textwrap

import pytest

import tdem

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def _child(code, **env):
    e = dict(os.environ)
    e.pop("TDEM_ARCH", None)
    e.pop("TDEM_THREADS", None)
    e.pop("TDEM_CFG_OPTIMIZATION", None)
    e.pop("TDEM_OPT_LEVEL", None)
    e.update(env)
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code)], cwd=ROOT, env=e,
                          capture_output=True, text=True, timeout=120)


def test_gpu_without_a_gpu_runs_on_the_cpu_with_a_warning():
    r = _child("""
        import warnings
        import tdem
        with warnings.catch_warnings(record=True) as w:
            warnings.simplefilter("always")
            sim = tdem.Simulation(arch="gpu", gravity=(0.0, 0.0), progress=False)
        sim.add_particles([[0.0, 0.0], [0.25, 0.0]], 0.1, contact=tdem.LinearContact(kn=1e6))
        sim.run(steps=5)
        print("ARCH", sim.arch)
        for x in w:
            print("WARNING", x.category.__name__, x.message)
        """)
    assert r.returncode == 0, r.stderr[-2000:]
    if "ARCH cpu" in r.stdout:
        assert ("WARNING RuntimeWarning arch='gpu' asked, but no CUDA GPU is available: "
                "tdem runs on the CPU") in r.stdout
    else:  # a machine with a CUDA GPU
        assert "ARCH gpu" in r.stdout and "WARNING" not in r.stdout


def test_other_threads_or_arch_refused_once_taichi_runs():
    r = _child("""
        import numpy as np
        import tdem
        sim = tdem.Simulation(threads=2, gravity=(0.0, -9.81), progress=False)
        sim.add_particles([[0.0, 0.0], [0.25, 0.0]], 0.1, contact=tdem.LinearContact(kn=1e6))
        sim.run(steps=10)
        for kwargs in ({"threads": 1}, {"threads": 3}, {"arch": "gpu"}):
            try:
                tdem.Simulation(**kwargs)
                print("ACCEPTED", kwargs)
            except tdem.InputError as e:
                print("REFUSED", e)
        # the same settings, or none, are fine; the first simulation still runs
        tdem.Simulation(threads=2, arch="cpu")
        tdem.Simulation()
        sim.run(steps=10)
        y = sim.particles.numpy()["position"][:, 1]
        print("Y", np.allclose(y, -0.5 * 9.81 * sim.time ** 2, rtol=0.2))
        """)
    assert r.returncode == 0, r.stderr[-2000:]
    out = r.stdout
    assert "ACCEPTED" not in out
    assert ("REFUSED threads=1 asked, but Taichi already runs this process with threads=2; "
            "the thread count is process-wide: set it before the first Simulation") in out
    assert "REFUSED threads=3 asked, but Taichi already runs this process with threads=2" in out
    assert ("REFUSED arch='gpu' asked, but Taichi already runs this process on the CPU "
            "(arch='cpu')") in out
    assert "Y True" in out


def test_bad_thread_counts_are_named():
    with pytest.raises(tdem.InputError, match=r"threads must be a whole number >= 1, got 0"):
        tdem.Simulation(threads=0)
    with pytest.raises(tdem.InputError, match=r"threads must be a whole number >= 1, got 'two'"):
        tdem.Simulation(threads="two")


# control-flow optimisation off by default (it makes the first build of the step of
# shaped particles take minutes instead of seconds, tdem.backend.cfg_optimization);
# Taichi's own optimisation level (1) unless $TDEM_OPT_LEVEL asks for 0 (faster builds)
@pytest.mark.parametrize("name, attr, env, expected", [
    ("TDEM_CFG_OPTIMIZATION", "cfg_optimization", None, "False"),
    ("TDEM_CFG_OPTIMIZATION", "cfg_optimization", "0", "False"),
    ("TDEM_CFG_OPTIMIZATION", "cfg_optimization", "1", "True"),
    ("TDEM_OPT_LEVEL", "opt_level", None, "1"),
    ("TDEM_OPT_LEVEL", "opt_level", "0", "0"),
    ("TDEM_OPT_LEVEL", "opt_level", "1", "1")])
def test_taichi_settings_from_the_environment(name, attr, env, expected):
    r = _child(f"""
        import taichi as ti
        import tdem
        tdem.Simulation()
        print("SETTING", ti.lang.impl.current_cfg().{attr})
        """, **({} if env is None else {name: env}))
    assert r.returncode == 0, r.stderr[-2000:]
    assert f"SETTING {expected}" in r.stdout


@pytest.mark.parametrize("name, value, message", [
    ("TDEM_THREADS", "many", "TDEM_THREADS must be a whole number >= 1, got 'many'"),
    ("TDEM_CFG_OPTIMIZATION", "yes", "TDEM_CFG_OPTIMIZATION must be 0 or 1, got 'yes'"),
    ("TDEM_ADVANCED_OPTIMIZATION", "on",
     "TDEM_ADVANCED_OPTIMIZATION must be 0 or 1, got 'on'"),
    ("TDEM_OPT_LEVEL", "2", "TDEM_OPT_LEVEL must be 0 or 1, got '2'")])
def test_bad_environment_settings_are_named(name, value, message):
    r = _child("""
        import tdem
        try:
            tdem.Simulation()
        except tdem.InputError as e:
            print("REFUSED", e)
        """, **{name: value})
    assert r.returncode == 0, r.stderr[-2000:]
    assert "REFUSED " + message in r.stdout
