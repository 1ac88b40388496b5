"""Convex polyhedra with the overlap-volume contact (Chen's polyhedral DEM): mass properties
against closed forms and an independent hull, the overlap polyhedron against exact
half-space intersections and its normal against −∂V/∂x, and the dynamics against
rigid-body mechanics and the chain's sound speed: rest on a face, sliding and tipping
on an incline, a pulse along a column of cubes, restitution of a face-on impact, a
frictionless gas's energy and momentum, and the inputs refused."""
import math

import numpy as np
import pytest
from scipy.spatial import ConvexHull, HalfspaceIntersection
from scipy.spatial.transform import Rotation

import tdem
from physics.geometry.polyhedron import overlap_of, prism_overlap_of

I4 = [1.0, 0.0, 0.0, 0.0]


def quat(rot):
    """(w, x, y, z) of a scipy Rotation."""
    x, y, z, w = rot.as_quat()
    return [w, x, y, z]


# ------------------------------------------------------------------ mass properties
def test_cube_and_tetrahedron_mass_properties_are_the_closed_forms():
    c = tdem.Polyhedron(np.array([[x, y, z] for x in (0, 2) for y in (1, 3) for z in (-1, 1)],
                                 float))
    assert c.volume == pytest.approx(8.0, rel=1e-12)
    assert np.allclose(c.centroid, [1.0, 2.0, 0.0], atol=1e-12)
    assert np.allclose(c.principal_moments, 8.0 / 12.0, rtol=1e-9)     # m(a² + a²)/12 per m
    assert np.allclose(c.rotation, np.eye(3), atol=1e-12)
    assert (len(c.faces), len(c.edges), len(c.triangles)) == (6, 12, 12)
    t = tdem.Polyhedron.regular("tetrahedron", 1.0)
    a = math.sqrt(8.0 / 3.0)                                               # edge for R = 1
    assert t.volume == pytest.approx(a ** 3 / (6.0 * math.sqrt(2.0)), rel=1e-9)
    assert np.allclose(t.principal_moments, a * a / 20.0, rtol=1e-9)
    assert t.bounding_radius == pytest.approx(1.0, rel=1e-12)
    assert t.inscribed_radius == pytest.approx(1.0 / 3.0, rel=1e-9)
    b = tdem.Polyhedron.box(0.1, 0.2, 0.3)
    assert np.allclose(b.principal_moments, [(0.04 + 0.09) / 12, (0.01 + 0.09) / 12,
                                             (0.01 + 0.04) / 12], rtol=1e-9)
    assert np.allclose(b.rotation, np.eye(3), atol=1e-12)


def test_random_hull_mass_properties_against_scipy_and_a_voxel_count():
    p = tdem.Polyhedron.random(16, elongation=2.0, size=1.0, seed=4)
    pts = p.input_vertices
    assert p.volume == pytest.approx(ConvexHull(pts).volume, rel=1e-12)
    # a voxel count of the solid (in the frame of the points given)
    lo, hi = pts.min(0), pts.max(0)
    m = 100
    axes = [lo[k] + (np.arange(m) + 0.5) * (hi[k] - lo[k]) / m for k in range(3)]
    g = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, 3)
    eq = ConvexHull(pts).equations
    inside = g[(g @ eq[:, :3].T + eq[:, 3] <= 0).all(axis=1)]
    dv = np.prod((hi - lo) / m)
    assert len(inside) * dv == pytest.approx(p.volume, rel=0.01)
    assert np.allclose(inside.mean(0), p.centroid, atol=0.01 * (hi - lo).max())
    r = inside - p.centroid
    cov = r.T @ r / len(r)
    inertia = np.trace(cov) * np.eye(3) - cov
    body = p.rotation.T @ inertia @ p.rotation
    assert np.allclose(np.diag(body), p.principal_moments, rtol=0.02)
    assert np.abs(body - np.diag(np.diag(body))).max() < 0.01 * p.principal_moments.max()


