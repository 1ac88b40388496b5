"""3D spheres and triangle-mesh walls against Hertz theory and rigid-body mechanics
(Miyata et al. 2002, §2.4): normal impacts, oblique impacts in the sliding regime, rolling down a
triangulated incline across its seams, seams and vertices of a flat mesh felt as one
plane, energy of a frictionless gas, and the 3D inputs refused."""
import math

import numpy as np
import pytest

import tdem

E, NU, RHO, R = 1e8, 0.3, 2500.0, 0.01


def e_star():
    return E / (2.0 * (1.0 - NU ** 2))


def mass(r=R):
    return RHO * 4.0 / 3.0 * math.pi * r ** 3


def hertz_peak(mstar, rstar, v):
    """Peak overlap, peak force and contact time of an elastic Hertz impact at
    relative speed v (Johnson 1985, §11.1)."""
    d = (15.0 * mstar * v * v / (16.0 * e_star() * math.sqrt(rstar))) ** 0.4
    f = 4.0 / 3.0 * e_star() * math.sqrt(rstar) * d ** 1.5
    return d, f, 2.9432 * d / v


def record(sim, fn, steps):
    sim.monitor("probe", fn, every=1)
    sim.run(steps=steps)
    return np.asarray(sim.histories()["probe"][1])


def impact_series(sim, gap_fn, steps):
    """(times, gaps, force on particle 0) at every step."""
    vals = record(sim, lambda s: np.concatenate([[s.time, gap_fn(s)],
                                                 s.particles.numpy()["force"][0]]), steps)
    return vals[:, 0], vals[:, 1], vals[:, 2:]


def contact_window(t, gap):
    """Times the gap crosses zero (in, out), linearly interpolated."""
    neg = np.flatnonzero(gap < 0)
    a, b = neg[0], neg[-1]
    t_in = t[a - 1] + (t[a] - t[a - 1]) * gap[a - 1] / (gap[a - 1] - gap[a])
    t_out = t[b] + (t[b + 1] - t[b]) * gap[b] / (gap[b] - gap[b + 1])
    return t_in, t_out


def test_sphere_sphere_normal_impact_is_hertz():
    hm = tdem.HertzMindlin(young=E, poisson=NU, friction=0.0)
    sim = tdem.Simulation(dim=3, gravity=(0.0, 0.0, 0.0), dt_fraction=0.02, progress=False)
    v = 0.5
    sim.add_particles([[-R - 1e-4, 0, 0], [R + 1e-4, 0, 0]], R, density=RHO, contact=hm,
                      velocity=[[v, 0, 0], [-v, 0, 0]])
    d_th, f_th, tc_th = hertz_peak(0.5 * mass(), 0.5 * R, 2 * v)
    steps = int(1.6 * tc_th / sim.dt)

    def gap(s):
        x = s.particles.numpy()["position"]
        return np.linalg.norm(x[1] - x[0]) - 2 * R

    t, g, f = impact_series(sim, gap, steps)
    t_in, t_out = contact_window(t, g)
    assert -g.min() == pytest.approx(d_th, rel=0.02)
    assert np.abs(f[:, 0]).max() == pytest.approx(f_th, rel=0.02)
    assert t_out - t_in == pytest.approx(tc_th, rel=0.02)
    vel = sim.particles.numpy()["velocity"]
    assert vel[0, 0] == pytest.approx(-v, rel=1e-3)      # elastic: speed kept
    assert np.abs(vel[:, 1:]).max() < 1e-12
    p = mass() * vel.sum(axis=0)
    assert np.abs(p).max() < 1e-12 * mass() * v


