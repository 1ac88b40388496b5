"""Superellipse particles (Miyata et al. 2002, §2.3): geometry, contact depth, and mechanics against
closed forms.

- Area, polar moment and support function against a fine polygon of the boundary.
- The pair depth by the engine's warm-started 1-D minimisation against a dense scan of
  the normal angle, symmetric in i and j, and against the seed's geometric-potential
  method (Miyata Eqs. 36–42) at small overlaps.
- Superellipse(r, r, 2) gives the disc results (head-on impact, rolling on an incline).
- An ellipse comes to rest on its long side at b − mg/k; a box (n = 10, width 2×
  height) slides down an incline at g(sin θ − μ cos θ) and tips where tan θ > width /
  height with friction enough not to slide.
"""
import math

import numpy as np
import pytest
import taichi as ti

import tdem
from physics.shapes import Superellipse, geometric_potential_contact, support_depth

SHAPES = [Superellipse(0.195, 0.0976, 4), Superellipse(0.3, 0.1, 10),
          Superellipse(0.2, 0.15, 2.5), Superellipse(0.1, 0.05, 2)]


def _polygon(s, m=400_000):
    return s.outline(m)


@pytest.mark.parametrize("s", SHAPES, ids=repr)
def test_area_inertia_and_support_against_a_fine_polygon(s):
    p = _polygon(s)
    x, y = p[:, 0], p[:, 1]
    xn, yn = np.roll(x, -1), np.roll(y, -1)
    cr = x * yn - xn * y
    area = 0.5 * cr.sum()
    polar = (cr * (x * x + x * xn + xn * xn + y * y + y * yn + yn * yn)).sum() / 12.0
    assert s.area == pytest.approx(area, rel=1e-6)
    assert s.polar_moment == pytest.approx(polar, rel=1e-6)
    phi = np.linspace(0.0, 2 * math.pi, 97)
    u = np.stack([np.cos(phi), np.sin(phi)], 1)
    h, sp = s.support(u)
    np.testing.assert_allclose(h, (u @ p.T).max(axis=1), rtol=1e-6)
    # the support point is on the boundary, and h = p·u
    np.testing.assert_allclose(s.inside(sp), 0.0, atol=1e-12)
    np.testing.assert_allclose((sp * u).sum(1), h, rtol=1e-12)


@pytest.mark.parametrize("s", SHAPES, ids=repr)
def test_bounding_radius_holds_the_whole_boundary(s):
    """Miyata et al. (2002) give max(a, b); for n > 2 the corners reach beyond it (a square of
    n = 4 to 2^(1/4) a), and the neighbour search would miss corner contacts."""
    far = np.linalg.norm(_polygon(s, 1_000_000), axis=1).max()
    assert far <= s.bounding_radius <= far * (1 + 2e-6)
    if s.n == 2.0:
        assert s.bounding_radius == max(s.a, s.b)
    else:
        assert s.bounding_radius > 1.005 * max(s.a, s.b)


def test_square_superellipse_reaches_two_to_the_quarter():
    assert Superellipse(1.0, 1.0, 4).bounding_radius == pytest.approx(2 ** 0.25, rel=2e-6)


def test_disc_shape_has_the_disc_mass_and_inertia():
    s = Superellipse(0.1, 0.1, 2)
    assert s.area == pytest.approx(math.pi * 0.01, rel=1e-14)
    assert s.polar_moment == pytest.approx(0.5 * math.pi * 1e-4, rel=1e-14)


