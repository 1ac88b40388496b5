"""The state schema (tdem.state): a model with every kind of state — DEM discs of two
laws with rolling resistance, fixed discs, walls (one moving), a PCMM body, JWL
explosive, a deformable block, a rigid block and both kinds of coupling — keeps every
declared array through a snapshot/restore and through a checkpoint, and continues
exactly after either."""
import numpy as np
import pytest

import tdem
from tdem import state as schema
from tdem.continuum import SAVED as CONTINUUM_SAVED


def _square(nx, ny, R, origin):
    xs = origin[0] + 2 * R * np.arange(nx)
    ys = origin[1] + 2 * R * np.arange(ny)
    X, Y = np.meshgrid(xs, ys)
    return np.column_stack([X.ravel(), Y.ravel()])


def _everything():
    sim = tdem.Simulation(gravity=(0.0, -9.81), dt_fraction=0.3)
    R = 0.01
    lin = tdem.LinearContact(kn=1e6, friction=0.5, restitution=0.5,
                             rolling=tdem.RollingResistance(delta=0.3, model=2))
    hertz = tdem.HertzMindlin(young=1e8, poisson=0.3, friction=0.4)
    # a PCMM elastic body on a floor, discs of two laws dropped onto it
    body = sim.add_particles(_square(10, 3, R, (0.01, 0.0105)), R,
                             material=tdem.Elastic(density=2500.0, young=5e6, poisson=0.25), tolerance=0.5 * R)
    sim.add_particles(_square(4, 1, R, (0.03, 0.08)), R, density=2500.0, contact=lin,
                      velocity=(0.0, -0.5))
    hz = sim.add_particles(_square(3, 1, R, (0.12, 0.08)), R, density=2500.0, contact=hertz,
                           velocity=(0.1, -0.5))
    sim.fix_particles(hz.ids[:1], vx=0.0, omega=1.0)
    sim.add_wall((0.0, 0.0), (0.3, 0.0), contact=lin)
    add_charge_and_blocks(sim, lin, R)
    return sim


def add_charge_and_blocks(sim, law, R):
    """The rest of the model of every kind: a moving side wall, an explosive patch far
    from the rest detonated at once, a fixed deformable base block with a rigid block
    on it (vertex–edge coupling) and a disc of ``law`` on the base (particle–edge)."""
    side = sim.add_wall((0.0, 0.0), (0.0, 0.3), contact=law)
    side.velocity = (0.01, 0.0)
    tnt = sim.add_particles(_square(3, 3, 0.0025, (1.0, 1.0)), 0.0025, material=tdem.JWL.tnt(),
                            tolerance=0.0025)
    sim.detonate(tnt, (1.0, 1.0))
    vb, tb = tdem.mesh.rectangle(0.4, 0.05, 8, 1, origin=(0.5, -0.05))
    base = sim.add_block(vb, tb, material=tdem.Elastic(density=2500.0, young=1e8, poisson=0.25))
    base.fix(np.arange(len(vb)), vx=0.0, vy=0.0)
    vt, tt = tdem.mesh.rectangle(0.05, 0.05, 1, 1, origin=(0.55, -0.0001))
    top = sim.add_block(vt, tt, material=tdem.Elastic(density=2500.0, young=1e8, poisson=0.25), rigid=True,
                        velocity=(0.2, 0.0))
    sim.couple(top, base, tdem.PointEdge(friction_angle=25.0))
    disc = sim.add_particles([[0.75, 0.0099]], R, density=2500.0, contact=law,
                             velocity=(-0.1, -0.2))
    sim.couple(disc, base, tdem.PointEdge(kn=1e6, ks=1e6, friction_angle=20.0))


def _arrays(sim):
    """Every array the schemas declare as saved: the engine's and the continuum's."""
    out = {k: sim._a[k].to_numpy() for k in schema.saved()}
    sim._cont.sync_copies()
    out.update({"continuum." + k: v.to_numpy() for k, v in sim._cont.a.items()
                if k in CONTINUUM_SAVED})
    return out


def _assert_same(a, b, skip=()):
    assert a.keys() == b.keys()
    for k in a:
        if k not in skip:
            np.testing.assert_array_equal(a[k], b[k], err_msg=k)


@pytest.fixture(scope="module")
def model():
    sim = _everything()
    sim.run(steps=300)
    return sim


def test_the_model_has_every_kind_of_state(model):
    a = _arrays(model)
    c = model.contacts.numpy()
    assert model.n_particles == 30 + 4 + 3 + 9 + 1
    assert (c["pairs"][:, 1] >= 0).any() and (c["pairs"][:, 1] < 0).any()  # pairs and walls
    assert np.abs(a["hist"]).max() > 0 and np.abs(a["whist"]).max() > 0
    assert np.abs(a["continuum.pjwl"]).max() > 0           # the charge is burning
    assert np.abs(a["continuum.esig"]).max() > 0           # element stresses
    assert np.abs(a["continuum.psforce"]).max() > 0 or np.abs(a["continuum.vsforce"]).max() > 0
    assert np.abs(a["continuum.rstate"]).max() > 0         # the rigid block's state
    # no declared array is missing from the device state
    assert set(schema.saved()) <= set(model._a)


