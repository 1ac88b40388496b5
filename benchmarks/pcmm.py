"""PCMM throughput: a Mohr–Coulomb column collapsing under gravity.

A column of PCMM particles (square lattice, R = 1 cm, δ = R, 200 × 200 = 40,000
particles by default; 4 m wide and high) of a weak Mohr–Coulomb soil (ρ = 2000,
E = 10 MPa, ν = 0.3, c = 1 kPa, φ = 30°, T = 0.5 kPa, brittle) stands on a
frictional floor with no side support: it yields, elements are deleted and
created as it slumps and spreads, and touching particles that share no element
interact through the contact law. After the warm-up the timed steps are in the
large-deformation regime.

Prints particle-steps per second of the PCMM run and, measured in the same
process on the same machine, of the DEM pack benchmark (``pack2d.py``'s
workload), and their ratio:

    python benchmarks/pcmm.py --threads 2
    python benchmarks/pcmm.py --threads 1 --side 100      # 10,000 particles
"""
import argparse
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))


def build(side=200, arch=None, threads=None):
    import tdem
    r = 0.01
    pos, rad = tdem.pack.regular(2 * r * side, 2 * r * side, r, origin=(0.0, 0.0))
    soil = tdem.MohrCoulomb(density=2000.0, young=10e6, poisson=0.3, cohesion=1e3,
                            friction_angle=30.0, tensile_strength=500.0, brittle=True)
    law = tdem.LinearContact(kn=10e6, ks=10e6, friction=0.5)
    sim = tdem.Simulation(gravity=(0.0, -9.81), dt_fraction=0.4, arch=arch, threads=threads,
                          check_interval=500, progress=False, local_damping=0.05)
    sim.add_particles(pos, rad, material=soil, tolerance=r, contact=law)
    sim.add_wall((-10.0, 0.0), (12.0, 0.0), contact=law)
    return sim


def measure_pcmm(side, steps, warmup, arch, threads):
    sim = build(side, arch, threads)
    sim.run(steps=warmup)
    t = time.perf_counter()
    sim.run(steps=steps)
    p = sim.particles.numpy()
    el = time.perf_counter() - t
    info = {"particles": sim.n_particles, "steps": steps, "seconds": el,
            "rate": sim.n_particles * steps / el, "dt": sim.dt, "time": sim.time,
            "elements": len(sim.elements.numpy()["triangles"]),
            "failed_fraction": float(np.mean(p["failed"])),
            "spread": float(np.ptp(p["position"][:, 0]))}
    return info


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--side", type=int, default=200, help="particles per row (side²)")
    p.add_argument("--steps", type=int, default=500)
    p.add_argument("--warmup", type=int, default=1500)
    p.add_argument("--arch", default=None)
    p.add_argument("--no-dem", action="store_true", help="skip the DEM pack reference")
    args = p.parse_args(argv)
    from benchmarks.pack2d import measure as measure_dem
    r = measure_pcmm(args.side, args.steps, args.warmup, args.arch, args.threads)
    print(f"PCMM particles {r['particles']} steps {r['steps']} seconds {r['seconds']:.3f} "
          f"(t = {r['time']:.4g} s, dt = {r['dt']:.3g} s, {r['elements']} elements, "
          f"{100 * r['failed_fraction']:.0f} % failed, spread {r['spread']:.3f} m)")
    print(f"PCMM tdem {args.threads} particle_steps_per_s {r['rate']:.0f}", flush=True)
    if not args.no_dem:
        n, rate, _ = measure_dem(200, 200, 2000, 2000, args.arch, args.threads)
        print(f"DEM pack tdem {args.threads} particle_steps_per_s {rate:.0f} ({n} discs)")
        print(f"ratio PCMM/DEM {r['rate'] / rate:.3f}")


if __name__ == "__main__":
    main()
