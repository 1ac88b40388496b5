"""The simulation object: Python orchestrates, kernels compute.

State lives in ``ti.ndarray`` objects (structure of arrays; fixed-capacity contact
slots per particle). One time step is :func:`tdem.step.step` (forces, gather,
integration, walls) preceded, when the skin check asks for it, by
:func:`tdem.neighbors.rebuild`. The host only looks at the device every
``check_interval`` steps: it then reads the status word (slot overflow, unstable
particles), keeps a device-side snapshot of the state, records monitors and writes
output. A slot overflow restores the snapshot, grows the arrays and redoes the
steps; an instability restores the snapshot, replays step by step to name the
step and the particle, keeps the last good state and raises
:class:`tdem.InstabilityError`.
"""
import math
import sys
import time as _time

import numpy as np
import taichi as ti

from physics import contact_law as _claw
from physics.contact_law import ContactLaw
from physics.linear import LinearContact
from physics.materials import Material, MohrCoulomb

from . import backend, neighbors
from . import mesh as _mesh
from . import state as schema
from . import step as stepk
from .continuum import Continuum
from .errors import CapacityError, InputError, InstabilityError
from .neighbors import F_BAD, F_BUILDS, F_NEED, F_REBUILD, F_WALL_NEED, FLAGS_SIZE

MAX_SLOTS = 1024

# the engine's arrays are declared in tdem.state


def _vector2(name, value):
    """One 2-vector (gravity, a velocity, a point)."""
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be two numbers, got {value!r}") from None
    if a.shape != (2,) or not np.isfinite(a).all():
        raise InputError(f"{name} must be two finite numbers (x, y), got {value!r}")
    return a


def _as_xy(name, value, n=None):
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be numbers, got {value!r}") from None
    if n is not None and a.shape == (2,):
        a = np.broadcast_to(a, (n, 2)).copy()
    if a.ndim != 2 or a.shape[1] != 2 or (n is not None and a.shape[0] != n):
        want = f"({n}, 2)" if n is not None else "(N, 2)"
        raise InputError(f"{name} must have shape {want} or (2,), got shape {a.shape}")
    bad = ~np.isfinite(a).all(axis=1)
    if bad.any():
        k = int(np.argmax(bad))
        raise InputError(f"{name} must be finite: row {k} is {a[k].tolist()}")
    return a


class ParticleGroup:
    """Particles added by one call of :meth:`Simulation.add_particles`."""

    def __init__(self, sim, ids, contact, density):
        self._sim = sim
        self.ids = ids
        self.contact = contact
        self.density = density

    def __len__(self):
        return len(self.ids)

    def __repr__(self):
        return f"ParticleGroup({len(self.ids)} particles, ids {self.ids[0]}..{self.ids[-1]})"


class Block:
    """A deformable block: a triangle mesh with fixed connectivity (spec §4), made by
    :meth:`Simulation.add_block`. Its nodes carry lumped masses ρ·S/3; its
    triangles the stress (same FVM update as the PCMM elements, weight 1)."""

    def __init__(self, sim, index, vertices, triangles, material, slot, velocity):
        self._sim = sim
        self.index = index
        self.vertices = vertices
        self.triangles = triangles
        self.material = material
        self.slot = slot
        self.velocity = velocity
        self._fixes = []
        self._offset = 0
        self.rigid = False

    def __len__(self):
        return len(self.vertices)

    def __repr__(self):
        return (f"Block({len(self.vertices)} nodes, {len(self.triangles)} triangles, "
                f"{self.material!r})")

    def fix(self, nodes, vx=0.0, vy=None):
        """Prescribe velocity components of ``nodes`` (indices into the block's
        vertices): each of vx, vy is None (free), a float, an array (one per node)
        or a function of time returning either."""
        ids = np.atleast_1d(np.asarray(nodes, dtype=np.int64))
        nv = len(self.vertices)
        if ids.size == 0 or ids.min() < 0 or ids.max() >= nv:
            raise InputError(f"nodes must be vertex indices of the block in [0, {nv}), got "
                             f"{ids.tolist()[:8]}")
        vals = [_fix_value(name, v, ids) for name, v in (("vx", vx), ("vy", vy))]
        self._fixes.append((ids, *vals))
        cont = self._sim._cont
        if cont is not None:
            cont.apply_node_fixes(self._sim.time, initial=True)

    def kinematic(self):
        """Whether every node has both velocity components prescribed (the block then
        moves as told: a driven rigid tool, for instance)."""
        fx = np.zeros(len(self.vertices), bool)
        fy = np.zeros(len(self.vertices), bool)
        for ids, vx, vy in self._fixes:
            fx[ids] |= vx is not None
            fy[ids] |= vy is not None
        return bool(fx.all() and fy.all())

    def nodes(self):
        """Node state now, a dict of numpy arrays: position, velocity, force (of the
        elements and contacts), reaction (of the prescribed velocities), mass,
        displacement."""
        if self._sim._cont is None:
            x = self.vertices
            z = np.zeros_like(x)
            return {"position": x.copy(), "velocity": np.broadcast_to(self.velocity, x.shape).copy(),
                    "force": z.copy(), "reaction": z.copy(),
                    "mass": _mesh.nodal_masses(x, self.triangles, self.material.density),
                    "displacement": z.copy()}
        return self._sim._cont.block_nodes(self)

    def elements(self):
        """Triangles now: triangles (T, 3), stress (T, 2, 2), stress_zz, plastic_strain,
        failed."""
        self._sim._require_built()
        return self._sim._cont.block_elements(self)

    def nodes_in(self, xmin=-np.inf, xmax=np.inf, ymin=-np.inf, ymax=np.inf):
        """Indices of the vertices (initial positions) inside the box."""
        return _in_box(self.vertices, xmin, xmax, ymin, ymax)


def _in_box(x, xmin, xmax, ymin, ymax):
    return np.flatnonzero((x[:, 0] >= xmin) & (x[:, 0] <= xmax) &
                          (x[:, 1] >= ymin) & (x[:, 1] <= ymax))


def _fix_value(name, v, ids):
    if v is None or callable(v):
        return v
    a = np.broadcast_to(np.asarray(v, dtype=float), ids.shape).copy() \
        if np.ndim(v) <= 1 and (np.ndim(v) == 0 or len(v) == len(ids)) else None
    if a is None or not np.isfinite(a).all():
        raise InputError(f"{name} must be None, a finite number, {len(ids)} numbers "
                         f"or a function of time, got {v!r}")
    return a


