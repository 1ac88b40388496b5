"""Plate loading of a granular bed: circles against superellipses (Miyata et al. 2002, §3.2, Figs. 26–30).

Set-up (Miyata §3.2, Tables 1–2)
-------------------------------------------------------------
A 2D bed, 10 m wide with periodic sides, on a rigid floor, compressed by a rigid plate
that moves down at 0.01 m/s until it carries 900 kPa. Four beds:

- CS, CR: circles, r = 0.15 m; SS, SR: superellipses n = 4, a = 0.195 m, b = 0.0976 m
  (the same area, 0.0707 m²);
- S (smooth top): the particles with centres above 2.7 m are removed after settling;
  R (rough top): those above z = 2.7 + 0.3·sin(2πx/2) m (Miyata's Eq. 60).

ρ = 1650 kg/m³, linear contacts k_n = k_s = 1e7 N/m between particles and 1e8 N/m
against the floor and the plate, restitution e = 0.01, μ = 0.51, Δt = 1.7078e-4 s.
States of the plate stress: initial 0–50 kPa, transition 50–250 kPa, final > 250 kPa.
Every contact is tagged with the state in which it formed; at 900 kPa the case reports
the share of the load (the sum of the contacts' normal forces) that each group carries
(Miyata Fig. 30), beside the paper's statements: the initial and transition contacts
carry more than 70 % and the final ones at most 20 %; for SS/SR the initial ones more
than 50 % and the final ones less than 15 %.

Decisions the paper leaves open
-------------------------------
- The count (about 310 particles after the cut): 22 columns × 18 rows are dropped from
  a jittered lattice (spacing 0.45 m, random angles) and settle under gravity with
  μ = 0.51 (the paper's value) until their kinetic energy is below 1e-6 of their
  potential energy (or 8 s); the cut leaves the bed, which settles again (4 s at most).
- Contacts that exist when the plate starts (the settled bed's) belong to the initial
  group, formed at 0 kPa; a contact that opens and forms again takes the state of its
  new formation. Contacts are looked at every 20 steps (3.4 ms, 34 µm of plate travel).
- "Load carried" is the sum of the normal forces of the group's contacts over all
  contacts of the bed (particle–particle, floor and plate) at 900 kPa.
- Quick preset: the plate moves at 0.2 m/s (20×: the bed's kinetic energy stays below
  1e-3 of the plate's work, which the summary reports), and the beds settle to 1e-5 of
  their potential energy within 3 s and 1.5 s.
"""
import math

import numpy as np

import tdem

from . import _common as common

CASE = "plate_loading"

WIDTH = 10.0
CUT = 2.7
RHO = 1650.0
KN, KN_WALL = 1e7, 1e8
FRICTION, RESTITUTION = 0.51, 0.01
DT = 1.7078e-4
R_CIRCLE = 0.15
SQUARE = dict(a=0.195, b=0.0976, n=4)
STATES = (("initial", 0.0, 50e3), ("transition", 50e3, 250e3), ("final", 250e3, math.inf))
TARGET_STRESS = 900e3
POLL = 20

PRESETS = {
    "quick": {"speed": 0.2, "beds": ("CS", "CR", "SS", "SR"), "vtu_every": 1000,
              "settle": (3.0, 1.5), "calm": 1e-5},
    "paper": {"speed": 0.01, "beds": ("CS", "CR", "SS", "SR"), "vtu_every": 5000,
              "settle": (8.0, 4.0), "calm": 1e-6},
}

# the paper's statements (Fig. 30 text), as bounds on the load shares
PAPER = {"initial+transition": (">", 0.70), "final": ("<=", 0.20)}
PAPER_SQUARE = {"initial": (">", 0.50), "final": ("<", 0.15)}


def state_of(stress):
    for k, (_, lo, hi) in enumerate(STATES):
        if lo <= stress < hi:
            return k
    return len(STATES) - 1


def _laws():
    pp = tdem.LinearContact(kn=KN, ks=KN, friction=FRICTION, restitution=RESTITUTION)
    pw = tdem.LinearContact(kn=KN_WALL, ks=KN_WALL, friction=FRICTION,
                            restitution=RESTITUTION)
    return pp, pw


def _new_sim(opts):
    sim = tdem.Simulation(gravity=(0.0, -9.81), dt=DT, progress=False, **opts)
    sim.periodic(x=(0.0, WIDTH))
    return sim


