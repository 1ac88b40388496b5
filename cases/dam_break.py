"""Water column collapsing on a dry floor (Martin & Moyce 1952): tdem's two water models beside the measured surge front and a volume-of-fluid solution.

Set-up
------
Martin & Moyce's column of n² = 2: width a = 0.3 m, height h = n²a = 2a, against
the left wall of a tank 1.5 m long (three frictionless segment walls, the
particle–wall law k_n = 3K), released at rest at t = 0 with no damping. Water:
ρ = 1000 kg/m³, K = 2 MPa (weakly compressible: c = 44.7 m/s, above 10 × the
fastest water, sqrt(2gh) = 3.4 m/s), viscosity μ = 1 Pa·s (a numerical value, as in
water_blocks). Two models, each in its own simulation and output subfolder:

- ``cells``: ``tdem.Fluid(voronoi=True)`` on a random packing (radii 0.8–1.2 R,
  76 % of the column, ``tdem.pack.random``): each particle's pressure from its
  Voronoi cell (``physics.pcmm.cells``);
- ``elements``: ``tdem.Fluid()`` on a square lattice of R: PCMM triangles with the
  incremental pressure.

Read-out: the surge front, the largest particle x + R, as Z = x/a against
T = t·sqrt(2g/a) (their n·t·sqrt(g/a)), beside Martin & Moyce's Fig. 3 (a = 2.25 in,
as digitised by PySPH's ``db_exp_data.py``); the cells' water area Σ min(A, A0)
(water carries no tension, so a cell grown beyond its area at rest holds no more
water); the energy (kinetic + gravitational + stored + the walls' springs).

Presets: ``quick`` R = 7.5 mm cells (764 discs), R = 1 cm lattice (450), 24 s;
``paper`` R = 5 mm both (1,719 discs, 1,800 lattice particles), 60 s (one thread,
2026-12-06). To T = 3.4.

Result: the cells solve the problem, which runs ahead of the measurements
---------------------------------------------------------------------------
The problem as posed (a column released at once, frictionless walls, μ = 1 Pa·s, no
surface tension) is also solved by a volume-of-fluid reference, OpenFOAM's interFoam
on a uniform mesh (``docs/reference/dam_break_vof.py``; the front where the water
fraction is 0.5): :data:`VOF_FRONT`, 2.5 mm cells, within 0.9 % of the 5 mm mesh.
That front leads Martin & Moyce's by +13.5, +17.1, +14.0, +12.3, +10.7 % at T =
0.83, 1.22, 2.0, 2.55, 3.35; with water's viscosity and no-slip walls at the
experiment's own scale (a = 2.25 in, surface tension 0.07 N/m) still by +13.4,
+16.5, +13.2, +11.2, +9.5 % (the tables beside the script). An instantly released
column runs 10–17 % ahead of the measured one whatever the floor and the viscosity:
the measurements lag by what none of these models has, such as the gate's lift.
10 % against Martin & Moyce at every time is therefore not a fair aim for these
models; the case checks it (and fails) beside the fair one, 10 % against the
reference.

- The cells (paper preset, R = 5 mm): +12.1, +17.0, +13.9, +11.5, +9.3 % ahead of
  the measurements, within 1.3 % of the reference at every record from T = 0.3 to
  3.4; the lead on the measurements is the same within 3 points at R = 7.5, 5 and
  3.5 mm (tests/test_voronoi_water.py).
- The elements: +4.4, +7.8, +6.2, +4.5, +4.2 % on the 5 mm lattice (paper preset),
  that is 6–9 % behind the reference; −0.3 to +11.7 % on the 1 cm lattice (quick).
  The element water comes nearer the measurements by a dissipation of its own: with
  the same viscosity it has lost 24 % of its energy by T = 3.35 (R = 5 mm; its
  kinetic energy 228 J against the cells' 379 J), the cells 3.8 %
  (``energy_change_end`` in the checks): the elements break and form as it flows.

The cells' surface cells reach ``physics.pcmm.cells.REACH`` = 2.5 mean radii beyond
the surface particles, so that the water's free surface lies outside them; with 1.5
the front would fall by 2–4 points, but the column at rest of
tests/test_voronoi_water.py would read pressures up to 0.89 ρgh off ρg·depth (2.5:
0.31 %). How a run is split into segments (``sim.run`` calls: here one per record)
moves the front by up to 2.5 % for the elements and 0.5 % for the cells: round-off of
the sums, amplified by the flow.

Outputs (``--out DIR``, default out/dam_break): per model a VTU series (.pvd),
``front.png`` (Z against T, both models, the reference and the measurements), ``snapshots.png``
(both models at T = 1.22 and 2.55, coloured by pressure), ``summary.json``.
"""
import math

