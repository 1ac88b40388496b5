"""Kernel launches that skip Taichi's per-call checks of the arguments.

A Taichi kernel call from Python inspects every argument on every call (its kind,
dtype and shape, to find the compiled variant) before it launches. For a model of a
few hundred particles this is most of the step (measurements: benchmarks/RESULTS.md,
section 5. Small models).

:func:`cached` wraps a kernel so that a call whose arguments are the same ndarray
objects (and the same template values) as an earlier call reuses what that call
found: the compiled kernel and a launch context holding the arrays (by their host
addresses, the way Taichi passes numpy arrays; the CPU launcher reads them without
rewriting the context), so a call sets only its scalar arguments and launches
(measurements: benchmarks/RESULTS.md, section Launch contexts kept, host views). The
cache holds weak references to the arrays (it keeps no memory alive; an entry whose
arrays are gone is dropped when its key comes round again) and is cleared when Taichi
is re-initialised.

The fast path is taken on the CPU only (the GPU path is Taichi's own call) and for
kernels whose arguments are ndarrays, Python scalars and template values; anything
else (numpy arrays, keyword arguments, a kernel that returns a value) goes through
the plain call. ``TDEM_PLAIN_LAUNCH=1`` turns the fast path off everywhere (read
when the module is imported and when Taichi is initialised).
"""
import ctypes
import functools
import numbers
import operator
import os
import weakref

import numpy as np
import taichi as ti
from taichi.lang import impl
from taichi.lang._ndarray import Ndarray
from taichi.types import ndarray_type, primitive_types
from taichi.types.annotations import template

MAX_ENTRIES = 64           # argument sets remembered per kernel (the snapshot copy: one per array)
_generation = [0]          # bumped whenever Taichi is (re-)initialised


def _enabled():
    return os.environ.get("TDEM_PLAIN_LAUNCH", "") in ("", "0")


ENABLED = _enabled()       # read again by reset(); tests may set it


def reset():
    """Forget every cached launch (Taichi was re-initialised)."""
    global ENABLED
    _generation[0] += 1
    ENABLED = _enabled()


def _picker(indices):
    """A function returning the tuple of the arguments at ``indices``."""
    if not indices:
        return lambda args: ()
    if len(indices) == 1:
        i = indices[0]
        return lambda args: (args[i],)
    return operator.itemgetter(*indices)


class _Entry:
    __slots__ = ("t_kernel", "data", "refs", "scalars", "ctx")


