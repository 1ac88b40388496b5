"""Particles entering and leaving a running model (tdem.flows): insertion at a rate
puts in the mass due within one particle and never overlaps, outlets count every
particle that left, identities, groups and fixes follow a removal, the energy account
stays closed, and a checkpoint with an inserter and an outlet restarts bit for bit."""
import numpy as np
import pytest

import tdem

LAW = tdem.LinearContact(kn=2e4, friction=0.3, restitution=0.5)
FLOOR = (np.array([[-0.3, -0.3, 0], [0.5, -0.3, 0], [0.5, 0.5, 0], [-0.3, 0.5, 0]]),
         np.array([[0, 1, 2], [0, 2, 3]]))


def _bin(rate=1.0, until=2.0, grading=None, radius=0.012, seed=0):
    sim = tdem.Simulation(dim=3, progress=False)
    sim.add_mesh(*FLOOR, contact=LAW)
    kw = {"grading": grading} if grading is not None else {"radius": radius}
    ins = sim.insert(box=((0.0, 0.0, 0.15), (0.2, 0.2, 0.35)), rate=rate, density=2500.0,
                     contact=LAW, until=until, seed=seed, **kw)
    return sim, ins


def _largest_overlap(sim):
    p = sim.particles.numpy()
    x, r = p["position"], p["radius"]
    from scipy.spatial import cKDTree
    pairs = cKDTree(x).query_pairs(2.0 * r.max(), output_type="ndarray")
    if not len(pairs):
        return 0.0
    gap = np.linalg.norm(x[pairs[:, 0]] - x[pairs[:, 1]], axis=1) - r[pairs].sum(axis=1)
    return float(max(0.0, (-gap / np.minimum(r[pairs[:, 0]], r[pairs[:, 1]])).max()))


def test_insertion_at_a_rate_puts_in_the_mass_due_without_overlaps():
    g = tdem.grading.uniform(0.016, 0.028)
    sim, ins = _bin(rate=1.0, until=2.0, grading=g)
    worst = 0.0
    while sim.time < 2.0:
        sim.run(until=min(sim.time + 0.05, 2.0))
    # every particle placed so far: none overlaps another by 1 % of its radius when placed
    # (the bed below is compressed by its weight, so the check is at placement:
    # the particles of the last batch against all others)
    p = sim.particles.numpy()
    last = np.isin(p["id"], ins.ids[ins.times == ins.times.max()])
    x, r = p["position"], p["radius"]
    d = np.linalg.norm(x[last][:, None] - x[None], axis=2) - r[last][:, None] - r[None]
    d[np.arange(last.sum()), np.flatnonzero(last)] = np.inf
    worst = max(worst, float((-d / r[last][:, None]).max()))
    assert worst < 0.01
    big = float(p["mass"].max())
    assert abs(ins.mass - 2.0) <= big                    # 2 kg within one particle
    assert float(p["mass"].sum()) == pytest.approx(ins.mass, rel=1e-12)
    assert ins.count == sim.n_particles == len(np.unique(p["id"]))
    # the mass went in at the rate: half of it by 1 s, within a particle and a segment
    seg = sim.check_interval * sim.dt
    half = float(p["mass"][np.isin(p["id"], ins.ids[ins.times <= 1.0 - seg])].sum())
    assert abs(half - (1.0 - seg)) <= big + seg * 1.0 + big


def test_the_grading_of_what_went_in_is_the_grading_asked_for():
    g = tdem.grading(sizes=[0.014, 0.02, 0.03], passing=[0, 50, 100])
    sim = tdem.Simulation(dim=3, progress=False)
    sim.add_mesh(*FLOOR, contact=LAW)
    ins = sim.insert(box=((-1.0, -1.0, 0.2), (1.2, 1.2, 2.0)), count=4000, grading=g,
                     density=2500.0, contact=LAW)
    sim.run(steps=1)
    assert ins.count == 4000
    r = sim.particles.numpy()["radius"]
    got = tdem.gradings.passing_of(r, [0.017, 0.02, 0.025])
    want = g.passing([0.017, 0.02, 0.025])
    np.testing.assert_allclose(got, want, atol=2.0)


