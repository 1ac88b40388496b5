"""The rock of uniaxial_compression as parallel-bonded discs and spheres: uniaxial compression, Brazilian tests and the bonded-particle model's trends (Potyondy & Cundall 2004).

The rock of Feng, Li & Oñate (2015) §3.2 (``cases.uniaxial_compression``: E = 30 GPa,
ν = 0.25, c = 3 MPa, T = 1 MPa, φ = 40°, ρ = 2500 kg/m³; its Mohr–Coulomb uniaxial
strength 2c cos φ/(1 − sin φ) = 12.87 MPa) built as PFC users build rock: discs joined
by parallel bonds (``tdem.ParallelBond``), acting beside the discs' linear contacts.

Set-up and the stated rule (our choices: a BPM is calibrated, and the rule below is the
uncalibrated start a PFC user makes)
----------------------------------------------------------------------------------
- Discs: radii uniform in [R_min, 1.66 R_min] (Potyondy & Cundall's ratio), R_min =
  2 mm (quick) or 1 mm (paper), ``tdem.pack.random`` at 0.80 area fraction with overlaps below 5e-5 R_min (a contact
  overlapping by more would push its bond past σ̄_c before any load: k_n δ > σ̄_c Ā), ρ = 2500.
- Contacts: ``LinearContact(kn = E_c, ks = E_c/κ, friction = 0.5)`` per metre, E_c the
  rock's E (k_n = E_c A/L with A = 2R, L = 2R for equal discs) and κ = 2.5 (P&C's).
- Bonds between discs within 5 % of R_min: Ē = E, κ̄ = 2.5, λ̄ = 1; the strengths the
  rock's: σ̄_c = T, c̄ = c, φ̄ = φ.
- Uniaxial compression of a 0.1 × 0.2 m sample between two frictional platens (segment
  walls) closing at 2 × 0.005 m/s (ramped over 1 ms: the peak comes after about 40
  P-wave transits of the sample, quasi-static), local damping 0.7, until the
  stress falls below 60 % of its peak after it (or 4e-3 strain). E: the secant slope
  between 20 % and 50 % of the peak; UCS the peak.
- Brazilian test: a disc of 0.1 m diameter of the same particles between two platens
  closing at 2 × 0.005 m/s; σ_t = 2 P_max / (π D), P_max the peak force per metre.
- Trends (P&C §4): the same sample with Ē and E_c doubled (E should double), and with
  σ̄_c and c̄ doubled (UCS should double).
- Bonded spheres: a 0.05 × 0.05 × 0.1 m prism of spheres (radii 1.25 R_min to 1.66 ×
  that, ``tdem.pack.random3d`` at 0.55 with overlaps below 5e-5 R_min), the same bonds,
  contacts k_n = E_c π R̄/2 (PFC3D's E_c A/L, A = πR², L = 2R, at the mean radius),
  between two square mesh platens: uniaxial compression and its strength trend.
- Brazilian test of bonded spheres: a disc of D = 0.1 m and thickness t = 0.05 m
  (t/D = 0.5, the ISRM's proportion; 1311 spheres at the quick preset, the radii and
  bonds of the prism), cut from a ``random3d`` packing of its bounding box (0.55):
  the spheres whose centre lies within D/2 − r/2 of the axis, so that the rim is as
  rough as half a sphere either side of the nominal diameter. At the top and bottom
  the spheres that the packing pressed flat against the box's faces form two flat
  seats, and two square mesh platens rest on them, closing as in the 2D test; σ_t =
  2 P_max/(π D t). (Keeping only the spheres wholly inside the cylinder leaves one
  sphere on top: its bonds broke at 1 % of the load and the platen then closed on
  nothing for millimetres.) The seats span 2α ≈ 30° at the quick preset
  (``seat_angle_deg``); Hondros' solution for a load spread over such arcs puts the
  centre's tension at (sin 2α − α)/sin α ≈ 0.92 × 2P/(πDt) (``hondros_factor``,
  reported, not applied: the 2D disc rests on single discs and uses the line-load
  formula, and so does this one).
- The splitting: the share of the Brazilian cracks (discs and spheres) within ±D/8 of
  the loaded diameter, against the share of the disc's area in that band, 0.315,
  where evenly spread cracks would lie; the check: most (above 0.5) lie there, and most
  are tension cracks.
- The continua: the stress–strain curves of the same rock as Mohr–Coulomb continua,
  ``uniaxial_compression``'s PCMM random model and FVM regular mesh (UC_MODELS: a
  random packing as the bonded particles', and the mesh), are made by running that
  case's own ``run`` for those two models at the same preset into
  OUT/uniaxial_compression (its summary.json, histories.h5 and plots, as that case
  writes them; about 30 s at the quick preset), so that the curves are that case's
  and no copy of its set-up lives here; ``--curves DIR`` reads them instead from the
  histories.h5 of a folder that case wrote (any preset, e.g. docs/validation's). They
  are loaded by a top plate at 0.1 m/s with the bottom fixed (strain rate 0.5/s,
  10 × the bonded samples', and their curves keep the steps of the stress waves); E
  of each as its case measures it (continua: least squares over strain 0.1e-3 to
  0.3e-3; bonded: the secant above, their peaks coming before 0.1e-3), UCS the peak.
  ``models_stress_strain.png``: axial stress against axial strain of the four, the
  Mohr–Coulomb UCS dashed; on the right the bonded particles' range enlarged.

What is compared: the trends (within 5 % and 15 %), the ratio σ_t/σ_c of discs and
of spheres beside the rock's T/UCS = 0.078 (P&C: the parallel bond overestimates it,
≈ 0.25 for their granite model against ≈ 0.05–0.1 for rock; the check: above the
rock's), the Brazilian splitting (above), E and UCS reported beside the rock's
E/(1 − ν²) = 32 GPa and 12.87 MPa and beside the PCMM and FVM models of
``uniaxial_compression`` (summary.json ``data.models``), and the cracks' modes (P&C:
most in tension).

Outputs (``--out DIR``, default out/bonded_rock): ``summary.json``,
``stress_strain.png`` (the bonded samples, the Brazilian tests), ``cracks.png``,
``models_stress_strain.png`` and the folder uniaxial_compression (above).
"""
import math
from pathlib import Path

