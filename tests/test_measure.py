"""sim.measure: Love–Weber stress, porosity, coordination and fabric of a region.

A pack compressed between four walls and brought to rest: over the region the walls
enclose, the Love–Weber stress is the stress the walls carry (σ_xx = −F_x/H, σ_yy =
−F_y/W, tension-positive) within 2 %; porosity, coordination and fabric follow from
their definitions. In 3D, periodic cubic lattices of pressed spheres and ellipsoids,
against the Hertz force and the lattice's geometry."""
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
    # porosity from the part of every disc inside the circle: the lens, as two
    # circular segments cut by the common chord
    solid = _lens_areas(np.linalg.norm(p["position"] - centre, axis=1), p["radius"], 0.08)
    assert m["porosity"] == pytest.approx(1.0 - solid.sum() / (math.pi * 0.08 ** 2),
                                          rel=1e-12)
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


def _segment(r, h):
    """Area of the segment of a circle of radius r cut at distance h from its centre."""
    h = np.clip(h, -r, r)
    return r * r * np.arccos(h / r) - h * np.sqrt(r * r - h * h)


def _lens_areas(d, r, rc):
    """Area of discs of radius r at distance d from the centre of a circle of radius
    rc inside it: whole, nothing, or two segments cut by the common chord."""
    d = np.asarray(d, float)
    a = np.where(d <= rc - r, math.pi * r * r, 0.0)
    lens = (d > rc - r) & (d < rc + r)
    x = (d[lens] ** 2 + rc ** 2 - r[lens] ** 2) / (2.0 * d[lens])   # chord from the centre
    a[lens] = _segment(rc, x) + _segment(r[lens], d[lens] - x)
    return a


def _lens_volumes(d, r, rc):
    """Volume of spheres of radius r at distance d from the centre of a sphere of
    radius rc inside it: whole, nothing, or two caps cut by the common plane."""
    d = np.asarray(d, float)
    r = np.broadcast_to(r, d.shape)
    v = np.where(d <= rc - r, 4.0 / 3.0 * math.pi * r ** 3, 0.0)
    lens = (d > rc - r) & (d < rc + r)
    x = (d[lens] ** 2 + rc ** 2 - r[lens] ** 2) / (2.0 * d[lens])

    def cap(R, h):                        # cap of height h of a sphere of radius R
        return math.pi * h * h * (3.0 * R - h) / 3.0
    v[lens] = cap(rc, rc - x) + cap(r[lens], r[lens] - (d[lens] - x))
    return v


@pytest.mark.parametrize("kw, match", [
    ({}, r"exactly one of box=, circle=, polygon="),
    ({"box": ((0, 0), (0, 1))}, r"^box must be \(\(x0, y0\), \(x1, y1\)\) with x1 > x0"),
    ({"circle": ((0, 0), -1.0)}, r"^circle must be \(\(cx, cy\), r\) with r > 0"),
    ({"polygon": [(0, 0), (1, 1)]}, r"^polygon must be \(K, 2\) vertices"),
])
def test_bad_regions_are_refused(pack, kw, match):
    with pytest.raises(tdem.InputError, match=match):
        pack[0].measure(**kw)


def _periodic_lattice(shape=None, n=4, R=0.01, delta=2e-4, semi=None):
    """A simple cubic lattice, periodic on all three axes, of spheres of radius R (or
    ellipsoids of semi-axes ``semi``, not turned), each pressed into its six
    neighbours by ``delta`` (``n`` cells, or one number per axis); no gravity, at rest: every particle in equilibrium."""
    hm = tdem.HertzMindlin(young=1e8, poisson=0.25, friction=0.5, restitution=0.5)
    half = np.array(semi if semi is not None else (R, R, R))
    step = 2.0 * half - delta
    n = np.broadcast_to(n, 3)                # cells along x, y, z
    sim = tdem.Simulation(dim=3, gravity=(0.0, 0.0, 0.0), progress=False)
    sim.periodic(x=(0.0, n[0] * step[0]), y=(0.0, n[1] * step[1]), z=(0.0, n[2] * step[2]))
    g = (np.stack(np.meshgrid(*[np.arange(k) for k in n], indexing="ij"), -1).reshape(-1, 3)
         + 0.5) * step
    if semi is None:
        sim.add_particles(g, R, density=2000.0, contact=hm)
    else:
        sim.add_particles(g, shape=tdem.Ellipsoid(*semi), density=2000.0, contact=hm)
    sim.run(steps=1)
    return sim, step, hm