def _add(sim, bed, pos, angle, law):
    if bed[0] == "C":
        return sim.add_particles(pos, R_CIRCLE, density=RHO, contact=law)
    return sim.add_particles(pos, shape=tdem.Superellipse(**SQUARE), angle=angle,
                             density=RHO, contact=law)


def settle(sim, max_time=8.0, calm=1e-6, chunk=0.25):
    """Run until the kinetic energy is below ``calm`` × the potential energy above the
    floor (or ``max_time``)."""
    t_end = sim.time + max_time
    while sim.time < t_end:
        sim.run(until=sim.time + chunk)
        e = sim.energy()
        p = sim.particles.numpy()
        pot = float((p["mass"] * 9.81 * p["position"][:, 1]).sum())
        if e["kinetic"] < calm * pot:
            break
    return sim


def build_bed(bed, seed, opts, settle_times=(8.0, 4.0), calm=1e-6):
    """The settled, cut and resettled bed ``bed`` ("CS", "CR", "SS", "SR")."""
    rng = np.random.default_rng(seed)
    pp, pw = _laws()
    nx, ny, h = 22, 18, 0.45
    gx = (np.arange(nx) + 0.5) * WIDTH / nx
    gy = 0.3 + np.arange(ny) * h
    pos = np.stack(np.meshgrid(gx, gy), -1).reshape(-1, 2)
    pos += rng.uniform(-0.02, 0.02, pos.shape)
    angle = rng.uniform(0.0, 360.0, len(pos))
    sim = _new_sim(opts)
    _add(sim, bed, pos, angle, pp)
    sim.add_wall((-1.0, 0.0), (WIDTH + 1.0, 0.0), contact=pw)
    settle(sim, settle_times[0], calm)
    p = sim.particles.numpy()
    x, y = p["position"][:, 0], p["position"][:, 1]
    top = CUT + (0.3 * np.sin(2.0 * math.pi * x / 2.0) if bed[1] == "R" else 0.0)
    keep = y <= top
    sim2 = _new_sim(opts)
    _add(sim2, bed, p["position"][keep], p["angle"][keep], pp)
    sim2.add_wall((-1.0, 0.0), (WIDTH + 1.0, 0.0), contact=pw)
    settle(sim2, settle_times[1], calm)
    return sim2, pw


class Tags:
    """The state in which each contact formed (module docstring)."""

    def __init__(self):
        self.tag = {}
        self.formed = [0, 0, 0]

    def update(self, pairs, state):
        now = {}
        for i, j in pairs:
            key = (int(min(i, j)), int(max(i, j))) if j >= 0 else (int(i), int(j))
            t = self.tag.get(key)
            if t is None:
                t = state
                self.formed[state] += 1
            now[key] = t
        self.tag = now

    def of(self, pairs):
        return np.array([self.tag[(int(min(i, j)), int(max(i, j))) if j >= 0 else
                                  (int(i), int(j))] for i, j in pairs], dtype=int)


def load(sim, pw, speed, out=None, vtu_every=None):
    """The plate from just above the bed down at ``speed`` until 900 kPa: the history
    (settlement, plate stress, plate contacts) and the contact tags."""
    p = sim.particles.numpy()
    ytop = float((p["position"][:, 1] + p["radius"]).max())
    plate = sim.add_wall((-1.0, ytop + 0.01), (WIDTH + 1.0, ytop + 0.01), contact=pw,
                         velocity=(0.0, -speed))
    tags = Tags()
    c = sim.contacts.numpy()
    tags.update(c["pairs"], 0)
    tags.formed = [0, 0, 0]                     # count those formed from here on
    rows = []
    y0 = plate.center[1]
    output = common.start_output(sim, out, vtu_every) if out is not None else None
    work0 = sim.energy()
    stress = 0.0
    while stress < TARGET_STRESS:
        sim.run(steps=POLL)
        stress = abs(float(plate.force[1])) / WIDTH
        c = sim.contacts.numpy()
        tags.update(c["pairs"], state_of(stress))
        on_plate = int(np.sum(c["pairs"][:, 1] == -1 - plate.index)) if len(c["pairs"]) else 0
        rows.append((sim.time, y0 - plate.center[1], stress, on_plate))
        if y0 - plate.center[1] > 2.0:
            raise RuntimeError("the plate went 2 m down without reaching 900 kPa")
    plate.velocity = (0.0, 0.0)
    if output is not None:
        output.write(sim)
        common.finish_output(output)
    e = sim.energy()
    return np.array(rows), tags, plate, {"kinetic_over_work": e["kinetic"] / max(
        e["boundary_work"] - work0["boundary_work"], 1e-30)}


