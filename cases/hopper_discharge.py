"""A flat-bottomed bin discharging through an orifice: mass flow rate against Beverloo's law (Beverloo et al. 1961).

Beverloo, Leniger and van de Velde (1961): the mass flow rate of a coarse, cohesionless
granular material through a circular orifice of diameter D in a flat floor is
W = C ρ_b √g (D − k d)^(5/2) (ρ_b the bulk density of the packed bed, d the grain
size; they give C ≈ 0.58, k ≈ 1.5), and does not depend on the height of the fill
(once it is above about the bin's width: Janssen's saturation of the pressure). In two
dimensions (a slot of width D in the floor of a bin of discs, W in kg/s per metre of
thickness, ρ_b the areal bulk density in kg/m²) the same argument (a free-fall arch of
span D) gives the exponent 3/2: W = C ρ_b √g (D − k d)^(3/2).

Reference values we compare to
------------------------------
- 3D: C = 0.58, k = 1.5 (Beverloo et al. 1961, Chem. Eng. Sci. 15:260).
- 2D: C = 1.03 and k = 1.5 as the 2D values quoted for Mankoc et al. (2007), "The flow
  rate of granular materials through an orifice", Granular Matter 9:407, whose
  experiments and simulations cover both two and three dimensions (they also give
  k ≈ 1.5–2.0 in 3D). These values have not been checked here against the paper's
  tables; the comparison bands below are wide for that reason.

Set-up (our choices; the law fixes none of them)
------------------------------------------------
- Grains: discs (2D) or spheres (3D) of d50 = 5 mm, diameters uniform by number in
  0.9–1.1 d50 (a narrow spread: a monodisperse bed crystallises in 2D, which changes
  the flow), ρ = 2500 kg/m³.
- Contact: ``tdem.LinearContact`` with friction 0.5 and restitution 0.5, no rolling
  resistance, walls of the same law. kn = 1e6 N/m per metre (2D): the weight of the
  fill, ρ_b g H ≈ 5 kPa at the floor (no Janssen relief), over one grain, is about
  25 N/m a contact, an overlap of 0.5 % d; the summary reports the mean and largest
  overlap between grains in the settled bed. kn = 2e3 N/m in 3D (the same estimate
  for a contact force ρ_b g H d²: 0.1–0.3 % d). The rate does not change with kn while the overlaps
  stay small (Beverloo's rate is set by free fall over the arch, not by stiffness):
  the 2D bin of D = 6 d with kn doubled discharges 1.5 % slower (21.09 against 21.41
  kg/(s·m)), within the scatter between the two fill windows.
- Bin: width 24 d (2.5 D_max + 4 d for D_max = 8 d: the rate does not depend on the
  bin once its width is above 2.5 D, Nedderman), fill 40 d high (2D quick preset);
  flat floor, a slot of width D in its middle (3D: a square bin, a floor plate with a
  circular hole, triangulated from polar rings).
- Filling: all grains inserted at once (``sim.insert(count=...)``, random positions
  without overlap in a box 2.4 times the fill's height) above the orifice, which is
  closed by a plug (a wall segment or a square mesh under the hole); they fall and
  settle for ``settle`` s. The bulk density ρ_b is then measured in the bed: the mass
  of the grains whose centres lie in a window 2 d from the side walls, 1 d above the
  floor and 3 d below the bed's surface, over its area (volume).
- Discharge: the plug moves down out of the way at 5 m/s (faster than the grains
  fall), grains that fall below the floor are removed by an outlet (``sim.remove_in``,
  a box from 3 d to 40 d below the floor: deeper than a grain falls between two
  checks) and counted with their time of removal. The first ``skip`` s after opening
  (start-up of the flow and the fall to the outlet) are left out; the run stops when
  the bed's height falls below ``h_stop`` (in bin widths) or at ``t_max``.
- The rate W: the slope (least squares) of the removed mass against time over the
  measured span, and over each of its two halves (the first at a higher fill than
  the second): the rate does not depend on the fill height if the two agree.
- Beverloo's C and k: W^(2/5) (2D: W^(2/3)) is linear in D:
  (W/(ρ_b √g))^(1/n) = C^(1/n) (D − k d), n = 5/2 (3D) or 3/2 (2D); a least-squares
  line through the orifices gives C (from its slope) and k (from its intercept). Each
  orifice's own measured ρ_b divides its rate.

What is compared (``summary.json``)
-----------------------------------
Pass or fail: the fit recovers C and k of synthetic Beverloo data exactly; every
orifice flows (no clog) and its rate over the two fill heights agrees within 10 %
(independence of the fill height); the fitted C and k within wide bands around the
references (2D: C 0.7–1.4, k 0.5–2.5; 3D: C 0.4–0.8, k 0.8–2.5); each orifice's rate
within 25 % of Beverloo's with the reference C and k and the measured ρ_b; the overlaps
in the settled bed below 1 % d. Reported: the rates, windows and fill heights, ρ_b,
the packing fraction, the fit's residuals.

Outputs (``--out DIR``, default out/hopper_discharge)
------------------------------------------------------
``discharge.png`` (removed mass against time for each orifice, the fitted slopes over
the two windows), ``beverloo.png`` (W^(1/n) against D: the points, the fitted line,
Beverloo's line with the reference C and k), ``snapshot.png`` (the bins during
discharge, grains coloured by speed), ``discharge.h5`` (the removal times and masses),
``summary.json``.
"""
import math
from pathlib import Path

