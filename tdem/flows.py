"""Particles that enter and leave a running model: inserters and outlets.

:meth:`tdem.Simulation.insert` makes an :class:`Inserter`: particles of a radius, a
grading (:mod:`tdem.gradings`) or a shape, placed without overlap at random in a region
(a box, which may be flat: a plane of pluviation; a sphere, a circle in 2D; a polygon in
2D), at a rate (kg/s, or kg/s per metre of thickness in 2D; or particles per second), up
to a count or a time. :meth:`tdem.Simulation.remove_in` makes an :class:`Outlet`: the
particles whose centres enter its region are removed and counted (number, mass, when).

Both act between run segments (every ``check_interval`` steps, where the engine looks at
the device anyway): an inserter places the particles due by the end of the coming
segment, an outlet removes those inside it then. Either rebuilds the engine's arrays for
the new particle count (``Runner._rebuild_from``: the kernels take arrays of any length,
nothing is compiled again); the cost is one download and upload of the state per event,
reported by ``benchmarks/flows.py``.

Every particle has an identity (``sim.particles.numpy()["id"]``, the ``id`` array of the
output files) that it keeps while particles before it leave: an index counts the
particles there now, an identity counts every particle ever added. Groups, prescribed
velocities and loads keep pointing at the same particles after a removal; particles with
prescribed velocities or applied loads are never removed (they are machinery). The
energy account stays closed: ``energy()["inflow"]`` is the energy the inserted particles
brought (kinetic and gravitational), ``energy()["outflow"]`` what the removed ones took
away (with their contact springs), and the removed particles' booked work and
dissipation stay in the sums.

Models with PCMM bodies or blocks take neither (their elements join particles by index).
"""
import math
import warnings

import numpy as np
import taichi as ti

from physics.shapes import Superellipse
from physics.validate import positive

from . import state as schema
from .errors import InputError
from .gradings import Grading
from .neighbors import F_REBUILD

PLACE_TRIES = 60      # random positions tried for one particle before the batch stops


