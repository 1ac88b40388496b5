"""Bearing capacity of a smooth rigid strip footing on weightless soil: Prandtl's collapse load.

The collapse of many elements flowing plastically together, checked against limit
analysis: a smooth rigid strip footing of width B = 2b pushed slowly into a
weightless Mohr–Coulomb soil reaches q = N_c·c, with Prandtl's (1920)

    N_c = 2 + π = 5.14 (φ = 0, Tresca),
    N_c = (N_q − 1)·cot φ,  N_q = e^{π tan φ}·tan²(45° + φ/2)  (= 14.83 at φ = 20°),

exact for a rigid–perfectly plastic soil with an associated flow rule. Each model is
run at three resolutions (cells, or particle spacings, under the half-footing) on
the PCMM regular, cross and random packings and on FVM block meshes, so that the
table shows the limit load converging towards N_c from above.

Set-up (the half of the problem right of the footing's centre line, x ≥ 0)
--------------------------------------------------------------------------
- Soil: ``tdem.MohrCoulomb``, c = 10 kPa, E = 10 MPa, ν = 0.3, ρ = 2000 kg/m³ (only
  the inertia of the slow push; no gravity). φ = 0: Tresca with tension allowed
  (T = 1 GPa, so that no cut-off acts: Prandtl's solution has none); φ = 20°:
  dilation ψ = φ (the associated flow Prandtl's N_c assumes) and the apex
  c/tan φ as tension cut-off. E/c = 1000 puts the elastic settlement at the limit
  load near 1 % of b: the curve reaches its plateau well inside the run.
- Domain: b = 0.5 m; φ = 0: 4b × 2b (Prandtl's mechanism reaches 3b from the
  centre line and b·sqrt(2) deep); φ = 20°: 8b × 3b (its log spiral reaches about
  6b). Bottom fixed; the centre line x = 0 (symmetry) and the far side on vertical
  rollers (vx = 0); for particles also frictionless walls there, which hold the
  rows that start half a spacing from a side (hexagonal lattice, random packing).
- Footing, pushed down at v = 0.01 m/s (v/c_p ≈ 1e-4: quasi-static): on PCMM
  soil a rigid block (every node driven: a kinematic tool) whose bottom edge spans
  x = −2h to b, touching the soil's surface, coupled to the particles by
  point–edge contacts without friction (``tdem.PointEdge(friction_angle=0)``),
  its edge x = b half-way between two surface particles, so that the particles
  under it have tributary widths adding up to b; on an FVM mesh the surface nodes
  at x ≤ b/(1 + 1/2n) driven down, their horizontal motion free, and b half-way to
  the next node (vertex–edge springs stiff enough to hold the mesh's surface
  vertices would cut the step tenfold, and the vertices beside the block's corner
  slipped off its edge, taking load away).
- Local damping 0.7 (quasi-static; the unbalanced forces of a steady push are small).
- Read-out: q = (vertical force on the footing)/b against the settlement s (the
  footing's travel) up to s = 0.1 b. The limit load is the mean q over
  s/b ∈ [0.08, 0.10]; the curve is flat there when q changes by less than 3 % of it
  between s/b = 0.07 and 0.10.

Discretisation
--------------
Constant-strain triangles lock in isochoric flow: every element must keep its area
while it flows plastically at constant volume, which a mesh of triangles cannot do
(it has about one volumetric constraint per degree of freedom), and the PCMM
element system, which superposes both diagonals of each square, has two. tdem's
elements therefore use the nodal mixed discretization (docs/pcmm.md): the volumetric
strain increment of each element is the mean over its three nodes (particles) of
their area-weighted averages, and the mean stress of its nodal forces likewise,
so that there is one volumetric constraint per node. The table in docs/pcmm.md
compares it with the plain element update.

Checks
------
- ``<model>.<n>.limit`` (φ = 0): N_c = 2 + π within 5 % at the finest resolution of
  each model, reported at the coarser ones;
- ``<model>.converging``: the limit loads fall (or stay within 1 %) from the
  coarsest to the finest resolution and stay above 0.97 N_c;
- ``<model>.<n>.flat``: the curve's rise between s/b = 0.07 and 0.10 below 3 %;
- ``phi20.<model>.limit``: N_c = 14.83 within 10 %.

Presets: ``quick``: resolutions 4, 6 and 8 (cells or spacings under the
half-footing) for FVM regular and PCMM regular, and φ = 20° on the PCMM regular
lattice at 6; ``paper``: 5, 10 and 20 for every model (FVM regular and cross, PCMM
regular, cross and random) and φ = 20° on FVM and PCMM regular at 10.

Outputs (``--out DIR``, default out/bearing_capacity): ``load_settlement.png``
(q/c against s/b, every model and resolution, with N_c), ``convergence.png``
(limit load against resolution), ``mechanism.png`` (the displacement of the
finest run of each model, over the settlement), ``histories.h5``, ``summary.json``.
"""
import math
import time

