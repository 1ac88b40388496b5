"""PCMM element system: triangles created from particle contacts.

Feng, Li & Oñate (2015), §2.2–2.3, with the gaps closed as in the project's
physics notes (§3). Positions x_i and radii R_i are given; δ is the contact-search
tolerance of the material.

Rules
-----
- **Neighbours** (Eq. 1): i and j are neighbours if d_ij ≤ R_i + R_j + δ.
- **Angular pruning** (§2.2, Fig. 4): a particle's neighbours are sorted
  counter-clockwise by position angle atan2(y_j − y_A, x_j − x_A) (ties by
  index). While two adjacent neighbours, the last and the first included, are
  less than 30° apart, the farther one of the pair is dropped (equal distances:
  the higher index). The pair handled first is the one with the smallest gap
  (first in the order on ties), so the result does not depend on where the
  circle is cut. Afterwards all gaps are ≥ 30°: at most 12 neighbours remain.
- **Creation**: particle A creates the triangle (A, i, i+1) for each pair of
  consecutive pruned neighbours (the last and the first included) when
    * it is counter-clockwise (the sector from i to i+1 is less than 180°; a wider
      sector is an open side of a boundary particle and creates nothing),
    * all three pairs satisfy Eq. 1,
    * every interior angle θ satisfies 30° ≤ θ ≤ 150° (Eq. 2), tested as
      |cos θ| ≤ cos 30°,
    * every edge d satisfies d ≥ 0.5·(R_1 + R_2 + R_3)/3 (Eq. 3).
  The pairs of one particle's ring are distinct and at most one of them spans
  more than 180°, so a particle never creates the same triangle twice; a
  triangle may however be created by each of its three vertices.

Storage (copies)
----------------
Each particle A stores the elements it created in its own slots
(``elem[A, s] = (i, i+1)``, s < ``ecnt[A]`` ≤ 12, in increasing order of i); the
element is (A, i, i+1), counter-clockwise. The element list is the union of all
slots, ordered by owner then slot, **copies included**: a triangle created by k of
its vertices appears k times. Every sum over elements below runs over this list.

Superposition (Eq. 4)
---------------------
N_e = the number of elements (copies included, e itself included) whose interior
strictly contains the probe point of e: the point with barycentric weights
(0.5, 0.3, 0.2) on e's vertices taken in increasing particle index. Copies of a
triangle get the same N_e. An element that covers the probe shares a vertex with
e, so only elements owned by e's vertices or by their Eq. 1 neighbours are tested
(an element (o, i, j) containing v has o = v or o a neighbour of v); an element
incident to several vertices of e is counted once, from the first of them. With
the weight w_e = 1/N_e, Σ_e w_e S_e is the area of the union of the elements
wherever every point of an element is covered as many times as its probe: exactly
on the square and hexagonal lattices, to 0.15 % on the paper's random packing.

Masses (Eq. 5)
--------------
M_i = Σ_{e ∋ i} ρ·S_e/(3·N_e) over the elements containing i; a particle in no
element gets ρ·π·R_i². Σ_i M_i = ρ·Σ_e S_e/N_e.

Rebuilt where something can have changed
-----------------------------------------
Inside a simulation (:func:`update`) the element set, N_e and the bookkeeping
that follows from them are recomputed only where they can have changed, and the
set stays exactly the one the rules give. Every answer a rule gives has a slack:
the distance each particle involved may move before the answer can change (a
distance against its cut-off: half the margin; an angle: the turn of the arms,
``_angle_slack``; the sign of an orientation or of a probe against an edge: the
exact bound of the change of a cross product, ``_orient_slack``). A particle's
Eq. 1 list, ring and elements depend on it and its candidates only; N_e of an
element on its vertices' Eq. 1 neighbourhoods. The rules are unchanged by a
translation, so what is tracked is each particle's displacement u since the
epoch began *relative to the particle whose rules they are*: with u measured from
the epoch's start, a particle built when the largest relative u around it was W
keeps its elements while the largest relative u around it stays below
slack − W. When the engine rebuilds its neighbour lists, a particle's new
candidates (beyond the Eq. 1 cut-off until then, by the engine's skin) add their
own slack. An epoch begins, everything rebuilt, at the first steps and after a
restore. As the u grow the budgets loosen, so after a step that had to rebuild many
particles or recount many N_e the epoch is renewed without a rebuild: each budget
is lowered by the relative u around it and the u restart from zero. A particle
that rebuilds and finds the same Eq. 1 list and elements (most of them: a
particle near a threshold rebuilds often, and the answers seldom flip) changes
nothing around it; only a change marks its neighbourhood for the bookkeeping.

Arrays
------
Everything lives in ``ti.ndarray`` objects passed to the module-level kernels
(compiled once per process; sizes and status indices in :mod:`physics.pcmm.layout`).
Fixed-capacity slots: the Eq. 1 neighbour list of a particle holds ``cap``
entries; a particle with more counts in ``flags`` and is never written past
(:class:`ElementSystem` grows ``cap`` and rebuilds). Results do not depend on the
number of threads: neighbour lists are sorted by index and every sum runs in a
fixed order.

Modules
-------
The package is split by responsibility; every name used from outside is
re-exported here (``physics.pcmm.NAME``).

- :mod:`physics.pcmm.layout` — array sizes and the indices of the status array
  ``pflags``;
- :mod:`physics.pcmm.rules` — the rules as Taichi functions (the Eq. 1 ring and its
  angular pruning, orientation and Eqs. 1–3 in ``_create``, the probe count N_e of
  Eq. 4 in ``_cover``), each with its slack;
- :mod:`physics.pcmm.system` — :class:`ElementSystem`, the element system of given
  positions built from scratch (initial elements, masses of Eq. 5), and
  :func:`check_rules`;
- :mod:`physics.pcmm.rebuild` — the engine-side system: :func:`candidates` and the
  lazy rebuild (:func:`displacements`, :func:`rebuild_elements`, :func:`mark_dirty`,
  :func:`copies`, :func:`incidence`, :func:`record_slots`, :func:`sync_copies`), the
  swelling JWL particles' rule radii (:func:`swell`);
- :mod:`physics.pcmm.stress` — the stress pass (:func:`stresses`,
  :func:`equation_of_state`) and the records the gather reads;
- :mod:`physics.pcmm.nodal` — the gather (:func:`gather`): each particle's force,
  stress and pair marks from the elements containing it;
- :mod:`physics.pcmm.step` — :func:`update`, one PCMM step in order.
"""
from .layout import (MAX_ELEMENTS, MAX_INCIDENT, P_BUILDS, P_BUILT, P_EPOCH, P_INC, P_NEED,
                     P_NEW, P_REBUILT, P_RECOUNT, P_SOFT, PFLAGS_INIT, PFLAGS_SIZE, SCAN_BLOCK)
