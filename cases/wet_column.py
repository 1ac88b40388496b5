"""A column of wet spheres standing where a dry one slumps: liquid bridges against a simple cohesive estimate.

Spheres settled in a square box are joined by pendular liquid bridges
(``tdem.LiquidBridge``: Willett's force, Lian's rupture distance) between every two
within a tenth of a diameter of each other; then the box's four sides are taken away.
A dry column (the same spheres, no bridges) slumps; a wet one stands if it is lower
than the height at which its own weight overcomes the bridges' cohesion.

The estimate (stated before the runs, not fitted)
-------------------------------------------------
Rumpf's tensile strength of a bed of equal spheres held by bridges of force F:
σ_t = (1 − n)/π · k · F/d², k the bridges a sphere (counted in the run, after the
bridges made beyond their rupture distance have gone), F = 2πRγ (Willett's at contact). Taken as the apparent cohesion of a
Mohr–Coulomb bed with a tension cut-off, c = σ_t tan φ (φ the bed's friction angle,
25° for spheres of μ = 0.5 without rolling resistance), an unsupported vertical face
stands up to Terzaghi's critical height H_c = 4c/(ρ_b g) · tan(45° + φ/2). The
estimate carries factors of two from each step: a column well below H_c must stand, one
well above it must not.

Set-up (our choices)
--------------------
- Spheres d = 2 mm (uniform 1.8–2.2 mm), ρ = 2500, ``LinearContact(kn=2000, μ = 0.5,
  e = 0.3)`` (overlap under a 40 d column about 0.1 % d), local damping 0.3; a box
  10 d × 10 d, spheres placed by ``tdem.pack.random3d`` (0.5 volume fraction, no
  overlap) and settled under gravity for 0.4 s.
- Bridges: V = 8e-12 m³ (0.2 % of a sphere's volume: pendular), γ = 0.072 N/m (water),
  θ = 0; made between spheres within the rupture distance V^(1/3) = 0.1 d.
- Bridges made at contact (``tdem.WetContact``, the same bridge and dry law): every two
  spheres that touch while settling or slumping are joined, and a slumping column makes
  new bridges as it goes (the walls keep the dry law). Compared beside the bonded ones.
- The sides are moved away at 1 m/s; the column is watched for 0.5 s. Its height: the
  98th percentile of the spheres' tops.

Checks: the dry column of 4 d loses more than a third of its height; the wet one of
4 d keeps more than 90 % (bridges made once, and made at contact), and 4 d is below
0.6 H_c; reported: the wet ones of 20 d (above H_c) and the estimate.
"""
import math

import numpy as np

import tdem

from . import _common as common

CASE = "wet_column"
PAPER = "Rumpf (1958) and Terzaghi's critical height; Willett et al. (2000); Lian et al. (1993)"
D = 2e-3
RHO = 2500.0
KN = 2000.0
MU = 0.5
PHI = 25.0
VOL, GAMMA = 8e-12, 0.072
SIDE = 10 * D
# wet: False (dry), "bond" (bridges made once, after settling, by sim.bond) or
# "contact" (tdem.WetContact: a bridge at every contact, made during the run)
PRESETS = {"quick": {"heights": (4, 4, 20, 4, 20),
                     "wet": (False, "bond", "bond", "contact", "contact"), "watch": 0.5},
           "paper": {"heights": (4, 4, 8, 12, 20, 30, 4, 12, 20, 30),
                     "wet": (False,) + ("bond",) * 5 + ("contact",) * 4, "watch": 1.0}}


def estimate(porosity, coordination):
    """(σ_t, c, H_c) of Rumpf's and Terzaghi's estimate for the bed's porosity and its
    bridges a sphere (Rumpf: σ_t = (1 − n)/π · k · F/d², k the bridges a sphere)."""
    f = 2 * math.pi * (D / 2) * GAMMA               # Willett's F(0) for equal spheres
    sigma_t = (1 - porosity) / math.pi * coordination * f / D ** 2
    c = sigma_t * math.tan(math.radians(PHI))
    rho_b = (1 - porosity) * RHO
    h_c = 4 * c / (rho_b * 9.81) * math.tan(math.radians(45 + PHI / 2))
    return sigma_t, c, h_c


