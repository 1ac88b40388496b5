"""The standalone PCMM element system of a set of particles.

:class:`ElementSystem` builds the elements of given positions from scratch with the
rules of :mod:`physics.pcmm.rules`: it bins the particles on a grid, finds their
Eq. 1 neighbours and pruned rings, creates the elements, counts N_e (Eq. 4) and
gives the masses of Eq. 5. A simulation takes its initial elements from it
(:class:`tdem.continuum.Continuum`), :mod:`tdem.pack` the elements of a packing;
:func:`check_rules` checks the rules on given triangles in numpy, independently of
the kernels.
"""
import math

import numpy as np
import taichi as ti

from tdem.core import backend
from tdem.core.arrays import ndarray
from tdem.core.errors import CapacityError, InputError

from ..validate import positive
from .layout import MAX_ELEMENTS
from .rules import _cover, _create, _has, _ring, _sorted3

MAX_CAPACITY = 1024      # largest Eq. 1 neighbour capacity ElementSystem grows to

# indices in the int status array ``flags``
F_NEED = 0               # largest number of Eq. 1 neighbours of any particle
F_OVER = 1               # number of particles whose neighbour list overflowed
FLAGS_SIZE = 4


# ------------------------------------------------------------------ kernels
@ti.func
def _cell(x, gridp: ti.template(), nx: ti.i32, ny: ti.i32):
    cx = ti.cast(ti.floor((x[0] - gridp[0]) / gridp[2]), ti.i32)
    cy = ti.cast(ti.floor((x[1] - gridp[1]) / gridp[2]), ti.i32)
    return ti.math.clamp(cx, 0, nx - 1), ti.math.clamp(cy, 0, ny - 1)


