"""Applied loads: forces and moments on particles (``sim.apply_force``), forces and
pressures on block nodes (``Block.apply_force``, ``Block.apply_pressure``), constant or
functions of time. Checked against motion under a known force and against the static
solutions of loaded columns (a node may carry an applied force)."""
import math

import numpy as np
import pytest

import tdem

E, NU, RHO = 1e7, 0.25, 2000.0


def test_a_free_disc_follows_its_applied_force_and_moment():
    """No gravity, no contact: fx = c·t (a function of time) and a constant moment M.
    The leapfrog gives ω = M t / I exactly and x close to c t³/6m; the work of the
    applied loads is the kinetic energy gained."""
    sim = tdem.Simulation(gravity=(0.0, 0.0), dt=1e-3)
    law = tdem.LinearContact(kn=1e5)
    sim.add_particles([[0.0, 0.0]], 0.1, density=1000.0, contact=law)
    m = 1000.0 * math.pi * 0.01
    inertia = 0.5 * m * 0.01
    c, M = 50.0, 2.0
    sim.apply_force([0], fx=lambda t: c * t, moment=M)
    sim.run(steps=1000)
    p = sim.particles.numpy()
    t = sim.time
    assert p["omega"][0] == pytest.approx(M * t / inertia, rel=1e-12)
    assert p["position"][0, 0] == pytest.approx(c * t ** 3 / (6 * m), rel=5e-3)
    w = sim.work()
    assert w["applied"] == pytest.approx(w["kinetic_change"], rel=1e-12)
    assert w["contacts"] == 0.0


def test_loads_add_up_and_are_checked():
    sim = tdem.Simulation(gravity=(0.0, 0.0), dt=1e-3)
    sim.add_particles([[0.0, 0.0], [1.0, 0.0]], 0.1, density=1000.0,
                      contact=tdem.LinearContact(kn=1e5))
    sim.apply_force([0, 1], fy=[1.0, 2.0])
    sim.apply_force([1], fy=3.0)
    sim.run(steps=10)
    vy = sim.particles.numpy()["velocity"][:, 1]
    assert vy[1] / vy[0] == pytest.approx(5.0, rel=1e-12)
    with pytest.raises(tdem.InputError, match="fx must be"):
        sim.apply_force([0], fx=[1.0, 2.0, 3.0])
    with pytest.raises(tdem.InputError, match="ids"):
        sim.apply_force([5], fx=1.0)


def _block_column(load):
    """An elastic block 0.2 × 0.5 m on rollers (bottom nodes fixed vertically, one of
    them also horizontally), loaded on its top edge, damped to rest."""
    W, H = 0.2, 0.5
    sim = tdem.Simulation(gravity=(0.0, 0.0), local_damping=0.7)
    v, t = tdem.mesh.rectangle(W, H, 4, 10)
    b = sim.add_block(v, t, material=tdem.Elastic(density=RHO, young=E, poisson=NU))
    bot = b.nodes_in(ymax=1e-9)
    b.fix(bot, vx=None, vy=0.0)
    b.fix(bot[:1], vx=0.0, vy=0.0)
    top = b.nodes_in(ymin=H - 1e-9)
    load(b, top, v)
    sim.run(until=0.3)
    return sim, b, top, H


@pytest.mark.parametrize("kind", ["pressure", "node forces"])
def test_loaded_block_column_reaches_the_static_solution(kind):
    """A uniform pressure p on the top edge (or the same load as node forces, p × the
    tributary length of each top node): σ_yy = −p in every triangle and the top moves
    down by p (1 − ν²) H / E (plane strain, free sides) within 1 %."""
    p = 1e4

    def load(b, top, v):
        if kind == "pressure":
            b.apply_pressure(p, top)
        else:
            x = np.sort(v[top, 0])
            trib = np.concatenate([[0.5 * (x[1] - x[0])], 0.5 * (x[2:] - x[:-2]),
                                   [0.5 * (x[-1] - x[-2])]])
            order = np.argsort(v[top, 0])
            fy = np.empty(len(top))
            fy[order] = -p * trib
            b.apply_force(top, fy=fy)

    sim, b, top, H = _block_column(load)
    el = b.elements()
    np.testing.assert_allclose(el["stress"][:, 1, 1], -p, rtol=0.01)
    uy = b.nodes()["displacement"][top, 1]
    np.testing.assert_allclose(uy, -p * (1 - NU ** 2) / E * H, rtol=0.01)
    w = sim.work()
    assert abs(w["residual"]) < 1e-9 * w["applied"]