# ------------------------------------------------------------------ overlap geometry
def test_cubes_face_to_face_overlap_is_exact():
    c = tdem.Polyhedron.cube(1.0)
    for dz, dx in ((0.9, 0.0), (0.95, 0.3)):
        r = overlap_of(c, [0, 0, 0], I4, c, [dx, 0.0, dz], I4)
        assert r["volume"] == pytest.approx((1.0 - dz) * (1.0 - dx), rel=1e-12)
        assert np.allclose(r["centroid"], [dx / 2, 0.0, dz / 2], atol=1e-12)
        n = (r["s_a"] - r["s_b"]) / np.linalg.norm(r["s_a"] - r["s_b"])
        if dx == 0.0:
            assert np.allclose(n, [0, 0, 1], atol=1e-12)     # the face normal, A to B
    # aligned in a column: the shared side faces count in neither area vector
    r = overlap_of(c, [0, 0, 0], I4, c, [0, 0, 0.99], I4)
    assert np.allclose(r["s_a"], [0, 0, 1.0], atol=1e-12)


def _world_planes(shape, x, q):
    R = Rotation.from_quat([q[1], q[2], q[3], q[0]]).as_matrix()
    n = shape.planes[:, :3] @ R.T
    return np.c_[n, -(shape.planes[:, 3] + n @ x)]


def test_random_poses_volume_centroid_and_normal_against_references():
    """Volume and centroid against scipy's half-space intersection; the normal against
    −∂V/∂x_B by central differences."""
    a = tdem.Polyhedron.random(14, elongation=1.5, size=1.0, seed=2)
    b = tdem.Polyhedron.regular("dodecahedron", 0.8)
    rng = np.random.default_rng(7)
    checked = 0
    while checked < 6:
        qa = quat(Rotation.random(random_state=rng))
        qb = quat(Rotation.random(random_state=rng))
        xb = rng.normal(size=3)
        xb *= rng.uniform(0.9, 1.4) / np.linalg.norm(xb)
        r = overlap_of(a, [0, 0, 0], qa, b, xb, qb)
        if r["volume"] < 1e-4:
            continue
        checked += 1
        hs = HalfspaceIntersection(np.r_[_world_planes(a, np.zeros(3), qa),
                                         _world_planes(b, xb, qb)], r["centroid"])
        ref = tdem.Polyhedron(hs.intersections)
        assert r["volume"] == pytest.approx(ref.volume, rel=1e-9)
        assert np.allclose(r["centroid"], ref.centroid, atol=1e-9)
        h = 1e-6
        grad = np.array([(overlap_of(a, [0, 0, 0], qa, b, xb + h * e, qb)["volume"]
                          - overlap_of(a, [0, 0, 0], qa, b, xb - h * e, qb)["volume"]) / (2 * h)
                         for e in np.eye(3)])
        s = 0.5 * (r["s_a"] - r["s_b"])
        assert np.abs(s + grad).max() < 1e-4 * np.linalg.norm(grad)
        assert np.abs(r["s_a"] + r["s_b"]).max() < 1e-12


def test_prism_of_a_triangle_cuts_the_part_behind_it():
    c = tdem.Polyhedron.cube(1.0)
    tri = [[-1.0, -1.0, 0.0], [2.0, -1.0, 0.0], [-1.0, 2.0, 0.0]]
    r = prism_overlap_of(c, [0.2, 0.1, 0.45], I4, tri, 1.5)
    # the footprint [-0.3, 0.7] × [-0.4, 0.6] less the corner beyond x + y = 1
    area = 1.0 - 0.5 * 0.3 * 0.3
    assert r["volume"] == pytest.approx(area * 0.05, rel=1e-12)
    assert np.allclose(r["cut"], [0, 0, area], atol=1e-12)


# ------------------------------------------------------------------ dynamics
L, E, RHO = 0.1, 1e7, 2000.0