import numpy as np

import tdem

from . import _common as common

CASE = "hopper_discharge"
PAPER = "Beverloo et al. (1961): discharge of a flat-bottomed bin through an orifice"

GRAVITY = 9.81
D50 = 0.005                    # grain size (m)
SPREAD = (0.9, 1.1)            # diameters uniform by number in these multiples of D50
RHO = 2500.0
FRICTION, RESTITUTION = 0.5, 0.5
KN = {2: 1e6, 3: 2e3}          # normal stiffness (2D: N/m per metre; 3D: N/m)
# the references: (C, k) and where they come from
REFERENCE = {
    2: (1.03, 1.5, "2D values quoted for Mankoc et al. (2007), Granular Matter 9:407"),
    3: (0.58, 1.5, "Beverloo et al. (1961), Chem. Eng. Sci. 15:260"),
}
BANDS = {2: {"C": (0.7, 1.4), "k": (0.5, 2.5)}, 3: {"C": (0.4, 0.8), "k": (0.8, 2.5)}}
RATE_BAND = 0.25               # each orifice's rate within this of Beverloo's
HEIGHT_BAND = 0.10             # the two windows' rates agree within this
OVERLAP_MEAN = 0.005           # the settled bed's mean overlap, over d
OVERLAP_P99 = 0.015            # ... and its 99th percentile
PLUG_SPEED = 5.0               # m/s, the plug moves down out of the way
OUTLET = (3.0, 40.0)           # the outlet: from this far below the floor to this (d)
SEGMENT = 0.05                 # s, the run is looked at this often

PRESETS = {
    "quick": {"dim": 2, "ratios": (5.0, 6.0, 7.0, 8.0), "width": 24.0, "fill": 50.0,
              "settle": 0.6, "skip": 0.2, "t_max": 1.4, "h_stop": 1.0, "seed": 1},
    "paper": {"dim": 2, "ratios": (5.0, 6.0, 7.0, 8.0, 10.0, 12.0), "width": 34.0,
              "fill": 80.0, "settle": 0.8, "skip": 0.25, "t_max": 2.5, "h_stop": 1.0,
              "seed": 1},
}
#: ``--dim 3``: spheres in a square bin with a circular hole (not yet run in full: the
#: quick preset's four bins hold about 13 000 spheres each)
PRESETS_3D = {
    "quick": {"dim": 3, "ratios": (5.0, 6.0, 7.0, 8.0), "width": 22.0, "fill": 24.0,
              "settle": 0.5, "skip": 0.2, "t_max": 1.0, "h_stop": 0.5, "seed": 1},
    "paper": {"dim": 3, "ratios": (5.0, 6.0, 7.0, 8.0, 10.0), "width": 28.0, "fill": 36.0,
              "settle": 0.6, "skip": 0.25, "t_max": 1.5, "h_stop": 0.5, "seed": 1},
}


# ------------------------------------------------------------------ the law
def exponent(dim):
    """Beverloo's exponent of (D − k d): 5/2 in 3D, 3/2 in 2D."""
    return 2.5 if dim == 3 else 1.5