import numpy as np

import tdem

from . import _common as common

CASE = "bonded_rock"
PAPER = "Potyondy & Cundall (2004), Int. J. Rock Mech. Min. Sci. 41:1329"
E_ROCK, NU, COH, TENS, PHI, RHO = 30e9, 0.25, 3e6, 1e6, 40.0, 2500.0
UCS_MC = 2 * COH * math.cos(math.radians(PHI)) / (1 - math.sin(math.radians(PHI)))
KAPPA = 2.5
WIDTH, HEIGHT, DIAM = 0.1, 0.2, 0.1
SPEED = 0.005             # m/s, each platen
RAMP = 1e-3               # s
DAMPING = 0.7
FRACTION = 0.80
SIDE3D, HEIGHT3D, FRACTION3D = 0.05, 0.1, 0.55
THICK3D = 0.05
BAND = 0.25                # the central band: ±BAND·R about the loaded diameter
UC_MODELS = ("random", "fvm")
PRESETS = {"quick": {"rmin": 2e-3, "seed": 1}, "paper": {"rmin": 1e-3, "seed": 1}}


def laws(scale_modulus=1.0, scale_strength=1.0):
    ec = E_ROCK * scale_modulus
    contact = tdem.LinearContact(kn=ec, ks=ec / KAPPA, friction=0.5)
    bond = tdem.ParallelBond(young=ec, stiffness_ratio=KAPPA,
                             tensile_strength=TENS * scale_strength,
                             cohesion=COH * scale_strength, friction_angle=PHI)
    return contact, bond


def _ramp(t):
    return SPEED * (0.5 - 0.5 * math.cos(math.pi * min(t / RAMP, 1.0)))


def specimen(cfg, shape, opts, scale_modulus=1.0, scale_strength=1.0):
    """A bonded sample between two platens: ``shape`` "prism" (0.1 × 0.2 m) or "disc"
    (0.1 m diameter). Returns (sim, top wall, bottom wall, height)."""
    rmin = cfg["rmin"]
    rmax = 1.66 * rmin
    if shape == "prism":
        x, r = tdem.pack.random(WIDTH, HEIGHT, rmin, rmax, seed=cfg["seed"],
                                target_fraction=FRACTION, overlap_tol=5e-5)
        h = HEIGHT
        lo, hi = 0.0, HEIGHT
        x0, x1 = -0.5 * WIDTH, 1.5 * WIDTH
    else:
        th = np.linspace(0, 2 * np.pi, 97)[:-1]
        poly = np.stack([0.5 * DIAM * np.cos(th), 0.5 * DIAM * np.sin(th)], 1) + 0.5 * DIAM
        x, r = tdem.pack.random(None, None, rmin, rmax, seed=cfg["seed"],
                                target_fraction=FRACTION, overlap_tol=5e-5, polygon=poly)
        h = DIAM
        lo, hi = float((x[:, 1] - r).min()), float((x[:, 1] + r).max())
        x0, x1 = -0.5 * DIAM, 1.5 * DIAM
    sim = tdem.Simulation(gravity=(0.0, 0.0), local_damping=DAMPING, progress=False,
                          **opts)
    contact, bond = laws(scale_modulus, scale_strength)
    g = sim.add_particles(x, r, density=RHO, contact=contact)
    made = sim.bond(g, bond, gap=0.05 * rmin)
    bottom = sim.add_wall((x1, lo), (x0, lo), contact=contact)
    top = sim.add_wall((x0, hi), (x1, hi), contact=contact)
    return sim, top, bottom, h, made


