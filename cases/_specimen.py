"""Biaxial specimens of discs: grading, preparation to a void ratio, consolidation and
strain-controlled shearing between four walls (Jiang, Yu & Harris 2005, §5).

The specimen is a rectangle of discs between four rigid walls with their own
contact law (frictionless, no rolling resistance, as in the paper). The walls are
longer than the sides of the specimen, so that they keep touching the corner discs
while the specimen changes shape. Stresses are wall forces over the current
lengths of the specimen's sides (plane, unit thickness), compression-positive:
``sigma_h`` from the two side walls, ``sigma_v`` from the bottom and top walls.

Preparation (:func:`prepare`)
-----------------------------
1. Diameters are drawn from a grading curve (:func:`gradation`) and the discs are
   placed, in random order, on a loose rectangular lattice (solid fraction about
   0.45) whose aspect ratio is that of the specimen.
2. The four walls close in at a uniform strain rate (which keeps the shape),
   slowing down on the way, until the void ratio is 0.06 above the target: still
   looser than any jammed packing of these discs, so no stress has built up.
3. The four walls are servo-controlled to the isotropic stress ``confining`` with
   the inter-particle friction set to ``prep_friction`` (default 1.0, twice the
   paper's material: a looser packing than the target). Once the specimen is at
   rest under that stress, the friction is lowered step by step (x 0.7 each time)
   and the specimen re-equilibrated at the same stress each time; a lower friction
   lets the discs slide into a denser arrangement. This stops as soon as the
   planar void ratio ``e = (W H - A_s)/A_s`` (``A_s`` the total area of the discs,
   ``W`` and ``H`` the distances between opposite walls) is no more than
   ``void_ratio`` + ``void_tolerance`` (0.002).
4. The friction is set back to the material's value and the specimen is brought
   to rest once more under the isotropic stress (restoring friction does not
   loosen it, so the void ratio stays where step 3 left it).

Rolling resistance is off during preparation (as in the paper, where the shape
parameter is set to zero so that every specimen has the same void ratio and
fabric); :func:`shear` switches it on before compression.

Shearing (:func:`shear`)
------------------------
The bottom and top walls move towards each other so that the vertical strain rate,
change of height over current height, stays at ``strain_rate``; the side walls are
servo-controlled to keep ``sigma_h``: their target force is ``sigma_h`` times the
current height, updated every ``update_strain`` of axial strain (5e-4), plus an
integral correction: the engine's servo is a proportional controller, which lags
behind its target by a force proportional to the wall's speed while the specimen
dilates; every update raises the target by half the mean stress error since the
last one. Axial strain is
``(H0 - H)/H0``, lateral strain ``(W0 - W)/W0`` and volumetric strain their sum
(compression-positive; dilation is negative). The mobilised friction angle is
``sin(phi) = (sigma_v - sigma_h)/(sigma_v + sigma_h)`` (:func:`friction_angles`).
"""
import math

import numpy as np

from physics import LinearContact, RollingResistance
from physics.validate import in_range, non_negative, positive

from tdem.errors import InputError
from tdem.simulation import Simulation
from tdem.step import W_CY, W_LAW, W_Y0, W_Y1

#: The specimens of Jiang, Yu & Harris (2005), §5.
PAPER = {
    "n": 1008, "width": 0.180, "height": 0.3067, "void_ratio": 0.25,
    "dmin": 6.0e-3, "dmax": 9.0e-3, "d50": 7.6e-3, "cu": 1.3,
    "kn": 2.0e8, "ks": 1.5e8, "friction": 0.5,
}
# walls reach this fraction of the specimen's side beyond each corner
_WALL_OVERHANG = 0.3
# walls close in at a uniform strain rate down to this much above the target void
# ratio (looser than any jammed packing of these discs), then servo control takes over
_COMPACT_MARGIN = 0.06
# lattice spacing of the initial loose arrangement, in largest diameters
_LATTICE_SPACING = 1.15


# ------------------------------------------------------------------ grading
def _grading_knots(dmin, dmax, d50, cu):
    """Knots (diameter, fraction finer by area) of the piecewise-linear grading curve.

    The curve passes through (dmin, 0), (d10, 0.1), (d50, 0.5), (d60, 0.6), (dmax, 1)
    with d60 = cu · d10; d10 is the value that makes the steepest and the flattest
    of the four pieces as close as possible (a near-uniform curve)."""
    lo = max(dmin, d50 / cu) + 1e-9 * dmax
    hi = min(d50, dmax / cu) - 1e-9 * dmax
    if not lo < hi:
        raise InputError(f"cu={cu!r} cannot be met with dmin={dmin!r}, d50={d50!r}, "
                         f"dmax={dmax!r} (need dmin < d10 < d50 < d60 = cu·d10 < dmax)")
    best = None
    for d10 in np.linspace(lo, hi, 2001)[1:-1]:
        d60 = cu * d10
        if not (dmin < d10 < d50 < d60 < dmax):
            continue
        x = np.array([dmin, d10, d50, d60, dmax])
        y = np.array([0.0, 0.1, 0.5, 0.6, 1.0])
        slopes = np.diff(y) / np.diff(x)
        score = slopes.max() / slopes.min()
        if best is None or score < best[0]:
            best = (score, x, y)
    if best is None:
        raise InputError(f"cu={cu!r} cannot be met with dmin={dmin!r}, d50={d50!r}, "
                         f"dmax={dmax!r}")
    return best[1], best[2]


