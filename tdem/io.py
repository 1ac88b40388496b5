"""Output: monitors (histories), VTU snapshots and series, HDF5 histories, plots.

Conventions of the files written here (SI units throughout):

- VTU files are written with meshio (zlib-compressed binary). Points carry z = 0;
  vectors are written with three components (z = 0) and the particle stress as a
  nine-component tensor (row-major 3×3, σ_zz in the last slot), so that ParaView
  shows them as vectors and tensors.
- A snapshot is three files: particles (``vertex`` cells), walls (``line`` cells,
  one per wall) and contacts (``line`` cells, one per contact in force). A file with
  no walls or no contacts is still written, with zero points and zero cells; VTK
  and ParaView read it (meshio's own reader does not accept empty cell blocks).
- A series (:class:`Output`) lists its snapshots in ``particles.pvd``,
  ``walls.pvd`` and ``contacts.pvd`` with the simulated time of each.
- ``monitors.h5`` holds one group per monitor with datasets ``time`` (s),
  ``step`` and ``value`` (one row per record). A series rewrites it while the run
  goes on (at most every :attr:`Output.flush_interval` seconds of wall-clock time,
  when there are new records), at the end of each run and whenever a run stops; each
  write goes to a temporary file moved into place, so a process killed at any
  moment leaves a readable file.
"""
import math
import os
import time as _time
import warnings
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from physics.shapes import Superellipse

from .errors import InputError


class Monitor:
    """History of ``fn(sim)`` recorded every ``every`` steps."""

    def __init__(self, name, fn, every=100, start=0):
        if not callable(fn):
            raise InputError(f"fn must be a function of the simulation, got {fn!r}")
        if not isinstance(every, (int, float, np.integer)) or int(every) != every or every < 1:
            raise InputError(f"every must be a whole number of steps >= 1, got {every!r}")
        self.name = str(name)
        self.fn = fn
        self.every = int(every)
        self.next_step = int(start) + self.every
        self.steps, self.times, self.values = [], [], []

    def record(self, sim):
        got = self.fn(sim)          # first: fn may raise
        try:
            value = np.asarray(got, dtype=float)
        except (TypeError, ValueError):
            raise InputError(f"monitor {self.name!r}: its function must return a number or "
                             f"an array of numbers, got {got!r}") from None
        self.steps.append(sim.steps)
        self.times.append(sim.time)
        self.values.append(value)
        self.next_step = sim.steps + self.every

    def truncate(self, step):
        """Forget records after ``step`` (the run was rewound to it)."""
        while self.steps and self.steps[-1] > step:
            self.steps.pop()
            self.times.pop()
            self.values.pop()
        self.next_step = (self.steps[-1] if self.steps else step) + self.every
        if self.next_step <= step:
            self.next_step = step + 1

    def arrays(self):
        return np.array(self.times), (np.array(self.values) if self.values else np.zeros(0))


# ------------------------------------------------------------------ VTU files
def _xyz(a):
    """(N, 2) → (N, 3) float64 with z = 0; (N, 3) (3D) as it is."""
    a = np.asarray(a, dtype=np.float64)
    if a.ndim == 2 and a.shape[1] == 3:
        return a
    a = a.reshape(-1, 2)
    return np.concatenate([a, np.zeros((len(a), 1))], axis=1)


# components of a 3×3 row-major tensor that get their own named array
_TENSOR_PARTS = (("xx", 0), ("yy", 4), ("zz", 8), ("xy", 1))


def _with_parts(data, cell):
    """The data dict with, beside every 3×3 tensor (9 components), its components as
    named scalars (``stress_xx``, ``stress_yy``, ``stress_zz``, ``stress_xy``), which
    ParaView lists by name for colouring."""
    out = dict(data)
    for name, v in data.items():
        blocks = v if cell else [v]
        if all(np.ndim(b) == 2 and np.shape(b)[1] == 9 for b in blocks):
            for part, k in _TENSOR_PARTS:
                comp = [np.ascontiguousarray(np.asarray(b)[:, k]) for b in blocks]
                out[f"{name}_{part}"] = comp if cell else comp[0]
    return out


def _write_mesh(path, points, cells, point_data=None, cell_data=None):
    import meshio
    point_data, cell_data = point_data or {}, cell_data or {}
    if sum(len(c[1]) for c in cells) == 0:
        points, cells, point_data, cell_data = _placeholder(cells, point_data, cell_data)
    mesh = meshio.Mesh(points, cells, point_data=_with_parts(point_data, False),
                       cell_data=_with_parts(cell_data, True))
    mesh.write(str(path), file_format="vtu")


def _placeholder(cells, point_data, cell_data):
    """A file of nothing (no contacts yet, no walls) as one degenerate cell at the
    origin whose data are 0 (−1 for integers): meshio, and so many readers, cannot read
    a VTU file without cells. Its ``pair`` of a contact file is (−1, −1)."""
    kind = cells[0][0] if cells else "vertex"
    width = {"vertex": 1, "line": 2, "triangle": 3}.get(kind, 1)

    def one(v, rows):
        v = np.asarray(v)
        fill = -1 if np.issubdtype(v.dtype, np.integer) else 0
        return np.full((rows,) + v.shape[1:], fill, dtype=v.dtype)

    return (np.zeros((1, 3)), [(kind, np.zeros((1, width), dtype=np.int64))],
            {k: one(v, 1) for k, v in point_data.items()},
            {k: [one(v[0], 1)] for k, v in cell_data.items()})


