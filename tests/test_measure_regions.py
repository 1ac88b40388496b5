"""sim.measure over regions of a dense random pack under a uniform stress.

The Love–Weber sum of the particles whose centres lie in a region is scaled by
(1 − n)/Σ V_p, n the porosity of the parts of the particles inside the region (as
PFC's measurement circles): the stress does not depend on how many centres fall
in. A pack between frictionless walls (2D: four servo walls; 3D: a bed periodic in
x and y between a floor and a lid, 4–6 diameters high in 3D) brought to rest
carries the walls' stress; the force network makes a small region's stress scatter
about it (≈ 10 % at 5 diameters, 1.5 % at 20), and the mean over regions at random
offsets is the walls' stress within 3 %. The porosity is that of the exact areas (volumes) of the
particles inside, computed here by other formulas (the disc's quadrant areas, the
lens as two segments or two caps, sphere–box by Simpson's rule over slices).
"""
import math
import warnings

import numpy as np
import pytest

import tdem
from tdem import overlap_volume as ov


# -- independent references ------------------------------------------------
def _quadrant(x, y, r):
    """Area of the disc of radius r about the origin with X <= x and Y <= y."""
    x, y = np.clip(x, -r, r), np.clip(y, -r, r)

    def g(t):                                   # ∫ sqrt(r² − t²) dt
        t = np.clip(t, -r, r)
        return 0.5 * (t * np.sqrt(np.maximum(r * r - t * t, 0.0))
                      + r * r * np.arcsin(t / np.where(r > 0, r, 1.0)))
    s = np.sqrt(np.maximum(r * r - y * y, 0.0))
    c = np.clip(x, -s, s)
    middle = y * (c + s) + g(c) - g(-s)
    outer = 2.0 * (g(np.minimum(x, -s)) - g(-r)) + 2.0 * (g(np.maximum(x, s)) - g(s))
    return middle + np.where(y >= 0.0, outer, 0.0)


def _disc_box(c, r, lo, hi):
    x0, x1 = lo[0] - c[..., 0], hi[0] - c[..., 0]
    y0, y1 = lo[1] - c[..., 1], hi[1] - c[..., 1]
    return (_quadrant(x1, y1, r) - _quadrant(x0, y1, r) - _quadrant(x1, y0, r)
            + _quadrant(x0, y0, r))


def _segment(r, h):
    h = np.clip(h, -r, r)
    return r * r * np.arccos(h / r) - h * np.sqrt(r * r - h * h)


def _disc_circle(d, r, rc):
    a = np.where(d <= rc - r, math.pi * r * r, 0.0)
    lens = (d > rc - r) & (d < rc + r)
    x = (d[lens] ** 2 + rc ** 2 - r[lens] ** 2) / (2.0 * d[lens])
    a[lens] = _segment(rc, x) + _segment(r[lens], d[lens] - x)
    return a


def _sphere_sphere(d, r, rc):
    v = np.where(d <= rc - r, 4.0 / 3.0 * math.pi * r ** 3, 0.0)
    lens = (d > rc - r) & (d < rc + r)
    x = (d[lens] ** 2 + rc ** 2 - r[lens] ** 2) / (2.0 * d[lens])
    h1, h2 = rc - x, r[lens] - (d[lens] - x)
    v[lens] = math.pi / 3.0 * (h1 * h1 * (3.0 * rc - h1) + h2 * h2 * (3.0 * r[lens] - h2))
    return v


def _sphere_box(c, r, lo, hi, slices=1000):
    """Σ over the spheres of the volume inside the box, Simpson's rule over z."""
    c, r = np.asarray(c, float).reshape(-1, 3), np.asarray(r, float).reshape(-1)
    za, zb = np.maximum(c[:, 2] - r, lo[2]), np.minimum(c[:, 2] + r, hi[2])
    keep = zb > za
    c, r, za, zb = c[keep], r[keep], za[keep], zb[keep]
    u = np.linspace(0.0, 1.0, slices + 1)
    z = za[:, None] + (zb - za)[:, None] * u                      # (M, slices + 1)
    rho = np.sqrt(np.maximum(r[:, None] ** 2 - (z - c[:, 2, None]) ** 2, 0.0))
    a = _disc_box(np.broadcast_to(c[:, None, :2], z.shape + (2,)), rho, lo[:2], hi[:2])
    w = np.ones(slices + 1)
    w[1:-1:2], w[2:-1:2] = 4.0, 2.0
    return float(np.sum((zb - za) / slices / 3.0 * (a @ w)))