from .rules import COS_30, MIN_GAP, PROBE
from .system import (F_NEED, F_OVER, FLAGS_SIZE, MAX_CAPACITY, ElementSystem, bin_particles,
                     check_rules, count_cover, create_elements, element_masses, find_neighbours)
from .rebuild import (EPOCH_REBUILT, EPOCH_RECOUNT, REBUILT_CHANGED, REBUILT_SAME, SLACK_FLOOR,
                      candidates, copies, displacements, incidence, mark_dirty, rebuild_elements,
                      record_slots, swell, sync_copies)
from .stress import (LOW32, bulk_viscosity, eos_volumes, equation_of_state, stresses,
                     viscous_stress)
from .nodal import CARRIED, FLUID_CORE, fluid_core_force, gather
from .step import update, volumes

__all__ = [
    # layout
    "MAX_ELEMENTS", "MAX_INCIDENT", "SCAN_BLOCK", "P_NEED", "P_BUILDS", "P_INC", "P_EPOCH",
    "P_NEW", "P_REBUILT", "P_RECOUNT", "P_BUILT", "P_SOFT", "PFLAGS_SIZE", "PFLAGS_INIT",
    # rules
    "MIN_GAP", "COS_30", "PROBE",
    # the standalone system
    "ElementSystem", "check_rules", "MAX_CAPACITY", "F_NEED", "F_OVER", "FLAGS_SIZE",
    "bin_particles", "find_neighbours", "create_elements", "count_cover", "element_masses",
    # the engine-side system
    "candidates", "displacements", "rebuild_elements", "mark_dirty", "copies", "sync_copies",
    "record_slots", "incidence", "swell", "EPOCH_REBUILT", "EPOCH_RECOUNT", "REBUILT_CHANGED",
    "REBUILT_SAME", "SLACK_FLOOR",
    # stresses
    "stresses", "equation_of_state", "eos_volumes", "bulk_viscosity", "viscous_stress",
    "LOW32",
    # gather and the step
    "gather", "fluid_core_force", "FLUID_CORE", "CARRIED", "update", "volumes",
]
