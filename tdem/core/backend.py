"""Taichi initialisation, done once per process.

The engine keeps its state in ``ti.ndarray`` objects and its kernels take them as
arguments, so a kernel is compiled once per process (per dtype) and reused by every
:class:`tdem.Simulation`, whatever its size. The architecture and the number of CPU
threads are process-wide Taichi settings: the first simulation decides them
(``arch`` argument, else ``$TDEM_ARCH``; ``$TDEM_THREADS`` for CPU threads), and a
later simulation asking for others is refused (Taichi is never re-initialised: that
would free the arrays of the simulations made before).
"""
import os
import warnings

import numpy as np
import taichi as ti

from . import launch
from .errors import InputError

_state = {"arch": None, "asked": None, "threads": None, "nthreads": None}


def _arch_from(name):
    if name in ("cpu", "x64", "arm64"):
        return ti.cpu
    if name in ("gpu", "cuda"):
        # CUDA only: probing ti.gpu's other backends (OpenGL, GLES) can crash the
        # process on a machine without them; Taichi falls back from CUDA to the CPU
        return ti.cuda
    raise InputError(f"arch must be 'cpu' or 'gpu', got {name!r}")


def _threads_from(threads, source="threads"):
    if isinstance(threads, str) and source != "threads":    # an environment variable
        try:
            threads = int(threads)
        except ValueError:
            raise InputError(f"{source} must be a whole number >= 1, got {threads!r}") from None
    if isinstance(threads, bool) or not isinstance(threads, (int, np.integer)) or threads < 1:
        raise InputError(f"{source} must be a whole number >= 1, got {threads!r}")
    return int(threads)


def init(arch=None, threads=None):
    """Initialise Taichi if needed; return the arch name in use ('cpu' or 'gpu').

    Taichi is initialised once per process: re-initialising it would invalidate the
    arrays of every simulation made before. Once it runs, ``None`` means the
    setting in use, and a different ``arch`` or ``threads`` is refused
    (:class:`tdem.InputError`). ``arch="gpu"`` without a CUDA GPU runs on the CPU
    with a warning."""
    if arch is not None and not isinstance(arch, str):
        raise InputError(f"arch must be 'cpu' or 'gpu', got {arch!r}")
    if threads is not None:
        threads = _threads_from(threads)
    if _state["arch"] is not None:
        return _same_settings(arch, threads)
    name = arch if arch is not None else os.environ.get("TDEM_ARCH", "cpu")
    source = "arch" if arch is not None else "TDEM_ARCH"
    name = {"x64": "cpu", "cuda": "gpu"}.get(name, name)
    if name not in ("cpu", "gpu", "arm64"):
        raise InputError(f"{source} must be 'cpu' or 'gpu', got {name!r}")
    name = "cpu" if name == "arm64" else name
    if threads is None and os.environ.get("TDEM_THREADS"):
        threads = _threads_from(os.environ["TDEM_THREADS"], "TDEM_THREADS")
    kwargs = dict(arch=_arch_from(name), default_fp=ti.f64, default_ip=ti.i32,
                  offline_cache=True, log_level=ti.WARN,
                  kernel_profiler=bool(os.environ.get("TDEM_PROFILE")))
    if threads is not None:
        kwargs["cpu_max_num_threads"] = threads
    kwargs["advanced_optimization"] = advanced_optimization(name)
    kwargs["cfg_optimization"] = cfg_optimization()
    level = opt_level()
    if level is not None:
        kwargs["opt_level"] = level
    ti.init(**kwargs)
    launch.reset()
    actual = "gpu" if ti.lang.impl.current_cfg().arch in (ti.cuda, ti.vulkan, ti.metal, ti.opengl) else "cpu"
    _state["arch"] = actual
    _state["asked"] = name
    _state["threads"] = threads
    _state["nthreads"] = int(ti.lang.impl.current_cfg().cpu_max_num_threads)
    _warn_fallback(name, actual, 4)
    return actual


def advanced_optimization(name):
    """Whether Taichi's advanced optimisation passes run: on the CPU yes; on CUDA no,
    since with them Taichi 1.7 builds kernels of shaped particles, PCMM bodies and
    blocks that stop with CUDA_ERROR_MISALIGNED_ADDRESS, and the DEM pack runs no
    slower without them (measurements: benchmarks/RESULTS.md, section 7. CUDA).
    ``$TDEM_ADVANCED_OPTIMIZATION`` (1 or 0) overrides."""
    env = os.environ.get("TDEM_ADVANCED_OPTIMIZATION", "")
    if env not in ("", "0", "1"):
        raise InputError(f"TDEM_ADVANCED_OPTIMIZATION must be 0 or 1, got {env!r}")
    if env:
        return env == "1"
    return name != "gpu"


def cfg_optimization():
    """Whether Taichi's control-flow-graph pass (store forwarding and dead stores over
    a kernel's whole body) runs: off unless ``$TDEM_CFG_OPTIMIZATION=1``. Its cost
    grows faster than the size of a kernel, and the step kernels of shaped particles
    are large, while LLVM's own passes do most of its work afterwards. Measurements
    (build times, run-time rates with and without it): benchmarks/RESULTS.md, section
    Kernel builds: Taichi's control-flow-graph pass."""
    env = os.environ.get("TDEM_CFG_OPTIMIZATION", "")
    if env not in ("", "0", "1"):
        raise InputError(f"TDEM_CFG_OPTIMIZATION must be 0 or 1, got {env!r}")
    return env == "1"