def cube_sim(friction=0.5, restitution=None, gravity=(0.0, 0.0, -9.81), **kw):
    sim = tdem.Simulation(dim=3, gravity=gravity, progress=False, **kw)
    law = tdem.VolumeContact(young=E, friction=friction, restitution=restitution)
    return sim, law


def test_cube_rests_on_a_face_at_the_static_overlap():
    sim, law = cube_sim(restitution=0.3)
    sim.add_particles([[0.01, -0.02, 0.0501]], shape=tdem.Polyhedron.cube(L), density=RHO,
                      contact=law)
    v, t = tdem.surfaces.plane((0, 0, 0), (0, 0, 1), size=1.0, divisions=3)
    floor = sim.add_mesh(v, t, contact=law)
    sim.run(until=0.5)
    mg = RHO * L ** 3 * 9.81
    z = sim.particles.numpy()["position"][0, 2]
    assert z == pytest.approx(L / 2 - mg * L / (E * L * L), abs=1e-4 * mg * L / (E * L * L)
                              + 1e-12)
    assert floor.force[2] == pytest.approx(-mg, rel=1e-6)
    assert np.abs(floor.force[:2]).max() < 1e-9 * mg


def incline_run(theta_deg, friction, seconds):
    th = math.radians(theta_deg)
    n = np.array([-math.sin(th), 0.0, math.cos(th)])
    sim, law = cube_sim(friction=friction, restitution=0.3)
    q = quat(Rotation.from_rotvec([0.0, -th, 0.0]))
    sim.add_particles([0.5 * L * n * 0.999 + [0.3, 0, 0.3 * math.tan(th)]],
                      shape=tdem.Polyhedron.cube(L), density=RHO, contact=law, orientation=q)
    v, t = tdem.surfaces.plane((0.3, 0, 0.3 * math.tan(th)), n, size=1.2, divisions=4)
    sim.add_mesh(v, t, contact=law)
    down = np.array([-math.cos(th), 0.0, -math.sin(th)])
    sim.monitor("s", lambda s: [s.time, float(s.particles.numpy()["velocity"][0] @ down),
                                float(Rotation.from_quat(np.roll(
                                    s.particles.numpy()["orientation"][0], -1)).magnitude()),
                                float(s.particles.numpy()["position"][0] @ down)],
                every=20)
    sim.run(until=seconds)
    return np.asarray(sim.histories()["s"][1]), th


def test_cube_slides_down_an_incline_at_g_sin_minus_mu_cos():
    h, th = incline_run(30.0, 0.3, 0.25)
    t, v = h[:, 0], h[:, 1]
    late = t > 0.05
    a = np.polyfit(t[late], v[late], 1)[0]
    assert a == pytest.approx(9.81 * (math.sin(th) - 0.3 * math.cos(th)), rel=0.03)
    assert h[:, 2].max() < math.radians(30.0) + math.radians(0.5)    # slides, no tipping


@pytest.mark.parametrize("theta,tips", [(40.0, False), (50.0, True)])
def test_cube_with_high_friction_tips_beyond_45_degrees(theta, tips):
    h, th = incline_run(theta, 2.0, 0.6)
    turned = h[:, 2] - th                   # rotation beyond the incline's
    if tips:
        assert turned[-1] > math.radians(20.0)
    else:
        assert np.abs(turned).max() < math.radians(2.0)


