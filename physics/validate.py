"""Argument checks shared by the parameter classes: clear errors naming the argument."""
import math

from tdem.core.errors import InputError


def positive(name, value):
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a positive number, got {value!r}") from None
    if not math.isfinite(v) or v <= 0.0:
        raise InputError(f"{name} must be a positive number, got {value!r}")
    return v


def non_negative(name, value):
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a number >= 0, got {value!r}") from None
    if not math.isfinite(v) or v < 0.0:
        raise InputError(f"{name} must be a number >= 0, got {value!r}")
    return v


def in_range(name, value, lo, hi, lo_open=False, hi_open=False):
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a number, got {value!r}") from None
    bad = (not math.isfinite(v) or (v < lo) or (v > hi) or (lo_open and v == lo)
           or (hi_open and v == hi))
    if bad:
        lb = "(" if lo_open else "["
        rb = ")" if hi_open else "]"
        raise InputError(f"{name} must lie in {lb}{lo}, {hi}{rb}, got {value!r}")
    return v


def indices(name, value, n, what="particle"):
    """Indices into ``n`` items (``what``s) from ``value``: integers (a number, a list or
    an integer array), a boolean mask of length ``n`` (its True entries), or an object
    with ``.ids`` (a particle group). Floats (``[2.9]``), masks of another length, and
    indices outside [0, n) are refused naming the argument; so is an empty selection.
    Returns an int64 numpy array."""
    import numpy as np

    if hasattr(value, "ids"):
        value = value.ids
    try:
        a = np.atleast_1d(np.asarray(value))
    except (TypeError, ValueError):
        raise InputError(f"{name} must be {what} indices or a boolean mask, got "
                         f"{value!r}") from None
    if a.size == 0:
        raise InputError(f"{name} selects no {what}")
    if a.dtype == bool:
        if a.ndim != 1 or len(a) != n:
            raise InputError(f"{name}: a boolean mask must have one entry per {what} "
                             f"({n}), got shape {a.shape}")
        a = np.flatnonzero(a)
    elif not np.issubdtype(a.dtype, np.integer):
        raise InputError(f"{name} must be integer {what} indices or a boolean mask, got "
                         f"{a.dtype} values {a.ravel().tolist()[:8]}")
    a = a.astype(np.int64).ravel()
    bad = a[(a < 0) | (a >= n)]
    if bad.size:
        many = {"vertex": "vertices"}.get(what, what + "s")
        raise InputError(f"{name} must be {many} of this model (indices in [0, {n})), got "
                         f"{bad.tolist()[:8]}")
    return a
