"""Triangle meshes for the walls of 3D simulations (:meth:`tdem.Simulation.add_mesh`).

Each helper returns ``(vertices (V, 3), triangles (T, 3))`` with the triangles wound
counter-clockwise seen from the side the particles are meant to be on (the normal
(b − a) × (c − a) points to them); the contact itself does not depend on the
winding. :func:`read` loads any file meshio reads (STL, OBJ, PLY, VTU, …).
"""
import numpy as np

from .errors import InputError


def plane(point, normal, size, divisions=1):
    """A square of side ``size`` centred at ``point``, normal to ``normal``, cut into
    ``divisions`` × ``divisions`` squares of two triangles each."""
    p = np.asarray(point, dtype=float).reshape(3)
    n = np.asarray(normal, dtype=float).reshape(3)
    if not np.linalg.norm(n) > 0:
        raise InputError(f"normal must be a non-zero 3-vector, got {normal!r}")
    n = n / np.linalg.norm(n)
    if not float(size) > 0:
        raise InputError(f"size must be positive, got {size!r}")
    k = int(divisions)
    if k < 1:
        raise InputError(f"divisions must be >= 1, got {divisions!r}")
    t1 = np.cross(n, [1.0, 0.0, 0.0] if abs(n[0]) < 0.9 else [0.0, 1.0, 0.0])
    t1 /= np.linalg.norm(t1)
    t2 = np.cross(n, t1)
    s = np.linspace(-0.5 * size, 0.5 * size, k + 1)
    u, v = np.meshgrid(s, s, indexing="ij")
    verts = p + u.reshape(-1, 1) * t1 + v.reshape(-1, 1) * t2
    tris = []
    for i in range(k):
        for j in range(k):
            a, b = i * (k + 1) + j, (i + 1) * (k + 1) + j
            tris += [[a, b, b + 1], [a, b + 1, a + 1]]
    tris = np.array(tris)
    # wind so that the normal is n
    e = np.cross(verts[tris[:, 1]] - verts[tris[:, 0]], verts[tris[:, 2]] - verts[tris[:, 0]])
    flip = e @ n < 0
    tris[flip] = tris[flip][:, ::-1]
    return verts, tris


def box(lower, upper, open_top=True):
    """The inside of the box [lower, upper] (the floor and four sides; the lid too if
    ``open_top`` is False): normals point inwards."""
    lo = np.asarray(lower, dtype=float).reshape(3)
    hi = np.asarray(upper, dtype=float).reshape(3)
    if not np.all(hi > lo):
        raise InputError(f"upper must exceed lower on every axis, got lower={lower!r}, "
                         f"upper={upper!r}")
    c = np.array([[lo[0], lo[1], lo[2]], [hi[0], lo[1], lo[2]], [hi[0], hi[1], lo[2]],
                  [lo[0], hi[1], lo[2]], [lo[0], lo[1], hi[2]], [hi[0], lo[1], hi[2]],
                  [hi[0], hi[1], hi[2]], [lo[0], hi[1], hi[2]]])
    faces = [(0, 1, 2, 3), (0, 4, 5, 1), (1, 5, 6, 2), (2, 6, 7, 3), (3, 7, 4, 0)]
    if not open_top:
        faces.append((4, 7, 6, 5))
    tris = []
    centre = 0.5 * (lo + hi)
    for q in faces:
        for t in ((q[0], q[1], q[2]), (q[0], q[2], q[3])):
            a, b, cc = c[list(t)]
            nrm = np.cross(b - a, cc - a)
            tris.append(t if np.dot(nrm, centre - a) > 0 else t[::-1])
    return c, np.array(tris)


def cylinder(center, radius, height, segments=32, bottom=True):
    """The inside of a vertical cylinder (axis z) of ``radius`` and ``height`` whose
    bottom centre is ``center``: ``segments`` flat sides, with a floor if ``bottom``."""
    c = np.asarray(center, dtype=float).reshape(3)
    k = int(segments)
    if k < 3:
        raise InputError(f"segments must be >= 3, got {segments!r}")
    if not (float(radius) > 0 and float(height) > 0):
        raise InputError(f"radius and height must be positive, got {radius!r}, {height!r}")
    th = 2 * np.pi * np.arange(k) / k
    ring = np.stack([radius * np.cos(th), radius * np.sin(th), np.zeros(k)], axis=1)
    verts = np.concatenate([c + ring, c + ring + [0.0, 0.0, height], [c]])
    tris = []
    for i in range(k):
        j = (i + 1) % k
        tris += [[i, k + i, j], [j, k + i, k + j]]
        if bottom:
            tris.append([2 * k, j, i])
    tris = np.array(tris)
    # inward normals
    a, b, cc = verts[tris[:, 0]], verts[tris[:, 1]], verts[tris[:, 2]]
    nrm = np.cross(b - a, cc - a)
    mid = (a + b + cc) / 3.0
    inward = np.where((mid[:, 2] - c[2]) < 1e-12 * height, 1.0, 0.0)
    to_axis = np.stack([c[0] - mid[:, 0], c[1] - mid[:, 1], inward * height], axis=1)
    flip = np.einsum("ij,ij->i", nrm, to_axis) < 0
    tris[flip] = tris[flip][:, ::-1]
    return verts, tris


def read(path):
    """(vertices, triangles) of a surface file meshio reads (its triangle cells; quads
    are cut in two)."""
    import meshio

    try:
        m = meshio.read(str(path))
    except Exception as e:          # (meshio raises many kinds)
        raise InputError(f"vertices: cannot read the mesh file {str(path)!r}: {e}") from None
    tris = []
    for block in m.cells:
        if block.type == "triangle":
            tris.append(block.data)
        elif block.type == "quad":
            q = block.data
            tris += [q[:, [0, 1, 2]], q[:, [0, 2, 3]]]
    if not tris:
        raise InputError(f"vertices: the mesh file {str(path)!r} has no triangles "
                         f"(cells: {[b.type for b in m.cells]})")
    return np.asarray(m.points, dtype=float)[:, :3], np.concatenate(tris).astype(np.int64)
