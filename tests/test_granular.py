"""tdem.Granular: contact laws composed of sub-models (physics.granular), the built-in
laws recomposed, and a sub-model of one's own run on discs, spheres and ellipsoids."""

import numpy as np
import pytest
import taichi as ti

import tdem

G = tdem.granular


@tdem.register_submodel
class Power(G.NormalModel):
    """A toy normal model written here: F_n = k u^p (k_n = p k u^(p−1))."""

    params = ("k", "p")

    def __init__(self, k, p):
        self.k, self.p = float(k), float(p)

    def critical_stiffness(self, radius, mass):
        return self.p * self.k * (0.05 * np.asarray(radius)) ** (self.p - 1.0)

    @staticmethod
    @ti.func
    def force(q, u, reff, s):
        f = q[0] * u ** q[1]
        return f, q[1] * f / u, s

    @staticmethod
    @ti.func
    def energy(q, u, reff, s):
        return q[0] * u ** (q[1] + 1.0) / (q[1] + 1.0)


def _pack2d(law, steps):
    x, r = tdem.pack.random(0.2, 0.2, 0.004, 0.006, seed=1)
    sim = tdem.Simulation(gravity=(0.0, -9.81), progress=False)
    sim.add_particles(x, r, density=2600.0, contact=law)
    for p0, p1 in (((-0.01, 0.0), (0.21, 0.0)), ((0.0, 0.3), (0.0, -0.01)),
                   ((0.2, -0.01), (0.2, 0.3))):
        sim.add_wall(p0, p1, contact=law)
    sim.run(steps=steps)
    return sim


def _pack3d(law, steps):
    x, r = tdem.pack.random3d((0, 0, 0), (0.04, 0.04, 0.04), 0.003, 0.004, seed=2)
    sim = tdem.Simulation(dim=3, gravity=(0.0, 0.0, -9.81), progress=False)
    sim.add_particles(x, r, density=2500.0, contact=law)
    v, t = tdem.surfaces.box((-0.005,) * 3, (0.045, 0.045, 0.06))
    sim.add_mesh(v, t, contact=law)
    sim.run(steps=steps)
    return sim


def _same(a, b, steps=20):
    """The two models step alike: the velocities agree to round-off (1e-12 of the
    largest; the kernels differ in form, and fast math rounds them apart in the last
    bits), the energies likewise."""
    sa, sb = a(steps), b(steps)
    assert sa.dt == sb.dt
    va, vb = sa.particles.numpy()["velocity"], sb.particles.numpy()["velocity"]
    assert np.abs(va).max() > 0.0
    assert np.abs(va - vb).max() <= 1e-12 * np.abs(va).max()
    assert sa.energy()["elastic"] == pytest.approx(sb.energy()["elastic"], rel=1e-10)
    assert sa.energy()["dissipated"] == pytest.approx(sb.energy()["dissipated"], rel=1e-10)


def test_hooke_ratio_linear_history_is_the_linear_law():
    roll = tdem.RollingResistance(delta=0.4, model=1)
    lin = tdem.LinearContact(kn=1e6, ks=5e5, friction=0.5, damping_ratio=2e-5, rolling=roll)
    gran = tdem.Granular(normal=G.Hooke(1e6), damping=G.Ratio(2e-5),
                         tangential=G.LinearHistory(5e5, friction=0.5), rolling=roll)
    _same(lambda n: _pack2d(lin, n), lambda n: _pack2d(gran, n))


def test_hertz_restitution_mindlin_is_the_hertz_mindlin_law():
    hm = tdem.HertzMindlin(young=1e8, poisson=0.3, friction=0.5, restitution=0.6)
    gran = tdem.Granular(normal=G.Hertz(1e8, 0.3), damping=G.Restitution(0.6),
                         tangential=G.Mindlin(1e8, 0.3, friction=0.5))
    _same(lambda n: _pack3d(hm, n), lambda n: _pack3d(gran, n))


def _resting(kind, law):
    """One particle resting on a floor of the same law under gravity (local damping):
    its overlap, and its weight."""
    dim = 2 if kind == "disc" else 3
    g = 9.81
    sim = tdem.Simulation(dim=dim, gravity=(0.0,) * (dim - 1) + (-g,), progress=False,
                          local_damping=0.7)
    if kind == "disc":
        r = 0.01
        sim.add_particles([[0.0, r]], r, density=2500.0, contact=law)
        sim.add_wall((-0.1, 0.0), (0.1, 0.0), contact=law)
        low = lambda p: p["position"][0, 1] - r                       # noqa: E731
    else:
        v, t = tdem.surfaces.plane((0.0, 0.0, 0.0), (0, 0, 1), 0.2)
        sim.add_mesh(v, t, contact=law)
        if kind == "sphere":
            r = 0.01
            sim.add_particles([[0.0, 0.0, r]], r, density=2500.0, contact=law)
            low = lambda p: p["position"][0, 2] - r                   # noqa: E731
        else:
            c = 0.006        # an ellipsoid lying on its shortest axis (z)
            sim.add_particles([[0.0, 0.0, c]], shape=tdem.Ellipsoid(0.012, 0.009, c),
                              density=2500.0, contact=law)
            low = lambda p: p["position"][0, 2] - c                   # noqa: E731
    sim.run(until=0.3)
    p = sim.particles.numpy()
    return -low(p), p["mass"][0] * g


