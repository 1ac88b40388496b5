"""The contact laws are written on tangent-plane vectors, so that one law serves 2D
(one component, along t) and 3D (three global components). A 3D call with the
tangential velocity along a unit direction e of the tangent plane must give the 2D
call's numbers times e: the spring, the total force, the dissipation, the history and
the stored energy, in the elastic range and at the Coulomb limit."""
import numpy as np
import pytest
import taichi as ti

import tdem
from physics.contact_law import _turned
from tdem import backend
from tdem.step import turn_quaternion

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


@ti.kernel
def _turn_spring(v: ti.types.ndarray(), n: ti.types.ndarray(), out: ti.types.ndarray()):
    for r in range(v.shape[0]):
        h = ti.Vector([v[r, 0], v[r, 1], v[r, 2]])
        nv = ti.Vector([n[r, 0], n[r, 1], n[r, 2]])
        h = _turned(h, 0, nv)
        for c in ti.static(range(3)):
            out[r, c] = h[c]


def test_spring_turned_onto_the_tangent_plane_keeps_its_length():
    """The shear spring is turned onto the current tangent plane with its
    length kept. Normals turned from the spring's plane by 1e-9 to 0.5 rad (the
    series branch below a turn of 1e-3 rad, the exact one above): the result lies in
    the plane, keeps |F_s| to 2 ulp and points where the exact projection does."""
    backend.init()
    rng = np.random.default_rng(3)
    angles = np.concatenate([np.geomspace(1e-9, 0.5, 40), [0.0]])
    v = rng.normal(size=(angles.size, 3)) * rng.uniform(1e-3, 1e3, size=(angles.size, 1))
    # a unit normal at angle a from the plane normal to v (the plane of the spring)
    w = np.cross(v, rng.normal(size=v.shape))
    w /= np.linalg.norm(w, axis=1)[:, None]
    e = v / np.linalg.norm(v, axis=1)[:, None]
    n = np.cos(angles)[:, None] * w + np.sin(angles)[:, None] * e
    n /= np.linalg.norm(n, axis=1)[:, None]
    out = np.zeros_like(v)
    _turn_spring(v, n, out)
    m = np.linalg.norm(v, axis=1)
    p = v - np.sum(v * n, axis=1)[:, None] * n
    exact = p * (m / np.linalg.norm(p, axis=1))[:, None]
    np.testing.assert_allclose(np.linalg.norm(out, axis=1), m, rtol=5e-16)
    np.testing.assert_allclose(np.abs(np.sum(out * n, axis=1)) / m, 0.0, atol=1e-15)
    np.testing.assert_allclose(out / m[:, None], exact / m[:, None], rtol=0, atol=1e-15)


@ti.kernel
def _turn_quat(q: ti.types.ndarray(), phi: ti.types.ndarray(), out: ti.types.ndarray()):
    for r in range(q.shape[0]):
        qr = ti.Vector([q[r, 0], q[r, 1], q[r, 2], q[r, 3]])
        p = ti.Vector([phi[r, 0], phi[r, 1], phi[r, 2]])
        qr = turn_quaternion(qr, p)
        for c in ti.static(range(4)):
            out[r, c] = qr[c]


def test_quaternion_turn_is_the_exponential_map():
    """A sphere's orientation turns by exp(φ/2) ⊗ q each step. The small turns of a
    step take the series of cos(a/2) and sin(a/2)/a and a first-order
    renormalisation: against the exact map (numpy's sin and cos, an exact norm) to
    round-off for turns of 1e-12 to 2 rad, and unit to round-off."""
    backend.init()
    rng = np.random.default_rng(5)
    a = np.concatenate([np.geomspace(1e-12, 2.0, 60), [0.0]])
    axis = rng.normal(size=(a.size, 3))
    phi = axis / np.linalg.norm(axis, axis=1)[:, None] * a[:, None]
    q = rng.normal(size=(a.size, 4))
    q /= np.linalg.norm(q, axis=1)[:, None]
    out = np.zeros_like(q)
    _turn_quat(q, phi, out)
    s = np.where(a > 0, np.sin(0.5 * a) / np.where(a > 0, a, 1.0), 0.5)
    dq = np.column_stack([np.cos(0.5 * a), s[:, None] * phi])
    w0, x0, y0, z0 = dq.T
    w1, x1, y1, z1 = q.T
    exact = np.column_stack([w0 * w1 - x0 * x1 - y0 * y1 - z0 * z1,
                             w0 * x1 + x0 * w1 + y0 * z1 - z0 * y1,
                             w0 * y1 - x0 * z1 + y0 * w1 + z0 * x1,
                             w0 * z1 + x0 * y1 - y0 * x1 + z0 * w1])
    exact /= np.linalg.norm(exact, axis=1)[:, None]
    np.testing.assert_allclose(out, exact, rtol=0, atol=1e-15)
    np.testing.assert_allclose(np.linalg.norm(out, axis=1), 1.0, rtol=0, atol=5e-16)
