"""Primitive walls of 3D models (tdem.primitives): infinite planes and cylinders
without triangles, against their analytic references and against a meshed plane.

- a sphere at rest on a plane (and on a tilted one) sits at the overlap m g / k_n of
  the linear law;
- a sphere dropped on a plane, head-on and at a slant with spin and friction, follows
  the trajectory it follows on a meshed plane (tdem.surfaces.plane) hitting a face
  interior, to round-off: the same contact (law, tangential history, R* = R_i);
- a bounce gives the coefficient of restitution the law is set for;
- a sphere pressed against the inside or the outside of a cylinder sits at m g / k_n;
- the energy account closes and equals the meshed plane's;
- a plane moving at a prescribed velocity (a piston) compresses a small pack, and the
  force it reports is minus the sum of its contacts' forces on the particles;
- a checkpoint restarts bit for bit; bad input is refused naming the argument.
"""
import math

import numpy as np
import pytest

import tdem

R = 0.01
RHO = 2500.0
MASS = RHO * 4.0 / 3.0 * math.pi * R ** 3
G = 9.81


def _settle(sim, steps=40000):
    sim.run(steps=steps)
    return sim.particles.numpy()


def test_sphere_at_rest_on_a_plane_sits_at_m_g_over_kn():
    kn = 1e4
    law = tdem.LinearContact(kn=kn, friction=0.5, restitution=0.3)
    sim = tdem.Simulation(dim=3, gravity=(0, 0, -G), dt=1e-5, local_damping=0.5,
                          progress=False)
    sim.add_particles([[0.3, -0.2, 0.5 + R]], radius=R, density=RHO, contact=law)
    floor = sim.add_plane((0.0, 0.0, 0.5), (0, 0, 2.0), contact=law)
    p = _settle(sim)
    u = 0.5 + R - p["position"][0, 2]
    assert u == pytest.approx(MASS * G / kn, rel=1e-6)
    assert np.abs(p["position"][0, :2] - [0.3, -0.2]).max() < 1e-12
    np.testing.assert_allclose(floor.force, [0, 0, -MASS * G], rtol=1e-6, atol=1e-12)
    assert floor.contacts == 1 and floor.kind == "plane"


def test_sphere_at_rest_on_a_tilted_plane():
    """The plane's normal along (1, 2, 3), gravity against it."""
    kn = 1e4
    law = tdem.LinearContact(kn=kn, friction=0.5, restitution=0.3)
    nrm = np.array([1.0, 2.0, 3.0]) / math.sqrt(14.0)
    p0 = np.array([0.1, 0.2, -0.3])
    sim = tdem.Simulation(dim=3, gravity=tuple(-G * nrm), dt=1e-5, local_damping=0.5,
                          progress=False)
    sim.add_particles([p0 + 1.02 * R * nrm], radius=R, density=RHO, contact=law)
    plane = sim.add_plane(p0, (1.0, 2.0, 3.0), contact=law)
    np.testing.assert_allclose(plane.normal, nrm, rtol=1e-15)
    x = _settle(sim)["position"][0]
    d = (x - p0) @ nrm
    assert R - d == pytest.approx(MASS * G / kn, rel=1e-6)
    np.testing.assert_allclose(plane.force, -MASS * G * nrm, rtol=1e-6)
    # the contact output names it after the mesh triangles (none here): j = -1
    c = sim.contacts.numpy()
    assert c["pairs"].tolist() == [[0, -1]]
    assert c["overlap"][0] == pytest.approx(MASS * G / kn, rel=1e-6)
    np.testing.assert_allclose(c["direction"][0], -nrm, rtol=1e-12)