import numpy as np

import tdem

from . import _common as common
from . import _pcmm

CASE = "dam_break"
A = 0.3
H = 2.0 * A
TANK = 1.5
RHO, G, K, MU = 1000.0, 9.81, 2e6, 1.0
#: Martin & Moyce (1952), Fig. 3, n² = 2, a = 2.25 in: (T, Z)
MARTIN_MOYCE = [(0.832, 1.217), (1.219, 1.474), (1.997, 2.292), (2.547, 2.995),
                (3.345, 4.134)]
#: The same problem solved by volume of fluid (OpenFOAM interFoam v1912, 2.5 mm
#: square cells, water ν = 1e-3 m²/s, air, free-slip walls, no surface tension):
#: (T, Z) of docs/reference/dam_break_vof_dx2.5mm_nu0.001_slip.csv, made by
#: ``python docs/reference/dam_break_vof.py --dx 0.0025 --nu 1e-3 --walls slip``
VOF_FRONT = [
    (0, 1.0), (0.1, 1.008), (0.2, 1.027), (0.3, 1.059), (0.4, 1.102), (0.5, 1.154),
    (0.6, 1.214), (0.7, 1.282), (0.8, 1.356), (0.9, 1.436), (1, 1.522), (1.1, 1.612),
    (1.2, 1.707), (1.3, 1.807), (1.4, 1.912), (1.5, 2.020), (1.6, 2.133), (1.7, 2.249),
    (1.8, 2.368), (1.9, 2.492), (2, 2.618), (2.1, 2.748), (2.2, 2.880), (2.3, 3.016),
    (2.4, 3.154), (2.5, 3.295), (2.6, 3.439), (2.7, 3.585), (2.8, 3.733), (2.9, 3.883),
    (3, 4.037), (3.1, 4.191), (3.2, 4.348), (3.3, 4.506), (3.4, 4.666)]
#: Water at the experiment's own scale by the same method (a = 2.25 in, ν = 1e-6 m²/s,
#: no-slip walls, surface tension 0.07 N/m, 0.95 mm cells; ``--a 0.05715 --dx 0.00095
#: --nu 1e-6 --sigma 0.07 --walls noslip``): what a column released at once does
#: with the floor's friction and the water's own viscosity (plotted, not checked)
VOF_FRONT_WATER = [
    (0, 0.997), (0.2, 1.028), (0.4, 1.104), (0.6, 1.214), (0.8, 1.355), (1, 1.518),
    (1.2, 1.700), (1.4, 1.900), (1.6, 2.118), (1.8, 2.351), (2, 2.598), (2.2, 2.857),
    (2.4, 3.128), (2.6, 3.408), (2.8, 3.696), (3, 3.996), (3.2, 4.300), (3.4, 4.613)]
T_END = 3.4
SNAP_T = (1.219, 2.547)
PRESETS = {"quick": {"cells": 0.0075, "elements": 0.01},
           "paper": {"cells": 0.005, "elements": 0.005}}
MODELS = ("cells", "elements")


def time_scale():
    """Seconds per unit of T = t·sqrt(2g/a)."""
    return 1.0 / math.sqrt(2.0 * G / A)


def build(model, radius, arch=None, threads=None):
    """The column of ``model`` ("cells" or "elements") with discs of ``radius``."""
    sim = tdem.Simulation(gravity=(0.0, -G), dt_fraction=0.5, arch=arch,
                          **({"threads": threads} if threads else {}))
    if model == "cells":
        water = tdem.Fluid(density=RHO, bulk_modulus=K, viscosity=MU, voronoi=True)
        pos, r = tdem.pack.random(A, H, 0.8 * radius, 1.2 * radius, seed=1,
                                  target_fraction=0.76)
    else:
        water = tdem.Fluid(density=RHO, bulk_modulus=K, viscosity=MU)
        pos, r = tdem.pack.regular(A, H, radius)
    sim.add_particles(pos, r, material=water, tolerance=radius)
    _pcmm.water_tank(sim, TANK, 2.0 * H, K)
    return sim, len(pos)


def _energy(sim):
    e = sim.energy()
    return e["kinetic"] + e["gravitational"] + e["strain"] + e["elastic"]


