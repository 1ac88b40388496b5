"""tdem: continuum–discontinuum simulation in geomechanics, on Taichi.

The public API (see docs/api.md): :class:`Simulation`, the contact laws
:class:`LinearContact`, :class:`HertzMindlin`, :class:`VolumeContact` (polyhedra),
:class:`Granular` (composed of sub-models, :mod:`physics.granular`, with
:func:`register_submodel`), :class:`WetContact` (liquid bridges made at contact),
:class:`RollingResistance`, :class:`ParallelBond` and :class:`LiquidBridge` (bonded
particles, ``sim.bond``) (and :class:`ContactLaw` with :func:`register_law` for laws of
one's own, which may act across a gap), the
continuum materials :class:`Elastic`, :class:`MohrCoulomb`, :class:`Fluid`, :class:`JWL`, the
geometry helpers :mod:`tdem.pack` and :mod:`tdem.mesh`, and the errors
:class:`InputError`, :class:`InstabilityError`; :func:`plot_history` plots monitor
histories; :class:`TriaxialCell` is a cubical cell of six servo-controlled walls
(3D stress paths); :func:`ensemble` runs a function over many parameter sets on a Dask
cluster (``tdem.ensemble.grid`` makes a grid of them).
"""
from coupling.point_edge import PointEdge
from physics.contact_law import ContactLaw, register_law
from physics.hertz_mindlin import HertzMindlin
from physics.linear import LinearContact
from physics.volume_contact import VolumeContact
from physics.rolling import RollingResistance
from physics.parallel_bond import ParallelBond
from physics.liquid_bridge import LiquidBridge
from physics.wet_contact import WetContact
from physics import granular
from physics.granular import Granular, register_submodel
from physics.materials import JWL, Elastic, Fluid, MohrCoulomb
from physics.polyhedron import Polyhedron
from physics.shapes import Ellipsoid, Superellipse

from . import mesh, motion, pack, surfaces
from .plot import plot_history
from .errors import CapacityError, InputError, InstabilityError
from .pack import random_orientations
from .gradings import Grading, grading
from .simulation import Block, Mesh, ParticleGroup, Primitive, Simulation, Wall
from .cell import TriaxialCell
from .ensemble import Results as _EnsembleResults, ensemble, grid as _grid

ensemble.grid = _grid                  # tdem.ensemble.grid(a=[...], b=[...])
ensemble.Results = _EnsembleResults

__version__ = "0.1.0"

__all__ = ["Simulation", "ParticleGroup", "Wall", "Mesh", "Primitive", "Block", "surfaces",
           "random_orientations", "ContactLaw", "register_law",
           "LinearContact", "HertzMindlin", "VolumeContact", "Polyhedron",
           "RollingResistance", "PointEdge", "Superellipse", "Ellipsoid", "Elastic", "MohrCoulomb", "Fluid", "JWL", "InputError",
           "InstabilityError", "CapacityError", "mesh", "pack", "plot_history",
           "ensemble", "grading", "Grading", "motion", "TriaxialCell", "ParallelBond",
           "LiquidBridge", "WetContact", "Granular", "granular", "register_submodel"]