def write_particles_vtu(sim, path, particles=None):
    """Particles of ``sim`` to ``path``: one ``vertex`` cell per disc.

    Point data: ``id``, ``radius`` (m), ``mass`` (kg per metre of thickness),
    ``velocity`` (m/s), ``omega`` (rad/s, counter-clockwise positive), ``force`` (N,
    the contact force of the last step), ``torque`` (N·m), ``displacement`` (m, from
    the position at insertion), ``stress`` (Pa, tension-positive average stress of
    the disc, 3×3 row-major with σ_zz last) and ``pressure`` (Pa). ``particles``:
    ``sim.particles.numpy()`` if the caller has it already.
    """
    p = sim.particles.numpy() if particles is None else particles
    n = len(p["radius"])
    if getattr(sim, "dim", 2) == 3:
        return _write_spheres_vtu(path, p, np.concatenate(sim._host["shape"])
                                  if sim._host["shape"] else np.zeros((0, 4)))
    st = np.zeros((n, 3, 3))
    st[:, :2, :2] = p["stress"]
    st[:, 2, 2] = p["stress_zz"]
    point_data = {
        "id": np.asarray(p.get("id", np.arange(n)), dtype=np.int64),
        "radius": np.asarray(p["radius"], dtype=np.float64),
        "mass": np.asarray(p["mass"], dtype=np.float64),
        "velocity": _xyz(p["velocity"]),
        "omega": np.asarray(p["omega"], dtype=np.float64),
        "angle": np.asarray(p["angle"], dtype=np.float64),
        "force": _xyz(p["force"]),
        "torque": np.asarray(p["torque"], dtype=np.float64),
        "displacement": _xyz(p["displacement"]),
        "stress": st.reshape(n, 9),
        "pressure": np.asarray(p["pressure"], dtype=np.float64),
    }
    if _has_shapes(sim):
        # 1 for a shaped particle (drawn from the shapes file), 0 for a disc
        point_data["shape"] = (np.concatenate(sim._host["shape"])[:, 2] > 0).astype(np.int64)
    for name in ("plastic_strain", "elements"):
        if name in p:
            point_data[name] = np.asarray(p[name], dtype=np.float64)
    if "failed" in p:
        point_data["failed"] = np.asarray(p["failed"], dtype=np.int64)
    if "strain" in p:
        e = np.asarray(p["strain"], dtype=np.float64)
        point_data["strain"] = np.stack([e[:, 0], e[:, 2], np.zeros(n), e[:, 2], e[:, 1],
                                         np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n)], 1)
    _write_mesh(path, _xyz(p["position"]), [("vertex", np.arange(n, dtype=np.int64)[:, None])],
                point_data=point_data)
    return path


def _write_spheres_vtu(path, p, shape):
    """3D: one ``vertex`` cell per sphere or ellipsoid with its ``radius`` (bounding)
    and ``diameter`` (ParaView: Glyph of Sphere scaled by diameter — the glyph's radius
    is 0.5 — or Point Gaussian), ``velocity``, ``omega``, ``orientation`` (unit
    quaternion w, x, y, z), ``force``, ``torque`` and ``displacement`` as 3-vectors.
    With ellipsoids, ``shape_tensor`` R diag(2a, 2b, 2c) Rᵀ (3 × 3, row-major; 2r I
    for a sphere): ParaView's *Tensor Glyph* of a Sphere (radius 0.5) with
    *Extract Eigenvalues* draws each particle as its true ellipsoid."""
    n = len(p["radius"])
    tensor = None
    ell = np.asarray(shape)[:, 3] > 0 if len(shape) == n else np.zeros(n, bool)
    if ell.any():
        from .runner import _rotations
        tensor = np.zeros((n, 3, 3))
        tensor[:] = np.eye(3) * (2.0 * np.asarray(p["radius"]))[:, None, None]
        rot = _rotations(np.asarray(p["orientation"])[ell])
        axes = 2.0 * np.asarray(shape)[ell, :3]
        tensor[ell] = np.einsum("nij,nj,nkj->nik", rot, axes, rot)
    point_data = {
        "id": np.asarray(p.get("id", np.arange(n)), dtype=np.int64),
        "radius": np.asarray(p["radius"], dtype=np.float64),
        "diameter": 2.0 * np.asarray(p["radius"], dtype=np.float64),
        "mass": np.asarray(p["mass"], dtype=np.float64),
        "velocity": _xyz(p["velocity"]),
        "omega": _xyz(p["omega"]),
        "orientation": np.asarray(p["orientation"], dtype=np.float64).reshape(-1, 4),
        "force": _xyz(p["force"]),
        "torque": _xyz(p["torque"]),
        "displacement": _xyz(p["displacement"]),
    }
    if tensor is not None:
        point_data["shape_tensor"] = tensor.reshape(n, 9)
        point_data["ellipsoid"] = ell.astype(np.int64)
    _write_mesh(path, _xyz(p["position"]), [("vertex", np.arange(n, dtype=np.int64)[:, None])],
                point_data=point_data)
    return path


def write_meshes_vtu(sim, path):
    """3D: the mesh walls and the primitive walls to ``path``, one ``triangle`` cell
    per triangle. Cell data: ``mesh`` (its index; −1 on a primitive), ``primitive``
    (its index; −1 on a mesh triangle), ``force`` (N, received by the triangle in the
    last step), ``velocity`` (m/s, translation).

    A primitive is infinite; it is drawn as a patch around the particles: a plane as a
    square of 2·PRIMITIVE_DIVISIONS² cells centred on the particles' bounding box's
    centre projected onto it, as wide as the box's diagonal plus twice a margin; a
    cylinder as PRIMITIVE_SEGMENTS facets around its axis over the particles' extent
    along it plus the margin (the margin: a tenth of the diagonal, at least the
    largest radius). Its cells share its total force evenly, so that the force summed
    over a wall's cells is the force on it, for meshes and primitives alike."""
    from .step import T_AX, T_BX, T_CX, T_MESH, T_VX, TRI_WIDTH
    tri = np.asarray(sim._wall_rows(), dtype=np.float64).reshape(-1, TRI_WIDTH)
    pts = np.stack([tri[:, T_AX:T_AX + 3], tri[:, T_BX:T_BX + 3], tri[:, T_CX:T_CX + 3]],
                   axis=1).reshape(-1, 3)
    loads = np.asarray(sim._wall_loads(), dtype=np.float64).reshape(-1, 7)
    pts, mesh, prim = [pts], [tri[:, T_MESH].astype(np.int64)], [np.full(len(tri), -1)]
    force, velocity = [loads[:, :3].copy()], [tri[:, T_VX:T_VX + 3].copy()]
    for k, w in enumerate(getattr(sim, "primitives", [])):
        t = _primitive_patch(sim, w)
        m = len(t)
        pts.append(t.reshape(-1, 3))
        mesh.append(np.full(m, -1))
        prim.append(np.full(m, k))
        force.append(np.tile(w.force / m, (m, 1)))
        velocity.append(np.tile(w.velocity, (m, 1)))
    pts = np.concatenate(pts)
    cell_data = {
        "mesh": [np.concatenate(mesh).astype(np.int64)],
        "primitive": [np.concatenate(prim).astype(np.int64)],
        "force": [np.concatenate(force)],
        "velocity": [np.concatenate(velocity)],
    }
    _write_mesh(path, pts, [("triangle", np.arange(len(pts), dtype=np.int64).reshape(-1, 3))],
                cell_data=cell_data)
    return path