import numpy as np

import tdem

from . import _common as common
from . import _pcmm

CASE = "bearing_capacity"
B_HALF = 0.5
COHESION, YOUNG, POISSON, RHO = 10e3, 10e6, 0.3, 2000.0
SPEED = 0.01
S_END = 0.10                  # settlement / b at the end of a run
WINDOW = (0.08, 0.10)         # the limit load: mean q over this range of s/b
FLAT_FROM = 0.07              # flat: q(0.10) − q(0.07) below FLAT_TOL of q
FLAT_TOL, LIMIT_TOL, PHI20_TOL, FLOOR = 0.03, 0.05, 0.10, 0.97
SAMPLES = 40                  # points of the load–settlement curve

PRESETS = {
    "quick": {"models": ("fvm", "regular"), "resolutions": (4, 6, 8),
              "phi20": (("regular", 6),)},
    "paper": {"models": ("fvm", "fvm_cross", "regular", "cross", "random"),
              "resolutions": (5, 10, 20), "phi20": (("fvm", 10), ("regular", 10))},
}


LABELS_KINDS = ("fvm", "fvm_cross", "regular", "cross", "random")


def prandtl(phi_deg):
    """Prandtl's N_c for the friction angle φ (degrees): 2 + π at φ = 0,
    (N_q − 1)·cot φ with N_q = e^{π tan φ}·tan²(45° + φ/2) above."""
    if phi_deg == 0:
        return 2.0 + math.pi
    t = math.tan(math.radians(phi_deg))
    nq = math.exp(math.pi * t) * math.tan(math.radians(45.0 + 0.5 * phi_deg)) ** 2
    return (nq - 1.0) / t


def soil(phi_deg):
    """The soil's material (module docstring)."""
    if phi_deg == 0:
        return tdem.MohrCoulomb(density=RHO, young=YOUNG, poisson=POISSON, cohesion=COHESION,
                                friction_angle=0.0, tensile_strength=1e9)
    return tdem.MohrCoulomb(density=RHO, young=YOUNG, poisson=POISSON, cohesion=COHESION,
                            friction_angle=phi_deg, dilation_angle=phi_deg)


def domain(phi_deg):
    """(W, H) of the half-model."""
    return (4.0 * B_HALF, 2.0 * B_HALF) if phi_deg == 0 else (8.0 * B_HALF, 3.0 * B_HALF)


def spec(kind, n, W, H, seed=0):
    """The model spec (cases._pcmm) of ``kind`` with n cells or spacings under the
    half-footing (h = b/n); ``seed``: the random packing's."""
    h = B_HALF / n
    if kind in ("fvm", "fvm_cross"):
        return {"kind": "fvm", "cells": (int(round(W / h)), int(round(H / h))),
                "pattern": "cross" if kind == "fvm_cross" else "regular"}
    if kind == "regular":
        return {"kind": "regular", "radius": 0.5 * h, "tolerance": 0.5 * h, "inset": 0}
    if kind == "cross":
        return {"kind": "cross", "radius": 0.5 * h, "tolerance": 0.5 * h, "inset": 0,
                "fit": True}
    if kind == "random":
        # radii 0.6–1.4 of the lattices' (the same mean spacing), denser than jamming
        # with the holes of the element cover filled, as the other PCMM cases
        return {"kind": "random", "rmin": 0.3 * h, "rmax": 0.7 * h, "tolerance": 0.5 * h,
                "fraction": 0.86, "overlap_tol": 0.7, "fill_holes": True,
                "edge_centres": True, "seed": int(seed)}
    raise ValueError(f"kind {kind!r}: choose fvm, fvm_cross, regular, cross or random")


