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
again after loading) and prescribed velocities given as functions of time (saved
as free, with a warning).

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
import warnings

import numpy as np

from .continuum import SAVED as CONTINUUM_SAVED
from .errors import InputError
from .step import WALL_WIDTH

FORMAT = "tdem-checkpoint"
VERSION = 1
_FIX_NAMES = ("vx", "vy", "omega")
_HOST_KEYS = ("pos", "vel", "radius", "density", "law", "mat")


def _config(sim):
    laws = sim._laws
    groups = []
    for g in sim._groups:
        law = next(k for k, known in enumerate(laws) if known is g.contact)
        groups.append({"first": int(g.ids[0]), "count": int(len(g.ids)), "law": law})
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
        "couples": [{"ids": None if ids is None else [int(i) for i in ids],
                     "a": None if a is None else int(a.index), "block": int(b.index),
                     "law": law.to_dict()} for ids, a, b, law in sim._couples],
    }


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
        host.create_dataset("walls", data=walls.reshape(len(sim._walls_host), WALL_WIDTH))
        fixes = f.create_group("fixes")
        for n, (ids, *vals) in enumerate(sim._fixes):
            g = fixes.create_group(f"{n:04d}")
            g.create_dataset("ids", data=np.asarray(ids, dtype=np.int64))
            for name, v in zip(_FIX_NAMES, vals):
                if v is None:
                    continue
                if callable(v):
                    warnings.warn(f"save: the prescribed {name} of fix_particles call {n} is a "
                                  f"function ({getattr(v, '__name__', v)!r}) and cannot be "
                                  f"saved; the loaded simulation leaves {name} of these "
                                  "particles free", stacklevel=3)
                    continue
                g.create_dataset(name, data=np.asarray(v, dtype=np.float64))
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
                    cg.create_dataset(k, data=arr.to_numpy())
            for kind in sim._cont.nr:
                ng = f.create_group(f"nonreflecting_{kind}")
                ng.create_dataset("ids", data=sim._cont.a[f"nr{kind}ids"].to_numpy())
                ng.create_dataset("coef", data=sim._cont.a[f"nr{kind}coef"].to_numpy())
    return path




def load(path, arch=None):
    """A new :class:`tdem.Simulation` from a checkpoint written by :func:`save`.

    ``arch``: as for :class:`tdem.Simulation` (None: ``$TDEM_ARCH``, else "cpu").
    The loaded simulation has the same time, step count, particles, contacts (with
    their history), walls, laws and prescribed velocities, and continues exactly as
    the saved one would have.
    """
    import h5py

    from physics.contact_law import ContactLaw

    from physics.materials import Material

    from .simulation import Block, ParticleGroup, Simulation

    with h5py.File(str(path), "r") as f:
        if f.attrs.get("format") != FORMAT:
            raise InputError(f"path: {str(path)!r} is not a tdem checkpoint")
        version = int(f.attrs.get("version", 0))
        if version > VERSION:
            raise InputError(f"path: checkpoint version {version} is newer than this tdem "
                             f"reads ({VERSION})")
        cfg = json.loads(f.attrs["config"])
        state = {k: d[()] for k, d in f["state"].items()}
        host = {k: f["host"][k][()] for k in f["host"]}
        blocks = []
        for key in sorted(f["blocks"]) if "blocks" in f else []:
            g = f["blocks"][key]
            bfix = []
            for fk in sorted(x for x in g if x.startswith("fix")):
                fg = g[fk]
                bfix.append((fg["ids"][()], *[fg[nm][()] if nm in fg else None
                                              for nm in ("vx", "vy")]))
            blocks.append((int(g.attrs["slot"]), g["vertices"][()], g["triangles"][()],
                           g["velocity"][()], bfix, bool(g.attrs.get("rigid", False))))
        cstate = ({k: d[()] for k, d in f["continuum"].items()} if "continuum" in f else {})
        nonref = {kind: (f[f"nonreflecting_{kind}"]["ids"][()],
                         f[f"nonreflecting_{kind}"]["coef"][()])
                  for kind in ("p", "v") if f"nonreflecting_{kind}" in f}
        fixes = []
        for key in sorted(f["fixes"]):
            g = f["fixes"][key]
            fixes.append((g["ids"][()], *[g[name][()] if name in g else None
                                          for name in _FIX_NAMES]))

    sim = Simulation(gravity=cfg["gravity"], dt=None, dt_fraction=cfg["dt_fraction"],
                     arch=arch, precision=cfg["precision"],
                     local_damping=cfg["local_damping"], global_damping=cfg["global_damping"],
                     skin=cfg["skin"], check_interval=cfg["check_interval"],
                     progress=cfg["progress"])
    sim._dt_user = cfg["dt"]
    sim._laws = [ContactLaw.from_dict(d) for d in cfg["laws"]]
    sim._pair_override = {(a, b): c for a, b, c in cfg["pair_override"]}

    offsets = np.concatenate([[0], np.cumsum(host["sizes"])]).astype(np.int64)
    if "mat" not in host and "radius" in host:
        host["mat"] = np.full(len(host["radius"]), -1)
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
    sim._fixes = fixes
    sim._n = cfg["n"]
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
            if arr is not None and tuple(arr.shape) == v.shape[:len(arr.shape)]:
                arr.from_numpy(np.ascontiguousarray(v))
        sim._cont.apply_node_fixes(sim._time, initial=True)
        for kind, (ids, coef) in nonref.items():
            sim._cont.set_non_reflecting(kind, ids, coef)
    sim._last_fit = cfg["last_fit"]
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
