"""Checkpoints: the whole state of a :class:`tdem.Simulation` in one HDF5 file.

:func:`save` stores every device array (positions, velocities, neighbour lists with
their contact history, wall slots, walls, the cell grid and the status flags) and
the host-side description the object is rebuilt from (constructor parameters,
contact laws, groups, walls, prescribed velocities, capacities, clock).
:func:`load` rebuilds a simulation that continues exactly: the same steps give
the same numbers, bit for bit, as the run that was saved, on the same number of
threads (the engine's summation order is fixed; one thread sums in another order
than several, which agrees to round-off). Wall forces, which are summed
with atomic additions, are output only and may differ in the last bits between
two runs on several threads.

Not saved: monitors and output writers (they hold Python functions; attach them
again after loading), prescribed velocities given as functions of time (saved
as free, with a warning) and motions of walls given as functions other than
:mod:`tdem.motion`'s (saved as their velocity then, with a warning). Inserters and
outlets (:mod:`tdem.flows`) are saved with their records and random streams.

Layout of the file:

- attribute ``format`` = "tdem-checkpoint", ``version``, ``config`` (JSON: the
  constructor parameters, laws, pair overrides, groups, clock and capacities),
  ``simulation`` (the repr, for people);
- group ``state``: one dataset per device array (names as in ``sim._a``);
- group ``host``: the particles as added (``pos``, ``vel``, ``radius``, ``density``,
  ``law``, concatenated, and ``sizes``, one entry per :meth:`add_particles` call)
  and ``walls`` (the wall table, one row per wall);
- group ``fixes``: one subgroup per :meth:`fix_particles` call with ``ids`` and the
  datasets among ``vx``, ``vy``, ``omega`` that were prescribed.
"""
import json
import math
import warnings

import numpy as np

from physics.polyhedron import Polyhedron

from .continuum import SAVED as CONTINUUM_SAVED
from . import mesh as _mesh
from .errors import InputError
from .primitives import CYLINDER_IN, CYLINDER_OUT, PLANE, PR_KIND, PR_LAW, PRIM_WIDTH
from .step import T_LAW, TRI_WIDTH, W_LAW, wall_width

FORMAT = "tdem-checkpoint"
VERSION = 4     # 2: particle shapes and angles; two more history columns; 3: work account;
                # 4: each block's boundary edges listed once for its point-edge couples
_FIX_NAMES = ("vx", "vy", "omega")
_FIX_NAMES_3D = ("vx", "vy", "vz", "omega")
_HOST_KEYS = ("pos", "vel", "radius", "density", "law", "mat", "shape", "angle", "omega",
              "ident")


def _config(sim):
    laws = sim._laws
    groups = []
    first = 0
    for g in sim._groups:
        # (each group is one run of rows: particles removed leave the rest in order)
        law = next(k for k, known in enumerate(laws) if known is g.contact)
        groups.append({"first": first, "count": int(len(g.ids)), "law": law})
        first += len(g.ids)
    return {
        "gravity": [float(x) for x in sim.gravity],
        "dt": sim._dt_user,
        "dt_fraction": sim.dt_fraction,
        "precision": sim.precision,
        "local_damping": sim.local_damping,
        "global_damping": sim.global_damping,
        "skin": sim._skin_user,
        "check_interval": sim.check_interval,
        "progress": sim.progress,
        "arch": sim.arch,
        "laws": [law.to_dict() for law in laws],
        "pair_override": [[int(a), int(b), int(c)] for (a, b), c in sim._pair_override.items()],
        "groups": groups,
        "n": int(sim._n),
        "cap": int(sim._cap),
        "capw": int(sim._capw),
        "time": float(sim._time),
        "steps": int(sim._steps),
        "last_fit": int(sim._last_fit),
        "built": bool(sim._built),
        "slots": [{"material": m.to_dict(), "tolerance": t} for m, t in sim._slots],
        "continuum_capacity": int(sim._cont.capacity) if sim._cont is not None else 0,
        "periodic": [None if p is None else [float(p[0]), float(p[1])] for p in sim._periodic],
        "dim": int(sim.dim),
        "broad_phase": sim.broad_phase,
        "mixed_discretization": bool(sim.mixed_discretization),
        "meshes": [[int(a), int(b)] for a, b in sim._meshes],
        # primitive walls (3D planes, cylinders): their rows now (JSON keeps the floats)
        "primitives": [[float(x) for x in row] for row in sim._prims_host],
        "mesh_servo": [[int(m), float(k), float(f), [float(x) for x in d], float(a), float(v)]
                       for m, (k, f, d, a, v) in sorted(sim._mesh_servo.items())],
        "polyhedra": [p.input_vertices.tolist() for p in getattr(sim, "_polys", [])],
        "account0": sim._account0,
        "motions": _motions_config(sim),
        "next_ident": int(sim._next_ident),
        "nbonds": int(sim._nbonds),
        "flow_offsets": {k: float(v) for k, v in sim._flow_offsets.items()},
        "inserters": [_inserter_config(sim, ins) for ins in sim._inserters],
        "outlets": [{"region": o.region.to_dict(), "every": o.every, "name": o.name,
                     "last": int(o._last)} for o in sim._outlets],
        "couples": [{"ids": None if ids is None else [int(i) for i in ids],
                     "a": None if a is None else int(a.index), "block": int(b.index),
                     "law": law.to_dict()} for ids, a, b, law in sim._couples],
    }