@pytest.mark.parametrize("restitution", [1.0, 0.5])
def test_sphere_on_mesh_plane_impact(restitution):
    hm = tdem.HertzMindlin(young=E, poisson=NU, friction=0.0,
                           restitution=None if restitution == 1.0 else restitution)
    sim = tdem.Simulation(dim=3, gravity=(0.0, 0.0, 0.0), dt_fraction=0.02, progress=False)
    v = 1.0
    sim.add_particles([[0.0013, 0.0021, R + 1e-4]], R, density=RHO, contact=hm,
                      velocity=(0.0, 0.0, -v))
    verts, tris = tdem.surfaces.plane((0, 0, 0), (0, 0, 1), 0.2, divisions=4)
    floor = sim.add_mesh(verts, tris, contact=hm)
    d_th, f_th, tc_th = hertz_peak(mass(), R, v)        # against a wall: m* = m, R* = R
    steps = int(1.6 * tc_th / sim.dt)
    t, g, f = impact_series(sim, lambda s: s.particles.numpy()["position"][0, 2] - R, steps)
    vz = sim.particles.numpy()["velocity"][0, 2]
    assert vz == pytest.approx(restitution * v, rel=0.03)
    if restitution == 1.0:
        t_in, t_out = contact_window(t, g)
        assert -g.min() == pytest.approx(d_th, rel=0.02)
        assert f[:, 2].max() == pytest.approx(f_th, rel=0.02)
        assert t_out - t_in == pytest.approx(tc_th, rel=0.02)
    assert np.abs(floor.force).max() == 0.0            # (contact over: nothing received)


@pytest.mark.parametrize("ratio", [3.0, 4.5, 7.0])
def test_oblique_impact_sliding_regime(ratio):
    """Chung & Ooi tests 4–6, sliding regime (v_t/v_n >= 7μ for e = 1): the friction
    impulse is μ·2m v_n throughout, so v_t' = v_t − 2μ v_n and ω' R = 5μ v_n."""
    mu = 0.3
    hm = tdem.HertzMindlin(young=E, poisson=NU, friction=mu)
    sim = tdem.Simulation(dim=3, gravity=(0.0, 0.0, 0.0), dt_fraction=0.02, progress=False)
    vn = 1.0
    sim.add_particles([[0.0, 0.0, R + 1e-5]], R, density=RHO, contact=hm,
                      velocity=(ratio * vn, 0.0, -vn))
    verts, tris = tdem.surfaces.plane((0, 0, 0), (0, 0, 1), 1.0, divisions=1)
    sim.add_mesh(verts, tris, contact=hm)
    tc = hertz_peak(mass(), R, vn)[2]
    sim.run(steps=int(1.5 * tc / sim.dt))
    s = sim.particles.numpy()
    assert s["velocity"][0, 0] == pytest.approx(ratio * vn - 2 * mu * vn, rel=0.05)
    assert s["omega"][0, 1] * R == pytest.approx(5 * mu * vn, rel=0.05)
    assert s["velocity"][0, 2] == pytest.approx(vn, rel=0.01)


def test_sphere_rolls_down_a_triangulated_incline():
    """(5/7) g sin θ within 2 %, the normal force steady across the seams."""
    th = math.radians(20.0)
    hm = tdem.HertzMindlin(young=E, poisson=NU, friction=0.5, restitution=0.3)
    g = 9.81
    sim = tdem.Simulation(dim=3, gravity=(0.0, 0.0, -g), progress=False)
    n = np.array([-math.sin(th), 0.0, math.cos(th)])      # incline rising along −x
    verts, tris = tdem.surfaces.plane((0, 0, 0), n, 0.4, divisions=10)
    sim.add_mesh(verts, tris, contact=hm)
    fn = mass() * g * math.cos(th)
    delta = (3 * fn / (4 * e_star() * math.sqrt(R))) ** (2 / 3)
    x0 = np.array([0.16, 0.013, 0.0])
    x0 = x0 - x0.dot(n) * n + (R - delta) * n
    sim.add_particles([x0], R, density=RHO, contact=hm)
    down = np.array([math.cos(th), 0.0, math.sin(th)])    # down the slope: −x, −z
    down = -down
    sim.run(until=0.02)                                    # settle on the slope
    vals = record(sim, lambda s: np.concatenate([
        [s.time], s.particles.numpy()["position"][0],
        [-s.meshes[0].force.dot(n)]]), 3500)
    t, x, fnorm = vals[:, 0], vals[:, 1:4], vals[:, 4]
    along = x @ down
    height = x @ n
    a = 2.0 * np.polyfit(t, along, 2)[0]
    assert a == pytest.approx(5.0 / 7.0 * g * math.sin(th), rel=0.02)
    assert along[-1] - along[0] > 0.1          # it crossed many seams (cells of 0.04 m)
    assert np.ptp(height) < 0.01 * R
    assert np.abs(fnorm / fn - 1.0).max() < 0.02


