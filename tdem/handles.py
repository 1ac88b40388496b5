"""The handles a model hands back: particle groups, walls, blocks and result views.

:class:`ParticleGroup` (what ``add_particles`` returns), :class:`Wall` (``add_wall``:
velocity, servo control, the force it receives), :class:`Mesh` (``add_mesh``),
:class:`Primitive` (``add_plane``, ``add_cylinder``), :class:`Block` (``add_block``:
nodes, fixes, elements), and the small helpers that check the inputs they share.
Each handle reads and writes the state of the :class:`tdem.Simulation` it belongs to.
"""
import math

import numpy as np

from physics.validate import indices

from . import mesh as _mesh
from . import primitives as _prims
from . import step as stepk
from .errors import InputError


def _vector2(name, value, dim=2):
    """One 2-vector (gravity, a velocity, a point); a 3-vector with ``dim`` 3."""
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be {('two', 'three')[dim - 2]} numbers, got "
                         f"{value!r}") from None
    if a.shape != (dim,) or not np.isfinite(a).all():
        raise InputError(f"{name} must be {('two', 'three')[dim - 2]} finite numbers "
                         f"({('x, y', 'x, y, z')[dim - 2]}), got {value!r}")
    return a


def _as_xy(name, value, n=None, dim=2):
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be numbers, got {value!r}") from None
    if n is not None and a.shape == (dim,):
        a = np.broadcast_to(a, (n, dim)).copy()
    if a.ndim != 2 or a.shape[1] != dim or (n is not None and a.shape[0] != n):
        want = f"({n}, {dim})" if n is not None else f"(N, {dim})"
        hint = ""
        if a.ndim == 2 and a.shape[1] in (2, 3) and a.shape[1] != dim:
            hint = (f" ({a.shape[1]} columns: a {a.shape[1]}D array in a {dim}D simulation; "
                    f"tdem.Simulation(dim={a.shape[1]}) takes it)")
        raise InputError(f"{name} must have shape {want} or ({dim},), got shape "
                         f"{a.shape}{hint}")
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
    """A deformable block: a triangle mesh with fixed connectivity (the CDEM's blocks), made by
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
        self._loads = []      # (node ids, fx, fy), as fix's (apply_force, apply_pressure)
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
        ids = indices("nodes", nodes, len(self.vertices), "vertex")
        vals = [_fix_value(name, v, ids) for name, v in (("vx", vx), ("vy", vy))]
        self._fixes.append((ids, *vals))
        cont = self._sim._cont
        if cont is not None:
            cont.apply_node_fixes(self._sim.time, initial=True)

    def apply_force(self, nodes, fx=None, fy=None):
        """Apply forces (N per metre of thickness) to ``nodes`` (indices into the
        block's vertices): each of fx, fy is None, a float, an array (one per node) or
        a function of time returning either. Loads add up over calls."""
        ids = indices("nodes", nodes, len(self.vertices), "vertex")
        vals = [_fix_value(name, v, ids) for name, v in (("fx", fx), ("fy", fy))]
        self._add_load((ids, *vals))

    def apply_pressure(self, pressure, nodes):
        """A pressure (Pa, positive pushing into the block; a float or a function of
        time) on the boundary edges whose two ends are both among ``nodes`` (e.g.
        ``block.nodes_in(ymin=0.99)``): p × the edge's length, half to each end, along
        the edge's inward normal. The edges' directions and lengths are those of the
        mesh as added (a dead load: the load does not turn with the block)."""
        ids = indices("nodes", nodes, len(self.vertices), "vertex")
        if not callable(pressure):
            try:
                pressure = float(pressure)
            except (TypeError, ValueError):
                raise InputError(f"pressure must be a number (Pa) or a function of time, got "
                                 f"{pressure!r}") from None
            if not np.isfinite(pressure):
                raise InputError(f"pressure must be finite, got {pressure!r}")
        sel = np.zeros(len(self.vertices), bool)
        sel[ids] = True
        edges = _mesh.boundary_edges(self.triangles)
        edges = edges[sel[edges[:, 0]] & sel[edges[:, 1]]]
        if len(edges) == 0:
            raise InputError(f"nodes: no boundary edge has both ends among the {len(ids)} "
                             "nodes given")
        d = self.vertices[edges[:, 1]] - self.vertices[edges[:, 0]]
        # the mesh is to the left of a→b: the inward normal times the length is the
        # edge turned by +90°
        inward = np.column_stack([-d[:, 1], d[:, 0]])
        coef = np.zeros((len(self.vertices), 2))
        np.add.at(coef, edges[:, 0], 0.5 * inward)
        np.add.at(coef, edges[:, 1], 0.5 * inward)
        used = np.unique(edges)
        cx, cy = coef[used, 0], coef[used, 1]
        if callable(pressure):
            self._add_load((used, lambda t: float(pressure(t)) * cx,
                            lambda t: float(pressure(t)) * cy))
        else:
            self._add_load((used, pressure * cx, pressure * cy))

    def _add_load(self, entry):
        self._loads.append(entry)
        cont = self._sim._cont
        if cont is not None:
            cont.apply_node_loads(self._sim.time, initial=True)

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


def _in_box(x, xmin, xmax, ymin, ymax, zmin=-np.inf, zmax=np.inf):
    inside = (x[:, 0] >= xmin) & (x[:, 0] <= xmax) & (x[:, 1] >= ymin) & (x[:, 1] <= ymax)
    if x.shape[1] > 2:
        inside &= (x[:, 2] >= zmin) & (x[:, 2] <= zmax)
    return np.flatnonzero(inside)


def _servo_target(force, stress, size):
    """The force a servo holds (Wall.servo, Mesh.servo): ``force``, or ``stress`` × the
    wall's length or the mesh's area; checked."""
    if (force is None) == (stress is None):
        raise InputError(f"give force or stress, not both: force={force!r}, stress={stress!r}")
    name, value = ("force", force) if force is not None else ("stress", stress)
    try:
        target = float(value) * (1.0 if force is not None else size)
    except (TypeError, ValueError):
        target = float("nan")
    if not math.isfinite(target):
        raise InputError(f"{name} must be a finite number, got {value!r}")
    return target


def _servo_settings(sim, law, direction, normal, centre, relaxation, max_speed):
    """A servo's unit direction (``direction``, else ``normal`` turned towards the
    particles' centroid as seen from ``centre``), a contact's stiffness k of its law
    at the mean radius, its relaxation and speed limit (default 0.01 × the smallest
    radius per step); checked, naming the argument."""
    if direction is None:
        d = np.asarray(normal, dtype=float) / np.linalg.norm(normal)
        x = sim.particles.numpy(stress=False)["position"] if sim.n_particles else None
        if x is not None and len(x) and np.dot(x.mean(axis=0) - centre, d) < 0:
            d = -d
    else:
        d = _vector2("direction", direction, len(normal))
        if np.linalg.norm(d) == 0:
            raise InputError(f"direction must not be zero, got {direction!r}")
        d = d / np.linalg.norm(d)
    relaxation = float(relaxation)
    if not 0.0 < relaxation <= 1.0:
        raise InputError(f"relaxation must lie in (0, 1], got {relaxation!r}")
    r = sim._radii()
    k = law.critical_stiffness(float(r.mean()) if len(r) else 1.0, 1.0)
    if max_speed is None:
        max_speed = 0.01 * float(r.min() if len(r) else 1.0) / sim.dt
    max_speed = float(max_speed)
    if not (max_speed > 0 and math.isfinite(max_speed)):
        raise InputError(f"max_speed must be a positive number, got {max_speed!r}")
    return d, k, relaxation, max_speed


def _fix_value(name, v, ids):
    if v is None or callable(v):
        return v
    try:
        a = np.broadcast_to(np.asarray(v, dtype=float), ids.shape).copy() \
            if np.ndim(v) <= 1 and (np.ndim(v) == 0 or len(v) == len(ids)) else None
    except (TypeError, ValueError):
        a = None
    if a is None or not np.isfinite(a).all():
        raise InputError(f"{name} must be None, a finite number, {len(ids)} numbers "
                         f"or a function of time, got {v!r}")
    return a


def _motion_part(name, v, n):
    """A motion's part: None (not prescribed), a function of time (checked when it is
    called, every step), or a constant of ``n`` finite numbers (returned as an array)."""
    if v is None or callable(v):
        return v
    from .motion import as_vector
    a = as_vector(v, n)
    if a is None:
        raise InputError(f"{name} must be None, {n} finite number"
                         + ("s" if n > 1 else "") + f" or a function of time, got {v!r}")
    return a


def _set_motion(handle, kind, first, count, velocity, angular_velocity, center, dim):
    """Wall.motion / Mesh.motion: constants set now, functions of time registered for
    the runner (:meth:`tdem.runner.Runner._apply_motions`)."""
    sim = handle._sim
    key = (kind, handle.index)
    if kind == "mesh" and handle.index in sim._mesh_servo or (
            kind == "wall" and handle._row()[stepk.W_SERVO_K] != 0.0):
        raise InputError(f"{kind} {handle.index} is servo-controlled: switch the servo off "
                         "(servo()) before giving it a motion")
    vel = _motion_part("velocity", velocity, dim)
    ang = _motion_part("angular_velocity", angular_velocity, 1 if dim == 2 else 3)
    if center is not None:
        c = _vector2("center", center, dim)
        handle._set_center(c)
    # constants (or nothing: at rest) now, functions from the next step on
    handle.velocity = np.zeros(dim) if vel is None or callable(vel) else vel
    w0 = np.zeros(1 if dim == 2 else 3) if ang is None or callable(ang) else ang
    handle.angular_velocity = float(w0[0]) if dim == 2 else w0
    fn_v = vel if callable(vel) else None
    fn_w = ang if callable(ang) else None
    if fn_v is None and fn_w is None:
        sim._motions.pop(key, None)
    else:
        sim._motions[key] = (first, count, fn_v, fn_w)
    return handle


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

    def _set_center(self, c):
        self._set([stepk.W_CX, stepk.W_CY], c)

    def motion(self, velocity=None, angular_velocity=None, center=None):
        """Move this wall by functions of time (machinery): ``velocity`` (2 numbers,
        m/s) and ``angular_velocity`` (rad/s, counter-clockwise, about :attr:`center`),
        each a constant or a function of the time t (s) returning them, evaluated at
        the start of every step (a vibration: ``tdem.motion.vibration``); ``center``
        the point it turns about now (it moves with the wall). A part left None is
        held at 0; ``motion()`` stops the wall. The force and moment it receives are
        :attr:`force` and :attr:`moment`."""
        return _set_motion(self, "wall", self.index, 1, velocity, angular_velocity, center, 2)

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
        sim._motions.pop(("wall", self.index), None)
        row = self._row()
        if force is None and stress is None:
            self._set([stepk.W_SERVO_K, stepk.W_VX, stepk.W_VY], [0.0, 0.0, 0.0])
            return self
        a, b = self.endpoints
        length = float(np.linalg.norm(b - a))
        target = _servo_target(force, stress, length)
        t = (b - a) / length
        d, k, relaxation, max_speed = _servo_settings(
            sim, sim._laws[int(row[stepk.W_LAW])], direction, np.array([-t[1], t[0]]),
            0.5 * (a + b), relaxation, max_speed)
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


class Mesh:
    """A rigid triangle-mesh wall (3D). ``velocity`` and ``angular_velocity`` (about
    :attr:`center`) may be changed between runs; :attr:`force` and :attr:`torque` are
    what it received in the last step."""

    def __init__(self, sim, index):
        self._sim = sim
        self.index = index

    def _rows(self):
        first, count = self._sim._meshes[self.index]
        return self._sim._wall_rows()[first:first + count]

    def _set(self, col, v):
        first, count = self._sim._meshes[self.index]
        rows = self._sim._wall_rows()
        rows[first:first + count, col:col + 3] = v
        self._sim._set_wall_rows(rows)

    @property
    def velocity(self):
        return self._rows()[0, stepk.T_VX:stepk.T_VX + 3].copy()

    @velocity.setter
    def velocity(self, v):
        self._set(stepk.T_VX, _vector2("velocity", v, 3))

    @property
    def angular_velocity(self):
        """Angular velocity (rad/s, a 3-vector) about :attr:`center`."""
        return self._rows()[0, stepk.T_WX:stepk.T_WX + 3].copy()

    @angular_velocity.setter
    def angular_velocity(self, w):
        self._set(stepk.T_WX, _vector2("angular_velocity", w, 3))

    @property
    def center(self):
        return self._rows()[0, stepk.T_OX:stepk.T_OX + 3].copy()

    def _set_center(self, c):
        self._set(stepk.T_OX, c)

    @property
    def surface_velocity(self):
        """A conveyor belt: the velocity (m/s, a 3-vector) of the mesh's surface along
        itself, its part in each triangle's plane added to the velocity particles
        meet there (the triangles themselves do not move with it)."""
        return self._rows()[0, stepk.T_SX:stepk.T_SX + 3].copy()

    @surface_velocity.setter
    def surface_velocity(self, v):
        self._set(stepk.T_SX, _vector2("surface_velocity", v, 3))

    def motion(self, velocity=None, angular_velocity=None, center=None):
        """Move this mesh by functions of time (machinery: a drum, a mixer's blade, a
        vibrating plate): ``velocity`` (3 numbers, m/s) and ``angular_velocity``
        (rad/s, a 3-vector: a rotation about any axis through :attr:`center`), each a
        constant or a function of the time t (s) returning them, evaluated at the start
        of every step (``tdem.motion.vibration`` makes a vibration's); ``center`` the
        point it turns about now (it moves with the mesh). A part left None is held at
        0; ``motion()`` stops the mesh. The force and torque it receives are
        :attr:`force` and :attr:`torque`."""
        first, count = self._sim._meshes[self.index]
        return _set_motion(self, "mesh", first, count, velocity, angular_velocity, center, 3)

    @property
    def triangles(self):
        """The triangles' corners now, (T, 3, 3)."""
        r = self._rows()
        return np.stack([r[:, stepk.T_AX:stepk.T_AX + 3], r[:, stepk.T_BX:stepk.T_BX + 3],
                         r[:, stepk.T_CX:stepk.T_CX + 3]], axis=1)

    def _loads(self):
        first, count = self._sim._meshes[self.index]
        return self._sim._wall_loads()[first:first + count]

    def servo(self, force=None, stress=None, direction=None, relaxation=0.5, max_speed=None):
        """Drive this mesh so that it receives ``force`` (N, compression-positive) — or
        ``stress`` (Pa) × its area — along ``direction``, the unit direction in which it
        moves to compress (default: its area-weighted mean normal, turned towards the
        particles' centroid; a mesh without one, a closed box, needs it given). As a
        segment's :meth:`Wall.servo`: the speed for the next step is set on the device
        from the force received, relaxation × (target − measured)/(contacts × k), k a
        contact's stiffness; ``max_speed`` caps it (default: 0.01 × the smallest radius
        per step). The mesh translates; ``mesh.servo()`` switches the control off and
        stops it."""
        sim = self._sim
        sim._motions.pop(("mesh", self.index), None)
        first, count = sim._meshes[self.index]
        if force is None and stress is None:
            sim._mesh_servo.pop(self.index, None)
            self._set(stepk.T_VX, np.zeros(3))
            sim._upload_mesh_servo()
            return self
        tri = self.triangles
        cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        area = 0.5 * float(np.linalg.norm(cross, axis=1).sum())
        target = _servo_target(force, stress, area)
        mean = 0.5 * cross.sum(axis=0)
        if direction is None and np.linalg.norm(mean) <= 1e-6 * area:
            raise InputError(f"direction: mesh {self.index} has no mean normal (a closed "
                             "surface?); give the direction in which it moves to compress")
        d, k, relaxation, max_speed = _servo_settings(
            sim, sim._laws[int(self._rows()[0, stepk.T_LAW])], direction, mean,
            tri.reshape(-1, 3).mean(axis=0), relaxation, max_speed)
        self._set(stepk.T_WX, np.zeros(3))
        sim._mesh_servo[self.index] = (k, target, d, relaxation, max_speed)
        sim._upload_mesh_servo()
        return self

    @property
    def force(self):
        """Total contact force (3,) the mesh received in the last step."""
        return self._loads()[:, :3].sum(axis=0)

    @property
    def torque(self):
        """Moment (3,) of the contact forces about :attr:`center` in the last step."""
        return self._loads()[:, 3:6].sum(axis=0)

    def __repr__(self):
        return f"Mesh({self.index}, triangles={len(self._rows())})"


class Primitive:
    """A primitive wall (3D): an infinite plane (:meth:`tdem.Simulation.add_plane`) or
    cylinder (:meth:`tdem.Simulation.add_cylinder`). It translates at :attr:`velocity`
    (changeable between runs, or a function of time through :meth:`motion`);
    :attr:`force` and :attr:`torque` are what it received in the last step."""

    def __init__(self, sim, index):
        self._sim = sim
        self.index = index

    def _row(self):
        return self._sim._prim_rows()[self.index]

    def _set(self, col, v):
        rows = self._sim._prim_rows().copy()
        rows[self.index, col:col + len(v)] = v
        self._sim._set_prim_rows(rows)

    @property
    def kind(self):
        """"plane" or "cylinder"."""
        return _prims.KIND_NAMES[int(self._row()[_prims.PR_KIND])]

    @property
    def point(self):
        """A point of the plane, or of the cylinder's axis, now (it moves with the wall)."""
        return self._row()[_prims.PR_PX:_prims.PR_PX + 3].copy()

    @property
    def normal(self):
        """The plane's unit normal (towards the particles), the cylinder's unit axis."""
        return self._row()[_prims.PR_NX:_prims.PR_NX + 3].copy()

    @property
    def radius(self):
        """The cylinder's radius (0 for a plane)."""
        return float(self._row()[_prims.PR_RADIUS])

    @property
    def inside(self):
        """Whether the particles are inside the cylinder (None for a plane)."""
        k = int(self._row()[_prims.PR_KIND])
        return None if k == _prims.PLANE else k == _prims.CYLINDER_IN

    @property
    def velocity(self):
        return self._row()[_prims.PR_VX:_prims.PR_VX + 3].copy()

    @velocity.setter
    def velocity(self, v):
        self._set(_prims.PR_VX, _vector2("velocity", v, 3))

    @property
    def angular_velocity(self):
        """A primitive does not turn: (0, 0, 0)."""
        return np.zeros(3)

    @angular_velocity.setter
    def angular_velocity(self, w):
        if np.any(_vector2("angular_velocity", w, 3) != 0.0):
            raise InputError(f"angular_velocity: a primitive wall translates only, got {w!r}")

    def motion(self, velocity=None):
        """Move this wall by a function of time: ``velocity`` (3 numbers, m/s), a
        constant or a function of the time t (s) returning them, evaluated at the
        start of every step (``tdem.motion.vibration``, ``tdem.motion.ramp``; a
        checkpoint keeps those). None holds it at rest; ``motion()`` stops it."""
        return _set_motion(self, "primitive", self.index, 1, velocity, None, None, 3)

    @property
    def force(self):
        """Total contact force (3,) the wall received in the last step."""
        return self._sim._prim_loads()[self.index, :3].copy()

    @property
    def torque(self):
        """Moment (3,) of the contact forces about :attr:`point` in the last step."""
        return self._sim._prim_loads()[self.index, 3:6].copy()

    @property
    def contacts(self):
        """The number of particles that touched it in the last step."""
        return int(self._sim._prim_loads()[self.index, 6])

    def __repr__(self):
        r = self._row()
        if int(r[_prims.PR_KIND]) == _prims.PLANE:
            return f"Primitive({self.index}, plane, point={self.point.tolist()}, " \
                   f"normal={self.normal.tolist()})"
        return f"Primitive({self.index}, cylinder, point={self.point.tolist()}, " \
               f"axis={self.normal.tolist()}, radius={self.radius:g}, inside={self.inside})"


class _View:
    """``sim.particles`` / ``sim.contacts``: ``.numpy()`` gives a dict of arrays."""

    def __init__(self, fn, count):
        self._fn = fn
        self._count = count

    def numpy(self, **options):
        return self._fn(**options)

    def __len__(self):
        return self._count()
