"""Water at rest: element water against water of Voronoi cells, step cost.

The column of ``tests/test_voronoi_water.py`` (0.3 × 0.5 m, R = 5 mm, K =
ρ(10·sqrt(2gh))², μ = 1 Pa·s, frictionless tank, local damping 0.7) on a hexagonal
lattice and on a random packing (radii 0.8–1.2 R, 76 %), as ``tdem.Fluid`` with
element pressure and with ``voronoi=True``; each model runs ``--warmup`` steps,
then ``--steps`` timed steps, in alternating rounds (``--rounds``: the machine's
speed drifts). Prints milliseconds per step and particle-steps per second, the
medians over the rounds:

    python benchmarks/water.py --threads 1
"""
import argparse
import math
import time

import numpy as np

import tdem
from cases._pcmm import water_tank

R, W, H, RHO, G = 0.005, 0.3, 0.5, 1000.0, 9.81


def model(kind, cells, threads):
    k = RHO * (10.0 * math.sqrt(2.0 * G * H)) ** 2
    water = tdem.Fluid(density=RHO, bulk_modulus=k, viscosity=1.0, voronoi=cells)
    sim = tdem.Simulation(gravity=(0.0, -G), dt_fraction=0.5, local_damping=0.7,
                          threads=threads, progress=False)
    pos, r = (tdem.pack.cross(W, H, R) if kind == "hexagonal" else
              tdem.pack.random(W, H, 0.8 * R, 1.2 * R, seed=1, target_fraction=0.76))
    sim.add_particles(pos, r, material=water, tolerance=R)
    water_tank(sim, W, 2 * H, k)
    return sim, len(r)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--threads", type=int, default=1)
    p.add_argument("--steps", type=int, default=1000)
    p.add_argument("--warmup", type=int, default=1000)
    p.add_argument("--rounds", type=int, default=2)
    args = p.parse_args(argv)
    models = {(kind, cells): model(kind, cells, args.threads)
              for kind in ("hexagonal", "random") for cells in (False, True)}
    for sim, _ in models.values():
        sim.run(steps=args.warmup)
    times = {key: [] for key in models}
    for _ in range(args.rounds):
        for key, (sim, _) in models.items():
            t0 = time.perf_counter()
            sim.run(steps=args.steps)
            times[key].append((time.perf_counter() - t0) / args.steps)
    print("| packing | water | particles | dt (s) | ms per step | particle-steps/s |")
    print("| --- | --- | --- | --- | --- | --- |")
    for (kind, cells), (sim, n) in models.items():
        t = float(np.median(times[(kind, cells)]))
        print(f"| {kind} | {'cells' if cells else 'elements'} | {n} | {sim.dt:.3g} | "
              f"{1e3 * t:.2f} | {n / t:,.0f} |")


if __name__ == "__main__":
    main()