def test_pcmm_column_under_a_surface_pressure_reaches_the_static_solution():
    """A PCMM elastic column (square lattice, R = 1 cm, δ = R) on a frictionless floor,
    its top row loaded by p over its share 2R of the surface. At rest: the floor
    carries the whole load within 0.1 %; inside, σ_yy is the load over the width the
    elements span (between the outer centres) within 1 %; the top moves down by the
    plane-strain shortening of the element height plus the floor contacts' give
    (F/k_n per particle) within 1 %."""
    R, W, H, p = 0.01, 0.2, 0.4, 1e4
    sim = tdem.Simulation(gravity=(0.0, 0.0), local_damping=0.7)
    pos, rad = tdem.pack.regular(W, H, R)
    sim.add_particles(pos, rad, material=tdem.Elastic(density=RHO, young=E, poisson=NU),
                      tolerance=R)
    floor = sim.add_wall((-1.0, 0.0), (1.0, 0.0), contact=tdem.LinearContact(kn=E, friction=0.0))
    top = np.flatnonzero(pos[:, 1] > pos[:, 1].max() - 1e-9)
    bottom = np.flatnonzero(pos[:, 1] < pos[:, 1].min() + 1e-9)
    sim.apply_force(top, fy=-p * 2 * R)
    sim.run(until=0.8)
    total = p * 2 * R * len(top)
    assert floor.force[1] == pytest.approx(-total, rel=1e-3)
    s = sim.particles.numpy()
    span = pos[:, 0].max() - pos[:, 0].min()
    inner = (pos[:, 1] > 0.1) & (pos[:, 1] < 0.3) & (np.abs(pos[:, 0] - W / 2) < 0.06)
    assert s["stress"][inner, 1, 1].mean() == pytest.approx(-total / span, rel=0.01)
    height = pos[:, 1].max() - pos[:, 1].min()
    give = total / len(bottom) / E
    expect = -(total / span) * (1 - NU ** 2) / E * height - give
    assert s["displacement"][top, 1].mean() == pytest.approx(expect, rel=0.01)


def test_loads_survive_a_checkpoint(tmp_path):
    """Constant loads on particles and block nodes are kept by a checkpoint: the
    loaded simulation continues exactly as the saved one."""
    sim = tdem.Simulation(gravity=(0.0, -9.81), local_damping=0.3)
    law = tdem.LinearContact(kn=1e6, friction=0.4)
    g = sim.add_particles([[0.1, 0.25], [0.15, 0.3]], 0.02, density=1000.0, contact=law)
    v, t = tdem.mesh.rectangle(0.3, 0.1, 4, 2)
    b = sim.add_block(v, t, material=tdem.Elastic(density=RHO, young=E, poisson=NU))
    b.fix(b.nodes_in(ymax=1e-9), vx=0.0, vy=0.0)
    b.apply_pressure(2e3, b.nodes_in(ymin=0.1 - 1e-9))
    sim.apply_force(g.ids, fx=[1.0, -2.0], moment=0.01)
    sim.couple(g, b, tdem.PointEdge(kn=1e6, ks=1e6, friction_angle=20.0))
    sim.run(steps=200)
    sim.save(tmp_path / "c.h5")
    other = tdem.Simulation.load(tmp_path / "c.h5")
    sim.run(steps=200)
    other.run(steps=200)
    np.testing.assert_array_equal(sim.particles.numpy()["position"],
                                  other.particles.numpy()["position"])
    np.testing.assert_array_equal(b.nodes()["position"], other._blocks[0].nodes()["position"])
    assert sim.work() == other.work()
    assert sim.work()["applied"] != 0.0


