"""The engine's state arrays, declared once.

Every device array of the particle engine is one :class:`Array` of :data:`ENGINE`:
its name (the key in ``Simulation._a`` and the kernels' parameter name), its owner
(what its first index runs over), its components, its dtype and its role. The rest
is derived from this table:

- allocation (:func:`allocate`), for the sizes of a model;
- fresh rows for particles being added (:func:`fresh_rows`), with each array's fill;
- the restore point of a run segment (:func:`dynamic`, copied by :func:`copy`);
- what a checkpoint saves (:func:`saved`) and the numpy views.

Roles: ``dynamic`` arrays change during a run (a snapshot restores them, a checkpoint
saves them); ``setup`` arrays are set by the host between runs (saved, not in the
snapshot); ``scratch`` arrays are rebuilt whenever needed (neither).

Owners and their shapes: ``particle`` (n,), ``slot`` (n, cap) the half neighbour
list, ``wall_slot`` (n, capw) a particle's candidate walls, ``bond`` (bonds,) the
bonds (:mod:`tdem.bonds`), ``wall`` (walls,),
``wall_part`` (chunks, walls) per chunk of the step's pair loop, ``prim_slot``
(n, primitives) a particle's contacts with the primitive walls (one row, (1, 1), in a
model without them), ``prim`` (primitives,), ``prim_part`` (chunks, primitives), and
fixed-size tables. Components: 0 a scalar, k a k-vector, ``"H"`` / ``"HW"`` a pair's or a wall
contact's history vector (as wide as the registered contact laws need,
:mod:`physics.contact_law`).

:mod:`tdem.continuum` keeps the PCMM, block and coupling arrays in the same way
(``Continuum.a``, its snapshot list).
"""
from dataclasses import dataclass

import taichi as ti

from physics import contact_law
from physics.parallel_bond import BP_WIDTH
from physics.polyhedron import PI_WIDTH, PT_WIDTH

from .core.arrays import ndarray  # noqa: F401  (state.ndarray: the engine's arrays are made by it)
from .core.launch import cached
from .core.layout import PROP_INERTIA, PROP_MASS, PROP_RADIUS, PROP_WIDTH  # noqa: F401
from .primitives import PRIM_WIDTH


@dataclass(frozen=True)
class Array:
    name: str
    owner: str            # particle | slot | wall_slot | wall | wall_part | table
    comps: object         # 0 scalar, k vector, "H" / "HW" history, (a, b) a 2-d table row
    dtype: str            # "f": the simulation's precision, "f64", "i32"
    role: str             # dynamic | setup | scratch
    fill: float = 0.0     # value of a fresh entry
    doc: str = ""


# the columns of the particle property vector ``prop`` (PROP_*) are in tdem.core.layout

