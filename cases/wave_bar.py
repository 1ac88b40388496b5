"""Wave propagation in a rock bar (Feng et al. 2015 §3.3, Figs. 14-16): PCMM regular/cross/random vs FVM.

Set-up
------
Bar 20 × 0.6 m, elastic ρ = 2500 kg/m³, E = 30 GPa, ν = 0.25, plane strain, no
gravity, no damping (dt = 0.5 × the critical step). Right end fixed (vx = vy = 0);
left end driven horizontally by a half sine vx = 10·sin(2πt/6 ms) m/s for
0 ≤ t < 3 ms, then vx = 0 (held), vy free. Runs to 10 ms. Four models, each in
its own simulation and output subfolder:

- regular PCMM: square lattice R = 5 cm, δ = 5 cm: 1200 particles (the lattice
  built from R inside the bar; the paper says 1206);
- cross PCMM: hexagonal lattice R = 5 cm, δ = 0.1 cm: 1197 particles (paper 1404);
- random PCMM: ``tdem.pack.random`` at 86 % area fraction, δ = 5 cm, the paper's
  R = 1.39-4.23 cm: 3862 particles (the paper's GiD packing has 5043, too many for
  uniform radii in this range), denser than jamming, the discs overlapping (at
  most 0.7 rmin, ``overlap_tol``; 0.87 and above are not reached), and 38 more
  put into the holes of the element cover (``pcmm_tolerance=δ``; 3900 in all).
  At 80 % (3580 particles) the voids left holes in the element cover: the wave
  arrived 2.0 % late with 9.4 % less stress than ρ·c·v; at 86 % 1.5 % late, 0.9 %
  over; with the holes filled 1.5 % late, 0.7 % under. A coarser
  packing is not a faster stand-in: with 1.5 × the radii (1439 particles at 74 %)
  the wave arrives about 20 % late at half the stress, and a static compression
  of a 2 × 0.6 m strip gives 0.82 E/(1 − ν²) instead of 0.97 at the paper's radii
  (the element cover of a coarse random packing is too irregular for the
  superposition weights);
- FVM block: 200 × 6 cells of 10 × 10 cm, two triangles each (2400 triangles;
  the paper counts 1200 elements = cells).

The driven "left end" of a PCMM model is its first column of particles (discs
reaching within half the largest radius of the leftmost disc edge), likewise the
fixed right end; FVM: the nodes on x = 0 and x = 20 m.

Read-out (paper Figs. 15-16): horizontal velocity and σ_xx at x = 10 m: the mean
over the particles whose centres lie within one radius of x = 10 m (random: the
mean radius) across the height; FVM: mean velocity of the nodes on x = 10 m, mean
σ_xx of the elements with centroids within one cell of x = 10 m.

Targets. The wave length (c × 6 ms ≈ 21 m) is ≫ the height, so the bar carries
the plane-strain bar speed c = sqrt(E/(ρ(1 − ν²))) = 3578 m/s; the P-wave speed
sqrt((K + 4G/3)/ρ) = 3795 m/s is the short-wave limit (a bar of finite height lies
between the two). Arrival: the first time |vx| at x = 10 m exceeds 5 % of its
peak, against (10 m − x_drive)/c + t₅, t₅ = (6 ms/2π)·asin(0.05) = 0.048 ms the
time the drive itself takes to reach 5 %; within 5 %. Peak velocity of the
incident pulse (before the reflection from the fixed end returns, t < 8 ms):
within 10 % of 10 m/s. Peak compressive stress: within 10 % of ρ·c·v = 89.4 MPa.

Presets: ``quick`` and ``paper`` are the same model (the random packing at the
paper's radii; see above).

Outputs (``--out DIR``, default out/wave_bar): one subfolder per model with its
VTU series (.pvd) and monitors.h5; ``histories.h5``; ``fig14_models.png``,
``fig15_velocity.png``, ``fig16_stress.png``; ``summary.json``.
"""
import math

import numpy as np

import tdem
from tdem.errors import InputError

from . import _common as common
from . import _pcmm

CASE = "wave_bar"
W, H = 20.0, 0.6
RHO, E, NU = 2500.0, 30e9, 0.25
AMP, PERIOD, DURATION = 10.0, 6e-3, 3e-3
X_STATION = 10.0
T_END = 10e-3
T_REFLECT_WINDOW = 8e-3
FRAC = 0.05
TOL_ARRIVAL, TOL_V, TOL_S = 0.05, 0.10, 0.10

