"""3D ellipsoids (Miyata et al. 2002, §2.4): the penetration depth against a brute-force search, the
torque-free rotation (|L| and energy kept, the flip about the intermediate axis with
the period of the Jacobi elliptic solution), an ellipsoid coming to rest on its
shortest axis at the Hertz height, and a sphere-shaped ellipsoid giving the sphere's
results to round-off."""
import math

import numpy as np
import pytest
import taichi as ti

import tdem
from tdem.runner import _rotations

E, NU = 1e7, 0.3


def random_quaternion(rng):
    q = rng.normal(size=4)
    return q / np.linalg.norm(q)


def shape_matrix(q, abc):
    r = _rotations(np.asarray(q)[None])[0]
    return r @ np.diag(np.square(abc)) @ r.T


def brute_depth(mi, mj, d, samples=100_000, seed=0):
    """min over unit n of h_i(n) + h_j(n) − d·n by dense sampling, then refined."""
    from scipy.optimize import minimize

    def f(n):
        n = n / np.linalg.norm(n)
        return math.sqrt(n @ mi @ n) + math.sqrt(n @ mj @ n) - d @ n

    rng = np.random.default_rng(seed)
    ns = rng.normal(size=(samples, 3))
    ns /= np.linalg.norm(ns, axis=1)[:, None]
    vals = (np.sqrt(np.einsum("ni,ij,nj->n", ns, mi, ns))
            + np.sqrt(np.einsum("ni,ij,nj->n", ns, mj, ns)) - ns @ d)
    best = ns[np.argmin(vals)]
    res = minimize(f, best, method="BFGS", options={"gtol": 1e-13})
    n = res.x / np.linalg.norm(res.x)
    return f(n), n


def test_penetration_depth_against_brute_force_and_symmetric():
    tdem.Simulation(dim=3, progress=False)          # (Taichi started)
    from physics.geometry import ellipsoid as el

    @ti.kernel
    def depth(mi: ti.types.ndarray(), mj: ti.types.ndarray(), d: ti.types.ndarray(),
              out: ti.types.ndarray()):
        for _ in range(1):
            a = ti.Matrix([[mi[r, c] for c in ti.static(range(3))] for r in ti.static(range(3))])
            b = ti.Matrix([[mj[r, c] for c in ti.static(range(3))] for r in ti.static(range(3))])
            dv = ti.Vector([d[0], d[1], d[2]])
            u, n, status, hi, hj, oi, oj = el.penetration(a, b, dv, dv.normalized(), 1e-13, 60)
            out[0] = u
            out[1], out[2], out[3] = n[0], n[1], n[2]
            out[4] = status
            out[5], out[6] = hi, hj
            for c in ti.static(range(3)):
                out[7 + c] = oi[c]
                out[10 + c] = oj[c]

    rng = np.random.default_rng(7)
    for _ in range(6):
        abc_i = rng.uniform(0.5, 2.0, 3)
        abc_j = rng.uniform(0.5, 2.0, 3)
        mi = shape_matrix(random_quaternion(rng), abc_i)
        mj = shape_matrix(random_quaternion(rng), abc_j)
        dirn = rng.normal(size=3)
        dirn /= np.linalg.norm(dirn)
        # a pose with a small overlap: the centres apart by the sum of the supports
        # along a random direction, less a little, until they overlap
        dist = math.sqrt(dirn @ mi @ dirn) + math.sqrt(dirn @ mj @ dirn)
        for shrink in (0.97, 0.9, 0.8, 0.7, 0.6, 0.5):
            d = dirn * dist * shrink
            ref, nref = brute_depth(mi, mj, d)
            if ref > 0.0:
                break
        out = np.zeros(13)
        depth(mi, mj, d, out)
        assert out[4] == 0
        assert out[0] == pytest.approx(ref, abs=1e-9 * dist)
        np.testing.assert_allclose(out[1:4], nref, atol=1e-5)
        # the support values and offsets at the returned normal come with it
        n = out[1:4]
        for h, off, m in ((out[5], out[7:10], mi), (out[6], out[10:13], mj)):
            assert h == pytest.approx(math.sqrt(n @ m @ n), rel=1e-12)
            np.testing.assert_allclose(off, m @ n / h, rtol=1e-12, atol=1e-15 * dist)
        back = np.zeros(13)
        depth(mj, mi, -d, back)                       # i and j swapped
        assert back[0] == pytest.approx(out[0], rel=1e-10)
        np.testing.assert_allclose(back[1:4], -out[1:4], atol=1e-9)


