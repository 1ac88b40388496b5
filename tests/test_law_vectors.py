"""The contact laws are written on tangent-plane vectors, so that one law serves 2D
(one component, along t) and 3D (three global components). A 3D call with the
tangential velocity along a unit direction e of the tangent plane must give the 2D
call's numbers times e: the spring, the total force, the dissipation, the history and
the stored energy, in the elastic range and at the Coulomb limit."""
import numpy as np
import pytest
import taichi as ti

import tdem
from tdem import backend

LAWS = [tdem.LinearContact(kn=2e6, ks=1.5e6, friction=0.4, restitution=0.6),
        tdem.HertzMindlin(young=5e9, poisson=0.25, friction=0.4, restitution=0.6)]


@ti.kernel
def _call(law: ti.template(), q: ti.types.ndarray(), u: ti.f64, vn: ti.f64,
          vt1: ti.f64, e: ti.types.ndarray(), h0: ti.f64, out: ti.types.ndarray()):
    dt = 1e-5
    qv = ti.Vector([q[c] for c in ti.static(range(6))])
    # 2D: the tangent plane is the line along t
    h1 = ti.Vector([h0, 0.0])
    fn_el, fn, ft, kn, cn, diss, h1 = law.force(qv, u, vn, ti.Vector([vt1]), 1.0, 0.01,
                                                dt, h1)
    out[0] = fn_el
    out[1] = fn
    out[2] = ft[0]
    out[3] = diss
    out[4] = h1[0]
    out[5] = law.energy(qv, u, 0.01, h1, 1)
    # 3D: the same tangential quantities along the unit vector e
    ev = ti.Vector([e[0], e[1], e[2]])
    h3 = ti.Vector([h0 * e[0], h0 * e[1], h0 * e[2], 0.0])
    fn_el3, fn3, ft3, kn3, cn3, diss3, h3 = law.force(qv, u, vn, vt1 * ev, 1.0, 0.01, dt, h3)
    out[6] = fn_el3
    out[7] = fn3
    for c in ti.static(range(3)):
        out[8 + c] = ft3[c]
        out[11 + c] = h3[c]
    out[14] = diss3
    out[15] = law.energy(qv, u, 0.01, h3, 3)


@pytest.mark.parametrize("law", LAWS, ids=lambda l: type(l).__name__)
@pytest.mark.parametrize("h0, vt", [(0.5, 0.2), (20.0, 3.0), (-30.0, -8.0)],
                         ids=["elastic", "sliding", "sliding-negative"])
def test_3d_tangent_vector_is_the_2d_law_along_its_direction(law, h0, vt):
    backend.init()
    q = np.array(law.values(), dtype=np.float64)
    e = np.array([0.48, -0.6, 0.64])
    e /= np.linalg.norm(e)
    out = np.zeros(16)
    _call(type(law), q, 1e-5, -0.05, vt, e, h0, out)
    fn_el, fn, ft, diss, h, energy = out[:6]
    assert out[6] == pytest.approx(fn_el, rel=1e-14)
    assert out[7] == pytest.approx(fn, rel=1e-14)
    np.testing.assert_allclose(out[8:11], ft * e, rtol=1e-12, atol=1e-12 * abs(ft))
    np.testing.assert_allclose(out[11:14], h * e, rtol=1e-12, atol=1e-12 * abs(h))
    assert out[14] == pytest.approx(diss, rel=1e-10, abs=1e-18)
    assert out[15] == pytest.approx(energy, rel=1e-12)
    fmax = 0.4 * fn_el
    if abs(h0) > fmax:       # the sliding cases: the spring sits at the Coulomb limit
        assert abs(h) == pytest.approx(fmax, rel=1e-12)
        assert np.linalg.norm(out[11:14]) == pytest.approx(fmax, rel=1e-12)
        assert diss > 0.0
    else:
        assert abs(h) < fmax
