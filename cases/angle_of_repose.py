"""Heaps of cubes beside heaps of spheres on a rough base: angle of repose and base pressure (Chen, polyhedral DEM).

Chen's thesis (abstract): heaps of convex polyhedra with the
overlap-volume contact stand at "more realistic, high angles of repose" on a flat
base than any model with round particles; heaps built by wedge sequences show a
pressure dip under the apex, heaps built by layered sequences a pressure maximum.
The thesis text at hand gives no numbers: every comparison here is qualitative.

Set-up (our choices: the thesis gives none of them)
---------------------------------------------------
A quasi-two-dimensional heap (the thesis verifies its code on quasi-two-dimensional
heaps): a slab 6.5 d wide, periodic in y (d = 1 cm, the cube's edge), on a rough base
of length 2 L: a layer of fixed spheres glued above a flat floor (a jittered grid,
the spheres' diameter the cubes' volume-equivalent diameter d_eq = 1.241 d, centres
1.25 d_eq apart in x, 4 rows across the slab, heights jittered by 0.15 d_eq; the
same base, sphere for sphere, under every heap). Grains that leave the base fall
off its ends and are taken out of the heap (held where they are, counted).

- Cubes: ``tdem.Polyhedron.cube(d)``, ρ = 2600 kg/m³, ``tdem.VolumeContact`` with
  E = 2e5 Pa, μ = 0.5, e = 0.3 (the law of every contact of a cube: with another cube,
  with a base sphere, with the floor). E is low to cut the number of steps: the
  angle of repose does not depend on E while the overlaps stay small, and the
  summary reports the mean and largest overlap over the particle size (the overlap
  volume over the cube's volume; about 0.1 % and 1 % in the quick preset).
- Irregular polyhedra of a chosen aspect: each heap's grains are copies of one random
  convex polyhedron, the hull of 12 random points on an ellipsoid of aspect 1.5
  (``tdem.Polyhedron.random``, the heap's seed), scaled to the cube's volume, in
  random orientations; the cubes' law. Being longer (bounding radius 1.04–1.22 d against the cube's 0.87 d), they need
  a wider slab for three neighbour cells across the period: 7.5–8.5 d (the base has
  5 rows across it). Wedge heaps only.
- Spheres of the cubes' volume (radius 0.620 d), ρ = 2600 kg/m³, Hertz–Mindlin with
  E = 5e6 Pa, ν = 0.3, μ = 0.5, e = 0.3 (the same friction; a stiffer E, since a Hertz
  contact is softer at small overlaps: mean overlap over the radius about 0.5 %), no
  rolling resistance.
- Wedge sequence (a line source at the apex): batches of one row of particles across
  the slab (3 per row, 2.17 d apart, random orientations), released at x = 0 ±
  0.25 d, 1.3 bounding radii above the highest grain near the axis, at 0.3 m/s
  downward, every 0.04 s (a release point still occupied waits for the next batch);
  the heap then settles until its kinetic energy per grain is below 1e-6 m g d.
- Layered sequence (the same cubes, the same number): horizontal layers, each the
  width of the layer below less 2 h_l / tan(α) (h_l ≈ 0.8 d the layer's thickness, α
  = 0.85 × the wedge heap's measured angle of the same seed, so that the layers do
  not avalanche), particles dropped on a jittered grid 1.3 bounding radii above the
  surface below them, a layer every 0.08 s; then the same settling.

Three seeds (orientations, jitter) per heap; Δt = 0.3 of the engine's critical step
of one contact (the engine's VolumeContact estimate takes the stiffness of a contact
area of π R², about 5 times a cube's face contact; its default is 0.2).

What is measured
----------------
- The angle of repose of each heap, by a fit of its surface profile: the particles
  binned by x (bins 1 d wide), the surface height of a bin the highest particle top in
  it (a cube's highest vertex, a sphere's top); on each flank a straight line fitted
  (least squares) over the bins whose height lies between 20 % and 80 % of the
  heap's height above the base (the apex cap and the toe left out); the angle
  atan(|slope|) of each flank, the heap's angle the mean of its two flanks; over the
  seeds the mean ± standard deviation.
- The base pressure profile: each base sphere's vertical force over its share of the
  base (the base's area over the number of its spheres), averaged in bins of |x| (the
  two sides folded, bins 2 d wide), the floor's force (if any) spread over the base;
  the mean over the seeds and the standard error. (The force over the bin's area
  instead puts 2 or 3 of the base's columns, 0.78 d apart, in a bin: a ±20 % ripple
  of the binning alone.) A dip: the pressure under the apex
  (|x| < 2 d) lower than the largest pressure off the axis (2 d ≤ |x| ≤ 0.6 of the
  heap's half-width); a maximum: not lower.

What is compared (``summary.json``)
-----------------------------------
Pass or fail: the profile fit recovers the angle of a synthetic triangular heap
(to 0.1°); the thesis's claim that the polyhedra stand steeper than spheres (the
cubes' mean angle above the spheres', and the irregular polyhedra's, the seed spread
beside it; compared only where the difference exceeds twice its standard error over
the seeds, as the pressure claims below, else reported as not resolved); every heap at rest
at the end (kinetic energy per grain below 1e-5 m g d); the base carries each heap's
weight (within 1 %); the thesis's pressure dip under a wedge heap and maximum under a
layered heap, compared only where the difference (off-axis maximum − apex pressure)
exceeds twice its standard error over the seeds; where it does not, the summary says
that this heap is too small to resolve it and reports it, no pass or fail. Reported
only: the angles of every flank and seed, the overlaps, the grains that fell off the
base, the packing fraction of the heaps. No numbers in the thesis.

How close it comes
------------------
Paper preset (900 grains a heap, 8–11 d high; 81 minutes on one thread, 2026-12-05,
without the irregular heaps, added since; kept in docs/validation.md): the cubes
stand at 34.4° ± 2.6° (seeds 31.6°, 36.7°, 34.9°), the spheres of the same volume and
friction at 25.0° ± 3.3° (27.9°, 25.6°, 21.4°; sample standard deviations): 9.5° ±
2.4° (s.e.) steeper, resolved — the thesis's result. The layered heaps of cubes stand
at 26.9° ± 1.2°. The base pressure under the apex is 420 ± 215 Pa below the largest
off the axis (wedge: the thesis's dip, not resolved) and 379 ± 66 Pa below it
(layered: a dip, resolved, where the thesis has a maximum; the one check that
fails). Every heap ends at rest with the base carrying its weight to 0.1 %. Its
three heaps of irregular polyhedra take well over 30 minutes each on one thread
(``--no-irregular`` leaves them out).

What makes the layered heaps' dip is not known. Not their spreading as they are
built: how far each grain moves outward after it first comes to rest
(``Heap.spread``, in the pressure notes) was measured in a paper-preset run of
2026-12-08 stopped after four heaps of cubes: the wedge heaps' grains moved out by
2.54 and 2.20 d on average (seeds 1, 2; the spheres' 3.08–3.17 d), the layered
heap's by 0.25 d (seed 1): the layers stay about where they land, yet the earlier
run's layered heaps had the dip. The quick preset's heaps (210
grains, about 4 d high) are too small to tell the angles apart (cubes 21.8° ± 7.2°,
irregular 22.9° ± 6.7°, spheres 21.3° ± 3.6°); there the pressure under the apex is a
resolved maximum for both sequences (the thesis: a dip for the wedge), and one heap
was still creeping at the end of its 1.5 s of settling.

Outputs (``--out DIR``, default out/angle_of_repose, as every case)
-----------------------------------------------------------
``heap_profiles.png`` (the heaps of cubes and of spheres side by side, the particles,
the surface profiles and the fitted flanks with their angles), ``base_pressure.png``
(wedge against layered), ``angles.png`` (every flank of every seed),
``heaps.h5`` (the final positions, the profiles, the pressures),
``vtu/`` (the final heaps: ``MODEL_SEQ_seedS.vtu``, and the cubes' surfaces in
``*_shapes.vtu``), ``summary.json``.
"""
import math
import time
from pathlib import Path