# ------------------------------------------------------------------ regions
class Region:
    """Where particles are inserted or removed: ``box`` (two corners; an axis of zero
    width is a plane), ``sphere`` (centre, radius; a circle in 2D) or ``polygon``
    (2D: its corners in order)."""

    def __init__(self, dim, box=None, sphere=None, polygon=None):
        given = [k for k, v in (("box", box), ("sphere", sphere), ("polygon", polygon))
                 if v is not None]
        if len(given) != 1:
            raise InputError(f"give exactly one of box=, sphere=, polygon=, got "
                             f"{given or 'none'}")
        self.dim = dim
        self.kind = given[0]
        if box is not None:
            try:
                a = np.asarray(box, dtype=float)
            except (TypeError, ValueError):
                raise InputError(f"box must be two corners ((x0, y0{', z0' * (dim == 3)}), "
                                 f"(x1, y1{', z1' * (dim == 3)})), got {box!r}") from None
            if a.shape != (2, dim) or not np.isfinite(a).all():
                raise InputError(f"box must be two corners of {dim} finite numbers, got "
                                 f"{box!r}")
            self.lo, self.hi = a.min(axis=0), a.max(axis=0)
        elif sphere is not None:
            try:
                c, r = sphere
                c = np.asarray(c, dtype=float)
                r = float(r)
            except (TypeError, ValueError):
                raise InputError(f"sphere must be (centre, radius), got {sphere!r}") from None
            if c.shape != (dim,) or not np.isfinite(c).all() or not (r > 0 and
                                                                      math.isfinite(r)):
                raise InputError(f"sphere must be (centre of {dim} finite numbers, radius "
                                 f"> 0), got {sphere!r}")
            self.centre, self.radius = c, r
            self.lo, self.hi = c - r, c + r
        else:
            if dim != 2:
                raise InputError("polygon: a region given by a polygon is 2D; a 3D model "
                                 "takes box= or sphere=")
            try:
                p = np.asarray(polygon, dtype=float)
            except (TypeError, ValueError):
                raise InputError(f"polygon must be its corners (K, 2), got {polygon!r}") from None
            if p.ndim != 2 or p.shape[1] != 2 or len(p) < 3 or not np.isfinite(p).all():
                raise InputError(f"polygon must be at least 3 corners (K, 2) of finite "
                                 f"numbers, got {polygon!r}")
            area = 0.5 * np.sum(p[:, 0] * np.roll(p[:, 1], -1) - np.roll(p[:, 0], -1) * p[:, 1])
            if abs(area) <= 0.0:
                raise InputError(f"polygon has no area, got {polygon!r}")
            self.corners = p
            self.lo, self.hi = p.min(axis=0), p.max(axis=0)

    def params(self):
        """(kind code, parameters (8,), polygon corners (K, 2)) for :func:`_mark`."""
        par = np.zeros(8)
        poly = np.zeros((1, 2))
        if self.kind == "box":
            par[:self.dim], par[3:3 + self.dim] = self.lo, self.hi
            return 0, par, poly
        if self.kind == "sphere":
            par[:self.dim], par[3] = self.centre, self.radius
            return 1, par, poly
        par[0] = len(self.corners)
        return 2, par, self.corners

    def contains(self, x):
        """Which points (N, dim) lie inside (boundaries included)."""
        x = np.asarray(x, dtype=float).reshape(-1, self.dim)
        if self.kind == "box":
            return np.all((x >= self.lo) & (x <= self.hi), axis=1)
        if self.kind == "sphere":
            return np.einsum("ij,ij->i", x - self.centre, x - self.centre) <= self.radius ** 2
        from matplotlib.path import Path
        return Path(self.corners).contains_points(x, radius=1e-12)

    def sample(self, rng, r):
        """A random point where a particle of radius ``r`` lies inside (a flat box's
        thin axes excepted: the particle's centre lies on its plane); None if it does
        not fit."""
        if self.kind == "sphere":
            room = self.radius - r
            if room < 0:
                return None
            d = rng.normal(size=self.dim)
            d /= max(np.linalg.norm(d), 1e-300)
            return self.centre + d * room * rng.random() ** (1.0 / self.dim)
        lo, hi = self.lo.copy(), self.hi.copy()
        wide = (hi - lo) > 0
        lo[wide] += r
        hi[wide] -= r
        if np.any(hi < lo):
            return None
        for _ in range(20 if self.kind == "polygon" else 1):
            x = lo + (hi - lo) * rng.random(self.dim)
            if self.kind == "box" or self._inside_by(x, r):
                return x
        return None

    def _inside_by(self, x, r):
        p = self.corners
        if not self.contains(x[None])[0]:
            return False
        a, b = p, np.roll(p, -1, axis=0)
        ab = b - a
        t = np.clip(np.einsum("ij,ij->i", x - a, ab) / np.einsum("ij,ij->i", ab, ab), 0, 1)
        d = np.linalg.norm(a + t[:, None] * ab - x, axis=1)
        return bool(d.min() >= r)

    def to_dict(self):
        if self.kind == "box":
            return {"box": [self.lo.tolist(), self.hi.tolist()]}
        if self.kind == "sphere":
            return {"sphere": [self.centre.tolist(), self.radius]}
        return {"polygon": self.corners.tolist()}


@ti.kernel
def _mark(pos: ti.types.ndarray(), fix: ti.types.ndarray(), kind: ti.i32,
          par: ti.types.ndarray(), poly: ti.types.ndarray(), mark: ti.types.ndarray(),
          dim: ti.template()) -> ti.i32:
    """mark[i] = 1 for the particles whose centre lies in the region (none with a
    prescribed velocity); returns how many."""
    count = 0
    for i in range(pos.shape[0]):
        x = pos[i]
        inside = 0
        if fix[i] == 0:
            if kind == 0:
                inside = 1
                for k in ti.static(range(dim)):
                    if x[k] < par[k] or x[k] > par[3 + k]:
                        inside = 0
            elif kind == 1:
                d2 = 0.0
                for k in ti.static(range(dim)):
                    d2 += (x[k] - par[k]) ** 2
                if d2 <= par[3] * par[3]:
                    inside = 1
            else:
                # crossings of a ray along +x (even-odd rule)
                nc = ti.cast(par[0], ti.i32)
                for e in range(nc):
                    ax, ay = poly[e, 0], poly[e, 1]
                    bx, by = poly[(e + 1) % nc, 0], poly[(e + 1) % nc, 1]
                    if (ay > x[1]) != (by > x[1]):
                        xc = ax + (x[1] - ay) * (bx - ax) / (by - ay)
                        if x[0] < xc:
                            inside = 1 - inside
        mark[i] = inside
        count += inside
    return count


