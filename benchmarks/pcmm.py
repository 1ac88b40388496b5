"""PCMM throughput: a Mohr–Coulomb column collapsing under gravity.

A column of PCMM particles (R = 1 cm, δ = R, 200 × 200 = 40,000 particles by
default; 4 m wide and high) of a weak Mohr–Coulomb soil (ρ = 2000,
E = 10 MPa, ν = 0.3, c = 1 kPa, φ = 30°, T = 0.5 kPa, brittle) stands on a
frictional floor with no side support: it yields, elements are deleted and
created as it slumps and spreads, and touching particles that share no element
interact through the contact law. After the warm-up the timed steps are in the
large-deformation regime.

``--packing`` chooses the particles: ``regular`` (square lattice, the default),
``cross`` (hexagonal lattice, the DEM pack's; the column is √3/2 as high, for the
same count) or ``random`` (``tdem.pack.random``, radii 0.8–1.2 R at 80 % area
fraction; about 40,200 particles, 15 s to pack) or ``dense`` (the random packing
a PCMM body wants: 88 % with overlaps up to 0.7 rmin, the holes of its element
cover filled, ``pcmm_tolerance``; about 45,000 particles, 20 s to pack). The
square lattice is the heaviest: with δ = R both diagonals of each square are
element edges, so it holds four overlapping elements per particle (N_e = 2),
twice the others' two.

Prints particle-steps per second of the PCMM run and of the DEM pack benchmark
(``pack2d.py``'s workload), and their ratio. The machine's speed drifts, so both
run in the same process and are timed in alternating rounds (``--rounds``; each
round times a share of the PCMM steps, then four times as many DEM steps); the
rates printed are the medians over the rounds and the ratio is the median of the
rounds' ratios, with its range:

    python benchmarks/pcmm.py --threads 2
    python benchmarks/pcmm.py --threads 1 --side 100      # 10,000 particles
    python benchmarks/pcmm.py --threads 2 --packing random
"""
import argparse
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))


PACKINGS = ("regular", "cross", "random", "dense")


def build(side=200, arch=None, threads=None, packing="regular", mixed=True):
    import tdem
    r = 0.01
    w = 2 * r * side
    if packing == "regular":
        pos, rad = tdem.pack.regular(w, w, r)
    elif packing == "cross":
        pos, rad = tdem.pack.cross(w, w * np.sqrt(3.0) / 2.0, r)
    elif packing == "random":
        pos, rad = tdem.pack.random(w, w, 0.8 * r, 1.2 * r, seed=1, target_fraction=0.8)
    elif packing == "dense":
        pos, rad = tdem.pack.random(w, w, 0.8 * r, 1.2 * r, seed=1, target_fraction=0.88,
                                    overlap_tol=0.7, pcmm_tolerance=r)
    else:
        raise ValueError(f"packing must be one of {PACKINGS}, got {packing!r}")
    soil = tdem.MohrCoulomb(density=2000.0, young=10e6, poisson=0.3, cohesion=1e3,
                            friction_angle=30.0, tensile_strength=500.0, brittle=True)
    law = tdem.LinearContact(kn=10e6, ks=10e6, friction=0.5)
    sim = tdem.Simulation(gravity=(0.0, -9.81), dt_fraction=0.4, arch=arch, threads=threads,
                          check_interval=500, progress=False, local_damping=0.05,
                          mixed_discretization=mixed)
    sim.add_particles(pos, rad, material=soil, tolerance=r, contact=law)
    sim.add_wall((-10.0, 0.0), (12.0, 0.0), contact=law)
    return sim


def _timed(sim, steps):
    """Seconds for ``steps`` steps of ``sim`` (waiting for the device)."""
    import taichi as ti
    ti.sync()
    t = time.perf_counter()
    sim.run(steps=steps)
    ti.sync()
    return time.perf_counter() - t


