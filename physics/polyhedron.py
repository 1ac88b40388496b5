"""Convex polyhedra (Chen's polyhedral DEM): the host-side description.

:class:`Polyhedron` takes any points and keeps their convex hull (scipy's Qhull):

- the solid's volume, centroid and inertia tensor, exactly, from the tetrahedra of the
  hull's triangles (the covariance of each tetrahedron, Tonon 2004);
- the body frame: the centroid as origin and the principal axes of inertia as axes
  (:attr:`Polyhedron.vertices` are in that frame; :attr:`Polyhedron.rotation` turns them
  back to the frame of the points given);
- faces (coplanar hull triangles merged into one polygon) as planes n·x <= d with outward
  unit normals, edges with their two faces, a triangulation of the surface;
- its characteristic length l = V^(1/3), bounding radius (the largest vertex distance
  from the centroid) and inscribed radius (the nearest face plane).

The engine keeps every distinct polyhedron of a simulation in two tables (one row per
shape, :meth:`Polyhedron.table_rows`); fixed capacities keep the kernels free of
allocation: at most :data:`MAX_VERTICES` vertices and :data:`MAX_FACES` faces (a larger
hull is refused with a clear error).
"""
import math

import numpy as np

from tdem.core.errors import InputError

from .shapes import quaternion_rotations
from .validate import positive

MAX_VERTICES = 32
MAX_FACES = 60
MAX_EDGES = MAX_VERTICES + MAX_FACES - 2      # Euler: V − E + F = 2
MAX_TRIANGLES = 2 * MAX_VERTICES - 4

# the float row: counts and scalars, then vertices (x, y, z) and planes (nx, ny, nz, d)
PT_NV, PT_NF, PT_NE, PT_NT, PT_VOLUME, PT_LENGTH, PT_RADIUS = range(7)
PT_VERTS = 8
PT_PLANES = PT_VERTS + 3 * MAX_VERTICES
PT_WIDTH = PT_PLANES + 4 * MAX_FACES
# the integer row: edges (v0, v1, f0, f1), then surface triangles (v0, v1, v2)
PI_EDGES = 0
PI_TRIS = 4 * MAX_EDGES
PI_WIDTH = PI_TRIS + 3 * MAX_TRIANGLES


