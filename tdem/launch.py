"""Cached kernel launches: kept under this name for older imports.

``tdem.launch`` is :mod:`tdem.core.launch` itself, not a copy of its names: its
switch ``ENABLED`` is module state that ``reset()`` rebinds and tests set, and a copy
would go stale.
"""
import sys

from tdem.core import launch as _core

sys.modules[__name__] = _core