def beverloo(D, d, rho_b, C, k, dim=3, g=GRAVITY):
    """Beverloo's mass flow rate (kg/s; 2D: kg/s per metre): C ρ_b √g (D − k d)^n."""
    D = np.asarray(D, dtype=float)
    return C * rho_b * math.sqrt(g) * np.clip(D - k * d, 0.0, None) ** exponent(dim)


def fit_beverloo(D, W, d, rho_b, dim=3, g=GRAVITY):
    """C and k of Beverloo's law from rates ``W`` at orifices ``D`` (bulk densities
    ``rho_b``, one or one per orifice): the least-squares line of
    y = (W / (ρ_b √g))^(1/n) = C^(1/n) (D − k d) in D. Returns {C, k, slope,
    intercept, residuals (of y), rms_relative (of W from the fitted law)}."""
    D = np.asarray(D, dtype=float)
    W = np.asarray(W, dtype=float)
    rb = np.broadcast_to(np.asarray(rho_b, dtype=float), D.shape)
    n = exponent(dim)
    y = (W / (rb * math.sqrt(g))) ** (1.0 / n)
    A = np.stack([D, np.ones_like(D)], axis=1)
    (a, b), *_ = np.linalg.lstsq(A, y, rcond=None)
    C, k = a ** n, -b / (a * d)
    res = y - (a * D + b)
    W_fit = beverloo(D, d, rb, C, k, dim, g)
    return {"C": float(C), "k": float(k), "slope": float(a), "intercept": float(b),
            "residuals": res.tolist(),
            "rms_relative": float(np.sqrt(np.mean((W / W_fit - 1.0) ** 2)))}


def slope(t, m):
    """Least-squares slope of m against t (None with fewer than 3 points)."""
    t, m = np.asarray(t, dtype=float), np.asarray(m, dtype=float)
    if len(t) < 3 or np.ptp(t) <= 0:
        return None
    return float(np.polyfit(t, m, 1)[0])


# ------------------------------------------------------------------ geometry
def square_with_hole(half, radius, segments=32, rings=4):
    """A square plate [−half, half]² at z = 0 with a circular hole of ``radius`` at its
    centre, triangulated from polar rings: ``segments`` points (a multiple of 8: the
    square's corners are among them) on the hole, the same angles on the square's
    edge, ``rings`` rings between (radii graded). Normals point up (+z)."""
    k = int(segments)
    if k % 8 or k < 8:
        raise ValueError(f"segments must be a multiple of 8, got {segments!r}")
    if not 0 < radius < half:
        raise ValueError(f"the hole ({radius}) must lie inside the square ({half})")
    th = 2.0 * np.pi * np.arange(k) / k
    c, s = np.cos(th), np.sin(th)
    edge = half / np.maximum(np.abs(c), np.abs(s))     # the square's boundary at angle θ
    verts = []
    for j in range(rings + 1):
        f = (j / rings) ** 1.5
        r = radius + f * (edge - radius)
        verts.append(np.stack([r * c, r * s, np.zeros(k)], axis=1))
    verts = np.concatenate(verts)
    tris = []
    for j in range(rings):
        for i in range(k):
            a, b = j * k + i, j * k + (i + 1) % k
            a2, b2 = a + k, b + k
            tris += [[a, b, b2], [a, b2, a2]]
    tris = np.array(tris)
    e = np.cross(verts[tris[:, 1]] - verts[tris[:, 0]], verts[tris[:, 2]] - verts[tris[:, 0]])
    flip = e[:, 2] < 0
    tris[flip] = tris[flip][:, ::-1]
    return verts, tris