class Wall:
    """A rigid segment. ``velocity`` and ``angular_velocity`` may be changed between runs."""

    def __init__(self, sim, index):
        self._sim = sim
        self.index = index

    def _row(self):
        return self._sim._wall_rows()[self.index]

    def _set(self, cols, values):
        rows = self._sim._wall_rows()
        rows[self.index, cols] = values
        self._sim._set_wall_rows(rows)

    @property
    def velocity(self):
        r = self._row()
        return np.array([r[stepk.W_VX], r[stepk.W_VY]])

    @velocity.setter
    def velocity(self, v):
        v = _vector2("velocity", v)
        self._set([stepk.W_VX, stepk.W_VY], v)

    @property
    def angular_velocity(self):
        """Angular velocity about :attr:`center`, rad/s, counter-clockwise positive."""
        return float(self._row()[stepk.W_OMEGA])

    @angular_velocity.setter
    def angular_velocity(self, w):
        w = float(w)
        if not math.isfinite(w):
            raise InputError(f"angular_velocity must be finite, got {w!r}")
        self._set([stepk.W_OMEGA], [w])

    @property
    def center(self):
        r = self._row()
        return np.array([r[stepk.W_CX], r[stepk.W_CY]])

    @property
    def endpoints(self):
        r = self._row()
        return np.array([[r[stepk.W_X0], r[stepk.W_Y0]], [r[stepk.W_X1], r[stepk.W_Y1]]])

    def servo(self, force=None, stress=None, direction=None, relaxation=0.5, max_speed=None):
        """Drive this wall so that it receives ``force`` (N per metre of thickness,
        compression-positive) — or ``stress`` × its length — along ``direction`` (the unit
        direction in which it moves to compress; default: its normal pointing to the
        particles that touch it, else to the left of p0→p1). The speed is set every step
        on the device from the force received, with a gain from the contact stiffness
        (relaxation in (0, 1]); ``max_speed`` caps it (default: 0.01 × the smallest radius
        per step). ``wall.servo()`` switches the control off and stops the wall."""
        sim = self._sim
        row = self._row()
        if force is None and stress is None:
            self._set([stepk.W_SERVO_K, stepk.W_VX, stepk.W_VY], [0.0, 0.0, 0.0])
            return self
        if (force is None) == (stress is None):
            raise InputError(f"give force or stress, not both: force={force!r}, stress={stress!r}")
        a, b = self.endpoints
        length = float(np.linalg.norm(b - a))
        target = float(force) if force is not None else float(stress) * length
        if not math.isfinite(target):
            raise InputError(f"force must be finite, got {target!r}")
        if direction is None:
            t = (b - a) / length
            d = np.array([-t[1], t[0]])
            x = sim.particles.numpy(stress=False)["position"] if sim.n_particles else None
            if x is not None and len(x):
                mid = 0.5 * (a + b)
                if np.dot(x.mean(axis=0) - mid, d) < 0:
                    d = -d
        else:
            d = _vector2("direction", direction)
            if np.linalg.norm(d) == 0:
                raise InputError(f"direction must not be zero, got {direction!r}")
            d = d / np.linalg.norm(d)
        relaxation = float(relaxation)
        if not 0.0 < relaxation <= 1.0:
            raise InputError(f"relaxation must lie in (0, 1], got {relaxation!r}")
        law = sim._laws[int(row[stepk.W_LAW])]
        r = sim._radii()
        rmean = float(r.mean()) if len(r) else 1.0
        k = law.critical_stiffness(rmean, 1.0)
        dt = sim.dt
        if max_speed is None:
            max_speed = 0.01 * float(r.min() if len(r) else 1.0) / dt
        max_speed = float(max_speed)
        if not (max_speed > 0 and math.isfinite(max_speed)):
            raise InputError(f"max_speed must be a positive number, got {max_speed!r}")
        self._set([stepk.W_SERVO_K, stepk.W_SERVO_F, stepk.W_SERVO_DX, stepk.W_SERVO_DY,
                   stepk.W_SERVO_ALPHA, stepk.W_SERVO_VMAX, stepk.W_OMEGA],
                  [k, target, d[0], d[1], relaxation, max_speed, 0.0])
        return self

    @property
    def force(self):
        """Total contact force (2,) this wall received in the last step."""
        return self._sim._wall_loads()[self.index, :2].copy()

    @property
    def moment(self):
        """Moment of the contact forces about the wall's centre in the last step."""
        return float(self._sim._wall_loads()[self.index, 2])

    def __repr__(self):
        return f"Wall({self.index}, endpoints={self.endpoints.tolist()})"


class _View:
    """``sim.particles`` / ``sim.contacts``: ``.numpy()`` gives a dict of arrays."""

    def __init__(self, fn, count):
        self._fn = fn
        self._count = count

    def numpy(self, **options):
        return self._fn(**options)

    def __len__(self):
        return self._count()