def footing(kind, n, phi_deg=0.0, speed=SPEED, s_end=S_END, sim_kwargs=None, mixed=True,
            progress=False, seed=0):
    """Build and run one footing; returns a dict with the model, the load–settlement
    curve (``s_over_b``, ``q_over_c``), the limit load and the flatness.
    ``mixed=False`` runs the elements' plain update (for comparison); ``seed``: the
    random packing's."""
    W, H = domain(phi_deg)
    kw = dict(gravity=(0.0, 0.0), local_damping=0.7, progress=progress,
              mixed_discretization=mixed)
    kw.update(sim_kwargs or {})
    name = f"{kind}" if kind != "fvm_cross" else "fvm_cross"
    m = _pcmm.Model(name, spec(kind, n, W, H, seed), W, H, soil(phi_deg), kw)
    sim = m.sim
    x = m.x0
    tol = 1e-6 * W
    bottom = np.flatnonzero(x[:, 1] < x[:, 1].min() + tol)
    if m.is_fvm:
        left = np.flatnonzero(x[:, 0] < tol)
        right = np.flatnonzero(x[:, 0] > W - tol)
    else:
        left, right = m.edge("left"), m.edge("right")
    m.fix(bottom, vx=0.0, vy=0.0)
    m.fix(np.setdiff1d(left, bottom), vx=0.0, vy=None)
    m.fix(np.setdiff1d(right, bottom), vx=0.0, vy=None)
    if not m.is_fvm:
        # the centre line and the far side also as frictionless walls, a hair outside
        # (so that a particle centred on a side has a normal): the rows of a hexagonal
        # lattice (the inner discs of a random packing) that start half a spacing from
        # a side are held by them, not only the particles reaching it
        side = tdem.LinearContact(kn=YOUNG, ks=0.0, friction=0.0)
        eps = 1e-3 * float(m.r.min())
        sim.add_wall((-eps, 2.0 * H), (-eps, -H), contact=side)
        sim.add_wall((W + eps, -H), (W + eps, 2.0 * H), contact=side)
    h = B_HALF / n
    if m.is_fvm:
        # the rigid smooth footing is the surface nodes under it, driven down with
        # their horizontal motion free (the vertex–edge springs of a footing block
        # would limit the step tenfold, and surface vertices beside its corner slip
        # off its edge); its width runs to half-way to the next node, as below
        top = x[:, 1].max()
        driven = np.flatnonzero((x[:, 1] > top - tol) & (x[:, 0] <= B_HALF + tol))
        surf = np.sort(x[x[:, 1] > top - tol, 0])
        m.block.fix(driven, vx=None, vy=-speed)
        tool = None
    else:
        # a rigid block touching the surface, its edge half-way between two surface
        # particles, coupled by frictionless point–edge contacts; the springs take
        # the stiffer side's E (tdem.PointEdge), here the soil's: a spring of E over
        # 2R moves the footing by 1 % of b at the limit load
        r = m.r
        top = float((x[:, 1] + r).max())
        surf = np.sort(x[x[:, 1] + r > top - 0.5 * float(r.max()), 0])
    below = surf[surf <= B_HALF + tol]
    above = surf[surf > B_HALF + tol]
    b = 0.5 * (below.max() + above.min())
    if not m.is_fvm:
        fv = np.array([[-2.0 * h, top], [b, top], [b, top + 0.4 * B_HALF],
                       [-2.0 * h, top + 0.4 * B_HALF]])
        tool = sim.add_block(fv, np.array([[0, 1, 2], [0, 2, 3]]),
                             tdem.Elastic(density=RHO, young=YOUNG, poisson=0.2), rigid=True)
        tool.fix(np.arange(4), vx=0.0, vy=-speed)
        sim.couple(m.group, tool, tdem.PointEdge(friction_angle=0.0))
    t_end = s_end * b / speed
    times = np.linspace(0.0, t_end, SAMPLES + 1)[1:]
    s_b, q_c = [0.0], [0.0]
    watch = time.perf_counter()
    for t in times:
        sim.run(until=t)
        if m.is_fvm:
            nd = m.block.nodes()
            disp, react = nd["displacement"][driven], nd["reaction"][driven]
        else:
            nd = tool.nodes()
            disp, react = nd["displacement"], nd["reaction"]
        s_b.append(float(-disp[:, 1].mean()) / b)
        q_c.append(float(-react[:, 1].sum()) / b / COHESION)
    s_b, q_c = np.array(s_b), np.array(q_c)
    sel = (s_b >= WINDOW[0] * s_end / S_END) & (s_b <= WINDOW[1] * s_end / S_END + 1e-9)
    limit = float(q_c[sel].mean())
    q07 = float(np.interp(FLAT_FROM * s_end / S_END, s_b, q_c))
    rise = (q_c[-1] - q07) / q_c[-1]
    return {"model": m, "tool": tool, "b": b, "h": h, "n": n, "kind": kind, "phi": phi_deg,
            "s_over_b": s_b, "q_over_c": q_c, "limit": limit, "rise": float(rise),
            "steps": sim.steps, "dt": sim.dt, "run_s": time.perf_counter() - watch,
            "count": m.count}


