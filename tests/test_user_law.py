"""Contact laws written in a user's script: registered, used like the built-in ones.

- A re-implementation of the linear law (Cundall & Strack) in this file gives the
  built-in law's trajectories to round-off.
- A law with a history column of its own (Walton & Braun 1986: loading stiffness k1,
  unloading k2 from the largest overlap reached, so that e = sqrt(k1/k2)) gives its
  analytic restitution, and a checkpoint taken in the middle of a collision restarts
  exactly (its history column is saved and restored).
"""
import math

import numpy as np
import pytest
import taichi as ti

import tdem
from physics.contact_law import coulomb_shear, get_columns, put_columns, unregister_law


class MyLinear(tdem.ContactLaw):
    """The linear spring–dashpot law with Coulomb friction, written from scratch."""

    params = ("kn", "ks", "friction", "beta", "gamma")
    history = ("shear",)
    tangential = ("shear",)

    def __init__(self, kn, ks, friction, restitution, rolling=None):
        self.kn, self.ks, self.friction, self.restitution = kn, ks, friction, restitution
        le = math.log(1.0 / restitution)
        self.beta = 0.0
        self.gamma = 2.0 * le / math.sqrt(math.pi ** 2 + le ** 2)
        self.rolling = rolling

    def to_dict(self):
        d = {"type": "MyLinear", "kn": self.kn, "ks": self.ks, "friction": self.friction,
             "restitution": self.restitution}
        if self.rolling is not None:
            d["rolling"] = self.rolling.to_dict()
        return d

    def critical_stiffness(self, radius, mass):
        return max(self.kn, self.ks)

    @staticmethod
    @ti.func
    def force(q, u, vn, vt, meff, reff, dt, h):
        kn, ks, mu = q[0], q[1], q[2]
        fn_el = kn * u
        cn = q[3] * kn + q[4] * ti.sqrt(kn * meff)
        fn = fn_el - cn * vn
        fs_old = get_columns(h, 0, ti.static(vt.n))
        fs, fs_tot, diss = coulomb_shear(fs_old + ks * vt * dt, fn_el, mu, 0.0, ks,
                                         q[3] * ks, vt, dt, fs_old)
        diss += cn * vn * vn * dt
        h = put_columns(h, 0, fs)
        return fn_el, fn, fs_tot, kn, cn, diss, h

    @staticmethod
    @ti.func
    def energy(q, u, reff, h, T: ti.template()):
        e = 0.5 * q[0] * u * u
        if q[1] > 0.0:
            fs = get_columns(h, 0, T)
            e += 0.5 * fs.dot(fs) / q[1]
        return e

    @staticmethod
    @ti.func
    def stiffness(q, u, reff):
        return q[0]


class WaltonBraun(tdem.ContactLaw):
    """Hysteretic normal law: F = k1 u while loading, F = k2 (u − u0) while unloading
    from the largest overlap u_max (u0 = u_max (1 − k1/k2)); frictionless."""

    params = ("k1", "k2")
    history = ("shear", "max_overlap")     # frictionless: "shear" stays a scalar 0

    def __init__(self, k1, k2):
        self.k1, self.k2 = float(k1), float(k2)

    def critical_stiffness(self, radius, mass):
        return self.k2

    @staticmethod
    @ti.func
    def force(q, u, vn, vt, meff, reff, dt, h):
        k1, k2 = q[0], q[1]
        umax = h[1]
        diss = 0.0
        if u > umax:
            # recoverable energy 0.5 k2 (u − u0)² = 0.5 k1²/k2 u²: the rest is lost
            diss = 0.5 * k1 * (1.0 - k1 / k2) * (u * u - umax * umax)
            umax = u
        fn = ti.max(k2 * (u - umax * (1.0 - k1 / k2)), 0.0)
        kn = k2
        if u >= umax:
            kn = k1
        h[1] = umax
        return fn, fn, vt * 0.0, kn, 0.0, diss, h

    @staticmethod
    @ti.func
    def energy(q, u, reff, h, T: ti.template()):
        d = ti.max(u - h[1] * (1.0 - q[0] / q[1]), 0.0)
        return 0.5 * q[1] * d * d

    @staticmethod
    @ti.func
    def stiffness(q, u, reff):
        return q[1]


@pytest.fixture
def user_laws():
    tdem.register_law(MyLinear)
    tdem.register_law(WaltonBraun)
    yield
    unregister_law(WaltonBraun)
    unregister_law(MyLinear)