def run_model(model, radius, out, arch=None, threads=None):
    """One model's run: the front, the cells' area and the energy at every record."""
    sim, n = build(model, radius, arch, threads)
    sim.run(steps=1)
    a0 = sim.particles.numpy()["mass"] / RHO
    start = _energy(sim)
    ts = time_scale()
    grid = np.round(np.arange(0.1, T_END + 1e-9, 0.1), 6)
    times = sorted(set(grid) | {t for t, _ in MARTIN_MOYCE} | set(SNAP_T))
    output = common.start_output(sim, out / model, max(1, int(round(0.2 * ts / sim.dt))))
    rec = {"T": [], "Z": [], "area": [], "energy": []}
    snaps = {}
    for T in times:
        sim.run(until=T * ts)
        p = sim.particles.numpy()
        rec["T"].append(sim.time / ts)
        rec["Z"].append(float((p["position"][:, 0] + p["radius"]).max()) / A)
        if model == "cells":
            area = sim.water_cells()["area"]
            rec["area"].append(float(np.minimum(area, a0).sum() / a0.sum()) - 1.0)
        rec["energy"].append(_energy(sim) - start)
        if T in SNAP_T:
            snaps[T] = {"x": p["position"].copy(), "r": p["radius"].copy(),
                        "p": p["pressure"].copy()}
    common.finish_output(output)
    res = {k: np.asarray(v) for k, v in rec.items()}
    res.update(snaps=snaps, n=n, dt=sim.dt, start=start, radius=radius)
    return res


def vof_front(T):
    """The reference's front Z at T (linear between its records, 0.1 apart)."""
    t, z = np.array(VOF_FRONT).T
    return float(np.interp(T, t, z))


def vof_deviation(res, start=0.3):
    """The largest |Z/Z_ref − 1| of a model's records from T = ``start`` on."""
    return max(abs(z / vof_front(T) - 1.0) for T, z in zip(res["T"], res["Z"])
               if start - 1e-9 <= T <= T_END + 1e-9)


def front_at(res, T):
    """The recorded front Z at the record nearest T."""
    k = int(np.argmin(np.abs(res["T"] - T)))
    return float(res["Z"][k])