def run(preset="quick", out=None, models=None, arch=None, threads=None, seeds=(0,)):
    """Run the case; returns the summary dict (also written to out/summary.json).
    ``seeds``: the random packing is run once per seed at each resolution, and its
    limit load is the mean over them (the spread beside it)."""
    p = PRESETS[preset]
    kinds = list(p["models"] if models is None else models)
    bad = [k for k in kinds if k not in LABELS_KINDS]
    if bad:
        raise tdem.InputError(f"models: unknown {bad}; choose from {list(LABELS_KINDS)}")
    seeds = list(seeds)
    if (not seeds or len(set(seeds)) != len(seeds)
            or not all(isinstance(x, int) and not isinstance(x, bool) for x in seeds)):
        raise tdem.InputError(f"seeds must be distinct integers, got {seeds!r}")
    out = common.output_dir(CASE, out)
    watch = common.Stopwatch()
    sk = dict(arch=arch, threads=threads)
    nc0, nc20 = prandtl(0.0), prandtl(20.0)
    runs, checks, data, hist = [], [], {"N_c": {"0": nc0, "20": nc20}, "runs": {},
                                        "seeds": seeds}, {}
    for kind in kinds:
        mine = []
        for n in p["resolutions"]:
            group = []
            for seed in (seeds if kind == "random" else (0,)):
                r = footing(kind, n, 0.0, sim_kwargs=sk, seed=seed)
                r["seed"] = seed
                group.append(r)
                runs.append(r)
                print(f"  {kind} n = {n}" + (f", seed {seed}" if kind == "random" else "")
                      + f": q/c = {r['limit']:.3f} (N_c {nc0:.3f}), rise "
                      f"{100 * r['rise']:.1f} %, {r['steps']} steps, {r['run_s']:.0f} s",
                      flush=True)
            lims = np.array([r["limit"] for r in group])
            rises = np.array([r["rise"] for r in group])
            mine.append({"n": n, "limit": float(lims.mean()), "rise": float(rises.mean()),
                         "sd": float(lims.std(ddof=1)) if len(lims) > 1 else None,
                         "count": len(lims)})
        finest = mine[-1]["n"]
        for r in mine:
            label = f"{_pcmm.LABELS.get(kind, kind)}, {r['n']} per half-width"
            over = (f" (mean of {r['count']} seeds, sd {r['sd']:.3f})" if r["count"] > 1
                    else "")
            tol = common.rel(LIMIT_TOL) if r["n"] == finest else None
            checks.append(common.check(f"{kind}.{r['n']}.limit", r["limit"], nc0, tol, "q/c",
                                       f"{label}: mean q/c over s/b 0.08–0.10{over}; "
                                       "target 2 + π"))
            checks.append(common.check(f"{kind}.{r['n']}.flat", r["rise"], None,
                                       common.between(min=-FLAT_TOL, max=FLAT_TOL), "",
                                       f"{label}: (q(0.10 b) − q(0.07 b))/q{over}, within "
                                       "±3 %"))
        lims = [r["limit"] for r in mine]
        falls = all(lims[k + 1] <= lims[k] * 1.01 for k in range(len(lims) - 1))
        conv = float(falls and min(lims) >= FLOOR * nc0)
        checks.append(common.check(f"{kind}.converging", conv, 1.0, common.EQUAL, "",
                                   f"{_pcmm.LABELS.get(kind, kind)}: limit loads "
                                   f"{', '.join(f'{v:.3f}' for v in lims)} fall with the "
                                   f"resolution (1 % slack) and stay above {FLOOR} N_c"))
        if kind == "random" and len(seeds) > 1:
            data["random_seeds"] = {str(r["n"]): {"mean": r["limit"], "sd": r["sd"]}
                                    for r in mine}
    for kind, n in p["phi20"]:
        if kind not in kinds:
            continue
        r = footing(kind, n, 20.0, sim_kwargs=sk)
        runs.append(r)
        print(f"  phi = 20, {kind} n = {n}: q/c = {r['limit']:.3f} (N_c {nc20:.3f})", flush=True)
        checks.append(common.check(f"phi20.{kind}.limit", r["limit"], nc20,
                                   common.rel(PHI20_TOL), "q/c",
                                   f"{_pcmm.LABELS.get(kind, kind)}, {n} per half-width, "
                                   "φ = ψ = 20°: mean q/c over s/b 0.08–0.10; target "
                                   "(N_q − 1) cot φ"))
    for r in runs:
        key = f"phi{int(r['phi'])}.{r['kind']}.{r['n']}" + (
            f".seed{r['seed']}" if r["kind"] == "random" and len(seeds) > 1 else "")
        data["runs"][key] = {"limit": r["limit"], "rise": r["rise"], "b": r["b"], "h": r["h"],
                             "steps": r["steps"], "dt": r["dt"], "run_s": r["run_s"],
                             "count": r["count"]}
        hist[key] = {"s_over_b": r["s_over_b"], "q_over_c": r["q_over_c"]}
    return _pcmm.finish(CASE, preset, checks, data, out, hist,
                        lambda: plots(runs, out, nc0, nc20), watch, threads=threads,
                        paper="Prandtl (1920); limit analysis of a smooth strip footing")


