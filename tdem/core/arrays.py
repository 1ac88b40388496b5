"""Device arrays that are freed when dropped.

Taichi 1.7 frees a scalar ndarray when it is garbage-collected but never a vector or
matrix one (taichi-dev/taichi#8763). :func:`ndarray` makes either kind, and gives a
vector array the release that scalar ones have: the engine's state (``tdem.state``),
the continuum's arrays and the standalone PCMM element system all allocate through it.
"""
import weakref

import taichi as ti
from taichi.lang import impl

__all__ = ["ndarray"]


def _delete(prog, handle):
    # only the Taichi program that made the array may free it (a reset made a new one)
    rt = impl.get_runtime()
    if rt is not None and rt.prog is prog:
        prog.delete_ndarray(handle)


def ndarray(vec, dtype, shape):
    """A device array: of ``vec``-vectors (``vec`` > 0) or scalars (``vec`` 0 or None).

    Taichi 1.7 frees a scalar ndarray when it is garbage-collected but never a vector
    or matrix one (taichi-dev/taichi#8763): every model built and dropped, and every
    growth of its slots, would keep its memory until the process ends. A vector array
    made here gets the release that scalar ones have."""
    if not vec:
        return ti.ndarray(dtype, tuple(shape))
    arr = ti.Vector.ndarray(vec, dtype, tuple(shape))
    weakref.finalize(arr, _delete, impl.get_runtime().prog, arr.arr)
    return arr