# ------------------------------------------------------------------ inserters
class Inserter:
    """Particles entering the model (:meth:`tdem.Simulation.insert`). ``mass`` and
    ``count``: inserted so far; ``ids`` their identities and ``times`` when each came
    in; :meth:`stop` ends it."""

    def __init__(self, sim, region, rate=None, count=None, per_s=None, radius=None,
                 grading=None, density=2500.0, contact=None, velocity=None, shape=None,
                 orientation="random", until=None, seed=0, every=None):
        dim = sim.dim
        self._sim = sim
        self.region = region
        if rate is not None and per_s is not None:
            raise InputError(f"give rate= (kg/s) or per_s= (particles/s), not both (got "
                             f"rate={rate!r}, per_s={per_s!r})")
        if rate is None and per_s is None and count is None:
            raise InputError("give rate= (kg/s), per_s= (particles/s) or count= (a number "
                             "of particles, placed as soon as there is room)")
        self.rate = None if rate is None else positive("rate", rate)
        self.per_s = None if per_s is None else positive("per_s", per_s)
        if count is not None and (isinstance(count, bool) or int(count) != count or count < 1):
            raise InputError(f"count must be a whole number >= 1, got {count!r}")
        self.limit = None if count is None else int(count)
        given = [k for k, v in (("radius", radius), ("grading", grading), ("shape", shape))
                 if v is not None]
        if len(given) != 1:
            raise InputError(f"give one of radius=, grading=, shape= for the inserted "
                             f"particles, got {given or 'none'}")
        if grading is not None and not isinstance(grading, Grading):
            raise InputError(f"grading must be a tdem.grading(...), got {grading!r}")
        self.radius = None if radius is None else positive("radius", radius)
        self.grading = grading
        self.shape = shape
        self.density = positive("density", density)
        if contact is None:
            raise InputError("contact must be given: a law such as tdem.LinearContact(...)")
        sim._law_id(contact)                      # checked (and known to the model) now
        self.contact = contact
        v = np.zeros(dim) if velocity is None else np.asarray(velocity, dtype=float)
        if v.shape != (dim,) or not np.isfinite(v).all():
            raise InputError(f"velocity must be {dim} finite numbers, got {velocity!r}")
        self.velocity = v
        if orientation not in ("random", None):
            raise InputError(f"orientation must be 'random' or None (unturned), got "
                             f"{orientation!r}")
        self.orientation = orientation
        self.until = None if until is None else float(until)
        if self.until is not None and not math.isfinite(self.until):
            raise InputError(f"until must be a finite time, got {until!r}")
        if shape is not None and not hasattr(shape, "bounding_radius"):
            raise InputError(f"shape must be a shape such as tdem.Superellipse, "
                             f"tdem.Ellipsoid or tdem.Polyhedron, got {shape!r}")
        self.every = None if every is None else positive("every", every)
        self._last_batch = -math.inf
        self.seed = int(seed)
        self._rng = np.random.default_rng(self.seed)
        self.t0 = float(sim.time)
        self.mass = 0.0
        self.count = 0
        self.ids = np.zeros(0, np.int64)
        self.times = np.zeros(0)
        self.group = None             # the ParticleGroup its particles join
        self._pending = None          # the next particle's radius, drawn and not yet placed
        self._stopped = False
        self._full_warned = False
        # the smallest and largest particle it makes (the time step's and the grid's)
        if grading is not None:
            self.sizes = (0.5 * grading.d_min, 0.5 * grading.d_max)
        elif radius is not None:
            self.sizes = (self.radius, self.radius)
        else:
            self.sizes = (shape.bounding_radius, shape.bounding_radius)

    def stop(self):
        """No more particles from this inserter."""
        self._stopped = True
        return self

    @property
    def done(self):
        return self._stopped or (self.limit is not None and self.count >= self.limit) or (
            self.until is not None and self._sim.time >= self.until)

    def _mass_of(self, r):
        if self.shape is None:
            return float(self.density * (4.0 / 3.0 * math.pi * r ** 3 if self._sim.dim == 3
                                         else math.pi * r * r))
        sh = self.shape
        if isinstance(sh, Superellipse):
            return float(self.density * sh.area)
        if hasattr(sh, "volume") and not callable(sh.volume):
            return float(self.density * sh.volume)                       # a polyhedron
        return float(self.density * 4.0 / 3.0 * math.pi * sh.a * sh.b * sh.c)  # an ellipsoid

    def _next_radius(self):
        if self._pending is None:
            if self.grading is not None:
                self._pending = float(self.grading.sample(1, dim=self._sim.dim,
                                                          rng=self._rng)[0])
            else:
                self._pending = self.sizes[0]
        return self._pending

    def _due(self, t_end):
        """(mass due, number due) by the time ``t_end`` since the start."""
        t = t_end if self.until is None else min(t_end, self.until)
        span = max(t - self.t0, 0.0)
        mass = math.inf if self.rate is None else self.rate * span
        num = math.inf if self.per_s is None else self.per_s * span
        if self.limit is not None:
            num = min(num, self.limit)
        return mass, num

    def batch(self, t_end):
        """Draw and place the particles due by ``t_end``; returns (positions, radii,
        velocities, orientations) of those placed (possibly none)."""
        if self.done:
            return None
        sim = self._sim
        if self.every is not None:
            # a batch every ``every`` seconds, holding what is due until the next
            if sim.time < self._last_batch + self.every - 1e-12:
                return None
            self._last_batch = sim.time
            t_end = max(t_end, sim.time + self.every)
        mass_due, num_due = self._due(t_end)
        old_x, old_r = sim._particles_near(self.region.lo, self.region.hi)
        from scipy.spatial import cKDTree
        tree = cKDTree(old_x) if len(old_x) else None
        rmax_old = float(old_r.max()) if len(old_r) else 0.0
        new_x, new_r = [], []
        placed_mass = 0.0
        while True:
            n_now = self.count + len(new_r)
            if n_now + 1 > num_due + 1e-9:
                break
            r = self._next_radius()
            m = self._mass_of(r)
            if self.rate is not None and self.mass + placed_mass + 0.5 * m > mass_due:
                break
            x = None
            for _ in range(PLACE_TRIES):
                c = self.region.sample(self._rng, r)
                if c is None:
                    break
                if tree is not None:
                    near = tree.query_ball_point(c, r + rmax_old)
                    if near and np.any(np.linalg.norm(old_x[near] - c, axis=1)
                                       < r + old_r[near]):
                        continue
                if new_x:
                    d = np.linalg.norm(np.asarray(new_x) - c, axis=1)
                    if np.any(d < r + np.asarray(new_r)):
                        continue
                x = c
                break
            if x is None:
                if not self._full_warned and not new_r:
                    self._full_warned = True
                    warnings.warn(
                        f"insert: no room for a particle of radius {r:.4g} m in the region "
                        f"{self.region.to_dict()} after {PLACE_TRIES} tries; particles due "
                        f"wait until the region clears ({self.count} inserted so far)",
                        RuntimeWarning, stacklevel=4)
                break
            new_x.append(x)
            new_r.append(r)
            placed_mass += m
            self._pending = None
        if not new_r:
            return None
        k = len(new_r)
        if self.orientation == "random" and self.shape is not None:
            if sim.dim == 3:
                q = self._rng.normal(size=(k, 4))
                q /= np.linalg.norm(q, axis=1)[:, None]
                turn = q
            else:
                turn = self._rng.uniform(0.0, 360.0, k)
        else:
            turn = None
        return np.asarray(new_x), np.asarray(new_r), turn, placed_mass

    def record(self, ids, t, mass):
        self.ids = np.concatenate([self.ids, ids])
        self.times = np.concatenate([self.times, np.full(len(ids), t)])
        self.count += len(ids)
        self.mass += mass

    def to_dict(self):
        return {"region": self.region.to_dict(), "rate": self.rate, "per_s": self.per_s,
                "count": self.limit, "radius": self.radius,
                "grading": None if self.grading is None else self.grading.to_dict(),
                "density": self.density, "velocity": self.velocity.tolist(),
                "orientation": self.orientation, "until": self.until, "seed": self.seed,
                "t0": self.t0, "mass": self.mass, "inserted": self.count,
                "pending": self._pending, "stopped": self._stopped,
                "every": self.every, "last_batch": self._last_batch,
                "rng": self._rng.bit_generator.state}

    def __repr__(self):
        what = (f"rate={self.rate} kg/s" if self.rate is not None else
                f"per_s={self.per_s}" if self.per_s is not None else f"count={self.limit}")
        return f"Inserter({self.region.to_dict()}, {what}: {self.count} in, {self.mass:.4g} kg)"