def test_snapshot_restores_every_dynamic_array(model):
    model._take_snapshot()
    before = _arrays(model)
    clock = (model.time, model.steps)
    model.run(steps=50)
    moved = _arrays(model)
    assert not np.array_equal(moved["pos"], before["pos"])
    model._restore_snapshot()
    after = _arrays(model)
    assert (model.time, model.steps) == clock
    # setup arrays are not in the snapshot (unchanged during a run) and the grid may be
    # refitted between segments; everything else comes back bit for bit
    _assert_same(before, after, skip=("gridp", "gridn"))
    model.run(steps=50)
    _assert_same(_work_counts_out(moved), _work_counts_out(_arrays(model)),
                 skip=("gridp", "gridn"))


def _work_counts_out(arrays):
    """The arrays without the element system's counts of the work its last step did
    (particles rebuilt, N_e recounted): a restore rebuilds and recounts everything,
    after which the lazy rebuild's budgets start afresh, so later steps can do the
    same work in a different order (the swelling charge rebuilds at every step)."""
    from physics.pcmm import P_REBUILT, P_RECOUNT
    out = dict(arrays)
    flags = out["continuum.pflags"].copy()
    flags[[P_REBUILT, P_RECOUNT]] = 0
    out["continuum.pflags"] = flags
    return out


def test_checkpoint_keeps_every_declared_array_and_continues_exactly(model, tmp_path):
    model.save(tmp_path / "all.h5")
    other = tdem.Simulation.load(tmp_path / "all.h5")
    other._require_built()
    # (copies are known after a step: the running model's say which slots count)
    _assert_same(_meaningful(_arrays(model), model), _meaningful(_arrays(other), model))
    model.run(steps=100)
    other.run(steps=100)
    # after the same steps every array is the same, scratch ones included (an array
    # the checkpoint forgot would show here), and so is what the user reads
    a, b = (_meaningful(_work_counts_out(_all_arrays(model)), model),
            _meaningful(_work_counts_out(_all_arrays(other)), model))
    # wall loads are atomic sums (their order varies between runs on several threads).
    # cskip (scratch: pairs the PCMM elements carry) differs for the explosive's
    # particles, whose elements change as they swell: the running model keeps their
    # old marks, the loaded one rebuilt them; no force differs (every other array,
    # positions included, is the same)
    _assert_same(a, b, skip=("wforce", "cskip"))
    np.testing.assert_allclose(a["wforce"], b["wforce"], rtol=1e-9, atol=1e-12)
    diff = np.argwhere(a["cskip"] != b["cskip"])
    assert set(diff[:, 0]) <= set(range(37, 46))          # the charge's particles
    assert model.energy() == other.energy()
    for key, v in model.particles.numpy().items():
        np.testing.assert_array_equal(v, other.particles.numpy()[key], err_msg=key)


def _meaningful(arrays, sim):
    """N_e only where it is kept: in the slots of a particle's elements (below its
    count) whose stress it computes (``emult`` > 0); a copy's slot keeps whatever it
    held (the running model) or the recount wrote (a loaded one, which recounts
    everything)."""
    a = sim._cont.a
    ecnt, emult = a["ecnt"].to_numpy(), a["emult"].to_numpy()
    kept = (np.arange(emult.shape[1])[None, :] < ecnt[:, None]) & (emult > 0)
    out = dict(arrays)
    out["continuum.ncov"] = np.where(kept, out["continuum.ncov"], -1)
    return out


def _all_arrays(sim):
    sim._cont.sync_copies()
    out = {k: v.to_numpy() for k, v in sim._a.items() if k in schema.BY_NAME}
    # the continuum's derived element data (area, cover) of a loaded model is filled
    # at its next rebuild: its saved arrays only
    out.update({"continuum." + k: v.to_numpy() for k, v in sim._cont.a.items()
                if k in CONTINUUM_SAVED})
    return out


def test_history_columns_follow_the_registered_laws():
    from physics import contact_law as cl
    # the laws registered at import (tdem.WetContact and tdem.Granular, with wider
    # histories, register when first made)
    laws = tuple(c for c in cl.registered() if c.__module__ in
                 ("physics.linear", "physics.hertz_mindlin", "physics.volume_contact"))
    assert len(laws) == 3
    assert cl.history_width(laws) == 1 and cl.pair_history_width(laws) == 7
    assert cl.wall_history_width(laws) == 5      # law, rolling (3), shape state
    h = np.arange(10.0).reshape(2, 5)
    wide = cl.remap_history(h, 7, tail=4)
    np.testing.assert_array_equal(wide[:, 0], h[:, 0])
    np.testing.assert_array_equal(wide[:, 1:3], 0.0)
    np.testing.assert_array_equal(wide[:, 3:], h[:, 1:])
    np.testing.assert_array_equal(cl.remap_history(wide, 5, tail=4), h)
    old = cl.remap_history(np.ones((2, 4)), 5, tail=4)      # written before u0 existed
    np.testing.assert_array_equal(old, [[1, 1, 1, 1, 0]] * 2)