# sizes a shape may name: n, cap, capw, walls (>= 1), laws, law_width, cells,
# cell_starts; and fixed numbers
ENGINE = (
    # particles: kinematics, properties, prescribed motion
    Array("pos", "particle", "D", "f", "dynamic", doc="position x_n (m)"),
    Array("vel", "particle", "D", "f", "dynamic", doc="velocity v_{n-1/2} (m/s)"),
    Array("omega", "particle", "S", "f", "dynamic", doc="spin (rad/s; a 3-vector in 3D)"),
    Array("angle", "particle", "Q", "f", "dynamic",
          doc="angle θ (rad, counter-clockwise); in 3D the unit quaternion (w, x, y, z)"),
    Array("shp", "particle", 4, "f", "setup",
          doc="shape (a, b, n, area) of a superellipse (m, m, -, m²); n = 0 for a disc"),
    Array("prop", "particle", PROP_WIDTH, "f", "setup",
          doc="radius (m), mass (kg/m), inertia (kg m²/m): columns PROP_*"),
    Array("plaw", "particle", "i", "i32", "setup", doc="law group of the particle"),
    Array("fix", "particle", "i", "i32", "setup", doc="prescribed-velocity bits (step.FIX_*)"),
    Array("vfix", "particle", "DS", "f", "setup", doc="prescribed velocity, spin"),
    Array("force", "particle", "D", "f", "dynamic", doc="contact + element force (output)"),
    Array("torque", "particle", "S", "f", "dynamic", doc="moment (output)"),
    Array("xref", "particle", "D", "f", "dynamic", doc="position at the last list build"),
    Array("pos0", "particle", "D", "f", "dynamic",
          doc="position at the start (displacement; shifted with a periodic wrap)"),
    Array("facc", "particle", "DS", "f", "scratch", doc="force and moment sums of a step"),
    Array("wacc", "particle", {2: 5, 3: 8}, "f", "scratch",
          doc="3D: a particle's wall contacts of a step (force, moment, dissipation, work "
              "of the walls), from the step's wall loop to its pair loop"),
    Array("turn", "particle", {2: 2, 3: 9}, "f", "scratch",
          doc="cos θ, sin θ of each particle's angle at the step's start (2D); in 3D "
              "each particle's shape matrix, row by row (models with ellipsoids)"),
    Array("eacc", "particle", 2, "f", "dynamic", doc="dissipated energy, boundary work (J/m)"),
    Array("estate", "particle", 2, "f", "dynamic", doc="kinetic, gravitational energy at t_n"),
    Array("ework", "particle", 7, "f", "dynamic",
          doc="work done since the start by the contacts, the continuum (elements, "
              "point-edge contacts, viscous boundaries), gravity, damping, prescribed "
              "velocities, applied forces (J/m); kinetic energy at the start (J/m)"),
    Array("lmom", "particle", {2: 0, 3: 3}, "f", "dynamic",
          doc="3D: an ellipsoid's angular momentum L_{n-1/2}, world frame (kg m²/s)"),
    Array("fext", "particle", "DS", "f", "setup",
          doc="applied force (N/m) and moment (N m/m), sim.apply_force"),
    Array("ncnt", "particle", "i", "i32", "dynamic", doc="length of the half list"),
    Array("rcnt", "particle", "i", "i32", "dynamic", doc="length of the reverse list"),
    Array("ncnt_old", "particle", "i", "i32", "scratch", doc="half list before a rebuild"),
    # pair slots (half list, owner = lower index)
    Array("nbr", "slot", "i", "i32", "dynamic", fill=-1, doc="partner index"),
    Array("hist", "slot", "H", "f", "dynamic", doc="contact history (law, rolling, u0)"),
    Array("cn", "slot", "D", "f", "dynamic", doc="contact normal (output)"),
    Array("cf", "slot", "DS", "f", "dynamic", doc="force on the owner, moment on the partner"),
    Array("cs", "slot", 3, "f", "dynamic", doc="F_n, F_s, overlap (output)"),
    Array("rev", "slot", "i", "i32", "dynamic", doc="reverse list: owner << bits | slot"),
    Array("nbr_old", "slot", "i", "i32", "scratch", fill=-1, doc="half list before a rebuild"),
    Array("hist_old", "slot", "H", "f", "scratch", doc="history before a rebuild"),
    Array("cskip", "slot", "i", "i32", "scratch", doc="pair carried by PCMM elements"),
    # wall slots
    Array("wid", "wall_slot", "i", "i32", "dynamic", fill=-1, doc="candidate wall index"),
    Array("whist", "wall_slot", "HW", "f", "dynamic", doc="wall contact history"),
    Array("wcn", "wall_slot", "D", "f", "dynamic", doc="wall contact normal (output)"),
    Array("wcf", "wall_slot", {2: 4, 3: 6}, "f", "dynamic",
          doc="wall contact force, moment (output)"),
    Array("wcs", "wall_slot", 3, "f", "dynamic", doc="F_n, F_s, overlap (output)"),
    Array("wid_old", "wall_slot", "i", "i32", "scratch", fill=-1, doc="before a rebuild"),
    Array("whist_old", "wall_slot", "HW", "f", "scratch", doc="before a rebuild"),
    # primitive walls (3D planes and cylinders, tdem.primitives): every particle against
    # every primitive (a dense table; one row in a model without them)
    Array("phist", "prim_slot", "HW", "f", "dynamic", doc="primitive wall contact history"),
    Array("pcn", "prim_slot", "D", "f", "dynamic",
          doc="primitive wall contact normal (output)"),
    Array("pcf", "prim_slot", {2: 4, 3: 6}, "f", "dynamic",
          doc="primitive wall contact force, moment (output)"),
    Array("pcs", "prim_slot", 3, "f", "dynamic", doc="F_n, F_s, overlap (output)"),
    Array("prim", "table", ("prims", PRIM_WIDTH), "f64", "dynamic",
          doc="primitive walls' rows (tdem.primitives.PR_*)"),
    Array("pforce", "prim", 7, "f64", "dynamic",
          doc="force, moment about the primitive's point, contacts received"),
    Array("ppart", "prim_part", 7, "f64", "scratch",
          doc="pforce's partial sums, one row per chunk of the step's pair loop"),
    # bonds (tdem.bonds): the pair, its properties, its forces and, once broken, its record
    Array("bpair", "bond", 2, "i32", "setup", fill=-1, doc="the bond's two particles"),
    Array("bprop", "bond", BP_WIDTH, "f64", "setup",
          doc="stiffnesses, cross-section, strengths (physics.parallel_bond.BP_*)"),
    Array("bstate", "bond", 24, "f64", "dynamic",
          doc="forces, moments; the crack once broken (tdem.bonds.BS_*)"),
    Array("bforce", "particle", "DS", "f", "scratch",
          doc="the bonds' forces and moments on each particle in a step"),
    # walls and tables
    Array("wall", "table", ("walls", "wall_width"), "f64", "dynamic", doc="wall rows (step.W_*)"),
    Array("wforce", "wall", {2: 4, 3: 7}, "f64", "dynamic",
          doc="force, moment about the wall's centre, contacts received"),
    Array("wpart", "wall_part", {2: 4, 3: 7}, "f64", "scratch",
          doc="wforce's partial sums, one row per chunk of the step's pair loop"),
    Array("lawp", "table", ("laws", "law_width"), "f64", "scratch", doc="law parameters"),
    Array("lawpair", "table", ("laws", "laws"), "i32", "scratch", doc="law of a pair of groups"),
    Array("flags", "table", ("flags",), "i32", "dynamic", doc="status word (neighbors.F_*)"),
    Array("simp", "table", ("simp",), "f64", "scratch", doc="engine parameters (step.P_*)"),
    # neighbour grid
    Array("cell_count", "table", ("cells",), "i32", "scratch", doc="particles per cell"),
    Array("cell_start", "table", ("cell_starts",), "i32", "scratch", doc="prefix sums"),
    Array("sorted", "particle", "i", "i32", "scratch", doc="particles by cell"),
    Array("pcell", "particle", "i", "i32", "scratch", doc="cell of a particle"),
    Array("skey", "table", ("dim", "entries"), "f64", "scratch",
          doc="sort-and-sweep (tdem.sweep): the box ends' values along each axis, sorted"),
    Array("sent", "table", ("dim", "entries"), "i32", "scratch",
          doc="sort-and-sweep: the box ends in sorted order (particle << 1 | upper end)"),
    Array("srank", "table", ("entries",), "i32", "scratch",
          doc="sort-and-sweep: each box end's place along x (a fresh pair set's sweep)"),
    Array("spair", "slot", "i", "i32", "scratch", fill=-1,
          doc="sort-and-sweep: the particles (above this one) whose boxes overlap its own"),
    Array("scnt", "particle", "i", "i32", "scratch", doc="sort-and-sweep: length of spair"),
    Array("tbin_count", "table", ("tcells",), "i32", "scratch",
          doc="3D: mesh triangles per cell (the broad phase; 1 entry in 2D)"),
    Array("tbin_start", "table", ("tcell_starts",), "i32", "scratch",
          doc="3D: prefix sums of tbin_count, row totals after the cells"),
    Array("tbin_items", "table", ("tbin_cap",), "i32", "scratch",
          doc="3D: the triangles of each cell, from tbin_start"),
    Array("ptab", "table", ("pshapes", PT_WIDTH), "f64", "scratch",
          doc="3D: the polyhedra's vertices, planes, counts (physics.polyhedron.PT_*)"),
    Array("pint", "table", ("pshapes", PI_WIDTH), "i32", "scratch",
          doc="3D: the polyhedra's edges and surface triangles (physics.polyhedron.PI_*)"),
    Array("gridp", "table", ("dim2",), "f64", "setup", doc="grid origin, cell sizes"),
    Array("gridn", "table", (4,), "i32", "setup",
          doc="grid cells per axis (nz = 0 in 2D), particles"),
    Array("bounds", "table", ("dim2p1",), "f64", "scratch",
          doc="bounding box of the particles (lower, upper corner), largest radius"),
)
BY_NAME = {a.name: a for a in ENGINE}
# the primitive walls' arrays (a checkpoint of a model without them may lack them)
PRIM_ARRAYS = frozenset(a.name for a in ENGINE if a.owner.startswith("prim")
                        or a.name == "prim")