PRIMITIVE_DIVISIONS = 8    # a plane's patch: divisions × divisions squares, two cells each
PRIMITIVE_SEGMENTS = 48    # a cylinder's patch: facets around the axis


def _primitive_patch(sim, w):
    """Triangles (m, 3, 3) drawing primitive wall ``w`` around the particles."""
    x, r = np.zeros((0, 3)), np.zeros(0)
    if sim.n_particles:
        pa = sim.particles.numpy(stress=False)
        x = np.asarray(pa["position"], dtype=np.float64)
        r = np.asarray(pa["radius"], dtype=np.float64)
    p, a = np.asarray(w.point, dtype=np.float64), np.asarray(w.normal, dtype=np.float64)
    if len(x):
        lo, hi = (x - r[:, None]).min(axis=0), (x + r[:, None]).max(axis=0)
        diag = float(np.linalg.norm(hi - lo))
        margin = max(0.1 * diag, float(r.max()))
        centre = 0.5 * (lo + hi)
    else:
        diag, margin, centre = 0.0, max(1.0, 2.0 * w.radius), p
    # two unit vectors across a
    e = np.eye(3)[int(np.argmin(np.abs(a)))]
    u = np.cross(a, e)
    u /= np.linalg.norm(u)
    v = np.cross(a, u)
    if w.kind == "plane":
        c = centre - np.dot(centre - p, a) * a
        half = 0.5 * diag + margin
        s = np.linspace(-half, half, PRIMITIVE_DIVISIONS + 1)
        g = c + s[:, None, None] * u + s[None, :, None] * v      # (d+1, d+1, 3)
        q00, q10, q01, q11 = g[:-1, :-1], g[1:, :-1], g[:-1, 1:], g[1:, 1:]
        t = np.concatenate([np.stack([q00, q10, q11], axis=2).reshape(-1, 3, 3),
                            np.stack([q00, q11, q01], axis=2).reshape(-1, 3, 3)])
        return t
    along = (x - p) @ a if len(x) else np.zeros(1)
    rr = r if len(x) else np.zeros(1)
    z0, z1 = float((along - rr).min()) - margin, float((along + rr).max()) + margin
    phi = np.linspace(0.0, 2.0 * np.pi, PRIMITIVE_SEGMENTS + 1)
    ring = w.radius * (np.cos(phi)[:, None] * u + np.sin(phi)[:, None] * v)
    b, top = p + z0 * a + ring, p + z1 * a + ring
    t = np.concatenate([np.stack([b[:-1], b[1:], top[1:]], axis=1),
                        np.stack([b[:-1], top[1:], top[:-1]], axis=1)])
    return t


SHAPE_OUTLINE = 48    # boundary points of a shaped particle's polygon in the VTU file


def write_shapes_vtu(sim, path, particles=None):
    """The shaped particles (superellipses) of ``sim`` to ``path``: one ``polygon`` cell
    per particle, its boundary at SHAPE_OUTLINE points (Miyata's Eq. 35, denser at the
    corners), turned and placed, so that ParaView shows the true shapes (Surface
    representation, no glyphs). Cell data: ``id`` (the particle's index), ``angle``
    (degrees), ``velocity`` (m/s), ``omega`` (rad/s), ``force`` (N), ``displacement``
    (m), ``stress`` (Pa, tension-positive, 3×3 with σ_zz = 0) and ``pressure`` (Pa)."""
    p = sim.particles.numpy() if particles is None else particles
    rows = np.concatenate(sim._host["shape"]) if sim._n else np.zeros((0, 4))
    if sim.dim == 3:
        return _write_polyhedra_vtu(sim, path, p, rows)
    ids = np.flatnonzero(rows[:, 2] > 0)
    m = SHAPE_OUTLINE
    pts = np.zeros((len(ids), m, 2))
    th = np.radians(np.asarray(p["angle"])[ids])
    for key in np.unique(rows[ids, :3], axis=0):
        sel = np.flatnonzero(np.all(rows[ids, :3] == key, axis=1))
        pts[sel] = Superellipse(*key).placed(p["position"][ids[sel]], th[sel], m)
    pts = pts.reshape(-1, 2)
    cells = np.arange(len(ids) * m, dtype=np.int64).reshape(len(ids), m)
    st = np.zeros((len(ids), 3, 3))
    st[:, :2, :2] = np.asarray(p["stress"])[ids]
    data = {
        "id": ids.astype(np.int64),
        "angle": np.asarray(p["angle"], dtype=np.float64)[ids],
        "velocity": _xyz(np.asarray(p["velocity"])[ids]),
        "omega": np.asarray(p["omega"], dtype=np.float64)[ids],
        "force": _xyz(np.asarray(p["force"])[ids]),
        "displacement": _xyz(np.asarray(p["displacement"])[ids]),
        "stress": st.reshape(-1, 9),
        "pressure": np.asarray(p["pressure"], dtype=np.float64)[ids],
    }
    _write_mesh(path, _xyz(pts), [("polygon", cells)],
                cell_data={k: [v] for k, v in data.items()})
    return path


