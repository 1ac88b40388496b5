"""The work account (``sim.work()``) and the integration-error line of ``sim.energy()``.

The leapfrog's m (v_{n+1/2} − v_{n−1/2}) = ΣF Δt makes Σ_n F_n·(v_{n−1/2} + v_{n+1/2})/2 Δt
exactly the change of ½ m v² at the half steps: the booked work of every force must
add up to the kinetic-energy change to round-off, damped or not, with walls,
prescribed velocities, PCMM bodies, JWL, blocks and couplings. The gap between the
contact forces' work and the energy their springs store is the integration error:
zero for a linear spring kept in contact (the leapfrog keeps a discrete energy
exactly), falling as Δt² for a Hertz contact.
"""
import math

import numpy as np
import pytest

import tdem
from tdem.continuum import _stored
from physics.materials import MAT_G, MAT_K, MAT_TYPE, MAT_WIDTH

G = 9.81


def _scale(w):
    return max(abs(w["kinetic_change"]), *(abs(w[k]) for k in
                                           ("contacts", "continuum", "gravity", "damping",
                                            "constraints")))


def _box_gas(local_damping=0.0, global_damping=0.0, seed=2):
    """150 discs of two laws (linear with a dashpot and friction, Hertz–Mindlin) in a
    box whose lid moves down; one disc driven at a prescribed velocity."""
    rng = np.random.default_rng(seed)
    sim = tdem.Simulation(gravity=(0.0, -G), local_damping=local_damping,
                          global_damping=global_damping)
    lin = tdem.LinearContact(kn=1e6, friction=0.5, restitution=0.6)
    hz = tdem.HertzMindlin(young=5e7, poisson=0.3, friction=0.3, restitution=0.8)
    xs, ys = np.meshgrid(0.03 + 0.025 * np.arange(15), 0.03 + 0.025 * np.arange(10))
    pos = np.column_stack([xs.ravel(), ys.ravel()]) + rng.uniform(-0.002, 0.002, (150, 2))
    vel = rng.normal(0.0, 0.5, (150, 2))
    a = sim.add_particles(pos[:75], 0.01, density=2000.0, contact=lin, velocity=vel[:75])
    sim.add_particles(pos[75:], rng.uniform(0.008, 0.011, 75), density=2000.0, contact=hz,
                      velocity=vel[75:])
    sim.fix_particles(a.ids[:1], vx=0.3, omega=2.0)
    w, h = 0.41, 0.3
    for p, q in (((0, 0), (w, 0)), ((w, 0), (w, h)), ((0, h), (0, 0))):
        sim.add_wall(p, q, contact=lin)
    lid = sim.add_wall((w, h), (0, h), contact=lin)
    lid.velocity = (0.0, -0.2)
    return sim


@pytest.mark.parametrize("local_damping,global_damping", [(0.0, 0.0), (0.3, 2.0)])
def test_kinetic_energy_change_equals_recorded_work(local_damping, global_damping):
    sim = _box_gas(local_damping, global_damping)
    sim.run(steps=3000)
    w = sim.work()
    assert w["contacts"] != 0.0 and w["gravity"] != 0.0 and w["constraints"] != 0.0
    assert abs(w["residual"]) < 1e-9 * _scale(w)
    assert w["total"] == pytest.approx(sum(w[k] for k in ("contacts", "continuum", "gravity",
                                                           "damping", "constraints")), rel=1e-12)
    if local_damping or global_damping:
        assert w["damping"] < -0.05 * abs(w["kinetic_change"] - w["damping"])
    else:
        assert w["damping"] == 0.0


def test_damping_work_is_the_dissipation_booked():
    """Frictionless, elastic contacts and damping: all that is dissipated is the
    damping's work."""
    sim = tdem.Simulation(gravity=(0.0, -G), local_damping=0.2, global_damping=1.0)
    law = tdem.LinearContact(kn=1e6, friction=0.0)
    rng = np.random.default_rng(4)
    xs, ys = np.meshgrid(0.03 + 0.025 * np.arange(10), 0.03 + 0.025 * np.arange(6))
    sim.add_particles(np.column_stack([xs.ravel(), ys.ravel()]), 0.01, density=2000.0,
                      contact=law, velocity=rng.normal(0.0, 0.5, (60, 2)))
    for p, q in (((0, 0), (0.3, 0)), ((0.3, 0), (0.3, 0.3)), ((0, 0.3), (0, 0))):
        sim.add_wall(p, q, contact=law)
    sim.run(steps=1)
    e0 = sim.energy()
    sim.run(steps=2000)
    w, e = sim.work(), sim.energy()
    assert e["dissipated"] == pytest.approx(-w["damping"], rel=1e-12)
    assert e["dissipated"] > 0.2 * e0["kinetic"]