@pytest.fixture(scope="module")
def depth_kernel():
    tdem.Simulation()          # the Taichi runtime, as the engine sets it up
    from physics.geometry import superellipse as se

    @ti.kernel
    def k(si: ti.types.vector(3, ti.f64), ti_: ti.f64, sj: ti.types.vector(3, ti.f64),
          tj: ti.f64, d: ti.types.vector(2, ti.f64)) -> ti.types.vector(4, ti.f64):
        f, u, pi, pj, phi, ok, ri, rj = se.pair_depth(si, ti.cos(ti_), ti.sin(ti_), sj,
                                                      ti.cos(tj), ti.sin(tj), d,
                                                      ti.atan2(d[1], d[0]), False, False)
        return ti.Vector([f, u[0], u[1], ti.cast(ok, ti.f64)])

    def depth(si, ti_, sj, tj, d):
        r = k(ti.Vector(si.row), ti_, ti.Vector(sj.row), tj, ti.Vector(list(map(float, d))))
        assert r[3] == 1.0, "the iteration did not converge"
        return r[0], np.array([r[1], r[2]])
    return depth


def test_depth_matches_a_dense_scan_and_is_symmetric(depth_kernel):
    rng = np.random.default_rng(3)
    a, b = SHAPES[0], SHAPES[1]
    for _ in range(6):
        ta, tb, dirn = rng.uniform(0, 2 * math.pi, 3)
        for dist in (0.2, 0.3, 0.38):
            d = dist * np.array([math.cos(dirn), math.sin(dirn)])
            f, n = depth_kernel(a, ta, b, tb, d)
            ref, nref = support_depth(a, [0, 0], ta, b, d, tb, m=400_000)
            assert f == pytest.approx(ref, abs=1e-9)
            assert np.degrees(np.arccos(min(1.0, n @ nref))) < 0.01
            # the same pair seen from j: same depth, opposite normal
            f2, n2 = depth_kernel(b, tb, a, ta, -d)
            assert f2 == pytest.approx(f, abs=1e-13)
            np.testing.assert_allclose(n2, -n, atol=1e-10)


@pytest.mark.parametrize("n", [3.0, 4.0, 5.0, 8.0, 9.0, 4.5])
def test_support_by_square_roots_matches_the_power_form(depth_kernel, n):
    """Where 1/n or 1/(n − 1) is 1/2, 1/4 or 1/8 the kernel takes the powers by square
    roots; its support function and point equal the numpy power form to round-off."""
    from physics.geometry import superellipse as se
    s = Superellipse(0.3, 0.12, n)

    @ti.kernel
    def sup(sh: ti.types.vector(3, ti.f64), phi: ti.f64) -> ti.types.vector(3, ti.f64):
        h, p, r, dr = se.support_curv(sh, 1.0, 0.0, ti.Vector([ti.cos(phi), ti.sin(phi)]))
        return ti.Vector([h, p[0], p[1]])

    for phi in np.linspace(0.05, 6.2, 23):
        u = np.array([math.cos(phi), math.sin(phi)])
        h, p = s.support(u)
        got = sup(ti.Vector(s.row), phi)
        assert got[0] == pytest.approx(h, rel=1e-13)
        np.testing.assert_allclose([got[1], got[2]], p, rtol=1e-12, atol=1e-15)