def test_column_of_cubes_carries_a_pulse_at_the_bar_speed():
    """A column of touching cubes, its first driven at a constant speed: the front (half
    the driven speed) moves at sqrt(E/ρ) (the thesis's calibration, l_c = L)."""
    n, l = 40, 0.01
    sim, law = cube_sim(friction=0.0, gravity=(0.0, 0.0, 0.0), dt_fraction=0.1)
    pos = np.c_[np.arange(n) * l, np.zeros(n), np.zeros(n)]
    sim.add_particles(pos, shape=tdem.Polyhedron.cube(l), density=RHO, contact=law)
    v0 = 1e-3
    sim.fix_particles([0], vx=v0, vy=0.0, vz=0.0, omega=(0.0, 0.0, 0.0))
    c = math.sqrt(E / RHO)
    sim.monitor("v", lambda s: np.r_[s.time, s.particles.numpy()["velocity"][:, 0]], every=1)
    sim.run(until=0.8 * n * l / c)
    h = np.asarray(sim.histories()["v"][1])
    t, vx = h[:, 0], h[:, 1:]
    ks = np.arange(5, 30)
    arrive = [np.interp(0.5 * v0, vx[:, k], t) if vx[:, k].max() > 0.5 * v0 else np.nan
              for k in ks]
    # (the velocity rises monotonically through half the driven speed at the front)
    first = np.array([t[np.argmax(vx[:, k] > 0.5 * v0)] for k in ks])
    speed = l / np.polyfit(ks, first, 1)[0]
    assert np.isfinite(arrive).all()
    assert speed == pytest.approx(c, rel=0.05)


def test_face_on_impact_of_two_cubes_gives_the_restitution_asked():
    e = 0.6
    sim, law = cube_sim(friction=0.0, restitution=e, gravity=(0.0, 0.0, 0.0))
    v = 0.2
    sim.add_particles([[-0.5 * L - 1e-4, 0, 0], [0.5 * L + 1e-4, 0, 0]],
                      shape=tdem.Polyhedron.cube(L), density=RHO, contact=law,
                      velocity=[[v, 0, 0], [-v, 0, 0]])
    sim.run(until=0.01)
    out = sim.particles.numpy()["velocity"]
    assert (out[1, 0] - out[0, 0]) / (2 * v) == pytest.approx(e, rel=0.03)
    assert np.abs(out[:, 1:]).max() < 1e-9 * v


def test_frictionless_polyhedron_gas_keeps_energy_and_momenta():
    """Random polyhedra in a periodic box, no damping, no friction: energy within 1 %
    over 20,000 steps; linear and angular momentum (the forces are equal, opposite and
    at one point) kept to round-off."""
    sim, law = cube_sim(friction=0.0, gravity=(0.0, 0.0, 0.0), dt_fraction=0.1)
    box = 0.9
    sim.periodic(x=(0.0, box), y=(0.0, box), z=(0.0, box))
    rng = np.random.default_rng(3)
    g = np.stack(np.meshgrid(*[(np.arange(3) + 0.5) * box / 3] * 3, indexing="ij"), -1)
    pos = g.reshape(-1, 3)
    shapes = [tdem.Polyhedron.random(10, 1.5, 0.09, seed=s) for s in range(3)]
    vel = rng.normal(0.0, 1.0, pos.shape)
    vel -= vel.mean(axis=0)
    for k, shp in enumerate(shapes):
        sl = slice(9 * k, 9 * (k + 1))
        sim.add_particles(pos[sl], shape=shp, density=RHO, contact=law, velocity=vel[sl],
                          orientation=tdem.random_orientations(9, seed=k),
                          omega=rng.normal(0.0, 5.0, (9, 3)))
    sim.run(steps=1)
    e0 = sim.energy()["total"]

    def momenta(s):
        p = (s["mass"][:, None] * s["velocity"]).sum(axis=0)
        return p, float((s["mass"] * np.linalg.norm(s["velocity"], axis=1)).sum())

    p0, _ = momenta(sim.particles.numpy())
    sim.run(steps=20000)
    e = sim.energy()
    s = sim.particles.numpy()
    assert abs(e["total"] - e0) / e0 < 0.01
    p, scale = momenta(s)
    assert np.abs(p - p0).max() < 1e-10 * scale
    assert sim.neighbour_builds > 1 and sim.nonconverged_contacts == 0