def load(sim, top, bottom, h, max_strain=4e-3, drop=0.6, every=100):
    """Close the platens until the force falls below ``drop`` × its peak after it;
    returns arrays (strain, stress-per-width force, cracks)."""
    rows = []
    peak = 0.0
    while True:
        v = _ramp(sim.time)
        top.velocity = (0.0, -v)
        bottom.velocity = (0.0, v)
        sim.run(steps=every)
        f = 0.5 * (top.force[1] - bottom.force[1])
        strain = (rows[-1][0] if rows else 0.0) + 2 * v * every * sim.dt / h
        rows.append((strain, f, len(sim.cracks)))
        peak = max(peak, f)
        if strain >= max_strain or (peak > 0 and f < drop * peak and f < rows[-2][1]):
            break
    return np.array(rows)


def secant(strain, stress):
    """(E, peak): the secant slope of stress against strain between 20 % and 50 % of
    the peak, before it (the first and last points in that range), and the peak."""
    strain, stress = np.asarray(strain, float), np.asarray(stress, float)
    k = int(np.argmax(stress))
    peak = float(stress[k])
    sel = (stress[:k + 1] >= 0.2 * peak) & (stress[:k + 1] <= 0.5 * peak)
    lo, hi = np.flatnonzero(sel)[[0, -1]] if sel.sum() >= 2 else (0, k)
    e_mod = float((stress[hi] - stress[lo]) / (strain[hi] - strain[lo])) if hi > lo else \
        float("nan")
    return e_mod, peak


def _tension(c):
    return float(np.mean(c["mode"] == 0)) if len(c["mode"]) else None


def uniaxial(cfg, opts, **scale):
    sim, top, bottom, h, made = specimen(cfg, "prism", opts, **scale)
    hist = load(sim, top, bottom, h)
    stress = hist[:, 1] / WIDTH
    e_mod, peak = secant(hist[:, 0], stress)
    c = sim.cracks.numpy()
    return {"ucs": peak, "E": e_mod, "strain": hist[:, 0], "stress": stress,
            "particles": sim.n_particles, "bonds": made, "cracks": len(c["time"]),
            "tension_fraction": _tension(c),
            "crack_xy": c["position"], "crack_mode": c["mode"],
            "xy": sim.particles.numpy()["position"], "steps": sim.steps, "dt": sim.dt}


def _spheres(cfg, opts, x, r, scale_modulus=1.0, scale_strength=1.0):
    """A simulation of bonded spheres at (x, r): contacts k_n = E_c π R̄/2 (PFC3D's
    E_c A/L, A = π R², L = 2R, at the mean radius), the bonds of :func:`laws` made
    between spheres within 5 % of R_min. Returns (sim, contact law, bonds made)."""
    rmin = 1.25 * cfg["rmin"]
    sim = tdem.Simulation(dim=3, gravity=(0.0, 0.0, 0.0), local_damping=DAMPING,
                          progress=False, **opts)
    ec = E_ROCK * scale_modulus
    kn = ec * math.pi * float(np.mean(r)) / 2.0
    contact = tdem.LinearContact(kn=kn, ks=kn / KAPPA, friction=0.5)
    _, bond = laws(scale_modulus, scale_strength)
    g = sim.add_particles(x, r, density=RHO, contact=contact)
    made = sim.bond(g, bond, gap=0.05 * rmin)
    return sim, contact, made


def _platens3d(sim, contact, centre, lo, hi, size):
    """Two square mesh platens of side ``size`` at z = lo (facing up) and z = hi
    (facing down), centred over ``centre`` (x, y). Returns (top, bottom)."""
    v, t = tdem.surfaces.plane((centre[0], centre[1], lo), (0.0, 0.0, 1.0), size)
    bottom = sim.add_mesh(v, t, contact=contact)
    v2, t2 = tdem.surfaces.plane((centre[0], centre[1], hi), (0.0, 0.0, -1.0), size)
    top = sim.add_mesh(v2, t2, contact=contact)
    return top, bottom