def shares(sim, tags):
    c = sim.contacts.numpy()
    t = tags.of(c["pairs"])
    fn = np.asarray(c["normal"])
    load = np.array([fn[t == k].sum() for k in range(3)]) / fn.sum()
    count = np.array([np.sum(t == k) for k in range(3)]) / len(t)
    return load, count


def plot_settlement(results, png):
    plt = common.pyplot()
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    for bed, r in results.items():
        h = r["history"]
        ax.plot(h[:, 1], h[:, 2] / 1e3, label=bed, lw=1.3,
                ls="-" if bed[0] == "S" else "--")
    for name, lo, hi in STATES:
        ax.axhspan(lo / 1e3, min(hi, TARGET_STRESS) / 1e3, alpha=0.07,
                   color={"initial": "tab:blue", "transition": "tab:orange",
                          "final": "tab:green"}[name])
        ax.text(0.01, (lo + min(hi, TARGET_STRESS)) / 2e3, name, transform=ax.get_yaxis_transform(),
                va="center", fontsize=8, color="0.3")
    ax.set_xlabel("plate settlement (m)")
    ax.set_ylabel("plate stress (kPa)")
    ax.set_ylim(0, TARGET_STRESS / 1e3 * 1.03)
    ax.set_xlim(left=0)
    ax.legend(title="bed", loc="lower right")
    ax.set_title("Stress against settlement (Miyata Fig. 26)")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    common.save(fig, png)


def plot_shares(results, png):
    plt = common.pyplot()
    beds = list(results)
    fig, ax = plt.subplots(figsize=(6.4, 4.8))
    w = 0.26
    colors = ("tab:blue", "tab:orange", "tab:green")
    for k, (name, _, _) in enumerate(STATES):
        load = [100 * results[b]["load_share"][k] for b in beds]
        count = [100 * results[b]["count_share"][k] for b in beds]
        xs = np.arange(len(beds)) + (k - 1) * w
        ax.bar(xs, load, w, color=colors[k], label=f"{name}: share of load")
        ax.scatter(xs, count, marker="_", s=250, color="k", zorder=3,
                   label="share of contacts" if k == 0 else None)
    ax.axhline(20, color="tab:green", ls=":", lw=1, label="paper: final ≤ 20 %")
    ax.axhline(70, color="0.4", ls=":", lw=1, label="paper: initial + transition > 70 %")
    ax.set_xticks(np.arange(len(beds)), beds)
    ax.set_ylabel("share at 900 kPa (%)")
    ax.set_ylim(0, 100)
    ax.set_xlim(-0.5, len(beds) - 0.5)
    ax.set_title("Load carried by the contacts formed in each state (Miyata Fig. 30)",
                 fontsize=10)
    ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.1), ncol=2,
              frameon=False)
    ax.grid(alpha=0.3, axis="y")
    fig.tight_layout()
    common.save(fig, png)


def plot_chains(results, png):
    from matplotlib.collections import LineCollection, PolyCollection
    plt = common.pyplot()
    beds = list(results)
    fig, axes = plt.subplots(len(beds), 1, figsize=(9.0, 2.6 * len(beds)), squeeze=False,
                             sharex=True)
    ytop = max(r["plate_y"] for r in results.values()) + 0.1
    shape = tdem.Superellipse(**SQUARE)
    colors = np.array([[0.12, 0.47, 0.71], [1.0, 0.5, 0.05], [0.17, 0.63, 0.17]])
    for ax, bed in zip(axes[:, 0], beds):
        r = results[bed]
        p, c, t = r["particles"], r["contacts"], r["tags"]
        x, th = p["position"], np.radians(p["angle"])
        if bed[0] == "S":
            polys = shape.placed(x, th, 32)
        else:
            a = np.linspace(0, 2 * math.pi, 32, endpoint=False)
            polys = x[:, None, :] + R_CIRCLE * np.stack([np.cos(a), np.sin(a)], 1)[None]
        ax.add_collection(PolyCollection(polys, facecolor="0.88", edgecolor="0.6", lw=0.3))
        pairs = c["pairs"]
        inner = pairs[:, 1] >= 0
        a_ = x[pairs[inner, 0]]
        d = x[pairs[inner, 1]] - a_
        d[:, 0] -= WIDTH * np.round(d[:, 0] / WIDTH)
        b_ = a_ + d
        fn = c["normal"][inner]
        lw = 4.0 * fn / max(fn.max(), 1e-30)
        ax.add_collection(LineCollection(np.stack([a_, b_], 1), linewidths=lw,
                                         colors=colors[t[inner]]))
        ax.axhline(r["plate_y"], color="k", lw=2)
        ax.axhline(0.0, color="k", lw=2)
        ax.set_xlim(0, WIDTH)
        ax.set_ylim(-0.1, ytop)
        ax.set_aspect("equal")
        ax.set_ylabel(f"{bed}\ny (m)")
    axes[-1, 0].set_xlabel("x (m)")
    handles = [plt.Line2D([], [], color=colors[k], lw=3, label=f"formed in the {n} state")
               for k, (n, _, _) in enumerate(STATES)]
    axes[0, 0].legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, 1.45),
                      ncol=3, fontsize=8, frameon=False)
    fig.suptitle("Force chains at 900 kPa (line width ∝ normal force; Miyata Fig. 27)",
                 y=0.995)
    fig.tight_layout()
    common.save(fig, png)