def test_work_account_of_continua_blocks_and_couplings():
    """PCMM body, JWL charge, a fixed deformable block, a free rigid block and both
    couplings: the account still closes to round-off."""
    from test_state import _everything
    sim = _everything()
    sim.run(steps=300)
    w = sim.work()
    assert w["continuum"] != 0.0 and w["constraints"] != 0.0
    assert abs(w["residual"]) < 1e-9 * _scale(w)


def test_work_account_survives_a_checkpoint(tmp_path):
    sim = _box_gas(0.1, 0.0)
    sim.run(steps=500)
    sim.save(tmp_path / "c.h5")
    other = tdem.Simulation.load(tmp_path / "c.h5")
    sim.run(steps=300)
    other.run(steps=300)
    assert sim.work() == other.work()
    assert sim.energy()["integration_error"] == other.energy()["integration_error"]


def _resting_disc(law, dt_fraction, overlap, v0=(0.0, 0.0)):
    sim = tdem.Simulation(gravity=(0.0, -G), dt_fraction=dt_fraction)
    sim.add_particles([[0.0, 0.1 - overlap]], 0.1, density=1000.0, contact=law, velocity=[v0])
    sim.add_wall((-5.0, 0.0), (5.0, 0.0), contact=law)
    sim.monitor("err", lambda s: s.energy()["integration_error"], every=5)
    sim.monitor("elastic", lambda s: s.energy()["elastic"], every=5)
    sim.run(until=0.4)
    return sim.histories()


def test_linear_spring_in_contact_has_no_integration_error():
    """A disc pressed into the floor by gravity, released from 1.6 × its rest
    overlap: it oscillates on a linear spring without leaving the floor, and the
    leapfrog's discrete energy is exact, so the line is round-off."""
    k, m = 1e5, 1000.0 * math.pi * 0.01
    rest = m * G / k
    h = _resting_disc(tdem.LinearContact(kn=k, friction=0.0), 0.2, 1.6 * rest)
    _, el = h["elastic"]
    assert el.min() > 0.0                     # never leaves the floor
    _, err = h["err"]
    assert np.abs(err).max() < 1e-10 * el.max()


def test_integration_error_falls_as_dt_squared_for_hertz():
    """The same disc on a Hertz contact, thrown down and sideways (frictionless):
    the line's largest value falls by 4 (±10 %) at each halving of Δt."""
    law = tdem.HertzMindlin(young=1e7, poisson=0.3, friction=0.0)
    peaks = []
    for f in (0.1, 0.05, 0.025):
        h = _resting_disc(law, f, 0.0, v0=(0.3, -0.5))
        peaks.append(np.abs(h["err"][1]).max())
    ratios = np.array(peaks[:-1]) / np.array(peaks[1:])
    assert np.all(np.abs(ratios - 4.0) < 0.4), ratios


def test_strain_energy_of_a_uniaxial_stress():
    """p²/2K + s:s/4G of σ_xx alone is σ²/2E, E = 9KG/(3K + G); a Fluid row (G = 0)
    keeps the pressure part p²/2K; a JWL row counts nothing."""
    K, Gm, s = 2e9, 1e9, 3e6
    row = np.zeros((3, MAT_WIDTH))
    row[:, MAT_K] = K
    row[0, MAT_G] = Gm
    row[2, MAT_TYPE] = 3.0
    sig = np.zeros((3, 2, 2))
    sig[:, 0, 0] = s
    w = [_stored(sig[i:i + 1], np.zeros(1), row[i:i + 1], np.ones(1)) for i in range(3)]
    E = 9 * K * Gm / (3 * K + Gm)
    assert w[0] == pytest.approx(s * s / (2 * E), rel=1e-12)
    assert w[1] == pytest.approx((s / 3) ** 2 / (2 * K), rel=1e-12)
    assert w[2] == 0.0


def test_strain_energy_of_a_vibrating_block_matches_the_work_of_its_forces():
    """A cantilevered elastic block (fixed left edge) set moving: its kinetic energy
    goes into strain and back; the work of the nodal forces and the strain energy
    agree within 0.1 % of the largest strain energy at two time steps (what remains
    is the elements' geometric nonlinearity, not the time integration)."""
    for f in (0.2, 0.1):
        sim = tdem.Simulation(gravity=(0.0, 0.0), dt_fraction=f)
        v, t = tdem.mesh.rectangle(1.0, 0.1, 20, 2)
        b = sim.add_block(v, t, material=tdem.Elastic(density=2500.0, young=1e7, poisson=0.25),
                          velocity=(0.1, 0.05))
        b.fix(np.nonzero(v[:, 0] < 1e-9)[0], vx=0.0, vy=0.0)
        sim.monitor("e", lambda s: [s.energy()[k] for k in ("integration_error", "strain")],
                    every=5)
        sim.run(until=0.02)
        _, e = sim.histories()["e"]
        w = sim.work()
        assert e[:, 1].max() > 0.5 * 0.5 * 2500.0 * 0.1 * (0.1 ** 2 + 0.05 ** 2)
        assert np.abs(e[:, 0]).max() < 1e-3 * e[:, 1].max()
        assert abs(w["residual"]) < 1e-9 * _scale(w)