@pytest.mark.parametrize("where", ["face", "edge", "vertex"])
def test_flat_mesh_is_one_plane_at_seams_and_vertices(where):
    """A sphere pressed into a flat mesh feels the Hertz force of one plane wherever it
    sits: inside a face, on a shared edge, on a vertex shared by six triangles."""
    hm = tdem.HertzMindlin(young=E, poisson=NU, friction=0.0)
    sim = tdem.Simulation(dim=3, gravity=(0.0, 0.0, 0.0), dt_fraction=0.02, progress=False)
    verts, tris = tdem.surfaces.plane((0, 0, 0), (0, 0, 1), 0.2, divisions=4)   # cells 0.05
    xy = {"face": (0.013, 0.031), "edge": (0.0, 0.021), "vertex": (0.0, 0.0)}[where]
    delta = 1e-4
    sim.add_particles([[xy[0], xy[1], R - delta]], R, density=RHO, contact=hm)
    floor = sim.add_mesh(verts, tris, contact=hm)
    sim.run(steps=1)
    f = floor.force
    assert -f[2] == pytest.approx(4.0 / 3.0 * e_star() * math.sqrt(R) * delta ** 1.5,
                                  rel=1e-6)
    assert np.abs(f[:2]).max() < 1e-9 * abs(f[2])


def test_frictionless_sphere_gas_keeps_energy_and_momentum():
    """Collisions of about 11 steps (dt_fraction 0.1): the leapfrog's energy error,
    which falls fast with Δt (0.06 % at 0.1, 4 % at the default 0.2 where a collision takes 5
    steps), stays below 0.5 % over 2000 steps."""
    lin = tdem.LinearContact(kn=1e4, ks=0.0, friction=0.0)
    sim = tdem.Simulation(dim=3, gravity=(0.0, 0.0, 0.0), progress=False, dt_fraction=0.1)
    sim.periodic(x=(0.0, 0.2), y=(0.0, 0.2), z=(0.0, 0.2))
    rng = np.random.default_rng(1)
    g = np.stack(np.meshgrid(*[np.arange(5) * 0.04 + 0.02] * 3, indexing="ij"), -1)
    pos = g.reshape(-1, 3)
    vel = rng.normal(0.0, 0.5, pos.shape)
    vel -= vel.mean(axis=0)
    sim.add_particles(pos, R * 1.5, density=RHO, contact=lin, velocity=vel)
    e0 = 0.5 * float((mass(1.5 * R) * vel * vel).sum())
    sim.run(steps=2000)
    e = sim.energy()
    s = sim.particles.numpy()
    assert abs(e["total"] - e0) / e0 < 5e-3
    assert e["kinetic"] < 0.999 * e0        # (collisions: energy in the springs)
    assert abs(e["integration_error"]) / e0 < 5e-3
    p = (s["mass"][:, None] * s["velocity"]).sum(axis=0)
    scale = float((s["mass"] * np.linalg.norm(s["velocity"], axis=1)).sum())
    assert np.abs(p).max() < 1e-10 * scale
    assert sim.neighbour_builds > 1


def test_3d_inputs_refused_naming_the_argument():
    hm = tdem.HertzMindlin(young=E, poisson=NU)
    with pytest.raises(tdem.InputError, match="dim"):
        tdem.Simulation(dim=4)
    sim = tdem.Simulation(dim=3, progress=False)
    with pytest.raises(tdem.InputError, match=r"positions.*\(N, 3\).*2D array"):
        sim.add_particles(np.zeros((3, 2)), R, contact=hm)
    with pytest.raises(tdem.InputError, match="orientation.*unit quaternions"):
        sim.add_particles([[0, 0, 0]], R, contact=hm, orientation=[1.0, 1.0, 0.0, 0.0])
    with pytest.raises(tdem.InputError, match="orientation"):
        sim.add_particles([[0, 0, 0]], R, contact=hm, orientation=[float("nan"), 0, 0, 0])
    with pytest.raises(tdem.InputError, match="shape"):
        sim.add_particles([[0, 0, 0]], contact=hm, shape=tdem.Superellipse(0.01, 0.01, 2))
    with pytest.raises(tdem.InputError, match="add_mesh"):
        sim.add_wall((0, 0), (1, 0), contact=hm)
    with pytest.raises(tdem.InputError, match="gravity"):
        tdem.Simulation(dim=3, gravity=(0.0, -9.81))
    with pytest.raises(tdem.InputError, match="triangles"):
        sim.add_mesh(np.zeros((3, 3)), [[0, 1, 2]], contact=hm)        # no area
    with pytest.raises(tdem.InputError, match="triangles"):
        sim.add_mesh(np.eye(3), [[0, 1, 5]], contact=hm)
    with pytest.raises(tdem.InputError, match="rolling"):
        sim.add_particles([[0, 0, 0]], shape=tdem.Ellipsoid(0.01, 0.008, 0.005),
                          contact=tdem.HertzMindlin(young=E, poisson=NU,
                                                    rolling=tdem.RollingResistance(delta=0.1)))
    sim2 = tdem.Simulation(progress=False)
    with pytest.raises(tdem.InputError, match=r"positions.*\(N, 2\).*3D array"):
        sim2.add_particles(np.zeros((3, 3)), R, contact=hm)
    with pytest.raises(tdem.InputError, match="add_mesh is 3D"):
        sim2.add_mesh(np.eye(3), [[0, 1, 2]], contact=hm)
    assert sim.n_particles == 0 and sim2.n_particles == 0