class Polyhedron:
    """A convex polyhedron: the convex hull of ``vertices`` (V, 3) in m.

    Given to :meth:`tdem.Simulation.add_particles` as ``shape=`` in a 3D simulation, at
    ``positions`` (the centroids), turned by ``orientation=`` (unit quaternions from the
    body frame, :attr:`rotation`, to the world). Its contacts take
    :class:`tdem.VolumeContact`."""

    kind = "polyhedron"

    def __init__(self, vertices):
        from scipy.spatial import ConvexHull
        from scipy.spatial import QhullError

        try:
            pts = np.array(vertices, dtype=float)
        except (TypeError, ValueError):
            raise InputError(f"vertices must be an array (V, 3) of numbers, got "
                             f"{vertices!r}") from None
        if pts.ndim != 2 or pts.shape[1] != 3:
            raise InputError(f"vertices must have shape (V, 3), got {pts.shape}")
        if not np.isfinite(pts).all():
            k = int(np.argmax(~np.isfinite(pts).all(axis=1)))
            raise InputError(f"vertices must be finite: vertex {k} is {pts[k].tolist()}")
        if len(pts) < 4:
            raise InputError(f"vertices: a polyhedron needs at least 4 non-coplanar "
                             f"vertices, got {len(pts)}")
        try:
            hull = ConvexHull(pts)
        except QhullError:
            raise InputError("vertices: the points are flat (coplanar or collinear); a "
                             "polyhedron needs 4 non-coplanar vertices") from None
        ext = float(np.ptp(pts, axis=0).max())
        if hull.volume <= 1e-9 * ext ** 3:
            raise InputError(f"vertices: the polyhedron is flat (volume {hull.volume:.3g} "
                             f"m³ for an extent of {ext:.3g} m)")
        keep = np.sort(hull.vertices)
        if len(keep) > MAX_VERTICES:
            raise InputError(f"vertices: the hull has {len(keep)} vertices; a polyhedron "
                             f"may have at most {MAX_VERTICES}")
        self.input_vertices = pts
        p = pts[keep]
        remap = {int(k): i for i, k in enumerate(keep)}
        tris = np.array([[remap[int(k)] for k in s] for s in hull.simplices])
        # outward orientation of each hull triangle
        eq = hull.equations
        for t in range(len(tris)):
            a, b, c = p[tris[t]]
            if np.cross(b - a, c - a) @ eq[t, :3] < 0:
                tris[t] = tris[t][[0, 2, 1]]
        vol, centroid, inertia = _mass_properties(p, tris)
        moments, axes = _principal_axes(inertia)
        self.volume = vol
        self.centroid = centroid                 # in the frame of the points given
        self.rotation = axes                     # body frame -> frame of the points given
        self.principal_moments = moments / vol   # per unit mass (m²)
        v = (p - centroid) @ axes
        self.vertices = v
        self._faces(v, tris)
        if len(self.faces) > MAX_FACES:
            raise InputError(f"vertices: the hull has {len(self.faces)} faces; a polyhedron "
                             f"may have at most {MAX_FACES}")

    # ------------------------------------------------------------------ topology
    def _faces(self, v, tris):
        """Merge the hull's coplanar triangles into faces; planes, edges, triangles."""
        scale = float(np.abs(v).max())
        tol = 1e-9 * scale
        normals = np.cross(v[tris[:, 1]] - v[tris[:, 0]], v[tris[:, 2]] - v[tris[:, 0]])
        normals /= np.linalg.norm(normals, axis=1, keepdims=True)
        offsets = np.einsum("ij,ij->i", normals, v[tris[:, 0]])
        group = -np.ones(len(tris), int)
        planes = []
        for t in range(len(tris)):
            for g, (n, d) in enumerate(planes):
                if n @ normals[t] > 1.0 - 1e-9 and abs(d - offsets[t]) <= tol:
                    group[t] = g
                    break
            else:
                group[t] = len(planes)
                planes.append((normals[t], offsets[t]))
        faces = []
        for g, (n, d) in enumerate(planes):
            on = np.nonzero(np.abs(v @ n - d) <= 1e-7 * scale)[0]
            c = v[on].mean(axis=0)
            u = v[on[0]] - c
            u /= np.linalg.norm(u)
            w = np.cross(n, u)
            ang = np.arctan2((v[on] - c) @ w, (v[on] - c) @ u)
            faces.append(on[np.argsort(ang)])      # counter-clockwise about n
        self.faces = faces
        self.planes = np.array([np.r_[n, d] for n, d in planes])
        owners = {}
        for f, poly in enumerate(faces):
            for k in range(len(poly)):
                a, b = int(poly[k]), int(poly[(k + 1) % len(poly)])
                owners.setdefault((min(a, b), max(a, b)), []).append(f)
        edges = [(a, b, fs[0], fs[1]) for (a, b), fs in sorted(owners.items())]
        self.edges = np.array(edges, dtype=np.int64).reshape(-1, 4)
        tri = []
        for poly in faces:
            for k in range(1, len(poly) - 1):
                tri.append((poly[0], poly[k], poly[k + 1]))
        self.triangles = np.array(tri, dtype=np.int64)

    # ------------------------------------------------------------------ properties
    def __repr__(self):
        return (f"Polyhedron({len(self.vertices)} vertices, {len(self.faces)} faces, "
                f"volume={self.volume:.6g})")

    def __eq__(self, other):
        return isinstance(other, Polyhedron) and self.vertices.shape == other.vertices.shape \
            and np.array_equal(self.vertices, other.vertices)

    def __hash__(self):
        return hash(self.vertices.tobytes())

    def to_dict(self):
        return {"kind": self.kind, "vertices": self.input_vertices.tolist()}

    @property
    def length(self):
        """Characteristic length l = V^(1/3) (m; Chen's polyhedral DEM)."""
        return self.volume ** (1.0 / 3.0)

    @property
    def bounding_radius(self):
        """Largest distance of a vertex from the centroid (m)."""
        return float(np.linalg.norm(self.vertices, axis=1).max())

    @property
    def inscribed_radius(self):
        """Distance from the centroid to the nearest face plane (m)."""
        return float(self.planes[:, 3].min())

    def inertia(self, mass):
        """Principal moments of inertia (kg m²) for ``mass``, along the body axes."""
        return self.principal_moments * mass

    def surface(self, centres=None, orientations=None):
        """Triangulated surfaces: (points (N·V, 3), triangles (N·T, 3)) of the shape at
        ``centres`` (N, 3) turned by unit quaternions ``orientations`` (N, 4); the
        body-frame surface when both are None."""
        if centres is None:
            return self.vertices.copy(), self.triangles.copy()
        x = np.asarray(centres, float).reshape(-1, 3)
        q = np.asarray(orientations, float).reshape(-1, 4)
        rot = quaternion_rotations(q)
        pts = x[:, None, :] + np.einsum("nij,vj->nvi", rot, self.vertices)
        nv = len(self.vertices)
        tri = (self.triangles[None, :, :] + nv * np.arange(len(x))[:, None, None])
        return pts.reshape(-1, 3), tri.reshape(-1, 3)

    def table_rows(self):
        """(float row (PT_WIDTH,), integer row (PI_WIDTH,)) of the engine's shape tables."""
        f = np.zeros(PT_WIDTH)
        i = np.zeros(PI_WIDTH, dtype=np.int32)
        f[PT_NV] = len(self.vertices)
        f[PT_NF] = len(self.planes)
        f[PT_NE] = len(self.edges)
        f[PT_NT] = len(self.triangles)
        f[PT_VOLUME] = self.volume
        f[PT_LENGTH] = self.length
        f[PT_RADIUS] = self.bounding_radius
        f[PT_VERTS:PT_VERTS + self.vertices.size] = self.vertices.ravel()
        f[PT_PLANES:PT_PLANES + self.planes.size] = self.planes.ravel()
        i[PI_EDGES:PI_EDGES + self.edges.size] = self.edges.ravel()
        i[PI_TRIS:PI_TRIS + self.triangles.size] = self.triangles.ravel()
        return f, i

    # ------------------------------------------------------------------ makers
    @classmethod
    def box(cls, a, b, c):
        """A rectangular box of edges a, b, c (m) along x, y, z."""
        a, b, c = positive("a", a), positive("b", b), positive("c", c)
        s = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
        return cls(0.5 * s * [a, b, c])

    @classmethod
    def cube(cls, side):
        """A cube of edge ``side`` (m)."""
        side = positive("side", side)
        return cls.box(side, side, side)

    @classmethod
    def regular(cls, name, size=1.0):
        """A Platonic solid ("tetrahedron", "cube", "octahedron", "dodecahedron",
        "icosahedron") with circumradius ``size`` (m)."""
        size = positive("size", size)
        phi = (1.0 + math.sqrt(5.0)) / 2.0
        sets = {
            "tetrahedron": [[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]],
            "cube": [[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)],
            "octahedron": [[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1],
                           [0, 0, -1]],
            "icosahedron": [[0, s1, s2 * phi] for s1 in (-1, 1) for s2 in (-1, 1)]
            + [[s1, s2 * phi, 0] for s1 in (-1, 1) for s2 in (-1, 1)]
            + [[s2 * phi, 0, s1] for s1 in (-1, 1) for s2 in (-1, 1)],
            "dodecahedron": [[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
            + [[0, s1 / phi, s2 * phi] for s1 in (-1, 1) for s2 in (-1, 1)]
            + [[s1 / phi, s2 * phi, 0] for s1 in (-1, 1) for s2 in (-1, 1)]
            + [[s2 * phi, 0, s1 / phi] for s1 in (-1, 1) for s2 in (-1, 1)],
        }
        if name not in sets:
            raise InputError(f"name must be one of {sorted(sets)}, got {name!r}")
        p = np.array(sets[name], float)
        p *= size / np.linalg.norm(p, axis=1).max()
        return cls(p)

    @classmethod
    def random(cls, vertices=12, elongation=1.0, size=1.0, seed=0):
        """A random convex polyhedron: the hull of ``vertices`` random points on an
        ellipsoid of semi-axes (elongation, 1, 1) × size/elongation… scaled so that its
        longest semi-axis is ``size`` (m); ``elongation`` >= 1 is the ratio of the
        longest to the shortest axis."""
        try:
            nv = int(vertices)
        except (TypeError, ValueError):
            raise InputError(f"vertices must be an integer in [4, {MAX_VERTICES}], got "
                             f"{vertices!r}") from None
        if not 4 <= nv <= MAX_VERTICES or nv != vertices:
            raise InputError(f"vertices must be an integer in [4, {MAX_VERTICES}], got "
                             f"{vertices!r}")
        el = positive("elongation", elongation)
        if el < 1.0:
            raise InputError(f"elongation must be >= 1 (longest over shortest axis), got "
                             f"{elongation!r}")
        size = positive("size", size)
        rng = np.random.default_rng(seed)
        for _ in range(100):
            d = rng.normal(size=(nv, 3))
            d /= np.linalg.norm(d, axis=1, keepdims=True)
            p = d * np.array([1.0, 1.0 / el, 1.0 / el]) * size
            try:
                shape = cls(p)
            except InputError:
                continue
            if len(shape.vertices) == nv:
                return shape
        raise InputError(f"no convex polyhedron of {nv} vertices found (seed {seed!r})")


def _principal_axes(inertia):
    """(moments, axes as columns) of the inertia tensor, right-handed, the axes as near
    to the given ones as the tensor allows: among equal moments (a cube, a square
    prism) the given axes are kept, and the axes are ordered and signed as the given
    x, y, z they lie nearest to (so that a box built along x, y, z keeps its frame)."""
    from scipy.optimize import linear_sum_assignment

    moments, axes = np.linalg.eigh(inertia)
    scale = max(abs(moments).max(), 1e-300)
    groups, k = [], 0
    while k < 3:
        g = [k]
        while g[-1] + 1 < 3 and moments[g[-1] + 1] - moments[g[0]] <= 1e-9 * scale:
            g.append(g[-1] + 1)
        groups.append(g)
        k = g[-1] + 1
    eye = np.eye(3)
    for g in groups:
        if len(g) == 3:
            axes = eye.copy()
        elif len(g) == 2:
            q = axes[:, g]
            proj = q @ q.T @ eye                    # the given axes projected on the plane
            a1 = proj[:, int(np.argmax(np.linalg.norm(proj, axis=0)))]
            a1 /= np.linalg.norm(a1)
            other = [k for k in range(3) if k not in g][0]
            a2 = np.cross(axes[:, other], a1)
            axes[:, g[0]], axes[:, g[1]] = a1, a2
    rows, cols = linear_sum_assignment(-np.abs(axes))   # axis j of the body -> given rows[j]
    order = np.empty(3, int)
    order[rows] = cols
    axes = axes[:, order]
    moments = moments[order]
    axes *= np.where(np.diag(axes) < 0, -1.0, 1.0)
    if np.linalg.det(axes) < 0:
        axes[:, 2] *= -1.0
    return moments, axes


def _mass_properties(p, tris):
    """(volume, centroid, inertia tensor about the centroid per unit density) of the
    solid bounded by the outward triangles ``tris`` of points ``p``: the sum over the
    tetrahedra (o, a, b, c), o inside, of their covariance det(A) A C₀ Aᵀ with
    C₀ = (1 + δ_ij)/120 (Tonon 2004)."""
    o = p.mean(axis=0)
    c0 = (np.ones((3, 3)) + np.eye(3)) / 120.0
    vol = 0.0
    first = np.zeros(3)
    cov = np.zeros((3, 3))
    for t in tris:
        A = (p[t] - o).T                    # columns a − o, b − o, c − o
        det = float(np.linalg.det(A))
        vol += det / 6.0
        first += det / 6.0 * A.sum(axis=1) / 4.0
        cov += det * A @ c0 @ A.T
    centroid = first / vol
    cov -= vol * np.outer(centroid, centroid)      # about the centroid (o cancels)
    inertia = np.trace(cov) * np.eye(3) - cov
    return vol, o + centroid, inertia