def _motions_config(sim):
    """Walls and meshes moved by functions of time: tdem.motion's functions are kept;
    any other function cannot be, and the wall goes on at its velocity now (a
    warning says which)."""
    from .motion import Motion
    out = []
    for (kind, index), (first, count, vel, ang) in sorted(sim._motions.items()):
        parts = []
        for name, fn in (("velocity", vel), ("angular_velocity", ang)):
            if fn is None or isinstance(fn, Motion):
                parts.append(None if fn is None else fn.to_dict())
                continue
            warnings.warn(f"save: the {name} of {kind} {index} is a function "
                          f"({getattr(fn, '__name__', fn)!r}) that cannot be saved; the "
                          f"loaded simulation keeps its value now (tdem.motion.vibration "
                          f"and tdem.motion.ramp are kept)", stacklevel=4)
            parts.append(None)
        if any(p is not None for p in parts):
            out.append({"kind": kind, "index": int(index), "first": int(first),
                        "count": int(count), "velocity": parts[0],
                        "angular_velocity": parts[1]})
    return out


def _inserter_config(sim, ins):
    if ins.shape is not None:
        raise InputError(f"save: an inserter of shaped particles ({ins.shape!r}) cannot be "
                         f"saved; stop it (ins.stop()) or save before it is made")
    d = ins.to_dict()
    d["law"] = next(k for k, known in enumerate(sim._laws) if known is ins.contact)
    d["group"] = None if ins.group is None else sim._groups.index(ins.group)
    return d


def _flows_to(f, sim):
    g = f.create_group("flows")
    for k, ins in enumerate(sim._inserters):
        h = g.create_group(f"inserter{k:04d}")
        h.create_dataset("ids", data=np.asarray(ins.ids, np.int64))
        h.create_dataset("times", data=np.asarray(ins.times, float))
    for k, out in enumerate(sim._outlets):
        h = g.create_group(f"outlet{k:04d}")
        h.create_dataset("ids", data=np.asarray(out.ids, np.int64))
        h.create_dataset("times", data=np.asarray(out.times, float))
        h.create_dataset("masses", data=np.asarray(out.masses, float))


def _flows_from(sim, cfg, flows):
    """The inserters and outlets of a checkpoint, where they were."""
    from .flows import Inserter, Outlet, Region
    from .gradings import Grading
    for k, d in enumerate(cfg.get("inserters", [])):
        region = Region(sim.dim, **d["region"])
        ins = Inserter(sim, region, rate=d["rate"], count=d["count"], per_s=d["per_s"],
                       radius=d["radius"],
                       grading=None if d["grading"] is None else Grading.from_dict(d["grading"]),
                       density=d["density"], contact=sim._laws[d["law"]],
                       velocity=d["velocity"], orientation=d["orientation"],
                       until=d["until"], seed=d["seed"], every=d.get("every"))
        ins._last_batch = d.get("last_batch", -math.inf)
        ins.t0, ins.mass, ins.count = d["t0"], d["mass"], d["inserted"]
        ins._pending, ins._stopped = d["pending"], d["stopped"]
        ins._rng.bit_generator.state = d["rng"]
        ins.group = None if d["group"] is None else sim._groups[d["group"]]
        ins.ids, ins.times = flows.get(f"inserter{k:04d}", (ins.ids, ins.times))[:2]
        sim._inserters.append(ins)
    for k, d in enumerate(cfg.get("outlets", [])):
        out = Outlet(sim, Region(sim.dim, **d["region"]), every=d["every"], name=d["name"])
        out._last = d["last"]
        got = flows.get(f"outlet{k:04d}")
        if got is not None:
            out.ids, out.times, out.masses = got
            out.count, out.mass = len(out.ids), float(np.sum(out.masses))
        sim._outlets.append(out)