class Simulation:
    """A 2D DEM simulation (plane, unit thickness, SI units).

    Parameters
    ----------
    gravity : (2,) m/s²
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
    """

    def __init__(self, gravity=(0.0, -9.81), dt=None, dt_fraction=0.2, arch=None,
                 precision="f64", local_damping=0.0, global_damping=0.0, skin=None,
                 check_interval=100, progress=None, threads=None):
        g = _vector2("gravity", gravity)
        if precision not in ("f64", "f32"):
            raise InputError(f"precision must be 'f64' or 'f32', got {precision!r}")
        dt_fraction = float(dt_fraction)
        if not (0.0 < dt_fraction <= 1.0):
            raise InputError(f"dt_fraction must lie in (0, 1], got {dt_fraction!r}")
        for name, v in (("local_damping", local_damping), ("global_damping", global_damping)):
            if not (float(v) >= 0.0 and math.isfinite(float(v))):
                raise InputError(f"{name} must be a number >= 0, got {v!r}")
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
        self._pair_override = {}   # (law a, law b) -> law id
        self._groups = []
        self._host = {k: [] for k in ("pos", "vel", "radius", "density", "law", "mat")}
        self._slots = []           # (material, tolerance) of PCMM bodies and blocks
        self._blocks = []
        self._cont = None          # Continuum (PCMM elements, blocks) once built
        self._couples = []         # (particle ids, block, PointEdge)
        self._nonreflect = []      # ("p" | "v", ids, coef rows) of viscous boundaries
        self._lights = []          # (ids, lighting times) of JWL particles, before the build
        self._walls_host = []      # rows of the wall table
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

    def add_particles(self, positions, radius, density=2500.0, contact=None, material=None,
                      tolerance=0.0, velocity=None):
        """Add discs; returns a :class:`ParticleGroup` (``.ids`` their indices).

        With ``material`` (tdem.Elastic, MohrCoulomb, Fluid) the particles are PCMM
        particles of one continuum body: elements are created between particles of
        the same material and tolerance δ (Eq. 1: d ≤ R_i + R_j + δ), their masses
        follow Eq. 5 and ``density`` is the material's. ``contact`` then acts only
        between particles that touch but share no element (and against walls and
        other particles); by default a linear law with k_n = k_s = E (N/m per metre
        of thickness) and friction tan φ (MohrCoulomb) or 0.5.
        """
        slot = -1
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
            slot = self._slot_of(material, tol)
        elif self._built and self._cont is not None:
            raise InputError("positions: particles cannot be added after the first run of a "
                             "model with PCMM particles or blocks")
        pos = _as_xy("positions", positions)
        n = len(pos)
        if n == 0:
            raise InputError("positions must hold at least one particle, got none")
        try:
            r = np.broadcast_to(np.asarray(radius, dtype=float), (n,)).copy()
        except ValueError:
            raise InputError(f"radius must be a number or one per particle ({n}), "
                             f"got shape {np.shape(radius)}") from None
        bad = ~(np.isfinite(r) & (r > 0))
        if bad.any():
            k = int(np.argmax(bad))
            raise InputError(f"radius must be positive: particle {k} has radius {float(r[k])!r}")
        rho = np.broadcast_to(np.asarray(density, dtype=float), (n,)).copy()
        bad = ~(np.isfinite(rho) & (rho > 0))
        if bad.any():
            k = int(np.argmax(bad))
            raise InputError(f"density must be positive: particle {k} has density {float(rho[k])!r}")
        if contact is None:
            raise InputError("contact must be given: a law such as tdem.LinearContact(kn=...)")
        vel = np.zeros((n, 2)) if velocity is None else _as_xy("velocity", velocity, n)
        law = self._law_id(contact)
        state = self._download() if self._built else None
        ids = np.arange(self._n, self._n + n)
        self._host["pos"].append(pos)
        self._host["vel"].append(vel)
        self._host["radius"].append(r)
        self._host["density"].append(rho)
        self._host["law"].append(np.full(n, law))
        self._host["mat"].append(np.full(n, slot))
        self._n += n
        g = ParticleGroup(self, ids, contact, rho)
        self._groups.append(g)
        if state is not None:
            self._rebuild_from(state, new_particles=(pos, vel, r, rho, law))
        return g

    def _slot_of(self, material, tol):
        for k, (m, t) in enumerate(self._slots):
            if m is material and t == tol:
                return k
        self._slots.append((material, tol))
        return len(self._slots) - 1

    def add_block(self, vertices, triangles, material, rigid=False, velocity=(0.0, 0.0)):
        """Add a block: a triangle mesh (vertices (V, 2), counter-clockwise triangles
        (T, 3)) of a continuum material, with lumped nodal masses. ``rigid=True``: a
        rigid body (3 degrees of freedom: its mass, centre and moment of inertia from
        the lumped masses; no stress), free, or driven by fixing all its nodes.
        ``velocity``: initial velocity of every node. Returns a :class:`Block`."""
        if rigid not in (True, False):
            raise InputError(f"rigid must be True or False, got {rigid!r}")
        if not isinstance(material, Material):
            raise InputError("material must be a continuum material such as "
                             f"tdem.Elastic(...), got {material!r}")
        if self._built:
            raise InputError("vertices: blocks must be added before the first run")
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
        if not isinstance(law, PointEdge):
            raise InputError(f"law must be a tdem.PointEdge(...), got {law!r}")
        if not isinstance(b, Block) or b._sim is not self:
            raise InputError(f"b must be a block of this simulation (from add_block), got {b!r}")
        if isinstance(a, Block):
            if a._sim is not self or a is b:
                raise InputError(f"a must be another block of this simulation, got {a!r}")
            if self._built:
                raise InputError("a: couples must be set up before the first run")
            self._couples.append((None, a, b, law))
            return
        ids = a.ids if isinstance(a, ParticleGroup) else np.atleast_1d(np.asarray(a))
        ids = np.asarray(ids, dtype=np.int64)
        if ids.size == 0 or ids.min() < 0 or ids.max() >= self._n:
            raise InputError(f"a must be particles of this simulation (indices in "
                             f"[0, {self._n})), got {ids.tolist()[:8]}")
        if self._built:
            raise InputError("a: couples must be set up before the first run")
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
            nodes = bnodes if nodes is None else np.atleast_1d(np.asarray(nodes, np.int64))
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
            ids = target.ids if isinstance(target, ParticleGroup) else target
            ids = np.atleast_1d(np.asarray(ids, np.int64))
            if ids.size == 0 or ids.min() < 0 or ids.max() >= self._n:
                raise InputError(f"target must be particle indices in [0, {self._n}), a block "
                                 f"or (block, nodes), got {np.asarray(ids).tolist()[:8]}")
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
        t_l = ``time`` + |x_i − ``point``|/D (positions now) and releases its pressure
        over the next 3R/D (the burn fraction). ``target``: particle indices or a
        :class:`ParticleGroup` of JWL particles. Unlit JWL particles have no pressure.
        """
        from physics.materials import JWL
        ids = target.ids if isinstance(target, ParticleGroup) else target
        ids = np.atleast_1d(np.asarray(ids, np.int64))
        if ids.size == 0 or ids.min() < 0 or ids.max() >= self._n:
            raise InputError(f"target must be particle indices in [0, {self._n}) or a group, "
                             f"got {np.asarray(ids).tolist()[:8]}")
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

    def particles_in(self, xmin=-np.inf, xmax=np.inf, ymin=-np.inf, ymax=np.inf):
        """Indices of the particles whose centres lie in the box (now)."""
        if self._n == 0:
            return np.zeros(0, np.int64)
        pos = self._a["pos"].to_numpy() if self._built else np.concatenate(self._host["pos"])
        return _in_box(pos, xmin, xmax, ymin, ymax)

    def set_contact(self, group_a, group_b, contact):
        """Use ``contact`` between particles of two groups (default: the law of the group
        added later)."""
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

    @property
    def walls(self):
        return [Wall(self, k) for k in range(len(self._walls_host))]

    def fix_particles(self, ids, vx=0.0, vy=None, omega=None):
        """Prescribe velocity components of particles ``ids``.

        Each of vx, vy, omega is None (free), a float, an array (one per id) or a
        function of time returning either.
        """
        ids = np.atleast_1d(np.asarray(ids, dtype=np.int64))
        if ids.size == 0 or ids.min() < 0 or ids.max() >= self._n:
            raise InputError(f"ids must be particle indices in [0, {self._n}), got "
                             f"{ids.tolist()[:8]}")
        vals = [_fix_value(name, v, ids) for name, v in (("vx", vx), ("vy", vy), ("omega", omega))]
        self._fixes.append((ids, *vals))
        if self._built:
            self._apply_fixes(initial=True)

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
        key = (self._n, len(self._laws), len(self._walls_host), len(self._pair_override))
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
        if self._n == 0:
            if self._blocks:
                return crit
            raise InputError("the critical time step needs particles: add some first")
        r = self._radii()
        if self._built:
            m = self._a["prop"].to_numpy()[:, 1]
            plaw = self._a["plaw"].to_numpy()
        else:
            rho = np.concatenate(self._host["density"])
            m = rho * np.pi * r ** 2
            plaw = np.concatenate(self._host["law"])
        table = self._law_table()
        wall_laws = {int(w[stepk.W_LAW]) for w in self._walls_host}
        present = np.unique(plaw)
        for law_id in present:
            sel = plaw == law_id
            used = {int(table[law_id, other]) for other in present} | wall_laws
            k = np.zeros(int(sel.sum()))
            for u in used:
                law = self._laws[u]
                k = np.maximum(k, law.critical_stiffness(r[sel], m[sel]))
            crit = min(crit, float(np.min(2.0 * np.sqrt(m[sel] / k))))
        return crit

    def _law_table(self):
        nl = max(len(self._laws), 1)
        t = np.zeros((nl, nl), dtype=np.int32)
        for a in range(nl):
            for b in range(nl):
                t[a, b] = self._pair_override.get((a, b), max(a, b))
        return t

    # ------------------------------------------------------------ device state
    def _sizes(self, n, cap, capw, nwalls, nlaws, ncell):
        """The sizes :func:`tdem.state.allocate` takes, for this model."""
        return {"n": n, "cap": cap, "capw": capw, "walls": max(nwalls, 1), "laws": nlaws,
                "law_width": _claw.table_width(self._law_set), "cells": ncell,
                "cell_starts": ncell + 4096, "flags": FLAGS_SIZE, "simp": stepk.SIMP_SIZE,
                "wall_width": stepk.WALL_WIDTH, "laws_set": self._law_set}

    def _allocate(self, n, cap, capw, nwalls, nlaws, ncell):
        return schema.allocate(self._sizes(n, cap, capw, nwalls, nlaws, ncell), self._fdt)

    def _fresh_state(self):
        self._law_set = _claw.registered()
        pos = np.concatenate(self._host["pos"])
        vel = np.concatenate(self._host["vel"])
        r = np.concatenate(self._host["radius"])
        rho = np.concatenate(self._host["density"])
        m = rho * np.pi * r ** 2
        if self._cont is not None and self._cont.has_pcmm:
            pm = self._cont.masses
            m = np.where(np.isnan(pm), m, pm)
        n = len(r)
        s = self._new_rows(pos, vel, r, m, np.concatenate(self._host["law"]), self._cap,
                           self._capw)
        s["flags"] = np.array([1, 0, 0, n, 0, 0, 0, 0], np.int32)
        return s

    def _new_rows(self, pos, vel, r, m, law, cap, capw):
        """State rows of new particles (every saved per-particle and per-slot array)."""
        sizes = self._sizes(len(r), cap, capw, 1, 1, 1)
        return schema.fresh_rows(len(r), sizes, {
            "pos": pos, "vel": vel, "pos0": pos, "xref": pos,
            "prop": np.stack([r, m, 0.5 * m * r ** 2], axis=1),
            "plaw": np.broadcast_to(np.asarray(law, np.int32), (len(r),))})

    def _build(self):
        if self._n == 0 and not self._blocks:
            raise InputError("the simulation has no particles: call add_particles first")
        if self._slots:
            self._cont = self._new_continuum()
            for kind, ids, coef, block in self._nonreflect:
                self._cont.set_non_reflecting(
                    kind, ids + block._offset if kind == "v" else ids, coef)
            for ids, times in self._lights:
                self._cont.light(ids, times)
        if self._n == 0:
            # blocks only: no particle arrays, the engine's parameters only
            self._a = {"simp": ti.ndarray(ti.f64, (stepk.SIMP_SIZE,))}
            self._built = True
            self._upload_params()
            return
        self._rebuild_from(self._fresh_state())

    def _new_continuum(self):
        """The continuum (PCMM elements, blocks, couples) of the particles as added."""
        if self._n:
            pos = np.concatenate(self._host["pos"])
            rad = np.concatenate(self._host["radius"])
            pmat = np.concatenate(self._host["mat"]).astype(np.int64)
        else:
            pos, rad, pmat = np.zeros((0, 2)), np.zeros(0), np.zeros(0, np.int64)
        return Continuum(pos, rad, pmat, self._slots, self._blocks, couples=self._couple_rows())

    def _require_built(self):
        if not self._built:
            self._build()

    def _rebuild_from(self, state, new_particles=None):
        """(Re)allocate every array for the current sizes and fill it from ``state``."""
        self._set_law_set(state)
        if new_particles is not None:
            pos, vel, r, rho, law = new_particles
            m = rho * np.pi * r ** 2
            n = len(r)
            add = self._new_rows(pos, vel, r, m, law, state["nbr"].shape[1],
                                 state["wid"].shape[1])
            for k, v in add.items():
                state[k] = np.concatenate([state[k], v])
            state["flags"][F_REBUILD] = 1
        n = self._n
        nwalls = len(self._walls_host)
        ncell = self._grid_cells_for(state["pos"], state["prop"][:, 0])
        self._a = self._allocate(n, self._cap, self._capw, nwalls, max(len(self._laws), 1), ncell)
        self._snap = {}
        for k, v in state.items():
            if k in self._a:
                self._fill(k, v)
        self._built = True
        self._a["facc"].from_numpy(np.zeros((n, 3)))  # sums start from zero every step
        self._upload_laws()
        self._set_wall_rows(np.array(self._walls_host).reshape(-1, stepk.WALL_WIDTH), fresh=True)
        self._fit_grid(force=True)
        self._apply_fixes(initial=True)
        self._upload_params()
        self._a["flags"][F_REBUILD] = 1

    def _fill(self, k, v):
        arr = self._a[k]
        v = np.asarray(v)
        want = tuple(arr.shape) + ((arr.n,) if hasattr(arr, "n") else ())
        if v.shape != want:
            # pad or cut the slot dimension (growth of capacities)
            out = np.full(want, -1 if v.dtype.kind == "i" else 0, dtype=v.dtype)
            sl = tuple(slice(0, min(a, b)) for a, b in zip(want, v.shape))
            out[sl] = v[sl]
            v = out
        arr.from_numpy(v.astype(np.int32 if v.dtype.kind in "iu" else
                                (np.float64 if arr.dtype == ti.f64 else np.float32)))

    def _download(self):
        """Every device array as numpy; the host copy of the walls follows the device."""
        out = {k: self._a[k].to_numpy() for k in schema.saved()}
        self._walls_host = list(out["wall"][:len(self._walls_host)])
        return out

    def _set_law_set(self, state):
        """Take the contact laws registered now (the kernels' ``laws``); the history
        arrays of ``state`` get the columns these laws need."""
        self._law_set = _claw.registered()
        for k, width in (("hist", _claw.pair_history_width(self._law_set)),
                         ("whist", _claw.wall_history_width(self._law_set))):
            if k in state:
                state[k] = _claw.remap_history(state[k], width, tail=4 if k == "hist" else 3)

    def _upload_laws(self):
        width = _claw.table_width(self._law_set)
        rows = np.array([law.row(width) for law in self._laws], dtype=float)
        self._a["lawp"].from_numpy(rows)
        self._a["lawpair"].from_numpy(self._law_table())

    def _upload_params(self):
        p = np.zeros(stepk.SIMP_SIZE)
        p[stepk.P_DT] = self.dt
        p[stepk.P_GX], p[stepk.P_GY] = self.gravity
        p[stepk.P_ALPHA] = self.global_damping
        p[stepk.P_ALPHA_LOCAL] = self.local_damping
        p[stepk.P_SKIN] = self.skin
        p[stepk.P_NWALLS] = len(self._walls_host)
        self._a["simp"].from_numpy(p)
        self._dt_run = p[stepk.P_DT]

    def _wall_rows(self):
        if not self._built:
            return np.array(self._walls_host, dtype=float).reshape(-1, stepk.WALL_WIDTH)
        return self._a["wall"].to_numpy()[:len(self._walls_host)]

    def _set_wall_rows(self, rows, fresh=False):
        if not self._built:
            self._walls_host = list(rows)
            return
        full = np.zeros((max(len(rows), 1), stepk.WALL_WIDTH))
        full[:len(rows)] = rows
        self._a["wall"].from_numpy(full)
        self._walls_host = list(rows)
        self._a["flags"][F_REBUILD] = 1

    def _wall_loads(self):
        if not self._built:
            return np.zeros((len(self._walls_host), 4))
        return self._a["wforce"].to_numpy()[:len(self._walls_host)]

    def _grid_cells_for(self, pos, radius):
        h = 2.0 * float(radius.max()) + self.skin
        span = np.ptp(pos, axis=0) + 4 * h
        nx, ny = (np.ceil(span / h).astype(int) + 1)
        return int(max(nx * ny, 1))

    def _fit_grid(self, force=False):
        """Fit the cell grid to the particles' bounding box (host side, at checks)."""
        a = self._a
        neighbors.bounds(a["pos"], a["prop"], a["bounds"])
        b = a["bounds"].to_numpy()
        lo, hi, rmax = b[:2], b[2:4], b[4]
        if not np.all(np.isfinite(b)) or hi[0] < lo[0]:
            return
        h = 2.0 * rmax + self.skin
        gp = a["gridp"].to_numpy()
        gn = a["gridn"].to_numpy()
        self._last_fit = self._steps
        if not force:
            cur_lo = gp[:2]
            cur_hi = cur_lo + gp[2] * gn[:2]
            inside = np.all(lo >= cur_lo) and np.all(hi <= cur_hi)
            if inside and gp[2] >= h and np.prod((hi - lo) / gp[2] + 1) > 0.25 * gn[0] * gn[1]:
                return
        margin = 2 * h
        lo = lo - margin
        span = (hi + margin) - lo
        ncap = a["cell_count"].shape[0]
        limit = max(4 * self._n + 1024, ncap)
        nx, ny = (np.floor(span / h).astype(np.int64) + 1)
        while nx * ny > limit:
            h *= 1.5
            nx, ny = (np.floor(span / h).astype(np.int64) + 1)
        if nx * ny > ncap or ny > 4096:
            self._a["cell_count"] = ti.ndarray(ti.i32, (int(nx * ny),))
            self._a["cell_start"] = ti.ndarray(ti.i32, (int(nx * ny) + max(int(ny), 4096),))
        a["gridp"].from_numpy(np.array([lo[0], lo[1], h, 0.0]))
        a["gridn"].from_numpy(np.array([nx, ny, 0, 0], dtype=np.int32))
        a["flags"][F_REBUILD] = 1
        self._last_fit = self._steps

    def _apply_fixes(self, initial=False, t=None):
        """Upload prescribed velocities: all of them (``initial``), else only the values
        of the functions of time, evaluated at ``t``. The host keeps its own copy, so a
        step reads nothing back from the device."""
        if not self._fixes:
            return
        t = self._time if t is None else t
        if initial:
            fix = np.zeros(self._n, np.int32)
            self._vfix_host = np.zeros((self._n, 3))
        vfix = self._vfix_host
        any_fn = False
        for ids, *vals in self._fixes:
            for bit, col, v in zip((1, 2, 4), range(3), vals):
                if v is None:
                    continue
                if initial:
                    fix[ids] |= bit
                if callable(v):
                    any_fn = True
                    vfix[ids, col] = np.broadcast_to(np.asarray(v(t), dtype=float), ids.shape)
                elif initial:
                    vfix[ids, col] = v
        if initial:
            self._a["fix"].from_numpy(fix)
            self._fix_fn = any_fn
        self._a["vfix"].from_numpy(vfix.astype(np.float64 if self._fdt == ti.f64 else np.float32))

    # ------------------------------------------------------------------ stepping
    def _step_args(self):
        # the arrays by name; _one_step appends the last three (detail, continuum, laws)
        return schema.bind(stepk.step, self._a, xforce=self._xforce(), serial=self._serial(),
                           detail=False, continuum=False, laws=self._law_set)[:-3]

    def _xforce(self):
        if self._cont is not None:
            return self._cont.a["xforce"]
        x = self._a.get("xforce_none")
        if x is None:
            x = self._a["xforce_none"] = ti.Vector.ndarray(2, ti.f64, (1,))
        return x



    def _serial(self):
        """Whether this model's kernels run their loops on one thread
        (:func:`tdem.backend.serial_loops`, by the number of particles and block nodes)."""
        cont = self._cont
        nodes = cont.nv if cont is not None else 0
        elements = cont is not None and (cont.has_pcmm or nodes > 0)
        return backend.serial_loops(self._n + nodes, elements)

    def _engine_args(self):
        """Arguments of the step and rebuild kernels; the PCMM candidate search reach."""
        if self._cont is not None and self._cont.has_pcmm:
            h = float(self._a["gridp"].to_numpy()[2])
            self._reach = max(1, int(math.ceil((self._cont.reach_length + 2 * self.skin) / h)))
        else:
            self._reach = 1
        if self._n == 0:
            return None, None
        return self._step_args(), self._rebuild_args()

    def _rebuild_args(self):
        return schema.bind(neighbors.rebuild, self._a, sorted_ids=self._a["sorted"],
                           nwalls=len(self._walls_host), skin=float(self.skin))

    def _one_step(self, step_args, rebuild_args, host_reads_flag, detail):
        """One time step: the stages in the order the data flows (Feng et al.'s seven
        steps). Each stage owns what it writes:

        1. prescribed velocities (functions of time) uploaded — ``vfix``, node fixes;
        2. neighbour lists rebuilt when the skin check asked — slots and histories;
        3. PCMM elements (physics.pcmm) — element stresses, ``xforce``;
        4. blocks (physics.blocks) — triangle stresses, ``nforce``;
        5. point–edge contacts (coupling) — ``xforce``, ``nforce``;
        6. viscous (non-reflecting) boundaries — ``xforce``, ``nforce``;
        7. DEM pairs and walls, gathered with ``xforce``, and the particles' damped
           leapfrog (tdem.step, one kernel) — particle state, contacts, walls;
        8. block nodes and rigid blocks integrated (tdem.integrate) — node state.
        """
        cont = self._cont
        dt = self._dt_run
        if self._n and self._fix_fn:
            self._apply_fixes(t=self._time)
        if cont is not None:
            cont.prescribed(self)
        # on a GPU the rebuild kernel runs every step and returns at once unless the
        # device raised the flag; on the CPU the host reads the flag (shared memory)
        if self._n and (not host_reads_flag or self._a["flags"][F_REBUILD] != 0):
            neighbors.rebuild(*rebuild_args)
        if cont is not None:
            cont.pcmm_elements(self, dt, self._reach)
            cont.block_stresses(self, dt)
            cont.point_edge(self, dt)
            cont.viscous_boundaries(self)
        if self._n:
            stepk.step(*step_args, detail, cont is not None and cont.adds_forces, self._law_set)
        if cont is not None:
            cont.integrate(self)
        self._time += dt
        self._steps += 1

    def _take_snapshot(self):
        if self._cont is not None:
            self._cont.take_snapshot()
        self._snap_clock = (self._time, self._steps)
        if self._n == 0:
            return
        names = schema.dynamic()
        for k in names:
            src = self._a[k]
            dst = self._snap.get(k)
            if dst is None or tuple(dst.shape) != tuple(src.shape):
                self._snap[k] = schema.like(src)
        schema.copy(self._a, self._snap, names, self._serial())
        self._snap_clock = (self._time, self._steps)

    def _restore_snapshot(self):
        if self._cont is not None:
            self._cont.restore_snapshot()
        if self._n:
            schema.copy(self._snap, self._a, schema.dynamic(), self._serial())
        self._time, self._steps = self._snap_clock
        for m in self._monitors:
            m.truncate(self._steps)
        if self._output is not None:
            self._output.truncate(self._steps)

    def _status(self):
        a = self._a
        if self._n == 0:
            return np.array([0, 0, 0, 0, 0, 0, 0, 0], np.int32)
        stepk.check_stability(a["pos"], a["vel"], a["omega"], a["prop"], a["flags"],
                              float(self._dt_run))
        return a["flags"].to_numpy()

    def _grow(self, flags):
        need, needw = int(flags[F_NEED]), int(flags[F_WALL_NEED])
        state = self._download()
        if need > self._cap:
            new = 1 << int(math.ceil(math.log2(need + 1)))  # a power of two
            if new > MAX_SLOTS:
                raise CapacityError(f"a particle has {need} neighbours within its cut-off; more "
                                    f"than {MAX_SLOTS} slots are not supported (check radii and "
                                    "the skin)")
            self._cap = new
        if needw > self._capw:
            self._capw = needw + 1
        state["flags"][F_NEED] = 0
        state["flags"][F_WALL_NEED] = 0
        state["flags"][F_REBUILD] = 1
        self._rebuild_from(state)

    def run(self, until=None, steps=None):
        """Advance to simulated time ``until`` or by ``steps`` steps."""
        if (until is None) == (steps is None):
            raise InputError(f"give exactly one of until= or steps=, got until={until!r}, "
                             f"steps={steps!r}")
        if not self._built:
            self._build()
        if self._n:
            self._upload_laws()      # a law's parameters may have changed since (law.update)
        if self._cont is not None:
            self._cont.upload_materials()
        self._crit_cache = None
        if self._dt_user is not None:
            self._check_dt_value(self._dt_user)  # particles or laws may have changed since
        self._upload_params()
        dt = self._dt_run
        if steps is not None:
            if int(steps) != steps or steps < 0:
                raise InputError(f"steps must be a whole number >= 0, got {steps!r}")
            target = self._steps + int(steps)
        else:
            until = float(until)
            if not math.isfinite(until):
                raise InputError(f"until must be a finite time, got {until!r}")
            target = self._steps + max(0, int(math.ceil((until - self._time) / dt - 1e-9)))
        total = target - self._steps
        self._plan_events()
        bar = self._progress_bar(total)
        t_wall = _time.perf_counter()
        done_at_start = self._steps
        try:
            while self._steps < target:
                self._segment(target, bar)
                if bar is not None:
                    bar.update(self._steps - bar.n - done_at_start)
                    el = _time.perf_counter() - t_wall
                    bar.set_postfix_str(f"t={self._time:.4g}s, "
                                        f"{self._dofs() * (self._steps - done_at_start) / max(el, 1e-9):.3g} "
                                        "particle-steps/s")
        except KeyboardInterrupt:
            self._restore_snapshot()
            self._on_abort("interrupted")
            raise
        except InstabilityError:
            self._on_abort("unstable")
            raise
        except Exception:
            if self._output is not None:
                self._output.stopped(self)
            raise
        finally:
            if bar is not None:
                bar.close()
        if self._output is not None:
            self._output.flush(self)
        return self

    def _segment(self, target, bar):
        """Up to ``check_interval`` steps from a snapshot, then one look at the device."""
        n = min(self.check_interval, target - self._steps)
        self._take_snapshot()
        sargs, rargs = self._engine_args()
        host_flag = self._host_reads_flag
        for s in range(n):
            # output-only quantities are stored on the steps something will read them
            detail = s == n - 1 or self._steps + 1 >= self._next_event
            self._one_step(sargs, rargs, host_flag, detail)
            if self._steps >= self._next_event:
                self._events()
        flags = self._status()
        if self._cont is not None:
            need, bad = self._cont.status()
            if need > self._cont.capacity:
                self._restore_snapshot()
                self._cont.grow(need)
                return
            if bad >= 0:
                self._find_instability()
        if self._n and (flags[F_NEED] > self._cap or flags[F_WALL_NEED] > self._capw):
            self._restore_snapshot()
            self._grow(flags)
            return
        if flags[F_BAD] < self._n:
            self._find_instability()
        if self._n and self._steps - self._last_fit >= self.check_interval:
            self._fit_grid()

    def _find_instability(self):
        """Replay the last segment one step at a time to name the failing step."""
        self._restore_snapshot()
        self._plan_events()
        sargs, rargs = self._engine_args()
        host_flag = self._host_reads_flag
        for _ in range(self.check_interval + 1):
            self._take_snapshot()
            self._one_step(sargs, rargs, host_flag, True)
            flags = self._status()
            if self._cont is not None and self._cont.status()[1] >= 0:
                v = self._cont.status()[1]
                step, t = self._steps, self._time
                nodes = self._cont.a["npos"].to_numpy()[v], self._cont.a["nvel"].to_numpy()[v]
                self._restore_snapshot()
                b = next(b for b in self._blocks if b._offset <= v < b._offset + len(b))
                raise InstabilityError(
                    f"unstable at step {step} (t = {t:.6g} s): node {v - b._offset} of block "
                    f"{b.index} has position {nodes[0].tolist()} and velocity "
                    f"{nodes[1].tolist()} (dt = {self._dt_run:.3g} s). The last good state "
                    f"(step {self._steps}) is kept; reduce dt_fraction.",
                    step=step, time=t, particle=-1)
            if flags[F_BAD] < self._n:
                k = int(flags[F_BAD])
                step, t = self._steps, self._time
                s = self._particles_numpy(stress=False)
                self._restore_snapshot()
                raise InstabilityError(
                    f"unstable at step {step} (t = {t:.6g} s): particle {k} has position "
                    f"{s['position'][k].tolist()} and velocity {s['velocity'][k].tolist()} "
                    f"(dt = {self._dt_run:.3g} s). The last good state (step {self._steps}) is "
                    "kept; reduce dt_fraction or check stiffnesses.",
                    step=step, time=t, particle=k)
            if self._steps >= self._next_event:   # the records of the good steps
                self._events()
        self._restore_snapshot()
        raise InstabilityError("unstable run (could not isolate the step)")

    def _events(self):
        """Record the monitors and write the output that are due now."""
        for m in self._monitors:
            if self._steps >= m.next_step:
                m.record(self)
        if self._output is not None and self._steps >= self._output.next_step(self):
            self._output.write(self)
        self._plan_events()

    def _plan_events(self):
        nxt = [m.next_step for m in self._monitors]
        if self._output is not None:
            nxt.append(self._output.next_step(self))
        self._next_event = min(nxt) if nxt else 1 << 62

    def _on_abort(self, why):
        if self._output is not None:
            self._output.abort(self, why)

    def _dofs(self):
        """Particles plus block nodes (the bodies the throughput counts)."""
        return self._n + (self._cont.nv if self._cont is not None else 0)

    def _progress_bar(self, total):
        show = self.progress
        if show is None:
            show = sys.stderr.isatty() and self._dofs() * total > 2e7
        if not show or total <= 0:
            return None
        from tqdm.auto import tqdm
        return tqdm(total=total, unit="step", desc="tdem", leave=False)

    # ------------------------------------------------------------------ reading
    def _particles_numpy(self, stress=True):
        """Particle state; ``stress=False`` skips the stress (computed from the contacts)."""
        if not self._built:
            self._build()
        if self._n == 0:
            z2 = np.zeros((0, 2))
            z = np.zeros(0)
            out = {"position": z2, "velocity": z2, "omega": z, "radius": z, "mass": z,
                   "force": z2, "torque": z, "displacement": z2}
            if stress:
                out.update(stress=np.zeros((0, 2, 2)), stress_zz=z, pressure=z,
                           plastic_strain=z, strain=np.zeros((0, 3)))
            return out
        a = self._a
        prop = a["prop"].to_numpy()
        pos = a["pos"].to_numpy()
        out = {
            "position": pos, "velocity": a["vel"].to_numpy(), "omega": a["omega"].to_numpy(),
            "radius": prop[:, 0].copy(), "mass": prop[:, 1].copy(),
            "force": a["force"].to_numpy(), "torque": a["torque"].to_numpy(),
            "displacement": pos - a["pos0"].to_numpy(),
        }
        if stress:
            sa = self._a.get("stress_out")
            if sa is None or sa.shape[0] != self._n:
                sa = self._a["stress_out"] = ti.ndarray(ti.f64, (self._n, 3))
            stepk.particle_stress(*schema.bind(stepk.particle_stress, a, out=sa))
            s = sa.to_numpy()
            st = np.zeros((self._n, 2, 2))
            st[:, 0, 0], st[:, 1, 1] = s[:, 0], s[:, 1]
            st[:, 0, 1] = st[:, 1, 0] = s[:, 2]
            szz = np.zeros(self._n)
            out["plastic_strain"] = np.zeros(self._n)
            out["strain"] = np.zeros((self._n, 3))
            if self._cont is not None and self._cont.has_pcmm:
                c = self._cont.particle_fields()
                sel = c["pmat"] >= 0
                s4 = c["stress4"]
                st[sel, 0, 0], st[sel, 1, 1] = s4[sel, 0], s4[sel, 1]
                st[sel, 0, 1] = st[sel, 1, 0] = s4[sel, 2]
                szz[sel] = s4[sel, 3]
                out["plastic_strain"] = c["plastic_strain"]
                out["strain"] = c["strain"]
                out["failed"] = c["failed"]
                out["elements"] = c["elements"]
            out["stress"] = st
            out["stress_zz"] = szz
            out["pressure"] = -(st[:, 0, 0] + st[:, 1, 1] + szz) / 3.0
            # a disc's own stress has no out-of-plane part: its pressure is the in-plane mean
            if self._cont is None or not self._cont.has_pcmm:
                out["pressure"] = -(st[:, 0, 0] + st[:, 1, 1]) / 2.0
            else:
                dem = ~sel
                out["pressure"][dem] = -(st[dem, 0, 0] + st[dem, 1, 1]) / 2.0
        return out

    def _contacts_numpy(self):
        """Contacts in force now: pairs (C,2) (j = -1 - wall index for walls), normal (C,)
        compression-positive, shear (C,), moment (C,) (rolling couple on the first),
        direction (C,2) the unit normal, overlap (C,), point (C,2)."""
        if not self._built:
            self._build()
        if self._n == 0:
            return {"pairs": np.zeros((0, 2), np.int64), "normal": np.zeros(0),
                    "shear": np.zeros(0), "moment": np.zeros(0),
                    "direction": np.zeros((0, 2)), "overlap": np.zeros(0),
                    "point": np.zeros((0, 2))}
        a = self._a
        cs = a["cs"].to_numpy()
        nbr = a["nbr"].to_numpy()
        hist = a["hist"].to_numpy()
        cn = a["cn"].to_numpy()
        pos = a["pos"].to_numpy()
        r = a["prop"].to_numpy()[:, 0]
        ii, kk = np.nonzero((cs[:, :, 2] > 0) & (np.arange(self._cap)[None, :] <
                                                  a["ncnt"].to_numpy()[:, None]))
        jj = nbr[ii, kk]
        u = cs[ii, kk, 2]
        normal_dir = cn[ii, kk]
        pts = pos[ii] + (r[ii] - 0.5 * u)[:, None] * normal_dir
        wcs = a["wcs"].to_numpy()
        wid = a["wid"].to_numpy()
        wi, wk = np.nonzero((wid >= 0) & (wcs[:, :, 2] > 0))
        wu = wcs[wi, wk, 2]
        wn = a["wcn"].to_numpy()[wi, wk]
        whist = a["whist"].to_numpy()
        R = _claw.history_width(self._law_set)     # the rolling couple's column
        return {
            "pairs": np.concatenate([np.stack([ii, jj], 1),
                                     np.stack([wi, -1 - wid[wi, wk]], 1)]).astype(np.int64),
            "normal": np.concatenate([cs[ii, kk, 0], wcs[wi, wk, 0]]),
            "shear": np.concatenate([cs[ii, kk, 1], wcs[wi, wk, 1]]),
            "moment": np.concatenate([hist[ii, kk, R], whist[wi, wk, R]]),
            "direction": np.concatenate([normal_dir, wn]),
            "overlap": np.concatenate([u, wu]),
            "point": np.concatenate([pts, pos[wi] + (r[wi] - 0.5 * wu)[:, None] * wn]),
        }

    def _elements_numpy(self):
        """PCMM elements now (copies included): triangles (E, 3) of particle indices,
        owner, area, n_cover (N_e), weight (1/N_e), stress (E, 2, 2), stress_zz."""
        if not self._built:
            self._build()
        if self._cont is None or not self._cont.has_pcmm:
            return {"triangles": np.zeros((0, 3), np.int64), "owner": np.zeros(0, np.int64),
                    "area": np.zeros(0), "n_cover": np.zeros(0, np.int64),
                    "weight": np.zeros(0), "stress": np.zeros((0, 2, 2)),
                    "stress_zz": np.zeros(0)}
        return self._cont.elements()

    def point_edge_contacts(self):
        """Point–edge contacts in force now (particle–block and block–block), a dict of
        numpy arrays: point (C, 2) (particle centre or block vertex), foot (C, 2)
        (its projection on the edge), normal (C,) compression-positive, shear (C,),
        broken (C,) (cohesion and tension lost), kind (C,) 0 particle, 1 vertex."""
        self._require_built()
        pos = self._a["pos"].to_numpy() if self._n else np.zeros((0, 2))
        if self._cont is None:
            return {
                "point": np.zeros((0, 2)), "foot": np.zeros((0, 2)), "normal": np.zeros(0),
                "shear": np.zeros(0), "broken": np.zeros(0, bool), "kind": np.zeros(0, int)}
        return self._cont.point_edge_contacts(pos)

    def energy(self):
        """Energy account (J per metre of thickness) at the last completed step:
        kinetic, gravitational (relative to the origin), elastic (springs),
        dissipated (damping, friction, rolling), boundary_work (done by walls and
        prescribed velocities) and total = kinetic + gravitational + elastic +
        dissipated − boundary_work, which is conserved for DEM models; explosive: the
        internal energy Σ E·V0 of JWL particles (not in total: the strain energy of
        the continuum elements is not counted)."""
        if not self._built:
            self._build()
        a = self._a
        eacc = a["eacc"].to_numpy()
        estate = a["estate"].to_numpy()
        el = stepk.elastic_energy_sum(*schema.bind(stepk.elastic_energy_sum, a,
                                                   laws=self._law_set))
        e = {"kinetic": float(estate[:, 0].sum()), "gravitational": float(estate[:, 1].sum()),
             "elastic": float(el), "dissipated": float(eacc[:, 0].sum()),
             "boundary_work": float(eacc[:, 1].sum())}
        e["total"] = e["kinetic"] + e["gravitational"] + e["elastic"] + e["dissipated"] \
            - e["boundary_work"]
        e["explosive"] = self._explosive_energy()
        return e

    def _explosive_energy(self):
        """Σ E_i·V0_i of the JWL particles (V0 = m/ρ0): their internal energy."""
        c = self._cont
        if c is None or not getattr(c, "has_pcmm", False) or len(c.jwl_ids) == 0:
            return 0.0
        st = c.jwl_state()[c.jwl_ids]
        return float(np.sum(st[:, 1] * st[:, 4]))

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