def test_polyhedra_inputs_refused_naming_the_argument():
    with pytest.raises(tdem.InputError, match="vertices.*flat"):
        tdem.Polyhedron([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]])
    with pytest.raises(tdem.InputError, match="at least 4"):
        tdem.Polyhedron([[0, 0, 0], [1, 0, 0], [0, 1, 0]])
    with pytest.raises(tdem.InputError, match="at most 32"):
        tdem.Polyhedron(Rotation.random(100, random_state=0).apply([1.0, 0.0, 0.0]))
    with pytest.raises(tdem.InputError, match="finite"):
        tdem.Polyhedron([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, float("nan")]])
    sim = tdem.Simulation(dim=3, progress=False)
    hm = tdem.HertzMindlin(young=1e8, poisson=0.3)
    vol = tdem.VolumeContact(young=1e8)
    cube = tdem.Polyhedron.cube(0.01)
    with pytest.raises(tdem.InputError, match="contact: polyhedra take tdem.VolumeContact"):
        sim.add_particles([[0, 0, 0]], shape=cube, contact=hm)
    with pytest.raises(tdem.InputError, match="contact: tdem.VolumeContact is the law of"):
        sim.add_particles([[0, 0, 0]], 0.01, contact=vol)
    with pytest.raises(tdem.InputError, match="radius"):
        sim.add_particles([[0, 0, 0]], 0.01, shape=cube, contact=vol)
    sim.add_particles([[0, 0, 0]], shape=cube, contact=vol)
    with pytest.raises(tdem.InputError, match="shape: ellipsoids and polyhedra"):
        sim.add_particles([[1, 0, 0]], shape=tdem.Ellipsoid(0.01, 0.01, 0.02), contact=hm)
    with pytest.raises(tdem.InputError, match="shape"):
        tdem.Simulation().add_particles([[0, 0]], shape=cube, contact=vol)


def _cubes_in_a_box(n=3):
    sim, law = cube_sim(friction=0.4, restitution=0.3)
    g = np.stack(np.meshgrid(*[(np.arange(n) - (n - 1) / 2) * 0.15] * 2, indexing="ij"), -1)
    pos = np.c_[g.reshape(-1, 2), np.full(n * n, 0.08)]
    sim.add_particles(pos, shape=tdem.Polyhedron.cube(L), density=RHO, contact=law,
                      orientation=tdem.random_orientations(n * n, seed=1))
    sim.add_particles(pos + [0.0, 0.0, 0.16], shape=tdem.Polyhedron.regular("octahedron", 0.07),
                      density=RHO, contact=law)
    v, t = tdem.surfaces.box((-0.3, -0.3, 0.0), (0.3, 0.3, 0.4))
    sim.add_mesh(v, t, contact=law)
    return sim


def test_polyhedra_checkpoint_restarts_bit_for_bit(tmp_path):
    sim = _cubes_in_a_box()
    sim.run(until=0.1)
    sim.save(tmp_path / "c.h5")
    sim.run(steps=200)
    a = sim.particles.numpy()
    back = tdem.Simulation.load(tmp_path / "c.h5")
    back.run(steps=200)
    b = back.particles.numpy()
    for k in ("position", "velocity", "omega", "orientation", "force", "torque"):
        np.testing.assert_array_equal(a[k], b[k], err_msg=k)
    assert len(sim.contacts.numpy()["pairs"]) > 0


def test_polyhedra_surfaces_read_back(tmp_path):
    vtk = pytest.importorskip("vtk")
    from vtk.util.numpy_support import vtk_to_numpy

    sim = _cubes_in_a_box(2)
    sim.run(until=0.05)
    files = sim.write_vtu(tmp_path / "s.vtu")
    shapes = [f for f in files if "shapes" in str(f)]
    assert len(shapes) == 1
    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(str(shapes[0]))
    r.Update()
    grid = r.GetOutput()
    assert grid.GetNumberOfCells() == 4 * 12 + 4 * 8     # cubes: 12 triangles, octahedra 8
    ids = vtk_to_numpy(grid.GetCellData().GetArray("id"))
    assert sorted(set(ids.tolist())) == list(range(8))
    # the surface of each body encloses its volume (divergence theorem on the triangles)
    pts = vtk_to_numpy(grid.GetPoints().GetData())
    conn = vtk_to_numpy(grid.GetCells().GetConnectivityArray()).reshape(-1, 3)
    vol = np.einsum("ij,ij->i", pts[conn[:, 0]], np.cross(pts[conn[:, 1]], pts[conn[:, 2]])) / 6
    for k, expect in ((0, L ** 3), (4, tdem.Polyhedron.regular("octahedron", 0.07).volume)):
        assert vol[ids == k].sum() == pytest.approx(expect, rel=1e-9)


