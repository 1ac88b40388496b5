"""Bonded specimens: the cost of parallel bonds per step, beside the same pack unbonded.

A 2D specimen of discs (hexagonal lattice of touching discs, R = 1 mm, jittered by
0.1 % R) or a 3D one of spheres (simple cubic lattice of touching spheres), every
touching pair bonded (``tdem.ParallelBond``, Ē = 30 GPa) or not, compressed slowly
by two platens (the bonds stay intact): ``--steps`` timed steps after a warm-up,
particle-steps per second of each and their ratio.

    python benchmarks/bonds.py --dim 2 --n 40000 --threads 2
    python benchmarks/bonds.py --dim 3 --n 50000 --threads 2

With ``--wet`` the pair compared is the dry pack and the same pack with wet contacts
(``tdem.WetContact``, a law with a range: a liquid bridge at every contact, V = 1e-12 m³,
rupture distance 0.1 R), the cost of evaluating pairs across a gap.
"""
import argparse
import math
import time

import numpy as np


def specimen(dim, n, bonded, threads, wet=False):
    import tdem
    r = 1e-3
    if dim == 2:
        cols = int(math.sqrt(n / 0.866))
        rows = int(math.ceil(n / cols))
        j, i = np.divmod(np.arange(rows * cols), cols)
        x = np.stack([(2 * i + (j % 2)) * r, j * math.sqrt(3) * r], 1)[:n]
    else:
        side = int(round(n ** (1 / 3)))
        g = np.stack(np.meshgrid(*(np.arange(side),) * 3, indexing="ij"), -1).reshape(-1, 3)
        x = (g * 2 * r)[:n]
    x = x + np.random.default_rng(0).uniform(-1e-3 * r, 1e-3 * r, x.shape)
    sim = tdem.Simulation(dim=dim, gravity=(0.0,) * dim, local_damping=0.7,
                          progress=False, threads=threads)
    e = 30e9
    kn = e if dim == 2 else e * math.pi * r / 2
    law = tdem.LinearContact(kn=kn, ks=kn / 2.5, friction=0.5)
    pair_law = law
    if wet:
        pair_law = tdem.WetContact(law, tdem.LiquidBridge(volume=1e-12))
    g = sim.add_particles(x, r, density=2500.0, contact=pair_law)
    made = sim.bond(g, tdem.ParallelBond(young=e, stiffness_ratio=2.5), gap=1e-2 * r) \
        if bonded else 0
    top = float(x[:, -1].max()) + r
    if dim == 2:
        lo, hi = float(x[:, 0].min()) - 5 * r, float(x[:, 0].max()) + 5 * r
        sim.add_wall((hi, -r), (lo, -r), contact=law)
        w2 = sim.add_wall((lo, top), (hi, top), contact=law)
        w2.velocity = (0.0, -1e-3)
    else:
        c = 0.5 * float(x[:, 0].max())
        v, t = tdem.surfaces.plane((c, c, -r), (0.0, 0.0, 1.0), 3 * c + 10 * r)
        sim.add_mesh(v, t, contact=law)
        v, t = tdem.surfaces.plane((c, c, top), (0.0, 0.0, -1.0), 3 * c + 10 * r)
        m = sim.add_mesh(v, t, contact=law)
        m.velocity = (0.0, 0.0, -1e-3)
    return sim, made


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--dim", type=int, default=2, choices=(2, 3))
    ap.add_argument("--n", type=int, default=40000)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--steps", type=int, default=1000)
    ap.add_argument("--warmup", type=int, default=200)
    ap.add_argument("--wet", action="store_true",
                    help="compare wet contacts (a law with a range) with dry ones")
    args = ap.parse_args()
    rate = {}
    for bonded in (False, True):
        if args.wet:
            sim, made = specimen(args.dim, args.n, False, args.threads, wet=bonded)
        else:
            sim, made = specimen(args.dim, args.n, bonded, args.threads)
        sim.run(steps=args.warmup)
        t0 = time.perf_counter()
        sim.run(steps=args.steps)
        wall = time.perf_counter() - t0
        rate[bonded] = sim.n_particles * args.steps / wall
        print(f"{args.dim}D, {sim.n_particles} particles, {made} bonds: {args.steps} steps in "
              f"{wall:.1f} s, {rate[bonded]:.3g} particle-steps/s"
              + (f", {len(sim.cracks)} broken" if bonded and not args.wet else "")
              + (" (wet)" if bonded and args.wet else ""), flush=True)
    if args.wet:
        print(f"wet / dry: {rate[True] / rate[False]:.2f}")
    else:
        print(f"bonded / unbonded: {rate[True] / rate[False]:.2f}")


if __name__ == "__main__":
    main()