class Bin:
    """One bin with one orifice: the walls, the plug, the fill, the outlet."""

    def __init__(self, cfg, ratio, opts, log=None):
        self.cfg = cfg
        self.dim = dim = cfg["dim"]
        self.log = log or (lambda s: None)
        d = D50
        self.D = ratio * d
        self.width = cfg["width"] * d
        self.fill = cfg["fill"] * d
        self.law = tdem.LinearContact(kn=KN[dim], friction=FRICTION, restitution=RESTITUTION)
        gravity = (0.0, -GRAVITY) if dim == 2 else (0.0, 0.0, -GRAVITY)
        self.sim = sim = tdem.Simulation(dim=dim, gravity=gravity, progress=False, **opts)
        w, D = 0.5 * self.width, 0.5 * self.D
        top = 2.6 * self.fill
        if dim == 2:
            sim.add_wall((-w, 0.0), (-D, 0.0), contact=self.law)
            sim.add_wall((D, 0.0), (w, 0.0), contact=self.law)
            sim.add_wall((-w, 0.0), (-w, top), contact=self.law)
            sim.add_wall((w, 0.0), (w, top), contact=self.law)
            self.plug = sim.add_wall((-D, 0.0), (D, 0.0), contact=self.law)
            self.area = self.width                      # of the bed's cross-section
        else:
            v, t = square_with_hole(w, D, segments=48)
            sim.add_mesh(v, t, contact=self.law)
            v, t = tdem.surfaces.box((-w, -w, 0.0), (w, w, top))
            sides = ~np.all(np.isclose(v[t][:, :, 2], 0.0), axis=1)
            sim.add_mesh(v, t[sides], contact=self.law)
            v, t = tdem.surfaces.plane((0.0, 0.0, 0.0), (0.0, 0.0, 1.0), 2.0 * D + 2.0 * d)
            self.plug = sim.add_mesh(v, t, contact=self.law)
            self.area = self.width ** 2
        self.grading = tdem.grading.uniform(SPREAD[0] * d, SPREAD[1] * d, dim=dim)
        # the number of grains of the fill at a packing fraction of 0.82 (2D) or 0.6
        cell = self.area * self.fill
        phi, vol = (0.82, math.pi * (0.5 * d) ** 2) if dim == 2 else (
            0.6, math.pi / 6.0 * d ** 3)
        self.count = int(phi * cell / vol)
        self.opened = None

    # ------------------------------------------------------------ filling
    def fill_and_settle(self):
        sim, d = self.sim, D50
        w = 0.5 * self.width
        lo = (-w, 0.5 * d) if self.dim == 2 else (-w, -w, 0.5 * d)
        hi = (w, 2.4 * self.fill) if self.dim == 2 else (w, w, 2.4 * self.fill)
        self.inserter = sim.insert(box=(lo, hi), count=self.count, grading=self.grading,
                                   density=RHO, contact=self.law, seed=self.cfg["seed"])
        sim.run(until=self.cfg["settle"])
        if self.inserter.count < self.count:
            self.log(f"  inserted {self.inserter.count} of {self.count} grains")

    def positions(self):
        p = self.sim.particles.numpy()
        return p

    def bed(self):
        """The settled bed: bulk density in the inner window, its height, overlaps."""
        p = self.positions()
        d, dim = D50, self.dim
        x, r, m = p["position"], p["radius"], p["mass"]
        up = x[:, dim - 1]
        # the bed's surface: the mean of the highest grain tops across the bin
        lat = x[:, 0]
        edges = np.linspace(-0.5 * self.width, 0.5 * self.width, int(self.width / (2 * d)) + 1)
        tops = [float((up + r)[(lat >= a) & (lat < b)].max())
                for a, b in zip(edges[:-1], edges[1:]) if np.any((lat >= a) & (lat < b))]
        height = float(np.mean(tops))
        inner = 0.5 * self.width - 2.0 * d
        z0, z1 = 1.0 * d, height - 3.0 * d
        sel = (up >= z0) & (up <= z1) & (np.abs(x[:, 0]) <= inner)
        size = 2.0 * inner * (z1 - z0)
        if dim == 3:
            sel &= np.abs(x[:, 1]) <= inner
            size *= 2.0 * inner
        rho_b = float(m[sel].sum() / size)
        # overlaps between grains (contacts found by distance)
        from scipy.spatial import cKDTree
        pairs = cKDTree(x).query_pairs(2.0 * r.max(), output_type="ndarray")
        gap = np.linalg.norm(x[pairs[:, 0]] - x[pairs[:, 1]], axis=1) - r[pairs].sum(axis=1)
        ov = -gap[gap < 0] / D50
        ov99 = float(np.percentile(ov, 99)) if len(ov) else 0.0
        ke = float(0.5 * np.sum(m * np.einsum("ij,ij->i", p["velocity"], p["velocity"])))
        return {"rho_b": rho_b, "packing_fraction": rho_b / RHO, "height": height,
                "mass": float(m.sum()), "grains": int(len(m)),
                "overlap_mean": float(ov.mean()) if len(ov) else 0.0,
                "overlap_max": float(ov.max()) if len(ov) else 0.0, "overlap_p99": ov99,
                "kinetic_per_grain": ke / len(m)}

    # ------------------------------------------------------------ discharge
    def open(self):
        sim, d = self.sim, D50
        w = 0.5 * self.width
        lo, hi = -OUTLET[1] * d, -OUTLET[0] * d
        box = (((-2 * w, lo), (2 * w, hi)) if self.dim == 2 else
               ((-2 * w, -2 * w, lo), (2 * w, 2 * w, hi)))
        self.outlet = sim.remove_in(box=box)
        v = (0.0, -PLUG_SPEED) if self.dim == 2 else (0.0, 0.0, -PLUG_SPEED)
        self.plug.motion(velocity=v)
        self.opened = float(sim.time)

    def discharge(self, mass0, rho_b, snapshot_at=None):
        """Run until the bed's height is below h_stop bin widths or t_max after
        opening; a snapshot (positions, radii, speeds) near ``snapshot_at`` s after
        opening."""
        sim, cfg = self.sim, self.cfg
        h_stop = cfg["h_stop"] * self.width
        snap = None
        while True:
            t = sim.time - self.opened
            if t >= cfg["t_max"] - 1e-9:
                break
            height = (mass0 - self.outlet.mass) / (rho_b * self.area)
            if height < h_stop and t > cfg["skip"]:
                break
            sim.run(until=min(sim.time + SEGMENT, self.opened + cfg["t_max"]))
            if snap is None and snapshot_at is not None and \
                    sim.time - self.opened >= snapshot_at:
                p = sim.particles.numpy()
                snap = {"position": p["position"], "radius": p["radius"],
                        "speed": np.linalg.norm(p["velocity"], axis=1),
                        "t": sim.time - self.opened}
        return snap