def save(sim, path):
    """Write the whole state of ``sim`` to the HDF5 file ``path`` (overwritten).

    A simulation that has particles but has not run yet is built first (as its
    first run would). Returns ``path``.
    """
    import h5py
    if not sim._built and (sim._n > 0 or sim._blocks):
        sim._build()
    state = sim._download() if sim._built and sim._n > 0 else {}
    cfg = _config(sim)
    if sim._built and sim._n > 0:
        cfg["cells"] = [int(sim._a["cell_count"].shape[0]), int(sim._a["cell_start"].shape[0])]
    with h5py.File(str(path), "w") as f:
        f.attrs["format"] = FORMAT
        f.attrs["version"] = VERSION
        f.attrs["simulation"] = repr(sim)
        f.attrs["config"] = json.dumps(cfg)
        st = f.create_group("state")
        for k, v in state.items():
            st.create_dataset(k, data=v)
        host = f.create_group("host")
        sizes = [len(r) for r in sim._host["radius"]]
        host.create_dataset("sizes", data=np.asarray(sizes, dtype=np.int64))
        for k in _HOST_KEYS:
            chunks = sim._host[k]
            if chunks:
                host.create_dataset(k, data=np.concatenate(chunks))
        walls = np.asarray(sim._walls_host, dtype=np.float64)
        host.create_dataset("walls", data=walls.reshape(len(sim._walls_host),
                                                        wall_width(sim.dim)))
        fn_loads = [k for k, (ids, *vals) in enumerate(sim._loads) if any(map(callable, vals))]
        fn_loads += [f"block {b.index}" for b in sim._blocks
                     if any(callable(v) for _, *vals in b._loads for v in vals)]
        if fn_loads:
            warnings.warn(f"save: applied loads given as functions of time ({fn_loads}) are "
                          "saved as their values now; the loaded simulation keeps them "
                          "constant", stacklevel=3)
        fixes = f.create_group("fixes")
        for n, (ids, *vals) in enumerate(sim._fixes):
            g = fixes.create_group(f"{n:04d}")
            g.create_dataset("ids", data=np.asarray(ids, dtype=np.int64))
            for name, v in zip(_FIX_NAMES if sim.dim == 2 else _FIX_NAMES_3D, vals):
                if v is None:
                    continue
                if callable(v):
                    warnings.warn(f"save: the prescribed {name} of fix_particles call {n} is a "
                                  f"function ({getattr(v, '__name__', v)!r}) and cannot be "
                                  f"saved; the loaded simulation leaves {name} of these "
                                  "particles free", stacklevel=3)
                    continue
                g.create_dataset(name, data=np.asarray(v, dtype=np.float64))
        _flows_to(f, sim)
        blocks = f.create_group("blocks")
        for n, b in enumerate(sim._blocks):
            g = blocks.create_group(f"{n:04d}")
            g.attrs["slot"] = b.slot
            g.attrs["rigid"] = bool(b.rigid)
            g.create_dataset("vertices", data=b.vertices)
            g.create_dataset("triangles", data=b.triangles)
            g.create_dataset("velocity", data=b.velocity)
            for k, (ids, *vals) in enumerate(b._fixes):
                fg = g.create_group(f"fix{k:04d}")
                fg.create_dataset("ids", data=np.asarray(ids, dtype=np.int64))
                for name, v in zip(("vx", "vy"), vals):
                    if v is None:
                        continue
                    if callable(v):
                        warnings.warn(f"save: the prescribed {name} of fix call {k} of block {n} "
                                      "is a function and cannot be saved; the loaded "
                                      f"simulation leaves {name} of these nodes free",
                                      stacklevel=3)
                        continue
                    fg.create_dataset(name, data=np.asarray(v, dtype=np.float64))
        if sim._cont is not None:
            sim._cont.sync_copies()
            cg = f.create_group("continuum")
            for k, arr in sim._cont.a.items():
                if k in CONTINUUM_SAVED:
                    data = sim._cont.synced_cover() if k == "ncov" else arr.to_numpy()
                    cg.create_dataset(k, data=data)
            for kind in sim._cont.nr:
                ng = f.create_group(f"nonreflecting_{kind}")
                ng.create_dataset("ids", data=sim._cont.a[f"nr{kind}ids"].to_numpy())
                ng.create_dataset("coef", data=sim._cont.a[f"nr{kind}coef"].to_numpy())
    return path




_CONFIG_KEYS = ("gravity", "dt", "dt_fraction", "precision", "local_damping",
                "global_damping", "skin", "check_interval", "progress", "laws",
                "pair_override", "groups", "n", "cap", "capw", "time", "steps", "last_fit",
                "built")


