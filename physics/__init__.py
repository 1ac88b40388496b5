"""Physical laws: DEM contact laws and rolling resistance, and the continuum.

One law per file; each file holds the user-facing parameter class and the Taichi
function the engine calls for one contact. The continuum: :mod:`physics.pcmm` (the
PCMM element system, a package: ``rules.py``, ``system.py``, ``rebuild.py``,
``stress.py``, ``nodal.py``, ``step.py``, ``layout.py``), :mod:`physics.fvm` (the
triangle stress update), :mod:`physics.materials` and :mod:`physics.blocks`.
"""
# tdem first: these modules import tdem.core, and importing it runs tdem/__init__.py,
# which loads the engine, which imports this package's modules in its own order; the
# engine must start before any of them does (tdem/core/__init__.py)
import tdem  # noqa: F401

from .contact_law import ContactLaw, register_law
from .linear import LinearContact
from .hertz_mindlin import HertzMindlin
from .volume_contact import VolumeContact
from .rolling import RollingResistance

__all__ = ["ContactLaw", "register_law", "LinearContact", "HertzMindlin", "VolumeContact",
           "RollingResistance"]