# random packings denser than jamming, the discs overlapping (tdem.pack.random)
_DENSE = {"fraction": 0.86, "overlap_tol": 0.7, "fill_holes": True}

MODELS = {
    "quick": {
        "regular": {"kind": "regular", "radius": 0.05, "tolerance": 0.05},
        "cross": {"kind": "cross", "radius": 0.05, "tolerance": 0.001},
        "random": {"kind": "random", "rmin": 0.0139, "rmax": 0.0423, "tolerance": 0.05,
                   **_DENSE},
        "fvm": {"kind": "fvm", "cells": (200, 6), "pattern": "regular"},
    },
    "paper": {
        "regular": {"kind": "regular", "radius": 0.05, "tolerance": 0.05},
        "cross": {"kind": "cross", "radius": 0.05, "tolerance": 0.001},
        "random": {"kind": "random", "rmin": 0.0139, "rmax": 0.0423, "tolerance": 0.05,
                   **_DENSE},
        "fvm": {"kind": "fvm", "cells": (200, 6), "pattern": "regular"},
    },
}
PAPER_COUNTS = {"regular": 1206, "cross": 1404, "random": 5043, "fvm": 1200}


def material():
    return tdem.Elastic(density=RHO, young=E, poisson=NU)


def drive(t):
    return AMP * math.sin(2.0 * math.pi * t / PERIOD) if t < DURATION else 0.0


def station(m):
    """(kinematic ids, stress ids) of the read-out at x = 10 m."""
    if m.is_fvm:
        nodes = np.flatnonzero(np.abs(m.x0[:, 0] - X_STATION) <= 1e-9 * W)
        tri = np.asarray(m.block.triangles)
        cx = m.x0[tri].mean(axis=1)[:, 0]
        cell = W / m.spec["cells"][0]
        return nodes, np.flatnonzero(np.abs(cx - X_STATION) <= cell)
    r = m.r.max() if m.spec["kind"] != "random" else m.r.mean()
    ids = np.flatnonzero(np.abs(m.x0[:, 0] - X_STATION) <= r * (1 + 1e-6))
    return ids, ids


def read(m):
    s = m.state()
    return np.array([s["velocity"][m.kin, 0].mean(), s["stress"][m.sid, 0, 0].mean()])


def run_model(name, spec, out, preset, sim_kwargs, until=T_END):
    m = _pcmm.Model(name, spec, W, H, material(), sim_kwargs)
    left, right = m.edge("left"), m.edge("right")
    m.fix(left, vx=drive, vy=None)
    m.fix(right, vx=0.0, vy=0.0)
    m.x_drive = float(m.x0[left, 0].mean())
    m.kin, m.sid = station(m)
    sim = m.sim
    every = max(1, int(round(2e-5 / sim.dt)))
    sim.monitor("station_vx_sxx", lambda s: read(m), every=every)
    output = common.start_output(sim, out / name, every=max(1, int(round(5e-4 / sim.dt))))
    m.first_step()
    watch = common.Stopwatch()
    sim.run(until=until)
    m.run_s = watch()
    common.finish_output(output)
    t, v = sim.histories()["station_vx_sxx"]
    m.t, m.vx, m.sxx = np.asarray(t), np.asarray(v)[:, 0], np.asarray(v)[:, 1]
    print(f"  {name}: {m.count}, {sim.steps} steps (dt {sim.dt:.3g} s), station "
          f"{len(m.kin)} points, {m.run_s:.1f} s", flush=True)
    return m


