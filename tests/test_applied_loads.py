"""Applied loads: forces and moments on particles (``sim.apply_force``), forces and
pressures on block nodes (``Block.apply_force``, ``Block.apply_pressure``), constant or
functions of time. Checked against motion under a known force and against the static
solutions of loaded columns (PHYSICS §4: nodes may carry an applied force)."""
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
