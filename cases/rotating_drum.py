"""A drum turned by a function of time: the dynamic angle of repose against the Froude number.

A horizontal drum, part filled with spheres, is spun up by ``tdem.motion.ramp`` to a
constant angular velocity ω and turned until the bed's motion is steady. The regime and
the angle of the bed's free surface are read against the Froude number Fr = ω² R / g
(R the drum's radius): at low Fr the surface is flat and the bed rolls at a dynamic angle
of repose; as Fr rises the surface steepens and curls (cascading), and at Fr above about
1 the bed is carried round with the wall (centrifuging). The regimes and their Froude
ranges are those of Mellmann (2001), "The transverse motion of solids in rotating
cylinders — forms of motion and transition behavior", Powder Technology 118:251–270:
rolling 1e-4 < Fr < 1e-2, cascading 1e-3 < Fr < 1e-1, cataracting 0.1 < Fr < 1,
centrifuging Fr ≥ 1 (for a filling degree and wall friction like these).

Set-up (our choices; the regime map gives no particle properties)
-----------------------------------------------------------------
- The drum: radius R = 0.1 m, a cylinder of 48 flat sides (a mesh), axis z through the
  origin, gravity −y. A slice of it, periodic in z over 4.5 d: the bed is a long drum's
  middle, without the end walls whose friction raises the angle (a drum of
  end walls is another experiment). The mesh spans the period and a diameter more.
- Spheres of d = 6 mm (uniform in 5.4–6.6 mm: ±10 %, so that they do not crystallise
  against the smooth wall), ρ = 2500 kg/m³, ``tdem.LinearContact`` with k_n = 5000 N/m
  (overlap under the bed's weight about 0.1 % of d), k_s = k_n, μ = 0.5 between spheres
  restitution 0.5, rolling resistance δ = 0.1 (Model 1: a little, for spheres that are
  not perfectly round; its sensitivity is open). The wall is rough: μ_w = 1.0 and
  δ_w = 1.0, so that the spheres touching it are carried round instead of rolling on
  it (a liner; with the spheres' own law the bed slips and is not carried even at
  Fr = 4).
- Filling 35 % of the cross-section: the spheres are placed on a jittered lattice
  inside the circle below the fill line and settle for 0.3 s before the spin-up.
- The spin-up: ``tdem.motion.ramp((0, 0, ω), 0.2)``. The bed is turned until it has
  been lifted to its angle and flowed for a while: a run of (1.2 rad)/ω + 0.4 s, at
  least 1.2 s; the angle is read over its last third.

What is measured
----------------
- The angle of the free surface, two ways: (1) the bed's centroid: for a flat surface
  the centroid lies on the perpendicular to the surface through the axis, so the
  surface's angle is the centroid's angle from the downward vertical, atan(x_c / −y_c)
  (exact for a flat surface; a curled surface reads its mean); (2) a straight line
  fitted to the surface: the highest sphere top in bins 1 d wide along the line
  through the centroid's perpendicular, the middle 60 % of the chord. Both averaged
  over the last third of the run (every 0.02 s).
- The bed's co-rotation: its mean angular velocity about the axis, Σ m (x × v)_z / Σ m
  r², over ω — 1 for a bed carried round rigidly (centrifuging or a solid bed below
  its angle), below 1 once the surface flows.

Checks: the angle stays within 3° from Fr = 0.003 to 0.03 (rolling: a constant angle)
and rises by more than that at Fr = 0.1 (cascading); at Fr = 4 the bed centrifuges
(co-rotation at the end above 0.95). The dynamic angle is the slope of the surface's
middle (the usual measure: a rolling surface is S-shaped, steepest in the middle; the
centroid's angle, the chord's mean slope, is reported beside it). At Fr = 1.5 it cataracts (reported): a
bed of 35 % filling needs more than Fr = 1, the bound of one layer at the wall. Published DEM drums of spheres are
compared in docs/cases.md; their particles and walls differ from these, so no
absolute angle is a target here.
"""
import math

import numpy as np

import tdem

from . import _common as common

CASE = "rotating_drum"
PAPER = ("Mellmann (2001), Powder Technology 118:251 — the regimes of a rotating drum "
         "against the Froude number")