class _Reader:
    """Reads a checkpoint file; anything missing or unreadable is refused with an
    InputError naming the file and the item."""

    def __init__(self, f, name):
        self.f = f
        self.name = name

    def fail(self, what):
        raise InputError(f"path: checkpoint {self.name!r} is damaged: {what}")

    def has(self, key, node=None):
        try:
            return key in (self.f if node is None else node)
        except Exception as e:  # h5py raises several types for a broken file
            self.fail(f"cannot read {key!r} ({type(e).__name__}: {e})")

    def node(self, key, node=None):
        node = self.f if node is None else node
        if not self.has(key, node):
            self.fail(f"it lacks {_item(node, key)!r}")
        try:
            return node[key]
        except Exception as e:
            self.fail(f"cannot read {_item(node, key)!r} ({type(e).__name__}: {e})")

    def array(self, key, node=None):
        d = self.node(key, node)
        try:
            return np.asarray(d[()])
        except Exception as e:
            self.fail(f"cannot read {d.name!r} ({type(e).__name__}: {e})")

    def attr(self, key, node=None, default=KeyError):
        node = self.f if node is None else node
        try:
            if key not in node.attrs:
                if default is KeyError:
                    self.fail(f"it lacks the attribute {key!r} of {node.name!r}")
                return default
            return node.attrs[key]
        except InputError:
            raise
        except Exception as e:
            self.fail(f"cannot read the attribute {key!r} ({type(e).__name__}: {e})")

    def keys(self, node):
        try:
            return sorted(node)
        except Exception as e:
            self.fail(f"cannot list {node.name!r} ({type(e).__name__}: {e})")


def _item(node, key):
    return f"{node.name.rstrip('/')}/{key}" if node.name != "/" else f"/{key}"


def _read(path):
    """Everything :func:`load` needs from the file, as plain Python and numpy."""
    import os

    import h5py
    name = str(path)
    if not os.path.exists(name):
        raise FileNotFoundError(f"path: no checkpoint file {name!r}")
    try:
        f = h5py.File(name, "r")
    except OSError as e:
        raise InputError(f"path: {name!r} is not a readable HDF5 file (truncated or "
                         f"damaged?): {e}") from None
    r = _Reader(f, name)
    with f:
        if r.attr("format", default=None) != FORMAT:
            raise InputError(f"path: {name!r} is not a tdem checkpoint")
        version = int(r.attr("version", default=0))
        if version > VERSION:
            raise InputError(f"path: checkpoint version {version} is newer than this tdem "
                             f"reads ({VERSION})")
        try:
            cfg = json.loads(r.attr("config"))
        except (TypeError, ValueError) as e:
            r.fail(f"its config is not valid JSON ({e})")
        if not isinstance(cfg, dict):
            r.fail(f"its config is not a JSON object, got {type(cfg).__name__}")
        missing = [k for k in _CONFIG_KEYS if k not in cfg]
        if missing:
            r.fail(f"its config lacks {', '.join(map(repr, missing))}")
        st = r.node("state")
        state = {k: r.array(k, st) for k in r.keys(st)}
        hg = r.node("host")
        host = {k: r.array(k, hg) for k in r.keys(hg)}
        if cfg.get("dim", 2) == 3:
            # mesh rows written before the belts' surface velocity (21 columns)
            for table, k in ((host, "walls"), (state, "wall")):
                t = table.get(k)
                if t is not None and t.ndim == 2 and t.shape[1] == TRI_WIDTH - 3:
                    table[k] = np.concatenate([t, np.zeros((len(t), 3))], axis=1)
        blocks = []
        bg = r.node("blocks") if r.has("blocks") else None
        for key in r.keys(bg) if bg is not None else []:
            g = r.node(key, bg)
            bfix = []
            for fk in [x for x in r.keys(g) if x.startswith("fix")]:
                fg = r.node(fk, g)
                bfix.append((r.array("ids", fg), *[r.array(nm, fg) if r.has(nm, fg) else None
                                                   for nm in ("vx", "vy")]))
            blocks.append((int(r.attr("slot", g)), r.array("vertices", g),
                           r.array("triangles", g), r.array("velocity", g), bfix,
                           bool(r.attr("rigid", g, default=False))))
        cstate = {}
        if r.has("continuum"):
            cg = r.node("continuum")
            cstate = {k: r.array(k, cg) for k in r.keys(cg)}
        nonref = {}
        for kind in ("p", "v"):
            if r.has(f"nonreflecting_{kind}"):
                g = r.node(f"nonreflecting_{kind}")
                nonref[kind] = (r.array("ids", g), r.array("coef", g))
        fixes = []
        fg = r.node("fixes")
        for key in r.keys(fg):
            g = r.node(key, fg)
            names = _FIX_NAMES_3D if cfg.get("dim", 2) == 3 else _FIX_NAMES
            fixes.append((r.array("ids", g), *[r.array(nm, g) if r.has(nm, g) else None
                                               for nm in names]))
        flows = {}
        if r.has("flows"):
            fl = r.node("flows")
            for key in r.keys(fl):
                g = r.node(key, fl)
                flows[key] = tuple(r.array(nm, g) for nm in ("ids", "times", "masses")
                                   if r.has(nm, g))
    if version < 2:
        _upgrade_v1(state, host)
    if version < 3:
        _upgrade_v2(state)
    raw = dict(cfg=cfg, state=state, host=host, blocks=blocks, cstate=cstate, nonref=nonref,
               fixes=fixes, version=version, flows=flows)
    _check(r, raw)
    return raw


