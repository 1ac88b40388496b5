"""Argument checks shared by the parameter classes: clear errors naming the argument."""
import math

from tdem.errors import InputError


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
