"""Motions of machinery as functions of time, for ``Wall.motion`` and ``Mesh.motion``.

A wall or mesh takes its velocity and angular velocity as constants or as functions
of the time t; these make the usual ones.
"""
import math

import numpy as np

from .errors import InputError

__all__ = ["vibration"]


def as_vector(value, n):
    """``value`` as ``n`` finite numbers (an array), or None if it is not: the one
    check of a motion's parts, constants (``Wall.motion``) and the values its
    functions of time return (each step, :meth:`tdem.runner.Runner._apply_motions`)."""
    try:
        a = np.asarray(value, dtype=float).reshape(n)
    except (TypeError, ValueError):
        return None
    return a if np.isfinite(a).all() else None


def vibration(amplitude, frequency, direction, phase=0.0):
    """The velocity of a harmonic vibration, as a function of time: the displacement
    ``amplitude`` × sin(2π ``frequency`` t + ``phase``) along the unit of ``direction``
    (2 or 3 numbers), so the velocity 2π f × amplitude × cos(2π f t + phase) along it.
    For ``Wall.motion(velocity=...)`` or ``Mesh.motion(velocity=...)``; its peak
    acceleration, (2π f)² × amplitude, over g is the dimensionless Γ of vibrated beds."""
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
    d = d / np.linalg.norm(d)
    w = 2.0 * math.pi * f
    ph = float(phase)

    def velocity(t):
        return (w * a * math.cos(w * t + ph)) * d
    velocity.__doc__ = (f"vibration: amplitude {a:g} m, {f:g} Hz along {d.tolist()}")
    return velocity
