"""Particle–block and block–block point–edge contacts."""
# tdem first: these modules import tdem.core, and importing it runs tdem/__init__.py,
# which loads the engine, which imports this package's modules in its own order; the
# engine must start before any of them does (tdem/core/__init__.py)
import tdem  # noqa: F401

from .point_edge import PointEdge

__all__ = ["PointEdge"]
