import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
if ROOT not in sys.path:
    sys.path.insert(0, ROOT)

# Small models run their loops on one thread by default (tdem.backend.serial_loops);
# the suite's models are small, so keep them on the parallel path that large models
# take. Tests of the size rule itself change this variable where they need to.
os.environ.setdefault("TDEM_SERIAL_BELOW", "0")

# The suite builds many small models, each compiling its own kernels: Taichi's
# optimisation level 0 builds them about 40 % faster and runs them a little slower
# (tdem.backend.opt_level); a run that sets TDEM_OPT_LEVEL itself keeps its choice.
os.environ.setdefault("TDEM_OPT_LEVEL", "0")

# pytest-xdist runs the suite in worker processes (the README's command: two on two
# cores). A Taichi process takes every core by default, so each parallel loop would
# wait on threads the other workers hold: give each worker its share of the cores
# (one thread each for two workers on two cores: 4 test files 180 s -> 84 s).
_workers = int(os.environ.get("PYTEST_XDIST_WORKER_COUNT", "0") or 0)
if _workers > 0:
    os.environ.setdefault("TDEM_THREADS", str(max(1, (os.cpu_count() or 1) // _workers)))


# The longest files first (seconds each with the cache empty, 2026-12-07), so that
# the two workers do not end with one of them alone on a long file: pytest-xdist's
# --dist loadfile hands out the files in the order collected.
LONG_FILES = ("test_kernel_types.py", "test_voronoi_water.py", "test_biaxial.py",
              "test_pcmm_cases.py", "test_readme_examples.py", "test_contact_burst.py",
              "test_work_account.py", "test_cases_cli.py", "test_bearing_capacity.py",
              "test_dam_break_case.py", "test_spheres_3d.py")


def pytest_collection_modifyitems(config, items):
    rank = {name: k for k, name in enumerate(LONG_FILES)}
    items.sort(key=lambda it: rank.get(os.path.basename(str(it.fspath)), len(rank)))


import pytest  # noqa: E402


@pytest.fixture
def summation_paths():
    """Run ``script`` (it saves an array to argv[1] and prints ``chunk N``) once on one
    thread, twice on two threads with 8 chunks asked, and once with every pair through
    its slot (TDEM_CHUNKS=0: the GPU's path, on the CPU), each in its own process;
    returns ({name: the saved array}, {name: the chunk size printed}) for the names
    "one", "chunks", "chunks again" and "slots"."""
    import subprocess

    import numpy as np

    def run(script, tmp_path):
        out, chunk = {}, {}
        for name, threads, chunks in (("one", "1", ""), ("chunks", "2", "8"),
                                      ("chunks again", "2", "8"), ("slots", "2", "0")):
            path = tmp_path / f"{name}.npy"
            done = subprocess.run([sys.executable, str(script), str(path)],
                                  env=dict(os.environ, TDEM_THREADS=threads,
                                           TDEM_SERIAL_BELOW="0", TDEM_CHUNKS=chunks),
                                  check=True, capture_output=True, text=True)
            out[name] = np.load(path)
            chunk[name] = int(done.stdout.split("chunk")[-1])
        return out, chunk
    return run
