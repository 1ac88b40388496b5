"""Where the PCMM element records go (physics.pcmm.record_slots): one run per
particle, in particle order, so that neighbouring particles' records lie side by
side in memory."""
import numpy as np
import pytest

import tdem  # noqa: F401  (tdem first: it imports physics in its order)
from tdem import backend
from physics import pcmm


@pytest.mark.parametrize("n", [1, 7, pcmm.SCAN_BLOCK - 1, pcmm.SCAN_BLOCK,
                               pcmm.SCAN_BLOCK + 1, 5 * pcmm.SCAN_BLOCK + 17])
@pytest.mark.parametrize("serial", [False, True])
def test_record_runs_are_the_prefix_sum_of_computed_elements(n, serial):
    import taichi as ti
    backend.init()
    rng = np.random.default_rng(n)
    ecomp = rng.integers(0, pcmm.MAX_ELEMENTS + 1, n).astype(np.int32)
    arrays = {"ecomp": (n,), "ebase": (n,), "eoff": (n // pcmm.SCAN_BLOCK + 2,)}
    a = {k: ti.ndarray(ti.i32, shape) for k, shape in arrays.items()}
    a["ecomp"].from_numpy(ecomp)
    a["ebase"].fill(-7)
    pcmm.record_slots(a["ecomp"], a["ebase"], a["eoff"], serial)
    np.testing.assert_array_equal(a["ebase"].to_numpy(), np.cumsum(ecomp) - ecomp)


def test_computed_counts_follow_the_elements_through_deaths_and_births():
    """``ecomp``, kept by the copies pass only where something changed, is each
    particle's count of computed elements at every check of a body whose elements
    die and are born (and the records' runs its prefix sum)."""
    pos, rad = tdem.pack.random(0.3, 0.3, 0.008, 0.012, seed=2, target_fraction=0.72)
    rng = np.random.default_rng(2)
    vel = rng.normal(0.0, 0.3, pos.shape) - 8.0 * (pos - pos.mean(axis=0))
    sim = tdem.Simulation(gravity=(0.0, 0.0), dt_fraction=0.3, progress=False)
    sim.add_particles(pos, rad, material=tdem.Elastic(density=1000.0, young=2e4, poisson=0.25),
                      tolerance=0.012, velocity=vel,
                      contact=tdem.LinearContact(kn=2e4, ks=2e4, friction=0.3))
    changed = 0
    prev = None
    for _ in range(8):
        sim.run(steps=40)
        a = sim._cont.a
        ecnt, emult = a["ecnt"].to_numpy(), a["emult"].to_numpy()
        want = ((emult > 0) & (np.arange(emult.shape[1])[None, :] < ecnt[:, None])).sum(axis=1)
        np.testing.assert_array_equal(a["ecomp"].to_numpy(), want)
        np.testing.assert_array_equal(a["ebase"].to_numpy(), np.cumsum(want) - want)
        tri = {tuple(sorted(t)) for t in sim.elements.numpy()["triangles"]}
        if prev is not None:
            changed += len(tri ^ prev)
        prev = tri
    assert changed > 50


def _ringing_square(order):
    """A 12 × 12 square-lattice PCMM body (N_e = 2 everywhere, whatever the particle
    order: the probe never lies on a square's diagonal) set ringing by a velocity
    field of shear and spin, its particles listed in ``order``; returns the
    positions and stresses after 300 steps, in the lattice's own order."""
    pos, rad = tdem.pack.regular(1.2, 1.2, 0.05)
    c = pos - pos.mean(axis=0)
    vel = 0.4 * np.stack([c[:, 1], 0.3 * c[:, 0]], axis=1) \
        + 0.2 * np.stack([-c[:, 1], c[:, 0]], axis=1)
    sim = tdem.Simulation(gravity=(0.0, 0.0), progress=False)
    sim.add_particles(pos[order], rad[order], material=tdem.Elastic(
        density=2000.0, young=1e7, poisson=0.25), tolerance=0.05, velocity=vel[order])
    sim.run(steps=300)
    p = sim.particles.numpy()
    back = np.argsort(order)
    return p["position"][back], p["stress"][back], len(sim.elements.numpy()["triangles"])


def test_a_body_moves_the_same_whatever_the_order_of_its_particles():
    """The packed records (record_slots) follow the particle order; a body listed in
    a shuffled order must move as the same body listed row by row (to rounding: the
    sums run in another order)."""
    n = 144
    x0, s0, e0 = _ringing_square(np.arange(n))
    x1, s1, e1 = _ringing_square(np.random.default_rng(5).permutation(n))
    assert e0 == e1 == 4 * 11 * 11 * 2        # both diagonals of every square, 2 copies
    moved = np.abs(x0 - tdem.pack.regular(1.2, 1.2, 0.05)[0]).max()
    assert moved > 1e-3                       # the body did move and deform
    np.testing.assert_allclose(x1, x0, rtol=0, atol=1e-10 * moved)
    scale = np.abs(s0).max()
    assert scale > 1e3
    np.testing.assert_allclose(s1, s0, rtol=0, atol=1e-11 * scale)