import numpy as np

import tdem
from physics.shapes import quaternion_rotations as rotations

from . import _common as common

CASE = "angle_of_repose"
PAPER = "Chen (thesis), polyhedral DEM: heaps on a flat base"
NO_NUMBERS = "no numbers in the thesis"

GRAVITY = 9.81
D = 0.01                      # the cube's edge (m)
RHO = 2600.0
FRICTION, RESTITUTION = 0.5, 0.3
ASPECT = 1.5                  # irregular grains: longest over shortest axis of their ellipsoid
IRREGULAR_POINTS = 12         # ... and the random points whose hull they are
E_POLY = 2e5
E_SPHERE, POISSON = 5e6, 0.3
WIDTH = 6.5                   # slab width in d (the period must hold 3 neighbour cells)
REST = 1e-5                   # kinetic energy per grain over m g d: "at rest"
SETTLED = 1e-6                # the settling stops below this
LANDED_V = 0.02               # m/s: a released grain has landed once it is slower
FIT_BAND = (0.2, 0.8)         # the flank fit: heights between these shares of the heap's
BIN = 1.0                     # profile bins (d)
P_BIN = 2.0                   # pressure bins (d)
APEX = 2.0                    # |x| below this (d): "under the apex"

PRESETS = {
    "quick": {"particles": 210, "half_base": 16.0, "seeds": (1, 2, 3), "rows": 1, "release_v": 0.1,
              "batch_dt": 0.03, "layer_dt": 0.08, "settle_max": 1.5},
    "paper": {"particles": 900, "half_base": 34.0, "seeds": (1, 2, 3), "rows": 1, "release_v": 0.1,
              "batch_dt": 0.03, "layer_dt": 0.08, "settle_max": 3.0},
}


# ------------------------------------------------------------------ particles
def volume_radius(volume):
    """Radius of the sphere of ``volume``."""
    return (3.0 * volume / (4.0 * math.pi)) ** (1.0 / 3.0)


def irregular_shape(seed):
    """The irregular grain of a heap: the convex hull of IRREGULAR_POINTS random points
    on an ellipsoid of aspect ASPECT (tdem.Polyhedron.random, the heap's seed), scaled
    to the cube's volume."""
    unit = tdem.Polyhedron.random(IRREGULAR_POINTS, elongation=ASPECT, size=D, seed=seed)
    size = D * (D ** 3 / unit.volume) ** (1.0 / 3.0)
    return tdem.Polyhedron.random(IRREGULAR_POINTS, elongation=ASPECT, size=size, seed=seed)


class Model:
    """One kind of grain: its shape (a Polyhedron, or None for spheres), its law and
    the numbers the pour needs (bounding radius, volume, mass). ``seed`` picks the
    irregular grain of a heap (one random polyhedron per heap)."""

    def __init__(self, name, seed=1):
        self.name = name
        cube = tdem.Polyhedron.cube(D)
        self.volume = cube.volume
        if name in ("cubes", "irregular"):
            self.shape = cube if name == "cubes" else irregular_shape(seed)
            self.law = tdem.VolumeContact(young=E_POLY, friction=FRICTION,
                                          restitution=RESTITUTION)
            self.bound = self.shape.bounding_radius
            self.radius = None
            # the law's critical stiffness takes a contact area of π R², about 5 times a
            # cube's face contact (more for the longer irregular grains): 0.45 of its
            # critical step is below the stable step of a dense packing of face contacts
            self.dt_fraction = 0.45
            # the period must hold three neighbour cells (2 bounding radii and the skin,
            # about 0.25 d, each): the irregular grains, longer, need a wider slab
            self.width = max(WIDTH, 0.5 * math.ceil(2.0 * 3.0 * (2.0 * self.bound / D + 0.3)))
        elif name == "spheres":
            self.shape = None
            self.law = tdem.HertzMindlin(young=E_SPHERE, poisson=POISSON, friction=FRICTION,
                                         restitution=RESTITUTION)
            self.radius = volume_radius(self.volume)
            self.bound = self.radius
            self.dt_fraction = 0.2          # the engine's default
            self.width = WIDTH
        else:
            raise ValueError(f"model {name!r}")
        self.mass = RHO * self.volume

    def add(self, sim, pos, seed, velocity=None):
        pos = np.atleast_2d(pos)
        if self.shape is None:
            return sim.add_particles(pos, radius=self.radius, density=RHO, contact=self.law,
                                     velocity=velocity)
        return sim.add_particles(pos, shape=self.shape, density=RHO, contact=self.law,
                                 orientation=tdem.random_orientations(len(pos), seed=seed),
                                 velocity=velocity)

    def tops(self, p):
        """Height of each particle's highest point: a cube's highest vertex."""
        z = p["position"][:, 2]
        if self.shape is None:
            return z + self.radius
        r = rotations(p["orientation"])
        vz = np.einsum("nk,vk->nv", r[:, 2, :], self.shape.vertices)
        return z + vz.max(axis=1)