def gradation(n, dmin=PAPER["dmin"], dmax=PAPER["dmax"], d50=PAPER["d50"], cu=PAPER["cu"],
              seed=0):
    """``n`` disc diameters (m) from a grading curve by area (the 2D analogue of mass).

    The curve is piecewise linear through (dmin, 0 %), (d10, 10 %), (d50, 50 %),
    (d60, 60 %), (dmax, 100 %) with d60 = cu · d10 (the uniformity coefficient) and
    d10 chosen to keep the curve as close to uniform as it can be. Diameters are
    drawn by number: the number density is the area density over d².
    Deterministic for a given ``seed``.

    Returns
    -------
    numpy.ndarray (n,)
    """
    if int(n) != n or n < 1:
        raise InputError(f"n must be a whole number >= 1, got {n!r}")
    dmin, dmax, d50 = positive("dmin", dmin), positive("dmax", dmax), positive("d50", d50)
    cu = positive("cu", cu)
    if not dmin < d50 < dmax:
        raise InputError(f"d50 must lie between dmin and dmax, got dmin={dmin!r}, "
                         f"d50={d50!r}, dmax={dmax!r}")
    if cu <= 1.0:
        raise InputError(f"cu must be > 1, got {cu!r}")
    x, y = _grading_knots(dmin, dmax, d50, cu)
    d = np.linspace(dmin, dmax, 4001)
    # the area density is piecewise constant: evaluate it piece by piece
    piece = np.clip(np.searchsorted(x, d, side="right") - 1, 0, len(x) - 2)
    area_density = (np.diff(y) / np.diff(x))[piece]
    number_density = area_density / d ** 2
    cdf = np.concatenate([[0.0], np.cumsum(0.5 * (number_density[1:] + number_density[:-1])
                                           * np.diff(d))])
    cdf /= cdf[-1]
    rng = np.random.default_rng(seed)
    return np.interp(rng.uniform(0.0, 1.0, int(n)), cdf, d)


def grading(diameters):
    """d10, d50, d60 (m) by area and cu = d60/d10 of a set of disc diameters."""
    d = np.sort(np.asarray(diameters, dtype=float))
    if d.size == 0 or not np.all(np.isfinite(d)) or d[0] <= 0:
        raise InputError("diameters must be positive finite numbers, got "
                         f"{np.asarray(diameters).ravel()[:5].tolist()}")
    finer = np.cumsum(d ** 2) / np.sum(d ** 2)
    q = {k: float(np.interp(p, finer, d)) for k, p in (("d10", 0.1), ("d50", 0.5), ("d60", 0.6))}
    q["cu"] = q["d60"] / q["d10"]
    return q