def _upgrade_v2(state):
    """A checkpoint written before the work account: the account starts at the load,
    from the kinetic energy then."""
    if "pos" in state and "prop" in state and "vel" in state:
        n = len(state["pos"])
        work = np.zeros((n, 7))
        v, prop = state["vel"], state["prop"]
        w = state.get("omega", np.zeros(n))
        work[:, 6] = 0.5 * (prop[:, 1] * np.einsum("ij,ij->i", v, v) + prop[:, 2] * w * w)
        state.setdefault("ework", work)


def _upgrade_v1(state, host):
    """A version-1 checkpoint (discs only): the particles get angle 0 and the disc shape,
    the histories the shape columns (zeros: not tracked)."""
    from physics import contact_law as cl
    if "radius" in host:
        n = len(host["radius"])
        host.setdefault("shape", np.zeros((n, 4)))
        host.setdefault("angle", np.zeros(n))
    if "pos" in state:
        n = len(state["pos"])
        state.setdefault("angle", np.zeros(n))
        state.setdefault("shp", np.zeros((n, 4)))
    for k, tail in (("hist", 4), ("whist", 3)):
        if k in state:
            h = state[k]
            if k == "hist" and h.shape[-1] == 4:      # written before u0 existed
                h = cl.remap_history(h, 5, tail=4)
            new = len(cl.PAIR_TAIL if k == "hist" else cl.WALL_TAIL) + 3 - tail
            state[k] = np.concatenate([h, np.zeros(h.shape[:-1] + (new,), h.dtype)], axis=-1)


def _first_bad(a):
    """Index (a tuple) of the first non-finite entry of ``a``, or None."""
    a = np.asarray(a)
    if a.dtype.kind not in "fc":
        return None
    bad = ~np.isfinite(a)
    if not bad.any():
        return None
    return tuple(int(i) for i in np.argwhere(bad)[0])