def column(height_d, wet, opts, seed=1, watch=0.5):
    h = height_d * D
    x, r = tdem.pack.random3d((0, 0, 0), (SIDE, SIDE, h), 0.9 * D / 2, 1.1 * D / 2,
                              seed=seed, target_fraction=0.5)
    sim = tdem.Simulation(dim=3, local_damping=0.3, progress=False, **opts)
    law = tdem.LinearContact(kn=KN, friction=MU, restitution=0.3)
    lb = tdem.LiquidBridge(volume=VOL, surface_tension=GAMMA)
    # the walls keep the dry law: no bridges to walls
    g = sim.add_particles(x, r, density=RHO,
                          contact=tdem.WetContact(law, lb) if wet == "contact" else law)
    v, t = tdem.surfaces.plane((0.5 * SIDE, 0.5 * SIDE, 0.0), (0, 0, 1), 20 * SIDE)
    sim.add_mesh(v, t, contact=law)
    sides = []
    for c, nrm in (((0.0, 0.5 * SIDE, 0.5 * h), (1, 0, 0)), ((SIDE, 0.5 * SIDE, 0.5 * h), (-1, 0, 0)),
                   ((0.5 * SIDE, 0.0, 0.5 * h), (0, 1, 0)), ((0.5 * SIDE, SIDE, 0.5 * h), (0, -1, 0))):
        v, t = tdem.surfaces.plane(c, nrm, 2 * max(h, SIDE))
        sides.append((sim.add_mesh(v, t, contact=law), np.asarray(nrm, float)))
    sim.run(until=0.4)                                     # settle in the box
    p = sim.particles.numpy()
    vol = 4 / 3 * math.pi * np.sum(p["radius"] ** 3)
    top0 = float(np.percentile(p["position"][:, 2] + p["radius"], 98))
    porosity = 1 - vol / (SIDE * SIDE * top0)
    bridges = sim.bond(g, lb, gap=lb.rupture_distance) if wet == "bond" else 0
    if wet == "contact":
        bridges = _contact_bridges(sim)
    for m, nrm in sides:
        m.velocity = tuple(-1.0 * nrm)                     # away from the column
    sim.run(until=sim.time + 0.05)
    for m, _ in sides:
        m.velocity = (0.0, 0.0, 0.0)
    sim.run(until=sim.time + watch)
    p = sim.particles.numpy()
    top = float(np.percentile(p["position"][:, 2] + p["radius"], 98))
    left = len(sim.bonds) if wet == "bond" else _contact_bridges(sim) if wet else 0
    return {"height_d": height_d, "wet": bool(wet), "bridges": wet or None,
            "particles": sim.n_particles,
            "porosity": porosity, "bridges_made": bridges, "bridges_left": left,
            "coordination": 2.0 * bridges / sim.n_particles,
            "top_before": top0, "top_after": top, "kept": top / top0,
            "x": p["position"][:, 0].tolist(), "z": p["position"][:, 2].tolist()}


def _contact_bridges(sim):
    """Bridges of a WetContact model now: its pairs of spheres in force (every pair that
    has touched holds one until it ruptures)."""
    pairs = sim.contacts.numpy()["pairs"]
    return int(np.count_nonzero(pairs[:, 1] >= 0))


def plots(runs, h_c, out):
    plt = common.pyplot()
    fig, axes = plt.subplots(1, len(runs), figsize=(3.2 * len(runs), 4.2), sharey=True)
    for a, r in zip(np.atleast_1d(axes), runs):
        a.scatter(1e3 * np.asarray(r["x"]), 1e3 * np.asarray(r["z"]), s=2,
                  color={None: "C1", "bond": "C0", "contact": "C2"}[r["bridges"]])
        a.axhline(1e3 * r["top_before"], color="k", lw=0.8, ls=":")
        a.axhline(1e3 * h_c, color="C3", lw=0.8, ls="--")
        kind = {None: "dry", "bond": "wet (bonded)", "contact": "wet (at contact)"}
        a.set_title(f"{kind[r['bridges']]}, {r['height_d']} d:\n"
                    f"keeps {100 * r['kept']:.0f} %", fontsize=9)
        a.set_xlabel("x (mm)")
        a.set_xlim(-30, 50)
        a.set_aspect("equal")
    np.atleast_1d(axes)[0].set_ylabel("z (mm)")
    fig.suptitle("Columns after their sides are taken away (dotted: the height before; "
                 "dashed: the estimated H_c)", fontsize=10)
    fig.tight_layout()
    common.save(fig, out / "columns.png")


