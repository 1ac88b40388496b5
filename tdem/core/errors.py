"""Exceptions raised by tdem.

Also importable as ``tdem.errors`` and from ``tdem`` itself (the same classes).
"""

__all__ = ["InputError", "InstabilityError", "CapacityError"]


class InputError(ValueError):
    """Bad input: the message names the argument and the offending value."""


class InstabilityError(RuntimeError):
    """The run went unstable (NaN, or a particle moving absurdly far in one step).

    The simulation keeps the last good state; ``step``, ``time`` and ``particle``
    say where it failed.
    """

    def __init__(self, message, step=None, time=None, particle=None):
        super().__init__(message)
        self.step = step
        self.time = time
        self.particle = particle


class CapacityError(RuntimeError):
    """A fixed-capacity slot array would overflow and cannot grow further."""