R_DRUM = 0.1
D = 0.006
GRADE = (0.9 * D, 1.1 * D)
RHO = 2500.0
KN = 5000.0
MU = 0.5
ROLLING = 0.1
MU_WALL = 1.0
ROLLING_WALL = 1.0
FILL = 0.35
PERIOD = 4.5 * D
SIDES = 48
G = 9.81
SPIN_UP = 0.2
PRESETS = {
    "quick": {"froude": [0.003, 0.03, 0.1, 1.5, 4.0], "period": PERIOD, "seed": 1},
    "paper": {"froude": [0.001, 0.003, 0.01, 0.03, 0.1, 0.3, 1.0, 1.5, 4.0],
              "period": 8 * D, "seed": 1},
}
ROLLING_FR = 1e-2          # Mellmann: rolling below it
PLATEAU_TOL = 3.0          # °: the angle's fluctuation over the reading (std 2–4°)
CENTRIFUGE_FR = 4.0       # well above 1: a thick bed needs more than a wall layer


def law():
    return tdem.LinearContact(kn=KN, ks=KN, friction=MU, restitution=0.5,
                              rolling=tdem.RollingResistance(delta=ROLLING))


def wall_law():
    """A rough wall: friction MU_WALL and rolling resistance ROLLING_WALL, so that the
    spheres touching it are carried round rather than rolling on it (a drum's liner)."""
    return tdem.LinearContact(kn=KN, ks=KN, friction=MU_WALL, restitution=0.5,
                              rolling=tdem.RollingResistance(delta=ROLLING_WALL))


def drum_mesh(period):
    """The drum's cylinder, axis z, spanning the period and a diameter more each side."""
    span = period + 2 * D
    v, t = tdem.surfaces.cylinder((0.0, 0.0, -0.5 * span), R_DRUM, span, segments=SIDES,
                                  bottom=False)
    return v, t


def bed(period, seed):
    """Sphere centres (N, 3) and radii on a jittered lattice inside the drum, below the
    line that leaves FILL of the circle's area under it."""
    rng = np.random.default_rng(seed)
    # the fill line's height h: the segment's area (R² acos(h/R)... below −h) = FILL π R²
    from scipy.optimize import brentq
    r_in = R_DRUM - 0.6 * D           # the wall's facets lie inside the circle
    seg = lambda h: (r_in ** 2 * math.acos(h / r_in) - h * math.sqrt(r_in ** 2 - h * h)) \
        - FILL * math.pi * r_in ** 2      # noqa: E731
    h = -brentq(seg, -r_in + 1e-9, r_in - 1e-9)     # the segment below y = −|h| ... y = h
    a = 1.12 * GRADE[1]
    xs = np.arange(-r_in, r_in, a)
    ys = np.arange(-r_in, h, a)
    zs = np.arange(0.5 * a, period - 0.5 * a + 1e-12, a) - 0.5 * period
    g = np.stack(np.meshgrid(xs, ys, zs, indexing="ij"), -1).reshape(-1, 3)
    inside = np.hypot(g[:, 0], g[:, 1]) < r_in - 0.5 * a
    g = g[inside] + rng.uniform(-0.04 * D, 0.04 * D, (int(inside.sum()), 3))
    r = 0.5 * rng.uniform(*GRADE, len(g))
    return g, r, h


def build(fr, cfg, opts):
    sim = tdem.Simulation(dim=3, gravity=(0.0, -G, 0.0), progress=False, **opts)
    contact = law()
    mesh = sim.add_mesh(*drum_mesh(cfg["period"]), contact=wall_law())
    x, r, h = bed(cfg["period"], cfg["seed"])
    sim.add_particles(x, r, density=RHO, contact=contact)
    sim.periodic(z=(-0.5 * cfg["period"], 0.5 * cfg["period"]))
    return sim, mesh, h