def test_warm_started_depth_stops_within_its_tolerance(depth_kernel):
    """From a stored normal off the minimum by up to 1e-3 rad (what one step turns a
    contact by), the depth and normal agree with the cold solution: the last step on
    the cubic model leaves the support points facing each other within 1e-6 of the
    size, so the depth within 1e-12 m and the normal within 1e-6 rad here."""
    from physics.geometry import superellipse as se

    @ti.kernel
    def warm(si: ti.types.vector(3, ti.f64), ti_: ti.f64, sj: ti.types.vector(3, ti.f64),
             tj: ti.f64, d: ti.types.vector(2, ti.f64), phi0: ti.f64) -> ti.types.vector(4, ti.f64):
        f, u, pi, pj, phi, ok, ri, rj = se.pair_depth(si, ti.cos(ti_), ti.sin(ti_), sj,
                                                      ti.cos(tj), ti.sin(tj), d, phi0, True,
                                                      False)
        return ti.Vector([f, u[0], u[1], ti.cast(ok, ti.f64)])

    rng = np.random.default_rng(11)
    checked = 0
    for a, b in ((SHAPES[0], SHAPES[1]), (SHAPES[0], SHAPES[0]), (SHAPES[2], SHAPES[3])):
        for _ in range(5):
            ta, tb, dirn = rng.uniform(0, 2 * math.pi, 3)
            for dist in (0.2, 0.3):
                d = dist * np.array([math.cos(dirn), math.sin(dirn)])
                f, n = depth_kernel(a, ta, b, tb, d)
                if f < 0.0:
                    continue
                phi = math.atan2(n[1], n[0])
                for off in (1e-3, -3e-4, 1e-5):
                    r = warm(ti.Vector(a.row), ta, ti.Vector(b.row), tb,
                             ti.Vector(list(map(float, d))), phi + off)
                    assert r[3] == 1.0
                    assert r[0] == pytest.approx(f, abs=1e-12)
                    assert np.degrees(np.arccos(min(1.0, np.array([r[1], r[2]]) @ n))) < \
                        np.degrees(1e-6)
                    checked += 1
    assert checked > 40


def test_geometric_potential_method_agrees_at_small_overlaps(depth_kernel):
    rng = np.random.default_rng(5)
    a, b = SHAPES[0], SHAPES[2]
    for _ in range(5):
        ta, tb, dirn = rng.uniform(0, 2 * math.pi, 3)
        u = np.array([math.cos(dirn), math.sin(dirn)])
        lo, hi = 0.05, 0.8          # the distance of a 1e-4 m overlap, by bisection
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            if depth_kernel(a, ta, b, tb, mid * u)[0] > 1e-4:
                lo = mid
            else:
                hi = mid
        f, n = depth_kernel(a, ta, b, tb, lo * u)
        gp, ngp = geometric_potential_contact(a, [0, 0], ta, b, lo * u, tb)
        assert f == pytest.approx(1e-4, rel=1e-6)
        assert abs(gp - f) < 1e-6
        assert np.degrees(np.arccos(min(1.0, n @ ngp))) < 0.1


@pytest.mark.parametrize("s", SHAPES, ids=repr)
def test_curvature_radius_is_the_turn_of_the_support_point(depth_kernel, s):
    """ρ = t·dp/dφ (central difference of the numpy support point) and, for an ellipse,
    a²b²/h³; its derivative dρ/dφ (the Newton stop's third derivative) against a
    central difference of ρ."""
    from physics.geometry import superellipse as se

    @ti.kernel
    def rho_drho(sh: ti.types.vector(3, ti.f64), phi: ti.f64) -> ti.types.vector(2, ti.f64):
        h, p, r, dr = se.support_curv(sh, 1.0, 0.0, ti.Vector([ti.cos(phi), ti.sin(phi)]))
        return ti.Vector([r, dr])

    def rho(sh, phi):
        return rho_drho(sh, phi)[0]

    for phi in (0.3, 1.0, 2.2, 4.0):
        eps = 1e-5
        fd = (rho(ti.Vector(s.row), phi + eps) - rho(ti.Vector(s.row), phi - eps)) / (2 * eps)
        assert rho_drho(ti.Vector(s.row), phi)[1] == pytest.approx(fd, rel=1e-6)
        eps = 1e-6
        u = lambda a: np.array([math.cos(a), math.sin(a)])
        dp = (s.support(u(phi + eps))[1] - s.support(u(phi - eps))[1]) / (2 * eps)
        t = np.array([-math.sin(phi), math.cos(phi)])
        assert rho(ti.Vector(s.row), phi) == pytest.approx(t @ dp, rel=1e-6)
        if s.n == 2:
            h = s.support(u(phi))[0]
            assert rho(ti.Vector(s.row), phi) == pytest.approx((s.a * s.b) ** 2 / h ** 3,
                                                               rel=1e-12)


