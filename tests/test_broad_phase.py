"""Broad phase of the point-edge contacts (coupling.point_edge.bin_edges): the edges
a particle tests are those of its grid cell; the contacts found must be exactly the
pairs that the contact rule gives when every edge is tested."""
import numpy as np
import pytest

import tdem
from tdem.mesh import boundary_edges


@pytest.mark.filterwarnings("ignore:positions.*overlapping:RuntimeWarning")  # random discs
def test_grid_finds_exactly_the_touching_particle_edge_pairs():
    rng = np.random.default_rng(3)
    corners = [[0.0, 0.0], [1.2, 0.0], [1.4, 0.5], [0.6, 0.8], [-0.2, 0.4]]
    v, t = tdem.mesh.polygon(corners, 0.05)
    be = boundary_edges(t)
    sim = tdem.Simulation(gravity=(0.0, 0.0), dt=1e-9, progress=False)
    block = sim.add_block(v, t, material=tdem.Elastic(density=2500.0, young=1e7, poisson=0.25))
    block.fix(np.arange(len(v)), vx=0.0, vy=0.0)
    # discs scattered around the boundary (most within a radius of an edge) and far away
    k = rng.integers(0, len(be), 300)
    s = rng.uniform(0.0, 1.0, 300)
    foot = v[be[k, 0]] + s[:, None] * (v[be[k, 1]] - v[be[k, 0]])
    r = rng.uniform(0.01, 0.03, 300)
    x = foot + rng.normal(0.0, 0.03, (300, 2))
    x = np.vstack([x, [[5.0, 5.0], [-3.0, 0.2]]])
    r = np.concatenate([r, [0.02, 0.02]])
    discs = sim.add_particles(x, r, density=1000.0, contact=tdem.LinearContact(kn=1e5))
    sim.fix_particles(discs.ids, vx=0.0, vy=0.0)
    sim.couple(discs, block, tdem.PointEdge(kn=1e5, friction_angle=20.0))
    sim.run(steps=1)
    c = sim.point_edge_contacts()
    found = sorted(map(tuple, np.round(np.hstack([c["point"], c["foot"]]), 9)))
    # every edge tested: |d| < R and the projection on [0, 1), at most SLOTS per disc
    expect = []
    for p, rad in zip(x, r):
        hits = []
        for i, j in be:
            e = v[j] - v[i]
            L = np.linalg.norm(e)
            tt = e / L
            nn = np.array([tt[1], -tt[0]])
            ss = (p - v[i]) @ tt / L
            if 0.0 <= ss < 1.0 and abs((p - v[i]) @ nn) < rad:
                hits.append(tuple(np.round(np.concatenate([p, v[i] + ss * e]), 9)))
        expect += hits[:4]
    assert len(found) > 100
    assert found == sorted(expect)