def per_particle(nprims):
    """The owners whose arrays have a row per particle: the primitive walls' contacts
    too in a model with ``nprims`` > 0 primitives (without, their arrays are one row)."""
    return ("particle", "slot", "wall_slot") + (("prim_slot",) if nprims else ())


def dynamic():
    """Names of the arrays a snapshot restores."""
    return tuple(a.name for a in ENGINE if a.role == "dynamic")


def saved():
    """Names of the arrays a checkpoint saves."""
    return tuple(a.name for a in ENGINE if a.role != "scratch")


def _comps(a, sizes):
    """Components of array ``a``: a number, or by the dimension (``sizes["dim"]``,
    2 unless given): "D" a position vector, "S" a spin (a scalar in 2D, a 3-vector
    in 3D), "DS" both, "Q" an orientation (the angle in 2D, a unit quaternion in
    3D), a dict {dim: k}, "H" / "HW" the history vectors."""
    dim = sizes.get("dim", 2)
    c = a.comps
    if c in ("H", "HW"):
        tdim = contact_law.tangent_dim(dim)
        f = contact_law.pair_history_width if c == "H" else contact_law.wall_history_width
        extra = 0
        if dim == 3 and sizes.get("shaped"):
            # ellipsoids: a pair keeps its last normal and its state, a wall contact its
            # Hertz radius (tdem.shaped3d)
            extra = 4 if c == "H" else 1
        elif dim == 3 and sizes.get("rolling"):
            # spheres with rolling resistance: the couple and rotation (3-vectors) and
            # the broken flag (physics.rolling.rolling_couple_3d)
            extra = 7
        return f(sizes["laws_set"], tdim) + extra
    if isinstance(c, dict):
        return c[dim]
    return {"D": dim, "S": 0 if dim == 2 else 3, "DS": 3 if dim == 2 else 6,
            "Q": 0 if dim == 2 else 4}.get(c, c)