def _drop(primitive, normal, velocity, omega, law, steps=3000, segments=6):
    """A sphere dropped on a plane through the origin (a primitive, or a meshed square
    of side 1 whose face holds the point of impact); the positions and spins at the
    end of each segment."""
    n = np.asarray(normal, float) / np.linalg.norm(normal)
    sim = tdem.Simulation(dim=3, gravity=(0, 0, -G), dt=2e-6, progress=False)
    q = np.array([0.11, 0.07, 0.0])
    x0 = q - (q @ n) * n + 1.2 * R * n        # 0.2 R above the plane's point below q
    sim.add_particles([x0], radius=R, density=RHO, contact=law, velocity=[velocity],
                      omega=[omega])
    if primitive:
        wall = sim.add_plane((0, 0, 0), normal, contact=law)
    else:
        wall = sim.add_mesh(*tdem.surfaces.plane((0, 0, 0), normal, 1.0), contact=law)
    out = []
    for _ in range(segments):
        sim.run(steps=steps)
        p = sim.particles.numpy()
        out.append(np.concatenate([p["position"][0], p["velocity"][0], p["omega"][0],
                                   wall.force]))
    return np.array(out), sim


@pytest.mark.parametrize("normal, velocity, omega, rolling", [
    ((0, 0, 1), (0.0, 0.0, -0.5), (0.0, 0.0, 0.0), False),
    ((0.3, -0.2, 1.0), (0.8, -0.3, -0.6), (20.0, -5.0, 3.0), False),
    ((0.3, -0.2, 1.0), (0.8, -0.3, -0.6), (20.0, -5.0, 3.0), True),
])
def test_drop_equals_the_drop_on_a_meshed_plane(normal, velocity, omega, rolling):
    """The last case with rolling resistance (the couple's columns of the history)."""
    law = tdem.HertzMindlin(young=1e7, poisson=0.3, friction=0.3, restitution=0.5,
                            rolling=tdem.RollingResistance(0.4) if rolling else None)
    a, sim = _drop(True, normal, velocity, omega, law)
    b, _ = _drop(False, normal, velocity, omega, law)
    # the sphere met the plane: it came off it (and fell back) or rests on it
    n = np.asarray(normal, float) / np.linalg.norm(normal)
    assert (a[:, 3:6] @ n).max() > 0 or np.abs(a[:, 9:]).max() > 0
    # each vector against its largest size over the run (position, velocity, spin
    # in units of velocity / R, the wall's force)
    size = [np.abs(b[:, k:k + 3]).max() for k in (0, 3, 6, 9)]
    size[2] = max(size[2], size[1] / R)
    scale = np.repeat(size, 3)
    assert np.all(np.abs(a - b) <= 1e-9 * scale), np.abs(a - b) / scale
    if velocity[0] != 0.0:
        # tangential impact: friction turned the spin and the tangential velocity
        assert np.abs(a[-1, 6:9] - omega).max() > 1.0


@pytest.mark.parametrize("law", [
    tdem.HertzMindlin(young=1e7, poisson=0.3, friction=0.0, restitution=0.6),
    tdem.LinearContact(kn=1e4, friction=0.0, restitution=0.6),
])
def test_bounce_gives_the_laws_restitution(law):
    sim = tdem.Simulation(dim=3, gravity=(0, 0, 0), dt=1e-6, progress=False)
    sim.add_particles([[0, 0, 1.001 * R]], radius=R, density=RHO, contact=law,
                      velocity=[[0, 0, -1.0]])
    sim.add_plane((0, 0, 0), (0, 0, 1), contact=law)
    sim.run(steps=20000)
    v = sim.particles.numpy()["velocity"][0]
    assert sim.particles.numpy()["position"][0, 2] > R     # off the plane
    assert v[2] == pytest.approx(0.6, rel=0.01)


@pytest.mark.parametrize("inside", [True, False])
def test_sphere_pressed_against_a_cylinder(inside):
    """Axis along (0, 1, 1) through (0.1, 0, 0), radius 0.05; a body force along the
    radius (gravity along x) presses the sphere on the wall: its centre ends at the
    radius ∓ (R − m g / k_n) from the axis."""
    kn = 1e4
    law = tdem.LinearContact(kn=kn, friction=0.5, restitution=0.3)
    rc = 0.05
    c = np.array([0.1, 0.0, 0.0])
    sign = 1.0 if inside else -1.0
    sim = tdem.Simulation(dim=3, gravity=(sign * G, 0, 0), dt=1e-5, local_damping=0.5,
                          progress=False)
    x0 = c + [rc - sign * 1.02 * R, 0.03, 0.03]
    sim.add_particles([x0], radius=R, density=RHO, contact=law)
    cyl = sim.add_cylinder(c, (0, 1, 1), rc, contact=law, inside=inside)
    assert cyl.kind == "cylinder" and cyl.inside is inside and cyl.radius == rc
    x = _settle(sim)["position"][0]
    rho = x[0] - c[0]
    assert abs(x[1] - 0.03) < 1e-12 and abs(x[2] - 0.03) < 1e-12
    u = R - sign * (rc - rho)
    assert u == pytest.approx(MASS * G / kn, rel=1e-6)
    np.testing.assert_allclose(cyl.force, [sign * MASS * G, 0, 0], rtol=1e-6, atol=1e-12)


