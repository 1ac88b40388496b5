"""Viscous (Lysmer–Kuhlemeyer) non-reflecting boundaries (physics notes §6)."""
import math

import numpy as np
import pytest

import tdem

E, NU, RHO = 30e9, 0.25, 2500.0


def _bar(end, kind="block"):
    """A plane P-wave (lateral motion blocked) sent down a 20 m bar by a half-sine
    velocity pulse; the far end is fixed or non-reflecting. Returns the velocity
    history at x = 10 m."""
    mat = tdem.Elastic(density=RHO, young=E, poisson=NU)
    sim = tdem.Simulation(gravity=(0.0, 0.0), dt_fraction=0.5)
    T, amp = 2e-3, 1.0

    def pulse(t):
        return amp * math.sin(math.pi * t / T) if t < T else 0.0

    if kind == "block":
        v, t = tdem.mesh.rectangle(20.0, 0.5, 80, 2)
        b = sim.add_block(v, t, material=mat)
        b.fix(b.nodes_in(ymax=1e-9), vx=None, vy=0.0)
        b.fix(b.nodes_in(ymin=0.5 - 1e-9), vx=None, vy=0.0)
        b.fix(b.nodes_in(xmax=1e-9), vx=pulse, vy=0.0)
        right = b.nodes_in(xmin=20.0 - 1e-9)
        if end == "fixed":
            b.fix(right, vx=0.0, vy=0.0)
        else:
            sim.non_reflecting((b, right))
        probe = b.nodes_in(xmin=9.99, xmax=10.01)
        read = lambda s: float(b.nodes()["velocity"][probe, 0].mean())
    else:
        pos, rad = tdem.pack.regular(20.0, 0.5, 0.05)
        g = sim.add_particles(pos, rad, material=mat, tolerance=0.05)
        sim.fix_particles(sim.particles_in(ymax=0.06), vx=None, vy=0.0)
        sim.fix_particles(sim.particles_in(ymin=0.44), vx=None, vy=0.0)
        sim.fix_particles(sim.particles_in(xmax=0.06), vx=pulse, vy=0.0)
        right = sim.particles_in(xmin=19.94)
        if end == "fixed":
            sim.fix_particles(right, vx=0.0, vy=0.0)
        else:
            sim.non_reflecting(right, normal=(1.0, 0.0))
        probe = sim.particles_in(xmin=9.94, xmax=10.06)
        read = lambda s: float(s.particles.numpy(stress=False)["velocity"][probe, 0].mean())
    sim.monitor("v", read, every=5)
    sim.run(until=11e-3)
    t, v = sim.histories()["v"]
    return np.asarray(t), np.asarray(v), amp


@pytest.mark.parametrize("kind", ["block", "pcmm"])
def test_plane_wave_leaves_through_a_non_reflecting_end(kind):
    c = math.sqrt(E * (1 - NU) / ((1 + NU) * (1 - 2 * NU) * RHO))
    t, v, amp = _bar("free", kind)
    tf, vf, _ = _bar("fixed", kind)
    incident = np.abs(v[t < 10.0 / c + 3e-3]).max()
    back = t > 30.0 / c - 0.5e-3            # the reflection returns to x = 10 m at 30 m / c
    assert incident == pytest.approx(amp, rel=0.1)
    assert np.abs(vf[back]).max() > 0.8 * incident          # a fixed end reflects it (all)
    assert np.abs(v[back]).max() < 0.1 * incident            # this one (almost) nothing
