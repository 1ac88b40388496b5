"""sim.measure: Love–Weber stress, porosity, coordination and fabric of a region.

A pack compressed between four walls and brought to rest: over the region the walls
enclose, the Love–Weber stress is the stress the walls carry (σ_xx = −F_x/H, σ_yy =
−F_y/W, tension-positive) within 2 %; porosity, coordination and fabric follow from
their definitions."""
import math

import numpy as np
import pytest

import tdem


@pytest.fixture(scope="module")
def pack():
    law = tdem.LinearContact(kn=1e6, ks=5e5, friction=0.3)
    # frictionless walls (as in biaxial tests): with friction they carry shear, and
    # the stress inside is not uniform
    smooth = tdem.LinearContact(kn=1e6, ks=5e5, friction=0.0)
    sim = tdem.Simulation(gravity=(0.0, 0.0), local_damping=0.7)
    rng = np.random.default_rng(3)
    side, d = 16, 0.02
    xy = (np.stack(np.meshgrid(np.arange(side), np.arange(side)), -1).reshape(-1, 2)
          + 0.5) * d + rng.uniform(-1e-3, 1e-3, (side * side, 2))
    sim.add_particles(xy, rng.uniform(0.0085, 0.0098, len(xy)), density=2500.0,
                      contact=law)
    L = side * d
    walls = [sim.add_wall((0.0, 0.0), (L, 0.0), contact=smooth),     # bottom
             sim.add_wall((L, 0.0), (L, L), contact=smooth),         # right
             sim.add_wall((L, L), (0.0, L), contact=smooth),         # top
             sim.add_wall((0.0, L), (0.0, 0.0), contact=smooth)]     # left
    inward = [(0.0, 1.0), (-1.0, 0.0), (0.0, -1.0), (1.0, 0.0)]
    for w, v in zip(walls, inward):
        w.velocity = (0.05 * v[0], 0.05 * v[1])
    sim.run(until=0.5)           # 0.025 m in from each side: the pack is jammed
    for w in walls:
        w.velocity = (0.0, 0.0)
    sim.run(until=1.5)
    return sim, walls


def test_love_weber_stress_is_the_wall_stress(pack):
    sim, (bottom, right, top, left) = pack
    x0, x1 = left.endpoints[0][0], right.endpoints[0][0]
    y0, y1 = bottom.endpoints[0][1], top.endpoints[0][1]
    W, H = x1 - x0, y1 - y0
    # the walls receive the pack's push: outward, +x on the right wall
    sxx = -0.5 * (right.force[0] - left.force[0]) / H
    syy = -0.5 * (top.force[1] - bottom.force[1]) / W
    assert sxx < -1e3 and syy < -1e3          # compressed
    m = sim.measure(box=((x0, y0), (x1, y1)))
    assert m["particles"] == sim.n_particles and m["area"] == pytest.approx(W * H)
    assert m["stress"][0, 0] == pytest.approx(sxx, rel=0.02)
    assert m["stress"][1, 1] == pytest.approx(syy, rel=0.02)
    assert abs(m["stress"][0, 1]) < 0.02 * abs(sxx)


def test_porosity_coordination_and_fabric(pack):
    sim, walls = pack
    p = sim.particles.numpy()
    c = sim.contacts.numpy()
    centre = p["position"].mean(axis=0)
    m = sim.measure(circle=(centre, 0.08))
    inside = np.sum((p["position"] - centre) ** 2, axis=1) <= 0.08 ** 2
    assert m["particles"] == int(inside.sum())
    assert m["porosity"] == pytest.approx(
        1.0 - np.sum(math.pi * p["radius"][inside] ** 2) / (math.pi * 0.08 ** 2), rel=1e-12)
    # the contacts of the particles inside, each counted from each of its particles inside
    ids = np.flatnonzero(inside)
    count = np.isin(c["pairs"][:, 0], ids).sum() + np.isin(c["pairs"][:, 1], ids).sum()
    assert m["coordination"] == pytest.approx(count / len(ids), rel=1e-12)
    assert 3.0 < m["coordination"] < 6.0           # a jammed 2D pack
    assert np.trace(m["fabric"]) == pytest.approx(1.0, rel=1e-12)
    assert m["fabric"][0, 1] == pytest.approx(m["fabric"][1, 0])
    # a polygon of the same box gives the box's numbers
    b = ((0.05, 0.05), (0.25, 0.2))
    poly = [(0.05, 0.05), (0.25, 0.05), (0.25, 0.2), (0.05, 0.2)]
    mb, mp = sim.measure(box=b), sim.measure(polygon=poly)
    np.testing.assert_allclose(mp["stress"], mb["stress"], rtol=1e-12)
    assert mp["porosity"] == pytest.approx(mb["porosity"], rel=1e-12)


@pytest.mark.parametrize("kw, match", [
    ({}, r"exactly one of box=, circle=, polygon="),
    ({"box": ((0, 0), (0, 1))}, r"^box must be \(\(x0, y0\), \(x1, y1\)\) with x1 > x0"),
    ({"circle": ((0, 0), -1.0)}, r"^circle must be \(\(cx, cy\), r\) with r > 0"),
    ({"polygon": [(0, 0), (1, 1)]}, r"^polygon must be \(K, 2\) vertices"),
])
def test_bad_regions_are_refused(pack, kw, match):
    with pytest.raises(tdem.InputError, match=match):
        pack[0].measure(**kw)