def test_intersections_against_closed_forms():
    """The module's formulas against the references above and against exact cases:
    a sphere at a box's corner, edge and face keeps 1/8, 1/4 and 1/2 of itself."""
    rng = np.random.default_rng(0)
    lo, hi = np.array([0.0, 0.0, 0.0]), np.array([1.0, 0.7, 0.8])
    c = rng.uniform(-0.3, 1.3, (500, 2))
    r = rng.uniform(0.05, 0.5, 500)
    np.testing.assert_allclose(ov.disc_box_area(c, r, lo[:2], hi[:2]),
                               _disc_box(c, r, lo[:2], hi[:2]), atol=1e-12 * math.pi * 0.25)
    d = np.linalg.norm(c - 0.5, axis=1)
    np.testing.assert_allclose(ov.disc_disc_area(c, r, (0.5, 0.5), 0.3),
                               _disc_circle(d, r, 0.3), rtol=1e-10, atol=1e-14)
    c3 = rng.uniform(-0.3, 1.1, (40, 3))
    r3 = rng.uniform(0.1, 0.5, 40)
    vol = 4.0 / 3.0 * math.pi * r3 ** 3
    got = ov.sphere_box_volume(c3, r3, lo, hi)
    for k in range(len(r3)):
        assert got[k] == pytest.approx(_sphere_box(c3[k:k + 1], r3[k:k + 1], lo, hi),
                                       abs=1e-6 * vol[k])
    d3 = np.linalg.norm(c3 - 0.4, axis=1)
    np.testing.assert_allclose(ov.sphere_sphere_volume(c3, r3, (0.4, 0.4, 0.4), 0.35),
                               _sphere_sphere(d3, r3, 0.35), rtol=1e-10, atol=1e-14)
    parts = ov.sphere_box_volume([[0, 0, 0], [0.5, 0, 0], [0.5, 0.35, 0]], [0.2] * 3, lo, hi)
    np.testing.assert_allclose(parts / (4.0 / 3.0 * math.pi * 0.2 ** 3), [0.125, 0.25, 0.5],
                               rtol=1e-9)


# -- 2D --------------------------------------------------------------------
@pytest.fixture(scope="module")
def pack2d():
    L = 0.3
    pos, rad = tdem.pack.random(L, L, 0.004, 0.006, seed=1, target_fraction=0.8)
    law = tdem.LinearContact(kn=1e6, ks=5e5, friction=0.0)
    sim = tdem.Simulation(gravity=(0.0, 0.0), local_damping=0.7, progress=False)
    sim.add_particles(pos, rad, density=2500.0, contact=law)
    walls = [sim.add_wall((0.0, 0.0), (L, 0.0), contact=law),       # bottom
             sim.add_wall((L, 0.0), (L, L), contact=law),           # right
             sim.add_wall((L, L), (0.0, L), contact=law),           # top
             sim.add_wall((0.0, L), (0.0, 0.0), contact=law)]       # left
    for w in walls:
        w.servo(stress=2e4)
    sim.run(steps=3000)
    for w in walls:
        w.servo()
    sim.run(steps=2000)
    return sim, walls


def test_2d_regions_carry_the_walls_stress(pack2d):
    sim, (bottom, right, top, left) = pack2d
    x0, x1 = left.endpoints[0][0], right.endpoints[0][0]
    y0, y1 = bottom.endpoints[0][1], top.endpoints[0][1]
    wall = np.array([-0.5 * (right.force[0] - left.force[0]) / (y1 - y0),
                     -0.5 * (top.force[1] - bottom.force[1]) / (x1 - x0)])
    assert np.all(wall < -1.5e4)
    p = sim.particles.numpy()
    x, r = p["position"], p["radius"]
    rng = np.random.default_rng(0)
    d = 0.01                                     # the mean diameter
    # more regions where they scatter more (the mean's scatter about 1.3 % each)
    for size, count in ((5, 80), (10, 40), (15, 20), (20, 10)):
        s = size * d
        ratios = {"box": [], "circle": []}
        for _ in range(count):
            c = rng.uniform([x0 + s / 2 + d, y0 + s / 2 + d], [x1 - s / 2 - d, y1 - s / 2 - d])
            mb = sim.measure(box=(c - s / 2, c + s / 2))
            mc = sim.measure(circle=(c, s / 2))
            exact_b = 1.0 - _disc_box(x, r, c - s / 2, c + s / 2).sum() / s ** 2
            exact_c = 1.0 - _disc_circle(np.linalg.norm(x - c, axis=1), r, s / 2).sum() / (
                math.pi * s * s / 4)
            assert mb["porosity"] == pytest.approx(exact_b, rel=0.005)
            assert mc["porosity"] == pytest.approx(exact_c, rel=0.005)
            ratios["box"].append(np.diag(mb["stress"]) / wall)
            ratios["circle"].append(np.diag(mc["stress"]) / wall)
        for kind, v in ratios.items():
            np.testing.assert_allclose(np.mean(v, axis=0), 1.0, atol=0.03,
                                       err_msg=f"{kind} of {size} diameters")


