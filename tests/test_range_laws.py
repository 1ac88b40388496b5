"""Contact laws with a range (physics.contact_law): a user law that pulls across a gap,
and the built-in wet contact (physics.wet_contact: a dry law with a liquid bridge formed
at contact, Willett's force, Lian's rupture distance)."""
import math

import numpy as np
import pytest
import taichi as ti

import tdem
from physics.contact_law import unregister_law
from physics.liquid_bridge import potential

R = 1e-3
RHO = 2500.0


def _mass(dim):
    return RHO * (4.0 / 3.0 * math.pi * R ** 3 if dim == 3 else math.pi * R * R)


@pytest.fixture
def sticky():
    """A toy law of one's own: a linear spring in contact and a constant pull ``ka``
    across gaps below ``reach`` (its range); potential ka·(gap − reach) below it."""

    @tdem.register_law
    class Sticky(tdem.ContactLaw):
        params = ("kn", "ka", "reach")
        history = ("shear",)
        tangential = ("shear",)
        range = "reach"

        def __init__(self, kn, ka, reach):
            self.kn, self.ka, self.reach = float(kn), float(ka), float(reach)

        def critical_stiffness(self, radius, mass):
            return self.kn

        @staticmethod
        @ti.func
        def force(q, u, vn, vt, meff, reff, dt, h):
            fel = q[0] * ti.max(u, 0.0) - q[1]
            return fel, fel, vt * 0.0, q[0], 0.0, 0.0, h

        @staticmethod
        @ti.func
        def energy(q, u, reff, h, T: ti.template()):
            return 0.5 * q[0] * ti.max(u, 0.0) ** 2 - q[1] * (q[2] + u)

        @staticmethod
        @ti.func
        def stiffness(q, u, reff):
            return q[0]

    yield Sticky
    unregister_law(Sticky)


def _pair(dim, law, gap, dt=1e-6, fixed=True):
    sim = tdem.Simulation(gravity=(0.0,) * dim, progress=False, dt=dt, dim=dim,
                          local_damping=0.0)
    x = [[0.0] * dim, [2 * R + gap] + [0.0] * (dim - 1)]
    sim.add_particles(x, R, density=RHO, contact=law)
    if fixed:
        if dim == 2:
            sim.fix_particles([0], vx=0.0, vy=0.0, omega=0.0)
        else:
            sim.fix_particles([0], vx=0.0, vy=0.0, vz=0.0, omega=(0.0, 0.0, 0.0))
    return sim


def _move(sim, dim, v):
    if dim == 2:
        sim.fix_particles([1], vx=v, vy=0.0, omega=0.0)
    else:
        sim.fix_particles([1], vx=v, vy=0.0, vz=0.0, omega=(0.0, 0.0, 0.0))


@pytest.mark.parametrize("dim", [2, 3])
def test_a_user_law_with_a_range_pulls_across_a_gap_and_not_beyond(sticky, dim):
    """The range (2R, five times the default skin of 0.4R) is reached: at 1.5R apart
    the free particle is pulled at ka/m from the first step; at 2.5R nothing acts."""
    ka = 1e-3
    law = sticky(kn=1e4, ka=ka, reach=2 * R)
    near = _pair(dim, law, 1.5 * R)
    near.run(steps=1)
    v = near.particles.numpy()["velocity"][1, 0]
    assert v == pytest.approx(-ka / _mass(dim) * near.dt, rel=1e-12)
    c = near.contacts.numpy()
    assert len(c["pairs"]) == 1 and c["normal"][0] == pytest.approx(-ka, rel=1e-12)
    assert c["overlap"][0] == pytest.approx(-1.5 * R, rel=1e-9)
    far = _pair(dim, law, 2.5 * R)
    far.run(steps=5)
    assert far.particles.numpy()["velocity"][1, 0] == 0.0
    assert len(far.contacts.numpy()["pairs"]) == 0


@pytest.mark.parametrize("dim", [2, 3])
def test_an_approaching_particle_is_caught_when_it_enters_the_range(sticky, dim):
    """A particle coming from 6R away at 0.5 m/s (the lists rebuilt on the way) feels the
    pull from the first step that starts inside the range, not before."""
    law = sticky(kn=1e4, ka=1e-3, reach=2 * R)
    sim = _pair(dim, law, 6 * R, dt=1e-5)
    _move(sim, dim, -0.5)
    dt = sim.dt
    # x at the start of step n is 6R − 0.5 (n − 1) dt; inside the range once below 2R
    want = math.floor(4 * R / (0.5 * dt) + 1e-9) + 1
    sim.run(steps=want - 6)
    assert len(sim.contacts.numpy()["pairs"]) == 0
    first = None
    for n in range(want - 5, want + 5):
        sim.run(steps=1)
        if sim.contacts.numpy()["pairs"].shape[0]:
            first = n
            break
    assert first is not None and abs(first - want) <= 1