def angles(p):
    """(centroid angle, surface-fit angle, co-rotation numerator and denominator) of
    the bed now; angles in degrees, positive when the surface rises towards +x (the
    drum turning counter-clockwise lifts the bed on the +x side... seen from +z)."""
    x, v, m, r = p["position"], p["velocity"], p["mass"], p["radius"]
    xc = float(np.sum(m * x[:, 0]) / m.sum())
    yc = float(np.sum(m * x[:, 1]) / m.sum())
    theta_c = math.degrees(math.atan2(xc, -yc))
    # the surface: along the direction perpendicular to the centroid's radius
    n = np.array([xc, yc]) / math.hypot(xc, yc)       # from the axis to the centroid
    t = np.array([-n[1], n[0]])                        # along the surface
    s = x[:, :2] @ t
    up = x[:, :2] @ -n + r                             # height above the axis, away from the bed
    half = math.sqrt(max(R_DRUM ** 2 - float(np.median(up)) ** 2, 1e-12))
    edges = np.arange(-0.6 * half, 0.6 * half + D, D)
    ss, hh = [], []
    for a0, a1 in zip(edges[:-1], edges[1:]):
        sel = (s >= a0) & (s < a1)
        if sel.any():
            ss.append(0.5 * (a0 + a1))
            hh.append(float(up[sel].max()))
    fit = np.polyfit(ss, hh, 1) if len(ss) >= 3 else (np.nan, np.nan)
    theta_s = theta_c - math.degrees(math.atan(fit[0]))
    lz = float(np.sum(m * (x[:, 0] * v[:, 1] - x[:, 1] * v[:, 0])))
    ir = float(np.sum(m * (x[:, 0] ** 2 + x[:, 1] ** 2)))
    return theta_c, theta_s, lz, ir


def run_one(fr, cfg, opts, out):
    omega = math.sqrt(fr * G / R_DRUM)
    sim, mesh, h = build(fr, cfg, opts)
    sim.run(until=0.3)                                   # settle in the still drum
    mesh.motion(angular_velocity=tdem.motion.ramp((0.0, 0.0, omega), SPIN_UP,
                                                  start=sim.time),
                center=(0.0, 0.0, 0.0))
    duration = max(1.2 / omega + 0.4, 1.2)
    t_end = sim.time + duration
    t_read = sim.time + duration * 2.0 / 3.0
    rows = []
    step = 0.02
    while sim.time < t_end - 1e-12:
        sim.run(until=min(sim.time + step, t_end))
        if sim.time >= t_read - 1e-12:
            rows.append(angles(sim.particles.numpy()))
    rows = np.array(rows)
    p = sim.particles.numpy()
    from tdem import io as tio
    tio.write_particles_vtu(sim, out / f"drum_Fr{fr:g}.vtu")
    tio.write_meshes_vtu(sim, out / f"drum_Fr{fr:g}_wall.vtu")
    return {
        "froude": fr, "omega": omega, "particles": int(sim.n_particles),
        "steps": int(sim.steps), "dt": float(sim.dt), "duration_s": duration,
        "angle_centroid_deg": float(rows[:, 0].mean()),
        "angle_centroid_std_deg": float(rows[:, 0].std()),
        "angle_surface_deg": float(np.nanmean(rows[:, 1])),
        "angle_surface_std_deg": float(np.nanstd(rows[:, 1])),
        "corotation": float(np.mean(rows[:, 2] / rows[:, 3]) / omega),
        "corotation_end": float(rows[-1, 2] / rows[-1, 3] / omega),
        "fill_line_m": h,
        "snapshot": {"x": p["position"][:, 0].tolist(), "y": p["position"][:, 1].tolist(),
                     "speed": np.linalg.norm(p["velocity"], axis=1).tolist()},
    }


