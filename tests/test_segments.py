"""A run cut into segments gives the numbers of the uncut run, bit for bit.

The last step of every run (and of every ``check_interval`` segment) records what
output reads: contact normals and forces, and the gap of every listed pair of shaped
particles. That step must change nothing else: not the histories (an ellipsoid pair's
separating direction, kept as the next depth search's start) and not the round-off
(the step is one compiled kernel whichever it records; two variants of it, compiled
under fast math, rounded differently). Each model (tests/small_models.py) is run for
``STEPS`` steps at once, and again as 7 + the rest, and in segments of 5 steps."""
import numpy as np
import pytest

from small_models import cubes, ellipsoids, spheres, superellipses

STEPS = 120
KEYS = ("position", "velocity", "omega")


def _state(sim):
    s = sim.particles.numpy()
    return {k: s[k].copy() for k in KEYS}


@pytest.mark.parametrize("make", [ellipsoids, spheres, cubes, superellipses],
                         ids=["ellipsoids", "spheres", "cubes", "superellipses"])
def test_a_run_cut_into_segments_gives_the_same_numbers(make):
    whole = make()
    whole.run(steps=STEPS)
    ref = _state(whole)
    cut = make()
    cut.run(steps=7)
    cut.run(steps=STEPS - 7)
    short = make()
    short.check_interval = 5
    short.run(steps=STEPS)
    assert whole.steps == cut.steps == short.steps == STEPS
    moving = np.abs(ref["velocity"]).max()
    assert moving > 0.05           # (the models are still in motion)
    for sim in (cut, short):
        got = _state(sim)
        for k in KEYS:
            np.testing.assert_array_equal(got[k], ref[k], err_msg=k)
    n_contacts = len(whole.contacts.numpy()["pairs"])
    assert n_contacts > 10