# -- 3D --------------------------------------------------------------------
@pytest.fixture(scope="module")
def bed3d():
    """Spheres periodic in x and y, pressed between a frictionless floor and lid and
    held: σ_zz is the lid's force over L²."""
    L, H = 0.06, 0.09
    x, r = tdem.pack.random3d((0, 0, 0), (L, L, H), 0.003, 0.004, seed=2,
                              target_fraction=0.5)
    hm = tdem.HertzMindlin(young=1e7, poisson=0.3, friction=0.0, restitution=0.3)
    # half the default step: at the default the pressed bed's Hertz contacts need a
    # shorter one (the run warns), and it jitters at metres per second, the lid and the
    # floor apart by 10 %; at half it comes to rest (lid and floor equal to round-off)
    sim = tdem.Simulation(dim=3, gravity=(0, 0, 0), local_damping=0.7, progress=False,
                          dt_fraction=0.1)
    sim.periodic(x=(0.0, L), y=(0.0, L))
    floor = sim.add_mesh(*tdem.surfaces.plane((L / 2, L / 2, 0.0), (0, 0, 1.0), L + 0.03, 2),
                         contact=hm)
    lid = sim.add_mesh(*tdem.surfaces.plane((L / 2, L / 2, H), (0, 0, -1.0), L + 0.03, 2),
                       contact=hm)
    sim.add_particles(x, r, density=2500.0, contact=hm)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        lid.servo(stress=2e4)
        sim.run(until=0.15)
        lid.servo()
        sim.run(until=0.6)
    assert lid.force[2] == pytest.approx(-floor.force[2], rel=1e-6)     # at rest
    return sim, floor, lid, L


def test_3d_regions_carry_the_lid_stress(bed3d):
    sim, floor, lid, L = bed3d
    szz = -0.5 * (lid.force[2] - floor.force[2]) / L ** 2
    assert szz < -1.5e4
    p = sim.particles.numpy()
    x, r = p["position"], p["radius"]
    top = float(np.max(x[:, 2] + r))
    rng = np.random.default_rng(1)
    d = 0.007
    for size, count in ((4, 32), (5, 24), (6, 16)):
        s = size * d
        zz = {"box": [], "sphere": []}
        for _ in range(count):
            c = rng.uniform([0.0, 0.0, s / 2 + d / 2], [L, L, top - s / 2 - d / 2])
            mb = sim.measure(box=(c - s / 2, c + s / 2))
            ms = sim.measure(sphere=(c, s / 2))
            # the spheres and their images across the periodic sides
            img = np.concatenate([x + (i * L, j * L, 0.0) for i in (-1, 0, 1)
                                  for j in (-1, 0, 1)])
            rr = np.tile(r, 9)
            near = np.all(np.abs(img - c) < s / 2 + rr[:, None], axis=1)
            exact_b = 1.0 - _sphere_box(img[near], rr[near], c - s / 2, c + s / 2) / s ** 3
            exact_s = 1.0 - _sphere_sphere(np.linalg.norm(img - c, axis=1), rr, s / 2).sum() / (
                math.pi * s ** 3 / 6)
            assert mb["porosity"] == pytest.approx(exact_b, rel=0.005)
            assert ms["porosity"] == pytest.approx(exact_s, rel=0.005)
            zz["box"].append(mb["stress"][2, 2] / szz)
            zz["sphere"].append(ms["stress"][2, 2] / szz)
        for kind, v in zz.items():
            assert np.mean(v) == pytest.approx(1.0, abs=0.03), (kind, size, v)