def test_outlet_counts_every_particle_that_left_and_keeps_the_others():
    sim = tdem.Simulation(dim=3, progress=False)
    rng = np.random.default_rng(3)
    x = np.stack(np.meshgrid(*(np.arange(5) * 0.03,) * 3, indexing="ij"), -1).reshape(-1, 3)
    x = x + rng.uniform(-1e-3, 1e-3, x.shape) + [0.0, 0.0, 0.2]
    g = sim.add_particles(x, 0.01, density=2500.0, contact=LAW)
    held = [4, 9]        # the tops of two columns held still (machinery): nothing rests on them
    sim.fix_particles(held, vx=0.0, vy=0.0, vz=0.0)
    out = sim.remove_in(box=((-1, -1, -5), (1, 1, 0.1)), name="outlet")
    sim.run(until=0.3)
    p = sim.particles.numpy()
    # free fall from z >= 0.2: every free particle crossed z = 0.1 by t = sqrt(2·0.22/g)
    assert out.count == len(x) - len(held) == 123
    assert sim.n_particles == len(held)
    assert sorted(p["id"].tolist()) == held
    np.testing.assert_allclose(p["position"][:, 2], x[held, 2], atol=1e-12)  # still held
    assert out.mass == pytest.approx(123 * 2500.0 * 4 / 3 * np.pi * 0.01 ** 3, rel=1e-9)
    assert sorted(out.ids.tolist()) == sorted(set(range(len(x))) - set(held))
    # each left when its centre reached z = 0.1 (within a segment of fall)
    seg = sim.check_interval * sim.dt
    t_fall = np.sqrt(2.0 * (x[out.ids, 2] - 0.1) / 9.81)
    assert np.all(out.times >= t_fall - 1e-9) and np.all(out.times <= t_fall + seg + 1e-9)
    assert list(g.ids) == [0, 1]      # the group: its two particles left, renumbered
    times, values = sim.histories()["outlet"]
    assert values[-1][0] == 123


def _histories(sim):
    """{(id, id): history vector} of every pair in the half lists now."""
    ident = sim.particles.numpy()["id"]
    nbr, hist = sim._a["nbr"].to_numpy(), sim._a["hist"].to_numpy()
    cnt = sim._a["ncnt"].to_numpy()
    return {(int(ident[i]), int(ident[nbr[i, k]])): hist[i, k].copy()
            for i in range(len(nbr)) for k in range(cnt[i])}


def test_removal_keeps_identities_contact_history_and_energy_account():
    """A settled pile of spheres on a floor; the top layer is removed: the others keep
    their identities, positions and every contact's history exactly; the account
    stays closed (what left is in outflow) and goes on after it."""
    from tdem.flows import remove_rows
    sim = tdem.Simulation(dim=3, progress=False, local_damping=0.7)
    sim.add_mesh(*FLOOR, contact=LAW)
    x = np.stack(np.meshgrid(np.arange(4) * 0.026, np.arange(4) * 0.026,
                             0.0125 + np.arange(3) * 0.026, indexing="ij"), -1).reshape(-1, 3)
    x[:, :2] += np.random.default_rng(0).uniform(-4e-4, 4e-4, (len(x), 2))
    sim.add_particles(x, 0.0125, density=2500.0, contact=LAW)
    sim.run(steps=3000)
    e0 = sim.energy()
    before = sim.particles.numpy()
    h0 = _histories(sim)
    top = np.zeros(len(x), bool)
    top[np.argsort(before["position"][:, 2])[-16:]] = True          # the highest 16
    assert len(h0) > 30
    ids, masses = remove_rows(sim, np.flatnonzero(top))
    after = sim.particles.numpy()
    np.testing.assert_array_equal(ids, before["id"][top])
    np.testing.assert_array_equal(after["id"], before["id"][~top])
    np.testing.assert_array_equal(after["position"], before["position"][~top])
    h1 = _histories(sim)
    kept = {k: v for k, v in h0.items() if k[0] in after["id"] and k[1] in after["id"]}
    assert kept.keys() == h1.keys() and len(kept) >= 9
    for k, v in kept.items():
        np.testing.assert_array_equal(h1[k], v)
    e1 = sim.energy()
    assert e1["outflow"] > 0.0
    assert e1["total"] == pytest.approx(e0["total"], rel=0, abs=1e-12 * e1["outflow"])
    assert e1["integration_error"] == pytest.approx(e0["integration_error"], rel=0, abs=1e-15)
    assert e1["dissipated"] == pytest.approx(e0["dissipated"], rel=1e-12)
    # the run goes on: the rest stands (a settled pile loses its top)
    sim.run(steps=500)
    assert np.abs(sim.particles.numpy()["velocity"]).max() < 0.05