# ------------------------------------------------------------------ the base
def base_spheres(half_base, seed=0, width=WIDTH):
    """Centres and radius of the base: fixed spheres of the cubes' volume-equivalent
    diameter on a jittered grid over [−L, L] × [0, W), 4 rows across the slab of
    WIDTH (as many more as a wider slab needs for the same spacing)."""
    r = volume_radius(D ** 3)
    w = width * D
    rows = max(4, int(round(4 * width / WIDTH)))
    sx = 2.5 * r
    nx = int(2 * half_base * D / sx)
    xs = (np.arange(nx) - 0.5 * (nx - 1)) * sx
    rng = np.random.default_rng(1000 + seed)
    pts = []
    for k in range(rows):
        y = (k + 0.5) * w / rows
        for x in xs + (0.5 * sx if k % 2 else 0.0):
            if abs(x) > half_base * D - r:
                continue
            pts.append((x + rng.uniform(-0.1, 0.1) * r, y, r + rng.uniform(0.0, 0.3) * r))
    return np.array(pts), r


def floor_mesh(half_base, width=WIDTH):
    """The flat floor under the base: x in [−L, L], across three periods in y."""
    L, w = half_base * D, width * D
    v = np.array([[-L, -w, 0.0], [L, -w, 0.0], [L, 2 * w, 0.0], [-L, 2 * w, 0.0]])
    return v, np.array([[0, 1, 2], [0, 2, 3]])