def test_apart_pair_keeps_its_separating_direction_then_meets_at_the_true_depth():
    """Two crossed ellipsoids whose extents along the line of centres overlap while
    they are apart: the pair's history keeps a direction that separates them (the
    next step's start, state -1), and when they meet the depth and normal found from
    that start are the brute-force ones."""
    abc = (0.02, 0.01, 0.005)
    e = tdem.Ellipsoid(*abc)
    hm = tdem.HertzMindlin(young=E, poisson=NU, friction=0.3)
    sim = tdem.Simulation(dim=3, gravity=(0.0, 0.0, 0.0), progress=False)
    d0 = np.array([0.018, 0.018, 0.007])
    quarter = [math.cos(math.pi / 4), 0.0, 0.0, math.sin(math.pi / 4)]
    sim.add_particles([[0.0, 0.0, 0.0], d0], shape=e, density=2500.0, contact=hm,
                      orientation=[[1.0, 0.0, 0.0, 0.0], quarter],
                      velocity=[[0.0, 0.0, 0.0], -0.2 * d0 / np.linalg.norm(d0)])
    mi = shape_matrix([1.0, 0.0, 0.0, 0.0], abc)
    mj = shape_matrix(quarter, abc)
    u = d0 / np.linalg.norm(d0)
    assert math.sqrt(u @ mi @ u) + math.sqrt(u @ mj @ u) > np.linalg.norm(d0)
    assert brute_depth(mi, mj, d0)[0] < -5e-4
    sim.run(steps=1)
    hist = sim._a["hist"].to_numpy()[0, 0]           # (one pair: 0 owns slot 0)
    assert sim._a["nbr"].to_numpy()[0, 0] == 1
    n, state = hist[-4:-1], hist[-1]
    assert state == -1.0 and np.linalg.norm(n) == pytest.approx(1.0, abs=1e-12)
    d = np.diff(sim.particles.numpy()["position"], axis=0)[0]
    assert math.sqrt(n @ mi @ n) + math.sqrt(n @ mj @ n) - d @ n < 0.0
    assert not hist[:-4].any()                       # the law's columns stay zero
    # the contacts a step reports are those at its start: the state before it
    s = sim.particles.numpy()
    for _ in range(2000):
        s = sim.particles.numpy()
        sim.run(steps=1)
        c = sim.contacts.numpy()
        if len(c["pairs"]):
            break
    assert len(c["pairs"]) == 1
    mi = shape_matrix(s["orientation"][0], abc)
    mj = shape_matrix(s["orientation"][1], abc)
    ref, nref = brute_depth(mi, mj, s["position"][1] - s["position"][0])
    assert c["overlap"][0] == pytest.approx(ref, abs=1e-9 * abc[0])
    np.testing.assert_allclose(c["direction"][0], nref, atol=1e-5)
    assert sim.nonconverged_contacts == 0


def _spinning(w0, per_turn, abc=(0.03, 0.02, 0.01), rho=1000.0):
    e = tdem.Ellipsoid(*abc)
    sim = tdem.Simulation(dim=3, gravity=(0.0, 0.0, 0.0), progress=False, check_interval=2000)
    hm = tdem.HertzMindlin(young=1e3, poisson=NU, friction=0.0)
    sim.add_particles([[0.0, 0.0, 0.0]], shape=e, density=rho, contact=hm, omega=w0)
    sim.dt = 2.0 * math.pi / np.linalg.norm(w0) / per_turn
    inertia = e.inertia(rho * e.volume)
    return sim, inertia


def test_torque_free_ellipsoid_keeps_energy_and_angular_momentum():
    w0 = np.array([3.0, 1.0, 2.0])
    sim, inertia = _spinning(w0, 1000)
    l0 = inertia * w0
    e0 = 0.5 * w0 @ l0
    sim.run(steps=100 * 1000)                         # 100 turns
    lm = sim._a["lmom"].to_numpy()[0]
    w = sim.particles.numpy()["omega"][0]
    np.testing.assert_allclose(lm, l0, rtol=0, atol=1e-12 * np.linalg.norm(l0))
    assert abs(0.5 * w @ lm - e0) / e0 < 1e-6


def test_intermediate_axis_flips_with_the_jacobi_period():
    """Spun near the intermediate axis, the body flips (ω_y in the body frame changes
    sign) every 2K(k)/λ (Landau & Lifshitz, Mechanics §37)."""
    from scipy.special import ellipk

    w0 = np.array([0.05, 10.0, 0.05])                # body = world at the start
    sim, (i1, i2, i3) = _spinning(w0, 400)
    l2 = float(np.sum((np.array([i1, i2, i3]) * w0) ** 2))
    e2 = float(np.sum(np.array([i1, i2, i3]) * w0 ** 2))     # 2E
    if l2 > e2 * i2:
        lam = math.sqrt((i3 - i2) * (l2 - e2 * i1) / (i1 * i2 * i3))
        k2 = (i2 - i1) * (e2 * i3 - l2) / ((i3 - i2) * (l2 - e2 * i1))
    else:
        lam = math.sqrt((i2 - i1) * (e2 * i3 - l2) / (i1 * i2 * i3))
        k2 = (i3 - i2) * (l2 - e2 * i1) / ((i2 - i1) * (e2 * i3 - l2))
    interval = 2.0 * ellipk(k2) / lam

    def body_wy(s):
        p = s.particles.numpy()
        r = _rotations(p["orientation"])[0]
        return (r.T @ p["omega"][0])[1]

    sim.monitor("wy", body_wy, every=4)
    sim.run(until=3.6 * interval)
    t, wy = sim.histories()["wy"]
    k = np.flatnonzero(np.sign(wy[1:]) != np.sign(wy[:-1]))
    crossings = t[k] + (t[k + 1] - t[k]) * wy[k] / (wy[k] - wy[k + 1])
    assert len(crossings) >= 3
    assert np.mean(np.diff(crossings)) == pytest.approx(interval, rel=0.02)