@pytest.mark.parametrize("e", [0.1, 0.5, 0.9])
def test_hertz_dashpot_gives_the_restitution_asked(e):
    """The dimensionless Hertz contact with the dashpot of HertzMindlin rebounds at e
    (solved here independently, to 1e-6)."""
    from scipy.integrate import solve_ivp

    from physics.hertz_mindlin import hertz_damping

    c = hertz_damping(e) * math.sqrt(1.5)

    def rhs(t, y):
        x = max(y[0], 0.0)
        return [y[1], -x ** 1.5 - c * x ** 0.25 * y[1]]

    def out(t, y):
        return y[0]
    out.terminal, out.direction = True, -1
    sol = solve_ivp(rhs, (0.0, 100.0), [1e-12, 1.0], events=out, rtol=1e-11, atol=1e-13,
                    max_step=0.01)
    assert -sol.y_events[0][0][1] == pytest.approx(e, abs=1e-6)


def _box_of_spheres(n_side=4, seed=0):
    hm = tdem.HertzMindlin(young=E, poisson=NU, friction=0.4, restitution=0.5)
    sim = tdem.Simulation(dim=3, progress=False, check_interval=50)
    verts, tris = tdem.surfaces.box((0, 0, 0), (0.1, 0.1, 0.2))
    sim.add_mesh(verts, tris, contact=hm)
    rng = np.random.default_rng(seed)
    g = np.stack(np.meshgrid(*[np.arange(n_side) * 0.022 + 0.017] * 2,
                             np.arange(n_side) * 0.022 + 0.02, indexing="ij"), -1)
    pos = g.reshape(-1, 3) + rng.uniform(-0.001, 0.001, (n_side ** 3, 3))
    sim.add_particles(pos, rng.uniform(0.008, 0.01, len(pos)), density=RHO, contact=hm,
                      velocity=rng.normal(0.0, 0.2, pos.shape))
    return sim


def test_3d_checkpoint_restarts_bit_for_bit(tmp_path):
    sim = _box_of_spheres()
    sim.run(until=0.15)
    sim.save(tmp_path / "c.h5")
    sim.run(steps=300)
    a = sim.particles.numpy()
    back = tdem.Simulation.load(tmp_path / "c.h5")
    assert back.dim == 3 and back.steps == sim.steps - 300
    back.run(steps=300)
    b = back.particles.numpy()
    for k in ("position", "velocity", "omega", "orientation", "force", "torque"):
        np.testing.assert_array_equal(a[k], b[k], err_msg=k)
    np.testing.assert_array_equal(sim.meshes[0].force, back.meshes[0].force)
    assert len(sim.contacts.numpy()["pairs"]) > 20


