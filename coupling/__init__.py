"""Particle–block and block–block point–edge contacts."""
import tdem  # noqa: F401  (the engine first: these modules use its errors)

from .point_edge import PointEdge

__all__ = ["PointEdge"]
