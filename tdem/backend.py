"""Taichi initialisation, done once per process.

The engine keeps its state in ``ti.ndarray`` objects and its kernels take them as
arguments, so a kernel is compiled once per process (per dtype) and reused by every
:class:`tdem.Simulation`, whatever its size. The architecture and the number of CPU
threads are process-wide Taichi settings: the first simulation decides them
(``arch`` argument, else ``$TDEM_ARCH``; ``$TDEM_THREADS`` for CPU threads).
"""
import os

import taichi as ti

from .errors import InputError

_state = {"arch": None, "threads": None}


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
    actual = "gpu" if ti.lang.impl.current_cfg().arch in (ti.cuda, ti.vulkan, ti.metal, ti.opengl) else "cpu"
    _state["arch"] = actual
    _state["threads"] = threads
    return actual


def serial_loops():
    """True when parallel-for dispatch costs more than it gains (one CPU thread)."""
    return _state["arch"] == "cpu" and _state["threads"] == 1
