"""Dense 2D disc pack: the peers' benchmark workload, in tdem.

Same geometry as the peers' input (LIGGGHTS, Yade): 200 rows of discs of diameter
4 mm on a hexagonal lattice, resting under gravity in a box 0.8 m wide (walls left,
right, bottom), linear spring–dashpot contacts with history friction (mu = 0.5,
e = 0.5), density 2500, dt = 1e-5 s, 2,000 warm-up steps then N timed steps.

Discs in 2D have mass rho·pi·r² per metre; k_n is chosen so that the contact
period sqrt(m/k) equals the peers' (Hertz-derived LIGGGHTS "hooke" stiffness for
3D spheres of the same diameter), so the dynamics and the neighbour-rebuild rate
match.

Prints ``PEER tdem <threads> particle_steps_per_s <value>`` like the peers' script.

    python benchmarks/pack2d.py --threads 1            # the 40k workload
    python benchmarks/pack2d.py --threads 2
    python benchmarks/pack2d.py --scaling              # 10k ... 160k discs
"""
import argparse
import json
import math
import os
import subprocess
import sys
import time

import numpy as np


def peer_kn():
    """LIGGGHTS 'hooke' k_n for the peers' spheres (E=1e7, nu=0.3, e=0.5, v_char=1)."""
    r, rho, young, nu, vchar = 0.002, 2500.0, 1e7, 0.3, 1.0
    m = rho * 4.0 / 3.0 * math.pi * r ** 3
    mstar, rstar = m / 2.0, r / 2.0
    ystar = young / (2.0 * (1.0 - nu ** 2))
    return 16.0 / 15.0 * math.sqrt(rstar) * ystar * (
        15.0 * mstar * vchar ** 2 / (16.0 * math.sqrt(rstar) * ystar)) ** 0.2, m


def build(rows=200, cols=200, arch=None, threads=None):
    import tdem
    a = 0.004
    r = 0.5 * a
    h = a * math.sqrt(3) / 2
    width = cols * a
    pts = []
    for j in range(rows):
        for i in range(cols):
            x = r + i * a + (r if j % 2 else 0.0)
            if x > width - r + 1e-9:
                continue
            pts.append((x, 0.00173 + j * h))
    pts = np.array(pts)
    k3, m3 = peer_kn()
    m2 = 2500.0 * math.pi * r ** 2
    kn = k3 * m2 / m3
    law = tdem.LinearContact(kn=kn, ks=kn, friction=0.5, restitution=0.5)
    sim = tdem.Simulation(gravity=(0.0, -9.81), dt=1e-5, arch=arch, threads=threads,
                          skin=0.0004, check_interval=500, progress=False)
    sim.add_particles(pts, r, density=2500.0, contact=law)
    top = pts[:, 1].max() + 0.1
    sim.add_wall((0.0, top), (0.0, 0.0), contact=law)
    sim.add_wall((width, 0.0), (width, top), contact=law)
    sim.add_wall((-0.01, 0.0), (width + 0.01, 0.0), contact=law)
    return sim


def measure(rows, cols, steps, warmup, arch, threads):
    sim = build(rows, cols, arch, threads)
    sim.run(steps=warmup)
    t = time.perf_counter()
    sim.run(steps=steps)
    sim.particles.numpy()  # waits for the device
    el = time.perf_counter() - t
    return sim.n_particles, sim.n_particles * steps / el, el


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--threads", type=int, default=1)
    p.add_argument("--steps", type=int, default=2000)
    p.add_argument("--warmup", type=int, default=2000)
    p.add_argument("--arch", default=None)
    p.add_argument("--rows", type=int, default=200)
    p.add_argument("--cols", type=int, default=200)
    p.add_argument("--scaling", action="store_true",
                   help="run 10k, 20k, 40k, 80k, 160k discs, one process each")
    p.add_argument("--json", default=None, help="append the results to this JSON file")
    args = p.parse_args(argv)
    if args.scaling:
        for n in (10_000, 20_000, 40_000, 80_000, 160_000):
            side = int(round(math.sqrt(n)))
            cmd = [sys.executable, __file__, "--threads", str(args.threads), "--steps",
                   str(args.steps), "--warmup", str(args.warmup), "--rows", str(side),
                   "--cols", str(side)] + (["--arch", args.arch] if args.arch else [])
            out = subprocess.run(cmd, capture_output=True, text=True, check=True).stdout
            line = [ln for ln in out.splitlines() if ln.startswith("PEER")][-1]
            print(line, f"n={side * side}", flush=True)
        return
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
    n, rate, el = measure(args.rows, args.cols, args.steps, args.warmup, args.arch, args.threads)
    print(f"particles {n} steps {args.steps} seconds {el:.3f}")
    print(f"PEER tdem {args.threads} particle_steps_per_s {rate:.0f}", flush=True)
    if args.json:
        rec = {"particles": n, "threads": args.threads, "steps": args.steps,
               "seconds": el, "particle_steps_per_s": rate, "arch": args.arch or "cpu"}
        data = json.load(open(args.json)) if os.path.exists(args.json) else []
        data.append(rec)
        json.dump(data, open(args.json, "w"), indent=1)


if __name__ == "__main__":
    main()