class Cached:
    """A kernel whose repeated launches with the same ndarrays skip the argument
    checks (module docstring). Calls it cannot serve go to the kernel itself."""

    def __init__(self, kernel):
        functools.update_wrapper(self, kernel)
        self.kernel = kernel
        self._primal = kernel._primal
        self._entries = {}
        self._gen = None
        self._cpu = False
        kinds = []
        for arg in self._primal.arguments:
            ann = arg.annotation
            if isinstance(ann, template):
                kinds.append("t")
            elif isinstance(ann, ndarray_type.NdarrayType):
                kinds.append("a")
            elif id(ann) in primitive_types.real_type_ids:
                kinds.append("f")
            elif id(ann) in primitive_types.integer_type_ids:
                kinds.append("i")
            else:
                kinds.append("?")
        self._kinds = tuple(kinds)
        self._nargs = len(kinds)
        self._arrays = _picker([i for i, k in enumerate(kinds) if k == "a"])
        self._templates = _picker([i for i, k in enumerate(kinds) if k == "t"])
        self._plain = "?" in kinds or self._primal.return_type is not None

    def __call__(self, *args, **kwargs):
        if kwargs or self._plain or len(args) != self._nargs or not ENABLED:
            return self.kernel(*args, **kwargs)
        if self._gen != _generation[0]:
            self._entries.clear()
            self._gen = _generation[0]
            self._cpu = impl.current_cfg().arch in (ti.x64, ti.arm64)
        if not self._cpu:
            return self.kernel(*args)
        # the arrays by identity (an entry's weak references say whether they are
        # still the objects it was made for), the template values by type and value
        try:
            key = (tuple(map(id, self._arrays(args))),
                   tuple((type(v), v) for v in self._templates(args)))
            e = self._entries.get(key)
        except TypeError:                 # an unhashable template value
            return self.kernel(*args)
        if e is not None and not all(r() is not None for r in e.refs):
            del self._entries[key]        # an array of this entry is gone: its id may be reused
            e = None
        if e is None:
            # the plain call compiles the variant, checks the arguments and launches;
            # later calls with these arguments reuse what it found
            out = self.kernel(*args)
            e = self._setup(args)
            if e is not None:
                if len(self._entries) >= MAX_ENTRIES:
                    self._entries.pop(next(iter(self._entries)))
                self._entries[key] = e
            return out
        ctx = e.ctx
        for slot, i, real in e.scalars:
            if real:
                ctx.set_arg_float((slot,), float(args[i]))
            else:
                ctx.set_arg_int((slot,), int(args[i]))
        impl.get_runtime().prog.launch_kernel(e.data, ctx)
        return None

    def _setup(self, args):
        """The compiled kernel of these (already checked) arguments and where each one
        goes; None when the plain call must serve them."""
        primal = self._primal
        if primal.has_print:
            return None
        for kind, v in zip(self._kinds, args):
            if kind == "a" and (not isinstance(v, Ndarray) or v.grad is not None):
                return None
            if kind == "i" and not isinstance(v, numbers.Integral):
                return None
            if kind == "f" and not isinstance(v, numbers.Real):
                return None
        e = _Entry()
        e.t_kernel = primal.compiled_kernels[primal.ensure_compiled(*args)]
        prog = impl.get_runtime().prog
        e.data = prog.compile_kernel(prog.config(), prog.get_device_caps(), e.t_kernel)
        # one launch context for every call of this entry: the arrays go in by their
        # host addresses (as numpy arrays do), which the CPU launcher reads without
        # rewriting anything, so only the scalars change from call to call
        e.ctx = e.t_kernel.make_launch_context()
        refs, scalars = [], []
        slot = 0
        for i, (kind, v) in enumerate(zip(self._kinds, args)):
            if kind == "t":
                continue
            if kind == "a":
                refs.append(weakref.ref(v))
                a = v.arr
                e.ctx.set_arg_external_array_with_shape(
                    (slot,), int(prog.get_ndarray_data_ptr_as_int(a)),
                    int(a.nelement()) * int(a.element_size()), list(a.shape), 0)
            else:
                scalars.append((slot, i, kind == "f"))
            slot += 1
        e.refs, e.scalars = tuple(refs), tuple(scalars)
        return e


_CTYPES = {ti.i32: ctypes.c_int32, ti.i64: ctypes.c_int64, ti.f32: ctypes.c_float,
           ti.f64: ctypes.c_double}
_VIEWS = weakref.WeakKeyDictionary()     # array -> its view (or False: it has none)


def host_view(arr):
    """A numpy array over the memory of the CPU ``ti.ndarray`` ``arr`` of scalars
    (no copy; made once per array and valid while it lives): reading it costs what
    reading numpy does, against some 10 µs for ``arr[i]``. Kernels on the CPU have
    finished when their call returns, so the view reads what they wrote. None for
    other arrays (vectors, a GPU's)."""
    view = _VIEWS.get(arr)
    if view is None:
        ct = _CTYPES.get(arr.dtype)
        view = False
        if ct is not None and impl.current_cfg().arch in (ti.x64, ti.arm64) and \
                int(arr.arr.element_size()) == ctypes.sizeof(ct):
            ptr = int(impl.get_runtime().prog.get_ndarray_data_ptr_as_int(arr.arr))
            view = np.ctypeslib.as_array((ct * int(arr.arr.nelement())).from_address(ptr))
            view = view.reshape(tuple(arr.arr.shape))
        _VIEWS[arr] = view
    return view if view is not False else None


def host_copy(arr):
    """``arr.to_numpy()``, read through :func:`host_view` where it has one (a copy of
    the memory, without the copy kernel's launch: microseconds against some 150 µs)."""
    view = host_view(arr)
    return arr.to_numpy() if view is None else view.copy()


def cached(kernel):
    """Decorator (above ``@ti.kernel``): launches through :class:`Cached`."""
    return Cached(kernel)