def _pile(law, n=80, seed=3):
    sim = tdem.Simulation(gravity=(0.0, -9.81), dt=2e-5)
    rng = np.random.default_rng(seed)
    side = int(np.ceil(np.sqrt(n)))
    xs = (np.arange(side) + 0.5) * 0.025
    pos = np.array([(x, y) for y in xs for x in xs])[:n] + rng.uniform(-2e-3, 2e-3, (n, 2))
    pos[:, 1] += 0.02
    sim.add_particles(pos, rng.uniform(0.009, 0.011, n), density=2500.0, contact=law,
                      velocity=rng.uniform(-0.3, 0.3, (n, 2)))
    w = side * 0.025
    sim.add_wall((0.0, 0.0), (w, 0.0), contact=law)
    sim.add_wall((w, 0.0), (w, 1.0), contact=law)
    sim.add_wall((0.0, 1.0), (0.0, 0.0), contact=law)
    return sim


def test_user_linear_law_gives_the_built_in_trajectories(user_laws):
    rolling = tdem.RollingResistance(delta=0.4, model=1)
    runs = []
    for law in (tdem.LinearContact(kn=1e5, ks=1e5, friction=0.5, restitution=0.5,
                                   rolling=rolling),
                MyLinear(kn=1e5, ks=1e5, friction=0.5, restitution=0.5, rolling=rolling)):
        sim = _pile(law)
        sim.run(steps=12000)
        p = sim.particles.numpy()
        runs.append((p, sim.energy(), [w.force for w in sim.walls], sim.contacts.numpy()))
    (a, ea, wa, ca), (b, eb, wb, cb) = runs
    assert len(ca["pairs"]) > 60 and np.count_nonzero(ca["moment"]) > 30
    for key in ("position", "velocity", "omega"):
        scale = np.abs(a[key]).max()
        assert np.abs(a[key] - b[key]).max() <= 1e-12 * scale, key
    for key in ("elastic", "kinetic", "dissipated"):
        assert eb[key] == pytest.approx(ea[key], rel=1e-10, abs=1e-15), key
    np.testing.assert_allclose(np.array(wb), np.array(wa), rtol=1e-9, atol=1e-12)


def _collide(law, v=0.5, r=0.1, rho=1000.0):
    sim = tdem.Simulation(gravity=(0.0, 0.0), dt_fraction=0.01)
    sim.add_particles([[0.0, 0.0], [2 * r + 0.01, 0.0]], r, density=rho, contact=law,
                      velocity=[[v, 0.0], [-v, 0.0]])
    return sim


def test_history_law_restitution_and_exact_restart(user_laws, tmp_path):
    k1, k2 = 1e6, 4e6
    law = WaltonBraun(k1, k2)
    sim = _collide(law)
    # into the collision: past the largest overlap, on the unloading branch
    t_contact = 0.01 / 1.0
    half = 0.5 * math.pi * math.sqrt((1000.0 * math.pi * 0.01 / 2) / k1)
    sim.run(until=t_contact + 1.2 * half)
    c = sim.contacts.numpy()
    assert len(c["pairs"]) == 1 and c["overlap"][0] > 0.0
    hist = sim._a["hist"].to_numpy()
    umax = hist[0, 0, 1]
    assert umax > c["overlap"][0] > 0.0           # the law's own column holds u_max
    sim.save(tmp_path / "mid.h5")
    sim.run(until=0.1)

    vel = sim.particles.numpy()["velocity"]
    e = (vel[1, 0] - vel[0, 0]) / (2 * 0.5)
    assert e == pytest.approx(math.sqrt(k1 / k2), rel=5e-3)
    assert abs(vel[:, 0].sum()) < 1e-12
    # energy: the kinetic energy lost is what the law booked as dissipated
    en = sim.energy()
    ke0 = 2 * 0.5 * (1000.0 * math.pi * 0.01) * 0.25
    assert en["kinetic"] == pytest.approx(ke0 * k1 / k2, rel=1e-2)
    assert en["dissipated"] == pytest.approx(ke0 * (1 - k1 / k2), rel=1e-2)

    sim2 = tdem.Simulation.load(tmp_path / "mid.h5")
    assert type(sim2._laws[0]) is WaltonBraun
    assert sim2._a["hist"].to_numpy()[0, 0, 1] == umax
    sim2.run(until=0.1)
    a, b = sim.particles.numpy(), sim2.particles.numpy()
    for key in ("position", "velocity", "omega"):
        assert np.array_equal(a[key], b[key]), key
    assert sim2.energy() == sim.energy()


def test_unregistered_law_is_refused_naming_the_argument():
    class Stray(MyLinear):
        pass
    with pytest.raises(tdem.InputError, match="contact.*Stray.*register_law"):
        _collide(Stray(1e5, 1e5, 0.5, 0.5))


def test_a_law_class_must_declare_its_columns():
    class NoHistory(tdem.ContactLaw):
        params = ("k",)
        history = ()
    with pytest.raises(tdem.InputError, match="history"):
        tdem.register_law(NoHistory)

    class BadParams(tdem.ContactLaw):
        params = "k"
        history = ("shear",)
    with pytest.raises(tdem.InputError, match="params"):
        tdem.register_law(BadParams)
