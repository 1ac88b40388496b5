"""The runner: device state, run segments, snapshots, growth and replay.

:class:`Runner` is the part of :class:`tdem.Simulation` that turns the model the
user built into device arrays and advances it:

- building and rebuilding the device state (:mod:`tdem.state` declares the arrays),
  uploading laws, parameters, walls and prescribed velocities, fitting the cell grid;
- :meth:`Runner.run`: run segments of ``check_interval`` steps; the host looks at the
  device only between segments (status word, monitors, output);
- :meth:`Runner._one_step`: one time step, the stages in the order the data flows —
  the one place where a reader sees the data flow of a step;
- a snapshot of the dynamic state at the start of each segment: a slot overflow
  restores it, grows the arrays and redoes the steps; an instability restores it,
  replays step by step to name the step and the particle, and raises
  :class:`tdem.InstabilityError`.

It uses the model attributes that :class:`tdem.Simulation` sets up (``_host``,
``_laws``, ``_walls_host``, ``_cont``, ``_fixes`` …) and owns the device ones (``_a``,
``_slots``, ``_snap`` …).
"""
import math
import sys
import time as _time
import warnings

import numpy as np
import taichi as ti

from physics import contact_law as _claw
from physics.shapes import mass_properties, principal_inertia
from physics.shapes import quaternion_rotations as _rotations
from physics.volume_contact import VolumeContact

from . import backend, launch, neighbors, sweep
from . import bonds as _bonds
from . import primitives as _prims
from . import state as schema
from . import step as stepk
from .continuum import Continuum
from .errors import CapacityError, InputError, InstabilityError
from .primitives import PRIM_WIDTH
from .neighbors import F_BAD, F_FAST, F_NEED, F_REBUILD, F_SWEEP, F_WALL_NEED, FLAGS_SIZE


MAX_SLOTS = 1024
_COMPILED = False          # a run with a progress bar has happened in this process
# a run estimated to take longer than this (wall-clock seconds) says so on stderr:
# its time step, its number of steps and the estimated time (progress=False: silent)
ANNOUNCE_SECONDS = 30.0
# wall-clock seconds of steps, after the first segment (which compiles), the rate
# of the estimate is measured over
ANNOUNCE_MEASURE = 0.5


# how far above the stable step at the present largest Hertz overlap a run's step may
# be before it warns (Runner._warn_stiffened)
STIFFENED_MARGIN = 1.1