def measure(side, steps, warmup, arch, threads, rounds=5, dem=True, packing="regular",
            mixed=True):
    """Rates (particle-steps/s) of the PCMM column and, if ``dem``, of the DEM pack,
    timed in ``rounds`` alternating rounds after their warm-ups: (PCMM info, list of
    PCMM rates, list of DEM rates, DEM particle count)."""
    from benchmarks.pack2d import build as build_dem
    sim = build(side, arch, threads, packing, mixed)
    sim.run(steps=warmup)
    pack = None
    if dem:
        pack = build_dem(200, 200, arch, threads)
        pack.run(steps=2000)
    per = max(1, steps // rounds)
    rates, dem_rates = [], []
    for _ in range(rounds):
        rates.append(sim.n_particles * per / _timed(sim, per))
        if pack is not None:
            dem_rates.append(pack.n_particles * 4 * per / _timed(pack, 4 * per))
    p = sim.particles.numpy()
    info = {"particles": sim.n_particles, "steps": per * rounds, "dt": sim.dt, "time": sim.time,
            "elements": len(sim.elements.numpy()["triangles"]),
            "failed_fraction": float(np.mean(p["failed"])),
            "spread": float(np.ptp(p["position"][:, 0]))}
    return info, rates, dem_rates, (pack.n_particles if pack is not None else 0)


def machine():
    """One line naming the CPU, its count and cache sizes (Linux; what is not found is
    left out): the rates and their ratio differ much between machines."""
    import glob
    import platform
    name = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as f:
            names = [ln.split(":", 1)[1].strip() for ln in f if ln.startswith("model name")]
        name = names[0] if names else name
    except OSError:
        pass
    caches = {}
    for d in sorted(glob.glob("/sys/devices/system/cpu/cpu0/cache/index*")):
        try:
            with open(os.path.join(d, "level")) as f:
                level = f.read().strip()
            with open(os.path.join(d, "type")) as f:
                kind = f.read().strip()
            with open(os.path.join(d, "size")) as f:
                size = f.read().strip()
        except OSError:
            continue
        if kind != "Instruction":
            caches[f"L{level}"] = size
    parts = [name, f"{os.cpu_count()} CPUs"] + [f"{k} {v}" for k, v in sorted(caches.items())]
    return ", ".join(parts)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--side", type=int, default=200, help="particles per row (side²)")
    p.add_argument("--packing", choices=PACKINGS, default="regular")
    p.add_argument("--steps", type=int, default=500, help="timed PCMM steps, over all rounds")
    p.add_argument("--warmup", type=int, default=1500)
    p.add_argument("--rounds", type=int, default=5,
                   help="alternating timed rounds of the PCMM column and the DEM pack")
    p.add_argument("--arch", default=None)
    p.add_argument("--no-dem", action="store_true", help="skip the DEM pack reference")
    p.add_argument("--no-mixed", action="store_true",
                   help="Simulation(mixed_discretization=False): the elements' own update")
    args = p.parse_args(argv)
    if args.rounds < 1:
        p.error(f"--rounds must be >= 1, got {args.rounds}")
    r, rates, dem_rates, n_dem = measure(args.side, args.steps, args.warmup, args.arch,
                                         args.threads, args.rounds, not args.no_dem,
                                         args.packing, not args.no_mixed)
    rate = float(np.median(rates))
    print(f"machine: {machine()}")
    print(f"PCMM {args.packing} particles {r['particles']} steps {r['steps']} in {args.rounds} rounds "
          f"(t = {r['time']:.4g} s, dt = {r['dt']:.3g} s, {r['elements']} elements, "
          f"{100 * r['failed_fraction']:.0f} % failed, spread {r['spread']:.3f} m)")
    print("PCMM rounds " + " ".join(f"{x:.0f}" for x in rates))
    print(f"PCMM tdem {args.threads} particle_steps_per_s {rate:.0f}", flush=True)
    if dem_rates:
        ratios = np.array(rates) / np.array(dem_rates)
        print("DEM pack rounds " + " ".join(f"{x:.0f}" for x in dem_rates))
        print(f"DEM pack tdem {args.threads} particle_steps_per_s {np.median(dem_rates):.0f} "
              f"({n_dem} discs)")
        print(f"ratio PCMM/DEM {np.median(ratios):.3f} (rounds {ratios.min():.3f}-{ratios.max():.3f})")


if __name__ == "__main__":
    main()
