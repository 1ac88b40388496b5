"""The sort-and-sweep broad phase (``Simulation(broad_phase="sweep")``, tdem.sweep)
against the cell grid: the same lists, so the same trajectories bit for bit (spheres
with mesh walls, discs with segment walls, cubes), its box-pair set equal to a brute
force over the boxes at the last build, checkpoints restarting bit for bit, and the
models it cannot serve refused."""
import numpy as np
import pytest

import tdem
from tdem.neighbors import F_BUILDS

# random packings that start with overlaps (the same in both broad phases)
pytestmark = pytest.mark.filterwarnings("ignore:positions.*overlapping:RuntimeWarning")


def spheres(broad_phase, n=300, seed=0):
    rng = np.random.default_rng(seed)
    k = int(np.ceil(n ** (1 / 3)))
    g = np.stack(np.meshgrid(*[np.arange(k)] * 3, indexing="ij"), -1).reshape(-1, 3)[:n]
    pos = g * 0.021 + rng.uniform(-0.002, 0.002, g.shape) + 0.015
    law = tdem.HertzMindlin(young=1e7, poisson=0.3, friction=0.5, restitution=0.5)
    sim = tdem.Simulation(dim=3, broad_phase=broad_phase, check_interval=50)
    sim.add_particles(pos, radius=rng.uniform(0.008, 0.011, n), density=2500, contact=law,
                      velocity=rng.normal(0.0, 0.3, g.shape))
    w = k * 0.021 + 0.03
    sim.add_mesh(*tdem.surfaces.box((0.0, 0.0, 0.0), (w, w, 0.3)), contact=law)
    return sim


def discs(broad_phase, n=200, seed=1):
    rng = np.random.default_rng(seed)
    k = int(np.ceil(np.sqrt(n)))
    g = np.stack(np.meshgrid(np.arange(k), np.arange(k), indexing="ij"), -1).reshape(-1, 2)[:n]
    pos = g * 0.022 + rng.uniform(-0.001, 0.001, g.shape) + 0.015
    law = tdem.LinearContact(kn=1e6, ks=5e5, friction=0.4, restitution=0.5)
    sim = tdem.Simulation(broad_phase=broad_phase, check_interval=50)
    sim.add_particles(pos, radius=rng.uniform(0.008, 0.0105, n), density=2500, contact=law,
                      velocity=rng.normal(0.0, 0.3, g.shape))
    for a, b in (((0, 0), (0.35, 0)), ((0, 0), (0, 0.5)), ((0.35, 0), (0.35, 0.5))):
        sim.add_wall(a, b, contact=law)
    return sim


def cubes(broad_phase, seed=2):
    rng = np.random.default_rng(seed)
    g = np.stack(np.meshgrid(*[np.arange(4)] * 3, indexing="ij"), -1).reshape(-1, 3)
    pos = g * 0.016 + rng.uniform(-0.001, 0.001, g.shape) + [0.012, 0.012, 0.01]
    law = tdem.VolumeContact(young=1e6, friction=0.5, restitution=0.3)
    sim = tdem.Simulation(dim=3, broad_phase=broad_phase, check_interval=50)
    sim.add_particles(pos, shape=tdem.Polyhedron.cube(0.01), density=2500, contact=law,
                      orientation=tdem.random_orientations(len(g), seed=seed))
    sim.add_mesh(*tdem.surfaces.box((0.0, 0.0, 0.0), (0.09, 0.09, 0.2)), contact=law)
    return sim


def state(sim):
    p = sim.particles.numpy()
    return np.concatenate([p["position"].ravel(), p["velocity"].ravel()])