def test_checkpoint_with_inserter_and_outlet_restarts_bit_for_bit(tmp_path):
    g = tdem.grading.uniform(0.016, 0.024)

    def model():
        sim = tdem.Simulation(dim=3, progress=False)
        sim.add_mesh(*FLOOR, contact=LAW)
        ins = sim.insert(box=((0.0, 0.0, 0.15), (0.2, 0.2, 0.3)), rate=2.0, grading=g,
                         density=2500.0, contact=LAW, until=0.6, seed=5)
        out = sim.remove_in(box=((0.0, 0.0, -1.0), (0.1, 0.1, 0.02)))
        return sim, ins, out

    ref, ins, out = model()
    ref.run(until=0.3)
    path = tmp_path / "c.h5"
    ref.save(path)
    ref.run(until=0.7)
    sim = tdem.Simulation.load(path)
    sim.run(until=0.7)
    a, b = ref.particles.numpy(), sim.particles.numpy()
    np.testing.assert_array_equal(a["id"], b["id"])
    np.testing.assert_array_equal(a["position"], b["position"])
    assert sim._inserters[0].mass == ins.mass and sim._outlets[0].count == out.count
    assert out.count > 0 and ins.count > 0


def test_bad_flow_input_is_refused_naming_it():
    sim = tdem.Simulation(dim=3, progress=False)
    with pytest.raises(tdem.InputError, match="rate"):
        sim.insert(box=((0, 0, 0), (1, 1, 1)), rate=-1.0, radius=0.01, contact=LAW)
    with pytest.raises(tdem.InputError, match="box"):
        sim.insert(box=((0, 0), (1, 1)), rate=1.0, radius=0.01, contact=LAW)
    with pytest.raises(tdem.InputError, match="exactly one"):
        sim.remove_in(box=((0, 0, 0), (1, 1, 1)), sphere=((0, 0, 0), 1.0))
    with pytest.raises(tdem.InputError, match="polygon"):
        sim.remove_in(polygon=[(0, 0), (1, 0), (0, 1)])
    with pytest.raises(tdem.InputError, match="radius=, grading=, shape="):
        sim.insert(box=((0, 0, 0), (1, 1, 1)), rate=1.0, contact=LAW)
    s2 = tdem.Simulation(progress=False)
    grid = np.stack(np.meshgrid(np.arange(4) * 0.02, np.arange(4) * 0.02), -1).reshape(-1, 2)
    s2.add_particles(grid, 0.01, material=tdem.Elastic(young=1e6, poisson=0.2, density=1000.0), tolerance=0.01)
    with pytest.raises(tdem.InputError, match="PCMM"):
        s2.remove_in(box=((0, 0), (1, 1)))


def test_2d_pluviation_from_a_line_and_a_polygon_outlet():
    """2D: particles released from a line (a flat box) at 20 per second fall through a
    funnel-shaped outlet polygon below (deeper than a particle falls between two
    checks); every one released is counted out."""
    sim = tdem.Simulation(progress=False)
    law = tdem.LinearContact(kn=1e5, friction=0.3, restitution=0.5)
    ins = sim.insert(box=((0.0, 0.5), (0.5, 0.5)), per_s=20.0, radius=0.01, contact=law,
                     until=1.0, seed=1)
    out = sim.remove_in(polygon=[(-0.5, -3.0), (1.0, -3.0), (0.6, 0.0), (-0.1, 0.0)])
    sim.run(until=1.6)
    assert ins.count == 20
    assert np.all(ins.times <= 1.0)
    # every one counted out, but the last: an outlet leaves a model its last particle
    assert out.count + sim.n_particles == 20 and sim.n_particles == 1
    assert out.region.contains(sim.particles.numpy()["position"]).all()


def test_insertion_in_batches_every_so_often_keeps_the_rate():
    """per_s = 200 with every = 0.05 s: batches of 10 at 0.05 s intervals (the mass due
    until the next batch), 60 particles by 0.3 s, at six times."""
    sim = tdem.Simulation(dim=3, progress=False)
    sim.add_mesh(*FLOOR, contact=LAW)
    ins = sim.insert(box=((0.0, 0.0, 0.15), (0.2, 0.2, 0.35)), per_s=200.0, radius=0.01,
                     density=2500.0, contact=LAW, until=0.3, every=0.05, seed=2)
    sim.run(until=0.32)
    assert ins.count == 60
    times = np.unique(ins.times)
    assert len(times) == 6
    np.testing.assert_allclose(np.diff(times), 0.05, atol=sim.check_interval * sim.dt)
