"""The PCMM element kernel and gather, timed alone on a frozen state.

Runs the collapsing column of ``pcmm.py`` through its warm-up, then calls the
element kernel (``physics.pcmm.stresses``) and the gather (``physics.pcmm.gather``)
again and again with the arguments of the last step, in alternation, and prints
the fastest, first-quartile and median time of each. Whole runs on a shared
machine drift by more than a change to one kernel is worth; the fastest of many
calls on the same state does not:

    python benchmarks/pcmm_kernels.py --threads 2
"""
import argparse
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))

from benchmarks.pcmm import PACKINGS  # noqa: E402

KERNELS = ("stresses", "gather")


def measure(side, warmup, calls, arch, threads, packing="regular"):
    """{kernel name: array of ms per call} after ``warmup`` steps of the column."""
    import taichi as ti

    import tdem  # noqa: F401  (tdem first: it imports physics in its order)
    from benchmarks.pcmm import build
    from physics.pcmm import step as pcmm_step   # where update() looks the kernels up
    sim = build(side, arch, threads, packing)
    sim.run(steps=max(warmup - 1, 0))
    args, orig = {}, {name: getattr(pcmm_step, name) for name in KERNELS}

    def keep(name):
        def call(*a):
            args[name] = a
            return orig[name](*a)
        return call

    try:
        for name in KERNELS:
            setattr(pcmm_step, name, keep(name))
        sim.run(steps=1)
    finally:
        for name in KERNELS:
            setattr(pcmm_step, name, orig[name])
    times = {name: [] for name in KERNELS}
    for _ in range(calls):
        for name in KERNELS:
            ti.sync()
            t = time.perf_counter()
            orig[name](*args[name])
            ti.sync()
            times[name].append(1e3 * (time.perf_counter() - t))
    return {name: np.array(v) for name, v in times.items()}


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--side", type=int, default=200, help="particles per row (side²)")
    p.add_argument("--packing", choices=PACKINGS, default="regular")
    p.add_argument("--warmup", type=int, default=1500)
    p.add_argument("--calls", type=int, default=80, help="timed calls of each kernel")
    p.add_argument("--arch", default=None)
    args = p.parse_args(argv)
    if args.calls < 1:
        p.error(f"--calls must be >= 1, got {args.calls}")
    if args.warmup < 1:
        p.error(f"--warmup must be >= 1, got {args.warmup}")
    times = measure(args.side, args.warmup, args.calls, args.arch, args.threads, args.packing)
    for name, t in times.items():
        print(f"{name}: fastest {t.min():.2f} ms, first quartile {np.percentile(t, 25):.2f} ms, "
              f"median {np.median(t):.2f} ms ({len(t)} calls, {args.threads} threads)")


if __name__ == "__main__":
    main()
