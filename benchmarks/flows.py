"""A bin discharging through an orifice while it is fed: the cost of insertion and removal.

A square bin (side W, flat floor with a square orifice of side 6 d in its middle)
holds N spheres (d = 4 mm, uniform 3.6–4.4 mm, ρ = 2500, linear springs k_n = 2000 N/m,
μ = 0.5, e = 0.5), settled from a jittered lattice. Then the orifice opens: an outlet
takes every sphere whose centre is 5 d below the floor, and an inserter feeds the bin
from a box at its top at the discharge's rate (measured over a first stretch), so the
fill stays about constant: the model of a hopper that runs for hours.

Timed: ``--steps`` steps of the discharge with the outlet and the inserter, against the
same steps of the same model without them (the orifice plugged by nothing: the spheres
fall out of the open orifice into empty space). Reported: particle-steps per second of
each, the time spent in the flow events (removal and insertion: a download and upload
of the state each) per step and per event, the particles removed and inserted.

    python benchmarks/flows.py --n 100000 --threads 2 --steps 1000 --settle 600
    python benchmarks/flows.py --n 100000 --threads 2 --steps 1000 --settle 600 --every 500
"""
import argparse
import math
import time

import numpy as np

D = 0.004


def bin_model(n, threads, seed=0):
    import tdem
    sim = tdem.Simulation(dim=3, progress=False, threads=threads, check_interval=100)
    law = tdem.LinearContact(kn=2000.0, friction=0.5, restitution=0.5)
    # a square bin holding n spheres on a lattice of spacing 1.15 d, as tall as 1.5 wide
    a = 1.15 * 1.1 * D
    side = int(math.ceil((n / 1.5) ** (1.0 / 3.0)))
    layers = int(math.ceil(n / side ** 2))
    w = side * a
    g = np.stack(np.meshgrid(np.arange(side), np.arange(side), np.arange(layers),
                             indexing="ij"), -1).reshape(-1, 3)[:n]
    rng = np.random.default_rng(seed)
    x = (g + 0.5) * a - [0.5 * w, 0.5 * w, 0.0] + rng.uniform(-0.02 * D, 0.02 * D, (n, 3))
    r = 0.5 * rng.uniform(0.9 * D, 1.1 * D, n)
    sim.add_particles(x, r, density=2500.0, contact=law)
    h = 0.5 * w
    o = 3.0 * D                                    # half the orifice's side
    floor = np.array([[-h, -h, 0], [h, -h, 0], [h, h, 0], [-h, h, 0],
                      [-o, -o, 0], [o, -o, 0], [o, o, 0], [-o, o, 0]], float)
    ftri = np.array([[0, 1, 5], [0, 5, 4], [1, 2, 6], [1, 6, 5], [2, 3, 7], [2, 7, 6],
                     [3, 0, 4], [3, 4, 7]])
    sim.add_mesh(floor, ftri, contact=law)
    top = layers * a + 0.1
    walls = tdem.surfaces.box((-h, -h, 0.0), (h, h, top), open_top=True)
    v, t = walls
    keep = np.ptp(v[t][:, :, 2], axis=1) > 0            # the four sides (the floor is ours)
    sim.add_mesh(v, t[keep], contact=law)
    return sim, law, w, layers * a, o


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=100000)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--steps", type=int, default=3000)
    ap.add_argument("--settle", type=int, default=4000)
    ap.add_argument("--every", type=int, default=None,
                    help="steps between flow events (default: every check, 100 steps)")
    args = ap.parse_args()
    import tdem
    rows = {}
    for flows in (False, True):
        sim, law, w, height, o = bin_model(args.n, args.threads)
        sim.mesh_plug = None
        t0 = time.perf_counter()
        # settle with the orifice plugged by a plate just below the floor
        plug = sim.add_mesh(np.array([[-2 * o, -2 * o, -1e-4], [2 * o, -2 * o, -1e-4],
                                      [2 * o, 2 * o, -1e-4], [-2 * o, 2 * o, -1e-4]]),
                            np.array([[0, 1, 2], [0, 2, 3]]), contact=law)
        sim.run(steps=args.settle)
        settle_s = time.perf_counter() - t0
        plug.motion(velocity=(0.0, 0.0, -5.0))          # the plug drops away
        sim.run(steps=200)
        plug.motion()
        out = ins = None
        if flows:
            out = sim.remove_in(box=((-w, -w, -1.0), (w, w, -5 * D)), every=args.every)
            # feed at the Beverloo estimate, C = 0.58, k = 1.5 (square orifice: its
            # hydraulic diameter 6 d), bulk density 0.6 × 2500
            dh = 2 * o
            rate = 0.58 * 0.6 * 2500.0 * math.sqrt(9.81) * max(dh - 1.5 * D, D) ** 2.5
            ins = sim.insert(box=((-0.45 * w, -0.45 * w, height + 0.01),
                                  (0.45 * w, 0.45 * w, height + 0.05)),
                             rate=rate, grading=tdem.grading.uniform(0.9 * D, 1.1 * D),
                             density=2500.0, contact=law, seed=1,
                             every=None if args.every is None else args.every * sim.dt)
        spent = [0.0, 0]
        if flows:
            orig = sim._flow_events

            def timed(t_end):
                t = time.perf_counter()
                orig(t_end)
                spent[0] += time.perf_counter() - t
                spent[1] += 1
            sim._flow_events = timed
        n0 = sim.n_particles
        t0 = time.perf_counter()
        steps0 = sim.steps
        dofs = 0
        while sim.steps - steps0 < args.steps:
            before = sim.n_particles
            sim.run(steps=100)
            dofs += 100 * 0.5 * (before + sim.n_particles)
        wall = time.perf_counter() - t0
        rows[flows] = {"wall_s": wall, "particle_steps_per_s": dofs / wall,
                       "flow_s": spent[0], "events": spent[1],
                       "n_start": n0, "n_end": sim.n_particles,
                       "removed": 0 if out is None else out.count,
                       "inserted": 0 if ins is None else ins.count, "settle_s": settle_s}
        r = rows[flows]
        print(f"{'with' if flows else 'without'} inserter and outlet: {args.steps} steps, "
              f"{r['n_start']} -> {r['n_end']} spheres, {r['wall_s']:.1f} s, "
              f"{r['particle_steps_per_s']:.3g} particle-steps/s"
              + (f"; flow events {r['flow_s']:.2f} s over {r['events']} "
                 f"({1e3 * r['flow_s'] / max(r['events'], 1):.0f} ms each, "
                 f"{1e3 * r['flow_s'] / args.steps:.2f} ms per step), removed "
                 f"{r['removed']}, inserted {r['inserted']}" if flows else ""), flush=True)
    a, b = rows[False], rows[True]
    print(f"cost of insertion and removal: {100 * (a['particle_steps_per_s'] / b['particle_steps_per_s'] - 1):.1f} % "
          f"of the step time ({1e3 * (b['wall_s'] - a['wall_s']) / args.steps:.2f} ms per step)")


if __name__ == "__main__":
    main()