def shape(a, sizes):
    """Shape (and vector width, or None) of array ``a`` for ``sizes`` (a dict)."""
    if a.owner == "table":
        dim = sizes.get("dim", 2)
        derived = {"dim2": 2 * dim, "dim2p1": 2 * dim + 1}
        return tuple(derived[s] if s in derived else sizes[s] if isinstance(s, str) else s
                     for s in a.comps), None
    lead = {"particle": ("n",), "slot": ("n", "cap"), "wall_slot": ("n", "capw"),
            "wall": ("walls",), "wall_part": ("chunks", "walls"),
            "prim_slot": ("pn", "prims"), "prim": ("prims",),
            "prim_part": ("chunks", "prims"), "bond": ("bonds",)}[a.owner]
    comps = _comps(a, sizes)
    return tuple(sizes[s] for s in lead), (None if comps in (0, "i") else comps)


def allocate(sizes, fdt, names=None):
    """The device arrays for ``sizes`` (n, cap, capw, walls, laws, law_width, cells,
    cell_starts, flags, simp, wall_width and laws_set, the registered law classes);
    ``fdt`` the float type of "f" arrays."""
    out = {}
    for a in ENGINE:
        if names is not None and a.name not in names:
            continue
        shp, vec = shape(a, sizes)
        dt = {"f": fdt, "f64": ti.f64, "i32": ti.i32}[a.dtype]
        out[a.name] = ndarray(vec, dt, shp)
    return out


def fresh_rows(n, sizes, values):
    """numpy rows for ``n`` new particles of every saved per-particle or per-slot array:
    each array's fill, with ``values`` (a dict of arrays) where given."""
    import numpy as np

    rows = {}
    owners = per_particle(sizes.get("nprims", 0))
    for a in ENGINE:
        if a.role == "scratch" or a.owner not in owners:
            continue
        shp, vec = shape(a, {**sizes, "n": n})
        dt = np.int32 if a.dtype == "i32" else np.float64
        rows[a.name] = (np.asarray(values[a.name], dtype=dt) if a.name in values else
                        np.full(shp + ((vec,) if vec else ()), a.fill, dtype=dt))
    return rows


@cached
@ti.kernel
def _copy(src: ti.types.ndarray(), dst: ti.types.ndarray(), serial: ti.template()):
    # (a loop over an external array's indices: Taichi has no one-thread form of it)
    for I in ti.grouped(src):
        dst[I] = src[I]


def copy(src, dst, names, serial):
    """dst[k] <- src[k] for the arrays ``names`` (one launch each, on the device)."""
    for k in names:
        _copy(src[k], dst[k], serial)


def like(arr):
    """A device array of the shape and type of ``arr``."""
    return ndarray(getattr(arr, "n", None), arr.dtype, arr.shape)


def bind(kernel, arrays, **values):
    """The positional arguments of ``kernel`` taken by name: each parameter from
    ``values`` if given there, else from ``arrays`` (the state dict). A kernel thus
    receives its arrays by the names it declares, never by position in a tuple."""
    fn = getattr(kernel, "_primal", None) or kernel.kernel._primal
    out = []
    for arg in fn.arguments:
        name = arg.name
        if name in values:
            out.append(values[name])
        elif name in arrays:
            out.append(arrays[name])
        else:
            raise KeyError(f"kernel {fn.func.__name__} takes {name!r}, which is neither a "
                           f"state array nor given")
    return tuple(out)