def plots(runs, out):
    plt = common.pyplot()
    fr = np.array([r["froude"] for r in runs])
    ac = np.array([r["angle_centroid_deg"] for r in runs])
    as_ = np.array([r["angle_surface_deg"] for r in runs])
    co = np.array([r["corotation"] for r in runs])
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(10, 4))
    flowing = fr < 1.0
    ax.semilogx(fr[flowing], as_[flowing], "o-", label="slope of the surface's middle")
    ax.semilogx(fr[flowing], ac[flowing], "s--", label="centroid (the chord's mean slope)")
    for lo, hi, name in ((1e-4, 1e-2, "rolling"), (1e-3, 1e-1, "cascading"),
                         (0.1, 1.0, "cataracting"), (1.0, 10.0, "centrifuging")):
        ax.axvspan(lo, hi, alpha=0.06, color={"rolling": "C0", "cascading": "C1",
                                             "cataracting": "C2", "centrifuging": "C3"}[name])
        ax.text(math.sqrt(lo * hi), 0.02, name, transform=ax.get_xaxis_transform(),
                ha="center", fontsize=7)
    ax.set_xlabel("Froude number ω²R/g")
    ax.set_ylabel("dynamic angle of repose (°)")
    ax.set_title("Free-surface angle (regimes: Mellmann 2001)", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    bx.semilogx(fr, co, "o-")
    bx.axhline(1.0, color="k", lw=0.8)
    bx.set_xlabel("Froude number ω²R/g")
    bx.set_ylabel("bed's mean angular velocity / ω")
    bx.set_title("Co-rotation: 1 = carried round with the drum", fontsize=10)
    bx.grid(alpha=0.3)
    fig.tight_layout()
    common.save(fig, out / "angle_vs_froude.png")

    fig, axes = plt.subplots(1, len(runs), figsize=(3.2 * len(runs), 3.4))
    for a, r in zip(np.atleast_1d(axes), runs):
        snap = r["snapshot"]
        sc = a.scatter(snap["x"], snap["y"], c=snap["speed"], s=6, cmap="viridis")
        a.add_patch(plt.Circle((0, 0), R_DRUM, fill=False, color="k"))
        a.set_aspect("equal")
        a.set_xlim(-1.05 * R_DRUM, 1.05 * R_DRUM)
        a.set_ylim(-1.05 * R_DRUM, 1.05 * R_DRUM)
        a.set_title(f"Fr = {r['froude']:g}: " + (f"{r['angle_surface_deg']:.1f}°"
                                                   if r["froude"] < 1.0 else
                                                   f"carried {r['corotation_end']:.2f} ω"),
                    fontsize=9)
        a.set_xticks([])
        a.set_yticks([])
        fig.colorbar(sc, ax=a, shrink=0.7, label="speed (m/s)")
    fig.suptitle("Cross-sections at the end (drum turning counter-clockwise)", fontsize=10)
    fig.tight_layout()
    common.save(fig, out / "cross_sections.png")


def main(argv=None):
    args, out = common.parse(CASE, argv, description=__doc__.splitlines()[0])
    clock = common.Stopwatch()
    cfg = PRESETS[args.preset]
    opts = common.sim_options(args)
    runs = []
    for fr in cfg["froude"]:
        print(f"Fr = {fr:g}", flush=True)
        runs.append(run_one(fr, cfg, opts, out))
    plots(runs, out)
    by = {r["froude"]: r for r in runs}
    low, mid, high = by[0.003], by[0.03], by[0.1]
    checks = [
        common.check("rolling.plateau", mid["angle_surface_deg"] - low["angle_surface_deg"],
                     0.0, common.absolute(PLATEAU_TOL), "°",
                     f"the angle at Fr 0.03 less that at 0.003 ({mid['angle_surface_deg']:.1f}° "
                     f"− {low['angle_surface_deg']:.1f}°): rolling, a constant angle "
                     f"(Mellmann); the tolerance is the angle's fluctuation over the reading"),
        common.check("cascading.rise", high["angle_surface_deg"] - low["angle_surface_deg"],
                     None, common.between(min=PLATEAU_TOL), "°",
                     f"the angle at Fr 0.1 less that at 0.003 ({high['angle_surface_deg']:.1f}° "
                     f"− {low['angle_surface_deg']:.1f}°): cascading, a steeper surface "
                     f"(Mellmann)"),
        common.check("centrifuging.corotation", by[CENTRIFUGE_FR]["corotation_end"], 1.0,
                     common.between(min=0.95), "",
                     f"Fr {CENTRIFUGE_FR:g}: the bed's mean angular velocity over ω at the end"),
        common.check("cataracting.corotation", by[1.5]["corotation_end"], None, None, "",
                     "Fr 1.5: the bed's mean angular velocity over ω at the end (thrown, "
                     "not carried round)"),
        common.check("rolling.angle", low["angle_surface_deg"], None, None, "°",
                     "the dynamic angle at Fr 0.003, the slope of the surface's middle 60 % "
                     "(docs/cases.md: beside published drums)"),
        common.check("rolling.s_shape", low["angle_surface_deg"] - low["angle_centroid_deg"],
                     None, None, "°",
                     "the middle's slope less the centroid's angle (the mean slope of the "
                     "chord): the S-shape of the surface"),
    ]
    data = {"preset": {k: v for k, v in cfg.items()},
            "drum": {"radius_m": R_DRUM, "sides": SIDES, "fill": FILL, "d_m": D,
                     "grading_m": list(GRADE), "kn": KN, "friction": MU,
                     "rolling_delta": ROLLING, "spin_up_s": SPIN_UP},
            "runs": [{k: v for k, v in r.items() if k != "snapshot"} for r in runs]}
    summary = common.summary(CASE, args.preset, checks, data, clock(), threads=args.threads,
                             paper=PAPER)
    common.write_summary(out, summary)
    common.print_checks(summary)
    return summary


if __name__ == "__main__":
    main()