def specimen3d(cfg, opts, scale_modulus=1.0, scale_strength=1.0):
    """Bonded spheres: a 0.05 × 0.05 × 0.1 m prism (radii R_min·1.25 to 1.66·that),
    platens (square meshes) below and above. Returns (sim, top, bottom, height,
    bonds made)."""
    rmin = 1.25 * cfg["rmin"]
    x, r = tdem.pack.random3d((0.0, 0.0, 0.0), (SIDE3D, SIDE3D, HEIGHT3D), rmin,
                              1.66 * rmin, seed=cfg["seed"], target_fraction=FRACTION3D,
                              overlap_tol=5e-5)
    sim, contact, made = _spheres(cfg, opts, x, r, scale_modulus, scale_strength)
    top, bottom = _platens3d(sim, contact, (0.5 * SIDE3D, 0.5 * SIDE3D), 0.0, HEIGHT3D,
                             2 * SIDE3D)
    return sim, top, bottom, HEIGHT3D, made


def load3d(sim, top, bottom, h, area, max_strain=4e-3, drop=0.6, every=100):
    """:func:`load` for spheres between mesh platens (loaded along z): returns arrays
    (strain, platen force / ``area``, cracks)."""
    rows, peak = [], 0.0
    while True:
        v = _ramp(sim.time)
        top.velocity = (0.0, 0.0, -v)
        bottom.velocity = (0.0, 0.0, v)
        sim.run(steps=every)
        f = 0.5 * (top.force[2] - bottom.force[2])
        strain = (rows[-1][0] if rows else 0.0) + 2 * v * every * sim.dt / h
        rows.append((strain, f / area, len(sim.cracks)))
        peak = max(peak, rows[-1][1])
        if strain >= max_strain or (peak > 0 and rows[-1][1] < drop * peak
                                    and rows[-1][1] < rows[-2][1]):
            break
    return np.array(rows)


def uniaxial3d(cfg, opts, **scale):
    sim, top, bottom, h, made = specimen3d(cfg, opts, **scale)
    hist = load3d(sim, top, bottom, h, SIDE3D ** 2)
    stress = hist[:, 1]
    e_mod, peak = secant(hist[:, 0], stress)
    c = sim.cracks.numpy()
    return {"ucs": peak, "E": e_mod, "strain": hist[:, 0], "stress": stress,
            "particles": sim.n_particles, "bonds": made, "cracks": len(c["time"]),
            "tension_fraction": _tension(c), "steps": sim.steps, "dt": sim.dt}


def specimen3d_disc(cfg, opts):
    """Bonded spheres: a disc of diameter 0.1 m and thickness THICK3D (axis along y)
    cut from a random packing of its bounding box: the spheres whose centre lies within
    D/2 − r/2 of the axis (the rim as rough as half a sphere either side of the nominal
    diameter); at the top and bottom the spheres the packing pressed flat against the
    box's faces form two flat seats, on which two square mesh platens rest. Returns
    (sim, top, bottom, height, bonds made, seat half-width)."""
    rmin = 1.25 * cfg["rmin"]
    x, r = tdem.pack.random3d((0.0, 0.0, 0.0), (DIAM, THICK3D, DIAM), rmin, 1.66 * rmin,
                              seed=cfg["seed"], target_fraction=FRACTION3D,
                              overlap_tol=5e-5)
    keep = np.hypot(x[:, 0] - 0.5 * DIAM, x[:, 2] - 0.5 * DIAM) <= 0.5 * DIAM - 0.5 * r
    x, r = x[keep], r[keep]
    sim, contact, made = _spheres(cfg, opts, x, r)
    lo, hi = float((x[:, 2] - r).min()), float((x[:, 2] + r).max())
    top, bottom = _platens3d(sim, contact, (0.5 * DIAM, 0.5 * THICK3D), lo, hi, 1.5 * DIAM)
    # the seats: the spheres touching a platen at the start (within 1 % of R_min)
    seated = (x[:, 2] + r >= hi - 0.01 * rmin) | (x[:, 2] - r <= lo + 0.01 * rmin)
    seat = float(np.abs(x[seated, 0] - 0.5 * DIAM).max())
    return sim, top, bottom, hi - lo, made, seat


def band_share(a):
    """The share of a disc's area within ±a·R of a diameter: where cracks spread evenly
    over the disc would lie."""
    return 2.0 * (a * math.sqrt(1.0 - a * a) + math.asin(a)) / math.pi