# ------------------------------------------------------------------ mechanics
R, RHO, KN, G = 0.1, 1000.0, 1e6, 9.81


# the same step for both (a shape's critical step also has a rotational bound)
DT = 0.1 * 2.0 * math.sqrt(RHO * math.pi * R * R / (2.0 * KN))


def _pair(shape, v=1.0):
    sim = tdem.Simulation(gravity=(0.0, 0.0), dt=DT)
    law = tdem.LinearContact(kn=KN, ks=KN, friction=0.3, restitution=0.5)
    pos = [[0.0, 0.0], [2 * R + 0.01, 0.02]]
    if shape:
        sim.add_particles(pos, shape=Superellipse(R, R, 2), density=RHO, contact=law,
                          velocity=[[v, 0.0], [-v, 0.0]])
    else:
        sim.add_particles(pos, R, density=RHO, contact=law, velocity=[[v, 0.0], [-v, 0.0]])
    sim.run(until=0.05)
    return sim


def test_disc_shaped_superellipses_collide_as_discs():
    """An oblique impact with friction and damping: the same trajectories."""
    a, b = _pair(False), _pair(True)
    pa, pb = a.particles.numpy(), b.particles.numpy()
    for k in ("position", "velocity", "omega"):
        np.testing.assert_allclose(pb[k], pa[k], rtol=1e-9, atol=1e-12)
    ea, eb = a.energy(), b.energy()
    assert eb["dissipated"] == pytest.approx(ea["dissipated"], rel=1e-9)
    assert b.nonconverged_contacts == 0


def _incline(shape, theta, mu, until=0.6):
    sim = tdem.Simulation(gravity=(G * math.sin(theta), -G * math.cos(theta)), dt=DT)
    law = tdem.LinearContact(kn=KN, ks=KN, friction=mu)
    m = RHO * math.pi * R * R
    u0 = m * G * math.cos(theta) / KN
    if shape:
        sim.add_particles([[0.0, R - u0]], shape=Superellipse(R, R, 2), density=RHO,
                          contact=law)
    else:
        sim.add_particles([[0.0, R - u0]], R, density=RHO, contact=law)
    sim.add_wall((-20.0, 0.0), (20.0, 0.0), contact=law)
    sim.run(until=until)
    return sim


@pytest.mark.parametrize("mu", [0.5, 0.1])      # rolls; slides
def test_disc_shaped_superellipse_on_an_incline_moves_as_a_disc(mu):
    theta = math.radians(30.0)
    a, b = _incline(False, theta, mu), _incline(True, theta, mu)
    pa, pb = a.particles.numpy(), b.particles.numpy()
    for k in ("position", "velocity", "omega"):
        np.testing.assert_allclose(pb[k], pa[k], rtol=1e-9, atol=1e-12)


def test_ellipse_comes_to_rest_on_its_long_side():
    a, b, k = 0.1, 0.05, 1e5
    sim = tdem.Simulation(gravity=(0.0, -G), local_damping=0.7)
    law = tdem.LinearContact(kn=k, ks=k, friction=0.5)
    s = Superellipse(a, b, 2)
    sim.add_particles([[0.0, 0.15]], shape=s, angle=37.0, density=RHO, contact=law)
    sim.add_wall((-2.0, 0.0), (2.0, 0.0), contact=law)
    sim.run(until=4.0)
    p = sim.particles.numpy()
    m = RHO * s.area
    assert p["mass"][0] == pytest.approx(m, rel=1e-12)
    tilt = (p["angle"][0] + 90.0) % 180.0 - 90.0           # long axis against horizontal
    assert abs(tilt) < 0.05
    assert p["position"][0, 1] == pytest.approx(b - m * G / k, abs=1e-6)
    assert np.abs(p["velocity"]).max() < 1e-4
    assert sim.nonconverged_contacts == 0


BOX = Superellipse(0.2, 0.1, 10)       # width 2 × height


