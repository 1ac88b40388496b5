"""Motions of machinery as functions of time, for ``Wall.motion`` and ``Mesh.motion``.

A wall or mesh takes its velocity and angular velocity as constants or as functions
of the time t; these make the usual ones.
"""
import math

import numpy as np

from .errors import InputError

__all__ = ["vibration", "ramp"]


def as_vector(value, n):
    """``value`` as ``n`` finite numbers (an array), or None if it is not: the one
    check of a motion's parts, constants (``Wall.motion``) and the values its
    functions of time return (each step, :meth:`tdem.runner.Runner._apply_motions`)."""
    try:
        a = np.asarray(value, dtype=float).reshape(n)
    except (TypeError, ValueError):
        return None
    return a if np.isfinite(a).all() else None


class Motion:
    """A motion's part as a function of time that a checkpoint can keep: its kind and
    numbers (:meth:`to_dict`, :func:`from_dict`). Called with the time t (s)."""

    kind = ""

    def to_dict(self):
        return {"kind": self.kind, **self._numbers()}


class Vibration(Motion):
    """``amplitude`` × sin(2π ``frequency`` t + ``phase``) along ``direction``: its
    velocity (made by :func:`vibration`)."""

    kind = "vibration"

    def __init__(self, amplitude, frequency, direction, phase=0.0):
        a = float(amplitude)
        f = float(frequency)
        if not (math.isfinite(a) and a >= 0.0):
            raise InputError(f"amplitude must be a finite number >= 0, got {amplitude!r}")
        if not (math.isfinite(f) and f > 0.0):
            raise InputError(f"frequency must be a finite number > 0, got {frequency!r}")
        try:
            d = np.asarray(direction, dtype=float).ravel()
        except (TypeError, ValueError):
            d = np.zeros(0)
        if len(d) not in (2, 3) or not np.isfinite(d).all() or np.linalg.norm(d) == 0.0:
            raise InputError(f"direction must be 2 or 3 finite numbers, not all zero, got "
                             f"{direction!r}")
        self.amplitude, self.frequency = a, f
        self.direction = d / np.linalg.norm(d)
        self.phase = float(phase)
        self.__doc__ = f"vibration: amplitude {a:g} m, {f:g} Hz along {self.direction.tolist()}"

    def __call__(self, t):
        w = 2.0 * math.pi * self.frequency
        return (w * self.amplitude * math.cos(w * t + self.phase)) * self.direction

    def _numbers(self):
        return {"amplitude": self.amplitude, "frequency": self.frequency,
                "direction": self.direction.tolist(), "phase": self.phase}


class Ramp(Motion):
    """0 before ``start``, rising linearly to ``value`` over ``duration`` seconds, then
    ``value`` (made by :func:`ramp`)."""

    kind = "ramp"

    def __init__(self, value, duration, start=0.0):
        v = np.atleast_1d(np.asarray(value, dtype=float)).ravel()
        if not (len(v) in (1, 2, 3) and np.isfinite(v).all()):
            raise InputError(f"value must be 1 to 3 finite numbers, got {value!r}")
        d = float(duration)
        if not (math.isfinite(d) and d >= 0.0):
            raise InputError(f"duration must be a finite number >= 0, got {duration!r}")
        s0 = float(start)
        if not math.isfinite(s0):
            raise InputError(f"start must be a finite time, got {start!r}")
        self.value, self.duration, self.start = v, d, s0

    def __call__(self, t):
        if t <= self.start:
            f = 0.0
        elif self.duration == 0.0 or t >= self.start + self.duration:
            f = 1.0
        else:
            f = (t - self.start) / self.duration
        out = f * self.value
        return float(out[0]) if len(out) == 1 else out

    def _numbers(self):
        return {"value": self.value.tolist(), "duration": self.duration, "start": self.start}


_KINDS = {"vibration": Vibration, "ramp": Ramp}


def from_dict(d):
    """The motion a :meth:`Motion.to_dict` describes."""
    d = dict(d)
    cls = _KINDS.get(d.pop("kind", None))
    if cls is None:
        raise InputError(f"unknown motion {d!r}")
    return cls(**d)


def ramp(value, duration, start=0.0):
    """A velocity or angular velocity (``value``: 1 to 3 numbers) reached from rest
    linearly over ``duration`` seconds from the time ``start``: a drum spun up, a
    blade started. For ``Wall.motion`` / ``Mesh.motion``; a checkpoint keeps it."""
    return Ramp(value, duration, start)


def vibration(amplitude, frequency, direction, phase=0.0):
    """The velocity of a harmonic vibration, as a function of time: the displacement
    ``amplitude`` × sin(2π ``frequency`` t + ``phase``) along the unit of ``direction``
    (2 or 3 numbers), so the velocity 2π f × amplitude × cos(2π f t + phase) along it.
    For ``Wall.motion(velocity=...)`` or ``Mesh.motion(velocity=...)``; its peak
    acceleration, (2π f)² × amplitude, over g is the dimensionless Γ of vibrated beds.
    A checkpoint keeps it."""
    return Vibration(amplitude, frequency, direction, phase)