@pytest.mark.parametrize("kind", ["disc", "sphere", "ellipsoid"])
def test_a_normal_model_of_ones_own_runs_on_discs_spheres_and_ellipsoids(kind):
    """The toy Power model (this file) with the built-in damping and tangential models:
    a particle at rest on a floor overlaps it by (m g/k)^(1/p) (to 1e-6)."""
    k, p = 5e7, 1.5
    law = tdem.Granular(normal=Power(k, p), damping=G.Restitution(0.3),
                        tangential=G.LinearHistory(1e5, friction=0.5))
    u, w = _resting(kind, law)
    assert u == pytest.approx((w / k) ** (1.0 / p), rel=1e-6)


def test_the_energy_account_closes_with_a_sub_model_of_ones_own():
    """Two spheres colliding head-on through the Power model, undamped: kinetic +
    elastic (the model's own energy) stays at the start's, to the leapfrog's error."""
    law = tdem.Granular(normal=Power(1e8, 1.5), tangential=G.LinearHistory(0.0))
    # (a step that resolves the contact, about 100 steps long: the default step is
    # set by the stiffness at an overlap of 5 % of the radius, far above this one's)
    sim = tdem.Simulation(dim=3, gravity=(0.0, 0.0, 0.0), progress=False,
                          local_damping=0.0, dt=2e-6)
    sim.add_particles([[0.0, 0.0, 0.0], [0.021, 0.0, 0.0]], 0.01, density=2500.0,
                      contact=law, velocity=[[0.5, 0.0, 0.0], [-0.5, 0.0, 0.0]])
    e0 = sim.energy()["kinetic"]
    peak = 0.0
    for _ in range(60):
        sim.run(steps=40)
        e = sim.energy()
        peak = max(peak, e["elastic"])
        assert abs(e["integration_error"]) < 5e-4 * e0       # (in contact: the leapfrog's)
    assert abs(e["integration_error"]) < 1e-5 * e0           # after it
    assert peak > 0.5 * e0           # they met: most of the energy went into the spring
    assert sim.particles.numpy()["velocity"][0, 0] == pytest.approx(-0.5, rel=2e-3)


def test_granular_models_restart_bit_for_bit(tmp_path):
    def model():
        law = tdem.Granular(normal=G.Hertz(1e7, 0.3), damping=G.Ratio(1e-6),
                            tangential=G.Mindlin(1e7, 0.3, friction=0.4),
                            rolling=tdem.RollingResistance(delta=0.3, model=2))
        sim = tdem.Simulation(dim=3, gravity=(0.0, 0.0, -9.81), progress=False)
        x, r = tdem.pack.random3d((0, 0, 0), (0.04, 0.04, 0.04), 0.003, 0.004, seed=3)
        sim.add_particles(x, r, density=2500.0, contact=law)
        v, t = tdem.surfaces.box((-0.002,) * 3, (0.042, 0.042, 0.06))
        sim.add_mesh(v, t, contact=law)
        return sim

    ref = model()
    ref.run(steps=300)
    path = tmp_path / "g.h5"
    ref.save(path)
    ref.run(steps=300)
    back = tdem.Simulation.load(path)
    law = back._laws[0]
    assert isinstance(law, tdem.Granular) and isinstance(law.normal, G.Hertz)
    assert law.tangential.friction == 0.4 and law.rolling.model == 2
    back.run(steps=300)
    np.testing.assert_array_equal(ref.particles.numpy()["position"],
                                  back.particles.numpy()["position"])


def test_bad_granular_input_is_named():
    with pytest.raises(tdem.InputError, match="normal must be"):
        tdem.Granular(normal=G.LinearHistory(1e5), tangential=G.LinearHistory(1e5))
    with pytest.raises(tdem.InputError, match="tangential must be"):
        tdem.Granular(normal=G.Hooke(1e5), tangential=0.5)
    with pytest.raises(tdem.InputError, match="restitution"):
        G.Restitution(1.5)
    with pytest.raises(tdem.InputError, match="poisson"):
        G.Hertz(1e8, 0.6)

    class Wide(G.DampingModel):
        params = ("a", "b", "c")

        @staticmethod
        def coefficients():
            pass

    with pytest.raises(tdem.InputError, match="at most 2"):
        tdem.register_submodel(Wide)
    used = G._USED[0]
    G._USED[0] = True
    try:
        class Late(G.DampingModel):
            params = ("a",)

            @staticmethod
            def coefficients():
                pass

        with pytest.raises(tdem.InputError, match="before the first simulation"):
            tdem.register_submodel(Late)
    finally:
        G._USED[0] = used


def test_the_laws_say_whether_they_stiffen_as_hertz():
    """The runner's check of a pressed bed's step (tests/test_energy.py) reads
    ``law.hertzian``: Hertz–Mindlin, a Granular law of Hertz normal, a wet Hertz law."""
    hm = tdem.HertzMindlin(young=1e8, poisson=0.3)
    assert hm.hertzian and not tdem.LinearContact(kn=1e5).hertzian
    assert tdem.Granular(normal=G.Hertz(1e8, 0.3), tangential=G.Mindlin(1e8, 0.3)).hertzian
    assert not tdem.Granular(normal=G.Hooke(1e5), tangential=G.LinearHistory(1e5)).hertzian
    assert tdem.WetContact(hm, tdem.LiquidBridge(volume=1e-12)).hertzian
