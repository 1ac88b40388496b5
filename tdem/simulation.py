"""The public facade: :class:`Simulation`, the model a user builds.

This module holds what a script calls — the constructor, the methods that add
particles, walls, blocks, couplings, boundaries and prescribed motions, the time
step settings, monitors, output and checkpoints — with the checks of their input.
What happens when the model runs is in :mod:`tdem.runner` (device state, run segments,
snapshots, growth, replay; :meth:`tdem.runner.Runner._one_step` lists the stages of
one step in order), what it reads back in :mod:`tdem.results`, and the handles it
returns (particle groups, walls, blocks) in :mod:`tdem.handles`.

State lives in ``ti.ndarray`` objects (structure of arrays; fixed-capacity contact
slots per particle), declared once in :mod:`tdem.state`. The host only looks at the
device every ``check_interval`` steps: it then reads the status word (slot overflow,
unstable particles), keeps a device-side snapshot of the state, records monitors and
writes output.
"""
import math
import warnings

import numpy as np
import taichi as ti

from physics import contact_law as _claw
from physics.contact_law import ContactLaw
from physics.linear import LinearContact
from physics.materials import Material, MohrCoulomb
from physics.polyhedron import Polyhedron
from physics.shapes import Ellipsoid, Superellipse, mass_properties
from physics.volume_contact import VolumeContact
from physics import stability as _stability
from physics.validate import in_range, indices, non_negative

from . import backend
from . import mesh as _mesh
from . import pack as _pack
from . import primitives as _prims
from . import step as stepk
from .errors import InputError
from .handles import (Block, Mesh, ParticleGroup, Primitive, Wall, _View, _as_xy, _fix_value,
                      _in_box, _vector2)
from .bonds import BondView
from .results import Results
from .neighbors import F_BUILDS, F_NONCONV
from .runner import MAX_SLOTS, Runner  # noqa: F401  (MAX_SLOTS: part of this module's names)

# the engine's arrays are declared in tdem.state; the run loop is tdem.runner's, the
# numpy views tdem.results'


def _per_particle(name, value, n):
    """A number or one number per particle, as n floats; refused naming ``name``."""
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a number or one per particle ({n}), got "
                         f"{value!r}") from None
    if a.ndim > 1 or (a.ndim == 1 and len(a) != n):
        raise InputError(f"{name} must be a number or one per particle ({n}), got "
                         f"shape {a.shape}")
    return np.broadcast_to(a, (n,)).copy()


OVERLAP_WARN = 0.1    # initial overlap, relative to the smaller radius, that warns


def _warn_overlaps(old, old_r, new, new_r):
    """Warn when new discs start overlapping (each other or the plain discs already
    there; ``old_r`` is NaN for PCMM particles) by more than OVERLAP_WARN of the
    smaller radius: the springs then push them apart at speed in the first steps."""
    keep = ~np.isnan(old_r)
    ids = np.concatenate([np.flatnonzero(keep), len(old) + np.arange(len(new))])
    fresh = np.concatenate([np.zeros(int(keep.sum()), bool), np.ones(len(new), bool)])
    rel, i, j = _pack.largest_overlap(np.concatenate([old[keep], new]),
                                      np.concatenate([old_r[keep], new_r]), among=fresh)
    if rel > OVERLAP_WARN:
        warnings.warn(f"positions: particles {int(ids[i])} and {int(ids[j])} start "
                      f"overlapping by {rel:.0%} of the smaller radius (the largest initial "
                      f"overlap): their contact springs will push them apart at speed in "
                      f"the first steps; move them apart or let the packing relax first",
                      RuntimeWarning, stacklevel=3)