def test_sphere_rests_on_a_cube_at_the_cap_volume_balance():
    """A sphere on the top face of a fixed cube: E·V_cap/l_c = m g, V_cap = π u²(3r − u)/3,
    l_c the harmonic mean of the cube's edge and the sphere's (4/3 π r³)^(1/3); the pair
    takes the cube's VolumeContact though the sphere has its own law."""
    from scipy.optimize import brentq

    sim, law = cube_sim(restitution=0.3)
    r = 0.03
    sim.add_particles([[0, 0, 0]], shape=tdem.Polyhedron.cube(L), density=RHO, contact=law)
    sim.fix_particles([0], vx=0.0, vy=0.0, vz=0.0, omega=(0.0, 0.0, 0.0))
    hm = tdem.HertzMindlin(young=1e9, poisson=0.3, friction=0.5)
    sim.add_particles([[0.01, 0.005, L / 2 + r - 1e-5]], r, density=RHO, contact=hm)
    # (the dashpot on dV/dt damps a cap contact, whose projected area is far below
    # l_c², less than a face contact: it rings for a while)
    sim.run(until=0.8)
    ms = RHO * 4.0 / 3.0 * math.pi * r ** 3
    ls = (4.0 / 3.0 * math.pi) ** (1.0 / 3.0) * r
    lc = 2.0 * L * ls / (L + ls)
    u = brentq(lambda u: E * math.pi * u * u * (3 * r - u) / 3.0 / lc - ms * 9.81, 1e-12, r)
    z = sim.particles.numpy()["position"][1, 2]
    assert z == pytest.approx(L / 2 + r - u, abs=0.01 * u)
    c = sim.contacts.numpy()
    assert c["volume"][0] == pytest.approx(math.pi * u * u * (3 * r - u) / 3.0, rel=0.03)
    assert np.allclose(c["point"][0][:2], [0.01, 0.005], atol=1e-9)


@pytest.mark.parametrize("theta", [20.0, 35.0])
def test_cube_on_a_fixed_cube_sticks_or_slides_by_coulomb(theta):
    """Two cubes face to face (the pair's overlap polyhedron, not a wall), the lower one
    held, gravity tilted by θ: below atan μ the upper one stays, above it slides at
    g(sin θ − μ cos θ)."""
    th = math.radians(theta)
    g = 9.81
    sim, law = cube_sim(friction=0.5, restitution=0.3,
                        gravity=(g * math.sin(th), 0.0, -g * math.cos(th)))
    big = tdem.Polyhedron.box(1.0, 0.4, L)
    sim.add_particles([[0.0, 0.0, -L / 2]], shape=big, density=RHO, contact=law)
    sim.fix_particles([0], vx=0.0, vy=0.0, vz=0.0, omega=(0.0, 0.0, 0.0))
    sim.add_particles([[-0.3, 0.0, L / 2 - 1e-6]], shape=tdem.Polyhedron.cube(L), density=RHO,
                      contact=law)
    sim.monitor("x", lambda s: [s.time, s.particles.numpy()["velocity"][1, 0],
                                s.particles.numpy()["position"][1, 0]], every=10)
    sim.run(until=0.3)
    h = np.asarray(sim.histories()["x"][1])
    late = h[:, 0] > 0.1
    if theta < math.degrees(math.atan(0.5)):
        assert np.ptp(h[late, 2]) < 1e-4
    else:
        a = np.polyfit(h[late, 0], h[late, 1], 1)[0]
        assert a == pytest.approx(g * (math.sin(th) - 0.5 * math.cos(th)), rel=0.03)
