"""PCMM element system: triangles created from particle contacts (see
:mod:`physics.pcmm.rules`)."""
from . import rules
from .rules import *  # noqa: F401,F403