def test_block_loads_are_checked():
    sim = tdem.Simulation(gravity=(0.0, 0.0))
    v, t = tdem.mesh.rectangle(0.3, 0.1, 4, 2)
    b = sim.add_block(v, t, material=tdem.Elastic(density=RHO, young=E, poisson=NU))
    with pytest.raises(tdem.InputError, match="pressure must be"):
        b.apply_pressure("high", b.nodes_in(ymin=0.099))
    with pytest.raises(tdem.InputError, match="no boundary edge"):
        b.apply_pressure(1e3, b.nodes_in(ymin=0.099)[:1])
    with pytest.raises(tdem.InputError, match="fy must be"):
        b.apply_force([0, 1], fy=[1.0, 2.0, 3.0])
    with pytest.raises(tdem.InputError, match="nodes"):
        b.apply_force([len(v)], fx=1.0)


def test_pressure_given_as_a_function_of_time():
    """p(t) = 2e3·t on the top edge moves the block as the same nodal forces given as
    functions of time."""
    out = []
    for kind in ("pressure", "forces"):
        sim = tdem.Simulation(gravity=(0.0, 0.0), dt=1e-5)
        v, t = tdem.mesh.rectangle(0.3, 0.1, 3, 1)
        b = sim.add_block(v, t, material=tdem.Elastic(density=RHO, young=E, poisson=NU))
        b.fix(b.nodes_in(ymax=1e-9), vx=0.0, vy=0.0)
        top = np.sort(b.nodes_in(ymin=0.1 - 1e-9))
        if kind == "pressure":
            b.apply_pressure(lambda s: 2e3 * s, top)
        else:
            share = np.array([0.05, 0.1, 0.1, 0.05])[np.argsort(np.argsort(v[top, 0]))]
            b.apply_force(top, fy=lambda s: -2e3 * s * share)
        sim.run(steps=50)
        out.append(b.nodes()["position"])
    np.testing.assert_allclose(out[0], out[1], rtol=0, atol=1e-15)


def test_a_free_sphere_follows_its_applied_force_and_moment():
    """3D, no gravity, no contact: fz = c·t (a function of time), a constant fx and a
    constant moment vector M. The leapfrog gives ω = M t / I and v_x = F_x t / m
    exactly, z close to c t³/6m; the work of the loads is the kinetic energy gained."""
    sim = tdem.Simulation(dim=3, gravity=(0.0, 0.0, 0.0), dt=1e-3, progress=False)
    R = 0.1
    sim.add_particles([[0.0, 0.0, 0.0]], R, density=1000.0,
                      contact=tdem.HertzMindlin(young=1e7, poisson=0.3))
    m = 1000.0 * 4.0 / 3.0 * math.pi * R ** 3
    inertia = 0.4 * m * R ** 2
    c, fx, M = 50.0, 3.0, np.array([0.2, -0.5, 1.0])
    sim.apply_force([0], fx=fx, fz=lambda t: c * t, moment=M)
    sim.run(steps=1000)
    p = sim.particles.numpy()
    t = sim.time
    np.testing.assert_allclose(p["omega"][0], M * t / inertia, rtol=1e-12)
    assert p["velocity"][0, 0] == pytest.approx(fx * t / m, rel=1e-12)
    assert p["velocity"][0, 1] == 0.0
    assert p["position"][0, 2] == pytest.approx(c * t ** 3 / (6 * m), rel=5e-3)
    w = sim.work()
    assert w["applied"] == pytest.approx(w["kinetic_change"], rel=1e-12)
    assert w["applied"] > 0.0 and w["contacts"] == 0.0


def test_an_ellipsoid_spun_up_about_a_principal_axis():
    """A moment along the ellipsoid's shortest axis (body z, not turned): it spins up
    about that axis alone, ω = M t / I_c with I_c = m (a² + b²)/5, its angular
    momentum M t exactly, and the work of the moment is the kinetic energy gained."""
    a, b, cc = 0.03, 0.02, 0.01
    sim = tdem.Simulation(dim=3, gravity=(0.0, 0.0, 0.0), dt=1e-4, progress=False)
    sim.add_particles([[0.0, 0.0, 0.0]], shape=tdem.Ellipsoid(a, b, cc), density=2000.0,
                      contact=tdem.HertzMindlin(young=1e7, poisson=0.3))
    m = 2000.0 * 4.0 / 3.0 * math.pi * a * b * cc
    i_c = m * (a * a + b * b) / 5.0
    M = 1e-4
    sim.apply_force([0], moment=lambda t: [0.0, 0.0, M])
    sim.run(steps=2000)
    w = sim.particles.numpy()["omega"][0]
    assert w[2] == pytest.approx(M * sim.time / i_c, rel=1e-9)
    assert abs(w[0]) + abs(w[1]) < 1e-12 * abs(w[2])
    work = sim.work()
    assert work["applied"] == pytest.approx(work["kinetic_change"], rel=1e-9)
    assert work["applied"] == pytest.approx(0.5 * i_c * w[2] ** 2, rel=1e-3)