def _write_polyhedra_vtu(sim, path, p, rows):
    """3D: the surface of each polyhedron, its faces' triangles placed and turned (one
    ``triangle`` cell each; ParaView shows the true shapes as a Surface). Cell data, the
    particle's: ``id``, ``velocity``, ``omega``, ``force``, ``displacement`` (3-vectors)
    and ``speed``."""
    ids = np.flatnonzero(rows[:, 3] < 0)
    kind = -rows[ids, 3].astype(int) - 1
    pts, cells, owner = [], [], []
    offset = 0
    for k in np.unique(kind):
        sel = ids[kind == k]
        x, tri = sim._polys[k].surface(np.asarray(p["position"])[sel],
                                       np.asarray(p["orientation"])[sel])
        pts.append(x)
        cells.append(tri + offset)
        owner.append(np.repeat(sel, len(sim._polys[k].triangles)))
        offset += len(x)
    pts = np.concatenate(pts) if pts else np.zeros((0, 3))
    cells = np.concatenate(cells).astype(np.int64) if cells else np.zeros((0, 3), np.int64)
    owner = np.concatenate(owner) if owner else np.zeros(0, np.int64)
    vel = _xyz(np.asarray(p["velocity"]))[owner]
    data = {
        "id": owner.astype(np.int64),
        "velocity": vel,
        "speed": np.linalg.norm(vel, axis=1),
        "omega": _xyz(np.asarray(p["omega"]))[owner],
        "force": _xyz(np.asarray(p["force"]))[owner],
        "displacement": _xyz(np.asarray(p["displacement"]))[owner],
    }
    _write_mesh(path, pts, [("triangle", cells)], cell_data={k: [v] for k, v in data.items()})
    return path


def _has_shapes(sim):
    """Whether the model has shaped particles drawn as cells of their own: 2D
    superellipses (polygons) and 3D polyhedra (surfaces); 3D ellipsoids are drawn from
    the particles file's shape tensor."""
    if not getattr(sim, "_n", 0) or not sim._has_shapes:
        return False
    if getattr(sim, "dim", 2) == 2:
        return True
    return bool(getattr(sim, "_polys", None))


def _stress9(s, szz):
    out = np.zeros((len(s), 3, 3))
    out[:, :2, :2] = s
    out[:, 2, 2] = szz
    return out.reshape(len(s), 9)


def write_elements_vtu(sim, path, particles=None):
    """PCMM elements of ``sim`` to ``path``: one ``triangle`` cell per element (copies
    included) on the particle centres. Cell data: ``stress`` (Pa, 3×3 row-major,
    tension-positive), ``weight`` (1/N_e), ``n_cover`` (N_e), ``owner``; point data
    as the particles' ``displacement``, ``velocity`` and ``pressure``."""
    e = sim.elements.numpy()
    p = sim.particles.numpy() if particles is None else particles
    tri = np.asarray(e["triangles"], dtype=np.int64).reshape(-1, 3)
    cell_data = {"stress": [_stress9(e["stress"], e["stress_zz"])],
                 "weight": [np.asarray(e["weight"], dtype=np.float64)],
                 "n_cover": [np.asarray(e["n_cover"], dtype=np.int64)],
                 "owner": [np.asarray(e["owner"], dtype=np.int64)]}
    point_data = {"displacement": _xyz(p["displacement"]), "velocity": _xyz(p["velocity"]),
                  "pressure": np.asarray(p["pressure"], dtype=np.float64)}
    _write_mesh(path, _xyz(p["position"]), [("triangle", tri)], point_data=point_data,
                cell_data=cell_data)
    return path


def write_blocks_vtu(sim, path):
    """Blocks of ``sim`` to ``path``: their triangles on the current node positions.
    Point data: ``block``, ``velocity``, ``displacement``, ``force``, ``reaction``;
    cell data: ``block``, ``stress`` (Pa, 3×3 row-major), ``pressure``,
    ``plastic_strain``, ``failed``."""
    pts, tris, pd, cd = [], [], {k: [] for k in ("block", "velocity", "displacement",
                                                  "force", "reaction")}, \
        {k: [] for k in ("block", "stress", "pressure", "plastic_strain", "failed")}
    off = 0
    for b in sim.blocks:
        nd = b.nodes()
        el = b.elements()
        pts.append(_xyz(nd["position"]))
        tris.append(el["triangles"] + off)
        off += len(nd["position"])
        pd["block"].append(np.full(len(nd["position"]), b.index, np.int64))
        for k in ("velocity", "displacement", "force", "reaction"):
            pd[k].append(_xyz(nd[k]))
        t = len(el["triangles"])
        cd["block"].append(np.full(t, b.index, np.int64))
        cd["stress"].append(_stress9(el["stress"], el["stress_zz"]))
        cd["pressure"].append(-(el["stress"][:, 0, 0] + el["stress"][:, 1, 1]
                                + el["stress_zz"]) / 3.0)
        cd["plastic_strain"].append(el["plastic_strain"])
        cd["failed"].append(el["failed"].astype(np.int64))
    _write_mesh(path, np.concatenate(pts), [("triangle", np.concatenate(tris))],
                point_data={k: np.concatenate(v) for k, v in pd.items()},
                cell_data={k: [np.concatenate(v)] for k, v in cd.items()})
    return path


def write_couplings_vtu(sim, path):
    """Point–edge contacts of ``sim`` to ``path``: one ``line`` cell per contact, from
    the particle centre (or block vertex) to its foot on the edge. Cell data:
    ``normal_force`` (N, compression-positive), ``shear_force``, ``broken``, ``kind``
    (0 particle–block, 1 block–block)."""
    c = sim.point_edge_contacts()
    n = len(c["normal"])
    pts = np.concatenate([_xyz(c["point"]), _xyz(c["foot"])])
    lines = np.stack([np.arange(n), np.arange(n) + n], axis=1).astype(np.int64)
    _write_mesh(path, pts, [("line", lines)],
                cell_data={"normal_force": [np.asarray(c["normal"], float)],
                           "shear_force": [np.asarray(c["shear"], float)],
                           "broken": [np.asarray(c["broken"], np.int64)],
                           "kind": [np.asarray(c["kind"], np.int64)]})
    return path


