"""Particle and node indices taken from the user: boolean masks select their True
entries; floats, out-of-range indices and masks of the wrong length are refused,
naming the argument (a mask was cast to the indices 0 and 1; [2.9] was truncated to 2)."""
import numpy as np
import pytest

import tdem

LAW = tdem.LinearContact(kn=1e6)


def _row(n=6):
    sim = tdem.Simulation(gravity=(0.0, -9.81), dt=1e-4)
    pos = np.column_stack([np.arange(n) * 0.1, np.zeros(n)])
    sim.add_particles(pos, 0.02, density=1000.0, contact=LAW)
    return sim


def test_boolean_mask_fixes_exactly_its_true_particles():
    sim = _row()
    mask = np.array([False, False, False, True, False, True])
    sim.fix_particles(mask, vx=0.0, vy=0.0)
    sim.run(steps=100)
    y = sim.particles.numpy()["position"][:, 1]
    assert y[3] == 0.0 and y[5] == 0.0
    # the others fall freely: y = −g t²/2 at t = 0.01 s (leapfrog: within one step's drift)
    np.testing.assert_allclose(y[[0, 1, 2, 4]], -0.5 * 9.81 * 0.01 ** 2, rtol=0.02)


@pytest.mark.parametrize("ids, match", [
    ([2.9], r"ids must be integer particle indices.*2\.9"),
    (np.array([1.0, 2.0]), r"ids must be integer particle indices"),
    ([0, 6], r"ids must be particles of this model \(indices in \[0, 6\)\), got \[6\]"),
    ([-1], r"ids must be particles of this model \(indices in \[0, 6\)\), got \[-1\]"),
    (np.array([True, False]), r"ids: a boolean mask must have one entry per particle \(6\)"),
    ([], r"ids selects no particle"),
    ("0", r"ids must be integer particle indices"),
])
def test_bad_ids_are_refused_naming_the_argument(ids, match):
    sim = _row()
    with pytest.raises(tdem.InputError, match=match):
        sim.fix_particles(ids, vx=0.0)


def test_other_index_arguments_are_checked_the_same_way():
    sim = _row()
    v = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]) + [2.0, 0.0]
    t = np.array([[0, 1, 2], [0, 2, 3]])
    block = sim.add_block(v, t, material=tdem.Elastic(density=2500.0, young=1e8,
                                                      poisson=0.25))
    with pytest.raises(tdem.InputError, match=r"^a must be integer particle indices"):
        sim.couple([0.5], block, tdem.PointEdge(kn=1e6, ks=1e6))
    with pytest.raises(tdem.InputError, match=r"^target must be particles of this model"):
        sim.non_reflecting([7])
    with pytest.raises(tdem.InputError, match=r"^nodes must be integer vertex indices"):
        block.fix([1.5], vx=0.0)
    with pytest.raises(tdem.InputError, match=r"^nodes: a boolean mask must have one entry "
                                              r"per vertex \(4\)"):
        block.fix(np.array([True, False]), vx=0.0)
    block.fix(np.array([True, True, False, False]), vx=0.0, vy=0.0)   # a mask of 4 is fine
    assert [list(f[0]) for f in block._fixes] == [[0, 1]]