def measure(times, masses, opened, skip, mass0, rho_b, area):
    """The rate over the measured span (after ``skip``) and over its two halves, with
    the mean fill height (m) in each."""
    t = np.asarray(times, dtype=float) - opened
    m = np.cumsum(masses)
    keep = t >= skip
    out = {"t": t, "m": m}
    if keep.sum() < 6:
        return {**out, "W": None, "windows": [], "clogged": True}
    t0, t1 = skip, float(t[keep].max())
    mid = 0.5 * (t0 + t1)
    wins = []
    for a, b in ((t0, mid), (mid, t1)):
        s = (t >= a) & (t <= b)
        left = mass0 - m[s]
        wins.append({"t0": a, "t1": b, "W": slope(t[s], m[s]), "grains": int(s.sum()),
                     "fill_height": float(np.mean(left) / (rho_b * area))
                     if s.any() else None})
    # a clog: no grain out over the last quarter of the span
    late = t[keep] > t1 - 0.25 * (t1 - t0)
    return {**out, "W": slope(t[keep], m[keep]), "windows": wins, "span": (t0, t1),
            "clogged": bool(late.sum() < 2)}


def run_orifice(cfg, ratio, opts, log=print):
    clock = common.Stopwatch()
    b = Bin(cfg, ratio, opts, log)
    b.fill_and_settle()
    bed = b.bed()
    log(f"  D = {ratio:g} d: {bed['grains']} grains, rho_b = {bed['rho_b']:.4g}, "
        f"bed {bed['height'] / D50:.1f} d, overlap mean {100 * bed['overlap_mean']:.3f} % d, "
        f"p99 {100 * bed['overlap_p99']:.2f} % d, max {100 * bed['overlap_max']:.2f} % d, "
        f"kinetic energy a grain {bed['kinetic_per_grain']:.2e} J")
    b.open()
    snap = b.discharge(bed["mass"], bed["rho_b"], snapshot_at=0.5 * (cfg["skip"] + cfg["t_max"]))
    o = b.outlet
    r = measure(o.times, o.masses, b.opened, cfg["skip"], bed["mass"], bed["rho_b"], b.area)
    ref_C, ref_k, _ = REFERENCE[b.dim]
    W_bev = float(beverloo(b.D, D50, bed["rho_b"], ref_C, ref_k, b.dim))
    wins = ", ".join(f"{w['W']:.4g}" if w["W"] is not None else "–" for w in r["windows"])
    log(f"  D = {ratio:g} d: W = {r['W'] if r['W'] is None else round(r['W'], 4)} "
        f"(windows {wins}; Beverloo {W_bev:.4g}), {o.count} grains out, "
        f"{clock():.0f} s")
    return {"ratio": ratio, "D": b.D, "bed": bed, "W": r["W"], "windows": r["windows"],
            "span": r.get("span"), "clogged": r["clogged"], "W_beverloo": W_bev,
            "t": r["t"], "m": r["m"], "out": int(o.count), "snapshot": snap,
            "width": b.width, "wall_s": clock(), "steps": int(b.sim.steps),
            "dt": float(b.sim.dt)}