class Heap:
    """A simulation of one heap: the slab, the base, the pour and its bookkeeping."""

    def __init__(self, model, cfg, opts, seed, log=None):
        self.model, self.cfg, self.seed = model, cfg, seed
        self.log = log or (lambda s: None)
        self.rng = np.random.default_rng(seed)
        self.sim = tdem.Simulation(dim=3, gravity=(0.0, 0.0, -GRAVITY),
                                   dt_fraction=model.dt_fraction, progress=False, **opts)
        self.width = model.width * D
        self.sim.periodic(y=(0.0, self.width))
        self.half = cfg["half_base"] * D
        # the floor and the base spheres carry the polyhedra's law in a cube model
        v, t = floor_mesh(cfg["half_base"], model.width)
        floor_law = model.law
        self.floor = self.sim.add_mesh(v, t, contact=floor_law)
        pts, rb = base_spheres(cfg["half_base"], width=model.width)
        hm = (model.law if model.shape is None else
              tdem.HertzMindlin(young=E_SPHERE, poisson=POISSON, friction=FRICTION,
                                restitution=RESTITUTION))
        g = self.sim.add_particles(pts, radius=rb, density=RHO, contact=hm)
        self.sim.fix_particles(g.ids, vx=0.0, vy=0.0, vz=0.0, omega=(0.0, 0.0, 0.0))
        self.base_ids = np.asarray(g.ids)
        self.base_pos = pts
        self.base_top = float((pts[:, 2] + rb).max())
        self.base_r = rb
        self.grains = []             # ids of the poured grains
        self.gone = set()            # grains fallen off the base (held)
        self.batch = 0
        self.landed = {}             # grain id: its x when it first came to rest (m)

    # -------------------------------------------------------------- bookkeeping
    def state(self):
        p = self.sim.particles.numpy()
        ids = np.array(self.grains, dtype=int)
        return p, ids

    def free_ids(self):
        return np.array([i for i in self.grains if i not in self.gone], dtype=int)

    def hold_fallen(self):
        """Grains below the floor's level have left the base: hold them there."""
        if not self.grains:
            return
        p, ids = self.state()
        low = [int(i) for i in ids if p["position"][i, 2] < -2.0 * D and i not in self.gone]
        if low:
            self.sim.fix_particles(low, vx=0.0, vy=0.0, vz=0.0, omega=(0.0, 0.0, 0.0))
            self.gone.update(low)

    def note_landed(self):
        """Keep the x of every grain that has come to rest (speed below LANDED_V) for
        the first time since it was released: how far the heap's grains move out after
        they land is how much the heap spreads as it is built."""
        new = [i for i in self.grains if i not in self.landed and i not in self.gone]
        if not new:
            return
        p = self.sim.particles.numpy()
        ids = np.array(new, dtype=int)
        slow = np.linalg.norm(p["velocity"][ids], axis=1) < LANDED_V
        for i, x in zip(ids[slow], p["position"][ids[slow], 0]):
            self.landed[int(i)] = float(x)

    def spread(self):
        """How far the grains on the base moved outward (away from the axis) since they
        landed, in d: the mean and the share that moved out by more than d/2."""
        ids = [i for i in self.free_ids() if int(i) in self.landed]
        if not ids:
            return {"mean_d": None, "share_half_d": None, "grains": 0}
        x = self.sim.particles.numpy()["position"][np.array(ids), 0]
        x0 = np.array([self.landed[int(i)] for i in ids])
        out = np.sign(x0) * (x - x0) / D
        return {"mean_d": float(out.mean()), "share_half_d": float(np.mean(out > 0.5)),
                "grains": len(ids)}

    def surface_height(self, x, halfwidth):
        """The highest particle top within ``halfwidth`` of each x (the base's top
        where there is none)."""
        p, ids = self.state()
        out = np.full(len(np.atleast_1d(x)), self.base_top)
        if len(ids):
            keep = np.array([i not in self.gone for i in ids])
            ids = ids[keep]
            tops = self.model.tops({k: v[ids] for k, v in p.items()})
            px = p["position"][ids, 0]
            for k, xx in enumerate(np.atleast_1d(x)):
                m = np.abs(px - xx) < halfwidth
                if m.any():
                    out[k] = max(out[k], float(tops[m].max()))
        return out

    def clear(self, pts):
        """Which release points are clear of every particle (two bounding radii)."""
        p = self.sim.particles.numpy()["position"]
        if not len(p):
            return np.ones(len(pts), bool)
        d = p[None, :, :] - pts[:, None, :]
        d[:, :, 1] -= self.width * np.round(d[:, :, 1] / self.width)
        reach = 2.0 * max(self.model.bound, self.base_r) + 0.05 * D
        return (np.einsum("ijk,ijk->ij", d, d) > reach ** 2).all(axis=1)

    def add(self, pts, velocity=None):
        pts = np.asarray(pts, dtype=float)
        ok = self.clear(pts)
        pts = pts[ok]
        if not len(pts):
            return 0
        self.batch += 1
        g = self.model.add(self.sim, pts, seed=self.seed * 100003 + self.batch,
                           velocity=velocity)
        self.grains += [int(i) for i in g.ids]
        return len(pts)

    # -------------------------------------------------------------- pours
    def pour_wedge(self, n):
        """A line source at x = 0: a row of grains across the slab every batch_dt."""
        per_row = max(1, int(self.width / (2.0 * self.model.bound + 0.1 * D)))
        dy = self.width / per_row
        while len(self.grains) < n:
            top = float(self.surface_height([0.0], 1.5 * D)[0])
            z = top + 1.3 * self.model.bound
            rows = self.cfg["rows"]
            k = min(per_row * rows, n - len(self.grains))
            y0 = self.rng.uniform(0.0, dy)
            pts = np.array([[self.rng.uniform(-0.25, 0.25) * D,
                             (y0 + (j % per_row + 0.5 * (j // per_row)) * dy) % self.width,
                             z + (j // per_row) * (2.0 * self.model.bound + 0.1 * D)
                             + self.rng.uniform(0.0, 0.2) * D] for j in range(k)])
            self.add(pts, velocity=(0.0, 0.0, -self.cfg["release_v"]))
            self.sim.run(until=self.sim.time + self.cfg["batch_dt"])
            self.hold_fallen()
            self.note_landed()

    def pour_layers(self, n, angle):
        """Horizontal layers over the whole base, each narrower than the one below by
        2 h / tan(angle) (h the thickness of a layer)."""
        b = self.model.bound
        sx = 2.0 * b + 0.1 * D
        per_row = max(1, int(self.width / sx))
        dy = self.width / per_row
        # the heap these layers build: a triangle of the wedge heap's cross-section
        area = n * self.model.volume / (0.58 * self.width)     # 0.58: a guess of the packing
        t = math.tan(math.radians(angle))
        half = math.sqrt(area / t)                               # half-width at the base
        thick = 0.8 * D
        k = 0
        while len(self.grains) < n:
            w = half - k * thick / t
            if w < 0.5 * sx:
                w = 0.5 * sx
            nx = max(1, int(2 * w / sx))
            xs = (np.arange(nx) - 0.5 * (nx - 1)) * sx
            heights = self.surface_height(xs, 0.5 * sx)
            pts = []
            for x, h in zip(xs, heights):
                for j in range(per_row):
                    pts.append([x + self.rng.uniform(-0.1, 0.1) * D,
                                (j + 0.5 + (0.5 if k % 2 else 0.0)) * dy % self.width,
                                h + 1.3 * b + self.rng.uniform(0.0, 0.1) * D])
            pts = np.array(pts)
            room = n - len(self.grains)
            if len(pts) > room:
                pts = pts[self.rng.choice(len(pts), room, replace=False)]
            self.add(pts)
            self.sim.run(until=self.sim.time + self.cfg["layer_dt"])
            self.hold_fallen()
            self.note_landed()
            k += 1

    def settle(self, max_time, chunk=0.1):
        """Run until the kinetic energy per grain is below SETTLED m g d (or max_time)."""
        t0 = self.sim.time
        ratio = math.inf
        while self.sim.time - t0 < max_time:
            self.sim.run(until=self.sim.time + chunk)
            self.hold_fallen()
            self.note_landed()
            ratio = self.kinetic_ratio()
            if ratio < SETTLED:
                break
        return self.sim.time - t0, ratio

    def kinetic_ratio(self):
        """Kinetic energy (translation and rotation) of the grains on the base, per grain,
        over m g d."""
        ids = self.free_ids()
        if not len(ids):
            return 0.0
        p = self.sim.particles.numpy()
        v = p["velocity"][ids]
        w = p["omega"][ids]
        m = p["mass"][ids]
        # rotation: a sphere's moment of inertia, a cube's about any axis (D²/6 per
        # unit mass), an irregular grain's mean principal moment
        inertia = m * (float(np.mean(self.model.shape.principal_moments))
                       if self.model.shape is not None else 0.4 * self.model.radius ** 2)
        ke = 0.5 * (m * (v * v).sum(1) + inertia * (w * w).sum(1)).sum()
        return float(ke / len(ids) / (self.model.mass * GRAVITY * D))

    # -------------------------------------------------------------- measures
    def measures(self):
        """The heap now: positions, tops, base forces, overlaps."""
        p = self.sim.particles.numpy()
        ids = self.free_ids()
        tops = self.model.tops({k: v[ids] for k, v in p.items()})
        weight = float(p["mass"][ids].sum() * GRAVITY)
        base_fz = -p["force"][self.base_ids, 2]
        floor_fz = -float(self.floor.force[2])
        c = self.sim.contacts.numpy()
        pairs = c["pairs"]
        grain = np.zeros(len(p["mass"]), bool)
        grain[ids] = True
        touch = grain[pairs[:, 0]] | ((pairs[:, 1] >= 0) & grain[np.maximum(pairs[:, 1], 0)])
        ov = c["overlap"][touch]
        if self.model.shape is not None:
            size = self.model.shape.length     # u = V/l_c² over l = V^(1/3): V over the cube's volume
        else:
            size = self.model.radius           # the overlap depth over the radius
        return {
            "x": p["position"][ids, 0], "y": p["position"][ids, 1],
            "z": p["position"][ids, 2], "tops": tops, "weight": weight,
            "base_x": self.base_pos[:, 0], "base_fz": base_fz, "floor_fz": floor_fz,
            "overlap_mean": float(ov.mean() / size) if len(ov) else 0.0,
            "overlap_max": float(ov.max() / size) if len(ov) else 0.0,
            "contacts": int(touch.sum()),
            "grains": len(ids), "fallen": len(self.gone),
            "kinetic_ratio": self.kinetic_ratio(),
        }


# ------------------------------------------------------------------ analysis
def profile(x, tops, bin_width, base=0.0):
    """(bin centres, surface height): the highest top in each bin of ``bin_width``
    (bins without a particle are left out), heights above ``base``."""
    x = np.asarray(x, dtype=float)
    tops = np.asarray(tops, dtype=float)
    k = np.floor(x / bin_width).astype(int)
    keys = np.unique(k)
    centres = (keys + 0.5) * bin_width
    heights = np.array([tops[k == j].max() for j in keys]) - base
    return centres, heights


def fit_flanks(centres, heights, band=FIT_BAND):
    """Fit a straight line to each flank of a heap's profile over the bins whose
    height lies between band[0] and band[1] of the heap's height (the highest bin):
    {"left"/"right": {"angle" (deg), "slope", "intercept", "bins": [first, last]
    centres}} and the apex's x. A flank with fewer than 3 bins in the band gets no
    fit (angle None)."""
    centres = np.asarray(centres, dtype=float)
    heights = np.asarray(heights, dtype=float)
    top = int(np.argmax(heights))
    h = heights[top]
    apex_x = float(centres[top])
    out = {"apex_x": apex_x, "height": float(h)}
    for side, sel in (("left", centres < apex_x), ("right", centres > apex_x)):
        m = sel & (heights >= band[0] * h) & (heights <= band[1] * h)
        if m.sum() < 3:
            out[side] = {"angle": None, "slope": None, "intercept": None, "bins": None}
            continue
        slope, icpt = np.polyfit(centres[m], heights[m], 1)
        out[side] = {"angle": math.degrees(math.atan(abs(slope))), "slope": float(slope),
                     "intercept": float(icpt),
                     "bins": [float(centres[m].min()), float(centres[m].max())]}
    return out


def synthetic_cone(angle, half_width, bin_width=BIN, points=4000, seed=0):
    """Particle tops filling a triangular heap of ``angle`` (deg) and base half-width
    ``half_width``: the highest top in any bin lies on the flank (a synthetic test of
    the fit)."""
    rng = np.random.default_rng(seed)
    t = math.tan(math.radians(angle))
    x = rng.uniform(-half_width, half_width, points)
    k = np.floor(x / bin_width)
    # below the surface at the bin's side away from the apex
    below = np.clip(t * (half_width - np.abs((k + 0.5) * bin_width) - 0.5 * bin_width),
                    0.0, None)
    z = rng.uniform(0.0, 1.0, points) * below
    # each bin's highest top on the surface, at the bin's centre (as a grain would be)
    xc = (np.unique(k) + 0.5) * bin_width
    xs = np.concatenate([x, xc])
    zs = np.concatenate([z, t * (half_width - np.abs(xc))])
    return xs, zs


def pressure_profile(base_x, base_fz, floor_fz, half_base, width, cell_area,
                     bin_width=P_BIN * D):
    """(bin centres |x|, pressure): each base sphere's vertical force over its share of
    the base (``cell_area``), averaged in bins of |x| (both sides folded); the floor's
    force, if any, spread over the whole base. (The force over a bin's area would put
    2 or 3 of the base's columns, 0.78 d apart, in bins 2 d wide: a ±20 % ripple of the
    binning alone.)"""
    ax = np.abs(np.asarray(base_x, dtype=float))
    nb = int(math.ceil(half_base / bin_width))
    edges = np.arange(nb + 1) * bin_width
    f = np.histogram(ax, bins=edges, weights=base_fz)[0]
    count = np.maximum(np.histogram(ax, bins=edges)[0], 1)
    p = f / (count * cell_area) + floor_fz / (2.0 * half_base * width)
    return 0.5 * (edges[1:] + edges[:-1]), p


def pressure_shape(centres, p_mean, p_se, heap_half, apex=APEX * D):
    """The shape of a base pressure profile: the pressure under the apex (the bins
    with centre below ``apex``), the largest off the axis (centres up to 0.6 of the
    heap's half-width), their difference and its standard error, and which it is
    ("dip": the apex lower, "maximum": not lower) and whether the difference exceeds
    twice its standard error (resolved)."""
    centres = np.asarray(centres)
    under = centres < apex
    off = (centres >= apex) & (centres <= 0.6 * heap_half)
    if not under.any() or not off.any():
        return {"shape": None, "resolved": False}
    p_apex = float(np.mean(p_mean[under]))
    se_apex = float(np.sqrt(np.sum(np.asarray(p_se)[under] ** 2)) / under.sum())
    k = np.nonzero(off)[0][int(np.argmax(p_mean[off]))]
    p_off = float(p_mean[k])
    diff = p_off - p_apex
    se = math.hypot(se_apex, float(p_se[k]))
    return {"apex_pressure_Pa": p_apex, "off_axis_max_Pa": p_off,
            "off_axis_max_at_m": float(centres[k]), "difference_Pa": diff,
            "difference_se_Pa": se, "relative_dip": diff / p_off if p_off else None,
            "shape": "dip" if diff > 0 else "maximum",
            "resolved": bool(abs(diff) > 2.0 * se)}


def mean_std(values):
    v = np.asarray([x for x in values if x is not None], dtype=float)
    if not len(v):
        return None, None
    return float(v.mean()), float(v.std(ddof=1)) if len(v) > 1 else 0.0


def angle_difference(a, b):
    """Mean angle of heaps ``a`` minus that of heaps ``b`` (lists of angles, one per
    seed), its standard error over the seeds, and whether it is resolved: larger than
    twice that error (the rule the pressure comparisons follow)."""
    a = np.asarray([x for x in a if x is not None], dtype=float)
    b = np.asarray([x for x in b if x is not None], dtype=float)
    diff = float(a.mean() - b.mean())
    se = math.sqrt(sum(v.var(ddof=1) / len(v) for v in (a, b) if len(v) > 1))
    return diff, se, abs(diff) > 2.0 * se


def base_cell(half_base, width, count):
    """Each base sphere's share of the base (m²)."""
    return 2.0 * half_base * width / count


# ------------------------------------------------------------------ runs
def run_heap(model, sequence, cfg, opts, seed, angle=None, log=common.say):
    w0 = time.perf_counter()
    heap = Heap(model, cfg, opts, seed)
    if sequence == "wedge":
        heap.pour_wedge(cfg["particles"])
    else:
        heap.pour_layers(cfg["particles"], angle)
    t_settle, ratio = heap.settle(cfg["settle_max"])
    m = heap.measures()
    spread = heap.spread()
    centres, heights = profile(m["x"], m["tops"], BIN * D, base=heap.base_top)
    fit = fit_flanks(centres, heights)
    px, pp = pressure_profile(m["base_x"], m["base_fz"], m["floor_fz"], heap.half,
                              heap.width, base_cell(heap.half, heap.width, len(m["base_x"])))
    angles = [fit[s]["angle"] for s in ("left", "right")]
    mean = mean_std(angles)[0]
    # packing: the grains' volume over the area under the profile × slab width
    area = float(np.sum(np.clip(heights, 0.0, None)) * BIN * D)
    packing = m["grains"] * model.volume / (area * heap.width) if area > 0 else None
    res = {"model": model.name, "sequence": sequence, "seed": seed, "fit": fit,
           "angle": mean, "profile_x": centres, "profile_h": heights,
           "pressure_x": px, "pressure": pp, "packing": packing,
           "time_s": heap.sim.time, "settle_s": t_settle, "steps": heap.sim.steps,
           "dt_s": heap.sim.dt, "wall_s": time.perf_counter() - w0,
           "layer_angle": angle, "base_top": heap.base_top, "spread": spread, **m,
           "balance": (float(m["base_fz"].sum()) + m["floor_fz"]) / m["weight"]}
    log(f"{model.name:7s} {sequence:7s} seed {seed}: {m['grains']} grains "
        f"({m['fallen']} fell off), angle {fmt_angle(angles)}, height "
        f"{fit['height'] / D:.1f} d, base/weight {res['balance']:.4f}, "
        f"kinetic {m['kinetic_ratio']:.1e} mgd, moved out after landing "
        f"{spread['mean_d'] if spread['mean_d'] is not None else float('nan'):.2f} d, "
        f"{heap.sim.steps} steps, "
        f"{res['wall_s']:.0f} s")
    return res, heap


def spread_words(heaps, sequence):
    """Words for a pressure note: how far the heaps' grains moved outward after they
    landed (:meth:`Heap.spread`), over the seeds; for layered heaps also the angle the
    layers were set back at against the angle the heap ended at. A heap whose grains
    spread outward as it is built arches over its centre (the dip of a wedge pour); a
    heap built in layers that stay where they land carries each column's own weight."""
    sp = [r["spread"] for r in heaps if r.get("spread", {}).get("mean_d") is not None]
    if not sp:
        return ""
    words = (f"; after landing its grains moved outward by "
             f"{np.mean([q['mean_d'] for q in sp]):.2f} d on average, "
             f"{100 * np.mean([q['share_half_d'] for q in sp]):.0f} % of them by more than "
             "d/2 (mean over the seeds)")
    if sequence == "layered":
        set_back = [r["layer_angle"] for r in heaps if r.get("layer_angle") is not None]
        if set_back:
            words += (f"; the layers were set back at {np.mean(set_back):.1f}°, the heap "
                      f"ended at {np.mean([r['angle'] for r in heaps]):.1f}°")
    return words


def fmt_angle(angles):
    return " / ".join("–" if a is None else f"{a:.1f}°" for a in angles)


# ------------------------------------------------------------------ plots
def plot_profiles(runs, png):
    plt = common.pyplot()
    models = [m for m in ("cubes", "irregular", "spheres") if (m, "wedge") in runs]
    fig, axes = plt.subplots(len(models), 1, figsize=(9, 2.2 * len(models) + 0.8),
                             sharex=True, squeeze=False)
    colors = ("tab:blue", "tab:orange", "tab:green")
    for ax, name in zip(axes[:, 0], models):
        rs = runs[(name, "wedge")]
        r0 = rs[0]
        ax.scatter(r0["x"] / D, (r0["z"] - r0["base_top"]) / D, s=6, color="0.7",
                   label=f"grain centres, seed {r0['seed']}")
        for r, c in zip(rs, colors):
            ax.step(r["profile_x"] / D, r["profile_h"] / D, where="mid", color=c, lw=1.0,
                    label=f"surface, seed {r['seed']}")
            for side in ("left", "right"):
                f = r["fit"][side]
                if f["angle"] is None:
                    continue
                xs = np.array(f["bins"])
                ax.plot(xs / D, (f["slope"] * xs + f["intercept"]) / D, color=c, lw=2.2,
                        alpha=0.9)
        angles = [a for r in rs for a in (r["fit"]["left"]["angle"],
                                          r["fit"]["right"]["angle"]) if a is not None]
        m, s = mean_std([r["angle"] for r in rs])
        ax.set_title(f"{name}: angle of repose {m:.1f}° ± {s:.1f}° over {len(rs)} seeds "
                     f"(flanks {min(angles):.1f}–{max(angles):.1f}°); thick lines: the "
                     f"fits", fontsize=10)
        ax.set_ylabel("height above the base (d)")
        ax.set_aspect("equal")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="upper right", ncol=2)
    axes[-1, 0].set_xlabel("x (d, the cube's edge)")
    fig.suptitle("Heaps poured from a line source on a rough base: surface profiles and "
                 "fitted flanks", fontsize=11)
    fig.tight_layout()
    common.save(fig, png)


def plot_pressure(press, png):
    plt = common.pyplot()
    fig, ax = plt.subplots(figsize=(7.5, 4.4))
    for seq, c in (("wedge", "tab:red"), ("layered", "tab:blue")):
        if seq not in press:
            continue
        q = press[seq]
        x = np.asarray(q["x"]) / D
        ax.errorbar(x, np.asarray(q["mean"]), yerr=np.asarray(q["se"]), color=c, marker="o",
                    ms=4, capsize=3, lw=1.4,
                    label=f"{seq} sequence (mean of {q['seeds']} seeds ± s.e.)")
        for p in q["each"]:
            ax.plot(x, p, color=c, lw=0.6, alpha=0.35)
    ax.axvspan(0, APEX, color="0.85", alpha=0.5, lw=0, label="under the apex")
    ax.set_xlabel("|x|, distance from the heap's axis (d)")
    ax.set_ylabel("vertical stress on the base (Pa)")
    ax.set_xlim(0, None)
    ax.set_ylim(0, None)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title("Base pressure under heaps of cubes: wedge against layered sequence\n"
                 "(thin lines: each seed)", fontsize=10)
    common.save(fig, png)


def plot_angles(runs, png):
    plt = common.pyplot()
    fig, ax = plt.subplots(figsize=(6.5, 3.8))
    keys = [k for k in (("cubes", "wedge"), ("cubes", "layered"), ("irregular", "wedge"),
                        ("spheres", "wedge")) if k in runs]
    for i, k in enumerate(keys):
        for j, r in enumerate(runs[k]):
            for side, mk in (("left", "<"), ("right", ">")):
                a = r["fit"][side]["angle"]
                if a is not None:
                    ax.plot(i + 0.12 * (j - 1), a, mk, color="k", ms=6)
        m, s = mean_std([r["angle"] for r in runs[k]])
        ax.errorbar(i + 0.35, m, yerr=s, fmt="s", color="tab:red", capsize=4)
        ax.text(i + 0.42, m, f"{m:.1f}° ± {s:.1f}°", va="center", fontsize=8)
    ax.set_xticks(range(len(keys)), [f"{a}, {b}" for a, b in keys])
    ax.set_xlim(-0.5, len(keys) - 0.2)
    ax.set_ylabel("angle of repose (°)")
    ax.grid(alpha=0.3, axis="y")
    ax.set_title("Every flank (◁ left, ▷ right) of every seed; red: mean ± std of the "
                 "heaps", fontsize=9)
    common.save(fig, png)


# ------------------------------------------------------------------ main
HEAPS = (("cubes", "wedge"), ("spheres", "wedge"), ("cubes", "layered"),
         ("irregular", "wedge"))


def steeper_check(key, what, a, b, a_ms, b_ms):
    """The thesis's claim that polyhedra stand steeper than spheres, for the heaps of
    ``a`` against those of ``b`` (angles per seed; a_ms, b_ms their mean and std):
    compared where the seeds resolve the difference, else reported."""
    diff, se, resolved = angle_difference(a, b)
    note = (f"the thesis: polyhedra stand steeper than spheres ({NO_NUMBERS}); {what} "
            f"{a_ms[0]:.1f}° ± {a_ms[1]:.1f}°, spheres {b_ms[0]:.1f}° ± {b_ms[1]:.1f}° "
            f"(mean ± std over {len(a)} seeds); the difference {diff:.1f}° ± {se:.1f}° "
            f"(s.e. over the seeds)")
    if resolved:
        return common.check(key, diff, None, common.between(min=0.0), "deg",
                            note + "; resolved (the difference exceeds twice its "
                            "standard error)")
    return common.check(key, diff, None, None, "deg",
                        note + "; NOT resolved: the difference is within twice its "
                        "standard error, so these heaps are too small to tell (reported, "
                        "not compared)")


def pressures(rs):
    """Mean, standard error and each seed's profile of a set of heaps."""
    each = np.array([r["pressure"] for r in rs])
    se = (each.std(axis=0, ddof=1) / math.sqrt(len(rs)) if len(rs) > 1
          else np.zeros(each.shape[1]))
    return {"x": rs[0]["pressure_x"], "mean": each.mean(axis=0), "se": se,
            "each": each, "seeds": len(rs)}


def _extra(p):
    p.add_argument("--no-irregular", action="store_true",
                   help="leave out the heaps of irregular polyhedra (well over 30 minutes "
                        "each on one thread at the paper preset)")


def main(argv=None):
    args, out = common.parse(CASE, argv, description=__doc__.splitlines()[0], extra=_extra)
    clock = common.Stopwatch()
    cfg = PRESETS[args.preset]
    opts = common.sim_options(args)
    heaps = [h for h in HEAPS if not (args.no_irregular and h[0] == "irregular")]
    vtu = out / "vtu"
    vtu.mkdir(exist_ok=True)
    runs = {}
    for name, seq in heaps:
        runs[(name, seq)] = []
        for seed in cfg["seeds"]:
            model = Model(name, seed)
            angle = None
            if seq == "layered":
                wedge = [r for r in runs[(name, "wedge")] if r["seed"] == seed][0]
                angle = 0.85 * wedge["angle"]
            r, heap = run_heap(model, seq, cfg, opts, seed, angle)
            heap.sim.write_vtu(str(vtu / f"{name}_{seq}_seed{seed}.vtu"))
            runs[(name, seq)].append(r)
    return finish(args, out, cfg, runs, clock)


def finish(args, out, cfg, runs, clock):
    cubes, spheres = runs[("cubes", "wedge")], runs[("spheres", "wedge")]
    layered = runs[("cubes", "layered")]
    allr = [r for rs in runs.values() for r in rs]
    a_c = mean_std([r["angle"] for r in cubes])
    a_s = mean_std([r["angle"] for r in spheres])
    a_l = mean_std([r["angle"] for r in layered])
    # the fit on a synthetic heap of 33.0° (a known answer)
    sx, sz = synthetic_cone(33.0, 14.0 * D, BIN * D)
    sc, sh = profile(sx, sz, BIN * D)
    sfit = fit_flanks(sc, sh)
    synth_err = max(abs(sfit[s]["angle"] - 33.0) for s in ("left", "right"))
    press = {"wedge": pressures(cubes), "layered": pressures(layered)}
    heap_half = float(np.mean([0.5 * (r["profile_x"].max() - r["profile_x"].min())
                               for r in cubes]))
    shapes = {seq: pressure_shape(q["x"], q["mean"], q["se"], heap_half)
              for seq, q in press.items()}
    want = {"wedge": "dip", "layered": "maximum"}
    heaps_of = {"wedge": cubes, "layered": layered}
    pressure_checks = []
    for seq, s in shapes.items():
        note = (f"{NO_NUMBERS}; the thesis: a {want[seq]} under the apex. Apex "
                f"{s.get('apex_pressure_Pa', 0):.0f} Pa, off-axis maximum "
                f"{s.get('off_axis_max_Pa', 0):.0f} Pa at |x| = "
                f"{s.get('off_axis_max_at_m', 0) / D:.0f} d, difference "
                f"{s.get('difference_Pa', 0):.0f} ± {s.get('difference_se_Pa', 0):.0f} Pa "
                f"(s.e. over the seeds)") + spread_words(heaps_of[seq], seq)
        if s["resolved"]:
            pressure_checks.append(common.check(
                f"{seq}.pressure_under_apex", s["shape"], want[seq], common.EQUAL, "",
                note + "; resolved (the difference exceeds twice its standard error)"))
        else:
            pressure_checks.append(common.check(
                f"{seq}.pressure_under_apex", f"{s['shape']} (not resolved)", want[seq], None,
                "", note + "; NOT resolved: the difference is within twice its standard "
                "error, so this heap is too small to tell (reported, not compared)"))
    fell = [r["fallen"] for r in allr]
    angle_checks = [steeper_check("cubes_minus_spheres.angle", "cubes",
                                  [r["angle"] for r in cubes], [r["angle"] for r in spheres],
                                  a_c, a_s)]
    irregular = runs.get(("irregular", "wedge"), [])
    if irregular:
        a_i = mean_std([r["angle"] for r in irregular])
        angle_checks.append(steeper_check(
            "irregular_minus_spheres.angle",
            f"irregular polyhedra (aspect {ASPECT}, {IRREGULAR_POINTS} hull points)",
            [r["angle"] for r in irregular], [r["angle"] for r in spheres], a_i, a_s))
    checks = [
        common.check("fit.synthetic_heap_error", synth_err, 0.0, common.absolute(0.1), "deg",
                     "the profile fit on a synthetic triangular heap of 33°: the largest "
                     "error of its two flanks"),
        *angle_checks,
        common.check("heaps.at_rest", [r["kinetic_ratio"] for r in allr], None,
                     common.between(max=REST), "",
                     "kinetic energy per grain over m g d at the end, every heap"),
        common.check("heaps.base_carries_weight", [r["balance"] for r in allr], 1.0,
                     common.rel(0.01), "",
                     "vertical force on the base (spheres and floor) over the weight of the "
                     "grains on it, every heap"),
        *pressure_checks,
        common.check("cubes.angle", a_c[0], None, None, "deg",
                     f"wedge heaps of cubes, mean over the seeds (std {a_c[1]:.2f}°); "
                     f"{NO_NUMBERS}"),
        common.check("spheres.angle", a_s[0], None, None, "deg",
                     f"wedge heaps of spheres, mean over the seeds (std {a_s[1]:.2f}°)"),
        common.check("cubes_layered.angle", a_l[0], None, None, "deg",
                     f"layered heaps of cubes (their layers set back at 0.85 × the wedge "
                     f"angle; std {a_l[1]:.2f}°)"),
        *([common.check("irregular.angle", a_i[0], None, None, "deg",
                        f"wedge heaps of irregular polyhedra, one random grain per seed "
                        f"(std {a_i[1]:.2f}°)")] if irregular else []),
        common.check("cubes.overlap_mean", float(np.mean([r["overlap_mean"] for r in cubes])),
                     None, None, "", "mean overlap volume over the cube's volume"),
        common.check("spheres.overlap_mean",
                     float(np.mean([r["overlap_mean"] for r in spheres])), None, None, "",
                     "mean overlap depth over the sphere's radius"),
        common.check("grains_fallen_off", fell, None, None, "",
                     "grains that left the base, each heap (not in the heap)"),
    ]
    data = {
        "preset": dict(cfg),
        "set_up": {"d_m": D, "slab_width_m": WIDTH * D, "density": RHO,
                   "friction": FRICTION, "restitution": RESTITUTION,
                   "young_cubes_Pa": E_POLY, "young_spheres_Pa": E_SPHERE,
                   "sphere_radius_m": volume_radius(D ** 3),
                   "fit_band": list(FIT_BAND), "profile_bin_m": BIN * D,
                   "pressure_bin_m": P_BIN * D, "apex_m": APEX * D},
        "angles": {f"{m}_{s}": {"mean_deg": mean_std([r["angle"] for r in rs])[0],
                                "std_deg": mean_std([r["angle"] for r in rs])[1],
                                "flanks_deg": [[r["fit"]["left"]["angle"],
                                                r["fit"]["right"]["angle"]] for r in rs]}
                   for (m, s), rs in runs.items()},
        "synthetic_fit": {"angle_deg": 33.0, "left_deg": sfit["left"]["angle"],
                          "right_deg": sfit["right"]["angle"]},
        "pressure": {seq: {**shapes[seq], "x_m": press[seq]["x"],
                           "mean_Pa": press[seq]["mean"], "se_Pa": press[seq]["se"]}
                     for seq in press},
        "heaps": [{k: r[k] for k in ("model", "sequence", "seed", "angle", "grains",
                                     "fallen", "packing", "balance", "kinetic_ratio",
                                     "overlap_mean", "overlap_max", "contacts", "time_s",
                                     "settle_s", "steps", "dt_s", "wall_s", "layer_angle")}
                  | {"height_m": r["fit"]["height"], "apex_x_m": r["fit"]["apex_x"],
                     "moved_out_after_landing": r.get("spread")}
                  for r in allr],
    }
    plot_profiles(runs, out / "heap_profiles.png")
    plot_pressure(press, out / "base_pressure.png")
    plot_angles(runs, out / "angles.png")
    save_heaps(out / "heaps.h5", runs)
    summary = common.summary(CASE, args.preset, checks, data, clock(), threads=args.threads,
                             paper=PAPER)
    common.write_summary(out, summary)
    common.print_checks(summary)
    return summary


def save_heaps(path, runs):
    series = {}
    for (m, s), rs in runs.items():
        for r in rs:
            series[f"{m}_{s}_seed{r['seed']}"] = {
                "x": r["x"], "y": r["y"], "z": r["z"], "tops": r["tops"],
                "profile_x": r["profile_x"], "profile_h": r["profile_h"],
                "pressure_x": r["pressure_x"], "pressure": r["pressure"],
                "base_x": r["base_x"], "base_fz": r["base_fz"],
                "floor_fz": [r["floor_fz"]]}
    common.save_histories(path, series)


def reanalyse(source, out, extra=(), threads=1):
    """The summary, plots and heaps of a finished run made again from what it saved
    (``source``: its folder — summary.json, heaps.h5 and, for runs that saved no base
    forces in heaps.h5, the final heaps' VTU files), with this module's analysis;
    ``extra``: result dicts of more heaps (:func:`run_heap`'s, e.g. run one seed at a
    time) to add. Writes to ``out``; returns the summary."""
    import json
    import types

    import h5py
    import meshio

    source, out = Path(source), common.output_dir(CASE, out)
    old = json.loads((source / "summary.json").read_text())
    cfg = old["data"]["preset"]
    runs, wall = {}, 0.0
    with h5py.File(source / "heaps.h5", "r") as f:
        for h in old["data"]["heaps"]:
            key = f"{h['model']}_{h['sequence']}_seed{h['seed']}"
            g = {k: np.asarray(v) for k, v in f[key].items()}
            model = Model(h["model"], h["seed"])
            width = model.width * D
            pts, rb = base_spheres(cfg["half_base"], width=model.width)
            if "base_fz" in g:
                base_x, base_fz, floor_fz = g["base_x"], g["base_fz"], float(g["floor_fz"][0])
            else:
                # the base spheres are the first particles; the floor carries the rest
                # of the weight the base was measured to carry
                vtu = meshio.read(source / "vtu" / f"{key}.vtu")
                order = np.argsort(vtu.point_data["id"].ravel())
                base_x = pts[:, 0]
                base_fz = -vtu.point_data["force"][order][:len(pts), 2]
                weight = h["grains"] * model.mass * GRAVITY
                floor_fz = h["balance"] * weight - float(base_fz.sum())
            px, pp = pressure_profile(base_x, base_fz, floor_fz, cfg["half_base"] * D, width,
                                      base_cell(cfg["half_base"] * D, width, len(base_x)))
            fit = fit_flanks(g["profile_x"], g["profile_h"])
            r = {**h, "fit": fit, "angle": mean_std([fit[sd]["angle"]
                                                     for sd in ("left", "right")])[0],
                 "x": g["x"], "y": g["y"], "z": g["z"], "tops": g["tops"],
                 "profile_x": g["profile_x"], "profile_h": g["profile_h"],
                 "pressure_x": px, "pressure": pp, "base_x": base_x, "base_fz": base_fz,
                 "floor_fz": floor_fz, "base_top": float((pts[:, 2] + rb).max())}
            runs.setdefault((h["model"], h["sequence"]), []).append(r)
            wall += h["wall_s"]
    for r in extra:
        model = Model(r["model"], r["seed"])
        width = model.width * D
        px, pp = pressure_profile(r["base_x"], r["base_fz"], r["floor_fz"],
                                  cfg["half_base"] * D, width,
                                  base_cell(cfg["half_base"] * D, width, len(r["base_x"])))
        runs.setdefault((r["model"], r["sequence"]), []).append(
            {**r, "pressure_x": px, "pressure": pp})
        wall += r["wall_s"]
    args = types.SimpleNamespace(preset=old["preset"], threads=threads)
    return finish(args, out, cfg, runs, lambda: wall)


if __name__ == "__main__":
    main()