def in_band(xy, centre, half_width):
    """The share of the points ``xy`` (the cracks) within ``half_width`` of the loaded
    diameter x = ``centre`` (None: no cracks)."""
    return float(np.mean(np.abs(xy[:, 0] - centre) <= half_width)) if len(xy) else None


def hondros(alpha):
    """Hondros' tensile stress at the centre of a disc loaded over two arcs 2α (radial
    pressure), over 2P/(πDt) of a line load: (sin 2α − α)/sin α."""
    return (math.sin(2 * alpha) - alpha) / math.sin(alpha) if alpha > 0 else 1.0


def brazilian3d(cfg, opts):
    sim, top, bottom, h, made, seat = specimen3d_disc(cfg, opts)
    hist = load3d(sim, top, bottom, h, 1.0, max_strain=2e-2)
    p = float(hist[:, 1].max())
    c = sim.cracks.numpy()
    alpha = math.asin(min(1.0, seat / (0.5 * DIAM)))
    return {"sigma_t": 2 * p / (math.pi * DIAM * THICK3D), "P_max": p,
            "thickness": THICK3D, "strain": hist[:, 0],
            "nominal": 2 * hist[:, 1] / (math.pi * DIAM * THICK3D),
            "particles": sim.n_particles, "bonds": made, "cracks": len(c["time"]),
            "crack_xy": c["position"][:, [0, 2]], "crack_mode": c["mode"],
            "xy": sim.particles.numpy()["position"][:, [0, 2]],
            "tension_fraction": _tension(c),
            "central_band": in_band(c["position"], 0.5 * DIAM, BAND * 0.5 * DIAM),
            "seat_half_width": seat, "seat_angle_deg": math.degrees(2 * alpha),
            "hondros_factor": hondros(alpha), "steps": sim.steps, "dt": sim.dt}


def brazilian(cfg, opts):
    sim, top, bottom, h, made = specimen(cfg, "disc", opts)
    hist = load(sim, top, bottom, h, max_strain=2e-2)
    p = float(hist[:, 1].max())
    c = sim.cracks.numpy()
    return {"sigma_t": 2 * p / (math.pi * DIAM), "P_max": p, "strain": hist[:, 0],
            "nominal": 2 * hist[:, 1] / (math.pi * DIAM), "particles": sim.n_particles,
            "bonds": made, "cracks": len(c["time"]), "crack_xy": c["position"],
            "crack_mode": c["mode"], "xy": sim.particles.numpy()["position"],
            "tension_fraction": _tension(c),
            "central_band": in_band(c["position"], 0.5 * DIAM, BAND * 0.5 * DIAM),
            "steps": sim.steps, "dt": sim.dt}


def continuum_curves(preset, out, opts, source=None):
    """The stress–strain curves of ``uniaxial_compression``'s models UC_MODELS (the same
    rock as Mohr–Coulomb continua): read from ``source``/histories.h5 (a folder that
    case wrote) if given, else made by running that case's ``run`` for those models at
    ``preset`` into out/uniaxial_compression. Returns ({name: {strain, stress, label,
    E, ucs, elastic_slope}}, where they came from)."""
    import json

    import h5py

    from . import _pcmm
    from . import uniaxial_compression as uc
    if source is None:
        folder = out / uc.CASE
        uc.run(preset, folder, models=list(UC_MODELS), arch=opts.get("arch"),
               threads=opts.get("threads"))
        origin = {"ran": f"cases.uniaxial_compression, preset {preset}, models "
                         f"{', '.join(UC_MODELS)}", "folder": uc.CASE}
    else:
        folder = Path(source)
        meta = folder / "summary.json"
        ran = json.loads(meta.read_text()).get("preset") if meta.exists() else None
        origin = {"read": str(folder / "histories.h5"), "preset": ran}
    curves = {}
    with h5py.File(folder / "histories.h5", "r") as f:
        for name in UC_MODELS:
            if name not in f:
                print(f"  {name}: not in {folder / 'histories.h5'}", flush=True)
                continue
            strain, stress = np.asarray(f[name]["strain"]), np.asarray(f[name]["stress"])
            e_mod, peak = secant(strain, stress)
            curves[name] = {"strain": strain, "stress": stress, "label": _pcmm.LABELS[name],
                            "E": e_mod, "ucs": peak,
                            "elastic_slope": uc.elastic_slope(strain, stress)}
    return curves, origin


