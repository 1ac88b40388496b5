"""Cached kernel launches (tdem.launch): the same results as Taichi's own call."""
import gc

import numpy as np
import taichi as ti

import tdem  # noqa: F401  (initialises Taichi through the engine's first simulation)
from tdem import backend
from tdem import launch
from tdem.launch import cached


@cached
@ti.kernel
def _axpy(y: ti.types.ndarray(), x: ti.types.ndarray(), a: ti.f64, k: ti.i32,
          twice: ti.template()):
    for i in range(y.shape[0]):
        y[i] += a * x[i] + k
        if ti.static(twice):
            y[i] += a * x[i] + k


def _arrays(n, fill):
    y = ti.ndarray(ti.f64, (n,))
    x = ti.ndarray(ti.f64, (n,))
    y.fill(0.0)
    x.from_numpy(np.full(n, fill))
    return y, x


def test_cached_launches_follow_their_arguments():
    """Scalars, template values and arrays of every call reach the kernel: a new
    value, a new variant, a new pair of arrays (also one made where a freed array
    was), and numpy arrays (served by the plain call)."""
    backend.init()
    y, x = _arrays(5, 2.0)
    for _ in range(3):
        _axpy(y, x, 0.5, 1, False)            # the first call fills the cache
    assert len(_axpy._entries) >= 1
    np.testing.assert_array_equal(y.to_numpy(), np.full(5, 3 * (0.5 * 2.0 + 1)))
    _axpy(y, x, 1.5, -2, False)               # new scalars, same entry
    np.testing.assert_array_equal(y.to_numpy(), np.full(5, 6.0 + 1.5 * 2.0 - 2))
    _axpy(y, x, 1.0, 0, True)                 # the other variant
    np.testing.assert_array_equal(y.to_numpy(), np.full(5, 7.0 + 4.0))
    y2, x2 = _arrays(7, 3.0)                  # other arrays, other shape
    _axpy(y2, x2, 1.0, 0, False)
    _axpy(y2, x2, 1.0, 0, False)
    np.testing.assert_array_equal(y2.to_numpy(), np.full(7, 6.0))
    np.testing.assert_array_equal(y.to_numpy(), np.full(5, 11.0))
    for _ in range(20):                       # arrays freed and made again, ids reused
        del y, x
        gc.collect()
        y, x = _arrays(4, 1.0)
        _axpy(y, x, 2.0, 0, False)
        _axpy(y, x, 2.0, 0, False)
        np.testing.assert_array_equal(y.to_numpy(), np.full(4, 4.0))
    yn, xn = np.zeros(3), np.full(3, 1.0)
    _axpy(yn, xn, 1.0, 1, False)
    _axpy(yn, xn, 1.0, 1, False)
    np.testing.assert_array_equal(yn, np.full(3, 4.0))
    assert len(_axpy._entries) <= launch.MAX_ENTRIES


def _pcmm_run(monkeypatch, plain):
    monkeypatch.setattr(launch, "ENABLED", not plain)
    pos, rad = tdem.pack.regular(0.2, 0.2, 0.01)
    soil = tdem.MohrCoulomb(density=2000.0, young=10e6, poisson=0.3, cohesion=1e3,
                            friction_angle=30.0, tensile_strength=500.0)
    sim = tdem.Simulation(gravity=(0.0, -9.81), progress=False, check_interval=100)
    sim.add_particles(pos, rad, material=soil, tolerance=0.01,
                      contact=tdem.LinearContact(kn=10e6, friction=0.5))
    sim.add_wall((-1.0, 0.0), (1.2, 0.0), contact=tdem.LinearContact(kn=10e6, friction=0.5))
    sim.run(steps=300)
    from physics import pcmm
    if not plain:
        assert pcmm.stresses._entries          # the cached path served the element kernel
    p = sim.particles.numpy()
    return p["position"], p["velocity"], p["stress"]


def test_cached_and_plain_launches_give_the_same_run(monkeypatch):
    """A collapsing Mohr-Coulomb block (elements deleted and made, lists rebuilt,
    segments snapshotted) runs to the same bits with and without the cache."""
    fast = _pcmm_run(monkeypatch, False)
    plain = _pcmm_run(monkeypatch, True)
    for a, b in zip(fast, plain):
        np.testing.assert_array_equal(a, b)
    assert np.abs(fast[1]).max() > 1e-3        # it moved


def test_host_view_reads_what_kernels_wrote():
    """launch.host_view: a numpy view of a CPU array, with what the last kernel wrote
    (no copy: it follows later launches too)."""
    backend.init()
    y, x = _arrays(6, 1.5)
    view = launch.host_view(y)
    assert view.shape == (6,) and view.dtype == np.float64
    _axpy(y, x, 2.0, 1, False)
    np.testing.assert_array_equal(view, np.full(6, 4.0))
    _axpy(y, x, 2.0, 1, False)
    np.testing.assert_array_equal(view, y.to_numpy())
    flags = ti.ndarray(ti.i32, (3, 2))
    flags.from_numpy(np.arange(6, dtype=np.int32).reshape(3, 2))
    np.testing.assert_array_equal(launch.host_view(flags), np.arange(6).reshape(3, 2))