def test_3d_output_reads_back(tmp_path):
    vtk = pytest.importorskip("vtk")
    from vtk.util.numpy_support import vtk_to_numpy

    sim = _box_of_spheres(3)
    sim.run(until=0.15)
    files = sim.write_vtu(tmp_path / "s.vtu")
    s = sim.particles.numpy()

    def read(path):
        r = vtk.vtkXMLUnstructuredGridReader()
        r.SetFileName(str(path))
        r.Update()
        return r.GetOutput()

    parts = read(files[0])
    np.testing.assert_allclose(vtk_to_numpy(parts.GetPoints().GetData()), s["position"])
    np.testing.assert_allclose(vtk_to_numpy(parts.GetPointData().GetArray("radius")),
                               s["radius"])
    assert vtk_to_numpy(parts.GetPointData().GetArray("orientation")).shape == (27, 4)
    walls = read(files[1])
    assert walls.GetNumberOfCells() == 10                 # floor and four sides
    f = vtk_to_numpy(walls.GetCellData().GetArray("force"))
    np.testing.assert_allclose(f.sum(axis=0), sim.meshes[0].force, rtol=1e-12, atol=1e-15)
    contacts = read(files[2])
    assert contacts.GetNumberOfCells() == len(sim.contacts.numpy()["pairs"])
    assert vtk_to_numpy(contacts.GetCellData().GetArray("shear_force")).shape[1] == 3


@pytest.mark.parametrize("delta", [0.1, 0.3])
def test_rolling_resistance_decelerates_a_rolling_sphere(delta):
    """Jiang's Model 1 in its 3D vector form: once the rolling spring is at its cap
    M0 = F_n B/6 (B = δ·2R against a wall), a sphere rolling on a plane decelerates at
    M0/(R (m + I/R²)) = δ g/4.2, and it stops rolling there."""
    hm = tdem.HertzMindlin(young=E, poisson=NU, friction=0.8, restitution=0.5,
                           rolling=tdem.RollingResistance(delta=delta, model=1))
    g = 9.81
    sim = tdem.Simulation(dim=3, gravity=(0.0, 0.0, -g), progress=False)
    sim.add_mesh(*tdem.surfaces.plane((0, 0, 0), (0, 0, 1), 2.0, divisions=8), contact=hm)
    fn = mass() * g
    delta_z = (3 * fn / (4 * e_star() * math.sqrt(R))) ** (2 / 3)
    v0 = 0.5
    sim.add_particles([[0.0, 0.011, R - delta_z]], R, density=RHO, contact=hm,
                      velocity=(v0, 0.0, 0.0), omega=(0.0, v0 / R, 0.0))
    sim.run(until=0.01)
    vals = record(sim, lambda s: np.concatenate([[s.time], s.particles.numpy()["velocity"][0],
                                                 s.particles.numpy()["omega"][0]]), 600)
    t, vx, wy = vals[:, 0], vals[:, 1], vals[:, 5]
    a = np.polyfit(t, vx, 1)[0]
    assert -a == pytest.approx(delta * g / 4.2, rel=0.02)
    np.testing.assert_allclose(wy * R, vx, rtol=5e-3)          # still rolling
    assert sim.energy()["dissipated"] > 0.0


def _spheres_on_a_fine_mesh(bins):
    hm = tdem.HertzMindlin(young=E, poisson=NU, friction=0.4, restitution=0.5)
    sim = tdem.Simulation(dim=3, progress=False, check_interval=50)
    floor = sim.add_mesh(*tdem.surfaces.plane((0.05, 0.05, 0.0), (0, 0, 1), 0.4, divisions=40),
                         contact=hm)
    xyz = tdem.pack.lattice3d((0, 0, 0), (0.1, 0.1, 0.06), 0.0051, kind="cubic")
    rng = np.random.default_rng(3)
    sim.add_particles(xyz + rng.uniform(-3e-4, 3e-4, xyz.shape), 0.005, density=RHO,
                      contact=hm, velocity=rng.normal(0, 0.3, xyz.shape))
    if not bins:
        # no triangle bins: every build looks at all the triangles
        from tdem import neighbors
        import taichi as ti
        orig = sim._sync_triangle_bins

        def none():
            orig()
            sim._a["tbin_items"] = ti.ndarray(ti.i32, (1,))
            sim._a["flags"][neighbors.F_TBIN_NEED] = 0
        sim._sync_triangle_bins = none
    sim.run(until=0.1)
    return sim, floor