@pytest.mark.parametrize("dim", [2, 3])
def test_the_energy_account_closes_with_a_law_acting_across_a_gap(sticky, dim):
    """Two free particles pulled together from 0.9 of the range, bouncing on the spring
    and parting again (nothing dissipates): kinetic + elastic stays at its start,
    −ka·0.1·reach, to the leapfrog's error."""
    m = _mass(dim)
    ka, reach = 100.0 * m, 2 * R            # a pull of 100 m/s² on each
    law = sticky(kn=1e8 * m, ka=ka, reach=reach)
    sim = _pair(dim, law, 0.9 * reach, dt=2e-6, fixed=False)
    sim.run(steps=1)
    e0 = sim.energy()
    assert e0["elastic"] == pytest.approx(-ka * 0.1 * reach, rel=1e-3)
    most = 0.0
    for _ in range(10):
        sim.run(steps=1000)
        e = sim.energy()
        most = max(most, e["kinetic"])
        assert abs(e["integration_error"]) < 2e-3 * ka * 0.1 * reach
    # they met: at contact the kinetic energy is 0.9 ka·reach
    assert most > 0.5 * ka * reach


def test_a_range_must_name_a_parameter():
    class Bad(tdem.ContactLaw):
        params = ("kn",)
        history = ("shear",)
        tangential = ("shear",)
        range = "reach"

        @staticmethod
        def force():
            pass

        energy = stiffness = force

    with pytest.raises(tdem.InputError, match="range must name one of its params"):
        tdem.register_law(Bad)


def _wet(dry=None, volume=2e-12, angle=20.0):
    lb = tdem.LiquidBridge(volume=volume, surface_tension=0.072, contact_angle=angle)
    return tdem.WetContact(dry or tdem.LinearContact(kn=1e4), lb), lb


@pytest.mark.parametrize("dim", [2, 3])
def test_a_bridge_forms_at_contact_pulls_as_willett_and_ruptures_at_lians_distance(dim):
    """Brought within range the two do not attract (no bridge before the films meet);
    once they have touched and are pulled apart at 0.02 m/s the force is Willett's F(s)
    at every gap (to 1e-9; in 2D per metre F/(4R*) = F/(2R)), and the bridge ruptures
    at the first step that starts beyond Lian's (1 + θ/2)V^(1/3)."""
    law, lb = _wet()
    s_rup = lb.rupture_distance
    assert law.acting_range() == pytest.approx((1 + 0.5 * math.radians(20.0)) * 2e-12 ** (1 / 3))
    sim = _pair(dim, law, 0.5 * s_rup)
    _move(sim, dim, -0.02)
    sim.run(steps=100)
    assert len(sim.contacts.numpy()["pairs"]) == 0
    assert np.abs(sim.particles.numpy()["force"]).max() == 0.0
    v, dt = 0.02, sim.dt
    sim.run(steps=int(0.5 * s_rup / (v * dt)))        # into contact
    assert sim.contacts.numpy()["overlap"][0] > 0.0
    _move(sim, dim, v)
    per = 1.0 if dim == 3 else 1.0 / (2 * R)
    seen = 0
    chunk = 500
    while True:
        x_start = sim.particles.numpy()["position"][1, 0] - v * dt     # x_n of the last step
        if x_start - 2 * R + (chunk + 3) * v * dt > s_rup:
            break
        sim.run(steps=chunk)
        gap = sim.particles.numpy()["position"][1, 0] - 2 * R - v * dt
        if gap > 0.0:
            c = sim.contacts.numpy()
            assert c["normal"][0] == pytest.approx(-lb.bridge_force(gap, R, R) * per,
                                                   rel=1e-9)
            seen += 1
    assert seen >= 5
    # step to the rupture: the force stays until a step starts with the gap beyond s_rup
    while len(sim.contacts.numpy()["pairs"]):
        sim.run(steps=1)
    x_start = sim.particles.numpy()["position"][1, 0] - v * dt
    assert x_start - 2 * R > s_rup
    assert x_start - 2 * R == pytest.approx(s_rup, abs=1.01 * v * dt)
    assert np.abs(sim.particles.numpy()["force"]).max() == 0.0


