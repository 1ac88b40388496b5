"""Particle–block and block–block point–edge contacts."""
from .point_edge import PointEdge

__all__ = ["PointEdge"]