@pytest.mark.parametrize("seed", [3, 4])
def test_dropped_ellipsoid_rests_on_its_shortest_axis_at_the_hertz_height(seed):
    hm = tdem.HertzMindlin(young=E, poisson=NU, friction=0.5, restitution=0.3)
    e = tdem.Ellipsoid(0.02, 0.012, 0.008)
    sim = tdem.Simulation(dim=3, progress=False, local_damping=0.3)
    q = random_quaternion(np.random.default_rng(seed))
    sim.add_particles([[0.0, 0.0, 0.03]], shape=e, orientation=q, density=2500.0, contact=hm)
    verts, tris = tdem.surfaces.plane((0, 0, 0), (0, 0, 1), 0.3, 3)
    floor = sim.add_mesh(verts, tris, contact=hm)
    sim.run(until=2.5)
    s = sim.particles.numpy()
    r = _rotations(s["orientation"])[0]
    assert abs(r[2, 2]) > 0.9999                    # the body's c axis is vertical
    mass = 2500.0 * e.volume
    e_star = E / (2.0 * (1.0 - NU ** 2))
    # Hertz against a plane with the geometric-mean radius of curvature ab/c there
    delta = (3.0 * mass * 9.81 / (4.0 * e_star * math.sqrt(e.a * e.b / e.c))) ** (2.0 / 3.0)
    assert s["position"][0, 2] == pytest.approx(e.c - delta, abs=0.01 * delta)
    assert -floor.force[2] == pytest.approx(mass * 9.81, rel=1e-3)
    assert sim.nonconverged_contacts == 0


def _impacts(shape_of):
    """Two bodies colliding obliquely with spin, then one striking a mesh floor."""
    hm = tdem.HertzMindlin(young=E, poisson=NU, friction=0.3, restitution=0.6)
    sim = tdem.Simulation(dim=3, gravity=(0.0, 0.0, -9.81), dt=2e-6, progress=False)
    r = 0.01
    pos = [[0.0, 0.0, 0.02], [0.0195, 0.004, 0.0215]]
    kw = [dict(radius=r) if shape_of is None else dict(shape=shape_of(r))][0]
    sim.add_particles(pos, density=2500.0, contact=hm,
                      velocity=[[1.0, 0.2, -0.5], [-1.0, 0.0, 0.3]],
                      omega=[[0.0, 30.0, 5.0], [10.0, 0.0, -20.0]], **kw)
    verts, tris = tdem.surfaces.plane((0, 0, 0), (0, 0, 1), 0.3, 2)
    sim.add_mesh(verts, tris, contact=hm)
    sim.run(until=0.02)
    return sim.particles.numpy(), sim


def test_sphere_shaped_ellipsoid_gives_the_sphere_results():
    a, _ = _impacts(None)
    b, sim = _impacts(lambda r: tdem.Ellipsoid(r, r, r))
    for k in ("position", "velocity", "omega"):
        scale = np.abs(a[k]).max()
        np.testing.assert_allclose(b[k], a[k], rtol=0, atol=1e-9 * scale, err_msg=k)
    assert sim.nonconverged_contacts == 0


def test_ellipsoid_bed_checkpoint_restarts_bit_for_bit(tmp_path):
    hm = tdem.HertzMindlin(young=E, poisson=NU, friction=0.4, restitution=0.5)
    sim = tdem.Simulation(dim=3, progress=False, check_interval=50)
    sim.add_mesh(*tdem.surfaces.box((0, 0, 0), (0.06, 0.06, 0.2)), contact=hm)
    xyz = tdem.pack.lattice3d((0, 0, 0), (0.06, 0.06, 0.06), 0.0061, kind="cubic")
    sim.add_particles(xyz, shape=tdem.Ellipsoid(0.006, 0.0045, 0.003), density=2500.0,
                      orientation=tdem.random_orientations(len(xyz), 2), contact=hm)
    sim.run(until=0.08)
    sim.save(tmp_path / "e.h5")
    sim.run(steps=300)
    a = sim.particles.numpy()
    back = tdem.Simulation.load(tmp_path / "e.h5")
    back.run(steps=300)
    b = back.particles.numpy()
    for k in ("position", "velocity", "omega", "orientation"):
        np.testing.assert_array_equal(a[k], b[k], err_msg=k)
    np.testing.assert_array_equal(sim.meshes[0].force, back.meshes[0].force)
    assert len(sim.contacts.numpy()["pairs"]) > 0.75 * len(xyz)     # a bed, in contact
    assert sim.nonconverged_contacts == 0
