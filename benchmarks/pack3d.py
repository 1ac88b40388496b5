"""Dense 3D sphere pack: the peers' 3D benchmark workload, in tdem.

Same set-up as the peers' input (``liggghts_pack3d.in``): spheres of diameter 4 mm
on an fcc lattice of touching neighbours (cubic cell 5.657 mm, origin offset 0.36
cell) filling the block 0.002–0.118 × 0.002–0.118 × 0.002–0.158 m (47,068 spheres),
resting under gravity in a box 0.12 × 0.12 m (floor and four sides, here a
triangle mesh of 10 triangles), Hertz–Mindlin with history friction (E = 1e7,
ν = 0.3, e = 0.5, μ = 0.5), density 2500, Δt = 1e-5 s, skin 0.4 mm, 2,000 warm-up
steps then N timed steps.

Prints ``PEER tdem <threads> particle_steps_per_s <value>`` like the peers' script
(``WORKLOAD=pack3d bash peers.sh``).

    python benchmarks/pack3d.py --threads 1            # the 47k workload
    python benchmarks/pack3d.py --threads 2
    python benchmarks/pack3d.py --scaling              # 10k ... 500k spheres
    python benchmarks/pack3d.py --ellipsoids           # the same bed of ellipsoids
    python benchmarks/pack3d.py --cubes                # about 20,000 cubes
    python benchmarks/pack3d.py --cubes --yade         # ... and Yade's Polyhedra on them
    python benchmarks/pack3d.py --broad-phase sweep    # sort-and-sweep instead of the grid
    python benchmarks/pack3d.py --planes               # the box as five primitive planes
    python benchmarks/pack3d.py --cubes --pour         # cubes falling: the lists rebuilt often
    python benchmarks/pack3d.py --bare                 # ... and the step written bare
    python benchmarks/pack3d.py --threads 2 --profile  # the time of each loop of the step

Every run prints how many list builds its timed steps made and their time.

``--planes``: the box's floor and four sides as five primitive planes
(``sim.add_plane``, LIGGGHTS' ``wall/gran ... primitive``) instead of the mesh of 10
triangles; the same bed, law and steps (spheres only).

``--ellipsoids``: the same number of ellipsoids of semi-axes 2, 1.6 and 1.2 mm (aspect
1.67), their axes along x, y, z, on the lattice stretched by (1, 0.8, 0.6): the affine
image of the sphere pack, so that they touch as the spheres do (an affine map keeps
contacts), in a box 0.12 × 0.096 m; the same law and steps. Their rate beside the
spheres'.

``--cubes``: cubes of the spheres' volume (edge 3.224 mm) stacked face to face on a
simple cubic lattice, 37 × 37 × 15 = 20,535 of them, in the same box under gravity:
a settled bed where every inner cube has six face contacts (the heaviest contact of
the overlap-volume law: a full overlap polyhedron per face), with
``tdem.VolumeContact(young=1e7, friction=0.5, restitution=0.5)``; the same steps.
``--yade`` runs the same bed in Yade's Polyhedra (``yade -n -x -j 1``: one thread,
the floor as two facets) and prints its rate beside tdem's; ``--scale`` shrinks the
bed for both (Yade takes minutes per hundred steps of the full one). Exactly parallel
faces are a degenerate case for Yade's intersection (it warns and misses contacts on
the stacked lattice); ``--settled`` gives both codes a bed of randomly oriented cubes
settled under gravity (by tdem, cached in ``benchmarks/out/``).
"""
import argparse
import json
import math
import os
import subprocess
import sys
import time

import numpy as np

CELL = 0.0056568542


def fcc(hi=(0.118, 0.118, 0.158), lo=(0.002, 0.002, 0.002), cell=CELL, origin=0.36):
    """The lattice points of LIGGGHTS' ``lattice fcc`` inside the block [lo, hi]."""
    lo, hi = np.asarray(lo), np.asarray(hi)
    basis = np.array([[0, 0, 0], [0.5, 0.5, 0], [0.5, 0, 0.5], [0, 0.5, 0.5]])
    n = np.ceil(hi / cell).astype(int) + 1
    ijk = np.stack(np.meshgrid(*[np.arange(-1, k) for k in n], indexing="ij"), -1).reshape(-1, 3)
    pts = ((ijk[:, None, :] + basis[None] + origin) * cell).reshape(-1, 3)
    keep = np.all((pts >= lo) & (pts <= hi), axis=1)
    return pts[keep]


