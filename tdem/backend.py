"""Taichi initialisation, done once per process.

The engine keeps its state in ``ti.ndarray`` objects and its kernels take them as
arguments, so a kernel is compiled once per process (per dtype) and reused by every
:class:`tdem.Simulation`, whatever its size. The architecture and the number of CPU
threads are process-wide Taichi settings: the first simulation decides them
(``arch`` argument, else ``$TDEM_ARCH``; ``$TDEM_THREADS`` for CPU threads).
"""
import os

import taichi as ti

from . import launch
from .errors import InputError

_state = {"arch": None, "threads": None, "nthreads": None}


def _arch_from(name):
    if name in ("cpu", "x64", "arm64"):
        return ti.cpu
    if name in ("gpu", "cuda"):
        return ti.cuda if name == "cuda" else ti.gpu
    raise InputError(f"arch must be 'cpu' or 'gpu', got {name!r}")


def init(arch=None, threads=None):
    """Initialise Taichi if needed; return the arch name in use ('cpu' or 'gpu')."""
    name = arch if arch is not None else os.environ.get("TDEM_ARCH", "cpu")
    name = {"x64": "cpu", "cuda": "gpu"}.get(name, name)
    _arch_from(name)  # validates
    if threads is None and os.environ.get("TDEM_THREADS"):
        threads = int(os.environ["TDEM_THREADS"])
    if _state["arch"] is not None:
        if name == _state["arch"] and (threads is None or threads == _state["threads"]):
            return name
    kwargs = dict(arch=_arch_from(name), default_fp=ti.f64, default_ip=ti.i32,
                  offline_cache=True, log_level=ti.WARN,
                  kernel_profiler=bool(os.environ.get("TDEM_PROFILE")))
    if threads is not None:
        if threads < 1:
            raise InputError(f"threads must be >= 1, got {threads!r}")
        kwargs["cpu_max_num_threads"] = int(threads)
    if _state["arch"] is not None:
        ti.reset()
    ti.init(**kwargs)
    launch.reset()
    actual = "gpu" if ti.lang.impl.current_cfg().arch in (ti.cuda, ti.vulkan, ti.metal, ti.opengl) else "cpu"
    _state["arch"] = actual
    _state["threads"] = threads
    _state["nthreads"] = int(ti.lang.impl.current_cfg().cpu_max_num_threads)
    return actual


# Below these sizes the kernels run their loops on one thread even when Taichi has
# several: waking the pool costs about 65 us per parallel loop (a 2-core machine, a
# dozen loops per step), more than a small model's loops take. Measured crossovers
# on 2 threads (benchmarks/pack2d.py --rows, benchmarks/pcmm.py --side): a DEM pack
# runs faster on one thread up to about 12,000 discs, a PCMM body up to about 2,000
# particles (at 900, one thread is 1.2 times faster; at 8,100, two are 1.17 times).
SERIAL_BELOW_DEM = 12000
SERIAL_BELOW_ELEMENTS = 2000


def serial_below(elements=False):
    """The model size below which :func:`serial_loops` says yes, for the threads in
    use. With T threads a loop of n items takes n·c/T + D instead of n·c (D: waking
    the pool), so one thread is faster below n = D/(c·(1 − 1/T)): the sizes measured
    on 2 threads times 0.5/(1 − 1/T) (0.53 on 16 threads). ``$TDEM_SERIAL_BELOW``
    sets the size for every thread count and model (0: never)."""
    env = os.environ.get("TDEM_SERIAL_BELOW")
    if env:
        try:
            below = int(env)
        except ValueError:
            below = -1
        if below < 0:
            raise InputError(f"TDEM_SERIAL_BELOW must be a whole number >= 0, got {env!r}")
        return below
    base = SERIAL_BELOW_ELEMENTS if elements else SERIAL_BELOW_DEM
    t = max(int(_state["nthreads"] or 2), 2)
    return int(round(base * 0.5 / (1.0 - 1.0 / t)))


def serial_loops(n=None, elements=False):
    """Whether kernels should run their loops on one thread: always with one CPU
    thread, never on a GPU; on several CPU threads, for a model smaller than
    :func:`serial_below` (n: its particles and block nodes; ``elements``: it has PCMM
    elements or blocks). The one-thread path sums contact forces in another order
    than the parallel one: the two agree to round-off, and each gives the same
    result run after run."""
    if _state["arch"] != "cpu":
        return False
    if _state["threads"] == 1 or _state["nthreads"] == 1:
        return True
    if n is None:
        return False
    return int(n) < serial_below(elements)