class Runner:
    """Device state and the run loop of :class:`tdem.Simulation` (module docstring)."""


    def _shapes_present(self):
        """(any shaped particle, the step kernel's ``shapes`` bits tdem.step.SHAPES_*),
        worked out again only when particles were added."""
        chunks = self._host["shape"]
        if self._shaped_cache is None or self._shaped_cache[0] != len(chunks):
            shaped = any(bool((c[:, 2] > 0).any()) for c in chunks)
            code = 0
            if shaped:
                rows = np.concatenate(chunks)
                if self.dim == 2 or (rows[:, 3] > 0).any():
                    code |= stepk.SHAPES_SMOOTH
                if self.dim == 3 and (rows[:, 3] < 0).any():
                    code |= stepk.SHAPES_POLY
            self._shaped_cache = (len(chunks), shaped, code)
        return self._shaped_cache[1:]

    @property
    def _has_shapes(self):
        """Whether some particles are superellipses, ellipsoids or polyhedra."""
        return self._shapes_present()[0]

    @property
    def _shape_code(self):
        """The step kernel's ``shapes`` bits: which shape code it compiles."""
        return self._shapes_present()[1]

    def _upload_polyhedra(self):
        """The shape tables of the polyhedra (physics.polyhedron), one row each."""
        if not self._polys:
            return
        rows = [p.table_rows() for p in self._polys]
        self._a["ptab"].from_numpy(np.stack([r[0] for r in rows]))
        self._a["pint"].from_numpy(np.stack([r[1] for r in rows]).astype(np.int32))

    @property
    def _rolling3d(self):
        """3D with a law of rolling resistance: contacts keep the rolling columns."""
        return self.dim == 3 and any(law.rolling is not None for law in self._laws)

    def _law_table(self):
        nl = max(len(self._laws), 1)
        t = np.zeros((nl, nl), dtype=np.int32)
        for a in range(nl):
            for b in range(nl):
                default = max(a, b)
                if a < len(self._laws) and b < len(self._laws):
                    # a sphere–polyhedron pair takes the polyhedron's law (its geometry
                    # gives the overlap volume)
                    vol = [k for k in (a, b) if isinstance(self._laws[k], VolumeContact)]
                    if len(vol) == 1:
                        default = vol[0]
                t[a, b] = self._pair_override.get((a, b), default)
        return t

    # ------------------------------------------------------------ device state
    def _sizes(self, n, cap, capw, nwalls, nlaws, ncell):
        """The sizes :func:`tdem.state.allocate` takes, for this model."""
        return {"n": n, "cap": cap, "capw": capw, "walls": max(nwalls, 1), "laws": nlaws,
                "chunks": backend.max_chunks(),
                "law_width": _claw.table_width(self._law_set), "cells": ncell,
                "cell_starts": ncell + 4096, "flags": FLAGS_SIZE, "simp": stepk.SIMP_SIZE,
                "tcells": ncell if self.dim == 3 else 1,
                "tcell_starts": ncell + 4096 if self.dim == 3 else 1,
                "tbin_cap": 16 * nwalls + 1024 if self.dim == 3 else 1,
                "wall_width": stepk.wall_width(self.dim), "laws_set": self._law_set,
                "dim": self.dim, "shaped": self.dim == 3 and self._has_shapes,
                "rolling": self._rolling3d, "pshapes": max(len(self._polys), 1),
                "bonds": max(self._nbonds, 1),
                "entries": 2 * n if self.broad_phase == "sweep" else 1,
                # primitive walls: their contacts' arrays a row per particle only with them
                "nprims": len(self._prims_host), "prims": max(len(self._prims_host), 1),
                "pn": n if self._prims_host else 1}

    def _allocate(self, n, cap, capw, nwalls, nlaws, ncell):
        return schema.allocate(self._sizes(n, cap, capw, nwalls, nlaws, ncell), self._fdt)

    def _fresh_state(self):
        self._law_set = _claw.registered()
        pos = np.concatenate(self._host["pos"])
        vel = np.concatenate(self._host["vel"])
        r = np.concatenate(self._host["radius"])
        rho = np.concatenate(self._host["density"])
        shape = np.concatenate(self._host["shape"])
        m, inertia = mass_properties(shape, rho, r, self.dim, self._polys)
        if self._cont is not None and self._cont.has_pcmm:
            pm = self._cont.masses
            inertia = np.where(np.isnan(pm), inertia, 0.5 * pm * r ** 2)
            m = np.where(np.isnan(pm), m, pm)
        n = len(r)
        om = (np.concatenate(self._host["omega"]) if len(self._host["omega"]) == len(
            self._host["pos"]) else np.zeros(n if self.dim == 2 else (n, 3)))
        s = self._new_rows(pos, vel, r, m, inertia, np.concatenate(self._host["law"]), shape,
                           np.concatenate(self._host["angle"]), om, self._cap, self._capw)
        s["flags"] = np.zeros(FLAGS_SIZE, np.int32)
        s["flags"][F_REBUILD] = 1
        s["flags"][F_BAD] = n
        if self._nbonds:
            s.update(self._bond_host)
        return s

    def _new_rows(self, pos, vel, r, m, inertia, law, shape, angle, omega, cap, capw):
        """State rows of new particles (every saved per-particle and per-slot array)."""
        sizes = self._sizes(len(r), cap, capw, 1, 1, 1)
        work = np.zeros((len(r), 7))
        # the kinetic energy at the start, ½ m v² + ½ I ω²
        w2 = omega * omega if np.ndim(omega) == 1 else np.einsum("ij,ij->i", omega, omega)
        lmom = np.zeros_like(omega)
        if self.dim == 3:
            # ellipsoids and polyhedra: L = R I Rᵀ ω, and ½ ω·L their rotational energy
            ell = np.asarray(shape)[:, 3] != 0
            if ell.any():
                rot = _rotations(np.asarray(angle)[ell])
                i3 = principal_inertia(np.asarray(shape)[ell], np.asarray(m)[ell])
                wb = np.einsum("nji,nj->ni", rot, omega[ell])
                lmom[ell] = np.einsum("nij,nj->ni", rot, i3 * wb)
                w2 = w2.copy()
                w2[ell] = np.einsum("ij,ij->i", omega[ell], lmom[ell]) / np.asarray(inertia)[ell]
        work[:, 6] = 0.5 * (np.asarray(m) * np.einsum("ij,ij->i", vel, vel)
                            + np.asarray(inertia) * w2)
        return schema.fresh_rows(len(r), sizes, {
            "ework": work, "omega": omega, "lmom": lmom,
            "pos": pos, "vel": vel, "pos0": pos, "xref": pos, "shp": shape, "angle": angle,
            "prop": np.stack([r, m, inertia], axis=1),
            "plaw": np.broadcast_to(np.asarray(law, np.int32), (len(r),))})

    def _build(self):
        if self._n == 0 and not self._blocks:
            raise InputError("the simulation has no particles: call add_particles first")
        if self._law_range > 0.0 and self._has_shapes:
            law = next(law for law in self._laws if law.acting_range() > 0.0)
            raise InputError(f"contact={law!r} acts across a gap (its range "
                             f"{law.acting_range():g} m), which is built for discs and spheres; "
                             f"this model has shaped particles")
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
        walls = np.array(self._walls_host, float).reshape(-1, stepk.wall_width(self.dim))
        return Continuum(pos, rad, pmat, self._slots, self._blocks, couples=self._couple_rows(),
                         walls=walls, mixed=self.mixed_discretization)

    def _require_built(self):
        if not self._built:
            self._build()

    def _rebuild_from(self, state, new_particles=None):
        """(Re)allocate every array for the current sizes and fill it from ``state``."""
        self._built_roll3d = self._rolling3d
        self._built_range = self._law_range
        self._set_law_set(state)
        if new_particles is not None:
            pos, vel, r, rho, law, shape, ang, om = new_particles
            m, inertia = mass_properties(shape, rho, r, self.dim, self._polys)
            n = len(r)
            add = self._new_rows(pos, vel, r, m, inertia, law, shape, ang, om,
                                 state["nbr"].shape[1], state["wid"].shape[1])
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
        # sums start from zero every step
        self._a["facc"].from_numpy(np.zeros((n, self._a["facc"].n)))
        self._upload_laws()
        self._upload_polyhedra()
        self._set_wall_rows(np.array(self._walls_host).reshape(-1, stepk.wall_width(self.dim)),
                            fresh=True)
        self._set_prim_rows(np.array(self._prims_host).reshape(-1, PRIM_WIDTH))
        self._fit_grid(force=True)
        self._apply_fixes(initial=True)
        self._apply_loads(initial=True)
        self._upload_params()
        self._a["flags"][F_REBUILD] = 1
        self._start_sweep(state["pos"], state["prop"][:, 0])

    def _start_sweep(self, pos, radius):
        """Sort-and-sweep: the box ends of every axis in sorted order (the arrays are
        new), and the pair set asked to be made again at the next build."""
        if self.broad_phase != "sweep":
            return
        n = len(radius)
        ends = np.empty((self.dim, 2 * n))
        ends[:, 0::2] = (np.asarray(pos) - np.asarray(radius)[:, None]).T
        ends[:, 1::2] = (np.asarray(pos) + np.asarray(radius)[:, None]).T
        order = np.argsort(ends, axis=1, kind="stable").astype(np.int32)
        self._a["sent"].from_numpy(order)
        self._a["skey"].from_numpy(np.take_along_axis(ends, order, axis=1))
        self._sweep_stale()

    def _sweep_stale(self):
        """Sort-and-sweep: the lists were put back (a snapshot, a checkpoint) or made
        anew, and its box pairs were not: the next build makes them again from the
        sorted axes (tdem.sweep, flags[F_SWEEP])."""
        if self.broad_phase == "sweep":
            self._a["flags"][F_SWEEP] = 0

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
        self._prims_host = list(out["prim"][:len(self._prims_host)])
        return out

    def _set_law_set(self, state):
        """Take the contact laws registered now (the kernels' ``laws``); the history
        arrays of ``state`` get the columns these laws need."""
        self._law_set = _claw.registered()
        tdim = _claw.tangent_dim(self.dim)
        for k, width in (("hist", _claw.pair_history_width(self._law_set, tdim)),
                         ("whist", _claw.wall_history_width(self._law_set, tdim)),
                         # the primitive walls' contacts keep a wall contact's history
                         ("phist", _claw.wall_history_width(self._law_set, tdim))):
            if k in state and self.dim == 3:
                # 3D: the law's columns kept, an ellipsoid tail (tdem.shaped3d) zeroed
                # when the width changes (the warm starts are found again)
                h = np.asarray(state[k])
                shaped = self._has_shapes
                width += (4 if k == "hist" else 1) if shaped else 0
                width += 7 if self._rolling3d else 0
                if h.shape[-1] != width:
                    out = np.zeros(h.shape[:-1] + (width,), dtype=h.dtype)
                    keep = min(h.shape[-1], _claw.history_width(self._law_set, tdim))
                    out[..., :keep] = h[..., :keep]
                    state[k] = out
            elif k in state:
                tail = 3 + len(_claw.PAIR_TAIL if k == "hist" else _claw.WALL_TAIL)
                state[k] = _claw.remap_history(state[k], width, tail=tail)

    def _upload_laws(self):
        width = _claw.table_width(self._law_set)
        rows = np.array([law.row(width) for law in self._laws], dtype=float)
        self._a["lawp"].from_numpy(rows)
        self._a["lawpair"].from_numpy(self._law_table())

    def _upload_params(self):
        self._upload_mesh_servo()
        p = np.zeros(stepk.SIMP_SIZE)
        p[stepk.P_DT] = self.dt
        p[[stepk.P_GX, stepk.P_GY, stepk.P_GZ][:self.dim]] = self.gravity
        p[stepk.P_ALPHA] = self.global_damping
        p[stepk.P_ALPHA_LOCAL] = self.local_damping
        p[stepk.P_SKIN] = self.skin
        p[stepk.P_NWALLS] = len(self._walls_host)
        p[stepk.P_CHUNK] = self._chunk()
        for (c0, cl), span in zip(((stepk.P_PX0, stepk.P_PLX), (stepk.P_PY0, stepk.P_PLY),
                                   (stepk.P_PZ0, stepk.P_PLZ)), self._periodic):
            if span is not None:
                p[c0], p[cl] = span[0], span[1] - span[0]
        self._a["simp"].from_numpy(p)
        self._dt_run = p[stepk.P_DT]

    def _upload_mesh_servo(self):
        """The servo-controlled meshes' rows (:func:`tdem.step.servo_meshes`), from
        ``_mesh_servo`` (mesh index -> k, target, direction, relaxation, speed limit);
        None when no mesh has a servo."""
        servo = self._mesh_servo
        if not servo or not self._built:
            self._mservo_arr = None
            return
        rows = np.zeros((len(servo), stepk.MS_WIDTH))
        for r, (m, (k, target, d, relax, vmax)) in enumerate(sorted(servo.items())):
            first, count = self._meshes[m]
            rows[r, [stepk.MS_FIRST, stepk.MS_COUNT, stepk.MS_K, stepk.MS_F]] = \
                first, count, k, target
            rows[r, stepk.MS_DX:stepk.MS_DZ + 1] = d
            rows[r, [stepk.MS_ALPHA, stepk.MS_VMAX]] = relax, vmax
        arr = self._mservo_arr
        if arr is None or tuple(arr.shape) != rows.shape:
            arr = ti.ndarray(ti.f64, shape=rows.shape)
        arr.from_numpy(rows)
        self._mservo_arr = arr

    def _wall_rows(self):
        if not self._built:
            return np.array(self._walls_host, dtype=float).reshape(
                -1, stepk.wall_width(self.dim))
        return launch.host_copy(self._a["wall"])[:len(self._walls_host)]

    def _set_wall_rows(self, rows, fresh=False):
        if not self._built:
            self._walls_host = list(rows)
            return
        full = np.zeros((max(len(rows), 1), stepk.wall_width(self.dim)))
        full[:len(rows)] = rows
        self._a["wall"].from_numpy(full)
        self._walls_host = list(rows)
        self._a["flags"][F_REBUILD] = 1

    def _prim_rows(self):
        """The primitive walls' rows (tdem.primitives.PR_*), from the device once built."""
        if not self._built:
            return np.array(self._prims_host, dtype=float).reshape(-1, PRIM_WIDTH)
        return launch.host_copy(self._a["prim"])[:len(self._prims_host)]

    def _set_prim_rows(self, rows):
        self._prims_host = list(rows)
        if not self._built:
            return
        full = np.zeros((max(len(rows), 1), PRIM_WIDTH))
        full[:len(rows)] = rows
        self._a["prim"].from_numpy(full)

    def _prim_loads(self):
        """(primitives, 7): force, moment about the point, contacts of the last step."""
        if not self._built:
            return np.zeros((len(self._prims_host), 7))
        return launch.host_copy(self._a["pforce"])[:len(self._prims_host)]

    def _wall_loads(self):
        if not self._built:
            return np.zeros((len(self._walls_host), 4 if self.dim == 2 else 7))
        return launch.host_copy(self._a["wforce"])[:len(self._walls_host)]

    def _cell_limit(self):
        """Most cells the grid may have: memory stays O(particles) wherever they are."""
        return 4 * self._n + 1024

    def _grid_cells_for(self, pos, radius):
        h = 2.0 * float(radius.max()) + self._list_skin()
        span = np.ptp(pos, axis=0) + 4 * h
        counts = np.ceil(span / h).astype(np.int64) + 1
        return int(max(min(np.prod(counts), self._cell_limit()), 1))

    def _fit_grid(self, force=False):
        """Fit the cell grid to the particles (host side, at checks).

        The grid covers the particles' bounding box with cells of the largest
        diameter plus the skin, in at most :meth:`_cell_limit` cells. Where a few
        particles lie far from the rest (the box would need more cells), it covers
        the bulk — the box of the 0.5 %–99.5 % quantiles of the positions — and the
        cells along its edges take the particles outside (cell indices are clamped:
        particles that touch still fall in neighbouring cells, so no contact is
        missed). Only where even the bulk is too wide do the cells grow."""
        a = self._a
        d = self.dim
        neighbors.bounds(a["pos"], a["prop"], a["bounds"], d)
        b = a["bounds"].to_numpy()
        lo, hi, rmax = b[:d], b[d:2 * d], b[2 * d]
        if not np.all(np.isfinite(b)) or hi[0] < lo[0]:
            return
        h = 2.0 * rmax + self._list_skin()
        if any(p is not None for p in self._periodic):
            self._fit_periodic_grid(lo, hi, h, force)
            return
        gp = a["gridp"].to_numpy()
        gn = a["gridn"].to_numpy()
        self._last_fit = self._steps
        bulk = self._grid_bulk
        if not force:
            cur_lo = gp[:d]
            cur_hi = cur_lo + gp[d] * gn[:d]
            if bulk is not None:
                # fitted to the bulk: refit once the whole box has changed by a cell
                if gp[d] >= h and np.all(np.abs(b[:2 * d] - bulk) <= h):
                    return
            else:
                inside = np.all(lo >= cur_lo) and np.all(hi <= cur_hi)
                if (inside and gp[d] >= h
                        and np.prod((hi - lo) / gp[d] + 1) > 0.25 * np.prod(gn[:d])):
                    return
        margin = 2 * h
        limit = self._cell_limit()

        def cells(lo, hi, h):
            return np.floor((hi - lo + 2 * margin) / h).astype(np.int64) + 1

        self._grid_bulk = None
        counts = cells(lo, hi, h)
        if np.prod(counts) > limit and self._n >= 2:
            pos = a["pos"].to_numpy()
            qlo, qhi = np.quantile(pos, [0.005, 0.995], axis=0, method="nearest")
            if np.prod(cells(qlo, qhi, h)) <= limit:
                self._grid_bulk = b[:2 * d].copy()
                lo, hi = qlo, qhi
                counts = cells(lo, hi, h)
        while np.prod(counts) > limit:
            h *= 1.5
            counts = cells(lo, hi, h)
        lo = lo - margin
        self._set_grid(lo, (h,) * d, counts)

    def _set_grid(self, lo, h, counts):
        a = self._a
        counts = [int(c) for c in counts]
        ncell = int(np.prod(counts))
        rows = ncell // counts[0]
        ncap = a["cell_count"].shape[0]
        if ncell > ncap or rows > a["cell_start"].shape[0] - ncap:
            self._a["cell_count"] = ti.ndarray(ti.i32, (ncell,))
            self._a["cell_start"] = ti.ndarray(ti.i32, (ncell + max(rows, 4096),))
        a["gridp"].from_numpy(np.array(list(lo) + list(h), dtype=float))
        a["gridn"].from_numpy(np.array((counts + [0, 0])[:3] + [0], dtype=np.int32))
        a["flags"][F_REBUILD] = 1
        self._last_fit = self._steps

    def _fit_periodic_grid(self, lo, hi, h, force):
        """The grid when an axis is periodic: along it the cells tile the period exactly
        (at least three, so that the neighbour cells across the boundary are distinct);
        along an open axis as :meth:`_fit_grid` (cells of side h, with a margin; clamped
        at the edges). Refits whenever the particles' box or size calls for it."""
        a = self._a
        d = self.dim
        gp = a["gridp"].to_numpy()
        gn = a["gridn"].to_numpy()
        origin, sides, counts = [0.0] * d, [h] * d, [1] * d
        per = self._periodic[:d]
        for k, span in enumerate(per):
            if span is not None:
                length = span[1] - span[0]
                c = int(math.floor(length / h))
                if c < 3:
                    raise InputError(
                        f"periodic: the {'xyz'[k]} period {length:g} m must hold three cells "
                        f"of the neighbour grid (2 × the largest radius + the skin = {h:g} m "
                        f"each), i.e. be >= {3 * h:g} m")
                origin[k], sides[k], counts[k] = span[0], length / c, c
            else:
                margin = 2 * h
                c = int(np.floor((hi[k] - lo[k] + 2 * margin) / h)) + 1
                origin[k], counts[k] = lo[k] - margin, c
        # keep the grid while the periodic cells are unchanged and the particles of an
        # open axis stay inside it, in cells not too large for them
        same = all(gn[j] == counts[j] and abs(gp[d + j] - sides[j]) <= 1e-12 * sides[j]
                   for j in range(d) if per[j] is not None)
        for k in range(d):
            if per[k] is None:
                same = same and lo[k] >= gp[k] and hi[k] <= gp[k] + gp[d + k] * gn[k] and \
                    gp[d + k] >= h and (hi[k] - lo[k]) / gp[d + k] + 1 > 0.25 * gn[k]
        if same and not force:
            return
        while np.prod(counts) > self._cell_limit():
            k = next((j for j in range(d) if per[j] is None), None)
            if k is None:
                break
            sides[k] *= 1.5
            counts[k] = int(np.floor((hi[k] - lo[k] + 4 * h) / sides[k])) + 1
        self._set_grid(origin, sides, counts)

    def _apply_fixes(self, initial=False, t=None):
        """Upload prescribed velocities: all of them (``initial``), else only the values
        of the functions of time, evaluated at ``t``. The host keeps its own copy, so a
        step reads nothing back from the device."""
        if not self._fixes:
            return
        t = self._time if t is None else t
        if initial:
            fix = np.zeros(self._n, np.int32)
            self._vfix_host = np.zeros((self._n, 3 if self.dim == 2 else 6))
        vfix = self._vfix_host
        any_fn = False
        # (bit, columns) of vx, vy, omega (2D) or vx, vy, vz, omega (3D)
        cols = (((stepk.FIX_VX, 0), (stepk.FIX_VY, 1), (stepk.FIX_W, 2)) if self.dim == 2 else
                ((stepk.FIX_VX, 0), (stepk.FIX_VY, 1), (stepk.FIX_VZ, 2),
                 (stepk.FIX_W, slice(3, 6))))
        for ids, *vals in self._fixes:
            for (bit, col), v in zip(cols, vals):
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

    def _apply_loads(self, initial=False, t=None):
        """Upload the applied forces of particles (the sum of the apply_force calls) at
        time ``t``; the functions of time are evaluated again at every step."""
        if not self._loads or not self._n:
            return
        t = self._time if t is None else t
        ext = np.zeros((self._n, 3 if self.dim == 2 else 6))
        any_fn = False
        # the columns of fx, fy, moment (2D) or fx, fy, fz, moment (3D: a 3-vector)
        cols = (0, 1, 2) if self.dim == 2 else (0, 1, 2, slice(3, 6))
        for ids, *vals in self._loads:
            for col, v in zip(cols, vals):
                if v is None:
                    continue
                if callable(v):
                    any_fn = True
                    v = self._load_value(v, t, ids, col)
                ext[ids, col] += v
        if initial:
            self._load_fn = any_fn
        self._a["fext"].from_numpy(ext.astype(np.float64 if self._fdt == ti.f64 else np.float32))

    def _apply_motions(self, t):
        """Walls and meshes moved by functions of time: their velocities for the step
        from ``t`` (stage 1 of :meth:`_one_step`), set on the device by
        :func:`tdem.step.set_motion`; nothing is read back."""
        for (kind, index), (first, count, vel, ang) in self._motions.items():
            v = _motion_value(f"{kind} {index}: velocity", vel, t, self.dim)
            if kind == "primitive":
                if v is not None:
                    _prims.set_velocity(self._a["prim"], first, *(float(x) for x in v))
                continue
            w = _motion_value(f"{kind} {index}: angular_velocity", ang, t,
                              1 if self.dim == 2 else 3)
            vv = (0.0, 0.0, 0.0) if v is None else tuple(v) + (0.0,) * (3 - len(v))
            ww = (0.0, 0.0, 0.0) if w is None else ((0.0, 0.0, w[0]) if len(w) == 1
                                                   else tuple(w))
            stepk.set_motion(self._a["wall"], first, count, int(v is not None),
                             int(w is not None), *vv, *ww, self.dim)

    def _load_value(self, fn, t, ids, col):
        """A load given as a function of time, at ``t``: one number per id, or (3D
        moments, ``col`` a slice) one 3-vector per id; refused naming the load."""
        shape = ids.shape if not isinstance(col, slice) else (len(ids), 3)
        raw = fn(t)
        try:
            v = np.broadcast_to(np.asarray(raw, dtype=float), shape)
        except (TypeError, ValueError):
            v = None
        if v is None or not np.isfinite(v).all():
            name = ("fx", "fy", "moment" if self.dim == 2 else "fz", "moment")[
                3 if isinstance(col, slice) else col]
            want = (f"three numbers or {len(ids)} rows of three" if isinstance(col, slice)
                    else f"a finite number or {len(ids)} of them")
            raise InputError(f"apply_force: {name} as a function of time returned {raw!r} "
                             f"at t = {float(t):.6g} s; it must return {want}")
        return v

    # ------------------------------------------------------------------ stepping
    def _step_args(self):
        # the arrays by name; _one_step appends the last five (detail, continuum, laws,
        # shapes, dim)
        # (the chunk size itself goes up with the engine's parameters, _upload_params)
        return schema.bind(stepk.step, self._a, xforce=self._xforce(), serial=self._serial(),
                           chunk=self._chunk() > 0, loads=bool(self._loads_on),
                           bonds=self._nbonds > 0, ranged=self._law_range > 0.0,
                           prims=bool(self._prims_host),
                           periodic=any(p is not None for p in self._periodic), detail=False,
                           continuum=False, laws=self._law_set, shapes=False,
                           dim=self.dim)[:-5]

    @property
    def _law_range(self):
        """The longest range of the model's contact laws (m; 0: all act in contact only)."""
        return max((law.acting_range() for law in self._laws), default=0.0)

    def _list_skin(self):
        """The neighbour lists' reach beyond contact: the skin, plus the laws' range, so
        that a pair within range stays listed while no particle moves half a skin."""
        return float(self.skin) + self._law_range

    def _chunk(self):
        """Particles per chunk of the step's pair loop (:func:`tdem.backend.chunk_size`),
        0: none; never more chunks than the walls' partial sums have rows."""
        chunk = backend.chunk_size(self._n, self._serial())
        rows = self._a["wpart"].shape[0] if "wpart" in self._a else 1
        return max(chunk, -(-self._n // rows)) if chunk else 0

    def _xforce(self):
        if self._cont is not None:
            return self._cont.a["xforce"]
        x = self._a.get("xforce_none")
        if x is None:
            x = self._a["xforce_none"] = schema.ndarray(2, ti.f64, (1,))
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
        self._creach = 1
        if self._cont is not None and self._cont.has_pcmm:
            h = float(self._a["gridp"].to_numpy()[2])
            self._reach = max(1, int(math.ceil((self._cont.reach_length + 2 * self.skin) / h)))
            if self._cont.has_cells:
                self._creach = max(1, int(math.ceil((self._cont.cell_reach_length
                                                     + 2 * self.skin) / h)))
        else:
            self._reach = 1
        if self._n == 0:
            return None, None
        return self._step_args(), self._rebuild_args()

    def _sync_triangle_bins(self):
        """3D: the triangle bins sized like the particle cells (the grid may have been
        refitted or restored since), and grown when the last build needed more entries."""
        a = self._a
        if self.dim != 3 or "tbin_count" not in a:
            return
        if a["tbin_count"].shape != a["cell_count"].shape:
            a["tbin_count"] = ti.ndarray(ti.i32, tuple(a["cell_count"].shape))
        if a["tbin_start"].shape != a["cell_start"].shape:
            a["tbin_start"] = ti.ndarray(ti.i32, tuple(a["cell_start"].shape))
        need = int(a["flags"][neighbors.F_TBIN_NEED])
        if need > a["tbin_items"].shape[0]:
            # (used from the next build on: the lists of this one are complete)
            a["tbin_items"] = ti.ndarray(ti.i32, (int(need * 1.5) + 1024,))

    def _rebuild_args(self):
        self._sync_triangle_bins()
        if self.broad_phase == "sweep":
            return schema.bind(sweep.rebuild, self._a, nwalls=len(self._walls_host),
                               skin=self._list_skin(), dim=self.dim)
        return schema.bind(neighbors.rebuild, self._a, sorted_ids=self._a["sorted"],
                           nwalls=len(self._walls_host), skin=self._list_skin(),
                           dim=self.dim)

    def _one_step(self, step_args, rebuild_args, host_reads_flag, detail):
        """One time step: the stages in the order the data flows (Feng et al.'s seven
        steps). Each stage owns what it writes:

        1. prescribed velocities (functions of time) uploaded — ``vfix``, node fixes;
        2. neighbour lists rebuilt when the skin check asked — slots and histories;
        3. PCMM elements (physics.pcmm) — element stresses, ``xforce``; the Voronoi
           cells of water (physics.pcmm.cells) — their pressures, ``xforce``;
        4. blocks (physics.blocks) — triangle stresses, ``nforce``;
        5. point–edge contacts (coupling) — ``xforce``, ``nforce``;
        6. viscous (non-reflecting) boundaries — ``xforce``, ``nforce``;
        7. bonds (tdem.bonds) — their forces, cracks, ``bforce``; DEM pairs and walls,
           gathered with ``xforce`` and ``bforce``, and the particles' damped
           leapfrog (tdem.step, one kernel) — particle state, contacts, walls; then,
           in 3D models with servo-controlled meshes, their speeds for the next step
           (tdem.step.servo_meshes);
        8. block nodes and rigid blocks integrated (tdem.integrate) — node state;
        9. the volume change of the step of particles with an equation of state, by
           the elements that pushed over it (physics.pcmm.volumes) — ``pjwl``.
        """
        cont = self._cont
        dt = self._dt_run
        if self._n and self._fix_fn:
            self._apply_fixes(t=self._time)
        if self._load_fn:
            self._apply_loads(t=self._time)
        if self._motions:
            self._apply_motions(self._time)
        if cont is not None:
            cont.prescribed(self)
        # on a GPU the rebuild kernel runs every step and returns at once unless the
        # device raised the flag; on the CPU the host reads the flag (shared memory)
        if self._n and (not host_reads_flag
                        or launch.host_view(self._a["flags"])[F_REBUILD] != 0):
            (sweep if self.broad_phase == "sweep" else neighbors).rebuild(*rebuild_args)
        if cont is not None:
            cont.pcmm_elements(self, dt, self._reach)
            cont.cell_pressure(self, self._creach)
            cont.block_stresses(self, dt)
            cont.point_edge(self, dt)
            cont.viscous_boundaries(self)
        if self._nbonds:
            a = self._a
            _bonds.bond_forces(a["pos"], a["vel"], a["omega"], a["prop"], a["bpair"],
                               a["bprop"], a["bstate"], a["bforce"], dt, self._time,
                               self._nbonds, self.dim)
        if self._n:
            stepk.step(*step_args, int(detail), cont is not None and cont.adds_forces,
                       self._law_set, self._shape_code, self.dim)
            if self._mservo_arr is not None:
                stepk.servo_meshes(self._a["wall"], self._a["wforce"], self._mservo_arr, dt)
        if cont is not None:
            cont.integrate(self)
            cont.eos_volumes(self, dt)
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
            self._sweep_stale()
        self._time, self._steps = self._snap_clock
        if self._steps == 0:
            self._account0 = None      # taken again after the replayed first step
        for m in self._monitors:
            m.truncate(self._steps)
        if self._output is not None:
            self._output.truncate(self._steps)
        # the records of the steps redone are due again
        self._plan_events()

    def _status(self):
        a = self._a
        if self._n == 0:
            return np.array([0, 0, 0, 0, 0, 0, 0, 0], np.int32)
        # the overlap limit for plain DEM models (PCMM and water particles overlap by
        # design; their elements and nodes have their own checks)
        limit = stepk.OVERLAP_LIMIT if self._cont is None else 0.0
        stepk.check_stability(a["pos"], a["vel"], a["omega"], a["prop"], a["nbr"], a["ncnt"],
                              a["cs"], a["flags"], float(self._dt_run), limit, self.dim)
        flags = launch.host_copy(a["flags"])
        if (0 < flags[F_FAST] <= self._n and flags[F_BAD] >= self._n
                and not self._fast_warned):
            self._warn_fast(int(flags[F_FAST]) - 1)
        return flags

    def _warn_fast(self, k):
        """Say once that particle k has moved more than its radius in one step (free
        flight, ejecta: not an instability, but it may pass through a thin neighbour
        or a wall within a step)."""
        self._fast_warned = True
        v = launch.host_copy(self._a["vel"])[k]
        r = float(launch.host_copy(self._a["prop"])[k][0])
        dt = self._dt_run
        speed = float(np.linalg.norm(v))
        warnings.warn(
            f"particle {k} moved more than its radius ({r:.4g} m) in one step: faster than "
            f"{r / dt:.4g} m/s at dt = {dt:.4g} s (its speed at t = {self._time:.6g} s: "
            f"{speed:.4g} m/s, {speed * dt / r:.3g} radii a step). Not an instability, but "
            f"it may pass through a neighbour or a wall within a step without touching it; "
            f"a smaller dt (below {r / max(speed, r / dt):.3g} s at that speed) keeps its "
            "steps within its radius (said once)", RuntimeWarning, stacklevel=5)

    def _warn_dense_packing(self, dt):
        """Warn when the step exceeds the stable step of a dense packing of the
        particles (:meth:`tdem.Simulation.stable_dt`); not for models of fewer than
        seven particles (no particle can have six contacts). Checked again only when
        the step, the particles or the laws have changed."""
        key = (dt, self._n, len(self._walls_host), len(self._pair_override),
               tuple((type(law).__name__, tuple(law.values()),
                      law.rolling.delta if law.rolling is not None else 0.0)
                     for law in self._laws))
        if self._n < 7 or self._dense_checked == key:
            return
        self._dense_checked = key
        stable = self.stable_dt()
        if dt > stable:
            crit = self.critical_dt()
            warnings.warn(
                f"dt = {dt:.4g} s is above {stable:.4g} s, the stable step of a dense "
                f"(hexagonal) packing of these particles with their contact laws "
                f"(critical_dt() = {crit:.4g} s is that of one contact): a dense packing "
                f"will go unstable; use dt_fraction <= {stable / crit:.3g} or "
                f"dt <= {stable:.4g}", RuntimeWarning, stacklevel=3)

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
        if not self._built and self._inserters:
            # an inserter may fill an empty model: its first particles come before the build
            self._flow_events(self._time + self.check_interval * self.dt)
        if not self._built:
            self._build()
        elif self._n and (self._built_roll3d != self._rolling3d
                          or self._built_range != self._law_range):
            # 3D rolling resistance switched on or off (law.update) since the arrays were
            # built: the contacts' rolling columns are added (at zero) or dropped; or a
            # law's range changed: the lists reach as far, the step evaluates gaps
            self._rebuild_from(self._download())
        if self._n:
            self._upload_laws()      # a law's parameters may have changed since (law.update)
        if self._cont is not None:
            self._cont.upload_materials()
        self._crit_cache = None
        if self._dt_user is not None:
            self._check_dt_value(self._dt_user)  # particles or laws may have changed since
        self._upload_params()
        dt = self._dt_run
        self._warn_dense_packing(dt)
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
        watch = _LongRun(self, total, dt) if self.progress is not False and total > 0 else None
        try:
            while self._steps < target:
                if self._inserters or self._outlets:
                    self._flow_events(
                        self._time + min(self.check_interval, target - self._steps) * dt)
                self._segment(target, bar)
                if watch is not None and watch(self._steps - done_at_start, bar):
                    watch = None
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
        if self._has_shapes:
            self._warn_nonconverged()
        self._warn_stiffened()
        return self

    def _warn_stiffened(self):
        """Say when the step has become unstable for the contacts as they are now.
        Hertz contacts stiffen as they overlap (k_n ∝ sqrt(δ)), and the step
        (:meth:`tdem.Simulation.stable_dt`) is that of contacts overlapping by 5 % of
        the radius: a bed pressed harder needs a smaller one, by (0.05 R/δ)^(1/4) at
        its largest overlap δ. Without this the bed jitters at speed under damping,
        its walls disagree and its integration makes energy, none of it reported.
        Checked after each run of a sphere model whose laws are all Hertzian (of
        seven particles or more), with a margin (``STIFFENED_MARGIN``: the dense
        packing's bound is that of six contacts a particle, most have fewer); once
        per simulation."""
        if (self._cont is not None or self._n < 7 or self._has_shapes
                or self._stiff_warned
                or not all(law.hertzian for law in self._laws)):
            return
        a = self._a
        ratio = float(stepk.largest_overlap_ratio(a["cs"], a["nbr"], a["ncnt"], a["wcs"],
                                                  a["wid"], a["prop"]))
        if ratio <= 0.05:
            return
        stable = self.stable_dt() * (0.05 / ratio) ** 0.25
        if self._dt_run > STIFFENED_MARGIN * stable:
            self._stiff_warned = True
            warnings.warn(
                f"dt = {self._dt_run:.4g} s is more than 10 % above {stable:.4g} s, the "
                f"stable step of a dense packing whose Hertz contacts overlap by "
                f"{100.0 * ratio:.3g} % of the "
                f"radius, as the largest do now (stable_dt() = {self.stable_dt():.4g} s is "
                f"for 5 %): the particles jitter and the integration makes energy "
                f"(sim.energy()['integration_error']); use dt <= {stable:.4g} s or a "
                f"dt_fraction below {self.dt_fraction * stable / self._dt_run:.3g}",
                RuntimeWarning, stacklevel=3)

    def _warn_nonconverged(self):
        """Say when shaped-particle contacts stopped at the iteration cap (their normal
        and depth are then those of the last iterate)."""
        count = int(self._a["flags"].to_numpy()[neighbors.F_NONCONV])
        if count > self._nonconv_reported and self._polys:
            warnings.warn(f"{count - self._nonconv_reported} contact evaluations of polyhedra "
                          f"needed more overlap points than the fixed buffers hold ({count} "
                          "in all, sim.nonconverged_contacts): their volume and normal miss "
                          "the points left out; a smaller time step or less overlap helps",
                          RuntimeWarning, stacklevel=3)
        elif count > self._nonconv_reported:
            warnings.warn(f"{count - self._nonconv_reported} contact evaluations of shaped "
                          f"particles stopped at the iteration cap ({count} in all, "
                          "sim.nonconverged_contacts): their normal is the last iterate's; "
                          "a smaller time step or less overlap helps", RuntimeWarning,
                          stacklevel=3)
            self._nonconv_reported = count

    def _segment(self, target, bar):
        """Up to ``check_interval`` steps from a snapshot, then one look at the device.
        The energy account's reference (``_account0``, :meth:`energy`) is taken after
        the model's first step, when every contact and element of the start has been
        evaluated (a replayed step gives the same)."""
        n = min(self.check_interval, target - self._steps)
        self._take_snapshot()
        sargs, rargs = self._engine_args()
        host_flag = self._host_reads_flag
        for s in range(n):
            # output-only quantities are stored on the steps something will read them
            first = self._account0 is None
            detail = s == n - 1 or self._steps + 1 >= self._next_event or first
            self._one_step(sargs, rargs, host_flag, detail)
            if first:
                # a step made with lists too short is redone: its account is not taken
                # (its state may hold anything, non-finite numbers included)
                if self._grown_if_short(launch.host_copy(self._a["flags"]) if self._n
                                        else None):
                    return
                self._account0 = self._account_now()
                self._warn_silent_models()
            if self._steps >= self._next_event:
                self._events()
        flags = self._status()
        if self._grown_if_short(flags):
            return
        if self._cont is not None and self._cont.status()[1] >= 0:
            self._find_instability()
        if flags[F_BAD] < self._n:
            self._find_instability()
        if self._n and self._steps - self._last_fit >= self.check_interval:
            self._fit_grid()

    def _warn_silent_models(self):
        """Once, after the first step (the PCMM elements are made then): a body whose
        tolerance made (almost) no elements (under a tenth of its Delaunay triangles)
        runs as loose discs; element water (a Fluid without ``voronoi=True``) on a
        hexagonal lattice, under gravity, carries only part of ρgh. Each warning
        gives the elements made and what to change."""
        if self._silent_checked:
            return
        self._silent_checked = True
        if self._cont is None or not self._cont.has_pcmm:
            return
        from physics.materials import Fluid
        body = np.concatenate(self._host["mat"]).astype(np.int64)
        pos = np.concatenate(self._host["pos"])
        rad = np.concatenate(self._host["radius"])
        tri = self._cont.elements()["triangles"]
        made = np.bincount(body[tri[:, 0]], minlength=len(self._slots)) if len(tri) else \
            np.zeros(len(self._slots), np.int64)
        for k, (mat, tol) in enumerate(self._slots):
            ids = np.flatnonzero(body == k)
            if tol is None or len(ids) < 3 or (isinstance(mat, Fluid) and mat.voronoi):
                continue
            name = type(mat).__name__
            need, full, hexagonal = _delaunay_elements(pos[ids], rad[ids])
            if full is not None and made[k] < 0.1 * full:
                r = float(np.median(rad[ids]))
                warnings.warn(
                    f"PCMM body of material {name} (tolerance {tol:.4g} m, {len(ids)} "
                    f"particles) made {int(made[k])} elements, where its "
                    f"{full} Delaunay triangles would make one each: "
                    f"{'it runs as loose discs' if made[k] == 0 else 'most of it runs as loose discs'}. "
                    f"Eq. 1 joins particles with d <= R_i + R_j + tolerance; the diagonals "
                    f"of its lattice need tolerance >= {need:.4g} m ({need / r:.3g} R): raise "
                    f"the tolerance to at least that", RuntimeWarning, stacklevel=5)
            elif (isinstance(mat, Fluid) and hexagonal > 0.5 and mat.shear_modulus == 0.0
                  and float(np.linalg.norm(self.gravity)) > 0.0):
                # (a Maxwell fluid, with a shear modulus, holds: tests/test_fluid.py)
                warnings.warn(
                    f"PCMM body of material Fluid ({len(ids)} particles, {int(made[k])} "
                    f"elements): element water (Fluid without voronoi=True) carries only "
                    f"40–60 % of the hydrostatic pressure ρgh on a hexagonal lattice; "
                    f"Fluid(..., voronoi=True) gives each particle the pressure of its "
                    f"Voronoi cell, which carries it", RuntimeWarning, stacklevel=5)

    def _grown_if_short(self, flags):
        """When the steps since the snapshot overflowed a list (PCMM candidates, the
        particles' or the walls' slots): the snapshot restored, the lists grown, True
        (the steps are then redone)."""
        if self._cont is not None:
            need, _ = self._cont.status()
            if self._cont.short(need):
                self._restore_snapshot()
                self._cont.grow(need)
                return True
        if self._n and (flags[F_NEED] > self._cap or flags[F_WALL_NEED] > self._capw):
            self._restore_snapshot()
            self._grow(flags)
            return True
        return False

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
        """A bar (steps, simulated time, rate, ETA) for a run of ``total`` steps: with
        ``progress=True``, or on a terminal for runs of more than 2e7 particle-steps
        (a few seconds). The first run of a process says first that it compiles."""
        global _COMPILED
        show = self.progress
        if show is None:
            show = sys.stderr.isatty() and self._dofs() * total > 2e7
        if not show or total <= 0:
            return None
        if not _COMPILED:
            print("tdem: compiling kernels (the first run of a process; later runs reuse "
                  "them)", file=sys.stderr, flush=True)
        _COMPILED = True
        from tqdm.auto import tqdm
        return tqdm(total=total, unit="step", desc=f"tdem (dt {self._dt_run:.3g} s)",
                    leave=False)


def _delaunay_elements(pos, rad):
    """Of the Delaunay triangles of a body's particles: (the tolerance at which they
    become elements, the median over the triangles of their largest gap d − R_i −
    R_j; their number; the share of them that are equilateral within 10 %, a
    hexagonal lattice's). (0, None, 0) when the points make no triangulation."""
    from scipy.spatial import Delaunay, QhullError
    try:
        tri = Delaunay(pos).simplices
    except (QhullError, ValueError):
        return 0.0, None, 0.0
    gap = np.zeros(len(tri))
    side = []
    for a, b in ((0, 1), (1, 2), (0, 2)):
        i, j = tri[:, a], tri[:, b]
        d = np.linalg.norm(pos[i] - pos[j], axis=1)
        side.append(d)
        gap = np.maximum(gap, d - rad[i] - rad[j])
    # slivers along a convex hull make no element whatever the tolerance: leave them out
    keep = gap <= 2.0 * float(np.median(rad))
    if not keep.any():
        return 0.0, None, 0.0
    side = np.stack(side, axis=1)[keep]
    equilateral = float(np.mean(side.max(axis=1) <= 1.1 * side.min(axis=1)))
    return float(np.median(gap[keep])), int(keep.sum()), equilateral


def _duration(seconds):
    """'45 s', '3 min 20 s', '2 h 05 min'."""
    seconds = max(0.0, float(seconds))
    if seconds < 90:
        return f"{seconds:.0f} s"
    if seconds < 5400:
        return f"{int(seconds // 60)} min {int(seconds % 60):02d} s"
    return f"{int(seconds // 3600)} h {int(seconds % 3600 // 60):02d} min"


class _LongRun:
    """Says on stderr, once the rate of the steps is known, that a run will take long
    (over :data:`ANNOUNCE_SECONDS`): its time step, its steps and the estimated wall
    time. The rate is measured after the first segment (whose time includes compiling
    the kernels) over at least :data:`ANNOUNCE_MEASURE` seconds."""

    def __init__(self, runner, total, dt):
        self.runner, self.total, self.dt = runner, int(total), float(dt)
        self.until = float(runner._time) + self.total * self.dt
        self.t_start = _time.perf_counter()
        self.t0 = self.n0 = None

    def __call__(self, done, bar=None):
        """After a segment, ``done`` steps of the run made; True when nothing more is
        to be said (announced, or short)."""
        now = _time.perf_counter()
        if done >= self.total:
            return True
        if self.t0 is None:
            self.t0, self.n0 = now, done
            return False
        el = now - self.t0
        if el < ANNOUNCE_MEASURE or done <= self.n0:
            return False
        rate = (done - self.n0) / el
        left = (self.total - done) / rate
        if now - self.t_start + left <= ANNOUNCE_SECONDS:
            return True
        self.announce(rate, now - self.t_start + left, bar)
        return True

    def message(self, rate, seconds):
        return (f"tdem: a long run: {self.total} steps of dt = {self.dt:.6g} s "
                f"({self.total * self.dt:.6g} s of simulated time, to t = {self.until:.6g} s), "
                f"about {_duration(seconds)} of wall time at {rate:.4g} steps/s "
                f"({self.runner._dofs()} particles and nodes)")

    def announce(self, rate, seconds, bar=None):
        text = self.message(rate, seconds)
        if bar is not None:
            bar.write(text, file=sys.stderr)
        else:
            print(text, file=sys.stderr, flush=True)


def _motion_value(name, fn, t, n):
    """A motion's function of time (None: not prescribed) at ``t``: ``n`` finite
    numbers, or an error naming it."""
    if fn is None:
        return None
    from .motion import as_vector
    raw = fn(t)
    v = as_vector(raw, n)
    if v is None:
        raise InputError(f"{name} as a function of time returned {raw!r} at "
                         f"t = {float(t):.6g} s; it must return {n} finite number"
                         + ("s" if n > 1 else ""))
    return v
