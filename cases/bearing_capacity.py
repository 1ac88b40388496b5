"""Bearing capacity of a smooth rigid strip footing on weightless soil: Prandtl's collapse load.

The collapse of many elements flowing plastically together, checked against limit
analysis: a smooth rigid strip footing of width B = 2b pushed slowly into a
weightless Mohr–Coulomb soil reaches q = N_c·c, with Prandtl's (1920)

    N_c = 2 + π = 5.14 (φ = 0, Tresca),
    N_c = (N_q − 1)·cot φ,  N_q = e^{π tan φ}·tan²(45° + φ/2)  (= 14.83 at φ = 20°),

exact for a rigid–perfectly plastic soil with an associated flow rule. Each model is
run at three resolutions (cells, or particle spacings, under the half-footing) on
the PCMM regular, cross and random packings and on FVM block meshes, so that the
table shows the limit load converging towards N_c.

Set-up (the half of the problem right of the footing's centre line, x ≥ 0)
--------------------------------------------------------------------------
- Soil: ``tdem.MohrCoulomb``, c = 10 kPa, E = 100 MPa, ν = 0.3, ρ = 2000 kg/m³
  (only the inertia of the slow push; no gravity). φ = 0: Tresca with tension
  allowed (T = 1 GPa, so that no cut-off acts: Prandtl's solution has none); φ = 20°:
  dilation ψ = φ (the associated flow Prandtl's N_c assumes) and the apex
  c/tan φ as tension cut-off. E/c = 10⁴ (G/c ≈ 3,800) puts the elastic settlement
  at the limit load near 0.1 % of b, and the curve on its plateau from s ≈ 0.003 b.
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
  footing's travel) up to s = s₀ + 0.01 b. The limit load is the mean q over
  (s − s₀)/b ∈ [0.008, 0.010]; the curve is flat there when q changes by less than 3 %
  of it between (s − s₀)/b = 0.007 and 0.010. s₀ is the surface's relief under the
  footing (the tops of the particles centred on the top edge, highest less lowest): the
  footing carries the soil as a whole only once it has come down onto the lowest of
  them. It is 0 on the lattices and meshes, and on the case's random packing, whose
  discs centred on the sides all have the lattices' radius
  (``tdem.pack.random(edge_radius=)``: Prandtl's soil has a plane surface); with radii
  drawn there too (0.6–1.4 of the lattices') it is about 0.4 h.

Why a stiff soil and a small settlement
---------------------------------------
Prandtl's N_c is a small-displacement result: a rigid–plastic soil whose geometry
does not change while it flows. tdem's continuum is updated-Lagrangian (the
elements' strains and forces on their current geometry, Jaumann-rotated stresses),
so a footing that travels far heaves the soil beside it and shears the elements at
its corner by several of their own sizes, and the load rises with the settlement, as
large-deformation analyses of this footing show. The read-out must therefore stay
where the plastic settlement is small against b and against h at the finest
resolution. At E/c = 1000 and s = 0.08–0.10 b, as this case first ran, the load
rose with the settlement (measured on the crossed FVM mesh, E/c = 1000, pushed to
s = 0.2 b at b/h = 10 and 0.4 b at b/h = 5: q/c = 5.20, 5.32, 5.41, 5.63, 5.96 at
s = 0.04, 0.08, 0.10, 0.15, 0.20 b at b/h = 10; the same rise of about 0.2 q/c
between 0.02 b and 0.08 b at b/h = 5, 10 and 20, and a jump at b/h = 20 from 5.40 at
0.08 b to 5.82 at 0.10 b, where the corner elements are sheared by two of their
sizes), and the limit loads read 3–12 % above 2 + π and rose with the resolution.
With E/c = 10⁴ the plateau starts ten times sooner and is read over a settlement ten
times smaller (s/h ≤ 0.2 at b/h = 20). E and the window were chosen from that
argument; docs/pcmm.md has the table at both.

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
- ``<model>.converging``: the limit loads of the two finest resolutions differ by
  less than 2 % (the note says from which side they approach 2 + π: a discretisation
  that relaxes dynamically to its limit load, with the mixed discretization and the
  loaded width uncertain by part of a spacing, is not bound to approach it from
  above);
- ``<model>.<n>.flat``: the curve's rise between (s − s₀)/b = 0.007 and 0.010 below 3 %;
  on PCMM soil the note also counts the elements created or deleted over that range
  and the largest load steps between samples with and without such a change;
- ``phi20.<model>.limit``: N_c = 14.83 within 10 %.

Random packings: the load moves in steps where the element network changes
--------------------------------------------------------------------------------
On a random packing the load–settlement curve is jagged where the lattices' are
smooth, and its seeds spread (sd 0.17 q/c at b/h = 20 over seeds 0-2). The steps come
where PCMM elements are created or deleted as the packing flows (Eqs. 1-3): measured at
b/h = 10 over seeds 0-4 on the plateau ((s − s₀)/b ≥ 0.003, 29 sample intervals each),
11 of the 15 load steps above 2 % of q come in an interval where elements changed,
though only 41 of the 145 intervals have a change; the largest steps with a change are
3.0–7.3 %, without one 1.4–2.7 %. Seed 1 (22 changes over 0.007–0.010 b, a step of
7.3 %) rises 11 % there (tests/test_bearing_capacity.py), while its mean over the
window reads 5.13. The checks' notes give these counts for every run, and the
``converging`` note the standard error of the change between the two finest means
and the seeds a 2 % change would need to be resolved. Over eleven seeds (0–10) at
b/h = 10 and 20 the mean rises by 2.8 ± 1.2 % (5.118 ± 0.036 to 5.266 ± 0.054,
standard errors), 2.4 % above 2 + π at 20: the random packing does not converge
within 2 % there, and at b/h = 20 its seeds' loads rank with their element changes
over the window (Spearman's ρ = 0.72, p = 0.013), 2.5 times as many as at b/h = 10
(docs/pcmm.md).

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
COHESION, YOUNG, POISSON, RHO = 10e3, 100e6, 0.3, 2000.0
SPEED = 0.01
S_END = 0.010                 # settlement / b at the end of a run
WINDOW = (0.008, 0.010)       # the limit load: mean q over this range of s/b
FLAT_FROM = 0.007             # flat: q(0.010) − q(0.007) below FLAT_TOL of q
FLAT_TOL, LIMIT_TOL, PHI20_TOL, CONVERGED_TOL = 0.03, 0.05, 0.10, 0.02
SAMPLES = 40                  # points of the load–settlement curve

PRESETS = {
    "quick": {"models": ("fvm", "regular"), "resolutions": (4, 6, 8),
              "phi20": (("regular", 6),)},
    "paper": {"models": ("fvm", "fvm_cross", "regular", "cross", "random"),
              "resolutions": (5, 10, 20), "phi20": (("fvm", 10), ("regular", 10))},
}


LABELS_KINDS = ("fvm", "fvm_cross", "regular", "cross", "random")


def _window():
    return f"{WINDOW[0]:g}–{WINDOW[1]:g}"


def prandtl(phi_deg):
    """Prandtl's N_c for the friction angle φ (degrees): 2 + π at φ = 0,
    (N_q − 1)·cot φ with N_q = e^{π tan φ}·tan²(45° + φ/2) above."""
    if phi_deg == 0:
        return 2.0 + math.pi
    t = math.tan(math.radians(phi_deg))
    nq = math.exp(math.pi * t) * math.tan(math.radians(45.0 + 0.5 * phi_deg)) ** 2
    return (nq - 1.0) / t


def soil(phi_deg, young=YOUNG):
    """The soil's material (module docstring)."""
    if phi_deg == 0:
        return tdem.MohrCoulomb(density=RHO, young=young, poisson=POISSON, cohesion=COHESION,
                                friction_angle=0.0, tensile_strength=1e9)
    return tdem.MohrCoulomb(density=RHO, young=young, poisson=POISSON, cohesion=COHESION,
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
        # with the holes of the element cover filled, as the other PCMM cases; the
        # discs centred on the sides of the lattices' radius, so that the surface is
        # flush (Prandtl's soil has a plane surface)
        return {"kind": "random", "rmin": 0.3 * h, "rmax": 0.7 * h, "tolerance": 0.5 * h,
                "fraction": 0.86, "overlap_tol": 0.7, "fill_holes": True,
                "edge_centres": True, "edge_radius": 0.5 * h, "seed": int(seed)}
    raise ValueError(f"kind {kind!r}: choose fvm, fvm_cross, regular, cross or random")


def footing(kind, n, phi_deg=0.0, speed=SPEED, s_end=S_END, sim_kwargs=None, mixed=True,
            progress=False, seed=0, young=None):
    """Build and run one footing; returns a dict with the model, the load–settlement
    curve (``s_over_b``, ``q_over_c``), the limit load and the flatness.
    ``mixed=False`` runs the elements' plain update (for comparison); ``seed``: the
    random packing's; ``young``: the soil's E (default ``YOUNG``; the footing's
    springs and the side walls follow it); ``s_end``: the settlement / b at the end,
    the read-out window and the flatness scaled with it."""
    young = YOUNG if young is None else float(young)
    W, H = domain(phi_deg)
    kw = dict(gravity=(0.0, 0.0), local_damping=0.7, progress=progress,
              mixed_discretization=mixed)
    kw.update(sim_kwargs or {})
    name = f"{kind}" if kind != "fvm_cross" else "fvm_cross"
    m = _pcmm.Model(name, spec(kind, n, W, H, seed), W, H, soil(phi_deg, young), kw)
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
        side = tdem.LinearContact(kn=young, ks=0.0, friction=0.0)
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
        # 2R moves the footing by 0.1 % of b at the limit load
        r = m.r
        top = float((x[:, 1] + r).max())
        surf = np.sort(x[x[:, 1] + r > top - 0.5 * float(r.max()), 0])
    below = surf[surf <= B_HALF + tol]
    above = surf[surf > B_HALF + tol]
    b = 0.5 * (below.max() + above.min())
    seat = 0.0
    if not m.is_fvm:
        # the surface's relief under the footing: the particles centred on the top
        # edge have tops as uneven as their radii (a random packing with radii drawn
        # on its sides: 0.4 h), and the footing carries the whole soil only once it
        # has come down onto the lowest of them; the settlement is read from there
        # (lattices and the case's flush random packing: 0)
        edge = x[:, 1] > x[:, 1].max() - tol
        under = edge & (x[:, 0] <= b)
        seat = float(top - (x[under, 1] + r[under]).min())
    if not m.is_fvm:
        fv = np.array([[-2.0 * h, top], [b, top], [b, top + 0.4 * B_HALF],
                       [-2.0 * h, top + 0.4 * B_HALF]])
        tool = sim.add_block(fv, np.array([[0, 1, 2], [0, 2, 3]]),
                             tdem.Elastic(density=RHO, young=young, poisson=0.2), rigid=True)
        tool.fix(np.arange(4), vx=0.0, vy=-speed)
        sim.couple(m.group, tool, tdem.PointEdge(friction_angle=0.0))
    t_end = (s_end * b + seat) / speed
    # SAMPLES points over s_end·b, as many again over the seating
    samples = max(SAMPLES, int(round(SAMPLES * (1.0 + seat / (s_end * b)))))
    times = np.linspace(0.0, t_end, samples + 1)[1:]
    s_b, q_c = [0.0], [0.0]
    tris = None
    changes = [(0, 0)]            # PCMM elements created, deleted since the last sample
    watch = time.perf_counter()
    for t in times:
        sim.run(until=t)
        if not m.is_fvm:
            now = _triangles(sim)
            changes.append((0, 0) if tris is None else (len(now - tris), len(tris - now)))
            tris = now
        else:
            changes.append((0, 0))
        if m.is_fvm:
            nd = m.block.nodes()
            disp, react = nd["displacement"][driven], nd["reaction"][driven]
        else:
            nd = tool.nodes()
            disp, react = nd["displacement"], nd["reaction"]
        s_b.append(float(-disp[:, 1].mean()) / b)
        q_c.append(float(-react[:, 1].sum()) / b / COHESION)
    s_b, q_c = np.array(s_b), np.array(q_c)
    s0 = seat / b            # the window and the flatness counted from the seating
    sel = ((s_b >= s0 + WINDOW[0] * s_end / S_END)
           & (s_b <= s0 + WINDOW[1] * s_end / S_END + 1e-9))
    if not sel.any():
        raise RuntimeError(f"footing {kind} n = {n}: no sample in the read-out window")
    limit = float(q_c[sel].mean())
    q07 = float(np.interp(s0 + FLAT_FROM * s_end / S_END, s_b, q_c))
    rise = (q_c[-1] - q07) / q_c[-1]
    changes = np.array(changes, dtype=np.int64)
    late = s_b >= s0 + FLAT_FROM * s_end / S_END - 1e-12     # the flatness's range
    steps = np.abs(np.diff(q_c))[late[1:]] / max(abs(q_c[-1]), 1e-30)
    moved = changes[1:][late[1:]].sum(axis=1) > 0
    return {"model": m, "tool": tool, "b": b, "h": h, "n": n, "kind": kind, "phi": phi_deg,
            "seat_over_b": s0,
            "s_over_b": s_b, "q_over_c": q_c, "limit": limit, "rise": float(rise),
            "steps": sim.steps, "dt": sim.dt, "run_s": time.perf_counter() - watch,
            "count": m.count, "element_changes": changes,
            # over the flatness's range: how often the element network changed, and
            # the largest load step between samples with and without a change
            "late_changes": int(changes[1:][late[1:]].sum()),
            "late_step_changed": float(steps[moved].max()) if moved.any() else 0.0,
            "late_step_still": float(steps[~moved].max()) if (~moved).any() else 0.0}


def _events(group):
    """Words for a flatness note: where the PCMM element network changed over the
    flatness's range (s − s₀)/b ≥ FLAT_FROM, and the largest load steps between two
    samples with and without a change (runs of one resolution, one per seed)."""
    if all(r["model"].is_fvm for r in group):
        return ""
    parts = []
    for r in group:
        who = f"seed {r['seed']}: " if len(group) > 1 else ""
        if r["late_changes"]:
            parts.append(f"{who}{r['late_changes']} element changes, the load stepping by "
                         f"up to {100 * r['late_step_changed']:.1f} % between the samples "
                         f"where they happen, {100 * r['late_step_still']:.1f} % between "
                         "the others")
        else:
            parts.append(f"{who}no element changes, the load stepping by up to "
                         f"{100 * r['late_step_still']:.1f} %")
    return ("; over (s − s₀)/b ≥ " + f"{FLAT_FROM:g} (elements created or deleted "
            "between two samples): " + "; ".join(parts))


def _resolution(mine):
    """Words for a converging note over several seeds: the standard error of the
    change between the two finest means, and the seeds a change of CONVERGED_TOL
    would need to be resolved at two standard errors."""
    a, b = mine[-2], mine[-1]
    if a["count"] < 2 or b["count"] < 2 or a["sd"] is None or b["sd"] is None:
        return ""
    se = math.hypot(a["sd"] / math.sqrt(a["count"]), b["sd"] / math.sqrt(b["count"]))
    se_rel = se / b["limit"]
    var1 = (a["sd"] ** 2 + b["sd"] ** 2) / b["limit"] ** 2     # the variance of one pair
    need = math.ceil(var1 * (2.0 / CONVERGED_TOL) ** 2)
    return (f"; over {a['count']} and {b['count']} seeds its standard error is "
            f"{100 * se_rel:.1f} % (sd {a['sd']:.3f} and {b['sd']:.3f}): a change of "
            f"{100 * CONVERGED_TOL:g} % is resolved at two standard errors with about "
            f"{need} seeds at each")


def _triangles(sim):
    """The PCMM elements now, as a set of sorted particle triples."""
    tri = np.sort(sim._cont.elements()["triangles"], axis=1)
    return set(map(tuple, tri.tolist()))


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
                         "count": len(lims), "events": _events(group)})
        finest = mine[-1]["n"]
        for r in mine:
            label = f"{_pcmm.LABELS.get(kind, kind)}, {r['n']} per half-width"
            over = (f" (mean of {r['count']} seeds, sd {r['sd']:.3f})" if r["count"] > 1
                    else "")
            tol = common.rel(LIMIT_TOL) if r["n"] == finest else None
            checks.append(common.check(f"{kind}.{r['n']}.limit", r["limit"], nc0, tol, "q/c",
                                       f"{label}: mean q/c over s/b {_window()}{over}; "
                                       "target 2 + π"))
            checks.append(common.check(f"{kind}.{r['n']}.flat", r["rise"], None,
                                       common.between(min=-FLAT_TOL, max=FLAT_TOL), "",
                                       f"{label}: (q({S_END:g} b) − q({FLAT_FROM:g} b))/q"
                                       f"{over}, within ±3 %{r['events']}"))
        lims = [r["limit"] for r in mine]
        change = (lims[-1] - lims[-2]) / lims[-1] if len(lims) > 1 else float("nan")
        side = ("above" if all(v >= nc0 for v in lims) else
                "below" if all(v <= nc0 for v in lims) else "on both sides of")
        checks.append(common.check(f"{kind}.converging", change, None,
                                   common.between(min=-CONVERGED_TOL, max=CONVERGED_TOL), "",
                                   f"{_pcmm.LABELS.get(kind, kind)}: limit loads "
                                   f"{', '.join(f'{v:.3f}' for v in lims)} at b/h = "
                                   f"{', '.join(str(r['n']) for r in mine)} ({side} "
                                   f"2 + π); the change between the two finest, within "
                                   f"±{100 * CONVERGED_TOL:g} %{_resolution(mine)}"))
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
                                   f"φ = ψ = 20°: mean q/c over s/b {_window()}; target "
                                   "(N_q − 1) cot φ"))
    for r in runs:
        key = f"phi{int(r['phi'])}.{r['kind']}.{r['n']}" + (
            f".seed{r['seed']}" if r["kind"] == "random" and len(seeds) > 1 else "")
        data["runs"][key] = {"limit": r["limit"], "rise": r["rise"], "b": r["b"], "h": r["h"],
                             "seat_over_b": r["seat_over_b"],
                             "late_element_changes": r["late_changes"],
                             "late_step_with_change": r["late_step_changed"],
                             "late_step_without_change": r["late_step_still"],
                             "steps": r["steps"], "dt": r["dt"], "run_s": r["run_s"],
                             "count": r["count"]}
        hist[key] = {"s_over_b": r["s_over_b"], "q_over_c": r["q_over_c"],
                     "elements_created": r["element_changes"][:, 0],
                     "elements_deleted": r["element_changes"][:, 1]}
    return _pcmm.finish(CASE, preset, checks, data, out, hist,
                        lambda: plots(runs, out, nc0, nc20), watch, threads=threads,
                        paper="Prandtl (1920); limit analysis of a smooth strip footing")


