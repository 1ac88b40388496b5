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