def plots(base, stiff, strong, braz, out, sph=None, sph2=None, braz3=None, curves=None):
    plt = common.pyplot()
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 4))
    for r, lab in ((base, "Ē = E_c = 30 GPa, σ̄_c = T, c̄ = c"), (stiff, "moduli × 2"),
                   (strong, "strengths × 2")):
        ax.plot(1e3 * r["strain"], r["stress"] / 1e6, label=lab)
    for r, lab in ((sph, "bonded spheres"), (sph2, "bonded spheres, strengths × 2")):
        if r is not None:
            ax.plot(1e3 * r["strain"], r["stress"] / 1e6, ls="-.", label=lab)
    runs = [r for r in (base, stiff, strong, sph, sph2) if r is not None]
    top = max(float(r["stress"].max()) for r in runs)
    right = max(float(r["strain"][-1]) for r in runs)
    e = np.linspace(0, 1.1 * right, 5)
    ax.plot(1e3 * e, E_ROCK / (1 - NU ** 2) * e / 1e6, "k--", lw=0.8,
            label=f"rock's E/(1−ν²) (its UCS: {UCS_MC / 1e6:.2f} MPa)")
    ax.set_xlim(0, 1e3 * 1.1 * right)
    ax.set_ylim(0, 1.25 * top / 1e6)
    ax.set_xlabel("axial strain (‰)")
    ax.set_ylabel("axial stress (MPa)")
    ax.set_title("Uniaxial compression of bonded discs and spheres", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    bx.plot(1e3 * braz["strain"], braz["nominal"] / 1e6,
            label=f"discs: σ_t = {braz['sigma_t'] / 1e6:.2f} MPa")
    if braz3 is not None:
        bx.plot(1e3 * braz3["strain"], braz3["nominal"] / 1e6, ls="-.",
                label=f"spheres (t = {braz3['thickness']:g} m): σ_t = "
                      f"{braz3['sigma_t'] / 1e6:.2f} MPa")
    bx.set_xlabel("platen closure / diameter (‰)")
    bx.set_ylabel("2P/(πDt) (MPa)")
    bx.set_title("Brazilian tests, D = 0.1 m (rock T = 1 MPa)", fontsize=10)
    bx.grid(alpha=0.3)
    bx.legend(fontsize=7)
    fig.tight_layout()
    common.save(fig, out / "stress_strain.png")

    panels = [(base, "uniaxial, discs"), (braz, "Brazilian, discs")]
    if braz3 is not None:
        panels.append((braz3, "Brazilian, spheres (x–z)"))
    fig, axes = plt.subplots(1, len(panels), figsize=(4 * len(panels), 5))
    for a, (r, title) in zip(axes, panels):
        a.scatter(r["xy"][:, 0], r["xy"][:, 1], s=1, color="0.8")
        xy, mode = r["crack_xy"], r["crack_mode"]
        if len(xy):
            a.scatter(xy[mode == 0, 0], xy[mode == 0, 1], s=4, color="C3", label="tension")
            a.scatter(xy[mode == 1, 0], xy[mode == 1, 1], s=4, color="C0", label="shear")
        a.set_aspect("equal")
        a.set_title(f"{title}: {r['cracks']} cracks", fontsize=10)
        a.legend(fontsize=7, loc="upper right")
    fig.tight_layout()
    common.save(fig, out / "cracks.png")

    if curves:
        models_plot(base, sph, curves, out / "models_stress_strain.png")


def models_plot(discs, spheres, curves, png):
    """Axial stress against axial strain of the rock as Mohr–Coulomb continua (PCMM,
    FVM) and as bonded discs and spheres, on one scale (left) and the bonded
    particles' range enlarged (right)."""
    plt = common.pyplot()
    def label(name, e_mod, ucs):
        return f"{name}: E {e_mod / 1e9:.1f} GPa, UCS {ucs / 1e6:.2f} MPa"
    lines = [(c["strain"], c["stress"], label(c["label"], c["elastic_slope"], c["ucs"]),
              "-", 1.6) for c in curves.values()]
    lines += [(discs["strain"], discs["stress"],
               label("bonded discs", discs["E"], discs["ucs"]), "-", 1.3)]
    if spheres is not None:
        lines += [(spheres["strain"], spheres["stress"],
                   label("bonded spheres", spheres["E"], spheres["ucs"]), "-.", 1.3)]
    colors = ["C2", "C3", "C0", "C1"]
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.3))
    for ax in axes:
        for (e, s, lab, ls, lw), col in zip(lines, colors):
            ax.plot(1e3 * e, s / 1e6, ls=ls, lw=lw, color=col, label=lab)
        ax.axhline(UCS_MC / 1e6, color="k", ls="--", lw=1,
                   label=f"Mohr–Coulomb UCS 2c cosφ/(1−sinφ) = {UCS_MC / 1e6:.2f} MPa")
        ax.set_xlabel("axial strain (‰)")
        ax.set_ylabel("axial stress (MPa, compression +)")
        ax.grid(alpha=0.3)
    bonded = [discs] + ([spheres] if spheres is not None else [])
    right = max(float(r["strain"][-1]) for r in bonded)
    top = max(float(r["stress"].max()) for r in bonded)
    axes[0].set_xlim(left=0)
    axes[0].set_ylim(0, 1.15 * max(UCS_MC, max(float(c["stress"].max())
                                                  for c in curves.values())) / 1e6)
    axes[0].set_title("The rock of Feng et al. 2015 §3.2: continua and bonded particles",
                      fontsize=10)
    axes[0].legend(fontsize=8, loc="lower right")
    axes[1].set_xlim(0, 1e3 * right)
    axes[1].set_ylim(0, 1.3 * top / 1e6)
    axes[1].set_title("the bonded particles' range enlarged", fontsize=10)
    fig.tight_layout()
    common.save(fig, png)


