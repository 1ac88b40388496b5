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


def test_grid_finds_exactly_the_vertex_edge_contacts_of_many_coupled_blocks():
    """Blocks of 10 cm, tilted and sunk a little into one another and into a 3 m
    floor (whose corners' tributary length, 1.55 m, once set the grid's cells at
    3.1 m), every pair coupled: the vertex-edge contacts found through the grid are
    those of the contact rule with every edge tested (the crossed-least edge of
    each couple, the entrance rule), and each block's edges are listed once for
    the broad phase, however many couples reach them."""
    from coupling.point_edge import VERTEX_DEPTH, VERTEX_END, VERTEX_ENTRANCE
    rng = np.random.default_rng(5)
    sim = tdem.Simulation(gravity=(0.0, 0.0), dt=1e-9, progress=False)
    concrete = tdem.Elastic(density=2400.0, young=30e9, poisson=0.2)
    fv, ft = tdem.mesh.rectangle(3.0, 0.1, 1, 1, origin=(0.0, -0.1))
    floor = sim.add_block(fv, ft, material=concrete, rigid=True)
    bodies = [floor]
    a = 0.1
    sq = np.array([[0.0, 0.0], [a, 0.0], [a, a], [0.0, a]])
    for c in range(5):
        for r in range(3):
            ang = rng.uniform(-0.02, 0.02)
            rot = np.array([[np.cos(ang), -np.sin(ang)], [np.sin(ang), np.cos(ang)]])
            origin = [1.0 + c * (a - 1e-3), r * (a - 1e-3) - 1e-3] + rng.uniform(-5e-4, 5e-4, 2)
            v = (sq - 0.5 * a) @ rot.T + 0.5 * a + origin
            bodies.append(sim.add_block(v, np.array([[0, 1, 2], [0, 2, 3]]), material=concrete,
                                        rigid=True))
    for b in bodies:
        b.fix(np.arange(len(b.vertices)), vx=0.0, vy=0.0)
    law = tdem.PointEdge(kn=3e8, ks=1e8, friction_angle=25.0)
    for k, b in enumerate(bodies):
        for o in bodies[k + 1:]:
            sim.couple(b, o, law)
    sim.run(steps=1)
    c = sim.point_edge_contacts()
    vx = c["kind"] == 1
    found = sorted(map(tuple, np.round(np.hstack([c["point"][vx], c["foot"][vx]]), 9)))
    expect = []
    for src in bodies:
        for dst in bodies:
            if src is dst:
                continue
            xs = src.nodes()["position"]
            xd = dst.nodes()["position"]
            sb = boundary_edges(src.triangles)
            prev = {j: i for i, j in sb}
            nxt = {i: j for i, j in sb}
            trib = {i: 0.0 for i in prev}
            for i, j in sb:
                ln = np.linalg.norm(xs[j] - xs[i])
                trib[i] += 0.5 * ln
                trib[j] += 0.5 * ln
            for q in sorted(prev):
                x = xs[q]
                best, dbest = None, np.inf
                for i, j in boundary_edges(dst.triangles):
                    e = xd[j] - xd[i]
                    L = np.linalg.norm(e)
                    t = e / L
                    n = np.array([t[1], -t[0]])
                    s = (x - xd[i]) @ t / L
                    d = (x - xd[i]) @ n
                    if not (-VERTEX_END <= s <= 1.0 + VERTEX_END and -VERTEX_DEPTH * trib[q] < d < 0.0
                            and -d < dbest):
                        continue
                    if all((xs[nb] - x) @ n >= -VERTEX_ENTRANCE * np.linalg.norm(xs[nb] - x)
                           for nb in (prev[q], nxt[q])):
                        best, dbest = (i, j, s), -d
                if best is not None:
                    i, j, s = best
                    expect.append(tuple(np.round(np.concatenate([x, xd[i] + s * (xd[j] - xd[i])]), 9)))
    assert len(found) > 40
    assert found == sorted(expect)
    # 16 blocks of 4 boundary edges, each listed once (not once per couple: 240 couples)
    assert sim._cont.a["vedges"].shape[0] == 4 * len(bodies)