def test_a_bridge_makes_and_breaks_with_the_energy_account_closed():
    """Touch, pull apart, rupture: the bridge's forming books U at that step as
    dissipated, its potential −U(s) is in ``elastic``, and the account closes to 1e-3 of
    U(0) (the leapfrog's Riemann sum)."""
    law, lb = _wet()
    sim = _pair(3, law, -1e-7)          # touching: the bridge forms at the first step
    _move(sim, 3, 0.02)
    sim.run(steps=1)
    e0 = sim.energy()
    f0 = 2 * math.pi * R * 0.072 * math.cos(math.radians(20.0))
    k = 0.5 * math.sqrt(R / 2e-12)
    # formed at the first step's overlap of 1e-7 m: U(−1e-7) = U(0) + F₀·1e-7
    u0 = float(potential(-1e-7, f0, k, lb.rupture_distance))
    assert e0["dissipated"] == pytest.approx(u0, rel=1e-12)
    sim.run(steps=int(lb.rupture_distance / (0.02 * sim.dt)) + 100)
    e = sim.energy()
    assert e["elastic"] == 0.0 and len(sim.contacts.numpy()["pairs"]) == 0
    assert abs(e["integration_error"]) < 1e-3 * u0


@pytest.mark.parametrize("dim", [2, 3])
def test_a_bridge_holds_a_sphere_that_weighs_less_than_its_pull(dim):
    """A sphere hung under a fixed one and wetted by touching it stays pressed against
    it while its weight m g is below the bridge's F₀ = 2πRγ cos θ (Willett's F falls
    with the gap, so no gap is stable): the overlap is (F₀ − m g)/k_n (to 1e-6). One
    heavier than F₀ falls off beyond the rupture distance."""
    lb = tdem.LiquidBridge(volume=1e-11, surface_tension=0.072, contact_angle=0.0)
    kn = 1e3
    law = tdem.WetContact(tdem.LinearContact(kn=kn, restitution=0.3), lb)
    f0 = 2 * math.pi * R * 0.072 * (1.0 if dim == 3 else 1.0 / (2 * R))
    outcome = {}
    for rho in (RHO, 1e5):
        m = rho * (4.0 / 3.0 * math.pi * R ** 3 if dim == 3 else math.pi * R * R)
        g = 9.81
        sim = tdem.Simulation(gravity=(0.0,) * (dim - 1) + (-g,), progress=False, dim=dim,
                              local_damping=0.7, dt=2e-5)
        x = np.zeros((2, dim))
        x[1, -1] = -2 * R + 1e-8
        sim.add_particles(x, R, density=rho, contact=law)
        if dim == 2:
            sim.fix_particles([0], vx=0.0, vy=0.0, omega=0.0)
        else:
            sim.fix_particles([0], vx=0.0, vy=0.0, vz=0.0, omega=(0.0, 0.0, 0.0))
        sim.run(until=0.15)
        gap = -sim.particles.numpy()["position"][1, -1] - 2 * R
        outcome[rho] = (m * g, gap)
    w, gap = outcome[RHO]
    assert w < f0
    assert -gap == pytest.approx((f0 - w) / kn, rel=1e-6)
    w, gap = outcome[1e5]
    assert w > f0 and gap > lb.rupture_distance


def test_wet_contacts_restart_bit_for_bit(tmp_path):
    """A checkpoint keeps the wet law (its dry law and bridge) and the contacts' bridges."""
    def model():
        law, _ = _wet(tdem.HertzMindlin(young=1e7, poisson=0.3, restitution=0.5))
        sim = tdem.Simulation(dim=3, gravity=(0.0, 0.0, -9.81), progress=False,
                              local_damping=0.0)
        z = math.sqrt((2 * R - 1e-8) ** 2 - (0.3 * R) ** 2)     # touching: wetted
        x = np.array([[0.0, 0.0, 0.0], [0.3 * R, 0.0, -z], [3 * R, 0.0, 0.0]])
        sim.add_particles(x, R, density=RHO, contact=law)
        sim.fix_particles([0, 2], vx=0.0, vy=0.0, vz=0.0, omega=(0.0, 0.0, 0.0))
        return sim

    ref = model()
    ref.run(steps=2000)
    path = tmp_path / "w.h5"
    ref.save(path)
    ref.run(steps=3000)
    back = tdem.Simulation.load(path)
    assert isinstance(back._laws[0], tdem.WetContact)
    assert back._laws[0].bridge.volume == 2e-12
    back.run(steps=3000)
    np.testing.assert_array_equal(ref.particles.numpy()["position"],
                                  back.particles.numpy()["position"])
    assert ref.energy()["dissipated"] == back.energy()["dissipated"]


