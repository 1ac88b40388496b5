"""The time integration shared by particles, block nodes and rigid blocks.

One damped leapfrog (central differences, C&S Eqs. 34–36) for a velocity (a vector)
or a spin (a scalar) at the half step:

    v_{n+1/2} = [v_{n−1/2} (1 − α Δt/2) + (F + F_d) Δt / m] / (1 + α Δt/2)

with α the global mass-proportional damping and F_d = −α_l |F| sign(v_{n−1/2}) the
local non-viscous damping (Miyata Eq. 33, PFC form), per component. Positions then
follow x_{n+1} = x_n + v_{n+1/2} Δt (in the callers, which also apply prescribed
velocities and book the energy).
"""
import taichi as ti


@ti.func
def damped_leapfrog(v0, f, m, alpha, alpha_l, dt):
    """(v_{n+1/2}, F_d) from v_{n−1/2}, the force (or moment) F and the mass (or
    inertia) m (module docstring)."""
    fd = -alpha_l * ti.abs(f) * ti.math.sign(v0)
    den = 1.0 + 0.5 * alpha * dt
    num = 1.0 - 0.5 * alpha * dt
    return (v0 * num + (f + fd) / m * dt) / den, fd


@ti.func
def _quat_mul(a, b):
    return ti.Vector([a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
                      a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
                      a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
                      a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0]])


@ti.func
def _body_turn(q, lb, inertia, k: ti.template(), h):
    """The free rotor's flow about body axis k for a time h: the body turns by
    φ = L_k/I_k·h about that axis (q ← q ⊗ (cos φ/2, sin φ/2 e_k)) and the body-frame
    angular momentum turns back by −φ."""
    phi = lb[k] / inertia[k] * h
    c = ti.cos(0.5 * phi)
    s = ti.sin(0.5 * phi)
    dq = ti.Vector([c, 0.0, 0.0, 0.0])
    dq[k + 1] = s
    q = _quat_mul(q, dq)
    c2 = ti.cos(phi)
    s2 = ti.sin(phi)
    a = ti.static((k + 1) % 3)
    b = ti.static((k + 2) % 3)
    la = lb[a]
    lbb = lb[b]
    lb[a] = c2 * la + s2 * lbb
    lb[b] = -s2 * la + c2 * lbb
    return q, lb


@ti.func
def free_rotation(q, L, inertia, rot, dt):
    """The orientation after a step Δt of a rigid body of principal moments
    ``inertia`` (body axes) with the world-frame angular momentum L held over the step
    (a splitting rotation update; the symmetric composition of the exact
    flows about the three body axes of Dullweber, Leimkuhler & McLachlan 1997, whose
    |L| is exact and whose energy error stays bounded). ``rot`` is the rotation of q.
    Returns (q_{n+1}, ω_{n+1/2} = R I⁻¹ Rᵀ L at q_{n+1})."""
    lb = rot.transpose() @ L
    q, lb = _body_turn(q, lb, inertia, 0, 0.5 * dt)
    q, lb = _body_turn(q, lb, inertia, 1, 0.5 * dt)
    q, lb = _body_turn(q, lb, inertia, 2, dt)
    q, lb = _body_turn(q, lb, inertia, 1, 0.5 * dt)
    q, lb = _body_turn(q, lb, inertia, 0, 0.5 * dt)
    q = q / q.norm()
    w_body = lb / inertia
    w, x, y, z = q[0], q[1], q[2], q[3]
    r = ti.Matrix([[1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - w * z), 2.0 * (x * z + w * y)],
                   [2.0 * (x * y + w * z), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - w * x)],
                   [2.0 * (x * z - w * y), 2.0 * (y * z + w * x), 1.0 - 2.0 * (x * x + y * y)]])
    return q, r @ w_body
