"""Where the PCMM element records go (physics.pcmm.record_slots): one run per
particle, in particle order, so that neighbouring particles' records lie side by
side in memory."""
import numpy as np
import pytest

import tdem  # noqa: F401  (tdem first: it imports physics in its order)
from tdem import backend
from physics import pcmm


@pytest.mark.parametrize("n", [1, 7, pcmm.SCAN_BLOCK - 1, pcmm.SCAN_BLOCK,
                               pcmm.SCAN_BLOCK + 1, 5 * pcmm.SCAN_BLOCK + 17])
@pytest.mark.parametrize("serial", [False, True])
def test_record_runs_are_the_prefix_sum_of_computed_elements(n, serial):
    import taichi as ti
    backend.init()
    E = pcmm.MAX_ELEMENTS
    rng = np.random.default_rng(n)
    ecnt = rng.integers(0, E + 1, n).astype(np.int32)
    emult = rng.integers(0, 3, (n, E)).astype(np.int32)     # 0: a copy, not computed
    arrays = {"ecnt": (n,), "emult": (n, E), "ebase": (n,),
              "eoff": (n // pcmm.SCAN_BLOCK + 2,)}
    a = {k: ti.ndarray(ti.i32, shape) for k, shape in arrays.items()}
    a["ecnt"].from_numpy(ecnt)
    a["emult"].from_numpy(emult)
    a["ebase"].fill(-7)
    pcmm.record_slots(a["ecnt"], a["emult"], a["ebase"], a["eoff"], serial)
    computed = (emult > 0) & (np.arange(E)[None, :] < ecnt[:, None])
    runs = computed.sum(axis=1)
    np.testing.assert_array_equal(a["ebase"].to_numpy(), np.cumsum(runs) - runs)