def main(argv=None):
    args, out = common.parse(CASE, argv, description=__doc__.splitlines()[0])
    clock = common.Stopwatch()
    cfg = PRESETS[args.preset]
    opts = common.sim_options(args)
    runs = []
    for hd, wet in zip(cfg["heights"], cfg["wet"]):
        print(f"{'dry' if not wet else 'wet (' + wet + ')'} column, {hd} d", flush=True)
        runs.append(column(hd, wet, opts, watch=cfg["watch"]))
    wets = [r for r in runs if r["bridges"] == "bond"]
    sigma_t, c, h_c = estimate(float(np.mean([r["porosity"] for r in wets])),
                               float(np.mean([r["coordination"] for r in wets])))
    plots(runs, h_c, out)
    dry = next(r for r in runs if not r["wet"])
    wet10 = next(r for r in runs if r["bridges"] == "bond" and r["height_d"] == 4)
    tall = [r for r in runs if r["bridges"] == "bond" and r["height_d"] * D > h_c]
    contact = [r for r in runs if r["bridges"] == "contact"]
    c4 = next((r for r in contact if r["height_d"] == 4), None)
    checks = [
        common.check("dry.slumps", dry["kept"], None, common.between(max=2 / 3), "",
                     "the dry 4 d column's height kept (a third lost at least)"),
        common.check("wet.stands", wet10["kept"], 1.0, common.between(min=0.9), "",
                     f"the wet 4 d column's height kept; 4 d = {4 * D * 1e3:.0f} mm "
                     f"against the estimate H_c = {h_c * 1e3:.1f} mm"),
        common.check("wet.below_estimate", 4 * D / h_c, None, common.between(max=0.6), "",
                     "the standing column's height over the estimate H_c (well below it)"),
        common.check("estimate.H_c", h_c, None, None, "m",
                     f"Terzaghi's 4c/(ρ_b g) tan(45° + φ/2), c = σ_t tan φ, σ_t = "
                     f"{sigma_t:.0f} Pa (Rumpf)"),
    ] + [common.check(f"wet_{r['height_d']}d.kept", r["kept"], None, None, "",
                      f"a wet column of {r['height_d']} d ({r['height_d'] * D * 1e3:.0f} mm, "
                      f"above H_c): the height it keeps") for r in tall]
    if c4 is not None:
        checks.append(common.check(
            "wet_contact.stands", c4["kept"], 1.0, common.between(min=0.9), "",
            f"the wet 4 d column with bridges made at contact (tdem.WetContact, "
            f"{c4['coordination']:.1f} a sphere): the height it keeps"))
    checks += [common.check(
        f"wet_contact_{r['height_d']}d.kept", r["kept"], None, None, "",
        f"bridges made at contact, {r['height_d']} d: the height kept (the slump makes new "
        f"bridges; {r['bridges_left']} held at the end, {r['bridges_made']} before)")
        for r in contact if r["height_d"] * D > h_c]
    data = {"preset": {k: list(v) if isinstance(v, tuple) else v for k, v in cfg.items()},
            "estimate": {"sigma_t_Pa": sigma_t, "cohesion_Pa": c, "H_c_m": h_c, "phi": PHI},
            "runs": [{k: v for k, v in r.items() if k not in ("x", "z")} for r in runs]}
    summary = common.summary(CASE, args.preset, checks, data, clock(), threads=args.threads,
                             paper=PAPER)
    common.write_summary(out, summary)
    common.print_checks(summary)
    return summary


if __name__ == "__main__":
    main()