def _check(r, raw):
    """Refuse a checkpoint whose parts do not fit together (sizes, indices) or hold
    NaN or infinite values where the state must be finite."""
    from . import state as schema
    cfg, state, host = raw["cfg"], raw["state"], raw["host"]

    def whole(key, lo=0):
        v = cfg[key]
        if isinstance(v, bool) or not isinstance(v, int) or v < lo:
            r.fail(f"config {key!r} must be a whole number >= {lo}, got {v!r}")
        return v

    n, cap, capw = whole("n"), whole("cap", 1), whole("capw", 1)
    whole("steps")
    for key in ("time", "dt_fraction"):
        if not isinstance(cfg[key], (int, float)) or not math.isfinite(cfg[key]):
            r.fail(f"config {key!r} must be a finite number, got {cfg[key]!r}")
    if not isinstance(cfg["laws"], list) or not isinstance(cfg["groups"], list):
        r.fail("config 'laws' and 'groups' must be lists")
    nlaws = len(cfg["laws"])

    # the particles as added
    for k in ("sizes", "walls"):
        if k not in host:
            r.fail(f"it lacks '/host/{k}'")
    sizes = host["sizes"]
    if sizes.ndim != 1 or (sizes.size and (sizes.dtype.kind not in "iu" or sizes.min() < 0)) \
            or int(sizes.sum()) != n:
        r.fail(f"'/host/sizes' {sizes.tolist()[:8]} does not add up to its {n} particles")
    dim = cfg.get("dim", 2)
    if dim not in (2, 3):
        r.fail(f"its config gives dim {dim!r}, expected 2 or 3")
    WALL_WIDTH = wall_width(dim)
    if n:
        for k, width in (("pos", dim), ("vel", dim), ("radius", 0), ("density", 0),
                         ("law", 0)):
            if k not in host:
                r.fail(f"it lacks '/host/{k}'")
            want = (n, width) if width else (n,)
            if host[k].shape != want:
                r.fail(f"'/host/{k}' has shape {host[k].shape}, expected {want} for its {n} "
                       "particles")
            bad = _first_bad(host[k])
            if bad is not None:
                r.fail(f"'/host/{k}' holds {host[k][bad]} at {list(bad)} (not finite)")
        if host["law"].size and (host["law"].min() < 0 or host["law"].max() >= max(nlaws, 1)):
            r.fail(f"'/host/law' holds law ids outside [0, {nlaws})")
    walls = host["walls"]
    if walls.ndim != 2 or walls.shape[1] != WALL_WIDTH:
        r.fail(f"'/host/walls' has shape {walls.shape}, expected (walls, {WALL_WIDTH})")
    if _first_bad(walls) is not None:
        r.fail(f"'/host/walls' holds non-finite values (wall {_first_bad(walls)[0]})")
    wl = walls[:, W_LAW if dim == 2 else T_LAW]
    if len(walls) and (np.any(wl != np.round(wl)) or wl.min() < 0 or wl.max() >= nlaws):
        r.fail(f"'/host/walls' gives a wall the law {wl.tolist()[:8]}, outside [0, {nlaws})")
    prims = cfg.get("primitives", [])
    try:
        pr = np.asarray(prims, dtype=float).reshape(len(prims), PRIM_WIDTH)
    except (TypeError, ValueError):
        r.fail(f"config 'primitives' must be rows of {PRIM_WIDTH} numbers, got {prims!r:.80}")
    if len(pr) and (dim != 3 or not np.isfinite(pr).all()
                    or not np.isin(pr[:, PR_KIND], (PLANE, CYLINDER_IN, CYLINDER_OUT)).all()
                    or np.any(pr[:, PR_LAW] != np.round(pr[:, PR_LAW]))
                    or pr[:, PR_LAW].min() < 0 or pr[:, PR_LAW].max() >= nlaws):
        r.fail(f"config 'primitives' holds a row that is not a primitive wall of a 3D "
               f"model: {pr.tolist()!r:.200}")
    if n:
        for k in ("radius", "density"):
            bad = host[k] <= 0
            if bad.any():
                i = int(np.argmax(bad))
                r.fail(f"'/host/{k}' gives particle {i} the {k} {host[k][i]!r} (must be > 0)")

    for k, gd in enumerate(cfg["groups"]):
        try:
            first, count, law = int(gd["first"]), int(gd["count"]), int(gd["law"])
        except (KeyError, TypeError, ValueError):
            r.fail(f"config group {k} is {gd!r}, expected first, count and law")
        if first < 0 or count < 0 or first + count > n or not 0 <= law < nlaws:
            r.fail(f"config group {k} {gd!r} does not fit its {n} particles and {nlaws} laws")
    for ids, *vals in raw["fixes"]:
        if ids.ndim != 1 or ids.dtype.kind not in "iu" or (
                ids.size and (ids.min() < 0 or ids.max() >= n)):
            r.fail(f"a prescribed velocity names particles {ids.tolist()[:8]} outside "
                   f"[0, {n})")
        for v in vals:
            if v is not None and _first_bad(v) is not None:
                r.fail("a prescribed velocity is not finite")

    # the device state: every saved array, sized for n, cap, capw
    if cfg["built"] and n:
        lead = {"particle": (n,), "slot": (n, cap), "wall_slot": (n, capw)}
        for name in schema.saved():
            if name not in state and schema.BY_NAME[name].owner == "bond" and \
                    not cfg.get("nbonds", 0):
                continue                 # written before bonds, or a model without
            if name not in state and name in schema.PRIM_ARRAYS and \
                    not cfg.get("primitives"):
                continue                 # written before primitive walls, or without
            if name not in state:
                r.fail(f"it lacks '/state/{name}'")
            a, v = schema.BY_NAME[name], state[name]
            if a.owner in lead:
                want = lead[a.owner]
                comps = a.comps if a.comps in ("H", "HW") else schema._comps(a, {"dim": dim})
                extra = 0 if comps in (0, "i") else 1
                if v.shape[:len(want)] != want or v.ndim != len(want) + extra or (
                        isinstance(comps, int) and extra and v.shape[-1] != comps):
                    wanted = want + ((comps,) if isinstance(comps, int) and extra else
                                     ("k",) if extra else ())
                    r.fail(f"'/state/{name}' has shape {v.shape}, expected "
                           f"{tuple(wanted)} for its {n} particles")
                bad = _first_bad(v)
                if bad is not None:
                    what = "particle" if a.owner == "particle" else "entry"
                    r.fail(f"'/state/{name}' holds {v[bad]} at {list(bad)} (not finite, "
                           f"{what} {bad[0]})")
        nwalls = len(walls)
        for name, lo, hi in (("plaw", 0, max(nlaws, 1) - 1), ("nbr", -1, n - 1),
                             ("ncnt", 0, cap), ("rcnt", 0, cap), ("wid", -1, nwalls - 1)):
            v = state[name]
            if v.dtype.kind not in "iu":
                r.fail(f"'/state/{name}' holds {v.dtype} numbers, expected integers")
            out = (v < lo) | (v > hi)
            if out.any():
                k = tuple(int(i) for i in np.argwhere(out)[0])
                r.fail(f"'/state/{name}' holds {int(v[k])} at {list(k)}, outside "
                       f"[{lo}, {hi}]")
        for col, what in ((0, "radius"), (1, "mass")):
            bad = state["prop"][:, col] <= 0
            if bad.any():
                k = int(np.argmax(bad))
                r.fail(f"'/state/prop' gives particle {k} the {what} "
                       f"{state['prop'][k, col]!r} (must be > 0)")
        if state["wall"].ndim != 2 or state["wall"].shape[1] != WALL_WIDTH or \
                state["wall"].shape[0] < len(walls):
            r.fail(f"'/state/wall' has shape {state['wall'].shape}, expected "
                   f"({max(len(walls), 1)}, {WALL_WIDTH})")
        for name, size in (("flags", None), ("gridp", 2 * dim), ("gridn", 4)):
            v = state[name]
            if v.ndim != 1 or (size is not None and v.shape[0] != size):
                r.fail(f"'/state/{name}' has shape {v.shape}")
    elif cfg["built"] and state:
        r.fail(f"'/state' holds arrays but its config has {n} particles")

    # blocks: meshes, slots
    nslots = len(cfg.get("slots", []))
    for k, (slot, x, t, vel, bfix, rigid) in enumerate(raw["blocks"]):
        if not 0 <= slot < nslots:
            r.fail(f"block {k} has material slot {slot}, outside [0, {nslots})")
        try:
            _mesh.check_mesh(x, t)
        except InputError as e:
            r.fail(f"the mesh of block {k}: {e}")
        if vel.shape != x.shape or _first_bad(vel) is not None:
            r.fail(f"the velocity of block {k} has shape {vel.shape} or is not finite")
        for ids, *vals in bfix:
            if ids.ndim != 1 or ids.dtype.kind not in "iu" or (
                    ids.size and (ids.min() < 0 or ids.max() >= len(x))):
                r.fail(f"a prescribed velocity of block {k} names nodes outside "
                       f"[0, {len(x)})")
    for key in ("npos", "nvel", "npos0"):
        if key in raw["cstate"]:
            bad = _first_bad(raw["cstate"][key])
            if bad is not None:
                r.fail(f"'/continuum/{key}' holds {raw['cstate'][key][bad]} at {list(bad)} "
                       f"(not finite, block node {bad[0]})")


