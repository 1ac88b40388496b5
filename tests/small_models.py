"""Small models of each 3D shape and of superellipses, in motion and in contact
within a hundred steps, for tests that compare runs or accounts across shapes."""
import numpy as np

import tdem


def ellipsoids():
    """Ellipsoids in a box periodic in x and y, on a floor, a plate coming down."""
    L = 0.1
    hm = tdem.HertzMindlin(young=1e7, poisson=0.3, friction=0.5, restitution=0.5)
    sim = tdem.Simulation(dim=3, progress=False)
    sim.periodic(x=(0.0, L), y=(0.0, L))
    v, t = tdem.surfaces.plane((0.5 * L, 0.5 * L, 0.0), (0.0, 0.0, 1.0), L + 0.04, 4)
    sim.add_mesh(v, t, contact=hm)
    v, t = tdem.surfaces.plane((0.5 * L, 0.5 * L, 0.03), (0.0, 0.0, -1.0), L + 0.04, 4)
    sim.add_mesh(v, t, contact=hm, velocity=(0.0, 0.0, -0.05))
    rng = np.random.default_rng(1)
    g = np.stack(np.meshgrid(*[np.arange(7) * 0.0143 + 0.007] * 2, [0.007, 0.02],
                             indexing="ij"), -1).reshape(-1, 3)
    g += rng.uniform(-0.0005, 0.0005, g.shape)
    sim.add_particles(g, shape=tdem.Ellipsoid(0.007, 0.006, 0.005), density=2500,
                      contact=hm, orientation=tdem.random_orientations(len(g), seed=2),
                      velocity=rng.normal(0.0, 0.3, g.shape))
    return sim


def spheres():
    hm = tdem.HertzMindlin(young=1e7, poisson=0.3, friction=0.5, restitution=0.5)
    sim = tdem.Simulation(dim=3, progress=False)
    v, t = tdem.surfaces.plane((0.05, 0.05, 0.0), (0.0, 0.0, 1.0), 0.12, 4)
    sim.add_mesh(v, t, contact=hm)
    rng = np.random.default_rng(3)
    g = np.stack(np.meshgrid(*[np.arange(6) * 0.0125 + 0.008] * 3, indexing="ij"),
                 -1).reshape(-1, 3)
    sim.add_particles(g + rng.uniform(-0.0002, 0.0002, g.shape), 0.006, density=2500,
                      contact=hm, velocity=rng.normal(0.0, 0.3, g.shape))
    return sim


def cubes():
    vol = tdem.VolumeContact(young=1e6, friction=0.5, restitution=0.5)
    sim = tdem.Simulation(dim=3, progress=False)
    v, t = tdem.surfaces.plane((0.05, 0.05, 0.0), (0.0, 0.0, 1.0), 0.12, 4)
    sim.add_mesh(v, t, contact=vol)
    rng = np.random.default_rng(4)
    g = np.stack(np.meshgrid(*[np.arange(4) * 0.016 + 0.01] * 3, indexing="ij"),
                 -1).reshape(-1, 3)
    cube = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * 0.005
    sim.add_particles(g, shape=tdem.Polyhedron(cube), density=2500, contact=vol,
                      orientation=tdem.random_orientations(len(g), seed=5),
                      velocity=rng.normal(0.0, 0.3, g.shape))
    return sim


def superellipses():
    lin = tdem.LinearContact(kn=1e6, ks=5e5, friction=0.5, restitution=0.5)
    sim = tdem.Simulation(progress=False)
    sim.periodic(x=(0.0, 0.148))
    sim.add_wall((-0.1, 0.0), (0.3, 0.0), contact=lin)
    rng = np.random.default_rng(6)
    g = np.stack(np.meshgrid(np.arange(8) * 0.0185 + 0.01, np.arange(6) * 0.0112 + 0.006,
                             indexing="ij"), -1).reshape(-1, 2)
    sim.add_particles(g, shape=tdem.Superellipse(a=0.009, b=0.005, n=4), density=2000,
                      contact=lin, angle=rng.uniform(-20.0, 20.0, len(g)),
                      velocity=rng.normal(0.0, 0.3, g.shape))
    return sim