def test_3d_love_weber_stress_of_a_pressed_cubic_lattice():
    """Each sphere pressed by δ into its six neighbours carries the Hertz force
    F = 4/3 E* √(R/2) δ^{3/2} on each; over any region of whole cells the stress is
    −F/a² on the diagonal (a = 2R − δ the lattice step) and zero off it, porosity
    1 − (4/3)πR³/a³, coordination 6, fabric I/3. In a box of 2³ cells and in a sphere
    about one particle holding it and its six neighbours."""
    R, delta = 0.01, 2e-4
    sim, step, hm = _periodic_lattice(R=R, delta=delta)
    a = step[0]
    e_star = hm.young / (2.0 * (1.0 - hm.poisson ** 2))
    F = 4.0 / 3.0 * e_star * math.sqrt(0.5 * R) * delta ** 1.5
    c = sim.contacts.numpy()
    np.testing.assert_allclose(c["normal_force"], F, rtol=1e-9)
    m = sim.measure(box=((a, a, a), (3.0 * a, 3.0 * a, 3.0 * a)))
    assert m["particles"] == 8 and m["volume"] == pytest.approx(8.0 * a ** 3)
    np.testing.assert_allclose(m["stress"], -F / a ** 2 * np.eye(3), atol=1e-9 * F / a ** 2)
    assert m["porosity"] == pytest.approx(1.0 - 4.0 / 3.0 * math.pi * R ** 3 / a ** 3,
                                          rel=1e-12)
    assert m["coordination"] == pytest.approx(6.0)
    np.testing.assert_allclose(m["fabric"], np.eye(3) / 3.0, atol=1e-12)
    centre = 2.5 * a                       # a particle's centre
    r = 1.1 * a
    s = sim.measure(sphere=((centre, centre, centre), r))
    assert s["particles"] == 7
    # the seven centres inside carry 7 F a on the diagonal; scaled by the solid inside
    # (the caps of the spheres cut by the region) over their seven volumes
    vol = 4.0 / 3.0 * math.pi * r ** 3
    pos = sim.particles.numpy()["position"]
    solid = _lens_volumes(np.linalg.norm(pos - centre, axis=1), R, r).sum()
    assert s["porosity"] == pytest.approx(1.0 - solid / vol, rel=1e-12)
    vs = 4.0 / 3.0 * math.pi * R ** 3
    want = -7.0 * F * a * (solid / vol) / (7.0 * vs)
    np.testing.assert_allclose(s["stress"], want * np.eye(3), atol=1e-9 * abs(want))


def test_3d_measure_of_a_pressed_lattice_of_ellipsoids():
    """Ellipsoids (not turned) on a lattice of steps 2a − δ, 2b − δ, 2c − δ: the force
    along each axis F_k acts at the midpoint of the support points, half a step from
    each centre, so σ_kk = −F_k s_k / (s_x s_y s_z); the porosity counts each
    ellipsoid's volume (4/3)πabc."""
    semi = (0.012, 0.009, 0.006)
    sim, step, _ = _periodic_lattice(semi=semi, delta=1.5e-4, n=(4, 5, 8))
    c = sim.contacts.numpy()
    axis = np.argmax(np.abs(c["direction"]), axis=1)
    np.testing.assert_allclose(np.abs(c["direction"][np.arange(len(axis)), axis]), 1.0,
                               atol=1e-9)
    forces = np.array([c["normal_force"][axis == k].mean() for k in range(3)])
    for k in range(3):
        np.testing.assert_allclose(c["normal_force"][axis == k], forces[k], rtol=1e-6)
    cell = float(np.prod(step))
    lo, hi = step, 3.0 * step
    m = sim.measure(box=(lo, hi))
    assert m["particles"] == 8
    np.testing.assert_allclose(np.diag(m["stress"]), -forces * step / cell, rtol=1e-6)
    assert np.abs(m["stress"] - np.diag(np.diag(m["stress"]))).max() < 1e-6 * forces.max() / step.max() ** 2
    assert m["porosity"] == pytest.approx(1.0 - 4.0 / 3.0 * math.pi * np.prod(semi) / cell,
                                          rel=1e-9)


def test_3d_regions_are_checked():
    sim, step, _ = _periodic_lattice()
    with pytest.raises(tdem.InputError, match="circle: a 2D region"):
        sim.measure(circle=((0.0, 0.0), 1.0))
    with pytest.raises(tdem.InputError, match=r"box must be \(\(x0, y0, z0\)"):
        sim.measure(box=((0.0, 0.0), (1.0, 1.0)))
    with pytest.raises(tdem.InputError, match="sphere must be"):
        sim.measure(sphere=((0.0, 0.0, 0.0), -1.0))
    flat = tdem.Simulation(progress=False)
    flat.add_particles([[0.0, 0.0]], 0.1, contact=tdem.LinearContact(kn=1e5))
    with pytest.raises(tdem.InputError, match="sphere: a 3D region"):
        flat.measure(sphere=((0.0, 0.0, 0.0), 1.0))