def test_triangle_bins_give_the_same_run_as_every_triangle():
    """The broad phase over the mesh (triangles binned into the cells) finds the same
    candidates as looking at all 3200 triangles: the runs agree bit for bit."""
    from tdem import neighbors
    a, fa = _spheres_on_a_fine_mesh(True)
    b, fb = _spheres_on_a_fine_mesh(False)
    flags = a._a["flags"].to_numpy()
    assert 0 < flags[neighbors.F_TBIN_TOTAL] <= a._a["tbin_items"].shape[0]   # binned
    assert b._a["flags"].to_numpy()[neighbors.F_TBIN_TOTAL] > 1                # not
    for k in ("position", "velocity", "omega"):
        np.testing.assert_array_equal(a.particles.numpy()[k], b.particles.numpy()[k])
    np.testing.assert_array_equal(fa.force, fb.force)
    n = a.n_particles
    assert -fa.force[2] == pytest.approx(n * mass(0.005) * 9.81, rel=0.5)     # on the floor


@pytest.mark.parametrize("axis", [0, 1])
def test_sphere_crossing_a_periodic_side_keeps_its_mesh_floor(axis):
    """Walls are not periodic: a sphere that slides across a periodic side comes back
    over other triangles of the floor, which its candidate walls must already hold
    (those of its image, tdem.neighbors.finish_build). Its weight stays on the floor
    at every step, before and after the crossing, at the Hertz rest height."""
    L = 0.1
    hm = tdem.HertzMindlin(young=E, poisson=NU, friction=0.0)
    sim = tdem.Simulation(dim=3, progress=False)
    sim.periodic(x=(0.0, L), y=(0.0, L))
    verts, tris = tdem.surfaces.plane((0.5 * L, 0.5 * L, 0.0), (0.0, 0.0, 1.0), L + 0.04, 2)
    floor = sim.add_mesh(verts, tris, contact=hm)
    weight = mass() * 9.81
    delta = (3.0 * weight / (4.0 * e_star() * math.sqrt(R))) ** (2.0 / 3.0)
    x = [0.5 * L, 0.5 * L, R - delta]
    x[axis] = L - 0.05 * R
    v = [0.0, 0.0, 0.0]
    v[axis] = 0.05
    sim.add_particles([x], R, density=RHO, contact=hm, velocity=[v])
    steps = int(0.03 / sim.dt)
    vals = record(sim, lambda s: [s.particles.numpy()["position"][0, axis],
                                  s.particles.numpy()["position"][0, 2], -floor.force[2]],
                  steps)
    crossed = np.flatnonzero(vals[:, 0] < 0.5 * L)
    assert len(crossed) > steps // 2                   # it went across early on
    assert vals[-1, 0] == pytest.approx(0.05 * 0.03 - 0.05 * R, abs=1e-4)
    np.testing.assert_allclose(vals[:, 2], weight, rtol=0.05)
    np.testing.assert_allclose(vals[:, 1], R - delta, atol=0.1 * delta)


def test_particles_in_a_3d_box_and_the_bottom_layer_held():
    """sim.particles_in with z bounds picks a layer of a 4 × 4 × 3 lattice (16 of 48);
    held by fix_particles, that layer stays put while the others fall freely for 0.05 s
    (z drops by g t²/2 to 1 %); z bounds in 2D and a NaN bound are refused."""
    sim = tdem.Simulation(dim=3, progress=False)
    g = np.stack(np.meshgrid(*[np.arange(4) * 0.05] * 2, np.arange(3) * 0.05,
                             indexing="ij"), -1).reshape(-1, 3)
    sim.add_particles(g, 0.01, density=RHO, contact=tdem.HertzMindlin(young=E, poisson=NU))
    bottom = sim.particles_in(zmax=0.01)
    assert len(bottom) == 16 and np.all(g[bottom, 2] == 0.0)
    assert len(sim.particles_in(zmin=0.04, zmax=0.06, xmax=0.06)) == 8
    sim.fix_particles(bottom, vx=0.0, vy=0.0, vz=0.0)
    sim.run(until=0.05)                   # (they fall 12 mm, a gap of 30 mm below)
    z = sim.particles.numpy()["position"][:, 2]
    np.testing.assert_array_equal(z[bottom], 0.0)
    rest = np.setdiff1d(np.arange(len(g)), bottom)
    np.testing.assert_allclose(g[rest, 2] - z[rest], 0.5 * 9.81 * sim.time ** 2, rtol=0.01)
    with pytest.raises(tdem.InputError, match="zmin must be a number"):
        sim.particles_in(zmin=float("nan"))
    flat = tdem.Simulation(progress=False)
    flat.add_particles([[0.0, 0.0]], 0.1, contact=tdem.LinearContact(kn=1e5))
    with pytest.raises(tdem.InputError, match="zmax: a 2D simulation has no z axis"):
        flat.particles_in(zmax=1.0)