@pytest.mark.parametrize("make, steps", [(spheres, 1500), (discs, 1500), (cubes, 600)])
def test_sweep_gives_the_grids_trajectories_bit_for_bit(make, steps, monkeypatch):
    # the one-thread path, whose sums do not depend on when the host checks: the
    # sweep's box pairs need more slots than the grid's half lists, so its slots grow
    # (and the steps since the last check are redone) at other steps than the grid's;
    # on the parallel path that moves the last bits, as running the grid alone in
    # other chunks does (test below)
    monkeypatch.setenv("TDEM_SERIAL_BELOW", "1000000")
    runs = {}
    for bp in ("grid", "sweep"):
        sim = make(bp)
        sim.run(steps=steps)
        runs[bp] = (state(sim), int(sim._a["flags"][F_BUILDS]), sim)
    assert runs["sweep"][1] >= 10                 # many builds, each one incremental
    assert runs["sweep"][1] == runs["grid"][1]
    assert np.array_equal(runs["sweep"][0], runs["grid"][0])
    # the same contacts, force for force
    cg, cs = runs["grid"][2].contacts.numpy(), runs["sweep"][2].contacts.numpy()
    assert np.array_equal(cg["pairs"], cs["pairs"])
    for key in ("normal", "shear", "point"):
        assert np.array_equal(np.asarray(cg[key]), np.asarray(cs[key]))


def test_sweep_on_the_parallel_path_agrees_with_the_grid_to_round_off(monkeypatch):
    monkeypatch.setenv("TDEM_SERIAL_BELOW", "0")
    runs = {}
    for bp in ("grid", "sweep"):
        sim = spheres(bp)
        sim.run(steps=400)
        runs[bp] = state(sim)
    assert np.abs(runs["sweep"] - runs["grid"]).max() < 1e-12


def test_box_pair_set_is_every_pair_of_overlapping_boxes():
    sim = spheres("sweep", n=400, seed=3)
    sim.run(steps=1500)
    a = sim._a
    assert int(a["flags"][F_BUILDS]) > 20
    x = a["xref"].to_numpy()                     # the positions of the last build
    r = a["prop"].to_numpy()[:, 0]
    reach = r[:, None] + r[None, :] + sim.skin
    d = np.abs(x[:, None, :] - x[None, :, :]).max(axis=2)
    i, j = np.nonzero(np.triu(d <= reach, 1))
    want = set(zip(i.tolist(), j.tolist()))
    sp, sc = a["spair"].to_numpy(), a["scnt"].to_numpy()
    got = {(p, int(q)) for p in range(len(sc)) for q in sp[p, :sc[p]]}
    assert len(want) > 1000
    assert got == want
    # each box-pair list sorted (the half lists keep the partners' order)
    assert all(np.all(np.diff(sp[p, :sc[p]]) > 0) for p in range(len(sc)))


def test_sweep_checkpoint_restarts_bit_for_bit(tmp_path):
    sim = spheres("sweep", n=150)
    sim.run(steps=1000)
    sim.save(str(tmp_path / "c.h5"))
    sim.run(steps=1000)
    back = tdem.Simulation.load(str(tmp_path / "c.h5"))
    assert back.broad_phase == "sweep"
    back.run(steps=1000)
    assert np.array_equal(state(back), state(sim))


def test_sweep_refuses_what_it_cannot_serve():
    with pytest.raises(tdem.InputError, match="broad_phase"):
        tdem.Simulation(broad_phase="octree")
    sim = tdem.Simulation(dim=3, broad_phase="sweep")
    with pytest.raises(tdem.InputError, match="periodic.*sweep"):
        sim.periodic(x=(0.0, 1.0))
    sim2 = tdem.Simulation(broad_phase="sweep")
    with pytest.raises(tdem.InputError, match="material.*broad_phase='grid'"):
        sim2.add_particles([[0.0, 0.0], [0.02, 0.0]], radius=0.01,
                           material=tdem.Elastic(density=2500, young=1e7, poisson=0.25))
    with pytest.raises(tdem.InputError, match="add_block.*broad_phase='grid'"):
        sim2.add_block([[0, 0], [1, 0], [0, 1]], [[0, 1, 2]],
                       material=tdem.Elastic(density=2500, young=1e7, poisson=0.25))