def _quaternions(name, q, n):
    """(n, 4) unit quaternions (w, x, y, z) from None (the identity), one (4,) or (n, 4);
    refused naming ``name`` unless finite and of unit norm (to 1e-6)."""
    if q is None:
        return np.tile([1.0, 0.0, 0.0, 0.0], (n, 1))
    try:
        a = np.asarray(q, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be unit quaternions (w, x, y, z), got {q!r}") from None
    if a.shape == (4,):
        a = np.tile(a, (n, 1))
    if a.shape != (n, 4):
        raise InputError(f"{name} must have shape ({n}, 4) or (4,): unit quaternions "
                         f"(w, x, y, z), got shape {a.shape}")
    norm = np.linalg.norm(a, axis=1)
    bad = ~(np.isfinite(a).all(axis=1) & (np.abs(norm - 1.0) <= 1e-6))
    if bad.any():
        k = int(np.argmax(bad))
        raise InputError(f"{name} must be unit quaternions: row {k} is {a[k].tolist()} "
                         f"(norm {norm[k]:.6g})")
    return a / norm[:, None]


def _refuse_coincident(old, new):
    """Refuse new particles whose centre coincides with another's (a contact of no
    direction: the run would fail at its first step)."""
    allpos = np.concatenate([old, new])
    _, inverse, counts = np.unique(allpos, axis=0, return_inverse=True, return_counts=True)
    dup = np.flatnonzero(counts[inverse.ravel()] > 1)
    if dup.size:
        same = dup[np.all(allpos[dup] == allpos[dup[0]], axis=1)]
        i, j = int(same[0]), int(same[1])
        raise InputError(f"positions: particles {i} and {j} have the same centre "
                         f"{tuple(float(c) for c in allpos[i])} (indices counted over the "
                         f"whole model)")


class Simulation(Runner, Results):
    """A DEM simulation in 2D (plane, unit thickness) or 3D (``dim=3``), SI units.

    Parameters
    ----------
    gravity : (2,) or, in 3D, (3,) m/s²; None: 9.81 m/s² along −y (2D) or −z (3D)
    dt : float or None
        Time step; None picks ``dt_fraction`` × the critical step 2·sqrt(m/k).
    dt_fraction : float in (0, 1]
    arch : "cpu" | "gpu" | None (then ``$TDEM_ARCH``, else "cpu")
    precision : "f64" | "f32" (storage precision of the float arrays)
    local_damping : α′ of the local non-viscous damping (0 = off)
    global_damping : α of C&S mass-proportional damping, 1/s (0 = off)
    skin : Verlet skin (m); None picks 0.4 × the smallest radius
    check_interval : steps between host checks (status, monitors, output)
    progress : None (a bar on a terminal for runs over 2 s), True or False
    threads : CPU threads (process-wide; None: Taichi's default or ``$TDEM_THREADS``)
    dim : 2 or 3. In 3D the particles are spheres (positions, velocities and spins
        are 3-vectors, orientations unit quaternions), ellipsoids or polyhedra, and
        the walls triangle meshes (:meth:`add_mesh`); PCMM bodies, blocks, segment
        walls and superellipses are 2D; rolling resistance is for discs and spheres.
    broad_phase : "grid" (a cell grid over bounding spheres, :mod:`tdem.neighbors`) or
        "sweep" (incremental sort-and-sweep of bounding boxes, :mod:`tdem.sweep`; not
        with periodic axes, PCMM bodies or blocks). Both list every pair within
        R_i + R_j + skin and give the same forces; benchmarks/RESULTS.md says which
        is faster where.
    """

    def __init__(self, gravity=None, dt=None, dt_fraction=0.2, arch=None,
                 precision="f64", local_damping=0.0, global_damping=0.0, skin=None,
                 check_interval=100, progress=None, threads=None, dim=2, broad_phase="grid",
                 mixed_discretization=True):
        if dim not in (2, 3) or isinstance(dim, bool):
            raise InputError(f"dim must be 2 or 3, got {dim!r}")
        if broad_phase not in ("grid", "sweep"):
            raise InputError(f"broad_phase must be 'grid' or 'sweep', got {broad_phase!r}")
        self.broad_phase = broad_phase
        if not isinstance(mixed_discretization, (bool, np.bool_)):
            raise InputError("mixed_discretization must be True or False, got "
                             f"{mixed_discretization!r}")
        self.mixed_discretization = bool(mixed_discretization)
        self.dim = int(dim)
        if gravity is None:
            gravity = (0.0, -9.81) if dim == 2 else (0.0, 0.0, -9.81)
        g = _vector2("gravity", gravity, self.dim)
        if precision not in ("f64", "f32"):
            raise InputError(f"precision must be 'f64' or 'f32', got {precision!r}")
        dt_fraction = in_range("dt_fraction", dt_fraction, 0.0, 1.0, lo_open=True)
        for name, v in (("local_damping", local_damping), ("global_damping", global_damping)):
            non_negative(name, v)
        if float(local_damping) >= 1.0:
            raise InputError(f"local_damping must lie in [0, 1), got {local_damping!r}")
        if skin is not None and not (float(skin) > 0.0 and math.isfinite(float(skin))):
            raise InputError(f"skin must be a positive number, got {skin!r}")
        if int(check_interval) < 1:
            raise InputError(f"check_interval must be >= 1, got {check_interval!r}")
        self.arch = backend.init(arch, threads)
        self.gravity = g
        self.precision = precision
        self._fdt = ti.f64 if precision == "f64" else ti.f32
        self.dt_fraction = dt_fraction
        self.local_damping = float(local_damping)
        self.global_damping = float(global_damping)
        self._skin_user = None if skin is None else float(skin)
        self.check_interval = int(check_interval)
        self.progress = progress
        self._dt_user = None
        # host-side description
        self._laws = []            # ContactLaw objects, index = law id
        self._law_set = _claw.registered()   # the law classes the kernels compile for
        self._built_roll3d = False           # the arrays hold 3D rolling columns
        self._built_range = 0.0              # ... and lists for the laws' range then
        self._pair_override = {}   # (law a, law b) -> law id
        self._groups = []
        self._host = {k: [] for k in ("pos", "vel", "radius", "density", "law", "mat", "shape",
                                      "angle", "omega", "ident")}
        self._next_ident = 0       # the identity of the next particle added (tdem.flows)
        self._inserters = []       # tdem.flows.Inserter
        self._outlets = []         # tdem.flows.Outlet
        self._flow_offsets = {}    # the account's sums of particles removed (tdem.flows)
        self._placed_clear = False  # add_particles of an inserter's batch: no overlap checks
        self._pending_state = None  # a flow event's state, rebuilt once (tdem.flows)
        self._pending_new = []
        self._shaped_cache = None
        self._polys = []          # the distinct polyhedra (their index: the shape tables' row)
        self._nonconv_reported = 0
        self._account0 = None      # the energy account after the first step (Results.energy)
        self._loads = []           # apply_force calls: (ids, fx, fy, moment)
        self._loads_on = False     # the step kernel's variant with applied loads
        self._load_fn = False
        self._slots = []           # (material, tolerance) of PCMM bodies and blocks
        self._blocks = []
        self._cont = None          # Continuum (PCMM elements, blocks) once built
        self._couples = []         # (particle ids, block, PointEdge)
        self._nonreflect = []      # ("p" | "v", ids, coef rows) of viscous boundaries
        self._lights = []          # (ids, lighting times) of JWL particles, before the build
        self._walls_host = []      # rows of the wall table
        self._periodic = [None] * self.dim   # (start, end) of the periodic x, y (z) axes
        self._meshes = []          # 3D: (first triangle row, number of rows) of each mesh
        self._prims_host = []      # 3D: rows of the primitive walls (tdem.primitives.PR_*)
        self._motions = {}         # (kind, index) -> (first, count, velocity, angular velocity)
        self._mesh_servo = {}      # 3D: mesh index -> (k, target, direction, relaxation, vmax)
        self._mservo_arr = None    # ... their rows on the device (tdem.step.servo_meshes)
        self._dt_run = None        # the step the device runs with (set by _upload_params)
        self._grid_bulk = None     # the cell grid's bulk box, when it covers only the bulk
        self._fast_warned = False  # warnings given once: a particle faster than R a step,
        self._stiff_warned = False  # a contact stiffer than the step allows,
        self._silent_checked = False   # a model with nothing moving it
        self._dense_checked = None     # (key) the dense-packing step check done for
        self._fixes = []           # (ids, vx, vy, omega) prescribed velocities
        self._n = 0
        self._built = False
        self._a = {}
        self._snap = {}
        self._cap = 8
        self._capw = 4
        self._time = 0.0
        self._steps = 0
        self._monitors = []
        self._output = None
        self._fix_fn = None
        self._crit_cache = None
        self._skin_auto = None
        self._host_reads_flag = self.arch == "cpu"
        self._last_fit = 0
        self._next_event = 1 << 62
        if dt is not None:
            self._dt_user = self._check_dt_value(dt)
        self._nbonds = 0           # bonds made (intact and broken: tdem.bonds)
        self._bond_host = {}       # their rows before the first build
        self.bonds = BondView(self, broken=False)
        self.cracks = BondView(self, broken=True)
        self.particles = _View(self._particles_numpy, lambda: self._n)
        self.contacts = _View(self._contacts_numpy, lambda: len(self._contacts_numpy()["pairs"]))
        self.elements = _View(self._elements_numpy,
                              lambda: len(self._elements_numpy()["triangles"]))

    # ------------------------------------------------------------------ set-up
    def _law_id(self, law, argname="contact"):
        if not isinstance(law, ContactLaw):
            raise InputError(f"{argname} must be a contact law such as tdem.LinearContact(...), "
                             f"got {law!r}")
        if not _claw.is_registered(type(law)):
            raise InputError(f"{argname}: the contact law {type(law).__name__} is not registered: "
                             f"decorate its class with @tdem.register_law")
        for k, known in enumerate(self._laws):
            if known is law:
                return k
        self._laws.append(law)
        return len(self._laws) - 1

    def periodic(self, x=None, y=None, z=None):
        """Make the x and/or y (and in 3D z) axis periodic over [x0, x1) (and [y0, y1),
        [z0, z1)): particles that
        leave on one side come back on the other, the neighbour search and the contacts
        see across the boundary (between images), walls and output are unaffected.
        ``None`` leaves an axis as it is; ``False`` makes it open again. The period
        must hold three cells of the neighbour grid (2 × the largest radius + the skin
        each), checked when a run starts. PCMM particles and blocks cannot be periodic.
        """
        new = list(self._periodic)
        if z is not None and self.dim == 2:
            raise InputError(f"z: a 2D simulation has no z axis (got z={z!r})")
        for k, (name, v) in enumerate((("x", x), ("y", y), ("z", z))[:self.dim]):
            if v is None:
                continue
            if v is False:
                new[k] = None
                continue
            try:
                lo, hi = (float(c) for c in v)
            except (TypeError, ValueError):
                raise InputError(f"{name} must be a pair (start, end) of numbers, got "
                                 f"{v!r}") from None
            if not (math.isfinite(lo) and math.isfinite(hi) and hi > lo):
                raise InputError(f"{name} must be (start, end) with start < end, both "
                                 f"finite, got {v!r}")
            new[k] = (lo, hi)
        if any(p is not None for p in new) and self.broad_phase == "sweep":
            raise InputError("periodic: broad_phase='sweep' does not support periodic axes "
                             "(use broad_phase='grid')")
        if any(p is not None for p in new) and self._nbonds:
            raise InputError("periodic: a model with bonds cannot be periodic (bonds do "
                             "not cross periodic boundaries)")
        if any(p is not None for p in new) and (self._slots or self._blocks):
            raise InputError("periodic: PCMM particles and blocks cannot be periodic (their "
                             "elements would span the boundary)")
        self._periodic = new
        if self._built:
            self._upload_params()
            if self._n:
                self._fit_grid(force=True)
        return self

    def add_particles(self, positions, radius=None, density=2500.0, contact=None,
                      material=None, tolerance=0.0, velocity=None, shape=None, angle=None,
                      omega=None, orientation=None):
        """Add discs (``radius``) or shaped particles (``shape``, e.g.
        :class:`tdem.Superellipse`, turned by ``angle``: degrees, counter-clockwise, a
        number or one per particle; default 0); returns a :class:`ParticleGroup`
        (``.ids`` their indices). ``velocity``: (N, 2) or (2,), m/s; ``omega``: the
        initial spin, rad/s counter-clockwise, a number or one per particle. A shape's bounding radius (the largest distance of its boundary from
        its centre) serves as the
        particle's radius (neighbour search, output); its mass and inertia are the
        shape's. Shaped particles take the linear or Hertz–Mindlin law (no rolling
        resistance) and cannot be PCMM particles.

        With ``material`` (tdem.Elastic, MohrCoulomb, Fluid) the particles are PCMM
        particles of one continuum body: elements are created between particles of
        the same material and tolerance δ (Eq. 1: d ≤ R_i + R_j + δ), their masses
        follow Eq. 5 and ``density`` is the material's. ``contact`` then acts only
        between particles that touch but share no element (and against walls and
        other particles); by default a linear law with k_n = k_s = E (N/m per metre
        of thickness) and friction tan φ (MohrCoulomb) or 0.5.

        In 3D (``dim=3``): spheres of ``radius`` at (N, 3) ``positions``; ``velocity``
        and ``omega`` (N, 3) or (3,); ``orientation`` (N, 4) or (4,) unit quaternions
        (w, x, y, z), default (1, 0, 0, 0).
        """
        slot = -1
        if self.dim == 3:
            if shape is not None and not isinstance(shape, (Ellipsoid, Polyhedron)):
                raise InputError(f"shape: a 3D simulation takes spheres (radius=), "
                                 f"tdem.Ellipsoid(a, b, c) or tdem.Polyhedron(vertices); got "
                                 f"{shape!r}")
            self._check_polyhedral(shape, contact)
            self._refuse_2d_only(material=material, angle=angle)
            rolls = contact is not None and getattr(contact, "rolling", None) is not None
            if rolls and (shape is not None or self._has_shapes):
                raise InputError(f"contact: rolling resistance is for spheres; a model with "
                                 f"ellipsoids takes laws without rolling= (got {contact!r})")
            if shape is not None and self._rolling3d:
                raise InputError("shape: ellipsoids cannot join a model whose laws have "
                                 "rolling resistance (a sphere feature)")
            if shape is not None and self._prims_host:
                raise InputError(f"shape: primitive walls (add_plane, add_cylinder) take "
                                 f"spheres only; got shape={shape!r} (use a mesh wall, "
                                 f"add_mesh with tdem.surfaces.plane)")
        elif orientation is not None:
            raise InputError(f"orientation: a 2D particle's orientation is its angle= "
                             f"(got orientation={orientation!r})")
        if shape is not None:
            if self.dim == 2 and not isinstance(shape, Superellipse):
                raise InputError(f"shape must be a shape such as tdem.Superellipse(a, b, n), got "
                                 f"{shape!r}" + (" (an ellipsoid is 3D: tdem.Simulation(dim=3))"
                                                 if isinstance(shape, Ellipsoid) else ""))
            if radius is not None:
                raise InputError(f"radius: a shaped particle's size is its shape's ({shape!r}); "
                                 f"give radius or shape, not both (got radius={radius!r})")
            if material is not None:
                raise InputError(f"material: shaped particles cannot be PCMM particles (got "
                                 f"shape={shape!r} with material={material!r})")
            if contact is not None and getattr(contact, "rolling", None) is not None:
                raise InputError(f"contact: rolling resistance is a disc feature; shaped "
                                 f"particles take a law without rolling= (got {contact!r})")
        elif radius is None:
            raise InputError("radius must be given (one number or one per particle), or a "
                             "shape= such as tdem.Superellipse(a, b, n)")
        elif angle is not None:
            raise InputError(f"angle: discs have no angle to set (got angle={angle!r}); it "
                             "goes with shape=")
        if material is not None:
            if not isinstance(material, Material):
                raise InputError("material must be a continuum material such as "
                                 f"tdem.Elastic(...), got {material!r}")
            try:
                tol = float(tolerance)
            except (TypeError, ValueError):
                raise InputError(f"tolerance must be a number >= 0, got {tolerance!r}") from None
            if not (tol >= 0.0 and math.isfinite(tol)):
                raise InputError(f"tolerance must be a number >= 0, got {tolerance!r}")
            if self._built:
                raise InputError("material: PCMM particles must be added before the first run "
                                 "(their element system and masses are set up then)")
            density = material.density
            if contact is None:
                young = getattr(material, "young", None) or 3.0 * material.bulk
                fr = math.tan(math.radians(material.friction_angle)) \
                    if isinstance(material, MohrCoulomb) else 0.5
                contact = LinearContact(kn=young, ks=young, friction=fr)
        elif self._built and self._cont is not None:
            raise InputError("positions: particles cannot be added after the first run of a "
                             "model with PCMM particles or blocks")
        pos = _as_xy("positions", positions, dim=self.dim)
        n = len(pos)
        if n == 0:
            raise InputError("positions must hold at least one particle, got none")
        if isinstance(shape, Polyhedron):
            r = np.full(n, shape.bounding_radius)
            k = next((k for k, p in enumerate(self._polys) if p == shape), len(self._polys))
            shp = np.tile(list(shape.principal_moments) + [-(k + 1.0)], (n, 1))
            ang = _quaternions("orientation", orientation, n)
        elif shape is not None and self.dim == 3:
            r = np.full(n, shape.bounding_radius)
            shp = np.tile([shape.a, shape.b, shape.c, 1.0], (n, 1))
            ang = _quaternions("orientation", orientation, n)
        elif shape is not None:
            r = np.full(n, shape.bounding_radius)
            shp = np.tile([shape.a, shape.b, shape.n, shape.area], (n, 1))
            ang = np.radians(_per_particle("angle", 0.0 if angle is None else angle, n))
            if not np.isfinite(ang).all():
                k = int(np.argmax(~np.isfinite(ang)))
                raise InputError(f"angle must be finite: particle {k} has angle "
                                 f"{float(np.degrees(ang[k]))!r}")
        else:
            r = _per_particle("radius", radius, n)
            shp = np.zeros((n, 4))
            ang = np.zeros(n) if self.dim == 2 else _quaternions("orientation", orientation, n)
        bad = ~(np.isfinite(r) & (r > 0))
        if bad.any():
            k = int(np.argmax(bad))
            raise InputError(f"radius must be positive: particle {k} has radius {float(r[k])!r}")
        rho = _per_particle("density", density, n)
        bad = ~(np.isfinite(rho) & (rho > 0))
        if bad.any():
            k = int(np.argmax(bad))
            raise InputError(f"density must be positive: particle {k} has density {float(rho[k])!r}")
        if contact is None:
            raise InputError("contact must be given: a law such as tdem.LinearContact(kn=...)")
        vel = np.zeros((n, self.dim)) if velocity is None else _as_xy("velocity", velocity, n,
                                                                        dim=self.dim)
        if self.dim == 3:
            om = np.zeros((n, 3)) if omega is None else _as_xy("omega", omega, n, dim=3)
        else:
            om = _per_particle("omega", 0.0 if omega is None else omega, n)
        if not np.isfinite(om).all():
            k = int(np.argmax(~np.isfinite(om)))
            raise InputError(f"omega must be finite: particle {k} has omega {float(om[k])!r}")
        pending = self._pending_state
        state = pending if pending is not None else (self._download() if self._built
                                                     else None)
        old = state["pos"] if state is not None else (
            np.concatenate(self._host["pos"]) if self._host["pos"] else np.zeros((0, self.dim)))
        # (an inserter's batch is placed clear of every particle: tdem.flows)
        clear = self._placed_clear
        if not clear:
            _refuse_coincident(old, pos)
        if material is None and not clear:
            # (a shape's inscribed circle: a warning means a real overlap)
            _warn_overlaps(old, self._dem_radii(state), pos,
                           r if shape is None else np.full(n, shape.inscribed_radius))
        # every check passed: from here on the model changes (the law is checked
        # before it is added)
        law = self._law_id(contact)
        if isinstance(shape, Polyhedron) and not any(p == shape for p in self._polys):
            self._polys.append(shape)
        if material is not None:
            slot = self._slot_of(material, tol)
        ids = np.arange(self._n, self._n + n)
        self._host["pos"].append(pos)
        self._host["vel"].append(vel)
        self._host["radius"].append(r)
        self._host["density"].append(rho)
        self._host["law"].append(np.full(n, law))
        self._host["mat"].append(np.full(n, slot))
        self._host["shape"].append(shp)
        self._host["angle"].append(ang)
        self._host["omega"].append(om)
        self._host["ident"].append(np.arange(self._next_ident, self._next_ident + n))
        self._next_ident += n
        self._n += n
        g = ParticleGroup(self, ids, contact, rho)
        self._groups.append(g)
        if pending is not None:
            # (tdem.flows: one rebuild for a segment's removals and insertions)
            self._pending_new.append((pos, vel, r, rho, law, shp, ang, om))
        elif state is not None:
            self._rebuild_from(state, new_particles=(pos, vel, r, rho, law, shp, ang, om))
        return g

    def _dem_radii(self, state):
        """Radii of the particles there now, NaN for PCMM ones (their overlaps are
        meant: elements hold them)."""
        if not self._n:
            return np.zeros(0)
        r = state["prop"][:, 0].copy() if state is not None else np.concatenate(
            self._host["radius"])
        r[np.concatenate(self._host["mat"]) >= 0] = np.nan
        shp = np.concatenate(self._host["shape"])
        if self.dim == 3:
            ell = shp[:, 3] > 0
            r[ell] = shp[ell, :3].min(axis=1)                     # inscribed spheres
            poly = shp[:, 3] < 0
            if poly.any():
                ins = np.array([p.inscribed_radius for p in self._polys])
                r[poly] = ins[-shp[poly, 3].astype(int) - 1]
            return r
        shaped = shp[:, 2] > 0
        r[shaped] = np.minimum(shp[shaped, 0], shp[shaped, 1])    # inscribed circles
        return r

    def _check_polyhedral(self, shape, contact):
        """Polyhedra take tdem.VolumeContact, and only they do; they do not share a model
        with ellipsoids (no contact of the two is defined)."""
        poly = isinstance(shape, Polyhedron)
        if poly and contact is not None and not isinstance(contact, VolumeContact):
            raise InputError(f"contact: polyhedra take tdem.VolumeContact(young=, friction=, "
                             f"restitution=), got {contact!r}")
        if not poly and isinstance(contact, VolumeContact):
            raise InputError(f"contact: tdem.VolumeContact is the law of polyhedra (the "
                             f"overlap volume); spheres and ellipsoids take LinearContact or "
                             f"HertzMindlin (a sphere–polyhedron pair takes the polyhedron's "
                             f"law), got {contact!r} for shape={shape!r}")
        rows = np.concatenate(self._host["shape"]) if self._host["shape"] else np.zeros((0, 4))
        if (poly and (rows[:, 3] > 0).any()) or (isinstance(shape, Ellipsoid)
                                                 and (rows[:, 3] < 0).any()):
            raise InputError(f"shape: ellipsoids and polyhedra cannot share a simulation (no "
                             f"contact between the two is defined), got {shape!r}")

    def _slot_of(self, material, tol):
        for k, (m, t) in enumerate(self._slots):
            if m is material and t == tol:
                return k
        self._refuse_sweep(f"material={material!r}")
        self._slots.append((material, tol))
        return len(self._slots) - 1

    def _refuse_sweep(self, what):
        """PCMM bodies and blocks find their candidates in the grid's cells."""
        if self.broad_phase == "sweep":
            raise InputError(f"{what}: PCMM bodies and blocks need broad_phase='grid' (their "
                             f"element search uses the cell grid), this simulation has "
                             f"broad_phase='sweep'")

    def add_block(self, vertices, triangles, material, rigid=False, velocity=(0.0, 0.0)):
        """Add a block: a triangle mesh (vertices (V, 2), counter-clockwise triangles
        (T, 3)) of a continuum material, with lumped nodal masses. ``rigid=True``: a
        rigid body (3 degrees of freedom: its mass, centre and moment of inertia from
        the lumped masses; no stress), free, or driven by fixing all its nodes.
        ``velocity``: initial velocity of every node. Returns a :class:`Block`."""
        if self.dim == 3:
            self._refuse_2d_only(material=material)
        if rigid not in (True, False):
            raise InputError(f"rigid must be True or False, got {rigid!r}")
        if not isinstance(material, Material):
            raise InputError("material must be a continuum material such as "
                             f"tdem.Elastic(...), got {material!r}")
        if self._built:
            raise InputError("vertices: blocks must be added before the first run")
        self._refuse_sweep("add_block")
        x, t = _mesh.check_mesh(vertices, triangles)
        used = np.zeros(len(x), bool)
        used[t.ravel()] = True
        if not used.all():
            k = int(np.argmin(used))
            raise InputError(f"vertices: vertex {k} belongs to no triangle")
        v = _vector2("velocity", velocity)
        slot = len(self._slots)
        self._slots.append((material, None))
        b = Block(self, len(self._blocks), x, t, material, slot,
                  np.broadcast_to(v, x.shape).copy())
        b.rigid = bool(rigid)
        self._blocks.append(b)
        return b

    @property
    def blocks(self):
        return list(self._blocks)

    def couple(self, a, b, law):
        """Point–edge contacts (``tdem.PointEdge``) between the particles ``a`` (a
        :class:`ParticleGroup` or particle indices) and the boundary edges of the
        block ``b`` (Feng et al. §2.6); or, with ``a`` a block, vertex–edge contacts
        both ways between the two blocks' boundaries. Must be called before the
        first run."""
        from coupling.point_edge import PointEdge
        if self.dim == 3:
            self._refuse_2d_only(law=law)
        if not isinstance(law, PointEdge):
            raise InputError(f"law must be a tdem.PointEdge(...), got {law!r}")
        if not isinstance(b, Block) or b._sim is not self:
            raise InputError(f"b must be a block of this simulation (from add_block), got {b!r}")
        if isinstance(a, Block):
            if a._sim is not self or a is b:
                raise InputError(f"a must be another block of this simulation, got {a!r}")
            if self._built:
                raise InputError("a: couples must be set up before the first run")
            for ids0, a0, b0, _ in self._couples:
                if ids0 is None and {id(a0), id(b0)} == {id(a), id(b)}:
                    raise InputError(f"a: the blocks {a!r} and {b!r} are coupled already "
                                     f"(a second couple would double the contact stiffness)")
            self._couples.append((None, a, b, law))
            return
        ids = indices("a", a, self._n)
        if self._built:
            raise InputError("a: couples must be set up before the first run")
        for ids0, a0, b0, _ in self._couples:
            if ids0 is not None and b0 is b:
                both = np.intersect1d(ids0, ids)
                if both.size:
                    raise InputError(f"a: particles {both.tolist()[:8]} are coupled to "
                                     f"{b!r} already (a second couple would double the "
                                     f"contact stiffness)")
        self._couples.append((ids, None, b, law))

    def non_reflecting(self, target, normal=None):
        """Viscous (Lysmer–Kuhlemeyer) non-reflecting boundary on particles or block
        nodes: the traction −ρ·c_p·v_n on the normal and −ρ·c_s·v_s on the tangential
        velocity, over the point's tributary length (for particles, half the
        distances to their neighbours along the boundary line given; for nodes, half
        their two boundary edges), ρ, c_p, c_s of its material.

        ``target``: particle indices (or a :class:`ParticleGroup`) of PCMM particles,
        a :class:`Block` (all its boundary nodes) or ``(block, nodes)``. ``normal``:
        the outward unit normal, (2,) or one per point; default: from the block's
        boundary edges joining the given nodes (which also give the tributary
        lengths), or for particles away from the centroid of their neighbours
        within 3R.
        """
        if isinstance(target, tuple) and len(target) == 2 and isinstance(target[0], Block):
            block, nodes = target
        elif isinstance(target, Block):
            block, nodes = target, None
        else:
            block = None
        if block is not None:
            be = _mesh.boundary_edges(block.triangles)
            x = block.vertices
            bnodes = np.unique(be)
            nodes = bnodes if nodes is None else indices("target: nodes", nodes,
                                                         len(block.vertices), "vertex")
            if nodes.size == 0 or not np.isin(nodes, bnodes).all():
                raise InputError(f"target: nodes must be boundary nodes of the block, got "
                                 f"{np.asarray(nodes).tolist()[:8]}")
            # the boundary covered: the edges with both ends among the nodes
            be = be[np.isin(be[:, 0], nodes) & np.isin(be[:, 1], nodes)]
            if len(be) == 0:
                raise InputError("target: the nodes must span at least one boundary edge")
            m = x[be[:, 1]] - x[be[:, 0]]
            nrm_len = np.stack([m[:, 1], -m[:, 0]], 1)          # n·L, outward
            acc = np.zeros_like(x)
            trib = np.zeros(len(x))
            for k in (0, 1):
                np.add.at(acc, be[:, k], nrm_len)
                np.add.at(trib, be[:, k], 0.5 * np.linalg.norm(m, axis=1))
            n = acc[nodes] / np.linalg.norm(acc[nodes], axis=1)[:, None] if normal is None \
                else self._unit_normals(normal, len(nodes))
            mat = block.material
            area = trib[nodes]
            kind, ids = "v", nodes
        else:
            ids = indices("target", target, self._n)
            slots = np.concatenate(self._host["mat"])[ids]
            if (slots < 0).any() or len(np.unique(slots)) != 1:
                raise InputError("target: a viscous boundary needs PCMM particles of one "
                                 "material (add_particles(..., material=...))")
            mat = self._slots[int(slots[0])][0]
            pos = np.concatenate(self._host["pos"])
            rad = np.concatenate(self._host["radius"])
            if normal is None:
                n = np.zeros((len(ids), 2))
                body = np.flatnonzero(np.concatenate(self._host["mat"]) == slots[0])
                for k, i in enumerate(ids):
                    d = pos[body] - pos[i]
                    near = body[np.einsum("ij,ij->i", d, d) < (3 * rad[i]) ** 2]
                    out = pos[i] - pos[near].mean(axis=0)
                    n[k] = out / max(np.linalg.norm(out), 1e-300)
            else:
                n = self._unit_normals(normal, len(ids))
            area = self._tributary(pos[ids], rad[ids])
            kind = "p"
        rho = mat.density
        cp = mat.p_wave_speed
        cs = math.sqrt(mat.shear / rho)
        coef = np.column_stack([n, area * rho * cp, area * rho * cs])
        if kind == "v":
            ids = ids + block._offset if self._cont is not None else ids
        self._nonreflect.append((kind, ids, coef, block))
        if self._cont is not None:
            self._cont.set_non_reflecting(kind, ids, coef)

    @staticmethod
    def _tributary(x, r):
        """Tributary length of each point of a boundary line of particles: half the
        distances to its two nearest neighbours on the line, or half the one of an
        end point (both neighbours on one side); 2R for a lone particle."""
        out = 2.0 * r.copy()
        if len(x) < 2:
            return out
        for k in range(len(x)):
            d = x - x[k]
            dist = np.linalg.norm(d, axis=1)
            dist[k] = np.inf
            order = np.argsort(dist)
            a = order[0]
            if len(x) == 2:
                out[k] = 0.5 * dist[a]
                continue
            b = order[1]
            if np.dot(d[a], d[b]) > 0.0:          # both on one side: an end point
                out[k] = 0.5 * dist[a]
            else:
                out[k] = 0.5 * (dist[a] + dist[b])
        return out

    def detonate(self, target, point, time=0.0):
        """Programmed burn of JWL particles (:class:`tdem.JWL`): particle i lights at
        t_l = ``time`` + ‖x_i − ``point``‖/D (positions now) and releases its pressure
        over the next 3R/D (the burn fraction). ``target``: particle indices or a
        :class:`ParticleGroup` of JWL particles. Unlit JWL particles have no pressure.
        """
        from physics.materials import JWL
        ids = indices("target", target, self._n)
        slots = np.concatenate(self._host["mat"])[ids]
        mats = {self._slots[int(k)][0] if k >= 0 else None for k in np.unique(slots)}
        if len(mats) != 1 or not isinstance(next(iter(mats)), JWL):
            raise InputError("target: detonate needs particles of one JWL material "
                             "(add_particles(..., material=tdem.JWL...))")
        point = np.asarray(point, dtype=float)
        if point.shape != (2,) or not np.isfinite(point).all():
            raise InputError(f"point must be a finite (x, y), got {point.tolist()!r}")
        time = float(time)
        if not math.isfinite(time):
            raise InputError(f"time must be finite, got {time!r}")
        pos = self._a["pos"].to_numpy()[ids] if self._built else \
            np.concatenate(self._host["pos"])[ids]
        times = time + np.linalg.norm(pos - point, axis=1) / next(iter(mats)).D
        if self._built:
            self._cont.light(ids, times)
        else:
            self._lights.append((ids, times))
        return times

    @staticmethod
    def _unit_normals(normal, k):
        n = np.broadcast_to(np.asarray(normal, dtype=float), (k, 2)).copy()
        ln = np.linalg.norm(n, axis=1)
        if not np.all(np.isfinite(n)) or (ln == 0).any():
            raise InputError(f"normal must be non-zero vectors, got {normal!r}")
        return n / ln[:, None]

    def _couple_rows(self):
        """Couples with their stiffnesses resolved (PointEdge docstring)."""
        rows = []
        laws = np.concatenate(self._host["law"]) if self._n else np.zeros(0, int)
        mats = np.concatenate(self._host["mat"]) if self._n else np.zeros(0, int)
        for ids, a, b, law in self._couples:
            cands = [(getattr(m, "young", 3 * m.bulk), getattr(m, "poisson", 0.5))
                     for m in ([b.material] + ([a.material] if a is not None else []))]
            if ids is None:
                ids = np.zeros(0, np.int64)
            for slot in np.unique(mats[ids]):
                if slot >= 0:
                    m = self._slots[slot][0]
                    cands.append((getattr(m, "young", 3 * m.bulk), getattr(m, "poisson", 0.5)))
            for lid in np.unique(laws[ids]):
                kn_law = getattr(self._laws[lid], "kn", None)
                if kn_law is not None:
                    cands.append((kn_law, 0.25))
            e, nu = max(cands)
            kn = law.kn if law.kn is not None else e
            ks = law.ks if law.ks is not None else kn / (2.0 * (1.0 + nu))
            rows.append((ids, a, b, law, kn, ks))
        return rows

    def particles_in(self, xmin=-np.inf, xmax=np.inf, ymin=-np.inf, ymax=np.inf,
                     zmin=None, zmax=None):
        """Indices of the particles whose centres lie in the box (now); zmin and zmax
        in 3D."""
        bounds = dict(xmin=xmin, xmax=xmax, ymin=ymin, ymax=ymax, zmin=zmin, zmax=zmax)
        if self.dim == 2:
            for name in ("zmin", "zmax"):
                if bounds[name] is not None:
                    raise InputError(f"{name}: a 2D simulation has no z axis "
                                     f"(got {name}={bounds[name]!r})")
        bounds["zmin"] = -np.inf if zmin is None else zmin
        bounds["zmax"] = np.inf if zmax is None else zmax
        for name, v in bounds.items():
            try:
                bad = math.isnan(float(v))
            except (TypeError, ValueError):
                bad = True
            if bad:
                raise InputError(f"{name} must be a number, got {v!r}")
        if self._n == 0:
            return np.zeros(0, np.int64)
        pos = self._a["pos"].to_numpy() if self._built else np.concatenate(self._host["pos"])
        return _in_box(pos, **bounds)

    def set_contact(self, group_a, group_b, contact):
        """Use ``contact`` between particles of two groups (default: the law of the group
        added later; between spheres and polyhedra the polyhedra's VolumeContact)."""
        la = self._law_id(group_a.contact, "group_a")
        lb = self._law_id(group_b.contact, "group_b")
        law = self._law_id(contact)
        self._pair_override[(la, lb)] = law
        self._pair_override[(lb, la)] = law
        if self._built:
            self._upload_laws()

    def add_wall(self, p0, p1, contact=None, velocity=(0.0, 0.0), angular_velocity=0.0,
                 center=None):
        """Add a rigid segment from p0 to p1; it moves with ``velocity`` and rotates at
        ``angular_velocity`` (rad/s) about ``center`` (default: its midpoint)."""
        if self.dim == 3:
            raise InputError("add_wall adds a 2D segment; a 3D simulation takes triangle "
                             "meshes: sim.add_mesh(vertices, triangles, contact=...) (planes, "
                             "boxes and cylinders: tdem.surfaces)")
        a, b = _vector2("p0", p0), _vector2("p1", p1)
        if np.allclose(a, b):
            raise InputError(f"p1 must differ from p0, got p0={a.tolist()} p1={b.tolist()}")
        if contact is None:
            raise InputError("contact must be given: a law such as tdem.LinearContact(kn=...)")
        v = _vector2("velocity", velocity)
        c = 0.5 * (a + b) if center is None else _vector2("center", center)
        w = float(angular_velocity)
        if not math.isfinite(w):
            raise InputError(f"angular_velocity must be finite, got {angular_velocity!r}")
        law = self._law_id(contact)
        row = np.zeros(stepk.WALL_WIDTH)
        row[:stepk.W_INVLL + 1] = [a[0], a[1], b[0], b[1], v[0], v[1], w, c[0], c[1], law,
                                   1.0 / float(np.dot(b - a, b - a))]
        if self._built:
            state = self._download()
            self._walls_host.append(row)
            self._rebuild_from(state)
        else:
            self._walls_host.append(row)
        return Wall(self, len(self._walls_host) - 1)

    def add_mesh(self, vertices, triangles=None, contact=None, velocity=(0.0, 0.0, 0.0),
                 angular_velocity=(0.0, 0.0, 0.0), center=None):
        """3D: add a rigid triangle-mesh wall; returns a :class:`tdem.handles.Mesh`.

        ``vertices`` (V, 3) and ``triangles`` (T, 3) vertex indices, or ``vertices`` the
        path of a file meshio reads (STL, OBJ, …) and ``triangles`` None. The mesh
        translates at ``velocity`` and turns at ``angular_velocity`` (rad/s, a
        3-vector) about ``center`` (default: the vertices' centroid). Spheres meet its
        faces, edges and vertices (:mod:`physics.geometry.sphere_triangle`)."""
        if self.dim != 3:
            raise InputError("add_mesh is 3D: use tdem.Simulation(dim=3); a 2D simulation "
                             "takes segment walls (add_wall)")
        if isinstance(vertices, (str, bytes)) or hasattr(vertices, "__fspath__"):
            if triangles is not None:
                raise InputError("triangles: give a file or arrays, not both (got a file and "
                                 f"triangles of type {type(triangles).__name__})")
            from .surfaces import read
            vertices, triangles = read(vertices)
        try:
            v = np.asarray(vertices, dtype=float)
        except (TypeError, ValueError):
            raise InputError(f"vertices must be a (V, 3) array of numbers, got "
                             f"{vertices!r}") from None
        if v.ndim != 2 or v.shape[1] != 3 or len(v) < 3 or not np.isfinite(v).all():
            raise InputError(f"vertices must be a finite (V, 3) array with V >= 3, got shape "
                             f"{v.shape}")
        try:
            t = np.asarray(triangles)
        except (TypeError, ValueError):
            t = np.zeros((0,))
        if t.ndim != 2 or t.shape[1] != 3 or len(t) == 0 or t.dtype.kind not in "iu":
            raise InputError(f"triangles must be a (T, 3) array of vertex indices, got "
                             f"{triangles!r:.80}")
        if t.min() < 0 or t.max() >= len(v):
            raise InputError(f"triangles: vertex indices must lie in [0, {len(v) - 1}], got "
                             f"{int(t.min())}..{int(t.max())}")
        a, b, c = v[t[:, 0]], v[t[:, 1]], v[t[:, 2]]
        area2 = np.linalg.norm(np.cross(b - a, c - a), axis=1)
        scale = float(np.ptp(v, axis=0).max())
        bad = ~(area2 > 1e-12 * scale * scale)
        if bad.any():
            k = int(np.argmax(bad))
            raise InputError(f"triangles: triangle {k} {t[k].tolist()} has no area (its "
                             f"corners are in line)")
        if contact is None:
            raise InputError("contact must be given: a law such as tdem.HertzMindlin(...)")
        vel = _vector2("velocity", velocity, 3)
        om = _vector2("angular_velocity", angular_velocity, 3)
        cen = v.mean(axis=0) if center is None else _vector2("center", center, 3)
        law = self._law_id(contact)
        rows = np.zeros((len(t), stepk.TRI_WIDTH))
        rows[:, stepk.T_AX:stepk.T_AX + 3] = a
        rows[:, stepk.T_BX:stepk.T_BX + 3] = b
        rows[:, stepk.T_CX:stepk.T_CX + 3] = c
        rows[:, stepk.T_VX:stepk.T_VX + 3] = vel
        rows[:, stepk.T_WX:stepk.T_WX + 3] = om
        rows[:, stepk.T_OX:stepk.T_OX + 3] = cen
        rows[:, stepk.T_LAW] = law
        rows[:, stepk.T_MESH] = len(self._meshes)
        state = self._download() if self._built else None
        self._meshes.append((len(self._walls_host), len(t)))
        self._walls_host.extend(rows)
        if state is not None:
            self._rebuild_from(state)
        return Mesh(self, len(self._meshes) - 1)

    @property
    def meshes(self):
        """The mesh walls (3D), in the order added."""
        return [Mesh(self, k) for k in range(len(self._meshes))]

    def add_plane(self, point, normal, contact=None, velocity=(0.0, 0.0, 0.0)):
        """3D: add an infinite plane wall through ``point`` (3 numbers) with the unit
        of ``normal`` pointing to the side the particles are on (LIGGGHTS' ``primitive
        type xplane`` and the like, at any orientation); returns a
        :class:`tdem.handles.Primitive`. No triangles: each sphere meets it as it would
        a mesh face (:mod:`tdem.primitives`), with the law ``contact``. The plane
        translates at ``velocity`` (m/s; :meth:`tdem.handles.Primitive.motion` for a
        function of time): a piston or a lid. Spheres only (no ellipsoids or
        polyhedra)."""
        self._primitive_check("add_plane", contact)
        row = _prims.plane_row(point, normal, 0, velocity)
        return self._add_primitive(row, contact)

    def add_cylinder(self, center, axis, radius, contact=None, inside=True,
                     velocity=(0.0, 0.0, 0.0)):
        """3D: add an infinite circular cylinder wall of ``radius`` about the line
        through ``center`` along ``axis`` (LIGGGHTS' ``primitive type zcylinder``, at
        any orientation); returns a :class:`tdem.handles.Primitive`. The particles are
        inside it (``inside=True``: a drum, a silo) or outside (a post). It has no ends
        (close it with :meth:`add_plane`). Same contact as :meth:`add_plane`; it
        translates at ``velocity``. Spheres only."""
        self._primitive_check("add_cylinder", contact)
        row = _prims.cylinder_row(center, axis, radius, inside, 0, velocity)
        return self._add_primitive(row, contact)

    def _primitive_check(self, what, contact):
        if self.dim != 3:
            raise InputError(f"{what} is 3D: use tdem.Simulation(dim=3); a 2D simulation "
                             "takes segment walls (add_wall)")
        if (self._n and self._has_shapes) or any(ins.shape is not None
                                                 for ins in self._inserters):
            raise InputError(f"{what}: primitive walls take spheres only; this model has "
                             "shaped particles (ellipsoids or polyhedra): use a mesh wall "
                             "(add_mesh with tdem.surfaces.plane)")
        if contact is None:
            raise InputError("contact must be given: a law such as tdem.HertzMindlin(...)")
        if isinstance(contact, VolumeContact):
            raise InputError(f"contact: {contact!r} is the polyhedra's overlap-volume law; "
                             "primitive walls take the spheres' laws")

    def _add_primitive(self, row, contact):
        row[_prims.PR_LAW] = self._law_id(contact)
        state = self._download() if self._built else None
        self._prims_host.append(row)
        if state is not None:
            self._rebuild_from(state)
        return Primitive(self, len(self._prims_host) - 1)

    @property
    def primitives(self):
        """The primitive walls (3D planes and cylinders), in the order added."""
        return [Primitive(self, k) for k in range(len(self._prims_host))]

    def _refuse_2d_only(self, **given):
        """In 3D, refuse the arguments of 2D-only features, naming the first given."""
        for name, v in given.items():
            if v is not None:
                raise InputError(f"{name}: a 2D feature (PCMM bodies, blocks, superellipses "
                                 f"and segment walls are 2D); a 3D simulation takes spheres, "
                                 f"ellipsoids, polyhedra and mesh walls (got {name}={v!r})")

    @property
    def walls(self):
        return [Wall(self, k) for k in range(len(self._walls_host))] if self.dim == 2 else []

    def insert(self, box=None, sphere=None, polygon=None, rate=None, count=None, per_s=None,
               radius=None, grading=None, density=2500.0, contact=None, velocity=None,
               shape=None, orientation="random", until=None, seed=0, every=None):
        """Insert particles during the run (pouring, pluviation, a feed): placed at
        random, without overlapping any particle, in a region — ``box`` (two corners;
        an axis of zero width makes it a plane: pluviation), ``sphere`` (centre,
        radius; a circle in 2D) or ``polygon`` (2D) — at ``rate`` kg/s (2D: kg/s per
        metre of thickness) or ``per_s`` particles/s from the time of this call, and/or
        up to ``count`` particles (``count`` alone: all of them, as soon as there is
        room), until the time ``until`` (s; None: no end). Their size: ``radius``, a
        ``grading`` (:func:`tdem.grading`: drawn by mass) or a ``shape`` (turned at
        random unless ``orientation=None``); ``density``, ``contact`` (a law) and
        ``velocity`` (their initial velocity) as for :meth:`add_particles`; ``seed``
        makes the draws repeatable.

        Particles are placed between run segments (every ``check_interval`` steps):
        those due by the end of the coming segment; with ``every`` (s), a batch every
        that long, holding what is due until the next (each placement rebuilds the
        engine's arrays: about 1.5 s for 100,000 spheres on 2 cores, so a large model
        is fed in fewer, larger batches). The region should be clear of
        walls. A particle that finds no room waits (a warning says so once). Returns an
        :class:`tdem.flows.Inserter` (``mass``, ``count``, ``ids``, ``times``,
        ``stop()``). Models with PCMM bodies or blocks take none."""
        from .flows import Inserter, Region
        self._refuse_flows("insert")
        if shape is not None and self.dim == 3 and self._prims_host:
            raise InputError(f"shape: primitive walls (add_plane, add_cylinder) take "
                             f"spheres only; got shape={shape!r}")
        region = Region(self.dim, box=box, sphere=sphere, polygon=polygon)
        ins = Inserter(self, region, rate=rate, count=count, per_s=per_s, radius=radius,
                       grading=grading, density=density, contact=contact, velocity=velocity,
                       shape=shape, orientation=orientation, until=until, seed=seed,
                       every=every)
        if shape is not None:
            self._check_polyhedral(shape, contact)
        self._inserters.append(ins)
        self._crit_cache = None
        return ins

    def remove_in(self, box=None, sphere=None, polygon=None, every=None, name=None):
        """An outlet: the particles whose centres lie in the region — ``box`` (two
        corners), ``sphere`` (centre, radius; a circle in 2D) or ``polygon`` (2D) — are
        removed, every ``every`` steps (default: every ``check_interval`` steps, when
        the engine looks at the device), and counted. Returns an
        :class:`tdem.flows.Outlet`: ``count`` and ``mass`` removed so far, ``ids``,
        ``times`` and ``masses`` of each, ``rate(window)`` the mass flow. ``name``:
        a monitor of that name records (count, mass) at each check. Particles with
        prescribed velocities or applied loads are never removed; the others keep
        their identities (``particles.numpy()["id"]``). Models with PCMM bodies or
        blocks take none."""
        from .flows import Outlet, Region
        self._refuse_flows("remove_in")
        region = Region(self.dim, box=box, sphere=sphere, polygon=polygon)
        out = Outlet(self, region, every=every, name=name)
        if name is not None:
            self.monitor(name, lambda sim, o=out: (o.count, o.mass), every=self.check_interval)
        self._outlets.append(out)
        return out

    def bond(self, group, law, other=None, gap=0.0):
        """Bond the particles of ``group`` (indices, a group or a mask) whose surfaces
        are at most ``gap`` (m) apart — overlapping ones too — with ``law`` (a
        :class:`tdem.ParallelBond`, or a :class:`tdem.LiquidBridge`: wet grains); with
        ``other``, only pairs of one particle from each. A bond acts in parallel with the particles' contact law until it breaks
        (:mod:`physics.parallel_bond`); it then leaves ``sim.bonds`` for
        ``sim.cracks``. Bonds are carried through neighbour rebuilds, growth,
        snapshots, replay, insertion, outlets and checkpoints. Returns the number of
        bonds made. Discs and spheres only; not across periodic boundaries, nor between
        PCMM particles."""
        from physics.liquid_bridge import LiquidBridge
        from physics.parallel_bond import ParallelBond
        from .bonds import BS_WIDTH, pairs_within
        if not isinstance(law, (ParallelBond, LiquidBridge)):
            raise InputError(f"law must be a tdem.ParallelBond(...) or a "
                             f"tdem.LiquidBridge(...), got {law!r}")
        g = non_negative("gap", gap)
        ids_a = indices("group", group, self._n)
        ids_b = None if other is None else indices("other", other, self._n)
        if len(ids_a) == 0 or (ids_b is not None and len(ids_b) == 0):
            raise InputError("group: no particles to bond")
        if any(p is not None for p in self._periodic):
            raise InputError("bond: bonds do not cross periodic boundaries; a periodic "
                             "model takes none")
        if self._n and (np.concatenate(self._host["mat"])[
                np.concatenate([ids_a] + ([] if ids_b is None else [ids_b]))] >= 0).any():
            raise InputError("group: PCMM particles are joined by their elements; bonds "
                             "are for plain particles")
        shp = np.concatenate(self._host["shape"])[
            np.concatenate([ids_a] + ([] if ids_b is None else [ids_b]))]
        if (shp[:, 2] > 0 if self.dim == 2 else shp[:, 3] != 0).any():
            raise InputError("group: bonds join discs and spheres; shaped particles "
                             "(superellipses, ellipsoids, polyhedra) take none")
        if self._built:
            state = self._download()
            pos, rad = state["pos"], state["prop"][:, 0]
        else:
            state = None
            pos, rad = np.concatenate(self._host["pos"]), np.concatenate(self._host["radius"])
        i, j, d0 = pairs_within(pos, rad, ids_a, ids_b, g)
        if len(i) == 0:
            return 0
        rows = {"bpair": np.stack([i, j], 1).astype(np.int32),
                "bprop": law.properties(rad[i], rad[j], d0, self.dim),
                "bstate": np.zeros((len(i), BS_WIDTH))}
        if isinstance(law, LiquidBridge):
            # its force and potential energy (−U) now; the energy its making releases
            from physics.liquid_bridge import potential
            from physics.parallel_bond import BP_CAP_F0, BP_CAP_K, BP_RUPTURE
            from .bonds import BS_FN, BS_MADE, BS_POT
            p = rows["bprop"]
            gap0 = d0 - rad[i] - rad[j]
            u0 = potential(gap0, p[:, BP_CAP_F0], p[:, BP_CAP_K], p[:, BP_RUPTURE])
            x = p[:, BP_CAP_K] * np.maximum(gap0, 0.0)
            rows["bstate"][:, BS_FN] = -p[:, BP_CAP_F0] / (1.0 + 2.1 * x + 10.0 * x * x)
            rows["bstate"][:, BS_MADE] = u0
            rows["bstate"][:, BS_POT] = -u0
        old = self._nbonds
        src = state if state is not None else self._bond_host
        for k, v in rows.items():
            have = np.asarray(src[k])[:old] if old else v[:0]
            rows[k] = np.concatenate([have, v])
        self._nbonds = old + len(i)
        self._crit_cache = None
        if state is not None:
            state.update(rows)
            self._rebuild_from(state)
        else:
            self._bond_host = rows
        return len(i)

    def _refuse_flows(self, what):
        if self._slots or self._blocks:
            raise InputError(f"{what}: models with PCMM bodies or blocks cannot gain or "
                             f"lose particles during a run (their elements join particles "
                             f"by index)")

    def _particles_near(self, lo, hi):
        """Positions and radii (bounding) of the particles whose spheres reach into the
        box [lo, hi] grown by the largest radius."""
        if not self._n:
            return np.zeros((0, self.dim)), np.zeros(0)
        if self._built:
            x = self._a["pos"].to_numpy()
            r = self._a["prop"].to_numpy()[:, 0]
        else:
            x = np.concatenate(self._host["pos"])
            r = np.concatenate(self._host["radius"])
        pad = float(r.max()) * 2.0
        sel = np.all((x >= np.asarray(lo) - pad) & (x <= np.asarray(hi) + pad), axis=1)
        return x[sel], r[sel]

    def _held_rows(self):
        """Rows with prescribed velocities or applied loads (outlets leave them)."""
        parts = [np.asarray(ids) for ids, *_ in self._fixes + self._loads]
        return np.unique(np.concatenate(parts)) if parts else np.zeros(0, np.int64)

    def _flow_events(self, t_end):
        """Between run segments: outlets remove what is inside them, inserters place
        what is due by ``t_end``; the arrays are rebuilt once for both."""
        from .flows import close_account, compact
        state = before = None
        if self._built and self._n:
            found = [(out, out.find()) for out in self._outlets if out.due(self._steps)]
            rows = np.concatenate([r for _, r in found]) if found else np.zeros(0, np.int64)
            if len(rows):
                owner = np.concatenate([np.full(len(r), k) for k, (_, r) in enumerate(found)])
                rows, first = np.unique(rows, return_index=True)
                owner = owner[first]
                if len(rows) >= self._n:
                    # (the engine's arrays keep one particle)
                    rows, owner = rows[:-1], owner[:-1]
                if len(rows):
                    ids, masses, state, before = compact(self, rows)
                    for k, (out, _) in enumerate(found):
                        sel = owner == k
                        if sel.any():
                            out.record(ids[sel], self._time, masses[sel])
        batches = [(ins, ins.batch(t_end)) for ins in self._inserters]
        batches = [(ins, got) for ins, got in batches if got is not None]
        if batches and self._built and state is None:
            state = self._download()
        self._pending_state = state
        self._pending_new = []
        ke_in = 0.0
        try:
            for ins, (x, r, turn, mass) in batches:
                kw = dict(density=ins.density, contact=ins.contact, velocity=ins.velocity)
                if ins.shape is None:
                    kw["radius"] = r
                else:
                    kw["shape"] = ins.shape
                    if turn is not None:
                        kw["orientation" if self.dim == 3 else "angle"] = turn
                self._placed_clear = True
                try:
                    g = self.add_particles(x, **kw)
                finally:
                    self._placed_clear = False
                if not self._merge_last_groups(ins):
                    ins.group = g
                ins.record(self._host["ident"][-1][-len(r):], self._time, mass)
                inflow, ke = self._inflow_energy(x, r, ins)
                self._flow_offsets["inflow"] = self._flow_offsets.get("inflow", 0.0) + inflow
                ke_in += ke
        finally:
            self._pending_state = None
            new, self._pending_new = self._pending_new, []
        if state is not None:
            self._rebuild_from(state, new_particles=tuple(
                np.concatenate([np.broadcast_to(b[k], (len(b[2]),) + np.shape(b[k])[1:])
                                if np.ndim(b[k]) == 0 else b[k] for b in new])
                for k in range(8)) if new else None)
        if before is not None:
            close_account(self, before, ke_in=ke_in)

    def _merge_last_groups(self, ins):
        """An inserter's batches make one group while nothing else is added between."""
        if ins.group is None or len(self._groups) < 2 or self._groups[-2] is not ins.group:
            return False
        new = self._groups.pop()
        ins.group.ids = np.concatenate([ins.group.ids, new.ids])
        for k in self._host:
            last = self._host[k].pop()
            self._host[k][-1] = np.concatenate([self._host[k][-1], last])
        return True

    def _inflow_energy(self, x, r, ins):
        """(Kinetic and gravitational energy the inserted particles bring, ½ M v² −
        Σ m g·x, and the kinetic part alone): they start without spin and contacts."""
        m = np.array([ins._mass_of(ri) for ri in r])
        g = np.asarray(self.gravity, float)[:self.dim]
        ke = float(0.5 * m.sum() * ins.velocity @ ins.velocity)
        return ke - float(np.sum(m * (x @ g))), ke

    def fix_particles(self, ids, vx=0.0, vy=None, omega=None, vz=None):
        """Prescribe velocity components of particles ``ids``.

        Each of vx, vy, omega (and vz in 3D) is None (free), a float, an array (one per
        id) or a function of time returning either; in 3D omega is None or a constant
        3-vector.
        """
        ids = indices("ids", ids, self._n)
        if self.dim == 2:
            if vz is not None:
                raise InputError(f"vz: a 2D simulation has no z axis (got vz={vz!r})")
            vals = [_fix_value(name, v, ids)
                    for name, v in (("vx", vx), ("vy", vy), ("omega", omega))]
        else:
            vals = [_fix_value(name, v, ids) for name, v in (("vx", vx), ("vy", vy), ("vz", vz))]
            vals.append(None if omega is None else _vector2("omega", omega, 3))
        self._fixes.append((ids, *vals))
        if self._built:
            self._apply_fixes(initial=True)

    def apply_force(self, ids, fx=None, fy=None, moment=None, fz=None):
        """Apply forces and moments to particles ``ids``: in 2D forces in N per metre of
        thickness and moments in N·m/m, in 3D N and N·m. Each of fx, fy (and fz in 3D)
        is None, a float, an array (one per id) or a function of time returning either;
        a 2D moment likewise, a 3D moment a 3-vector (for every id), an (n, 3) array or
        a function of time returning either. Loads add up over calls and count in the
        work account (``sim.work()["applied"]``). Blocks have :meth:`Block.apply_force`
        and :meth:`Block.apply_pressure`."""
        ids = indices("ids", ids, self._n)
        if self.dim == 3:
            vals = [_fix_value(name, v, ids) for name, v in (("fx", fx), ("fy", fy), ("fz", fz))]
            vals.append(_moment3(moment, ids))
        else:
            if fz is not None:
                raise InputError(f"fz: a 2D simulation has no z axis (got fz={fz!r})")
            vals = [_fix_value(name, v, ids)
                    for name, v in (("fx", fx), ("fy", fy), ("moment", moment))]
        self._loads.append((ids, *vals))
        if self._built:
            try:
                self._apply_loads(initial=True)   # (functions of time tried at once)
            except Exception:
                self._loads.pop()                 # (nothing was uploaded)
                raise
        self._loads_on = True

    # ------------------------------------------------------------- properties
    @property
    def time(self):
        return self._time

    @property
    def steps(self):
        return self._steps

    @property
    def dt(self):
        if self._dt_user is not None:
            return self._dt_user
        return self.dt_fraction * self.critical_dt()

    @dt.setter
    def dt(self, value):
        if value is None:
            self._dt_user = None
            return
        self._dt_user = self._check_dt_value(value)

    def _check_dt_value(self, value):
        try:
            v = float(value)
        except (TypeError, ValueError):
            raise InputError(f"dt must be a positive number, got {value!r}") from None
        if not (v > 0 and math.isfinite(v)):
            raise InputError(f"dt must be a positive number, got {value!r}")
        if self._n:
            crit = self.critical_dt()
            if v > crit:
                raise InputError(f"dt={v!r} is larger than the critical time step "
                                 f"{crit:.6g} s (2·sqrt(m/k)); use dt <= {crit:.6g}")
        return v

    @property
    def skin(self):
        """Verlet skin (m): the given one, else 0.4 × the smallest radius."""
        if self._skin_user is not None:
            return self._skin_user
        if self._n == 0:
            return 0.0
        if self._skin_auto is None or self._skin_auto[0] != self._n:
            r = self._radii()
            self._skin_auto = (self._n, 0.4 * float(r.min()) if len(r) else 0.0)
        return self._skin_auto[1]

    def _radii(self):
        if self._built:
            return self._a["prop"].to_numpy()[:, 0]
        return np.concatenate(self._host["radius"]) if self._host["radius"] else np.zeros(0)

    def critical_dt(self):
        """Smallest 2·sqrt(m/k) over particles and the laws each one can meet (C&S p. 54),
        and, with continua, the shortest element altitude / c_p (PCMM elements in the
        initial configuration, block triangles)."""
        key = (self._n, len(self._laws), len(self._walls_host), len(self._pair_override),
               sum(not ins.done for ins in self._inserters), self._nbonds,
               len(self._prims_host))
        if self._crit_cache is None or self._crit_cache[0] != key:
            self._crit_cache = (key, self._critical_dt())
        return self._crit_cache[1]

    def _critical_dt(self):
        if self._slots:
            self._require_built()
        crit = self._cont.critical_dt() if self._cont is not None else np.inf
        for ids, a, b, law, kn, ks in (self._couple_rows() if self._couples else []):
            nmass = self._cont.a["nmass"].to_numpy()
            m = min(float(nmass[o._offset:o._offset + len(o)].min())
                    for o in ([b] if a is None else [a, b]))
            if len(ids):
                m = min(m, float(self._a["prop"].to_numpy()[ids, 1].min()))
            crit = min(crit, 2.0 * math.sqrt(m / max(kn, ks)))
        for r, m, law in self._inserted_probes():
            crit = min(crit, float(np.min(2.0 * np.sqrt(m / law.critical_stiffness(r, m)))))
        if self._n == 0:
            if self._blocks or self._inserters:
                return crit
            raise InputError("the critical time step needs particles: add some first")
        r, m, plaw = self._masses()
        crit = min(crit, self._bond_critical_dt(r, m))
        shaped = self._shaped_mask()
        inertia = self._inertias() if shaped.any() else None
        for sel, law in self._laws_met(plaw):
            k = law.critical_stiffness(r[sel], m[sel])
            crit = min(crit, float(np.min(2.0 * np.sqrt(m[sel] / k))))
            if inertia is not None and (sel & shaped).any():
                # a shape also turns under a contact force: its contact point moves as a
                # mass m* = 1/(1/m + r_b²/I), which is below both m and the I/r_b² of
                # Miyata et al.'s 2·sqrt(I/(k r_b²)): 2·sqrt(m*/k) bounds both
                rot = sel & shaped
                kr = law.critical_stiffness(r[rot], m[rot])
                mstar = 1.0 / (1.0 / m[rot] + r[rot] ** 2 / inertia[rot])
                crit = min(crit, float(np.min(2.0 * np.sqrt(mstar / kr))))
        return crit

    def _shaped_mask(self):
        if not self._n:
            return np.zeros(0, bool)
        return np.concatenate(self._host["shape"])[:, 2] > 0

    def _inertias(self):
        if self._built:
            return self._a["prop"].to_numpy()[:, 2]
        return mass_properties(np.concatenate(self._host["shape"]),
                               np.concatenate(self._host["density"]), self._radii(),
                               self.dim, self._polys)[1]

    def _bond_critical_dt(self, r, m):
        """2·sqrt(m/k) of each bond: its axial and shear springs on the lighter
        particle, its bending spring (with the shear spring's moment at the radius) on
        that particle's inertia (the discs' and spheres' 0.5 and 0.4 m R²)."""
        if not self._nbonds:
            return np.inf
        from physics.parallel_bond import (BP_CAP_F0, BP_CAP_K, BP_KN_A, BP_KN_I, BP_KS_A,
                                           BP_TYPE)
        src = self._a if self._built else None
        pair = (src["bpair"].to_numpy() if src else self._bond_host["bpair"])[:self._nbonds]
        prop = (src["bprop"].to_numpy() if src else self._bond_host["bprop"])[:self._nbonds]
        i, j = pair[:, 0], pair[:, 1]
        bridge = prop[:, BP_TYPE] == 1.0
        crit = np.inf
        if bridge.any():
            # a liquid bridge's stiffness: its force's steepest slope, 2.1 F₀ k
            kb = 2.1 * prop[bridge, BP_CAP_F0] * prop[bridge, BP_CAP_K]
            ib, jb = i[bridge], j[bridge]
            ok = ib >= 0
            if ok.any():
                mb = np.minimum(m[ib[ok]], m[jb[ok]])
                crit = float(np.min(2.0 * np.sqrt(mb / kb[ok])))
        i, j, prop = i[~bridge], j[~bridge], prop[~bridge]
        ok = i >= 0
        i, j, prop = i[ok], j[ok], prop[ok]
        if not len(i):
            return crit
        mm = np.minimum(m[i], m[j])
        rr = np.minimum(r[i], r[j])
        k = np.maximum(prop[:, BP_KN_A], prop[:, BP_KS_A])
        share = 0.5 if self.dim == 2 else 0.4
        krot = prop[:, BP_KN_I] + prop[:, BP_KS_A] * rr ** 2
        # a particle held by several bonds: the springs add; bounded by the bond count
        count = np.bincount(np.concatenate([i, j]), minlength=len(m))
        many = np.maximum(count[i], count[j])
        return float(min(crit, np.min(2.0 * np.sqrt(mm / (k * many))),
                         np.min(2.0 * np.sqrt(share * mm * rr ** 2 / (krot * many)))))

    def _inserted_probes(self):
        """(radii, masses, law) of the smallest and largest particle each inserter that
        is still at work will bring, with every law it may meet (its own, the walls',
        the other particles'): the time step holds for what is yet to come."""
        laws = set(range(len(self._laws)))
        for ins in self._inserters:
            if ins.done:
                continue
            r = np.array(ins.sizes, dtype=float)
            m = np.array([ins._mass_of(x) for x in r])
            for u in sorted(laws):
                yield r, m, self._laws[u]

    def _masses(self):
        """(radius, mass, law group) of every particle, from the device once built."""
        r = self._radii()
        if self._built:
            return r, self._a["prop"].to_numpy()[:, 1], self._a["plaw"].to_numpy()
        m = mass_properties(np.concatenate(self._host["shape"]),
                            np.concatenate(self._host["density"]), r, self.dim,
                            self._polys)[0]
        return r, m, np.concatenate(self._host["law"])

    def _laws_met(self, plaw):
        """(particles, law) for each law group present and each law its particles
        can meet (other groups' and walls')."""
        table = self._law_table()
        # (the law's column of a segment wall's row in 2D, of a mesh triangle's in 3D)
        col = stepk.W_LAW if self.dim == 2 else stepk.T_LAW
        wall_laws = {int(w[col]) for w in self._walls_host}
        wall_laws |= {int(w[_prims.PR_LAW]) for w in self._prims_host}
        present = np.unique(plaw)
        for law_id in present:
            sel = plaw == law_id
            for u in sorted({int(table[law_id, other]) for other in present} | wall_laws):
                yield sel, self._laws[u]

    def stable_dt(self):
        """The stable time step of a dense (hexagonal) packing of these particles: the
        smallest over particles and the laws each can meet of 2/ω_max of the
        hexagonal lattice of discs of its mass with the law's normal, shear and
        rolling springs (:mod:`physics.stability`). :meth:`critical_dt` is that of
        one contact (C&S); a particle with six contacts and shear springs as stiff as
        the normal ones is stable only up to 0.20 of it. A run whose step exceeds
        this one warns (a dense packing would go unstable). Plain DEM particles only
        (PCMM particles are held by their elements, whose bound is in
        :meth:`critical_dt`)."""
        out = math.inf
        for r, m, law in self._inserted_probes():
            kn, ks = law.critical_stiffnesses(r, m)
            kn = np.broadcast_to(np.asarray(kn, dtype=float), r.shape)
            ks = np.broadcast_to(np.asarray(ks, dtype=float), r.shape)
            roll = law.rolling.delta ** 2 / 12.0 if law.rolling is not None else 0.0
            out = min(out, float(np.min(_stability.stable_dt(kn, ks, m, roll))))
        if self._n == 0:
            return out
        r, m, plaw = self._masses()
        dem = np.concatenate(self._host["mat"]) < 0       # PCMM particles: elements
        for sel, law in self._laws_met(plaw):
            sel = sel & dem
            if not sel.any():
                continue
            kn, ks = law.critical_stiffnesses(r[sel], m[sel])
            kn = np.broadcast_to(np.asarray(kn, dtype=float), r[sel].shape)
            ks = np.broadcast_to(np.asarray(ks, dtype=float), r[sel].shape)
            roll = law.rolling.delta ** 2 / 12.0 if law.rolling is not None else 0.0
            out = min(out, float(np.min(_stability.stable_dt(kn, ks, m[sel], roll))))
        return out

    # ------------------------------------------------ monitors, output, checkpoints
    def monitor(self, name, fn, every=100):
        """Record ``fn(sim)`` (a number or an array) every ``every`` steps under ``name``.

        Histories are in :meth:`histories` and in ``monitors.h5`` when output is on.
        """
        from .io import Monitor
        if any(m.name == name for m in self._monitors):
            raise InputError(f"name: a monitor called {name!r} exists already")
        m = Monitor(name, fn, every, start=self._steps)
        self._monitors.append(m)
        return m

    def histories(self):
        """{name: (times (K,), values (K, ...))} of every monitor."""
        return {m.name: m.arrays() for m in self._monitors}

    def output(self, directory, every=None, interval=None, contacts=True, walls=True,
               checkpoint_on_abort=True):
        """Write a VTU series (``.pvd`` index) every ``every`` steps or ``interval``
        seconds of simulated time into ``directory``, the monitors to
        ``directory/monitors.h5``; an interrupted or unstable run flushes them and
        leaves ``directory/last_good.h5``."""
        from .io import Output
        self._output = Output(directory, every=every, interval=interval, contacts=contacts,
                              walls=walls, checkpoint_on_abort=checkpoint_on_abort, sim=self)
        return self._output

    def write_vtu(self, path, walls=True, contacts=True):
        """Write one snapshot: particles to ``path``; walls and contacts beside it
        (``*_walls.vtu``, ``*_contacts.vtu``). Returns the paths written."""
        from .io import write_vtu
        return write_vtu(self, path, walls=walls, contacts=contacts)

    def save(self, path):
        """Checkpoint the whole state to HDF5; :meth:`load` restarts it exactly."""
        from .checkpoint import save
        save(self, path)

    @staticmethod
    def load(path, arch=None):
        """Rebuild a simulation from a checkpoint written by :meth:`save`."""
        from .checkpoint import load
        return load(path, arch=arch)

    @property
    def n_particles(self):
        return self._n

    @property
    def neighbour_builds(self):
        """How many times the neighbour lists have been built."""
        return int(self._a["flags"].to_numpy()[F_BUILDS]) if self._built else 0

    def __repr__(self):
        return (f"Simulation({self._n} particles, {len(self._walls_host)} walls, "
                f"t={self._time:.6g} s, step {self._steps}, arch={self.arch})")

    @property
    def nonconverged_contacts(self):
        """How many contact evaluations of shaped particles (all steps so far) stopped at
        the iteration cap before their normal converged (0 in a healthy run; a run that
        has some warns at its end)."""
        return int(self._a["flags"].to_numpy()[F_NONCONV]) if self._built and self._n else 0


def _moment3(v, ids):
    """A 3D moment of apply_force: None, a function of time (checked when the run
    evaluates it), or an (len(ids), 3) array from a 3-vector or one row per id."""
    if v is None or callable(v):
        return v
    try:
        a = np.asarray(v, dtype=float)
        a = np.broadcast_to(a, (len(ids), 3)).copy() if a.shape in ((3,), (len(ids), 3)) else None
    except (TypeError, ValueError):
        a = None
    if a is None or not np.isfinite(a).all():
        raise InputError(f"moment must be None, three finite numbers (x, y, z), {len(ids)} "
                         f"rows of three or a function of time, got {v!r}")
    return a