def test_energy_account_closes_and_equals_the_meshed_planes():
    law = tdem.HertzMindlin(young=1e7, poisson=0.3, friction=0.3, restitution=0.5)
    normal, v0, w0 = (0.3, -0.2, 1.0), (0.8, -0.3, -0.6), (20.0, -5.0, 3.0)
    _, sim = _drop(True, normal, v0, w0, law)
    _, ref = _drop(False, normal, v0, w0, law)
    e, f = sim.energy(), ref.energy()
    for k in ("kinetic", "gravitational", "elastic", "dissipated", "total"):
        assert e[k] == pytest.approx(f[k], rel=1e-9, abs=1e-15), k
    assert e["dissipated"] > 0.0
    # the total is what it was at the start, ½ m v² + ½ I ω² + m g z (the leapfrog's
    # half steps apart)
    n = np.asarray(normal) / np.linalg.norm(normal)
    q = np.array([0.11, 0.07, 0.0])
    z0 = (q - (q @ n) * n + 1.2 * R * n)[2]
    e0 = (0.5 * MASS * np.dot(v0, v0) + 0.5 * 0.4 * MASS * R * R * np.dot(w0, w0)
          + MASS * G * z0)
    assert e["total"] == pytest.approx(e0, rel=2e-3)


def _piston_box(v_lid=-0.05):
    """27 spheres in a box of five planes, a lid plane coming down at ``v_lid``."""
    law = tdem.HertzMindlin(young=1e7, poisson=0.3, friction=0.4, restitution=0.5)
    g = np.stack(np.meshgrid(*[np.arange(3)] * 3, indexing="ij"), -1).reshape(-1, 3)
    rng = np.random.default_rng(3)
    x = R + 0.0005 + g * 2.1 * R + rng.uniform(-2e-4, 2e-4, g.shape)
    sim = tdem.Simulation(dim=3, gravity=(0, 0, -G), dt=5e-6, local_damping=0.2,
                          progress=False)
    sim.add_particles(x, radius=R, density=RHO, contact=law)
    w = 3 * 2.1 * R + 0.001
    for p, n in (((0, 0, 0), (0, 0, 1)), ((0, 0, 0), (1, 0, 0)), ((w, 0, 0), (-1, 0, 0)),
                 ((0, 0, 0), (0, 1, 0)), ((0, w, 0), (0, -1, 0))):
        sim.add_plane(p, n, contact=law)
    top = x[:, 2].max() + R
    lid = sim.add_plane((0, 0, top), (0, 0, -1), contact=law, velocity=(0, 0, v_lid))
    return sim, lid, top


def test_piston_compresses_a_pack_and_its_force_is_the_contacts_sum():
    sim, lid, top = _piston_box()
    sim.run(steps=12000)
    assert lid.point[2] == pytest.approx(top - 0.05 * 12000 * 5e-6, rel=1e-12)
    c = sim.contacts.numpy()
    mine = c["pairs"][:, 1] == -1 - lid.index
    assert mine.sum() >= 4
    f_on_particles = (-c["normal"][mine, None] * c["direction"][mine]
                      + c["shear_force"][mine]).sum(axis=0)
    np.testing.assert_allclose(lid.force, -f_on_particles, rtol=1e-9,
                               atol=1e-9 * np.abs(lid.force).max())
    assert lid.force[2] > 27 * MASS * G      # it presses the pack: more than its weight
    assert lid.contacts == mine.sum()
    # the floor carries the lid's push and the weight, less what the sides hold by
    # friction; every wall's force is the sum of its contacts'
    for prim in sim.primitives:
        sel = c["pairs"][:, 1] == -1 - prim.index
        f = (-c["normal"][sel, None] * c["direction"][sel] + c["shear_force"][sel]).sum(0)
        np.testing.assert_allclose(prim.force, -f, rtol=1e-9,
                                   atol=1e-9 * np.abs(lid.force).max())


