"""Superellipse throughput beside the disc pack of ``pack2d.py``, same machine, one run.

The bed: 20,000 superellipses n = 4, a = 2 mm, b = 1 mm (aspect 2) stacked in 100
columns of 200 on a floor between two walls, side by side and on each other (centres
2a and 2b apart less 0.1 %: every particle starts with its four face contacts),
turned by small random angles (±0.3°), resting under gravity with the disc pack's law (linear spring–dashpot, μ = 0.5,
e = 0.5, k_n from the peers' stiffness), Δt = 1e-5 s; 2,000 warm-up steps then N
timed steps. Then the disc pack of ``pack2d.py`` (40,000 discs) in the same process.

Prints ``PEER tdem-superellipse <threads> particle_steps_per_s <value>`` and the disc
figure, and their ratio (the issue's aim: at least one fifth).

    python benchmarks/superellipse.py --threads 1
"""
import argparse
import json
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import pack2d  # noqa: E402


def build(cols=100, rows=200, arch=None, threads=None, seed=0):
    import tdem
    a, b = 0.002, 0.001
    shape = tdem.Superellipse(a=a, b=b, n=4)
    dx, dy = 2 * a * 0.999, 2 * b * 0.999
    x = a + np.arange(cols) * dx
    y = b * 0.999 + np.arange(rows) * dy
    pos = np.stack(np.meshgrid(x, y), -1).reshape(-1, 2)
    rng = np.random.default_rng(seed)
    k3, m3 = pack2d.peer_kn()
    m2 = 2500.0 * shape.area
    kn = k3 * m2 / m3
    law = tdem.LinearContact(kn=kn, ks=kn, friction=0.5, restitution=0.5)
    sim = tdem.Simulation(gravity=(0.0, -9.81), dt=1e-5, arch=arch, threads=threads,
                          skin=0.0004, check_interval=500, progress=False)
    sim.add_particles(pos, shape=shape, angle=rng.uniform(-0.3, 0.3, len(pos)),
                      density=2500.0, contact=law)
    width = (cols - 1) * dx + 2 * a * 0.999
    top = pos[:, 1].max() + 0.1
    sim.add_wall((0.0, top), (0.0, 0.0), contact=law)
    sim.add_wall((width, 0.0), (width, top), contact=law)
    sim.add_wall((-0.01, 0.0), (width + 0.01, 0.0), contact=law)
    return sim


def measure(steps, warmup, arch, threads, cols=100, rows=200):
    sim = build(cols, rows, arch, threads)
    sim.run(steps=warmup)
    t = time.perf_counter()
    sim.run(steps=steps)
    sim.particles.numpy()
    el = time.perf_counter() - t
    c = sim.contacts.numpy()
    return {"particles": sim.n_particles, "rate": sim.n_particles * steps / el, "seconds": el,
            "contacts_per_particle": 2 * len(c["pairs"]) / sim.n_particles,
            "nonconverged": sim.nonconverged_contacts}


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--threads", type=int, default=1)
    p.add_argument("--arch", default=None)
    p.add_argument("--steps", type=int, default=2000)
    p.add_argument("--warmup", type=int, default=2000)
    p.add_argument("--cols", type=int, default=100, help="columns of the bed")
    p.add_argument("--rows", type=int, default=200, help="rows of the bed")
    p.add_argument("--no-disc", action="store_true", help="skip the disc pack")
    args = p.parse_args(argv)
    se = measure(args.steps, args.warmup, args.arch, args.threads, args.cols, args.rows)
    print(f"PEER tdem-superellipse {args.threads} particle_steps_per_s {se['rate']:.4g}")
    if args.no_disc:
        print(json.dumps({"superellipse": se}, indent=1))
        return
    n, disc, _ = pack2d.measure(200, 200, args.steps, args.warmup, args.arch, args.threads)
    print(f"PEER tdem {args.threads} particle_steps_per_s {disc:.4g}")
    print(json.dumps({"superellipse": se, "disc": {"particles": n, "rate": disc},
                      "ratio": se["rate"] / disc}, indent=1))


if __name__ == "__main__":
    main()