# ------------------------------------------------------------------ outlets
class Outlet:
    """Particles leaving the model (:meth:`tdem.Simulation.remove_in`): ``count`` and
    ``mass`` removed so far; ``ids``, ``times``, ``masses`` of each removed particle
    (its identity, when, its mass); :meth:`rate` the mass flow over a window."""

    def __init__(self, sim, region, every=None, name=None):
        self._sim = sim
        self.region = region
        if every is not None and (isinstance(every, bool) or int(every) != every or every < 1):
            raise InputError(f"every must be a whole number of steps >= 1, got {every!r}")
        self.every = None if every is None else int(every)
        self.name = name
        self.count = 0
        self.mass = 0.0
        self.ids = np.zeros(0, np.int64)
        self.times = np.zeros(0)
        self.masses = np.zeros(0)
        self._last = sim.steps
        self._kind, par, poly = region.params()
        self._par = ti.ndarray(ti.f64, (8,))
        self._par.from_numpy(par)
        self._poly = ti.ndarray(ti.f64, poly.shape)
        self._poly.from_numpy(poly)
        self._mark = None

    def due(self, steps):
        return self.every is None or steps - self._last >= self.every

    def find(self):
        """The rows inside the region now (none with a prescribed velocity or a load)."""
        sim = self._sim
        a = sim._a
        n = sim._n
        self._last = sim.steps
        if n == 0:
            return np.zeros(0, np.int64)
        if self._mark is None or self._mark.shape[0] != n:
            self._mark = ti.ndarray(ti.i32, (n,))
        got = _mark(a["pos"], a["fix"], self._kind, self._par, self._poly, self._mark, sim.dim)
        if got == 0:
            return np.zeros(0, np.int64)
        rows = np.flatnonzero(self._mark.to_numpy())
        held = sim._held_rows()
        return rows[~np.isin(rows, held)] if len(held) else rows

    def record(self, ids, t, masses):
        self.ids = np.concatenate([self.ids, ids])
        self.times = np.concatenate([self.times, np.full(len(ids), t)])
        self.masses = np.concatenate([self.masses, masses])
        self.count += len(ids)
        self.mass += float(np.sum(masses))

    def rate(self, window=None):
        """Mass flow (kg/s; kg/s per metre in 2D) over the last ``window`` seconds (all
        the time since the first removal without): the mass removed in the window over
        its length."""
        if self.count == 0:
            return 0.0
        t1 = self._sim.time
        t0 = self.times[0] if window is None else t1 - float(window)
        if t1 <= t0:
            return 0.0
        return float(self.masses[self.times > t0].sum() / (t1 - t0))

    def to_dict(self):
        return {"region": self.region.to_dict(), "every": self.every, "name": self.name,
                "last": self._last, "ids": self.ids.tolist(), "times": self.times.tolist(),
                "masses": self.masses.tolist()}

    def __repr__(self):
        return f"Outlet({self.region.to_dict()}: {self.count} out, {self.mass:.4g} kg)"