@ti.kernel
def bin_particles(pos: ti.types.ndarray(), gridp: ti.types.ndarray(),
                  gridn: ti.types.ndarray(), cell_count: ti.types.ndarray(),
                  cell_start: ti.types.ndarray(), sorted_ids: ti.types.ndarray(),
                  pcell: ti.types.ndarray()):
    """Counting sort of the particles into the cells of the grid.

    gridp = (x0, y0, h): lower-left corner and cell side; gridn = (nx, ny).
    ``cell_start`` holds nx·ny + ny entries (row totals are kept past the cells).
    """
    n = pos.shape[0]
    nx = gridn[0]
    ny = gridn[1]
    ncell = nx * ny
    for c in range(ncell):
        cell_count[c] = 0
    for i in range(n):
        cx, cy = _cell(pos[i], gridp, nx, ny)
        c = cy * nx + cx
        pcell[i] = c
        ti.atomic_add(cell_count[c], 1)
    # exclusive prefix sum: rows in parallel, then the row offsets serially
    for r in range(ny):
        s = 0
        for cx in range(nx):
            c = r * nx + cx
            cell_start[c] = s
            s += cell_count[c]
        cell_start[ncell + r] = s
    ti.loop_config(serialize=True)
    for _ in range(1):
        s = 0
        for r in range(ny):
            tot = cell_start[ncell + r]
            cell_start[ncell + r] = s
            s += tot
    for c in range(ncell):
        cell_start[c] += cell_start[ncell + c // nx]
        cell_count[c] = 0
    for i in range(n):
        c = pcell[i]
        k = ti.atomic_add(cell_count[c], 1)
        sorted_ids[cell_start[c] + k] = i


@ti.kernel
def find_neighbours(pos: ti.types.ndarray(), rad: ti.types.ndarray(), tol: ti.f64,
                    gridp: ti.types.ndarray(), gridn: ti.types.ndarray(),
                    cell_count: ti.types.ndarray(), cell_start: ti.types.ndarray(),
                    sorted_ids: ti.types.ndarray(), nbr: ti.types.ndarray(),
                    nbr_cnt: ti.types.ndarray(), ring: ti.types.ndarray(),
                    ring_ang: ti.types.ndarray(), ring_cnt: ti.types.ndarray(),
                    flags: ti.types.ndarray()):
    """Eq. 1 neighbour lists (sorted by index) and the pruned angular rings.

    nbr[i, :nbr_cnt[i]]: every j with d_ij ≤ R_i + R_j + δ, increasing j (the list
    is symmetric: j lists i). ring[i, :ring_cnt[i]]: the neighbours left after the
    angular pruning, counter-clockwise; ring_ang holds their angles (radians,
    in (−π, π]). The grid cell side must be ≥ 2·max R + δ.
    """
    n = pos.shape[0]
    cap = nbr.shape[1]
    nx = gridn[0]
    ny = gridn[1]
    for i in range(n):
        xi = pos[i]
        ri = rad[i]
        cx, cy = _cell(xi, gridp, nx, ny)
        cnt = 0
        for dy in ti.static(range(-1, 2)):
            for dx in ti.static(range(-1, 2)):
                ccx = cx + dx
                ccy = cy + dy
                if 0 <= ccx < nx and 0 <= ccy < ny:
                    c = ccy * nx + ccx
                    for s in range(cell_start[c], cell_start[c] + cell_count[c]):
                        j = sorted_ids[s]
                        if j != i:
                            d = pos[j] - xi
                            cut = ri + rad[j] + tol
                            if d.dot(d) <= cut * cut:
                                if cnt < cap:
                                    k = cnt
                                    while k > 0 and nbr[i, k - 1] > j:
                                        nbr[i, k] = nbr[i, k - 1]
                                        k -= 1
                                    nbr[i, k] = j
                                cnt += 1
        ti.atomic_max(flags[F_NEED], cnt)
        if cnt > cap:
            ti.atomic_add(flags[F_OVER], 1)
        m = ti.min(cnt, cap)
        nbr_cnt[i] = m
        for k in range(m, cap):
            nbr[i, k] = -1
        m, ring_ok = _ring(i, xi, m, pos, nbr, ring, ring_ang)
        ring_cnt[i] = m
        for k in range(m, cap):
            ring[i, k] = -1


@ti.kernel
def create_elements(pos: ti.types.ndarray(), rad: ti.types.ndarray(), tol: ti.f64,
                    ring: ti.types.ndarray(), ring_cnt: ti.types.ndarray(),
                    elem: ti.types.ndarray(), ecnt: ti.types.ndarray(),
                    earea: ti.types.ndarray()):
    """Elements (A, i, i+1) of consecutive ring neighbours that pass the creation
    rules: elem[A, s, 0:2] = (i, i+1), earea[A, s] = area S_e, s < ecnt[A]."""
    n = pos.shape[0]
    for a in range(n):
        cnt, created = _create(a, ring_cnt[a], pos[a], rad[a], tol, pos, rad, ring, elem, earea)
        ecnt[a] = cnt
        for s in range(cnt, MAX_ELEMENTS):
            elem[a, s, 0] = -1
            elem[a, s, 1] = -1
            earea[a, s] = 0.0


@ti.kernel
def count_cover(pos: ti.types.ndarray(), nbr: ti.types.ndarray(), nbr_cnt: ti.types.ndarray(),
                elem: ti.types.ndarray(), ecnt: ti.types.ndarray(),
                ncover: ti.types.ndarray()):
    """N_e of every element: how many elements (copies included) strictly contain
    its probe point (weights 0.5, 0.3, 0.2 on the vertices by increasing index)."""
    n = pos.shape[0]
    for a in range(n):
        for s in range(ecnt[a]):
            v0, v1, v2 = _sorted3(a, elem[a, s, 0], elem[a, s, 1])
            count = _cover(v0, v1, v2, pos, nbr, nbr_cnt, elem, ecnt)
            ncover[a, s] = count
        for s in range(ecnt[a], MAX_ELEMENTS):
            ncover[a, s] = 0


@ti.kernel
def element_masses(rad: ti.types.ndarray(), density: ti.f64, nbr: ti.types.ndarray(),
                   nbr_cnt: ti.types.ndarray(), elem: ti.types.ndarray(),
                   ecnt: ti.types.ndarray(), earea: ti.types.ndarray(),
                   ncover: ti.types.ndarray(), mass: ti.types.ndarray()):
    """Eq. 5: M_i = Σ_{e ∋ i} ρ S_e / (3 N_e); ρ π R_i² for a particle in no element.

    Gathered per particle from the elements of i and of its Eq. 1 neighbours, in
    list order (a fixed summation order)."""
    n = rad.shape[0]
    for i in range(n):
        m = 0.0
        k = 0
        for q in range(nbr_cnt[i] + 1):
            o = i
            if q > 0:
                o = nbr[i, q - 1]
            for s in range(ecnt[o]):
                if _has(o, elem[o, s, 0], elem[o, s, 1], i):
                    m += density * earea[o, s] / (3.0 * ncover[o, s])
                    k += 1
        if k == 0:
            m = density * math.pi * rad[i] * rad[i]
        mass[i] = m


# ------------------------------------------------------------------ host side
def _positions(positions, n=None):
    try:
        p = np.asarray(positions, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"positions must be numbers, got {positions!r}") from None
    want = "(N, 2)" if n is None else f"({n}, 2)"
    if p.ndim != 2 or p.shape[1] != 2 or (n is not None and p.shape[0] != n):
        raise InputError(f"positions must have shape {want}, got shape {p.shape}")
    bad = ~np.isfinite(p).all(axis=1)
    if bad.any():
        k = int(np.argmax(bad))
        raise InputError(f"positions must be finite: row {k} is {p[k].tolist()}")
    return np.ascontiguousarray(p)


class ElementSystem:
    """The PCMM element system of a set of particles (see :mod:`physics.pcmm`).

    Parameters
    ----------
    positions : (N, 2) array of particle centres (m)
    radii : float or (N,) array of radii (m), > 0
    tolerance : δ of Eq. 1 (m), ≥ 0
    capacity : initial slots of a particle's Eq. 1 neighbour list; grown (powers
        of two, up to MAX_CAPACITY) when a build overflows it
    arch : Taichi architecture ('cpu' or 'gpu') when Taichi is not yet initialised

    ``build()`` (re)creates the elements for the current positions;
    ``build(positions)`` moves the particles first. ``numpy()`` returns the element
    list, ``masses(density)`` the particle masses of Eq. 5. The device arrays are
    in ``arrays`` (see :meth:`numpy` for their meaning).
    """

    def __init__(self, positions, radii, tolerance, capacity=32, arch=None):
        backend.init(arch)
        pos = _positions(positions)
        n = len(pos)
        if n == 0:
            raise InputError("positions must hold at least one particle, got none")
        try:
            r = np.asarray(radii, dtype=float)
        except (TypeError, ValueError):
            r = None
        if r is None or r.shape not in ((), (n,)):
            raise InputError(f"radii must be a number or an array of {n} numbers, "
                             f"got {radii!r}")
        r = np.broadcast_to(r, (n,)).copy()
        bad = ~(np.isfinite(r) & (r > 0))
        if bad.any():
            k = int(np.argmax(bad))
            raise InputError(f"radii must be positive: radius {k} is {r[k]!r}")
        try:
            tol = float(tolerance)
        except (TypeError, ValueError):
            raise InputError(f"tolerance must be a number >= 0, got {tolerance!r}") from None
        if not (tol >= 0.0 and math.isfinite(tol)):
            raise InputError(f"tolerance must be a number >= 0, got {tolerance!r}")
        if int(capacity) < 1:
            raise InputError(f"capacity must be >= 1, got {capacity!r}")
        self.n = n
        self.tolerance = tol
        self.capacity = 1 << (int(capacity) - 1).bit_length()
        self.neighbour_need = 0
        self._radii = r
        self._pos = pos
        self.arrays = {}
        self._allocate()
        self.arrays["rad"].from_numpy(r)
        self._built = False

    # ------------------------------------------------------------- arrays
    def _allocate(self):
        n, cap = self.n, self.capacity
        a = self.arrays
        if "pos" not in a:
            a["pos"] = ndarray(2, ti.f64, (n,))
            a["rad"] = ti.ndarray(ti.f64, (n,))
            a["elem"] = ti.ndarray(ti.i32, (n, MAX_ELEMENTS, 2))
            a["ecnt"] = ti.ndarray(ti.i32, (n,))
            a["earea"] = ti.ndarray(ti.f64, (n, MAX_ELEMENTS))
            a["ncover"] = ti.ndarray(ti.i32, (n, MAX_ELEMENTS))
            a["flags"] = ti.ndarray(ti.i32, (FLAGS_SIZE,))
            a["sorted"] = ti.ndarray(ti.i32, (n,))
            a["pcell"] = ti.ndarray(ti.i32, (n,))
            a["gridp"] = ti.ndarray(ti.f64, (3,))
            a["gridn"] = ti.ndarray(ti.i32, (2,))
            a["mass"] = ti.ndarray(ti.f64, (n,))
        a["nbr"] = ti.ndarray(ti.i32, (n, cap))
        a["nbr_cnt"] = ti.ndarray(ti.i32, (n,))
        a["ring"] = ti.ndarray(ti.i32, (n, cap))
        a["ring_ang"] = ti.ndarray(ti.f64, (n, cap))
        a["ring_cnt"] = ti.ndarray(ti.i32, (n,))

    def _fit_grid(self):
        """Cell side h = 2·max R + δ (the largest Eq. 1 cut-off) over the particles'
        bounding box, coarsened if the box would need more than 4N + 1024 cells."""
        h = 2.0 * float(self._radii.max()) + self.tolerance
        lo = self._pos.min(axis=0) - h
        span = self._pos.max(axis=0) + h - lo
        nx, ny = (np.floor(span / h).astype(np.int64) + 1)
        while nx * ny > 4 * self.n + 1024:
            h *= 1.5
            nx, ny = (np.floor(span / h).astype(np.int64) + 1)
        a = self.arrays
        ncell = int(nx * ny)
        if "cell_count" not in a or a["cell_count"].shape[0] < ncell or \
                a["cell_start"].shape[0] < ncell + int(ny):
            a["cell_count"] = ti.ndarray(ti.i32, (ncell,))
            a["cell_start"] = ti.ndarray(ti.i32, (ncell + int(ny),))
        a["gridp"].from_numpy(np.array([lo[0], lo[1], h]))
        a["gridn"].from_numpy(np.array([nx, ny], dtype=np.int32))

    # ------------------------------------------------------------- build
    def build(self, positions=None):
        """Create the element system for the current (or the given) positions."""
        if positions is not None:
            self._pos = _positions(positions, self.n)
        a = self.arrays
        a["pos"].from_numpy(self._pos)
        self._fit_grid()
        bin_particles(a["pos"], a["gridp"], a["gridn"], a["cell_count"], a["cell_start"],
                      a["sorted"], a["pcell"])
        while True:
            a["flags"].from_numpy(np.zeros(FLAGS_SIZE, np.int32))
            find_neighbours(a["pos"], a["rad"], self.tolerance, a["gridp"], a["gridn"],
                            a["cell_count"], a["cell_start"], a["sorted"], a["nbr"],
                            a["nbr_cnt"], a["ring"], a["ring_ang"], a["ring_cnt"],
                            a["flags"])
            flags = a["flags"].to_numpy()
            self.neighbour_need = int(flags[F_NEED])
            if flags[F_OVER] == 0:
                break
            need = 1 << (self.neighbour_need - 1).bit_length()
            if need > MAX_CAPACITY:
                raise CapacityError(f"a particle has {self.neighbour_need} Eq. 1 neighbours, "
                                    f"more than MAX_CAPACITY={MAX_CAPACITY}: is the "
                                    f"tolerance ({self.tolerance} m) far larger than the radii?")
            self.capacity = need
            self._allocate()
        create_elements(a["pos"], a["rad"], self.tolerance, a["ring"], a["ring_cnt"],
                        a["elem"], a["ecnt"], a["earea"])
        count_cover(a["pos"], a["nbr"], a["nbr_cnt"], a["elem"], a["ecnt"], a["ncover"])
        self._built = True
        return self

    def _require_built(self):
        if not self._built:
            self.build()

    # ------------------------------------------------------------- results
    def numpy(self):
        """The element list (union of the particles' slots, copies included, ordered
        by owner then slot) as a dict of numpy arrays:

        - ``triangles`` (E, 3): particle indices (owner, i, i+1), counter-clockwise;
        - ``owner`` (E,): the particle that created the element (= triangles[:, 0]);
        - ``area`` (E,): S_e (m²);
        - ``n_cover`` (E,): N_e of the superposition rule;
        - ``weight`` (E,): 1/N_e, the factor of the element's nodal forces (Eq. 14).
        """
        self._require_built()
        a = self.arrays
        ecnt = a["ecnt"].to_numpy()
        owner = np.repeat(np.arange(self.n), ecnt)
        slot = np.arange(len(owner)) - np.repeat(np.cumsum(ecnt) - ecnt, ecnt)
        elem = a["elem"].to_numpy()[owner, slot]
        ncov = a["ncover"].to_numpy()[owner, slot]
        return {
            "triangles": np.column_stack([owner, elem]).astype(np.int64),
            "owner": owner.astype(np.int64),
            "area": a["earea"].to_numpy()[owner, slot],
            "n_cover": ncov.astype(np.int64),
            "weight": 1.0 / ncov,
        }

    def neighbours(self):
        """Eq. 1 neighbour lists and pruned rings, as lists of index arrays."""
        self._require_built()
        a = self.arrays
        nbr, nc = a["nbr"].to_numpy(), a["nbr_cnt"].to_numpy()
        ring, rc = a["ring"].to_numpy(), a["ring_cnt"].to_numpy()
        return ([nbr[i, :nc[i]] for i in range(self.n)],
                [ring[i, :rc[i]] for i in range(self.n)])

    def masses(self, density):
        """Particle masses of Eq. 5 for the density ρ (kg/m³), per metre of thickness."""
        rho = positive("density", density)
        self._require_built()
        a = self.arrays
        element_masses(a["rad"], rho, a["nbr"], a["nbr_cnt"], a["elem"], a["ecnt"],
                       a["earea"], a["ncover"], a["mass"])
        return a["mass"].to_numpy()


def check_rules(positions, radii, tolerance, triangles, rtol=1e-9):
    """Check the creation rules on given triangles (numpy, independent of the kernels).

    Returns a dict of boolean arrays (E,), True where the rule holds:
    ``orientation`` (counter-clockwise, non-degenerate), ``contact`` (Eq. 1 for the
    three pairs), ``angle`` (Eq. 2: every interior angle in [30°, 150°]), ``edge``
    (Eq. 3: every edge ≥ 0.5 × the mean radius), and ``ok`` (all of them). Bounds
    are relaxed by ``rtol`` (relative) for round-off.
    """
    x = np.asarray(positions, dtype=float)
    t = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    r = np.broadcast_to(np.asarray(radii, dtype=float), (len(x),))
    p = x[t]                                   # (E, 3, 2)
    rr = r[t]                                  # (E, 3)
    e = np.roll(p, -1, axis=1) - p             # edge k: vertex k -> k+1
    length = np.linalg.norm(e, axis=2)
    cut = rr + np.roll(rr, -1, axis=1) + tolerance
    contact = np.all(length <= cut * (1 + rtol), axis=1)
    edge = np.all(length >= 0.5 * rr.mean(axis=1)[:, None] * (1 - rtol), axis=1)
    cross = e[:, 0, 0] * e[:, 1, 1] - e[:, 0, 1] * e[:, 1, 0]
    orientation = cross > 0
    # interior angle at vertex k between edges k (outgoing) and k-1 (incoming, reversed)
    u = e
    v = -np.roll(e, 1, axis=1)
    cosang = np.einsum("eki,eki->ek", u, v) / np.maximum(
        length * np.roll(length, 1, axis=1), 1e-300)
    ang = np.degrees(np.arccos(np.clip(cosang, -1.0, 1.0)))
    angle = np.all((ang >= 30.0 * (1 - rtol)) & (ang <= 150.0 * (1 + rtol)), axis=1)
    ok = contact & edge & orientation & angle
    return {"orientation": orientation, "contact": contact, "angle": angle, "edge": edge,
            "ok": ok}
