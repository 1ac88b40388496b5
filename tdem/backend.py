"""Taichi initialisation: kept under this name for older imports.

``tdem.backend`` is :mod:`tdem.core.backend` itself, not a copy of its names: its
settings (``_state``) are module state that the engine and tests read and change.
"""
import sys

from tdem.core import backend as _core

sys.modules[__name__] = _core