def _box_on_slope(theta, mu, until):
    sim = tdem.Simulation(gravity=(G * math.sin(theta), -G * math.cos(theta)),
                          dt_fraction=0.1)
    law = tdem.LinearContact(kn=KN, ks=KN, friction=mu)
    m = RHO * BOX.area
    u0 = m * G * math.cos(theta) / KN
    sim.add_particles([[0.0, BOX.b - u0]], shape=BOX, density=RHO, contact=law)
    sim.add_wall((-20.0, 0.0), (20.0, 0.0), contact=law)
    sim.monitor("box", lambda s: np.r_[s.particles.numpy()["velocity"][0],
                                       s.particles.numpy()["angle"][0]], every=10)
    sim.run(until=until)
    return sim


def test_box_slides_down_an_incline_at_g_sin_minus_mu_cos():
    theta, mu = math.radians(30.0), 0.3
    sim = _box_on_slope(theta, mu, 0.5)
    t, s = sim.histories()["box"]
    k = t > 0.1
    a = np.polyfit(t[k], s[k, 0], 1)[0]
    assert a == pytest.approx(G * (math.sin(theta) - mu * math.cos(theta)), rel=0.03)
    assert np.abs(s[:, 2]).max() < 1.0            # slides flat: it turns by less than 1°
    assert sim.nonconverged_contacts == 0


@pytest.mark.parametrize("deg, tips", [(70.0, True), (45.0, False)])
def test_box_tips_only_where_tan_exceeds_width_over_height(deg, tips):
    """tan θ = 2 at 63.4°; μ = 5 holds it from sliding on either slope. (The load is
    applied at once, so just below 63.4° the box may tip dynamically: the centre of
    mass has only millimetres to rise; 45° is well below.)"""
    sim = _box_on_slope(math.radians(deg), 5.0, 1.5)
    t, s = sim.histories()["box"]
    turned = abs(s[-1, 2])
    if tips:
        assert turned > 60.0
    else:
        assert turned < 1.0
        # it stays (sliding freely it would go 7.8 m): the shear spring's give and the
        # rocking of its single contact point let it creep by millimetres
        assert abs(sim.particles.numpy()["position"][0, 0]) < 5e-3


def test_shapes_are_written_as_polygons_of_their_area(tmp_path):
    import meshio
    s = Superellipse(0.2, 0.1, 4)
    sim = tdem.Simulation(gravity=(0.0, 0.0))
    law = tdem.LinearContact(kn=KN)
    sim.add_particles([[0.0, 0.0], [1.0, 0.3]], shape=s, angle=[0.0, 30.0], density=RHO,
                      contact=law)
    sim.add_particles([[3.0, 0.0]], 0.1, density=RHO, contact=law)
    paths = sim.write_vtu(tmp_path / "snap.vtu")
    m = meshio.read(next(p for p in paths if p.endswith("_shapes.vtu")))
    poly = m.cells_dict["polygon"]
    assert poly.shape == (2, 48)
    assert m.cell_data_dict["id"]["polygon"].tolist() == [0, 1]
    np.testing.assert_allclose(m.cell_data_dict["angle"]["polygon"], [0.0, 30.0], atol=1e-12)
    for k in range(2):
        x, y = m.points[poly[k], 0], m.points[poly[k], 1]
        area = 0.5 * (x * np.roll(y, -1) - np.roll(x, -1) * y).sum()
        assert area == pytest.approx(s.area, rel=0.01)      # 48 points on the boundary
    # the second one is turned by 30°: its farthest point along 30° is at a
    far = m.points[poly[1], :2] - [1.0, 0.3]
    u = np.array([np.cos(np.radians(30)), np.sin(np.radians(30))])
    assert (far @ u).max() == pytest.approx(s.a, rel=1e-3)
    p = meshio.read(paths[0])
    np.testing.assert_allclose(p.point_data["angle"], [0.0, 30.0, 0.0], atol=1e-12)
