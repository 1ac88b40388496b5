"""The stable step of a dense packing (physics.stability) against the run itself.

C&S's critical step 2·sqrt(m/k) is that of one contact: a hexagonal pack run at it
goes unstable within a few steps. The hexagonal lattice's own limit, from its
dynamical matrix, is 0.204 of it with k_s = k_n (all discs spinning one way, each
shear spring stretched by both) and 0.289 with k_s = k_n/2; a pack run just below it
stays bounded, just above it grows. A run above it warns, naming the step to use."""
import math
import warnings

import numpy as np
import pytest

import tdem
from physics.stability import hex_lambda

R = 0.01


def _hex_pack(ks, rows=20, cols=20):
    law = tdem.LinearContact(kn=1e6, ks=ks * 1e6, friction=10.0)
    pos = np.array([(2 * R * i + (R if j % 2 else 0.0), j * math.sqrt(3) * R)
                    for j in range(rows) for i in range(cols)])
    sim = tdem.Simulation(gravity=(0.0, 0.0), dt_fraction=1.0, check_interval=50)
    rng = np.random.default_rng(1)
    sim.add_particles(pos, R * 1.001, density=2500.0, contact=law,
                      velocity=rng.normal(0.0, 1e-3, (len(pos), 2)))
    return sim


@pytest.mark.parametrize("ks, lam", [(0.0, 6.0), (0.5, 12.0), (1.0, 24.0)])
def test_hexagonal_lattice_eigenvalue(ks, lam):
    # translation alone: 6 k_n/m (the lattice's optical corner); with shear springs the
    # co-rotation mode, 2 k_s r² × 6 bonds / (m r²/2) = 24 k_s/m, takes over
    assert hex_lambda(ks) == pytest.approx(lam, rel=1e-9)


def test_critical_step_of_one_contact_is_unstable_in_a_hexagonal_pack():
    sim = _hex_pack(1.0)
    assert sim.stable_dt() / sim.critical_dt() == pytest.approx(1.0 / math.sqrt(24.0),
                                                                rel=1e-9)
    with pytest.warns(RuntimeWarning, match=r"stable step of a dense \(hexagonal\) packing.*"
                                            r"dt_fraction <= 0\.204"):
        with pytest.raises(tdem.InstabilityError):
            sim.run(steps=500)


def _run(ks, fraction):
    """(mechanical energy at the start, at the end, largest spin at the end) of the
    undamped pack run 1,500 steps at ``fraction`` of its stable step; the end is the
    last good step where the growth stops the run (InstabilityError: its contact
    forces would turn a disc by more than a radian in a step)."""
    sim = _hex_pack(ks)
    sim.dt = fraction * sim.stable_dt()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        sim.run(steps=1)
        e0 = sim.energy()
        try:
            sim.run(steps=1500)
        except tdem.InstabilityError as e:
            assert fraction > 1.0 and sim.steps == e.step - 1
    e1 = sim.energy()
    spin = np.abs(sim.particles.numpy()["omega"]).max()
    return e0["kinetic"] + e0["elastic"], e1["kinetic"] + e1["elastic"], spin


@pytest.mark.parametrize("ks, above", [(1.0, 1.3), (0.5, 1.2)])
def test_stable_step_is_the_limit_of_the_pack(ks, above):
    e0, e1, spin_below = _run(ks, 0.95)
    assert e1 == pytest.approx(e0, rel=0.05)     # below: undamped, the energy is kept
    f0, f1, spin_above = _run(ks, above)
    assert f1 > 10.0 * f0                         # above: the fastest mode grows
    assert spin_above > 10.0 * spin_below


def test_no_warning_at_the_default_fraction():
    sim = _hex_pack(1.0)
    sim.dt = None
    sim.dt_fraction = 0.2
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        sim.run(steps=20)