def plots(runs, out, nc0, nc20):
    plt = common.pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.5), squeeze=False)
    for ax, phi, nc in ((axes[0, 0], 0.0, nc0), (axes[0, 1], 20.0, nc20)):
        mine = [r for r in runs if r["phi"] == phi]
        for r in mine:
            ns = sorted({q["n"] for q in mine if q["kind"] == r["kind"]})
            alpha = 0.35 + 0.65 * (ns.index(r["n"]) + 1) / len(ns)
            ax.plot(r["s_over_b"], r["q_over_c"], color=_pcmm.COLORS.get(r["kind"], "k"),
                    alpha=alpha, lw=1.2,
                    label=f"{_pcmm.LABELS.get(r['kind'], r['kind'])}, b/h = {r['n']}")
        ax.axhline(nc, color="k", ls="--", lw=1, label=f"Prandtl N_c = {nc:.2f}")
        ax.set_xlabel("settlement s / b")
        ax.set_ylabel("q / c")
        ax.set_title(f"φ = {phi:.0f}°", fontsize=10)
        ax.set_ylim(-0.45 * nc if len(mine) > 6 else 0.0, 1.3 * nc)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=6, loc="lower right", ncol=2 if len(mine) > 6 else 1,
                  framealpha=0.8)
    fig.suptitle("Smooth strip footing on weightless soil: load–settlement", fontsize=10)
    fig.tight_layout()
    common.save(fig, out / "load_settlement.png")

    fig, ax = plt.subplots(figsize=(5.5, 4))
    kinds = []
    for r in runs:
        if r["phi"] == 0 and r["kind"] not in kinds:
            kinds.append(r["kind"])
    for k in kinds:
        mine = [r for r in runs if r["phi"] == 0 and r["kind"] == k]
        ns = sorted({r["n"] for r in mine})
        by_n = [np.array([r["limit"] for r in mine if r["n"] == n]) for n in ns]
        mean = np.array([v.mean() for v in by_n])
        many = max(len(v) for v in by_n) > 1
        ax.errorbar(ns, mean, yerr=[mean - [v.min() for v in by_n],
                                    [v.max() for v in by_n] - mean] if many else None,
                    marker=_pcmm.MARKERS.get(k, "o"), mfc="none", capsize=3,
                    color=_pcmm.COLORS.get(k, "k"),
                    label=_pcmm.LABELS.get(k, k) + (" (mean, range over seeds)" if many
                                                    else ""))
    ax.axhline(nc0, color="k", ls="--", lw=1, label="2 + π")
    ax.axhspan(nc0, nc0 * (1 + LIMIT_TOL), color="0.85", label="within 5 %")
    ax.set_xscale("log")
    ticks = sorted({r["n"] for r in runs if r["phi"] == 0})
    ax.set_xticks(ticks)
    ax.set_xticklabels([str(n) for n in ticks])
    ax.minorticks_off()
    ax.set_xlabel("cells (particle spacings) under the half-footing, b/h")
    ax.set_ylabel("limit load q / c")
    ax.set_title("Tresca soil: limit load against resolution", fontsize=10)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    fig.tight_layout()
    common.save(fig, out / "convergence.png")

    finest = {}
    for r in runs:
        if r["phi"] == 0 and (r["kind"] not in finest or r["n"] > finest[r["kind"]]["n"]):
            finest[r["kind"]] = r
    if not finest:
        return
    fig, axes = plt.subplots(1, len(finest), figsize=(3.6 * len(finest), 2.8), squeeze=False)
    for ax, r in zip(axes[0], finest.values()):
        m = r["model"]
        s_end = r["s_over_b"][-1] * r["b"]
        if m.is_fvm:
            nd = m.block.nodes()
            xy = np.asarray(nd["position"])
            u = np.linalg.norm(np.asarray(nd["displacement"]), axis=1) / s_end
            pc = ax.tripcolor(xy[:, 0], xy[:, 1], np.asarray(m.block.triangles), u,
                              shading="gouraud", cmap="viridis", vmin=0.0, vmax=1.0)
        else:
            p = m.sim.particles.numpy(stress=False)
            xy = np.asarray(p["position"])
            u = np.linalg.norm(np.asarray(p["displacement"]), axis=1) / s_end
            pc = ax.scatter(xy[:, 0], xy[:, 1], c=u, s=2.0, cmap="viridis", vmin=0.0, vmax=1.0)
        ax.axvline(r["b"], color="w", lw=0.8, ls=":")
        ax.set_aspect("equal")
        ax.set_title(f"{_pcmm.LABELS.get(r['kind'], r['kind'])}, b/h = {r['n']}", fontsize=9)
        ax.tick_params(labelsize=7)
    fig.colorbar(pc, ax=list(axes[0]), shrink=0.8, label="|displacement| / settlement")
    fig.suptitle("Displacement at s = 0.1 b: the soil moving with the footing (Prandtl's "
                 "mechanism, φ = 0)", fontsize=10)
    common.save(fig, out / "mechanism.png")


def _extra(p):
    p.add_argument("--models", nargs="+", choices=list(LABELS_KINDS), default=None,
                   help="which models to run (default: the preset's)")
    p.add_argument("--seeds", nargs="+", type=int, default=[0], metavar="SEED",
                   help="the random packing once per seed at each resolution; its limit "
                        "load is the mean over them (default: 0)")


def main(argv=None):
    args, out = common.parse(CASE, argv, description=__doc__.splitlines()[0], extra=_extra)
    s = run(args.preset, out, models=args.models, arch=args.arch, threads=args.threads,
            seeds=args.seeds)
    common.print_checks(s)
    print(f"summary: {out / 'summary.json'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
