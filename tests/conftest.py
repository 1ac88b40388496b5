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