def main(argv=None):
    args, out = common.parse(CASE, argv, description=__doc__.splitlines()[0])
    clock = common.Stopwatch()
    cfg = PRESETS[args.preset]
    opts = common.sim_options(args)
    results = {}
    for k, bed in enumerate(cfg["beds"]):
        print(f"{bed}: settling the bed", flush=True)
        sim, pw = build_bed(bed, seed=k, opts=opts, settle_times=cfg["settle"],
                            calm=cfg["calm"])
        n = sim.n_particles
        print(f"{bed}: {n} particles; plate at {cfg['speed']} m/s to 900 kPa", flush=True)
        hist, tags, plate, extra = load(sim, pw, cfg["speed"], out=out / bed,
                                        vtu_every=cfg["vtu_every"])
        load_share, count_share = shares(sim, tags)
        results[bed] = {
            "particles": sim.particles.numpy(), "contacts": sim.contacts.numpy(),
            "tags": tags.of(sim.contacts.numpy()["pairs"]), "history": hist,
            "plate_y": plate.center[1], "n": n, "load_share": load_share,
            "count_share": count_share, "formed": tags.formed,
            "nonconverged": sim.nonconverged_contacts, **extra}
    plot_settlement(results, out / "fig26_stress_settlement.png")
    plot_shares(results, out / "fig30_load_shares.png")
    plot_chains(results, out / "fig27_force_chains.png")
    common.save_histories(out / "histories.h5", {
        b: {"time": r["history"][:, 0], "settlement": r["history"][:, 1],
            "plate_stress": r["history"][:, 2], "plate_contacts": r["history"][:, 3]}
        for b, r in results.items()})

    checks = []
    beds = {}
    for bed, r in results.items():
        ls = r["load_share"]
        checks += [
            common.check(f"{bed}.load_share_initial_transition", ls[0] + ls[1], None,
                         common.between(min=0.70), "",
                         "Miyata: over 70 % of the 900 kPa load"),
            common.check(f"{bed}.load_share_final", ls[2], None, common.between(max=0.20), "",
                         "Miyata: 20 % or less"),
        ]
        if bed[0] == "S":
            checks += [
                common.check(f"{bed}.load_share_initial", ls[0], None,
                             common.between(min=0.50), "", "Miyata (SS, SR): over 50 %"),
                common.check(f"{bed}.load_share_final_square", ls[2], None,
                             common.between(max=0.15), "", "Miyata (SS, SR): under 15 %"),
            ]
        h = r["history"]
        beds[bed] = {
            "particles": r["n"],
            "load_share": dict(zip([s[0] for s in STATES], ls.tolist())),
            "contact_share": dict(zip([s[0] for s in STATES], r["count_share"].tolist())),
            "contacts_formed_during_loading": dict(zip([s[0] for s in STATES], r["formed"])),
            "settlement_at_900kPa_m": float(h[-1, 1]),
            "settlement_at_50kPa_m": float(np.interp(50e3, h[:, 2], h[:, 1])),
            "settlement_at_250kPa_m": float(np.interp(250e3, h[:, 2], h[:, 1])),
            "plate_contacts_at_900kPa": int(h[-1, 3]),
            "kinetic_energy_over_plate_work": r["kinetic_over_work"],
            "nonconverged_contacts": r["nonconverged"],
        }
    summary = common.summary(
        CASE, args.preset, checks, {"plate_speed_m_s": cfg["speed"], "beds": beds}, clock(),
        threads=args.threads, paper="Miyata et al. (2002), §3.2, Figs. 26-30")
    common.write_summary(out, summary)
    common.print_checks(summary)
    return summary


if __name__ == "__main__":
    main()