def test_initial_spin_counts_in_the_kinetic_energy():
    """A disc thrown spinning (omega=) onto a rough floor: its spin is read back, the
    start's kinetic energy holds ½ I ω², and friction turns spin into rolling; the
    account closes."""
    sim = tdem.Simulation(gravity=(0.0, -G))
    law = tdem.LinearContact(kn=1e5, friction=0.5)
    g = sim.add_particles([[0.0, 0.1]], 0.1, density=1000.0, contact=law, omega=20.0)
    sim.add_wall((-5.0, 0.0), (5.0, 0.0), contact=law)
    assert sim.particles.numpy()["omega"][g.ids[0]] == 20.0
    m = 1000.0 * math.pi * 0.01
    ke0 = 0.5 * (0.5 * m * 0.01) * 400.0
    sim.run(until=0.5)
    p = sim.particles.numpy()
    w = sim.work()
    assert w["kinetic_change"] == pytest.approx(
        0.5 * m * (p["velocity"][0] ** 2).sum() + 0.25 * m * 0.01 * p["omega"][0] ** 2 - ke0,
        rel=1e-12)
    assert p["velocity"][0, 0] < -0.1              # spin turned into motion (ω > 0: leftward)
    assert abs(w["residual"]) < 1e-9 * _scale(w)


def test_checkpoint_written_before_the_work_account_loads(tmp_path):
    """A version-2 file (no work columns): it loads, and the account starts there,
    closing to round-off."""
    import h5py
    sim = _box_gas(0.1, 0.0)
    sim.run(steps=300)
    sim.save(tmp_path / "c.h5")
    with h5py.File(tmp_path / "c.h5", "r+") as f:
        del f["state/ework"]
        f.attrs["version"] = 2
    other = tdem.Simulation.load(tmp_path / "c.h5")
    assert other.work()["kinetic_change"] == pytest.approx(0.0, abs=1e-12)
    other.run(steps=300)
    w = other.work()
    assert w["contacts"] != 0.0 and abs(w["residual"]) < 1e-9 * _scale(w)


@pytest.mark.parametrize("shape, damping", [("spheres", 0.0), ("cubes", 0.0),
                                            ("ellipsoids", 0.0), ("cubes", 5.0),
                                            ("ellipsoids", 5.0)])
def test_3d_kinetic_energy_change_equals_recorded_work(shape, damping):
    """3D beds in contact, falling onto a mesh floor (tests/small_models.py), with and
    without global damping: the work of contacts, gravity and damping adds up to the
    kinetic energy change, rotation included (½ ω·L for shaped bodies; the damping
    moment of an ellipsoid acts on its angular momentum). For spheres and cubes,
    whose spin is along their angular momentum, exactly (round-off); for the
    tumbling ellipsoids to the rotation splitting's error, which falls with the time
    step."""
    import small_models

    def residual(divide):
        sim = getattr(small_models, shape)()
        sim.global_damping = damping
        dt = sim.dt
        sim.dt = dt / divide
        sim.run(until=300 * dt)
        w = sim.work()
        assert abs(w["contacts"]) > 1e-3 and w["gravity"] != 0.0
        assert (w["damping"] < -0.1 * abs(w["contacts"])) == (damping > 0.0)
        return w["residual"] / abs(w["contacts"])

    r1 = residual(1)
    if shape != "ellipsoids":
        assert abs(r1) < 1e-12
    else:
        assert abs(r1) < 1e-4
        assert abs(residual(4)) < 0.5 * abs(r1)


def test_work_of_a_spin_held_on_an_ellipsoid():
    """An ellipsoid held at a constant spin about no principal axis: its angular
    momentum turns with it, and the constraint's work (the impulse on L, times ω) is
    the change of its kinetic energy ½ ω·L, to round-off."""
    sim = tdem.Simulation(dim=3, gravity=(0.0, 0.0, 0.0), dt=1e-4, progress=False)
    sim.add_particles([[0.0, 0.0, 0.0]], shape=tdem.Ellipsoid(0.03, 0.02, 0.01),
                      density=2000.0, contact=tdem.HertzMindlin(young=1e7, poisson=0.3))
    sim.fix_particles([0], vx=None, omega=(3.0, 1.0, 2.0))
    sim.run(steps=3000)
    w = sim.work()
    assert w["constraints"] > 1e-5
    assert abs(w["residual"]) < 1e-12 * w["constraints"]