def _servo_bed(tmp_path=None):
    """Spheres in a box periodic in x and y, on a floor, under a lid held at a target
    force by its servo; damped to rest."""
    L, R = 0.06, 0.005
    hm = tdem.HertzMindlin(young=1e7, poisson=0.3, friction=0.3, restitution=0.5)
    smooth = tdem.HertzMindlin(young=1e7, poisson=0.3, friction=0.0, restitution=0.5)
    sim = tdem.Simulation(dim=3, local_damping=0.5, progress=False)
    sim.periodic(x=(0.0, L), y=(0.0, L))
    floor = sim.add_mesh(*tdem.surfaces.plane((0.5 * L, 0.5 * L, 0.0), (0.0, 0.0, 1.0),
                                              L + 0.03, 2), contact=smooth)
    lid = sim.add_mesh(*tdem.surfaces.plane((0.5 * L, 0.5 * L, 0.045), (0.0, 0.0, -1.0),
                                            L + 0.03, 2), contact=smooth)
    g = (np.stack(np.meshgrid(*[np.arange(6)] * 2, np.arange(3), indexing="ij"), -1)
         .reshape(-1, 3) + 0.5) * 0.0102
    sim.add_particles(g, R, density=2500.0, contact=hm)
    return sim, floor, lid


def test_a_servo_lid_holds_its_target_force_on_a_bed():
    """A lid under servo control (target 30 N, far above the bed's weight of 0.14 N)
    comes down, meets the bed and presses it until it receives the target within
    1 %; the floor then carries the target plus the weight within 1 %. Switched
    off, the lid stops."""
    sim, floor, lid = _servo_bed()
    target = 30.0
    lid.servo(force=target)
    weight = float(sim.particles.numpy()["mass"].sum()) * 9.81
    sim.run(until=0.4)
    assert lid.force[2] > 0.0                  # (it touches the bed)
    sim.run(until=0.6)
    assert lid.force[2] == pytest.approx(target, rel=0.01)     # pushed up by the bed
    assert -floor.force[2] == pytest.approx(target + weight, rel=0.01)
    assert lid.velocity[2] == pytest.approx(0.0, abs=1e-3)
    lid.servo()
    np.testing.assert_array_equal(lid.velocity, 0.0)


def test_a_servo_mesh_restarts_bit_for_bit(tmp_path):
    sim, floor, lid = _servo_bed()
    lid.servo(stress=5e3)                       # × the lid's area (0.09 × 0.09 m²)
    sim.run(steps=100)
    assert lid.velocity[2] < 0.0                # (coming down when saved)
    sim.save(tmp_path / "s.h5")
    sim.run(steps=600)
    back = tdem.Simulation.load(tmp_path / "s.h5")
    back.run(steps=600)
    np.testing.assert_array_equal(sim.particles.numpy()["position"],
                                  back.particles.numpy()["position"])
    np.testing.assert_array_equal(sim.meshes[1].triangles, back.meshes[1].triangles)
    np.testing.assert_array_equal(sim.meshes[1].force, back.meshes[1].force)
    assert sim.meshes[1].force[2] == pytest.approx(5e3 * 0.09 ** 2, rel=0.01)


def test_mesh_servo_input_is_checked():
    sim, floor, lid = _servo_bed()
    with pytest.raises(tdem.InputError, match="not both"):
        lid.servo(force=1.0, stress=1.0)
    with pytest.raises(tdem.InputError, match="relaxation"):
        lid.servo(force=1.0, relaxation=1.5)
    with pytest.raises(tdem.InputError, match="direction must not be zero"):
        lid.servo(force=1.0, direction=(0.0, 0.0, 0.0))
    with pytest.raises(tdem.InputError, match="force must be a finite number"):
        lid.servo(force=float("nan"))
    box = sim.add_mesh(*tdem.surfaces.box((0.0, 0.0, 0.0), (0.01, 0.01, 0.01),
                                                open_top=False),
                       contact=tdem.HertzMindlin(young=1e7, poisson=0.3))
    with pytest.raises(tdem.InputError, match="direction: mesh 2 has no mean normal"):
        box.servo(force=1.0)