def main(argv=None):
    def extra(p):
        p.add_argument("--curves", default=None, metavar="DIR",
                       help="a folder uniaxial_compression wrote (its histories.h5): the "
                            "PCMM and FVM curves to plot beside the bonded particles' "
                            "(default: run those two models here, into OUT/"
                            "uniaxial_compression)")
    args, out = common.parse(CASE, argv, description=__doc__.splitlines()[0], extra=extra)
    clock = common.Stopwatch()
    cfg = PRESETS[args.preset]
    opts = common.sim_options(args)
    print("uniaxial", flush=True)
    base = uniaxial(cfg, opts)
    print("uniaxial, moduli × 2", flush=True)
    stiff = uniaxial(cfg, opts, scale_modulus=2.0)
    print("uniaxial, strengths × 2", flush=True)
    strong = uniaxial(cfg, opts, scale_strength=2.0)
    print("Brazilian", flush=True)
    braz = brazilian(cfg, opts)
    print("uniaxial, bonded spheres", flush=True)
    sph = uniaxial3d(cfg, opts)
    print("uniaxial, bonded spheres, strengths × 2", flush=True)
    sph2 = uniaxial3d(cfg, opts, scale_strength=2.0)
    print("Brazilian, bonded spheres", flush=True)
    braz3 = brazilian3d(cfg, opts)
    print("the continua of uniaxial_compression (PCMM, FVM)", flush=True)
    curves, origin = continuum_curves(args.preset, out, opts, args.curves)
    plots(base, stiff, strong, braz, out, sph, sph2, braz3, curves)
    ratio = braz["sigma_t"] / base["ucs"]
    ratio3 = braz3["sigma_t"] / sph["ucs"]
    share = band_share(BAND)
    checks = [
        common.check("trend.modulus", stiff["E"] / base["E"], 2.0, common.rel(0.05), "",
                     "E with Ē and E_c doubled over E (P&C: E ∝ the moduli)"),
        common.check("trend.strength", strong["ucs"] / base["ucs"], 2.0, common.rel(0.15), "",
                     "UCS with σ̄_c and c̄ doubled over UCS (P&C: UCS ∝ the bond strengths; "
                     "the contacts' friction adds a part that does not double)"),
        common.check("tension_over_compression", ratio, TENS / UCS_MC,
                     common.between(min=TENS / UCS_MC), "",
                     "σ_t (Brazilian) / UCS beside the rock's T/UCS = 0.078: the parallel "
                     "bond overestimates it (P&C: about 0.25)"),
        common.check("brazilian.tension_cracks", braz["tension_fraction"], None,
                     common.between(min=0.5), "",
                     "Brazilian disc: share of the cracks in tension (P&C: most; the disc "
                     "splits in tension)"),
        common.check("brazilian.central_band", braz["central_band"], None,
                     common.between(min=0.5), "",
                     f"Brazilian disc: share of the cracks within ±D/8 of the loaded "
                     f"diameter (the splitting along it): most, where cracks spread evenly "
                     f"would put {share:.3f} there"),
        common.check("uniaxial.E", base["E"], E_ROCK / (1 - NU ** 2), None, "Pa",
                     "secant 20–50 % of the peak, beside the rock's E/(1 − ν²)"),
        common.check("uniaxial.UCS", base["ucs"], UCS_MC, None, "Pa",
                     "peak stress beside the rock's Mohr–Coulomb strength"),
        common.check("brazilian.sigma_t", braz["sigma_t"], TENS, None, "Pa",
                     "2 P_max/(π D) beside the rock's T"),
        common.check("uniaxial.tension_cracks", base["tension_fraction"], None, None, "",
                     "share of the cracks in tension at the end (P&C: most)"),
    ]
    checks += [
        common.check("spheres.trend.strength", sph2["ucs"] / sph["ucs"], 2.0,
                     common.rel(0.15), "", "bonded spheres: UCS with the strengths doubled "
                     "over UCS"),
        common.check("spheres.tension_over_compression", ratio3, TENS / UCS_MC,
                     common.between(min=TENS / UCS_MC), "",
                     "bonded spheres: σ_t (Brazilian, 2 P_max/(π D t)) / UCS beside the "
                     "rock's T/UCS = 0.078 (P&C: the parallel bond overestimates it)"),
        common.check("spheres.brazilian.tension_cracks", braz3["tension_fraction"], None,
                     common.between(min=0.5), "",
                     "bonded spheres, Brazilian: share of the cracks in tension (P&C: most)"),
        common.check("spheres.brazilian.central_band", braz3["central_band"], None,
                     common.between(min=0.5), "",
                     f"bonded spheres, Brazilian: share of the cracks within ±D/8 of the "
                     f"loaded diameter: most, where cracks spread evenly would put "
                     f"{share:.3f} there"),
        common.check("spheres.E", sph["E"], E_ROCK, None, "Pa",
                     "bonded spheres: secant 20–50 % of the peak, beside the rock's E"),
        common.check("spheres.UCS", sph["ucs"], UCS_MC, None, "Pa",
                     "bonded spheres: the peak beside the rock's strength"),
        common.check("spheres.brazilian.sigma_t", braz3["sigma_t"], TENS, None, "Pa",
                     "bonded spheres: 2 P_max/(π D t) beside the rock's T"),
    ]
    checks.append(common.check(
        "calibration.strength_factor", UCS_MC / base["ucs"], None, None, "",
        "the factor on σ̄_c and c̄ that gives the rock's UCS (UCS ∝ the strengths, "
        "trend.strength); its σ_t would then be this × the Brazilian's"))
    keep = ("ucs", "E", "particles", "bonds", "cracks", "tension_fraction", "steps", "dt")
    secant_note = "secant 20–50 % of the peak"
    models = {name: {"label": c["label"], "E": c["elastic_slope"], "ucs": c["ucs"],
                     "E_measure": "uniaxial_compression's: least squares, strain 0.1e-3 to "
                                  "0.3e-3", "E_secant_20_50": c["E"]}
              for name, c in curves.items()}
    models["bonded_discs"] = {"label": "bonded discs", "E": base["E"], "ucs": base["ucs"],
                              "E_measure": secant_note}
    models["bonded_spheres"] = {"label": "bonded spheres", "E": sph["E"], "ucs": sph["ucs"],
                                "E_measure": secant_note}
    data = {"preset": cfg, "rock": {"E": E_ROCK, "nu": NU, "c": COH, "T": TENS, "phi": PHI,
                                     "ucs_mohr_coulomb": UCS_MC,
                                     "plane_strain_modulus": E_ROCK / (1 - NU ** 2)},
            "models": models,
            "models_note": "the rock as Mohr–Coulomb continua (uniaxial_compression) and "
                           "as bonded particles: E each as its case measures it "
                           "(E_measure), ucs the peak stress",
            "continua": origin,
            "uniaxial": {k: base[k] for k in keep},
            "moduli_x2": {k: stiff[k] for k in keep},
            "strengths_x2": {k: strong[k] for k in keep},
            "brazilian": {k: braz[k] for k in ("sigma_t", "P_max", "particles", "bonds",
                                                "cracks", "tension_fraction",
                                                "central_band", "steps", "dt")},
            "spheres": {k: sph[k] for k in keep},
            "spheres_strengths_x2": {k: sph2[k] for k in keep},
            "spheres_brazilian": {k: braz3[k] for k in (
                "sigma_t", "P_max", "thickness", "particles", "bonds", "cracks",
                "tension_fraction", "central_band", "seat_half_width", "seat_angle_deg",
                "hondros_factor", "steps", "dt")},
            "central_band_even_share": share}
    summary = common.summary(CASE, args.preset, checks, data, clock(), threads=args.threads,
                             paper=PAPER)
    common.write_summary(out, summary)
    print("model: E (GPa), UCS (MPa)")
    for m in models.values():
        print(f"  {m['label']}: {m['E'] / 1e9:.1f}, {m['ucs'] / 1e6:.2f}")
    common.print_checks(summary)
    return summary


if __name__ == "__main__":
    main()