def load(path, arch=None):
    """A new :class:`tdem.Simulation` from a checkpoint written by :func:`save`.

    ``arch``: as for :class:`tdem.Simulation` (None: the one in use, else
    ``$TDEM_ARCH``, else "cpu"). The loaded simulation has the same time, step count,
    particles, contacts (with their history), walls, laws and prescribed velocities,
    and continues exactly as the saved one would have.

    A file that is not a readable tdem checkpoint, or whose parts are missing, do not
    fit together (array sizes, indices) or hold NaN or infinite values in the state,
    is refused with :class:`tdem.InputError` (a ``ValueError``) naming the file and
    what is wrong.
    """
    from physics.contact_law import ContactLaw

    from physics.materials import Material

    from .simulation import Block, ParticleGroup, Simulation

    raw = _read(path)
    cfg, state, host, blocks = raw["cfg"], raw["state"], raw["host"], raw["blocks"]
    cstate, nonref, fixes = raw["cstate"], raw["nonref"], raw["fixes"]

    sim = Simulation(gravity=cfg["gravity"], dt=None, dt_fraction=cfg["dt_fraction"],
                     arch=arch, precision=cfg["precision"],
                     local_damping=cfg["local_damping"], global_damping=cfg["global_damping"],
                     skin=cfg["skin"], check_interval=cfg["check_interval"],
                     progress=cfg["progress"], dim=cfg.get("dim", 2),
                     broad_phase=cfg.get("broad_phase", "grid"),
                     # files written before the mixed discretization continue without it
                     mixed_discretization=bool(cfg.get("mixed_discretization", False)))
    sim._dt_user = cfg["dt"]
    sim._laws = [ContactLaw.from_dict(d) for d in cfg["laws"]]
    sim._pair_override = {(a, b): c for a, b, c in cfg["pair_override"]}

    offsets = np.concatenate([[0], np.cumsum(host["sizes"])]).astype(np.int64)
    if "mat" not in host and "radius" in host:
        host["mat"] = np.full(len(host["radius"]), -1)
    if "omega" not in host and "radius" in host:
        host["omega"] = np.zeros(len(host["radius"]))     # written before initial spins
    if "ident" not in host and "radius" in host:
        host["ident"] = np.arange(len(host["radius"]))    # written before identities
    for k in _HOST_KEYS:
        sim._host[k] = ([np.array(host[k][a:b]) for a, b in zip(offsets[:-1], offsets[1:])]
                        if k in host else [])
    sim._slots = [(Material.from_dict(d["material"]), d["tolerance"])
                  for d in cfg.get("slots", [])]
    for k, (slot, x, t, vel, bfix, rigid) in enumerate(blocks):
        b = Block(sim, k, x, t, sim._slots[slot][0], slot, vel)
        b._fixes = bfix
        b.rigid = rigid
        sim._blocks.append(b)
    from coupling.point_edge import PointEdge
    sim._couples = [(None if c["ids"] is None else np.asarray(c["ids"], np.int64),
                     None if c.get("a") is None else sim._blocks[c["a"]],
                     sim._blocks[c["block"]], PointEdge(**c["law"]))
                    for c in cfg.get("couples", [])]
    for gd, rho in zip(cfg["groups"], sim._host["density"]):
        ids = np.arange(gd["first"], gd["first"] + gd["count"])
        sim._groups.append(ParticleGroup(sim, ids, sim._laws[gd["law"]], rho))
    sim._walls_host = list(host["walls"])
    sim._periodic = [None if p is None else tuple(p)
                     for p in cfg.get("periodic", [None] * sim.dim)]
    sim._meshes = [tuple(m) for m in cfg.get("meshes", [])]
    sim._prims_host = [np.asarray(row, dtype=float) for row in cfg.get("primitives", [])]
    sim._mesh_servo = {m: (k, f, np.asarray(d, float), a, v)
                       for m, k, f, d, a, v in cfg.get("mesh_servo", [])}
    sim._polys = [Polyhedron(v) for v in cfg.get("polyhedra", [])]
    sim._fixes = fixes
    sim._n = cfg["n"]
    sim._next_ident = int(cfg.get("next_ident", cfg["n"]))
    sim._nbonds = int(cfg.get("nbonds", 0))
    if sim._nbonds and not cfg["built"]:
        sim._bond_host = {k: np.asarray(state[k])[:sim._nbonds]
                          for k in ("bpair", "bprop", "bstate")}
    sim._flow_offsets = dict(cfg.get("flow_offsets", {}))
    _flows_from(sim, cfg, raw.get("flows", {}))
    from .motion import from_dict as _motion
    for m in cfg.get("motions", []):
        sim._motions[(m["kind"], m["index"])] = (
            m["first"], m["count"],
            None if m["velocity"] is None else _motion(m["velocity"]),
            None if m["angular_velocity"] is None else _motion(m["angular_velocity"]))
    sim._cap = cfg["cap"]
    sim._capw = cfg["capw"]
    sim._time = cfg["time"]
    sim._steps = cfg["steps"]

    if cfg["built"] and sim._slots:
        sim._cont = sim._new_continuum()
        cap = cfg.get("continuum_capacity", 0)
        if cap > sim._cont.capacity:
            sim._cont.capacity = cap
            sim._cont._alloc_lists()
    if cfg["built"] and state:
        _restore_device(sim, state, cfg)
    elif cfg["built"] and sim._blocks:
        sim._build()
    if sim._cont is not None:
        for k, v in cstate.items():
            arr = sim._cont.a.get(k)
            if arr is None:
                continue
            if k == "pjwl" and v.ndim == 2 and v.shape[1] == 5:
                # files written before the pending volume change (column 5) was kept
                v = np.concatenate([v, np.zeros((len(v), 1))], axis=1)
            if k in ("psedge", "vsedge") and raw["version"] < 4:
                v = sim._cont.edges_from_version_3(k[0], v)
            if k == "ccand" and v.ndim == 2 and arr.shape[1] != v.shape[1]:
                sim._cont._cells_cap(v.shape[1])     # the saved run's capacity
                arr = sim._cont.a[k]
            if tuple(arr.shape) != v.shape[:len(arr.shape)]:
                raise InputError(f"path: checkpoint {str(path)!r} is damaged: "
                                 f"'/continuum/{k}' has shape {v.shape}, expected "
                                 f"{tuple(arr.shape)} first")
            arr.from_numpy(np.ascontiguousarray(v))
        sim._cont.apply_node_fixes(sim._time, initial=True)
        for kind, (ids, coef) in nonref.items():
            sim._cont.set_non_reflecting(kind, ids, coef)
    sim._last_fit = cfg["last_fit"]
    sim._account0 = cfg.get("account0")
    sim._loads_on = bool("fext" in state and np.any(state["fext"]))
    if raw["version"] < 3 and sim._cont is not None and sim._cont.nv:
        # no work account before version 3: it starts at the load
        sim._cont.restart_work()
    return sim


def _restore_device(sim, state, cfg):
    """Allocate and fill the device arrays, then put back what the rebuild refits:
    the cell grid, the scratch sizes that depend on it, and the status flags (so
    that the neighbour lists are rebuilt when, and only when, the saved run would
    have rebuilt them)."""
    import taichi as ti

    if "hist" in state and state["hist"].shape[-1] == 4:
        # written before the pair history held the overlap offset (step.pair_contact)
        state["hist"] = np.concatenate([state["hist"], np.zeros(state["hist"].shape[:-1]
                                                                + (1,))], axis=-1)
    sim._rebuild_from({k: np.array(v) for k, v in state.items()})
    a = sim._a
    ncount, nstart = cfg.get("cells", (a["cell_count"].shape[0], a["cell_start"].shape[0]))
    if a["cell_count"].shape[0] != ncount:
        a["cell_count"] = ti.ndarray(ti.i32, (int(ncount),))
    if a["cell_start"].shape[0] != nstart:
        a["cell_start"] = ti.ndarray(ti.i32, (int(nstart),))
    for k in ("gridp", "gridn", "flags"):
        if k in state:
            sim._fill(k, state[k])
    sim._sweep_stale()