# ------------------------------------------------------------------ the specimen
class Specimen:
    """Discs between four walls (left, right, bottom, top) in a :class:`tdem.Simulation`.

    Attributes
    ----------
    sim : tdem.Simulation
    walls : dict of name -> tdem.Wall ("left", "right", "bottom", "top")
    law : tdem.LinearContact, the disc–disc law (changed in place by :func:`shear`)
    wall_law : tdem.LinearContact, the disc–wall law
    friction : float, the material's inter-particle friction coefficient
    solid_area : float, total area of the discs (m² per metre of thickness)
    confining : float, the isotropic stress of the last consolidation (Pa)
    history : dict, numbers recorded during preparation
    """

    def __init__(self, sim, walls, law, wall_law, friction, solid_area):
        self.sim = sim
        self.walls = walls
        self.law = law
        self.wall_law = wall_law
        self.friction = friction
        self.solid_area = solid_area
        self.confining = None
        self.history = {}

    # geometry ----------------------------------------------------------------
    def box(self):
        """(x_left, x_right, y_bottom, y_top) of the wall lines (m)."""
        rows = self.sim._wall_rows()
        idx = {k: w.index for k, w in self.walls.items()}
        return (float(rows[idx["left"], 0]), float(rows[idx["right"], 0]),
                float(rows[idx["bottom"], 1]), float(rows[idx["top"], 1]))

    @property
    def width(self):
        x0, x1, _, _ = self.box()
        return x1 - x0

    @property
    def height(self):
        _, _, y0, y1 = self.box()
        return y1 - y0

    def void_ratio(self):
        """Planar void ratio (W H − A_s)/A_s."""
        return self.width * self.height / self.solid_area - 1.0

    def stresses(self):
        """(sigma_h, sigma_v) in Pa from the wall forces of the last step,
        compression-positive: the mean force of two opposite walls over the current
        length of the side they load."""
        loads = self.sim._wall_loads()
        w = self.walls
        fh = 0.5 * (loads[w["right"].index, 0] - loads[w["left"].index, 0])
        fv = 0.5 * (loads[w["top"].index, 1] - loads[w["bottom"].index, 1])
        x0, x1, y0, y1 = self.box()
        return float(fh / (y1 - y0)), float(fv / (x1 - x0))

    # control ---------------------------------------------------------------
    def servo_lateral(self, sigma, max_speed=None, relaxation=0.5):
        """Side walls servo-controlled to ``sigma`` × the current height."""
        h = self.height
        for name in ("left", "right"):
            self.walls[name].servo(force=sigma * h, direction=_INWARD[name],
                                   max_speed=max_speed, relaxation=relaxation)

    def servo_vertical(self, sigma, max_speed=None):
        """Bottom and top walls servo-controlled to ``sigma`` × the current width."""
        w = self.width
        for name in ("bottom", "top"):
            self.walls[name].servo(force=sigma * w, direction=_INWARD[name],
                                   max_speed=max_speed)

    def stop_walls(self):
        for wall in self.walls.values():
            wall.servo()

    def compact(self, void_ratio, speed=0.5, check_every=25, max_steps=500000):
        """Close the walls on a loose arrangement at a uniform strain rate (the top and
        bottom walls at ``speed``, the side walls in proportion to the width), which
        keeps the specimen's shape, until its void ratio is ``void_ratio`` (choose
        one looser than the packing can jam at). Returns the steps run."""
        void_ratio = positive("void_ratio", void_ratio)
        speed = positive("speed", speed)
        start = self.sim.steps
        self.stop_walls()
        while self.void_ratio() > void_ratio and self.sim.steps - start < max_steps:
            # slow down on the way, so that the discs arrive without impact
            v = speed * min(1.0, max(0.1, (self.void_ratio() - void_ratio) / 0.1))
            lateral = v * self.width / self.height
            for name, d in _INWARD.items():
                self.walls[name].velocity = (d[0] * lateral, d[1] * v)
            self.sim.run(steps=check_every)
        for wall in self.walls.values():
            wall.velocity = (0.0, 0.0)
        return self.sim.steps - start

    def consolidate(self, sigma, tolerance=0.01, chunk=500, settle_chunks=3,
                    max_steps=200000, max_speed=None):
        """Servo all four walls to the isotropic stress ``sigma`` and run until the
        specimen is at rest under it: ``settle_chunks`` consecutive chunks of
        ``chunk`` steps in which both mean wall stresses are within ``tolerance`` of
        ``sigma`` and the void ratio changes by less than 1e-4. Returns the steps run.
        Raises :class:`RuntimeError` after ``max_steps`` steps without rest."""
        sigma = positive("sigma", sigma)
        start = self.sim.steps
        calm = 0
        e_prev = self.void_ratio()
        while self.sim.steps - start < max_steps:
            # speed limits in proportion to the sides: the shape is kept while the
            # walls close in on a loose arrangement at their limit
            lateral = None if max_speed is None else max_speed * self.width / self.height
            self.servo_lateral(sigma, lateral)
            self.servo_vertical(sigma, max_speed)
            sh, sv = self._mean_stresses(chunk)
            e = self.void_ratio()
            ok = (abs(sh / sigma - 1.0) < tolerance and abs(sv / sigma - 1.0) < tolerance
                  and abs(e - e_prev) < 1e-4)
            calm = calm + 1 if ok else 0
            e_prev = e
            if calm >= settle_chunks:
                self.confining = sigma
                return self.sim.steps - start
        raise RuntimeError(f"the specimen did not come to rest under {sigma:g} Pa in "
                           f"{max_steps} steps (void ratio {self.void_ratio():.4f}, "
                           f"stresses {self.stresses()})")

    def _move_wall_to(self, wall, y):
        """Translate a horizontal wall (bottom or top) to height ``y`` at once."""
        rows = self.sim._wall_rows()
        dy = float(y) - float(rows[wall.index, W_Y0])
        for c in (W_Y0, W_Y1, W_CY):
            rows[wall.index, c] += dy
        self.sim._set_wall_rows(rows)

    def settle(self, chunk=500, tolerance=1e-3, max_steps=100000):
        """Walls at rest; run until the mean wall stress changes by less than
        ``tolerance`` of itself (or of 1 kPa) from one chunk to the next."""
        self.stop_walls()
        prev = None
        for _ in range(max(1, max_steps // chunk)):
            s = float(np.mean(self._mean_stresses(chunk)))
            if prev is not None and abs(s - prev) < tolerance * max(abs(s), 1e3):
                return s
            prev = s
        import warnings
        warnings.warn(f"settle: the wall stress still changed by more than {tolerance:g} of "
                      f"itself after {max_steps} steps (last {prev:.4g} Pa)", RuntimeWarning,
                      stacklevel=2)
        return prev

    def band_void_ratios(self, bands):
        """Void ratio of ``bands`` equal horizontal bands of the specimen, from the
        disc areas inside each band (exact disc–box intersections, tdem.overlap_volume)."""
        from tdem.overlap_volume import disc_box_area
        p = self.sim.particles.numpy()
        x, r = p["position"], p["radius"]
        x0, x1, y0, y1 = self.box()
        edges = np.linspace(y0, y1, int(bands) + 1)
        solid = np.array([np.sum(disc_box_area(x, r, (x0, lo), (x1, hi)))
                          for lo, hi in zip(edges[:-1], edges[1:])])
        return (self.width * np.diff(edges) - solid) / solid

    def _mean_stresses(self, steps, samples=10):
        """Run ``steps`` steps and return the mean (sigma_h, sigma_v) over ``samples``
        evenly spaced readings."""
        per = max(1, steps // samples)
        acc = np.zeros(2)
        k = 0
        done = 0
        while done < steps:
            n = min(per, steps - done)
            self.sim.run(steps=n)
            done += n
            acc += self.stresses()
            k += 1
        return tuple(acc / k)

    # checkpoints --------------------------------------------------------------
    def save(self, path):
        """Checkpoint the specimen (:meth:`tdem.Simulation.save` plus what the specimen
        adds: walls, friction, solid area, confining stress, preparation history)."""
        import json

        import h5py
        self.sim.save(path)
        meta = {"walls": {k: w.index for k, w in self.walls.items()},
                "friction": self.friction, "solid_area": self.solid_area,
                "confining": self.confining, "history": self.history,
                "grading": getattr(self, "grading", None),
                "target_void_ratio": getattr(self, "target_void_ratio", None)}
        with h5py.File(path, "a") as f:
            f.attrs["specimen"] = json.dumps(meta)
        return path

    @classmethod
    def load(cls, path, arch=None):
        """A specimen saved by :meth:`save`, ready to continue exactly where it was."""
        import json

        import h5py
        with h5py.File(path, "r") as f:
            if "specimen" not in f.attrs:
                raise InputError(f"path: {str(path)!r} holds no specimen (saved by "
                                 "Specimen.save)")
            meta = json.loads(f.attrs["specimen"])
        sim = Simulation.load(path, arch=arch)
        walls = {k: sim.walls[i] for k, i in meta["walls"].items()}
        law = sim._groups[0].contact
        wall_law = sim._laws[int(sim._wall_rows()[walls["left"].index, W_LAW])]
        spec = cls(sim, walls, law, wall_law, meta["friction"], meta["solid_area"])
        spec.confining = meta["confining"]
        spec.history = meta["history"]
        spec.grading = meta["grading"]
        spec.target_void_ratio = meta["target_void_ratio"]
        return spec

    def state(self):
        """A small dict describing the specimen now (for summaries)."""
        sh, sv = self.stresses()
        return {"n": self.sim.n_particles, "width": self.width, "height": self.height,
                "void_ratio": self.void_ratio(), "sigma_h": sh, "sigma_v": sv,
                "time": self.sim.time, "steps": self.sim.steps}


_INWARD = {"left": (1.0, 0.0), "right": (-1.0, 0.0), "bottom": (0.0, 1.0), "top": (0.0, -1.0)}


def _lattice(n, aspect, spacing, rng):
    """``n`` centres on a rectangular lattice, at least ``spacing`` apart, filling a
    box of height/width ``aspect``; random sites when the lattice has more than ``n``.
    Returns (centres, box width, box height)."""
    nx = max(1, int(round(math.sqrt(n / aspect))))
    ny = int(math.ceil(n / nx))
    w = nx * spacing
    h = aspect * w
    if h < ny * spacing:
        h = ny * spacing
        w = h / aspect
    sites = (np.stack(np.meshgrid(np.arange(nx), np.arange(ny)), -1).reshape(-1, 2) + 0.5)
    keep = np.sort(rng.choice(len(sites), size=n, replace=False))
    return sites[keep] * np.array([w / nx, h / ny]), w, h


def prepare(n=PAPER["n"], void_ratio=PAPER["void_ratio"], confining=200e3,
            aspect=PAPER["height"] / PAPER["width"], kn=PAPER["kn"], ks=PAPER["ks"],
            friction=PAPER["friction"], density=2650.0, dmin=PAPER["dmin"],
            dmax=PAPER["dmax"], d50=PAPER["d50"], cu=PAPER["cu"], seed=0,
            prep_friction=1.0, friction_factor=0.7, min_friction=1e-3,
            void_tolerance=0.002, local_damping=0.7, dt_fraction=0.2, max_speed=0.5,
            arch=None, threads=None, check_interval=100):
    """Build, compact and consolidate a biaxial specimen (module docstring).

    Parameters
    ----------
    n : int, number of discs (the paper: 1008)
    void_ratio : float, target planar void ratio (the paper: 0.25)
    confining : float, isotropic consolidation stress (Pa)
    aspect : float, height / width of the initial arrangement (the paper: 306.7/180)
    kn, ks : float, contact stiffnesses (N/m), discs and walls
    friction : float, inter-particle friction coefficient of the material
    density : float, disc density (kg/m³; the paper gives none)
    dmin, dmax, d50, cu : grading (m, m, m, -), see :func:`gradation`
    seed : int, random seed of the diameters and of their order on the lattice
    prep_friction : float or None, friction of the first consolidation (None: ``friction``)
    friction_factor : float in (0, 1), each lowering multiplies the friction by this
    min_friction : float, below this the friction is set to zero (the last step)
    void_tolerance : float, stop lowering once e <= void_ratio + void_tolerance
    local_damping, dt_fraction, arch, threads, check_interval : see :class:`tdem.Simulation`
    max_speed : float, speed of the walls closing in and speed limit of the servo
        walls (m/s)

    Returns
    -------
    Specimen
        At rest under ``confining``, friction restored, no rolling resistance;
        ``history`` holds the friction steps and the void ratio after each.
    """
    if int(n) != n or n < 4:
        raise InputError(f"n must be a whole number >= 4, got {n!r}")
    void_ratio = positive("void_ratio", void_ratio)
    confining = positive("confining", confining)
    aspect = positive("aspect", aspect)
    friction = non_negative("friction", friction)
    prep_friction = friction if prep_friction is None else non_negative("prep_friction",
                                                                        prep_friction)
    friction_factor = in_range("friction_factor", friction_factor, 0.0, 1.0, True, True)
    void_tolerance = non_negative("void_tolerance", void_tolerance)
    max_speed = positive("max_speed", max_speed)
    rng = np.random.default_rng(seed)
    d = gradation(n, dmin, dmax, d50, cu, seed=seed)
    rng.shuffle(d)
    r = 0.5 * d
    xy, w, h = _lattice(int(n), aspect, _LATTICE_SPACING * dmax, rng)
    law = LinearContact(kn=kn, ks=ks, friction=prep_friction)
    wall_law = LinearContact(kn=kn, ks=ks, friction=0.0)
    sim = Simulation(gravity=(0.0, 0.0), local_damping=local_damping, dt_fraction=dt_fraction,
                     arch=arch, threads=threads, check_interval=check_interval)
    sim.add_particles(xy, r, density=density, contact=law)
    ox, oy = _WALL_OVERHANG * w, _WALL_OVERHANG * h
    walls = {
        "bottom": sim.add_wall((-ox, 0.0), (w + ox, 0.0), contact=wall_law),
        "right": sim.add_wall((w, -oy), (w, h + oy), contact=wall_law),
        "top": sim.add_wall((w + ox, h), (-ox, h), contact=wall_law),
        "left": sim.add_wall((0.0, h + oy), (0.0, -oy), contact=wall_law),
    }
    spec = Specimen(sim, walls, law, wall_law, friction, float(np.sum(np.pi * r * r)))
    hist = {"friction": [], "void_ratio": [], "steps": []}

    def record(mu):
        hist["friction"].append(mu)
        hist["void_ratio"].append(spec.void_ratio())
        hist["steps"].append(sim.steps)

    mu = prep_friction
    spec.compact(void_ratio + _COMPACT_MARGIN, speed=max_speed)
    spec.consolidate(confining, max_speed=max_speed)
    record(mu)
    while spec.void_ratio() > void_ratio + void_tolerance and mu > 0.0:
        mu = mu * friction_factor
        if mu < min_friction:
            mu = 0.0
        law.update(friction=mu)
        spec.consolidate(confining, max_speed=max_speed)
        record(mu)
    if mu != friction:
        law.update(friction=friction)
        spec.consolidate(confining, max_speed=max_speed)
        record(friction)
    spec.history = hist
    spec.grading = grading(d)
    spec.target_void_ratio = void_ratio
    return spec


def layer_heights(areas, width, void_ratio, undercompaction):
    """Heights (m) to which the top wall compacts each layer of the multi-layer
    under-compaction method (Jiang, Konrad & Leroueil 2003): layer i is pressed to
    its share of the final height inflated by U_i, over the layers below at theirs,

        h_i = (1 + e) [A_1 + ... + A_(i-1) + (1 + U_i) A_i] / W,
        U_i = U_1 (L - i) / (L - 1),

    ``areas`` the layers' disc areas A_i (m²), ``undercompaction`` U_1 (the first
    layer's), falling linearly to 0 at the last layer, so that the last one sets the
    specimen to ``void_ratio`` exactly; the later layers' compaction presses the
    earlier ones down to it."""
    a = np.asarray(areas, dtype=float)
    n = len(a)
    u = undercompaction * (n - 1 - np.arange(n)) / max(n - 1, 1)
    below = np.concatenate([[0.0], np.cumsum(a)[:-1]])
    return (1.0 + void_ratio) * (below + (1.0 + u) * a) / width


def prepare_layers(n=PAPER["n"], void_ratio=PAPER["void_ratio"], width=PAPER["width"],
                   layers=5, undercompaction=0.2, kn=PAPER["kn"], ks=PAPER["ks"],
                   friction=PAPER["friction"], compaction_friction=None, density=2650.0,
                   dmin=PAPER["dmin"], dmax=PAPER["dmax"], d50=PAPER["d50"], cu=PAPER["cu"],
                   seed=0, local_damping=0.7, dt_fraction=0.2, speed=0.5, check_every=25,
                   arch=None, threads=None, check_interval=100):
    """A specimen made by multi-layer under-compaction (Jiang, Konrad & Leroueil 2003,
    the method of Jiang, Yu & Harris 2005): ``layers`` layers of discs added one at a
    time on a loose lattice above the ones before, each pressed by the top wall (at
    ``speed``, slowing down over the last two diameters) to :func:`layer_heights`, with
    ``compaction_friction`` (default: the material's ``friction``) and no gravity; the
    side walls stand ``width`` apart. The last layer brings the specimen to
    ``void_ratio`` exactly; it is then left to relax with the walls at rest and the
    material's friction. Each layer holds a random, size-stratified share of the
    grading. Not consolidated: :meth:`Specimen.consolidate` brings a copy to each
    confining stress, so that all start from the same fabric and void ratio (the paper).

    ``history`` holds each layer's compaction height and the void ratios of the
    layers' bands at the end (:meth:`Specimen.band_void_ratios`), the measure of the
    method's aim, a homogeneous specimen."""
    if int(n) != n or n < 4:
        raise InputError(f"n must be a whole number >= 4, got {n!r}")
    if int(layers) != layers or not 1 <= layers <= n:
        raise InputError(f"layers must be a whole number from 1 to n={n}, got {layers!r}")
    void_ratio = positive("void_ratio", void_ratio)
    width = positive("width", width)
    undercompaction = in_range("undercompaction", undercompaction, 0.0, 1.0)
    speed = positive("speed", speed)
    friction = non_negative("friction", friction)
    mu_c = friction if compaction_friction is None else non_negative(
        "compaction_friction", compaction_friction)
    rng = np.random.default_rng(seed)
    d = gradation(n, dmin, dmax, d50, cu, seed=seed)
    # stratified by size: sorted diameters dealt in turn to the layers, then shuffled
    d = np.sort(d)
    layer_of = np.empty(int(n), dtype=int)
    for k in range(0, int(n), int(layers)):
        m = min(int(layers), int(n) - k)
        layer_of[k:k + m] = rng.permutation(int(layers))[:m]
    r = 0.5 * d
    parts = [rng.permutation(r[layer_of == i]) for i in range(int(layers))]
    areas = [float(np.sum(np.pi * p * p)) for p in parts]
    heights = layer_heights(areas, width, void_ratio, undercompaction)
    spacing = _LATTICE_SPACING * dmax
    nx = max(1, int(width // spacing))
    rows_max = max(int(math.ceil(len(p) / nx)) for p in parts)
    tall = heights[-1] + (rows_max + 2) * spacing
    law = LinearContact(kn=kn, ks=ks, friction=mu_c)
    wall_law = LinearContact(kn=kn, ks=ks, friction=0.0)
    sim = Simulation(gravity=(0.0, 0.0), local_damping=local_damping, dt_fraction=dt_fraction,
                     arch=arch, threads=threads, check_interval=check_interval)
    ox = _WALL_OVERHANG * width
    walls = {
        "bottom": sim.add_wall((-ox, 0.0), (width + ox, 0.0), contact=wall_law),
        "right": sim.add_wall((width, -ox), (width, tall + ox), contact=wall_law),
        "top": sim.add_wall((width + ox, tall), (-ox, tall), contact=wall_law),
        "left": sim.add_wall((0.0, tall + ox), (0.0, -ox), contact=wall_law),
    }
    spec = Specimen(sim, walls, law, wall_law, friction, float(sum(areas)))
    base = 0.0
    top = walls["top"]
    hist = {"layer_height": [], "layer_steps": [], "layer_stress": []}
    for i, part in enumerate(parts):
        rows = int(math.ceil(len(part) / nx))
        y0 = base + 0.5 * spacing + 0.5 * dmax
        sites = (np.stack(np.meshgrid(np.arange(nx), np.arange(rows)), -1).reshape(-1, 2)
                 + 0.5) * np.array([width / nx, spacing])
        keep = np.sort(rng.choice(len(sites), size=len(part), replace=False))
        xy = sites[keep] + np.array([0.0, y0 - 0.5 * spacing])
        spec._move_wall_to(top, y0 + rows * spacing)
        sim.add_particles(xy, part, density=density, contact=law)
        start = sim.steps
        target = float(heights[i])
        while True:
            y = spec.box()[3]
            if y <= target + 1e-9 * dmax:
                break
            v = speed * min(1.0, max(0.02, (y - target) / (2.0 * dmax)))
            top.velocity = (0.0, -min(v, (y - target) / (check_every * sim.dt)))
            sim.run(steps=check_every)
        top.velocity = (0.0, 0.0)
        hist["layer_height"].append(spec.box()[3])
        hist["layer_steps"].append(sim.steps - start)
        hist["layer_stress"].append(spec.stresses()[1])
        base = spec.box()[3]
    law.update(friction=friction)
    spec.settle()
    hist["band_void_ratio"] = spec.band_void_ratios(int(layers)).tolist()
    hist["undercompaction"] = float(undercompaction)
    hist["compaction_friction"] = float(mu_c)
    hist["layers"] = int(layers)
    spec.history = hist
    spec.grading = grading(d)
    spec.target_void_ratio = void_ratio
    return spec


# ------------------------------------------------------------------ shearing
def shear(spec, rolling=None, strain_rate=0.5, axial_strain=0.15, record_every=50,
          update_strain=5e-4, integral_gain=0.5, relaxation=1.0, max_speed=None):
    """Compress ``spec`` vertically at a constant true strain rate, holding ``sigma_h``
    (the specimen's last consolidation stress) with the side walls.

    Parameters
    ----------
    spec : Specimen, consolidated (:func:`prepare`)
    rolling : tdem.RollingResistance or None, set on the disc–disc law before shearing
    strain_rate : float, vertical strain rate dH/H per second (1/s)
    axial_strain : float in (0, 1), engineering axial strain (H0 − H)/H0 to stop at
    record_every : int, steps between records
    update_strain : float, axial strain between updates of the wall speeds and of the
        side walls' servo target (at least ``record_every`` steps apart)
    integral_gain : float in [0, 1], integral correction of the side walls' target
    relaxation : float in (0, 1], gain of the side walls' servo (:meth:`tdem.Wall.servo`)
    max_speed : float or None, speed limit of the side walls (m/s)

    Returns
    -------
    dict of numpy arrays: time (s from the start of compression), axial_strain,
    lateral_strain, volumetric_strain, sigma_h, sigma_v (Pa), void_ratio, width,
    height (m); and floats sigma_h_target, strain_rate. The records are also the
    simulation's monitors ``shearK_sigma_h``, ``shearK_sigma_v``, ``shearK_width``,
    ``shearK_height`` (K = 0 for the first compression of the simulation).
    """
    if not isinstance(spec, Specimen):
        raise InputError(f"spec must be a Specimen from tdem.specimen.prepare, got {spec!r}")
    if spec.confining is None:
        raise InputError("spec must be consolidated first (spec.confining is None)")
    if rolling is not None and not isinstance(rolling, RollingResistance):
        raise InputError(f"rolling must be a tdem.RollingResistance or None, got {rolling!r}")
    strain_rate = positive("strain_rate", strain_rate)
    integral_gain = in_range("integral_gain", integral_gain, 0.0, 1.0)
    axial_strain = in_range("axial_strain", axial_strain, 0.0, 1.0, True, True)
    if int(record_every) != record_every or record_every < 1:
        raise InputError(f"record_every must be a whole number >= 1, got {record_every!r}")
    update_strain = positive("update_strain", update_strain)
    sim = spec.sim
    sigma = spec.confining
    spec.law.update(friction=spec.friction, rolling=rolling)
    spec.stop_walls()
    record_every = int(record_every)
    update_every = max(record_every, int(round(update_strain / (strain_rate * sim.dt))))
    w0, h0 = spec.width, spec.height
    t0 = sim.time
    # records are engine monitors (taken inside the run, at their exact steps)
    taken = sim.histories()
    tag = 0
    while f"shear{tag}_sigma_h" in taken:
        tag += 1
    probes = {"sigma_h": lambda s: spec.stresses()[0], "sigma_v": lambda s: spec.stresses()[1],
              "width": lambda s: spec.width, "height": lambda s: spec.height}
    first = {k: fn(sim) for k, fn in probes.items()}
    mons = {k: sim.monitor(f"shear{tag}_{k}", fn, every=record_every) for k, fn in probes.items()}
    # the engine's servo is proportional: a side wall that has to keep moving (the
    # specimen dilates) lags behind its target by a force proportional to its speed.
    # An integral term on the host removes that offset: every update the target is
    # raised by ``integral_gain`` × the mean stress error since the last update.
    correction = 0.0
    seen = 0
    while spec.height > (1.0 - axial_strain) * h0:
        new = mons["sigma_h"].values[seen:]
        if new:
            correction += integral_gain * (sigma - float(np.mean(new)))
            seen += len(new)
        v = 0.5 * strain_rate * spec.height
        spec.walls["bottom"].velocity = (0.0, v)
        spec.walls["top"].velocity = (0.0, -v)
        spec.servo_lateral(sigma + correction, max_speed, relaxation)
        sim.run(steps=update_every)
    # the state at the end, unless the last record was taken at the last step
    last = {k: fn(sim) for k, fn in probes.items()} \
        if not mons["height"].steps or mons["height"].steps[-1] != sim.steps else None
    spec.walls["bottom"].velocity = (0.0, 0.0)
    spec.walls["top"].velocity = (0.0, 0.0)
    spec.servo_lateral(sigma, max_speed)
    rec = {}
    for k, m in mons.items():
        t, v = m.arrays()
        tail = [] if last is None else [last[k]]
        rec[k] = np.concatenate([[first[k]], np.asarray(v, dtype=float).ravel(), tail])
        rec["time"] = np.concatenate([[0.0], np.asarray(t, dtype=float) - t0,
                                      [] if last is None else [sim.time - t0]])
    w, h = rec.pop("width"), rec.pop("height")
    rec["axial_strain"] = (h0 - h) / h0
    rec["lateral_strain"] = (w0 - w) / w0
    rec["volumetric_strain"] = (w0 * h0 - w * h) / (w0 * h0)
    rec["void_ratio"] = w * h / spec.solid_area - 1.0
    rec["width"], rec["height"] = w, h
    out = {k: np.asarray(v) for k, v in rec.items()}
    out["sigma_h_target"] = sigma
    out["strain_rate"] = strain_rate
    return out


def smooth(values, window):
    """Centred moving average over ``window`` records (edges: shorter windows)."""
    v = np.asarray(values, dtype=float)
    window = max(1, int(window))
    if window == 1 or v.size == 0:
        return v.copy()
    c = np.concatenate([[0.0], np.cumsum(v)])
    half = window // 2
    i = np.arange(v.size)
    lo = np.clip(i - half, 0, v.size)
    hi = np.clip(i + half + 1, 0, v.size)
    return (c[hi] - c[lo]) / (hi - lo)


def friction_angles(result, smoothing=0.002, residual_from=0.75):
    """Peak and residual mobilised friction angles (degrees) of a :func:`shear` result.

    sin(phi) = (sigma_v − sigma_h)/(sigma_v + sigma_h), with both stresses averaged
    over a moving window of ``smoothing`` axial strain. Peak: the largest value;
    residual: the mean over the records with axial strain at least
    ``residual_from`` × the final axial strain.

    Returns
    -------
    dict: phi_peak, phi_residual (degrees), strain_at_peak, sigma_v_peak,
    sigma_h_at_peak, sigma_v_residual, sigma_h_residual (Pa)
    """
    ea = np.asarray(result["axial_strain"])
    if ea.size < 3:
        raise InputError(f"result must hold at least 3 records, got {ea.size}")
    step = float(np.median(np.diff(ea))) if ea.size > 1 else 0.0
    window = int(round(smoothing / step)) if step > 0 else 1
    sv = smooth(result["sigma_v"], window)
    sh = smooth(result["sigma_h"], window)
    sin_phi = (sv - sh) / (sv + sh)
    k = int(np.argmax(sin_phi))
    late = ea >= residual_from * ea[-1]
    sv_r, sh_r = float(sv[late].mean()), float(sh[late].mean())
    return {
        "phi_peak": math.degrees(math.asin(float(np.clip(sin_phi[k], -1, 1)))),
        "phi_residual": math.degrees(math.asin(float(np.clip((sv_r - sh_r) / (sv_r + sh_r),
                                                             -1, 1)))),
        "strain_at_peak": float(ea[k]), "sigma_v_peak": float(sv[k]),
        "sigma_h_at_peak": float(sh[k]), "sigma_v_residual": sv_r, "sigma_h_residual": sh_r,
    }
