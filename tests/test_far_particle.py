"""One particle far from the rest: the cell grid stays within O(particles) cells of the
right size (it used to be sized to the bounding box: 1e6 m away passed 8 GB, and
1e4 m made every cell hold the whole pile), and the pile moves exactly as without it."""
import numpy as np
import pytest

import tdem

LAW = tdem.LinearContact(kn=1e6, friction=0.3, restitution=0.5)


def _pile(far=None):
    sim = tdem.Simulation(gravity=(0.0, -9.81), dt=1e-4)
    rng = np.random.default_rng(7)
    xs = (np.arange(20) + 0.5) * 0.02
    pos = np.array([(x, y) for y in xs for x in xs]) + rng.uniform(-5e-4, 5e-4, (400, 2))
    pos[:, 1] += 0.011
    sim.add_particles(pos, 0.009, density=2500.0, contact=LAW)
    if far is not None:
        sim.add_particles([far], 0.009, density=2500.0, contact=LAW)
    sim.add_wall((-0.1, 0.0), (0.5, 0.0), contact=LAW)
    return sim


@pytest.mark.parametrize("far", [(1e4, 0.0), (0.2, 1e6), (-1e6, -1e6)])
def test_far_particle_keeps_the_grid_small_and_the_pile_unchanged(far):
    ref = _pile()
    ref.run(steps=600)
    sim = _pile(far)
    sim.run(steps=600)
    n = sim.n_particles
    cells = sim._a["cell_count"].shape[0]
    assert cells <= 4 * n + 1024
    # cells of one diameter plus the skin, as without the far particle
    assert sim._a["gridp"].to_numpy()[2] == pytest.approx(2 * 0.009 + sim.skin, rel=1e-12)
    a = ref.particles.numpy()["position"]
    b = sim.particles.numpy()["position"][:400]
    np.testing.assert_allclose(b, a, rtol=0, atol=1e-12)
    # the far one falls freely, y = y0 − g t²/2 (within the leapfrog's one-step drift)
    t = 600 * 1e-4
    yf = sim.particles.numpy()["position"][400, 1]
    assert yf == pytest.approx(far[1] - 0.5 * 9.81 * t * t, abs=1e-3 * abs(far[1]) + 1e-3)