def test_piston_moved_by_a_function_of_time_and_stopped():
    sim, lid, top = _piston_box(v_lid=0.0)
    ramp = tdem.motion.ramp((0, 0, -0.1), 0.01)
    lid.motion(velocity=ramp)
    sim.run(steps=4000)       # 0.02 s: about 0.5 mm in the ramp, then 1 mm
    # the velocity of each step is the ramp's at its start
    dt = sim.dt
    moved = sum(ramp(k * dt)[2] for k in range(4000)) * dt
    assert moved == pytest.approx(-0.0015, rel=1e-3)
    assert lid.point[2] == pytest.approx(top + moved, rel=1e-12)
    np.testing.assert_allclose(lid.velocity, [0, 0, -0.1])
    at = lid.point[2]
    lid.motion()
    sim.run(steps=100)
    assert lid.point[2] == at
    np.testing.assert_allclose(lid.velocity, [0, 0, 0])


def test_checkpoint_restarts_bit_for_bit(tmp_path):
    sim, lid, top = _piston_box()
    w = 3 * 2.1 * R + 0.001
    sim.add_cylinder((0.5 * w, 0.5 * w, 0), (0, 0, 1), 0.6 * w, contact=sim._laws[0])
    lid.motion(velocity=tdem.motion.ramp((0, 0, -0.1), 0.01))
    sim.run(steps=9000)
    path = tmp_path / "prim.h5"
    sim.save(path)
    sim.run(steps=2000)
    back = tdem.Simulation.load(path)
    assert len(back.primitives) == 7
    back.run(steps=2000)
    a, b = sim.particles.numpy(), back.particles.numpy()
    for k in ("position", "velocity", "omega"):
        assert np.array_equal(a[k], b[k]), k
    for p, q in zip(sim.primitives, back.primitives):
        assert np.array_equal(p.force, q.force)
        assert np.array_equal(p.point, q.point)
    assert back.primitives[5].velocity.tolist() == [0.0, 0.0, -0.1]
    assert sim.primitives[5].contacts > 0 and sim.primitives[6].contacts > 0