def test_bad_wet_input_is_named():
    lb = tdem.LiquidBridge(volume=1e-12)
    with pytest.raises(tdem.InputError, match="dry must be"):
        tdem.WetContact(tdem.VolumeContact(young=1e8), lb)
    with pytest.raises(tdem.InputError, match="bridge must be"):
        tdem.WetContact(tdem.LinearContact(kn=1e4), 0.5)
    sim = tdem.Simulation(dim=3, gravity=(0.0, 0.0, 0.0), progress=False)
    sim.add_particles([[0.0, 0.0, 0.0]], shape=tdem.Ellipsoid(2e-3, 1e-3, 1e-3),
                      density=RHO, contact=tdem.WetContact(tdem.LinearContact(kn=1e4), lb))
    with pytest.raises(tdem.InputError, match="acts across a gap"):
        sim.run(steps=1)
    law = tdem.WetContact(tdem.LinearContact(kn=1e4), lb)
    law.update(volume=8e-12, friction=0.3)
    assert law.bridge.volume == 8e-12 and law.dry.friction == 0.3
    assert law.acting_range() == pytest.approx(2e-4)


@pytest.mark.parametrize("dim", [2, 3])
def test_a_bridge_to_a_wall_holds_across_the_gap_to_its_rupture(dim):
    """A sphere wetted by touching a floor (a segment wall in 2D, a mesh in 3D) of the
    wet law, lifted at 0.02 m/s: the pull is Willett's for a sphere and a plane, R =
    2R* = 2R_i (F₀ = 4πR_iγ cos θ; in 2D per metre of a layer 4R* = 4R_i thick), at
    every gap to 1e-9, until the gap passes Lian's distance."""
    law, lb = _wet()
    sim = tdem.Simulation(gravity=(0.0,) * dim, progress=False, dt=1e-6, dim=dim,
                          local_damping=0.0)
    x = np.zeros((1, dim))
    x[0, -1] = R - 1e-8
    sim.add_particles(x, R, density=RHO, contact=law)
    if dim == 2:
        sim.add_wall((-0.01, 0.0), (0.01, 0.0), contact=law)
        sim.fix_particles([0], vx=0.0, vy=0.02, omega=0.0)
    else:
        v, t = tdem.surfaces.plane((0.0, 0.0, 0.0), (0, 0, 1), 0.01)
        sim.add_mesh(v, t, contact=law)
        sim.fix_particles([0], vx=0.0, vy=0.0, vz=0.02, omega=(0.0, 0.0, 0.0))
    v, dt, s_rup = 0.02, sim.dt, lb.rupture_distance
    f0 = 4 * math.pi * R * 0.072 * math.cos(math.radians(20.0))
    k = 0.5 * math.sqrt(2 * R / 2e-12)
    per = 1.0 if dim == 3 else 1.0 / (4 * R)
    seen = 0
    for _ in range(7):
        sim.run(steps=1000)
        gap = sim.particles.numpy()["position"][0, -1] - R - v * dt       # at x_n
        c = sim.contacts.numpy()
        assert c["pairs"][0, 1] == -1
        x_ = k * gap
        assert c["normal"][0] == pytest.approx(-per * f0 / (1 + 2.1 * x_ + 10 * x_ * x_),
                                               rel=1e-9)
        seen += 1
    sim.run(steps=int(s_rup / (v * dt)) - 7000 + 5)
    assert len(sim.contacts.numpy()["pairs"]) == 0
    assert np.abs(sim.particles.numpy()["force"]).max() == 0.0


def test_a_range_changed_between_runs_takes_effect(sticky):
    """law.update(reach=...) after a run: the lists and the step follow the new range."""
    law = sticky(kn=1e4, ka=1e-3, reach=R)
    sim = _pair(3, law, 1.5 * R)
    sim.run(steps=2)
    assert sim.particles.numpy()["velocity"][1, 0] == 0.0
    law.update(reach=2 * R)
    sim.run(steps=1)
    assert sim.particles.numpy()["velocity"][1, 0] == pytest.approx(
        -1e-3 / _mass(3) * sim.dt, rel=1e-12)