def write_walls_vtu(sim, path):
    """Walls of ``sim`` to ``path``: one ``line`` cell per wall (points p0, p1).

    Cell data: ``id`` (wall index), ``force`` (N, the total contact force the wall
    received in the last step, z = 0), ``moment`` (N·m about the wall's centre) and
    ``velocity`` (m/s, translation). In 3D the mesh walls (:func:`write_meshes_vtu`).
    """
    if getattr(sim, "dim", 2) == 3:
        return write_meshes_vtu(sim, path)
    walls = sim.walls
    pts = np.concatenate([w.endpoints for w in walls]) if walls else np.zeros((0, 2))
    lines = np.arange(2 * len(walls), dtype=np.int64).reshape(-1, 2)
    force = np.array([w.force for w in walls]).reshape(-1, 2)
    cell_data = {
        "id": [np.arange(len(walls), dtype=np.int64)],
        "force": [_xyz(force)],
        "moment": [np.array([w.moment for w in walls], dtype=np.float64)],
        "velocity": [_xyz(np.array([w.velocity for w in walls]).reshape(-1, 2))],
    }
    _write_mesh(path, _xyz(pts), [("line", lines)], cell_data=cell_data)
    return path


def write_contacts_vtu(sim, path, particles=None):
    """Contacts in force to ``path``: one ``line`` cell per contact, from the centre
    of particle i to the centre of particle j, or, for a wall contact, to the contact
    point on the wall. Each contact has its own two points.

    Cell data: ``pair`` (i, j; j = −1 − wall index for a wall), ``normal_force`` (N,
    compression-positive), ``shear_force`` (N), ``moment`` (N·m, rolling couple),
    ``overlap`` (m) and ``direction`` (unit normal from i towards j, z = 0). The
    normal force is also point data (both ends of a line carry the value of their
    contact), for a *Tube* filter with radius varying by scalar. ``particles``:
    ``sim.particles.numpy()`` if the caller has it already.
    """
    c = sim.contacts.numpy()
    p = sim.particles.numpy() if particles is None else particles
    d = getattr(sim, "dim", 2)
    pos = np.asarray(p["position"], dtype=np.float64).reshape(-1, d)
    pairs = np.asarray(c["pairs"], dtype=np.int64).reshape(-1, 2)
    m = len(pairs)
    a = pos[pairs[:, 0]] if m else np.zeros((0, d))
    b = np.zeros((m, d))
    to_particle = pairs[:, 1] >= 0
    b[to_particle] = pos[pairs[to_particle, 1]]
    if any(p is not None for p in getattr(sim, "_periodic", ())):
        # to j's image nearest to i (across a periodic boundary)
        b[to_particle] = a[to_particle] + sim._image(b[to_particle] - a[to_particle])
    b[~to_particle] = np.asarray(c["point"]).reshape(-1, d)[~to_particle]
    pts = np.empty((2 * m, d))
    pts[0::2] = a
    pts[1::2] = b
    fn = np.asarray(c["normal"], dtype=np.float64)
    cell_data = {
        "pair": [pairs],
        "normal_force": [fn],
        "shear_force": [np.asarray(c["shear_force"] if d == 3 else c["shear"],
                                   dtype=np.float64)],
        "moment": [np.asarray(c["moment"] if d == 2 else np.zeros(m), dtype=np.float64)],
        "overlap": [np.asarray(c["overlap"], dtype=np.float64)],
        "direction": [_xyz(c["direction"])],
    }
    _write_mesh(path, _xyz(pts), [("line", np.arange(2 * m, dtype=np.int64).reshape(-1, 2))],
                point_data={"normal_force": np.repeat(fn, 2)}, cell_data=cell_data)
    return path


def write_bonds_vtu(sim, path, particles=None):
    """Intact bonds (:meth:`tdem.Simulation.bond`) to ``path``: one ``line`` cell per
    bond between the two particles' centres, with cell data ``pair``,
    ``normal_force`` (compression positive, tension negative), ``shear_force``
    (magnitude) and ``moment`` (the bending moment's magnitude); the normal force also
    as point data (a *Tube* by scalar, or colour by it)."""
    b = sim.bonds.numpy()
    p = sim.particles.numpy() if particles is None else particles
    d = getattr(sim, "dim", 2)
    pos = np.asarray(p["position"], dtype=np.float64).reshape(-1, d)
    pairs = np.asarray(b["pairs"], dtype=np.int64).reshape(-1, 2)
    m = len(pairs)
    pts = np.empty((2 * m, d))
    if m:
        pts[0::2], pts[1::2] = pos[pairs[:, 0]], pos[pairs[:, 1]]
    fn = np.asarray(b["normal_force"], dtype=np.float64)
    mom = np.asarray(b["moment"], dtype=np.float64)
    cell_data = {
        "id": [np.arange(m, dtype=np.int64)], "pair": [pairs], "normal_force": [fn],
        "shear_force": [np.linalg.norm(np.asarray(b["shear_force"], float).reshape(m, d), axis=1)],
        "moment": [np.abs(mom) if d == 2 else np.linalg.norm(mom.reshape(m, 3), axis=1)],
    }
    _write_mesh(path, _xyz(pts), [("line", np.arange(2 * m, dtype=np.int64).reshape(-1, 2))],
                point_data={"normal_force": np.repeat(fn, 2)}, cell_data=cell_data)
    return path