def test_bad_input_is_refused_naming_the_argument():
    law = tdem.LinearContact(kn=1e4)
    sim = tdem.Simulation(dim=3, progress=False)
    sim.add_particles([[0, 0, 0.05]], radius=R, density=RHO, contact=law)
    with pytest.raises(tdem.InputError, match=r"normal must not be zero, got \(0, 0, 0\)"):
        sim.add_plane((0, 0, 0), (0, 0, 0), contact=law)
    with pytest.raises(tdem.InputError, match="point must be three finite numbers.*nan"):
        sim.add_plane((0, float("nan"), 0), (0, 0, 1), contact=law)
    with pytest.raises(tdem.InputError, match="normal must be three finite numbers"):
        sim.add_plane((0, 0, 0), (0, 1), contact=law)
    with pytest.raises(tdem.InputError, match="contact must be given"):
        sim.add_plane((0, 0, 0), (0, 0, 1))
    with pytest.raises(tdem.InputError, match="velocity must be three finite"):
        sim.add_plane((0, 0, 0), (0, 0, 1), contact=law, velocity=(0, 0, float("inf")))
    with pytest.raises(tdem.InputError, match="radius must be a finite number > 0, got -1"):
        sim.add_cylinder((0, 0, 0), (0, 0, 1), -1, contact=law)
    with pytest.raises(tdem.InputError, match="radius must be a finite number > 0, got 0"):
        sim.add_cylinder((0, 0, 0), (0, 0, 1), 0, contact=law)
    with pytest.raises(tdem.InputError, match="axis must not be zero"):
        sim.add_cylinder((0, 0, 0), (0, 0, 0), 0.1, contact=law)
    with pytest.raises(tdem.InputError, match="inside must be True or False"):
        sim.add_cylinder((0, 0, 0), (0, 0, 1), 0.1, contact=law, inside="yes")
    assert sim.primitives == [] and len(sim._laws) == 1
    plane = sim.add_plane((0, 0, 0), (0, 0, 1), contact=law)
    with pytest.raises(tdem.InputError, match="angular_velocity: a primitive wall"):
        plane.angular_velocity = (0, 0, 1)
    with pytest.raises(tdem.InputError, match="shape: primitive walls"):
        sim.add_particles([[0, 0, 0.2]], shape=tdem.Ellipsoid(0.01, 0.008, 0.006),
                          density=RHO, contact=law)
    flat = tdem.Simulation(dim=2, progress=False)
    with pytest.raises(tdem.InputError, match="add_plane is 3D"):
        flat.add_plane((0, 0, 0), (0, 0, 1), contact=law)
    with pytest.raises(tdem.InputError, match="add_cylinder is 3D"):
        flat.add_cylinder((0, 0, 0), (0, 0, 1), 0.1, contact=law)
    shaped = tdem.Simulation(dim=3, progress=False)
    shaped.add_particles([[0, 0, 0.05]], shape=tdem.Ellipsoid(0.01, 0.008, 0.006),
                         density=RHO, contact=law)
    with pytest.raises(tdem.InputError, match="add_plane: primitive walls take spheres"):
        shaped.add_plane((0, 0, 0), (0, 0, 1), contact=law)


def test_particles_added_and_removed_around_primitives():
    """Particles added after the run started get their contact rows; an outlet that
    removes some keeps the others' rows with them (the histories follow their rows)."""
    sim, lid, top = _piston_box(v_lid=0.0)
    sim.run(steps=2000)
    law = sim._laws[0]
    sim.add_particles([[0.03, 0.03, top + 0.05]], radius=R, density=RHO, contact=law)
    assert sim._a["phist"].shape[:2] == (28, 6)
    # the bottom layer's contacts with the floor, by identity, before the outlet
    c = sim.contacts.numpy()
    ids = sim.particles.numpy()["id"]
    floor = {int(ids[i]): u for (i, j), u in zip(c["pairs"], c["overlap"]) if j == -1}
    assert len(floor) >= 3
    out = sim.remove_in(box=((0.04, -1, -1), (1, 1, 1)))
    sim.run(steps=1)
    assert out.count == 9 and sim.n_particles == 19
    c = sim.contacts.numpy()
    ids = sim.particles.numpy()["id"]
    after = {int(ids[i]): u for (i, j), u in zip(c["pairs"], c["overlap"]) if j == -1}
    assert set(after) == {k for k in floor if k in set(ids.tolist())}
    for k, u in after.items():
        assert u == pytest.approx(floor[k], rel=0.05)


_PISTON = """
import numpy as np, sys
sys.path.insert(0, {root!r})
sys.path.insert(0, {tests!r})
import tdem
from test_primitive_walls import _piston_box
sim, lid, top = _piston_box()
sim.run(steps=6000)
f = np.array([p.force for p in sim.primitives])
np.save(sys.argv[1], np.concatenate([sim.particles.numpy()["position"], f]))
print("chunk", tdem.backend.chunk_size(sim.n_particles, sim._serial()))
"""


def test_one_thread_and_parallel_paths_agree(tmp_path, summation_paths):
    """The primitives' forces summed over the chunks of the step's pair loop (two
    threads, 8 chunks) and with every pair through its slot (the GPU's path, run on
    the CPU) agree with one thread to round-off, and repeat bit for bit."""
    import os
    here = os.path.dirname(os.path.abspath(__file__))
    script = tmp_path / "piston.py"
    script.write_text(_PISTON.format(root=os.path.dirname(here), tests=here))
    out, chunk = summation_paths(script, tmp_path)
    assert chunk == {"one": 0, "chunks": 4, "chunks again": 4, "slots": 0}
    scale = np.abs(out["one"]).max(axis=0)
    for name in ("chunks", "slots"):
        assert np.all(np.abs(out[name] - out["one"]) <= 1e-9 * scale), name
    assert np.array_equal(out["chunks"], out["chunks again"])