def opt_level():
    """Taichi's optimisation level of its own passes over a kernel (its default, 1),
    or ``$TDEM_OPT_LEVEL`` (0 or 1). Level 0 builds kernels faster and runs them
    somewhat slower: worth it where models are small and many, as in the test suite
    (measurements: benchmarks/RESULTS.md, section Taichi's optimisation level 0)."""
    env = os.environ.get("TDEM_OPT_LEVEL", "")
    if env not in ("", "0", "1"):
        raise InputError(f"TDEM_OPT_LEVEL must be 0 or 1, got {env!r}")
    return int(env) if env else None


def _warn_fallback(asked, actual, stacklevel):
    if asked == "gpu" and actual == "cpu":
        warnings.warn("arch='gpu' asked, but no CUDA GPU is available: tdem runs on the CPU",
                      RuntimeWarning, stacklevel=stacklevel)


def _same_settings(arch, threads):
    """The arch in use, when ``arch`` and ``threads`` agree with the settings Taichi
    runs with (None agrees with anything); else InputError."""
    actual = _state["arch"]
    if arch is not None:
        name = {"x64": "cpu", "arm64": "cpu", "cuda": "gpu"}.get(arch, arch)
        if name not in ("cpu", "gpu"):
            raise InputError(f"arch must be 'cpu' or 'gpu', got {arch!r}")
        if name != actual and name != _state["asked"]:
            where = "on the CPU" if actual == "cpu" else "on the GPU"
            raise InputError(f"arch={arch!r} asked, but Taichi already runs this process "
                             f"{where} (arch={actual!r}); the architecture is process-wide: "
                             "set it before the first Simulation")
        _warn_fallback(name, actual, 5)
    if threads is not None and actual == "cpu" and threads != _state["nthreads"]:
        raise InputError(f"threads={threads} asked, but Taichi already runs this process with "
                         f"threads={_state['nthreads']}; the thread count is process-wide: set "
                         "it before the first Simulation")
    return actual


# Below these sizes the kernels run their loops on one thread even when Taichi has
# several: waking the pool costs about 65 us per parallel loop (a 2-core machine, a
# dozen loops per step), more than a small model's loops take. Measured crossovers
# on 2 threads (benchmarks/pack2d.py --rows, benchmarks/pcmm.py --side): a DEM pack
# runs faster on one thread up to about 12,000 discs, a PCMM body up to about 2,000
# particles (measurements: benchmarks/RESULTS.md, section 5. Small models).
SERIAL_BELOW_DEM = 12000
SERIAL_BELOW_ELEMENTS = 2000


# On several CPU threads the step's pair loop runs in chunks, each chunk of particles
# one thread's serial loop (tdem.step.step): a pair within a chunk gives the partner
# its share at once, as on one thread, and only pairs across chunks go through their
# slot and the gather (with a slot for every pair, as on a GPU, the step costs 1.8
# times the one-thread step's work: benchmarks/RESULTS.md). CHUNKS_PER_THREAD chunks
# per thread share the work out; fewer, larger chunks leave fewer pairs across them.
CHUNKS_PER_THREAD = 4
# ... but no chunk smaller than this unless TDEM_CHUNKS asks: each chunk beyond the
# first wakes a thread (about 50 us a step on 2 threads), which a small model's
# step does not repay
MIN_CHUNK = 1024


def _env_count(name):
    """The whole number >= 0 in environment variable ``name``, None where it is unset
    or empty; anything else is refused, naming the variable."""
    env = os.environ.get(name)
    if not env:
        return None
    try:
        k = int(env)
    except ValueError:
        k = -1
    if k < 0:
        raise InputError(f"{name} must be a whole number >= 0, got {env!r}")
    return k


def _chunks_asked():
    return _env_count("TDEM_CHUNKS")


def chunks_wanted():
    """Chunks of the step's pair loop on several CPU threads: ``$TDEM_CHUNKS`` (0: a
    slot for every pair, the GPU's path), else CHUNKS_PER_THREAD × threads."""
    k = _chunks_asked()
    if k is not None:
        return k
    return CHUNKS_PER_THREAD * max(int(_state["nthreads"] or 1), 1)


def max_chunks():
    """Rows of the walls' partial sums: the most chunks :func:`chunk_size` gives."""
    return max(chunks_wanted(), 1)


def chunk_size(n, serial):
    """Particles per chunk of the step's pair loop for a model of n particles: 0 on
    one thread (``serial``) and on a GPU (every pair through its slot), else
    n / :func:`chunks_wanted`, rounded up, and at least MIN_CHUNK unless
    ``$TDEM_CHUNKS`` asks (one chunk: the one-thread order on one thread). The result
    depends on the chunks (the order in which pairs across them are summed), not on
    which thread runs which: a run repeats itself bit for bit with the same chunks,
    and runs with other chunks agree to round-off. ``$TDEM_CHUNKS=K`` fixes the
    count whatever the threads."""
    if serial or _state["arch"] != "cpu":
        return 0
    k = chunks_wanted()
    if k == 0:
        return 0
    if _chunks_asked() is None:
        k = min(k, max(int(n) // MIN_CHUNK, 1))
    return max(1, -(-int(n) // k))


def serial_below(elements=False):
    """The model size below which :func:`serial_loops` says yes, for the threads in
    use. With T threads a loop of n items takes n·c/T + D instead of n·c (D: waking
    the pool), so one thread is faster below n = D/(c·(1 − 1/T)): the sizes measured
    on 2 threads times 0.5/(1 − 1/T) (0.53 on 16 threads). ``$TDEM_SERIAL_BELOW``
    sets the size for every thread count and model (0: never)."""
    below = _env_count("TDEM_SERIAL_BELOW")
    if below is not None:
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