def write_cracks_vtu(sim, path):
    """Broken bonds to ``path``: one ``vertex`` per crack at its contact point, with
    point data ``id``, ``time`` (s), ``mode`` (0 tension, 1 shear), ``normal`` (the bond's
    direction then), ``normal_force`` and ``shear_force`` at the break and ``energy``
    (released)."""
    c = sim.cracks.numpy()
    k = len(c["time"])
    point_data = {"id": np.arange(k, dtype=np.int64), "time": c["time"],
                  "mode": c["mode"].astype(np.int64),
                  "normal": _xyz(c["normal"]), "normal_force": c["normal_force"],
                  "shear_force": c["shear_force"], "energy": c["energy"]}
    _write_mesh(path, _xyz(c["position"]), [("vertex", np.arange(k, dtype=np.int64)[:, None])],
                point_data=point_data)
    return path


def write_vtu(sim, path, walls=True, contacts=True):
    """Write one snapshot of ``sim``: particles to ``path``, and beside it the walls
    to ``<stem>_walls.vtu`` and the contacts to ``<stem>_contacts.vtu`` (see
    :func:`write_particles_vtu`, :func:`write_walls_vtu`, :func:`write_contacts_vtu`
    for the fields). Files of zero walls or zero contacts hold one degenerate cell at
    the origin with zero data (pair (−1, −1)): meshio cannot read a VTU file without
    cells. Every 3×3 tensor field also comes as named components (``stress_xx``,
    ``stress_yy``, ``stress_zz``, ``stress_xy``).

    Returns the list of paths written (strings), particles first.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    p = sim.particles.numpy()
    written = [str(write_particles_vtu(sim, path, p))]
    if _has_elements(sim):
        written.append(str(write_elements_vtu(sim, path.with_name(path.stem + "_elements.vtu"),
                                              p)))
    if _has_shapes(sim):
        written.append(str(write_shapes_vtu(sim, path.with_name(path.stem + "_shapes.vtu"), p)))
    if sim.blocks:
        written.append(str(write_blocks_vtu(sim, path.with_name(path.stem + "_blocks.vtu"))))
    if getattr(sim, "_couples", None):
        written.append(str(write_couplings_vtu(sim, path.with_name(path.stem +
                                                                   "_couplings.vtu"))))
    if walls:
        written.append(str(write_walls_vtu(sim, path.with_name(path.stem + "_walls.vtu"))))
    if contacts:
        written.append(str(write_contacts_vtu(sim, path.with_name(path.stem + "_contacts.vtu"),
                                              p)))
    if getattr(sim, "_nbonds", 0):
        written.append(str(write_bonds_vtu(sim, path.with_name(path.stem + "_bonds.vtu"), p)))
        written.append(str(write_cracks_vtu(sim, path.with_name(path.stem + "_cracks.vtu"))))
    return written


def _has_elements(sim):
    return any(t is not None for _, t in getattr(sim, "_slots", []))


def _has_bodies(sim):
    return getattr(sim, "n_particles", 0) > 0 or bool(getattr(sim, "blocks", []))


def write_pvd(path, entries):
    """A ParaView collection file: ``entries`` is a list of (time in s, file name
    relative to the ``.pvd``). Written to a temporary file and moved into place, so
    that a reader never sees a half-written index."""
    root = ET.Element("VTKFile", type="Collection", version="0.1", byte_order="LittleEndian")
    coll = ET.SubElement(root, "Collection")
    for t, name in entries:
        ET.SubElement(coll, "DataSet", timestep=repr(float(t)), group="", part="0",
                      file=str(name))
    ET.indent(root)
    tmp = Path(str(path) + ".tmp")
    ET.ElementTree(root).write(tmp, encoding="utf-8", xml_declaration=True)
    os.replace(tmp, path)
    return path


# ------------------------------------------------------------------ HDF5 histories
def _h5_name(name):
    """An HDF5 group name for a monitor name ('/' separates groups in HDF5)."""
    name = str(name).replace("/", "_")
    return "_" if name in ("", ".") else name


def write_monitors(sim, path):
    """Write every monitor of ``sim`` to the HDF5 file ``path``.

    One group per monitor (its name, '/' replaced by '_'; the original name is the
    group's ``name`` attribute) with datasets ``time`` (K,) in s, ``step`` (K,) and
    ``value`` (K, ...) and the attribute ``every`` (steps). File attributes:
    ``simulation`` (its repr), ``time`` (s), ``steps``, ``dt`` (s), ``n_particles``.
    """
    import h5py
    path = Path(path)
    tmp = Path(str(path) + ".tmp")
    with h5py.File(tmp, "w") as f:
        f.attrs["simulation"] = repr(sim)
        f.attrs["time"] = float(sim.time)
        f.attrs["steps"] = int(sim.steps)
        f.attrs["n_particles"] = int(getattr(sim, "n_particles", 0))
        try:
            f.attrs["dt"] = float(sim.dt)
        except (InputError, ValueError):
            pass
        for m in getattr(sim, "_monitors", []):
            g = f.create_group(_h5_name(m.name))
            g.attrs["name"] = m.name
            g.attrs["every"] = int(m.every)
            t, v = m.arrays()
            g.create_dataset("time", data=np.asarray(t, dtype=np.float64))
            g.create_dataset("step", data=np.asarray(m.steps, dtype=np.int64))
            g.create_dataset("value", data=np.asarray(v, dtype=np.float64))
    os.replace(tmp, path)
    return path


def read_monitors(path):
    """{monitor name: (time (K,), value (K, ...))} from a file of :func:`write_monitors`."""
    import h5py
    out = {}
    with h5py.File(path, "r") as f:
        for key, g in f.items():
            if not isinstance(g, h5py.Group) or "time" not in g or "value" not in g:
                continue
            name = g.attrs.get("name", key)
            out[str(name)] = (g["time"][()], g["value"][()])
    return out


# ------------------------------------------------------------------ series
# wall-clock seconds between two writes of monitors.h5 while a run goes on
MONITOR_FLUSH_SECONDS = 1.0


class Output:
    """A VTU series with ``.pvd`` indices, monitor histories and abort checkpoints.

    Created by :meth:`tdem.Simulation.output`. Snapshots are written every ``every``
    steps, or every ``interval`` seconds of simulated time (at the first step at or
    after each multiple of ``interval`` from the time output was set up), or, with
    neither, only at the end of each run. The state when output is set up is the
    first snapshot. Files in ``directory``: ``particles_KKKKK.vtu``,
    ``walls_KKKKK.vtu``, ``contacts_KKKKK.vtu`` (K: snapshot number), the indices
    ``particles.pvd``, ``walls.pvd``, ``contacts.pvd``, ``monitors.h5`` and, after an
    interrupted or unstable run, ``last_good.h5`` (a checkpoint of the last good
    state, see :func:`tdem.checkpoint.load`), and ``view.py``, a ParaView script that
    shows the series and saves a PNG (``pvpython view.py``, headless ``xvfb-run -a
    pvpython view.py``; :mod:`tdem.paraview`; attribute ``view_script=False``: not
    written after the first snapshot).

    ``monitors.h5`` is written while the run goes on, at most every
    ``flush_interval`` seconds of wall-clock time (attribute, default
    :data:`MONITOR_FLUSH_SECONDS`; 0: at every record) when there are new records,
    and always at the end of each run and when a run stops (interrupted, unstable, or
    any error): a process killed outright loses at most the last ``flush_interval``
    seconds of records.

    The engine calls :meth:`next_step`, :meth:`write`, :meth:`truncate`,
    :meth:`flush`, :meth:`abort` and :meth:`stopped`.
    """

    def __init__(self, directory, every=None, interval=None, contacts=True, walls=True,
                 checkpoint_on_abort=True, sim=None):
        if every is not None and interval is not None:
            raise InputError(f"give at most one of every= and interval=, got every={every!r}, "
                             f"interval={interval!r}")
        if every is not None:
            try:
                ok = int(every) == every and every >= 1
            except (TypeError, ValueError):
                ok = False
            if not ok:
                raise InputError(f"every must be a whole number of steps >= 1, got {every!r}")
            every = int(every)
        if interval is not None:
            try:
                ok = float(interval) > 0 and math.isfinite(float(interval))
            except (TypeError, ValueError):
                ok = False
            if not ok:
                raise InputError(f"interval must be a positive time in seconds, got {interval!r}")
            interval = float(interval)
        self.directory = Path(directory)
        self.directory.mkdir(parents=True, exist_ok=True)
        self.every = every
        self.interval = interval
        self.contacts = bool(contacts)
        self.walls = bool(walls)
        self.checkpoint_on_abort = bool(checkpoint_on_abort)
        self._sim = sim
        self._entries = []          # (step, time, snapshot number), in step order
        self._start = (0, 0.0) if sim is None else (int(sim.steps), float(sim.time))
        self._initial_due = sim is not None
        self.flush_interval = MONITOR_FLUSH_SECONDS
        self._monitors_key = None        # the records last written to monitors.h5
        self._monitors_at = -math.inf    # and when (time.monotonic)
        self.view_script = True          # write view.py, a ParaView script of the series
        self._view_kinds = None          # the kinds of files view.py was written for
        if sim is not None and _has_bodies(sim):
            self._write_initial(sim)

    # ---------------------------------------------------------------- paths
    def _names(self, k):
        names = {"particles": f"particles_{k:05d}.vtu"}
        if self._sim is not None and _has_shapes(self._sim):
            names["shapes"] = f"shapes_{k:05d}.vtu"
        if self._sim is not None and _has_elements(self._sim):
            names["elements"] = f"elements_{k:05d}.vtu"
        if self._sim is not None and self._sim.blocks:
            names["blocks"] = f"blocks_{k:05d}.vtu"
        if self._sim is not None and getattr(self._sim, "_couples", None):
            names["couplings"] = f"couplings_{k:05d}.vtu"
        if self.walls:
            names["walls"] = f"walls_{k:05d}.vtu"
        if self.contacts:
            names["contacts"] = f"contacts_{k:05d}.vtu"
        if self._sim is not None and getattr(self._sim, "_nbonds", 0):
            names["bonds"] = f"bonds_{k:05d}.vtu"
            names["cracks"] = f"cracks_{k:05d}.vtu"
        return names

    @property
    def pvd_paths(self):
        """The ``.pvd`` index files of the series."""
        return [self.directory / f"{kind}.pvd" for kind in self._names(0)]

    @property
    def snapshots(self):
        """[(step, time in s)] of the snapshots listed in the series."""
        return [(s, t) for s, t, _ in self._entries]

    # ---------------------------------------------------------- engine calls
    def _write_initial(self, sim):
        self._initial_due = False
        self._start = (int(sim.steps), float(sim.time))
        self.write(sim)

    def next_step(self, sim):
        """The step at which the next snapshot is due (a very large number when none
        is). If output was set up before the simulation had particles, the initial
        snapshot is written here, at the start of the first run. The engine asks after
        every round of records: new monitor records are written to ``monitors.h5``
        here when ``flush_interval`` has passed since the last write."""
        self.write_monitors(sim, force=False)
        if self._initial_due and getattr(sim, "_built", True) and _has_bodies(sim):
            self._write_initial(sim)
        if self.every is not None:
            last = self._entries[-1][0] if self._entries else self._start[0]
            return last + self.every
        if self.interval is not None:
            last_step, last_time = ((self._entries[-1][0], self._entries[-1][1])
                                    if self._entries else self._start)
            t0 = self._start[1]
            k = math.floor((last_time - t0) / self.interval + 1e-9) + 1
            target = t0 + k * self.interval
            dt = float(sim.dt)
            return last_step + max(1, int(math.ceil((target - last_time) / dt - 1e-9)))
        return 1 << 62

    def write(self, sim):
        """Write a snapshot of the current state and rewrite the ``.pvd`` indices.
        Returns the paths of the files written."""
        step, t = int(sim.steps), float(sim.time)
        if self._entries and self._entries[-1][0] == step:
            k = self._entries.pop()[2]
        else:
            k = self._entries[-1][2] + 1 if self._entries else 0
        names = self._names(k)
        p = sim.particles.numpy()
        written = [str(write_particles_vtu(sim, self.directory / names["particles"], p))]
        if "shapes" in names:
            written.append(str(write_shapes_vtu(sim, self.directory / names["shapes"], p)))
        if "elements" in names:
            written.append(str(write_elements_vtu(sim, self.directory / names["elements"], p)))
        if "blocks" in names:
            written.append(str(write_blocks_vtu(sim, self.directory / names["blocks"])))
        if "couplings" in names:
            written.append(str(write_couplings_vtu(sim, self.directory / names["couplings"])))
        if self.walls:
            written.append(str(write_walls_vtu(sim, self.directory / names["walls"])))
        if self.contacts:
            written.append(str(write_contacts_vtu(sim, self.directory / names["contacts"], p)))
        if "bonds" in names:
            written.append(str(write_bonds_vtu(sim, self.directory / names["bonds"], p)))
            written.append(str(write_cracks_vtu(sim, self.directory / names["cracks"])))
        self._entries.append((step, t, k))
        self._write_indices()
        return written

    def _write_indices(self):
        for kind in self._names(0):
            write_pvd(self.directory / f"{kind}.pvd",
                      [(t, self._names(k)[kind]) for _, t, k in self._entries])
        self._write_view()

    def _write_view(self):
        """``view.py``, the ParaView script of the series (:mod:`tdem.paraview`), when
        it is not written yet or the kinds of files changed; a failure is a warning."""
        if not self.view_script:
            return
        kinds = tuple(self._names(0))
        if kinds == self._view_kinds:
            return
        from .paraview import write_view_script
        try:
            write_view_script(self.directory, series={k: f"{k}.pvd" for k in kinds},
                              sim=self._sim)
            self._view_kinds = kinds
        except Exception as e:  # noqa: BLE001 - a picture script must not stop a run
            warnings.warn(f"could not write {self.directory / 'view.py'}: {e!r}")

    def truncate(self, step):
        """The run was rewound to ``step``: forget (and delete) the snapshots written
        after it."""
        dropped = [e for e in self._entries if e[0] > step]
        if not dropped:
            return
        self._entries = [e for e in self._entries if e[0] <= step]
        for _, _, k in dropped:
            for name in self._names(k).values():
                try:
                    os.remove(self.directory / name)
                except FileNotFoundError:
                    pass
        self._write_indices()

    def flush(self, sim=None):
        """End of a run: write ``monitors.h5``; with neither ``every`` nor ``interval``
        also a snapshot of the current state."""
        sim = sim if sim is not None else self._sim
        if sim is None:
            return
        if self.every is None and self.interval is None and sim.n_particles > 0 and \
                not (self._entries and self._entries[-1][0] == sim.steps):
            self.write(sim)
        self.write_monitors(sim)

    def write_monitors(self, sim=None, force=True):
        """Write ``monitors.h5`` now (``force``), or only if it lacks records and
        ``flush_interval`` seconds have passed since the last write."""
        sim = sim if sim is not None else self._sim
        if sim is None:
            return
        mons = getattr(sim, "_monitors", [])
        key = tuple((m.name, len(m.steps), m.steps[-1] if m.steps else None) for m in mons)
        now = _time.monotonic()
        if not force and (key == self._monitors_key or
                          now - self._monitors_at < float(self.flush_interval)):
            return
        write_monitors(sim, self.directory / "monitors.h5")
        self._monitors_key, self._monitors_at = key, now

    def stopped(self, sim):
        """The run stopped on an error other than an interruption or an instability:
        write ``monitors.h5`` (a failure to write is a warning, so that the run's own
        error propagates)."""
        try:
            self.write_monitors(sim)
        except Exception as e:  # noqa: BLE001 - must not hide the run's own error
            warnings.warn(f"could not write monitors.h5 after the run stopped: {e!r}")

    def abort(self, sim, why):
        """The run stopped early (``why``: "interrupted" or "unstable") with the last
        good state in ``sim``: write ``monitors.h5`` and, if ``checkpoint_on_abort``,
        ``last_good.h5`` (its attribute ``abort_reason`` says why). Errors while
        writing are turned into warnings, so that the original error propagates."""
        self.stopped(sim)
        if not self.checkpoint_on_abort:
            return
        path = self.directory / "last_good.h5"
        try:
            sim.save(path)
            import h5py
            with h5py.File(path, "a") as f:
                f.attrs["abort_reason"] = str(why)
        except Exception as e:  # noqa: BLE001
            warnings.warn(f"could not write the checkpoint {path} after the run stopped: {e!r}")

    def close(self, sim=None):
        """Write ``monitors.h5`` now (for the simulation output was set up with)."""
        self.flush(sim)

    def __repr__(self):
        mode = (f"every={self.every}" if self.every is not None else
                f"interval={self.interval}" if self.interval is not None else "end of runs")
        return f"Output({str(self.directory)!r}, {mode}, {len(self._entries)} snapshots)"


# ------------------------------------------------------------------ plots
def plot_histories(source, png_path, names=None, title=None):
    """PNG of monitor histories, one panel per monitor, time (s) on the x axis, the
    unit of each monitor on its axis where its name tells it
    (:func:`tdem.plot.plot_history` with ``panels="monitor"``; that function, as
    ``tdem.plot_history``, also puts monitors of one unit on one panel).

    ``source``: a Simulation (its :meth:`~tdem.Simulation.histories`), the path of a
    ``monitors.h5`` file, or a dict {name: (times, values)}. ``names`` selects and
    orders the monitors (default: all). Vector-valued monitors get one line per
    component. Returns ``png_path``.
    """
    from .plot import plot_history
    png_path = str(png_path)
    plot_history(source, names=names, out=png_path, title=title, panels="monitor")
    return png_path