EDGE = (4.0 / 3.0 * math.pi * 0.002 ** 3) ** (1.0 / 3.0)     # a cube of a sphere's volume


def cube_lattice(w=0.12, layers=15):
    """Centres of cubes of edge EDGE stacked face to face in the box [0, w]², 0.05 %
    apart (exactly touching faces are a degenerate case for Yade's CGAL
    intersection; gravity closes the gaps in the warm-up)."""
    a = EDGE * 1.0005
    k = int(w // a)
    off = 0.5 * (w - k * a) + 0.5 * EDGE
    g = np.stack(np.meshgrid(off + a * np.arange(k), off + a * np.arange(k),
                             0.5 * a + a * np.arange(layers), indexing="ij"), -1)
    return g.reshape(-1, 3)


def loose_cubes(w):
    """Centres of the cubes' loose lattice (1.8 edges apart, as many as the stacked
    bed of box width w) and the height of the box that holds it."""
    a = 1.8 * EDGE
    k = int(w // a)
    layers = int(round(len(cube_lattice(w)) / (k * k)))
    off = 0.5 * (w - k * a) + 0.5 * a
    g = np.stack(np.meshgrid(off + a * np.arange(k), off + a * np.arange(k),
                             0.5 * a + a * np.arange(layers), indexing="ij"), -1).reshape(-1, 3)
    return g, layers * a + 0.01


def settled_cubes(scale, seed=0, seconds=0.35, threads=None):
    """A bed of randomly oriented cubes settled under gravity in tdem (no parallel
    faces: a fair bed for Yade's CGAL intersections): (centres, quaternions), cached
    in benchmarks/out/."""
    import tdem
    w = 0.12 * math.sqrt(scale)
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "out",
                        f"cubes_settled_{scale:g}_{seed}.npz")
    if os.path.exists(path):
        d = np.load(path)
        return d["x"], d["q"]
    g, height = loose_cubes(w)
    vol = tdem.VolumeContact(young=1e7, friction=0.5, restitution=0.5)
    sim = tdem.Simulation(dim=3, gravity=(0.0, 0.0, -9.81), dt=1e-5, local_damping=0.3,
                          progress=True, threads=threads)
    sim.add_particles(g, shape=tdem.Polyhedron.cube(EDGE), density=2500.0, contact=vol,
                      orientation=tdem.random_orientations(len(g), seed=seed))
    verts, tris = tdem.surfaces.box((0.0, 0.0, 0.0), (w, w, height))
    sim.add_mesh(verts, tris, contact=vol)
    sim.run(until=seconds)
    s = sim.particles.numpy()
    os.makedirs(os.path.dirname(path), exist_ok=True)
    np.savez(path, x=s["position"], q=s["orientation"])
    return s["position"], s["orientation"]


def build_cubes(arch=None, threads=None, scale=1.0, bed=None, broad_phase="grid"):
    import tdem
    w = 0.12 * math.sqrt(scale)
    vol = tdem.VolumeContact(young=1e7, friction=0.5, restitution=0.5)
    sim = tdem.Simulation(dim=3, gravity=(0.0, 0.0, -9.81), dt=1e-5, arch=arch,
                          threads=threads, skin=0.0004, check_interval=500, progress=False,
                          broad_phase=broad_phase)
    height = 0.2
    if bed == "pour":
        # the loose lattice the settled bed starts from (random orientations), falling:
        # a flow, the lists rebuilt every few steps
        g, height = loose_cubes(w)
        sim.add_particles(g, shape=tdem.Polyhedron.cube(EDGE), density=2500.0, contact=vol,
                          orientation=tdem.random_orientations(len(g), seed=0))
    elif bed is None:
        sim.add_particles(cube_lattice(w), shape=tdem.Polyhedron.cube(EDGE), density=2500.0,
                          contact=vol)
    else:
        sim.add_particles(bed[0], shape=tdem.Polyhedron.cube(EDGE), density=2500.0,
                          contact=vol, orientation=bed[1])
    verts, tris = tdem.surfaces.box((0.0, 0.0, 0.0), (w, w, height))
    sim.add_mesh(verts, tris, contact=vol)
    return sim


YADE_SCRIPT = """
import time, numpy as np
from yade import polyhedra_utils, log
log.setDefaultLogLevel(log.ERROR)     # (its intersection warns per contact otherwise)
O.engines = [ForceResetter(),
  InsertionSortCollider([Bo1_Polyhedra_Aabb(), Bo1_Facet_Aabb()], verletDist=0.0004),
  InteractionLoop([Ig2_Polyhedra_Polyhedra_PolyhedraGeom(), Ig2_Facet_Polyhedra_PolyhedraGeom()],
                  [Ip2_PolyhedraMat_PolyhedraMat_PolyhedraPhys()],
                  [Law2_PolyhedraGeom_PolyhedraPhys_Volumetric()]),
  NewtonIntegrator(damping=0.0, gravity=(0, 0, -9.81))]
mat = PolyhedraMat(density=2500, young=1e7, poisson=0.3, frictionAngle=0.4636)
O.materials.append(mat)
e = {edge!r}
cube = [(x, y, z) for x in (-e/2, e/2) for y in (-e/2, e/2) for z in (-e/2, e/2)]
for c, q in zip({centres!r}, {orientations!r}):
    b = polyhedra_utils.polyhedra(mat, v=cube, fixed=False)
    b.state.pos = c
    b.state.ori = Quaternion(*q) * b.state.ori
    O.bodies.append(b)
w = {width!r}
for f in [((0,0,0),(w,0,0),(w,w,0)), ((0,0,0),(w,w,0),(0,w,0))]:
    O.bodies.append(facet(f, material=mat, fixed=True))
O.dt = 1e-5
O.run({warmup}, True)
print("interactions", len([i for i in O.interactions if i.isReal]))
t = time.time()
O.run({steps}, True)
el = time.time() - t
print("PEER yade-polyhedra 1 particle_steps_per_s %.0f" % (len(O.bodies) * {steps} / el))
"""


def run_yade(steps, warmup, scale=1.0, bed=None):
    """Yade's Polyhedra on the cube bed (one thread; a floor, no side walls): its
    particle-steps per second, its contacts after the warm-up and its warnings."""
    import tempfile
    w = 0.12 * math.sqrt(scale)
    x, q = bed if bed is not None else (cube_lattice(w), np.tile([1.0, 0, 0, 0], (len(
        cube_lattice(w)), 1)))
    script = YADE_SCRIPT.format(edge=EDGE, width=w, warmup=warmup, steps=steps,
                                centres=[tuple(map(float, c)) for c in x],
                                orientations=[tuple(map(float, c)) for c in q])
    with tempfile.NamedTemporaryFile("w", suffix=".py", delete=False) as f:
        f.write(script)
    out = subprocess.run(["yade", "-n", "-x", "-j", "1", f.name], capture_output=True,
                         text=True)
    text = out.stdout + out.stderr
    lines = [ln for ln in text.splitlines() if ln.startswith(("PEER", "interactions"))]
    if not any(ln.startswith("PEER") for ln in lines):
        raise RuntimeError("yade gave no rate:\n" + out.stdout[-2000:] + out.stderr[-2000:])
    warned = sum(1 for ln in text.splitlines() if "WARN" in ln)
    return "\n".join(lines) + f"\nyade warnings {warned}"


def build(scale=1.0, arch=None, threads=None, ellipsoids=False, broad_phase="grid",
          planes=False):
    """The workload; ``scale`` widens the box in x and y (the scaling runs);
    ``planes``: the box as five primitive planes instead of a mesh."""
    import tdem
    w = 0.12 * math.sqrt(scale)
    pts = fcc(hi=(w - 0.002, w - 0.002, 0.158))
    hm = tdem.HertzMindlin(young=1e7, poisson=0.3, friction=0.5, restitution=0.5)
    sim = tdem.Simulation(dim=3, gravity=(0.0, 0.0, -9.81), dt=1e-5, arch=arch,
                          threads=threads, skin=0.0004, check_interval=500, progress=False,
                          broad_phase=broad_phase)
    stretch = np.array([1.0, 0.8, 0.6]) if ellipsoids else np.ones(3)
    if ellipsoids:
        sim.add_particles(pts * stretch, shape=tdem.Ellipsoid(*(0.002 * stretch)),
                          density=2500.0, contact=hm)
    else:
        sim.add_particles(pts, 0.002, density=2500.0, contact=hm)
    if planes:
        wy = w * stretch[1]
        for point, normal in (((0, 0, 0), (0, 0, 1)), ((0, 0, 0), (1, 0, 0)),
                              ((w, 0, 0), (-1, 0, 0)), ((0, 0, 0), (0, 1, 0)),
                              ((0, wy, 0), (0, -1, 0))):
            sim.add_plane(point, normal, contact=hm)
        return sim
    verts, tris = tdem.surfaces.box((0.0, 0.0, 0.0), (w, w * stretch[1], 0.2))
    sim.add_mesh(verts, tris, contact=hm)
    return sim


class BuildClock:
    """Wall time of the neighbour-list builds (either broad phase's kernel) while on;
    on the CPU a kernel call returns when it is done, and the host calls the build
    only when the lists need it."""

    def __init__(self):
        import tdem.neighbors
        import tdem.sweep
        self.builds, self.seconds, self.on = 0, 0.0, False
        for mod in (tdem.neighbors, tdem.sweep):
            mod.rebuild = self._wrap(mod.rebuild)

    def _wrap(self, kernel):
        def timed(*args):
            if not self.on:
                return kernel(*args)
            t = time.perf_counter()
            out = kernel(*args)
            self.seconds += time.perf_counter() - t
            self.builds += 1
            return out
        # (the engine binds a kernel's arguments by the names it declares)
        timed._primal = getattr(kernel, "_primal", None) or kernel.kernel._primal
        return timed


def measure(scale, steps, warmup, arch, threads, ellipsoids=False, cubes=False, bed=None,
            broad_phase="grid", clock=None, profile=False, planes=False):
    sim = (build_cubes(arch, threads, scale, bed, broad_phase) if cubes else
           build(scale, arch, threads, ellipsoids, broad_phase, planes))
    sim.run(steps=warmup)
    if profile:
        import taichi as ti
        ti.profiler.clear_kernel_profiler_info()
    if clock is not None:
        clock.on = True
    t = time.perf_counter()
    sim.run(steps=steps)
    sim.particles.numpy()  # waits for the device
    el = time.perf_counter() - t
    if clock is not None:
        clock.on = False
    return sim, sim.n_particles * steps / el, el


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--threads", type=int, default=1)
    p.add_argument("--steps", type=int, default=5000)
    p.add_argument("--warmup", type=int, default=2000)
    p.add_argument("--arch", default=None)
    p.add_argument("--scale", type=float, default=1.0,
                   help="box area × scale (particles × scale)")
    p.add_argument("--scaling", action="store_true",
                   help="run about 10k, 47k, 100k, 200k, 500k spheres, one process each")
    p.add_argument("--ellipsoids", action="store_true",
                   help="ellipsoids (2, 1.6, 1.2 mm) instead of spheres")
    p.add_argument("--cubes", action="store_true",
                   help="about 20,000 cubes stacked face to face (tdem.VolumeContact)")
    p.add_argument("--yade", action="store_true",
                   help="with --cubes: also Yade's Polyhedra on the same bed")
    p.add_argument("--settled", action="store_true",
                   help="with --cubes: randomly oriented cubes settled under gravity first "
                        "(in tdem, cached in benchmarks/out/) instead of the stacked lattice")
    p.add_argument("--pour", action="store_true",
                   help="with --cubes: the cubes falling from a loose lattice (a flow: the "
                        "lists rebuilt every few steps) instead of a settled bed")
    p.add_argument("--broad-phase", default="grid", choices=("grid", "sweep"),
                   help="the neighbour search (tdem.Simulation(broad_phase=)); the time "
                        "its list builds take is printed")
    p.add_argument("--bare", action="store_true",
                   help="then the same step written bare (benchmarks/bare3d.py) on the "
                        "engine's bed, with ndarrays and with fields")
    p.add_argument("--profile", action="store_true",
                   help="Taichi's kernel profiler over the timed steps: the time of each "
                        "loop of the step (its rate is then lower: each loop is timed)")
    p.add_argument("--planes", action="store_true",
                   help="the box's floor and sides as five primitive planes (add_plane) "
                        "instead of a mesh of 10 triangles")
    p.add_argument("--json", default=None, help="append the results to this JSON file")
    args = p.parse_args(argv)
    if args.planes and (args.cubes or args.ellipsoids):
        p.error("--planes: primitive walls take spheres only")
    if args.profile:
        os.environ["TDEM_PROFILE"] = "1"
    if args.scaling:
        for scale in (0.2125, 1.0, 2.125, 4.25, 10.625):
            cmd = [sys.executable, __file__, "--threads", str(args.threads), "--steps",
                   str(args.steps), "--warmup", str(args.warmup), "--scale", str(scale)] + (
                       ["--arch", args.arch] if args.arch else [])
            out = subprocess.run(cmd, capture_output=True, text=True, check=True).stdout
            print([ln for ln in out.splitlines() if ln.startswith("particles")][-1],
                  [ln for ln in out.splitlines() if ln.startswith("PEER")][-1], flush=True)
        return
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
    bed = settled_cubes(args.scale, threads=args.threads) if args.cubes and args.settled else None
    if args.cubes and args.pour:
        bed = "pour"
    clock = BuildClock() if (args.arch or "cpu") == "cpu" else None
    sim, rate, el = measure(args.scale, args.steps, args.warmup, args.arch, args.threads,
                            args.ellipsoids, args.cubes, bed, args.broad_phase, clock,
                            args.profile, args.planes)
    if args.profile:
        import taichi as ti
        ti.profiler.print_kernel_profiler_info("count")
    if args.cubes:
        print(f"contacts {len(sim.contacts.numpy()['pairs'])}")
    s = sim.particles.numpy()
    print(f"particles {sim.n_particles} steps {args.steps} seconds {el:.3f} "
          f"zmax {s['position'][:, 2].max() + 0.002:.5f} vz {s['velocity'][:, 2].mean():.3e}")
    if args.ellipsoids or args.cubes:
        print(f"nonconverged {sim.nonconverged_contacts}")
    if clock is not None:
        print(f"broad phase {args.broad_phase}: {clock.builds} list builds in the timed "
              f"steps, {1e3 * clock.seconds / max(clock.builds, 1):.2f} ms each, "
              f"{100 * clock.seconds / el:.1f} % of the time")
    tag = ("-ellipsoids" if args.ellipsoids else "-cubes" if args.cubes else
           "-planes" if args.planes else "")
    print(f"PEER tdem{tag} {args.threads} particle_steps_per_s {rate:.0f}", flush=True)
    if args.bare and not (args.cubes or args.ellipsoids):
        import bare3d
        contacts = sim.contacts.numpy()
        for storage in ("ndarray", "field"):
            r = bare3d.measure(s, args.steps, contacts, storage=storage)
            print(f"bare step ({storage}): {r['pairs']} pairs, {r['touching_start']} touching "
                  f"at the start, {r['touching_end']} at the end, {r['builds']} list builds "
                  f"(not timed); rate / tdem {r['rate'] / rate:.2f}", flush=True)
            print(f"PEER bare-{storage} {args.threads} particle_steps_per_s {r['rate']:.0f}",
                  flush=True)
    if args.cubes and args.yade and bed != "pour":
        print(run_yade(args.steps, args.warmup, args.scale, bed), flush=True)
    if args.json:
        rec = {"particles": sim.n_particles, "threads": args.threads, "steps": args.steps,
               "broad_phase": args.broad_phase, "container": "planes" if args.planes else "mesh",
               "seconds": el, "particle_steps_per_s": rate, "arch": args.arch or "cpu"}
        data = json.load(open(args.json)) if os.path.exists(args.json) else []
        data.append(rec)
        json.dump(data, open(args.json, "w"), indent=1)


if __name__ == "__main__":
    main()
