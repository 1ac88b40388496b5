"""Step time of the water_blocks case: water, 24 rigid blocks, point–edge contacts.

Builds the four-column system of ``cases.water_blocks`` with a preset's water
(quick: 700 particles of R = 2 cm; paper: 5,488 of R = 7.1 mm), lets it settle
for ``--warmup`` seconds of simulated time (or, with ``--after S``, for the preset's
settling time, then lifts the board as the case does and runs S seconds: the
surge), then times ``--span`` seconds and
prints the wall time per step, the particle-steps per second and the preset's
whole run (settling and the run after the board is lifted, one system) at that
rate. With ``--profile`` it also prints Taichi's kernel profile of the timed
steps (which kernel the step's time goes to).

The system is small, so the step's cost is set by the point–edge contacts
(every water particle is coupled to every block, every block to every other: 16,800
particle rows and 2,784 vertex rows in the quick preset) more than by its particles:

    python benchmarks/water_blocks.py --preset quick --threads 1
    python benchmarks/water_blocks.py --preset paper --threads 1 --profile
    python benchmarks/water_blocks.py --preset quick --threads 1 --after 0.5
"""
import argparse
import os
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--preset", choices=("quick", "paper"), default="quick")
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--warmup", type=float, default=0.002, help="simulated s before timing")
    ap.add_argument("--span", type=float, default=0.01, help="simulated s timed")
    ap.add_argument("--after", type=float, default=None,
                    help="settle, lift the board and run this many simulated s before timing")
    ap.add_argument("--profile", action="store_true", help="Taichi's kernel profile")
    args = ap.parse_args(argv)
    if args.profile:
        os.environ["TDEM_PROFILE"] = "1"
    import taichi as ti
    from cases import water_blocks as wb

    cfg = dict(wb.PRESETS[args.preset])
    m = wb.build(cfg, 4, threads=args.threads)
    sim = m["sim"]
    sim.progress = False
    if args.after is None:
        sim.run(until=args.warmup)
    else:
        sim.run(until=cfg["settle"])
        sim.local_damping = 0.0
        m["board"].velocity = (0.0, wb.BOARD_SPEED)
        sim.run(until=cfg["settle"] + args.after)
    start = sim.time
    if args.profile:
        ti.profiler.clear_kernel_profiler_info()
    steps0 = sim.steps
    t0 = time.perf_counter()
    sim.run(until=start + args.span)
    wall = time.perf_counter() - t0
    steps = sim.steps - steps0
    ms = 1e3 * wall / steps
    points = m["n"] + sum(len(b.vertices) for b in sim.blocks)
    total = (cfg["settle"] + cfg["duration"]) / sim.dt
    when = ("at rest behind the board" if args.after is None
            else f"{args.after:g} s after the board is lifted")
    print(f"water_blocks {args.preset}: {m['n']} water particles, {len(m['blocks'])} blocks, "
          f"dt = {sim.dt:.4g} s, {args.threads} thread(s), timed {when}")
    print(f"  {ms:.2f} ms per step, {points * steps / wall / 1e6:.3f} M particle-steps/s; "
          f"one system's {cfg['settle'] + cfg['duration']:g} s ({total:.0f} steps) at this "
          f"rate: {total * ms / 6e4:.1f} min")
    if args.profile:
        ti.profiler.print_kernel_profiler_info("count")


if __name__ == "__main__":
    main()