def test_a_plane_added_after_a_run_and_a_rolling_law_after_it():
    """A sphere falling in a model without primitives; a floor plane added between runs
    catches it (the step compiled with them from then on); a second sphere with a law
    of rolling resistance added later widens the histories, and the first keeps its
    contact."""
    kn = 1e4
    law = tdem.LinearContact(kn=kn, friction=0.5, restitution=0.3)
    sim = tdem.Simulation(dim=3, gravity=(0, 0, -G), dt=1e-5, local_damping=0.5,
                          progress=False)
    sim.add_particles([[0.0, 0.0, 0.05]], radius=R, density=RHO, contact=law)
    sim.run(steps=1000)
    assert sim.particles.numpy()["position"][0, 2] < 0.05
    floor = sim.add_plane((0, 0, 0), (0, 0, 1), contact=law)
    sim.run(steps=30000)
    assert R - sim.particles.numpy()["position"][0, 2] == pytest.approx(MASS * G / kn,
                                                                      rel=1e-6)
    rolling = tdem.LinearContact(kn=kn, friction=0.5, restitution=0.3,
                                 rolling=tdem.RollingResistance(0.3))
    sim.add_particles([[0.1, 0.0, R]], radius=R, density=RHO, contact=rolling)
    sim.run(steps=20000)
    z = sim.particles.numpy()["position"][:, 2]
    np.testing.assert_allclose(R - z, MASS * G / kn, rtol=1e-6)
    np.testing.assert_allclose(floor.force, [0, 0, -2 * MASS * G], rtol=1e-6, atol=1e-12)


def test_primitives_are_drawn_in_the_walls_file(tmp_path):
    """ParaView sees the primitives: the walls file holds a plane's patch on the plane
    and a cylinder's facets' corners on its radius, around the particles, and each
    wall's cells add up to the force on it."""
    import meshio

    law = tdem.LinearContact(kn=1e4, friction=0.5, restitution=0.3)
    sim = tdem.Simulation(dim=3, gravity=(0, 0, -G), dt=1e-5, progress=False)
    xs = [[0.02 * i - 0.03, 0.0, 0.0099] for i in range(4)]
    sim.add_particles(xs, radius=R, density=RHO, contact=law)
    floor = sim.add_plane((0.0, 0.0, 0.0), (0.0, 0.0, 1.0), contact=law)
    drum = sim.add_cylinder((0.0, 0.0, 0.0), (0.0, 0.0, 1.0), 0.1, contact=law)
    sim.run(steps=200)
    from tdem.io import write_vtu
    paths = write_vtu(sim, tmp_path / "snap.vtu")
    walls = meshio.read([q for q in paths if q.endswith("_walls.vtu")][0])
    tri = walls.cells_dict["triangle"]
    prim = walls.cell_data_dict["primitive"]["triangle"]
    force = walls.cell_data_dict["force"]["triangle"]
    pts = walls.points
    on_plane = pts[tri[prim == 0]].reshape(-1, 3)
    assert np.abs(on_plane[:, 2]).max() < 1e-12
    # the patch reaches past the particles on every side
    assert on_plane[:, 0].min() < -0.04 and on_plane[:, 0].max() > 0.04
    on_drum = pts[tri[prim == 1]].reshape(-1, 3)
    assert np.hypot(on_drum[:, 0], on_drum[:, 1]) == pytest.approx(0.1, rel=1e-12)
    assert on_drum[:, 2].min() < 0.0 < 0.022 < on_drum[:, 2].max()
    np.testing.assert_allclose(force[prim == 0].sum(axis=0), floor.force, rtol=1e-12,
                               atol=1e-15)
    np.testing.assert_allclose(force[prim == 1].sum(axis=0), drum.force, atol=1e-15)
    assert abs(floor.force[2]) > 0.1      # the spheres touch the floor: a real sum
    assert (walls.cell_data_dict["mesh"]["triangle"][prim >= 0] == -1).all()