def plot_curves(runs, out, nc0, nc20):
    """``load_settlement.png``: q/c against the settlement past the seating, (s − s₀)/b:
    the lattices and meshes, the random packings (every seed) and φ = 20°. ``runs``
    need ``kind``, ``n``, ``phi``, ``s_over_b``, ``q_over_c``, ``seat_over_b``."""
    plt = common.pyplot()
    panels = [("φ = 0°: lattices and meshes", 0.0, nc0, lambda r: r["kind"] != "random"),
              ("φ = 0°: random packings, every seed", 0.0, nc0,
               lambda r: r["kind"] == "random"),
              ("φ = ψ = 20°", 20.0, nc20, lambda r: True)]
    panels = [p for p in panels if any(r["phi"] == p[1] and p[3](r) for r in runs)]
    if not panels:
        return
    fig, axes = plt.subplots(1, len(panels), figsize=(5.2 * len(panels), 4.6),
                             squeeze=False)
    s_end = max(float(r["s_over_b"][-1] - r.get("seat_over_b", 0.0)) for r in runs)
    for ax, (title, phi, nc, keep) in zip(axes[0], panels):
        mine = [r for r in runs if r["phi"] == phi and keep(r)]
        seen = set()
        for r in mine:
            ns = sorted({q["n"] for q in mine if q["kind"] == r["kind"]})
            alpha = 0.35 + 0.65 * (ns.index(r["n"]) + 1) / len(ns)
            label = f"{_pcmm.LABELS.get(r['kind'], r['kind'])}, b/h = {r['n']}"
            ax.plot(np.asarray(r["s_over_b"]) - r.get("seat_over_b", 0.0), r["q_over_c"],
                    color=_pcmm.COLORS.get(r["kind"], "k"), alpha=alpha, lw=1.2,
                    label=None if label in seen else label)
            seen.add(label)
        ax.axhline(nc, color="k", ls="--", lw=1, label=f"Prandtl N_c = {nc:.2f}")
        ax.axvspan(WINDOW[0] * s_end / S_END, WINDOW[1] * s_end / S_END, color="0.9",
                   label="read-out window")
        ax.set_xlim(-0.25 * s_end, 1.05 * s_end)
        ax.set_ylim(0.0, 1.3 * nc)
        ax.set_xlabel("settlement past the seating (s − s₀) / b")
        ax.set_ylabel("q / c")
        ax.set_title(title, fontsize=10)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=6, loc="lower right", ncol=2 if len(seen) > 6 else 1,
                  framealpha=0.85)
    fig.suptitle("Smooth strip footing on weightless soil: load–settlement (s₀: the "
                 "surface's relief under the footing, 0 on lattices and meshes)",
                 fontsize=10)
    fig.tight_layout()
    common.save(fig, out / "load_settlement.png")


def plots(runs, out, nc0, nc20):
    plt = common.pyplot()
    plot_curves(runs, out, nc0, nc20)
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
    fig.suptitle(f"Displacement at s = {S_END:g} b: the soil moving with the footing (Prandtl's "
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