def plot_front(results, png):
    plt = common.pyplot()
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    tm, zm = np.array(MARTIN_MOYCE).T
    ax.fill_between(tm, 0.9 * zm, 1.1 * zm, color="0.85", label="Martin & Moyce ± 10 %")
    ax.plot(tm, zm, "ko", label="Martin & Moyce (1952), n² = 2, a = 2.25 in")
    tv, zv = np.array(VOF_FRONT).T
    ax.plot(tv, zv, "k-", lw=2.5, alpha=0.35,
            label="volume of fluid, the same problem (interFoam, 2.5 mm)")
    tw, zw = np.array(VOF_FRONT_WATER).T
    ax.plot(tw, zw, "k:", lw=1.2,
            label="volume of fluid, water at a = 2.25 in, no-slip, surface tension")
    styles = {"cells": "C0-", "elements": "C1--"}
    names = {"cells": "Voronoi cells, random packing", "elements": "elements, square lattice"}
    for model, res in results.items():
        ax.plot(res["T"], res["Z"], styles[model],
                label=f"tdem {names[model]}, R = {1e3 * res['radius']:g} mm ({res['n']})")
    ax.set_xlabel("T = t·sqrt(2g/a)")
    ax.set_ylabel("surge front Z = x/a")
    ax.set_title("Dam break (h = 2a, a = 0.3 m): the surge front", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    common.save(fig, png)


def plot_snapshots(results, png):
    plt = common.pyplot()
    from matplotlib.collections import EllipseCollection
    fig, axes = plt.subplots(len(results), len(SNAP_T), figsize=(10, 0.6 + 2.4 * len(results)),
                             squeeze=False, layout="constrained")
    pmax = RHO * G * H
    sc = None
    for row, (model, res) in zip(axes, results.items()):
        for ax, T in zip(row, SNAP_T):
            s = res["snaps"][T]
            sc = EllipseCollection(2 * s["r"], 2 * s["r"], np.zeros(len(s["r"])), units="xy",
                                   offsets=s["x"], offset_transform=ax.transData,
                                   cmap="viridis", linewidths=0)
            sc.set_array(s["p"] * 1e-3)
            sc.set_clim(0.0, pmax * 1e-3)
            ax.add_collection(sc)
            zm = dict(MARTIN_MOYCE)[T]
            ax.axvline(zm * A, color="k", ls=":", lw=1, label="Martin & Moyce's front")
            ax.set_xlim(0.0, 1.2)
            ax.set_ylim(0.0, H + 0.02)
            ax.set_aspect("equal")
            ax.set_title(f"{model}, T = {T:g}", fontsize=8)
            ax.tick_params(labelsize=7)
            ax.legend(fontsize=6, loc="upper right")
    fig.colorbar(sc, ax=axes.ravel().tolist(), label="pressure (kPa)", shrink=0.8)
    common.save(fig, png, dpi=110)


def run(preset="quick", out=None, arch=None, threads=None):
    """Run the case; returns the summary dict (also written to ``out/summary.json``)."""
    clock = common.Stopwatch()
    cfg = PRESETS[preset]
    out = common.output_dir(CASE, out)
    results = {}
    for model in MODELS:
        results[model] = run_model(model, cfg[model], out, arch, threads)
        common.say(f"dam_break: {model} done, {common.duration(clock())}")
    plot_front(results, out / "front.png")
    plot_snapshots(results, out / "snapshots.png")
    checks = []
    for model, res in results.items():
        for T, z in MARTIN_MOYCE:
            checks.append(common.check(
                f"{model}.front_T{T:g}", front_at(res, T), z, common.rel(0.10), "x/a",
                f"surge front (largest particle x + R) / a at T = {T:g} against Martin & "
                "Moyce's Fig. 3 (n² = 2, a = 2.25 in); the volume-of-fluid solution of "
                f"the same problem leads it by {100 * (vof_front(T) / z - 1):+.1f} % here "
                "(the column released at once; with water's viscosity, no-slip walls and "
                "surface tension at the experiment's scale by about as much: module "
                "docstring), so a model that solves the problem runs ahead of the "
                "measurements by that much: the front_vof check compares it with that "
                "solution"))
        for T, _ in MARTIN_MOYCE:
            checks.append(common.check(
                f"{model}.front_vof_T{T:g}", front_at(res, T), vof_front(T), common.rel(0.10),
                "x/a", f"surge front / a at T = {T:g} against the volume-of-fluid solution "
                "of the same problem (VOF_FRONT: released at once, free-slip walls, "
                "μ = 1 Pa·s)"))
        checks.append(common.check(
            f"{model}.front_vof_deviation_max", vof_deviation(res), None,
            common.between(max=0.10), "",
            "largest |Z/Z_ref − 1| against the volume-of-fluid front over every record "
            "from T = 0.3 to 3.4 (0.1 apart)"))
        checks.append(common.check(
            f"{model}.energy_gain_max", float(np.max(res["energy"]) / abs(res["start"])),
            None, common.between(max=1e-6), "",
            "largest rise of kinetic + gravitational + stored + wall energy above its "
            "start, relative to it: none may be made (the viscosity takes some away)"))
        checks.append(common.check(
            f"{model}.energy_change_end", float(res["energy"][-1] / abs(res["start"])),
            None, None, "",
            f"kinetic + gravitational + stored + wall energy at T = {T_END:g} against its "
            "start, relative to it: what the viscosity and the model's own dissipation "
            "took away (kinetic energy is what drives the front)"))
    cells = results["cells"]
    checks.append(common.check(
        "cells.area_change_max", float(np.max(np.abs(cells["area"]))), None,
        common.between(max=0.01), "",
        "largest change of the cells' water area Σ min(A, A0) relative to its start"))
    data = {"model": {"a_m": A, "h_m": H, "bulk_modulus_Pa": K, "viscosity_Pa_s": MU,
                      "radius_m": {m: r["radius"] for m, r in results.items()},
                      "particles": {m: r["n"] for m, r in results.items()},
                      "dt_s": {m: r["dt"] for m, r in results.items()}},
            "front": {m: {"T": r["T"], "Z": r["Z"]} for m, r in results.items()},
            "martin_moyce": MARTIN_MOYCE, "vof_front": VOF_FRONT,
            "vof_front_water": VOF_FRONT_WATER}
    summary = common.summary(
        CASE, preset, checks, data, clock(), threads=threads,
        paper="Martin & Moyce (1952), Phil. Trans. R. Soc. A 244, Fig. 3",
        notes="frictionless floor, released at once; the front is the largest x + R; "
              "an instantly released column leads Martin & Moyce by 10-17 % (the "
              "volume-of-fluid reference, even with no-slip walls and water's viscosity), "
              "so the front is also checked against that reference")
    common.write_summary(out, summary)
    return summary


def main(argv=None):
    return _pcmm.main(CASE, run, __doc__, argv)


if __name__ == "__main__":
    raise SystemExit(main())