def run(preset="quick", out=None, models=None, arch=None, threads=None, duration=None):
    """Run the case; returns the summary dict (also written to out/summary.json).
    ``duration`` (s) ends the run earlier than T_END (the pulse has passed the
    station at x = 10 m by 6 ms)."""
    try:
        until = T_END if duration is None else float(duration)
    except (TypeError, ValueError):
        until = float("nan")
    if not 0.0 < until <= T_END:
        raise InputError(f"duration must lie in (0, {T_END}] s, got {duration!r}")
    out = common.output_dir(CASE, out)
    watch = common.Stopwatch()
    mat = material()
    c_bar, c_p = _pcmm.wave_speeds(mat)
    sim_kwargs = dict(gravity=(0.0, 0.0), local_damping=0.0, dt_fraction=0.5,
                      arch=arch, threads=threads)
    runs = _pcmm.run_all(_pcmm.select_models(MODELS[preset], models),
                         lambda n, s: run_model(n, s, out, preset, sim_kwargs, until))
    t5 = PERIOD / (2.0 * math.pi) * math.asin(FRAC)
    s_target = RHO * c_bar * AMP
    data = {"bar_speed": c_bar, "p_wave_speed": c_p, "models": {}}
    checks = []
    hist = {}
    for m in runs:
        win = m.t < T_REFLECT_WINDOW
        vpk = float(np.max(m.vx[win]))
        spk = float(-np.min(m.sxx[win]))
        above = np.flatnonzero(np.abs(m.vx) > FRAC * vpk)
        t_arr = float(m.t[above[0]]) if len(above) else float("nan")
        d = X_STATION - m.x_drive
        t_tgt = d / c_bar + t5
        # speed measured from the arrival (threshold crossing) for information
        c_meas = d / (t_arr - t5) if t_arr == t_arr else float("nan")
        label = _pcmm.LABELS[m.name]
        checks += [
            common.check(f"{m.name}.arrival_time", t_arr, t_tgt, common.rel(TOL_ARRIVAL), "s",
                         f"{label}: first |vx| > 5 % of peak at x = 10 m; target "
                         f"(10 - x_drive)/c_bar + t5 (with c_p it would be "
                         f"{d / c_p + t5:.4g} s)"),
            common.check(f"{m.name}.peak_velocity", vpk, AMP, common.rel(TOL_V), "m/s",
                         f"{label}: t < 8 ms (before the reflection); target the drive's "
                         "amplitude"),
            common.check(f"{m.name}.peak_stress", spk, s_target, common.rel(TOL_S), "Pa",
                         f"{label}: largest compressive sigma_xx, t < 8 ms; target rho c_bar v"),
            common.check(f"{m.name}.apparent_speed", c_meas, c_bar, None, "m/s",
                         f"{label}: (10 m - x_drive) / (arrival - t5), for information; "
                         f"P-wave speed {c_p:.0f} m/s"),
            _pcmm.count_check(m, PAPER_COUNTS[m.name]),
        ]
        data["models"][m.name] = {
            "count": m.count, "paper_count": PAPER_COUNTS[m.name], "spec": m.spec,
            "steps": m.sim.steps, "dt": m.sim.dt, "run_s": m.run_s,
            "station_points": int(len(m.kin)), "x_drive": m.x_drive,
            "arrival_rel_error": _pcmm.rel(t_arr, t_tgt),
            "peak_velocity_rel_error": _pcmm.rel(vpk, AMP),
            "peak_stress_rel_error": _pcmm.rel(spk, s_target),
        }
        hist[m.name] = {"time": m.t, "vx": m.vx, "sigma_xx": m.sxx}
    return _pcmm.finish(CASE, preset, checks, data, out, hist,
                        lambda: plots(runs, out, c_bar), watch, threads=threads,
                        paper="Feng, Li & Oñate (2015), §3.3, Figs. 14-16")


def plots(runs, out, c_bar):
    plt = common.pyplot()
    _pcmm.plot_models(runs, out / "fig14_models.png",
                      title="Bar models, first 2 m (paper Fig. 14)")
    tt = np.linspace(0.0, T_END, 1001)
    for key, fname, label, fig_no in (("vx", "fig15_velocity.png", "horizontal velocity (m/s)", 15),
                                      ("sxx", "fig16_stress.png", "σ_xx (MPa, tension +)", 16)):
        fig, ax = plt.subplots(figsize=(7, 4))
        for m in runs:
            y = m.vx if key == "vx" else m.sxx / 1e6
            ax.plot(m.t * 1e3, y, color=_pcmm.COLORS[m.name], lw=1.2, label=_pcmm.LABELS[m.name])
        d = X_STATION - runs[0].x_drive
        ana = np.array([drive(t - d / c_bar) if t >= d / c_bar else 0.0 for t in tt])
        if key == "sxx":
            ana = -RHO * c_bar * ana / 1e6
        ax.plot(tt * 1e3, ana, "k--", lw=1, label="incident pulse, c = sqrt(E/ρ(1−ν²))")
        ax.set_xlabel("time (ms)")
        ax.set_ylabel(label)
        ax.set_title(f"Wave bar: {'velocity' if key == 'vx' else 'stress'} at x = 10 m "
                     f"(paper Fig. {fig_no})", fontsize=10)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        fig.tight_layout()
        common.save(fig, out / fname)


def main(argv=None):
    return _pcmm.main(CASE, run, __doc__, argv)


if __name__ == "__main__":
    raise SystemExit(main())