# ------------------------------------------------------------------ plots
def unit_W(dim):
    return "kg/s" if dim == 3 else "kg/(s·m)"


def plot_discharge(runs, cfg, png):
    plt = common.pyplot()
    fig, ax = plt.subplots(figsize=(7.5, 4.8))
    colours = plt.cm.viridis(np.linspace(0.0, 0.85, len(runs)))
    for r, c in zip(runs, colours):
        ax.plot(r["t"], r["m"], color=c, lw=1.6, label=f"D = {r['ratio']:g} d"
                + (f": W = {r['W']:.3g} {unit_W(cfg['dim'])}" if r["W"] else " (clogged)"))
        for k, w in enumerate(r["windows"]):
            if w["W"] is None:
                continue
            s = (r["t"] >= w["t0"]) & (r["t"] <= w["t1"])
            tt = np.array([w["t0"], w["t1"]])
            m0 = np.mean(r["m"][s]) - w["W"] * np.mean(r["t"][s])
            ax.plot(tt, m0 + w["W"] * tt, ls="--" if k == 0 else ":", color="k", lw=1.0)
    ax.axvline(cfg["skip"], color="0.6", lw=0.8)
    lo, hi = ax.get_ylim()
    ax.text(cfg["skip"], lo + 0.02 * (hi - lo), " ← start-up left out", fontsize=8,
            va="bottom", color="0.4")
    ax.plot([], [], "k--", lw=1.0, label="fit, window 1 (higher fill)")
    ax.plot([], [], "k:", lw=1.0, label="fit, window 2 (lower fill)")
    ax.set_xlabel("time since the orifice opened (s)")
    ax.set_ylabel("removed mass (" + ("kg" if cfg["dim"] == 3 else "kg/m") + ")")
    ax.set_title("Discharge: removed mass against time", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper left")
    fig.tight_layout()
    return common.save(fig, png)


def plot_beverloo(runs, fit, cfg, png):
    plt = common.pyplot()
    dim = cfg["dim"]
    n = exponent(dim)
    ok = [r for r in runs if r["W"]]
    D = np.array([r["D"] for r in ok])
    rb = np.array([r["bed"]["rho_b"] for r in ok])
    y = (np.array([r["W"] for r in ok]) / (rb * math.sqrt(GRAVITY))) ** (1.0 / n)
    fig, ax = plt.subplots(figsize=(6.5, 4.8))
    xs = np.linspace(0.0, max(D.max(), 1e-9) * 1.1, 50)
    ax.plot(D / D50, y * 1e3, "o", color="C0", ms=7, label="DEM (each orifice)")
    for r, yy in zip(ok, y):
        for w in r["windows"]:
            if w["W"]:
                ax.plot(r["D"] / D50, 1e3 * (w["W"] / (r["bed"]["rho_b"] * math.sqrt(GRAVITY)))
                        ** (1.0 / n), "_", color="C0", ms=10)
    if fit:
        ax.plot(xs / D50, 1e3 * np.clip(fit["slope"] * xs + fit["intercept"], 0, None), "C0-",
                label=f"fit: C = {fit['C']:.3f}, k = {fit['k']:.2f}")
    C, k, src = REFERENCE[dim]
    ax.plot(xs / D50, 1e3 * C ** (1.0 / n) * np.clip(xs - k * D50, 0, None), "C3--",
            label=f"Beverloo, C = {C:g}, k = {k:g}\n({src.split(',')[0]})")
    ax.set_xlabel("orifice D / d")
    p = "2/5" if dim == 3 else "2/3"
    ax.set_ylabel(f"(W / (ρ_b √g))^({p})  (10⁻³ m)")
    ax.set_title(f"Beverloo's linearisation ({dim}D): short bars are the two fill windows",
                 fontsize=10)
    ax.set_xlim(0, xs.max() / D50)
    ax.set_ylim(0, None)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper left")
    fig.tight_layout()
    return common.save(fig, png)


def plot_snapshot(runs, cfg, png):
    plt = common.pyplot()
    from matplotlib.collections import PatchCollection
    from matplotlib.patches import Circle
    shown = [r for r in runs if r["snapshot"] is not None]
    fig, axes = plt.subplots(1, len(shown), figsize=(3.0 * len(shown) + 0.8, 5.2),
                             squeeze=False)
    vmax = max(float(np.percentile(r["snapshot"]["speed"], 99)) for r in shown)
    mappable = None
    for ax, r in zip(axes[0], shown):
        s = r["snapshot"]
        x = s["position"]
        if cfg["dim"] == 3:         # a slice through the orifice's axis
            keep = np.abs(x[:, 1]) < 1.0 * D50
            xy = x[keep][:, [0, 2]]
            rad = s["radius"][keep]
            sp = s["speed"][keep]
        else:
            xy, rad, sp = x, s["radius"], s["speed"]
        pc = PatchCollection([Circle(p, q) for p, q in zip(xy, rad)], cmap="magma_r",
                             edgecolor="none")
        pc.set_array(sp)
        pc.set_clim(0.0, vmax)
        ax.add_collection(pc)
        mappable = pc
        w, Dh = 0.5 * r["width"], 0.5 * r["D"]
        ax.plot([-w, -Dh], [0, 0], "k-", lw=2.5)
        ax.plot([Dh, w], [0, 0], "k-", lw=2.5)
        ax.plot([-w, -w], [0, cfg["fill"] * D50 * 1.1], "k-", lw=2.5)
        ax.plot([w, w], [0, cfg["fill"] * D50 * 1.1], "k-", lw=2.5)
        ax.set_xlim(-w - 2 * D50, w + 2 * D50)
        ax.set_ylim(-12 * D50, cfg["fill"] * D50 * 1.1)
        ax.set_aspect("equal")
        ax.set_xticks([])
        ax.set_yticks([])
        ax.set_title(f"D = {r['ratio']:g} d, t = {s['t']:.2f} s", fontsize=9)
    cb = fig.colorbar(mappable, ax=list(axes[0]), shrink=0.8, pad=0.02)
    cb.set_label("speed (m/s)")
    fig.suptitle("The bins during discharge" + (" (a slice through the orifice)"
                                                if cfg["dim"] == 3 else ""), fontsize=10)
    return common.save(fig, png)


# ------------------------------------------------------------------ main
def _options(p):
    p.add_argument("--dim", type=int, choices=(2, 3), default=2,
                   help="2: discs in a bin with a slot (the presets' default); 3: spheres "
                        "in a square bin with a circular hole (hours on 2 cores)")


def main(argv=None):
    args, out = common.parse(CASE, argv, description=__doc__.splitlines()[0], extra=_options)
    clock = common.Stopwatch()
    cfg = (PRESETS if args.dim == 2 else PRESETS_3D)[args.preset]
    opts = common.sim_options(args)
    runs = []
    for ratio in cfg["ratios"]:
        runs.append(run_orifice(cfg, ratio, opts, log=common.say))
    return finish(args, out, cfg, runs, clock)


def finish(args, out, cfg, runs, clock):
    out = Path(out)
    dim = cfg["dim"]
    ref_C, ref_k, src = REFERENCE[dim]
    flowing = [r for r in runs if r["W"] and not r["clogged"]]
    fit = None
    if len(flowing) >= 3:
        fit = fit_beverloo([r["D"] for r in flowing], [r["W"] for r in flowing], D50,
                           [r["bed"]["rho_b"] for r in flowing], dim)
    # the fit on synthetic Beverloo data (a known answer)
    Ds = np.array([4.0, 5.0, 6.5, 8.0]) * D50
    syn = fit_beverloo(Ds, beverloo(Ds, D50, 1600.0, ref_C, ref_k, dim), D50, 1600.0, dim)
    checks = [
        common.check("fit.synthetic_C", syn["C"], ref_C, common.rel(1e-9), "",
                     "the fit of W^(1/n) linear in D recovers C of exact Beverloo rates"),
        common.check("fit.synthetic_k", syn["k"], ref_k, common.rel(1e-9), "",
                     "... and k"),
    ]
    unit = unit_W(dim)
    for r in runs:
        tag = f"D{r['ratio']:g}d"
        checks.append(common.check(f"{tag}.flows", not r["clogged"] and r["W"] is not None,
                                   True, common.EQUAL, "",
                                   "the orifice did not clog over the measured span"))
        w = [x["W"] for x in r["windows"]]
        if r["W"] and len(w) == 2 and None not in w:
            checks.append(common.check(
                f"{tag}.rate_ratio_lower_over_higher_fill", w[1] / w[0], 1.0,
                common.rel(HEIGHT_BAND), "",
                f"the rate over the second window (fill {r['windows'][1]['fill_height'] / D50:.1f} d) "
                f"over the first ({r['windows'][0]['fill_height'] / D50:.1f} d): the rate does not "
                f"depend on the fill height (Beverloo); ±{100 * HEIGHT_BAND:g} % allows the "
                f"scatter of {min(x['grains'] for x in r['windows'])}+ grains a window"))
        if r["W"]:
            checks.append(common.check(
                f"{tag}.W", r["W"], r["W_beverloo"], common.rel(RATE_BAND), unit,
                f"the rate against Beverloo's with C = {ref_C}, k = {ref_k} ({src}) and this "
                f"bin's measured ρ_b = {r['bed']['rho_b']:.4g}; the band allows the "
                "reference's own spread"))
        bed = r["bed"]
        checks.append(common.check(
            f"{tag}.overlap_mean", bed["overlap_mean"], None,
            common.between(max=OVERLAP_MEAN), "d",
            "the mean overlap between touching grains of the settled bed over d: the "
            "stiffness is high enough for the bed's weight"))
        checks.append(common.check(
            f"{tag}.overlap_p99", bed["overlap_p99"], None, common.between(max=OVERLAP_P99),
            "d", f"the 99th percentile of the overlaps over d (the largest: "
                 f"{bed['overlap_max']:.2e} d)"))
    if fit:
        b = BANDS[dim]
        checks += [
            common.check("fit.C", fit["C"], ref_C, common.between(*b["C"]), "",
                         f"Beverloo's C fitted over {len(flowing)} orifices ({src}); the "
                         f"fit's rms deviation of W from its law {100 * fit['rms_relative']:.1f} %"),
            common.check("fit.k", fit["k"], ref_k, common.between(*b["k"]), "",
                         f"Beverloo's k fitted over {len(flowing)} orifices ({src})"),
        ]
    checks.append(common.check(
        "rho_b", [r["bed"]["rho_b"] for r in runs], None, None,
        "kg/m³" if dim == 3 else "kg/m²",
        "the bulk density of each settled bed (areal in 2D), measured away from the "
        "walls and the surface"))
    data = {
        "preset": cfg, "dim": dim, "d50": D50, "spread": SPREAD, "density": RHO,
        "kn": KN[dim], "friction": FRICTION, "restitution": RESTITUTION,
        "reference": {"C": ref_C, "k": ref_k, "source": src},
        "fit": fit, "synthetic_fit": syn,
        "orifices": [{k: r[k] for k in ("ratio", "D", "W", "W_beverloo", "windows", "span",
                                        "clogged", "out", "bed", "wall_s", "steps", "dt")}
                     for r in runs],
    }
    s = common.summary(CASE, args.preset, checks, data, clock(), threads=args.threads,
                       paper=PAPER)
    import h5py
    with h5py.File(out / "discharge.h5", "w") as f:
        for r in runs:
            g = f.require_group(f"D{r['ratio']:g}d")
            g.create_dataset("time", data=np.asarray(r["t"], dtype=float))
            g.create_dataset("removed_mass", data=np.asarray(r["m"], dtype=float))
    plot_discharge(runs, cfg, out / "discharge.png")
    plot_beverloo(runs, fit, cfg, out / "beverloo.png")
    plot_snapshot(runs, cfg, out / "snapshot.png")
    s["wall_time_s"] = float(clock())
    common.write_summary(out, s)
    common.print_checks(s)
    return s


if __name__ == "__main__":
    main()