# ------------------------------------------------------------------ removal
_ACCOUNT_KEYS = ("dissipated", "boundary_work", "W_contacts", "W_continuum", "W_gravity",
                 "W_damping", "W_constraints", "W_applied", "Wp_damping", "Wp_constraints",
                 "ke_half", "ke_start", "P_half")


def remove_rows(sim, rows):
    """Remove the particles at ``rows`` (indices now) from a built DEM model: every
    per-particle array loses their rows, the others' contact lists are compacted (their
    history kept) and renumbered, groups, prescribed velocities, loads, bonds and
    identities follow; the energy they take away goes to the account's ``outflow``.
    Returns their identities and masses."""
    ids, masses, state, before = compact(sim, rows)
    sim._rebuild_from(state)
    close_account(sim, before)
    return ids, masses


def compact(sim, rows):
    """The first half of :func:`remove_rows`: the host side updated and the device
    state, downloaded, without the rows; (identities, masses, state, the account
    before). The caller rebuilds from the state (adding particles to it first, if it
    likes) and then calls :func:`close_account`."""
    rows = np.unique(np.asarray(rows, np.int64))
    n = sim._n
    keep = np.ones(n, bool)
    keep[rows] = False
    before = sim._account_now()
    state = sim._download()
    masses = state["prop"][rows, 1].copy()
    ident = np.concatenate(sim._host["ident"])
    gone = ident[rows]
    new_index = np.cumsum(keep) - 1
    new_index[~keep] = -1
    for name, v in list(state.items()):
        a = schema.BY_NAME.get(name)
        if a is not None and a.owner in schema.per_particle(len(sim._prims_host)):
            state[name] = v[keep]
    # the half lists: partners renumbered, the removed ones dropped (history kept)
    nbr = state["nbr"]
    mapped = np.where(nbr >= 0, new_index[np.maximum(nbr, 0)], -1)
    order = np.argsort(mapped < 0, axis=1, kind="stable")
    state["nbr"] = np.take_along_axis(mapped, order, axis=1).astype(np.int32)
    for name in ("hist", "cn", "cf", "cs"):
        v = state[name]
        idx = order.reshape(order.shape + (1,) * (v.ndim - 2))
        state[name] = np.take_along_axis(v, idx, axis=1)
    state["ncnt"] = (state["nbr"] >= 0).sum(axis=1).astype(np.int32)
    state["flags"][F_REBUILD] = 1
    if sim._nbonds:
        # bonds: renumbered; the intact ones of a removed particle go (their springs'
        # energy with the outflow), the broken ones stay as records of their cracks
        from .bonds import BS_BROKEN
        nb = sim._nbonds
        pair = state["bpair"][:nb]
        mapped = np.where(pair >= 0, new_index[np.maximum(pair, 0)], -1)
        broken = state["bstate"][:nb, BS_BROKEN] != 0.0
        keep_b = broken | np.all(mapped >= 0, axis=1)
        state["bpair"] = mapped[keep_b].astype(np.int32)
        state["bprop"] = state["bprop"][:nb][keep_b]
        state["bstate"] = state["bstate"][:nb][keep_b]
        sim._nbonds = int(keep_b.sum())
    # the host side
    starts = np.cumsum([0] + [len(c) for c in sim._host["radius"]])
    for k in sim._host:
        sim._host[k] = [np.asarray(c)[keep[a:b]] for c, a, b in
                        zip(sim._host[k], starts[:-1], starts[1:])]
    for g in sim._groups:
        ids = new_index[g.ids]
        g.ids = ids[ids >= 0]
    sim._fixes = [(new_index[ids], *vals) for ids, *vals in sim._fixes]
    sim._loads = [(new_index[ids], *vals) for ids, *vals in sim._loads]
    sim._n = int(keep.sum())
    return gone, masses, state, before


def close_account(sim, before, ke_in=0.0):
    """The second half of :func:`remove_rows`, once the arrays are rebuilt: what the
    removed particles had booked kept in the sums, what they held (kinetic,
    gravitational, their contact springs) into ``outflow``. ``ke_in``: the kinetic
    energy of particles added in the same rebuild (their own ``ke_start``, taken
    out)."""
    after = sim._account_now()
    after["ke_start"] -= ke_in
    after["ke_half"] -= ke_in
    off = sim._flow_offsets
    for k in _ACCOUNT_KEYS:
        off[k] = off.get(k, 0.0) + before[k] - after[k]
    lost = sum(before[k] - after[k] for k in ("kinetic", "gravitational", "elastic"))
    off["outflow"] = off.get("outflow", 0.0) + lost
    off["elastic_out"] = off.get("elastic_out", 0.0) + before["elastic"] - after["elastic"]