def test_3d_loads_add_up_and_are_checked():
    sim = tdem.Simulation(dim=3, gravity=(0.0, 0.0, 0.0), dt=1e-3, progress=False)
    sim.add_particles([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]], 0.1, density=1000.0,
                      contact=tdem.HertzMindlin(young=1e7, poisson=0.3))
    sim.apply_force([0, 1], fz=[1.0, 2.0], moment=[[0.0, 0.0, 1.0], [0.0, 0.0, 2.0]])
    sim.apply_force([1], fz=3.0, moment=(0.0, 0.0, 3.0))
    sim.run(steps=10)
    p = sim.particles.numpy()
    assert p["velocity"][1, 2] / p["velocity"][0, 2] == pytest.approx(5.0, rel=1e-12)
    assert p["omega"][1, 2] / p["omega"][0, 2] == pytest.approx(5.0, rel=1e-12)
    with pytest.raises(tdem.InputError, match="moment must be"):
        sim.apply_force([0], moment=(1.0, 2.0))
    with pytest.raises(tdem.InputError, match="moment must be"):
        sim.apply_force([0, 1], moment=[[0.0, 0.0, 1.0]] * 3)
    with pytest.raises(tdem.InputError, match="fz must be"):
        sim.apply_force([0], fz=[1.0, 2.0])
    # a function of time is tried at once on a built model, and a refused load is not kept
    with pytest.raises(tdem.InputError, match="moment as a function of time returned"):
        sim.apply_force([0], moment=lambda t: (1.0, 2.0))
    sim.run(steps=10)
    p = sim.particles.numpy()
    assert p["omega"][1, 2] / p["omega"][0, 2] == pytest.approx(5.0, rel=1e-12)
    fresh = tdem.Simulation(dim=3, gravity=(0.0, 0.0, 0.0), dt=1e-3, progress=False)
    fresh.add_particles([[0.0, 0.0, 0.0]], 0.1, density=1000.0,
                        contact=tdem.HertzMindlin(young=1e7, poisson=0.3))
    fresh.apply_force([0], fz=lambda t: [1.0, 2.0])
    with pytest.raises(tdem.InputError, match="fz as a function of time returned"):
        fresh.run(steps=1)


def test_3d_loads_survive_a_checkpoint(tmp_path):
    """Constant 3D forces and moments on spheres resting on a mesh floor are kept by a
    checkpoint: the loaded simulation continues exactly as the saved one."""
    sim = tdem.Simulation(dim=3, progress=False)
    hm = tdem.HertzMindlin(young=1e7, poisson=0.3, friction=0.4, restitution=0.5)
    sim.add_mesh(*tdem.surfaces.plane((0.0, 0.0, 0.0), (0.0, 0.0, 1.0), 0.5, 2), contact=hm)
    g = sim.add_particles([[0.0, 0.0, 0.021], [0.05, 0.0, 0.021]], 0.02, density=1000.0,
                          contact=hm)
    sim.apply_force(g.ids, fx=[0.05, -0.1], moment=(0.0, 1e-4, 0.0))
    sim.run(steps=200)
    sim.save(tmp_path / "c.h5")
    other = tdem.Simulation.load(tmp_path / "c.h5")
    sim.run(steps=200)
    other.run(steps=200)
    for k in ("position", "velocity", "omega"):
        np.testing.assert_array_equal(sim.particles.numpy()[k], other.particles.numpy()[k])
    assert sim.work() == other.work()
    assert sim.work()["applied"] != 0.0
