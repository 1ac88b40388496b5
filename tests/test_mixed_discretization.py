"""The nodal mixed discretization of the elements (physics/fvm.py, "Nodal mixed
discretization"): a block's triangles and the PCMM elements of a Mohr–Coulomb
material take the volumetric part of their strain increment, and the in-plane mean
stress of their nodal forces, as means through their nodes. The soil here is
Mohr–Coulomb of a cohesion that keeps it elastic.

- Patch test: under a uniform velocity gradient (every node or particle driven
  by v = L·x₀, on a jittered Delaunay mesh and on a square lattice) every element
  has the same strain, so the averages change nothing: the stresses with and
  without the mixed discretization agree to round-off (1e-12 of their size), and
  equal plane-strain Hooke's law of the accumulated strain.
- Energy: an undamped elastic block held on one side and loaded at once by a
  body force vibrates about its compressed state; kinetic + strain + potential
  energy stays within 3 % of the largest strain energy over 3000 steps (2.3 %
  measured, the kinetic energy being that of the half steps), with the mixed
  discretization as without it (within 10 % of the same figure) (the leapfrog's bounded error; a force that
  did not take the same average as the strain would do work the stresses do not
  store).
- The collapse it exists for is in tests/test_bearing_capacity.py.
"""
import numpy as np
import pytest

import tdem

E, NU, RHO = 1.0e9, 0.3, 2500.0


def _soil():
    """Mohr–Coulomb (it mixes), strong enough to stay elastic."""
    return tdem.MohrCoulomb(density=RHO, young=E, poisson=NU, cohesion=1e12,
                            friction_angle=30.0)
K = E / (3 * (1 - 2 * NU))
G = E / (2 * (1 + NU))
LAM = K - 2 * G / 3
L = np.array([[2e-3, 1e-3], [-0.5e-3, -1e-3]])     # a velocity gradient (1/s)


def _jittered_mesh(seed=3):
    v, t = tdem.mesh.polygon(np.array([[0, 0], [1, 0], [1, 0.8], [0, 0.8]], float), 0.15)
    return np.asarray(v, float), np.asarray(t)


def _block_stress(mixed, steps=40):
    v, t = _jittered_mesh()
    sim = tdem.Simulation(gravity=(0.0, 0.0), mixed_discretization=mixed)
    blk = sim.add_block(v, t, _soil())
    vel = v @ L.T
    blk.fix(np.arange(len(v)), vx=vel[:, 0], vy=vel[:, 1])
    sim.run(steps=steps)
    e = blk.elements()
    return sim, np.asarray(e["stress"]), np.asarray(e["stress_zz"])


def test_block_patch_uniform_gradient_is_unchanged_by_the_averages():
    sim, s1, z1 = _block_stress(True)
    _, s0, z0 = _block_stress(False)
    scale = np.abs(s0).max()
    assert scale > 0
    assert np.abs(s1 - s0).max() < 1e-12 * scale
    assert np.abs(z1 - z0).max() < 1e-12 * scale
    # and it is Hooke's law of the strain the nodes' motion gives (small strain here:
    # 40 steps of the gradient; the rotation part is small, a 2 % tolerance)
    t = sim.time - sim.dt      # the first step strains nothing (v_{-1/2} = 0)
    D = 0.5 * (L + L.T) * t
    th = D[0, 0] + D[1, 1]
    want = np.array([[2 * G * D[0, 0] + LAM * th, 2 * G * D[0, 1]],
                     [2 * G * D[0, 1], 2 * G * D[1, 1] + LAM * th]])
    assert np.allclose(s1, want, rtol=0.0, atol=0.01 * np.abs(want).max())


def _lattice_stress(mixed, steps=40):
    pos, r = tdem.pack.regular(0.6, 0.6, 0.05)
    sim = tdem.Simulation(gravity=(0.0, 0.0), mixed_discretization=mixed)
    sim.add_particles(pos, r, material=_soil(),
                      tolerance=0.05)
    vel = pos @ L.T
    sim.fix_particles(np.arange(len(pos)), vx=vel[:, 0], vy=vel[:, 1])
    sim.run(steps=steps)
    return np.asarray(sim.elements.numpy()["stress"])


def test_pcmm_patch_uniform_gradient_is_unchanged_by_the_averages():
    s1 = _lattice_stress(True)
    s0 = _lattice_stress(False)
    assert len(s0) > 100
    scale = np.abs(s0).max()
    assert np.abs(s1 - s0).max() < 1e-12 * scale


def _vibrating_block(mixed, steps=3000, g=50.0):
    """A block held on its left side, loaded at once by a body force g along −x,
    undamped: it vibrates about its compressed state. Returns the largest change
    of kinetic + strain + potential energy over the run, over the largest strain
    energy, and that largest strain energy over the static one (≈ 2 at the peaks)."""
    v, t = _jittered_mesh()
    sim = tdem.Simulation(gravity=(-g, 0.0), mixed_discretization=mixed, dt_fraction=0.5)
    blk = sim.add_block(v, t, _soil())
    blk.fix(blk.nodes_in(xmax=1e-9), vx=0.0, vy=0.0)

    def energy():
        nd = blk.nodes()
        m = nd["mass"]
        kin = 0.5 * float(m @ (nd["velocity"] ** 2).sum(axis=1))
        strain = sim.energy()["strain"]
        return kin + strain + g * float(m @ nd["position"][:, 0]), strain

    e0, _ = energy()
    worst, smax = 0.0, 0.0
    for _ in range(30):
        sim.run(steps=steps // 30)
        e, s = energy()
        worst = max(worst, abs(e - e0))
        smax = max(smax, s)
    return worst / smax, smax


def test_vibrating_block_keeps_its_energy_as_without_the_averages():
    mixed, smax = _vibrating_block(True)
    plain, _ = _vibrating_block(False)
    assert smax > 0
    # the leapfrog's bounded error (kinetic energy at half steps): 2.3e-2 both
    assert mixed < 0.03 and plain < 0.03
    assert mixed < 1.1 * plain, (mixed, plain)


def test_elastic_material_keeps_its_own_update():
    # an Elastic material does not mix: the same block, mixed or not (to round-off:
    # the two are compiled apart)
    v, t = _jittered_mesh()
    out = []
    for mixed in (True, False):
        sim = tdem.Simulation(gravity=(0.0, -9.81), mixed_discretization=mixed)
        blk = sim.add_block(v, t, tdem.Elastic(density=RHO, young=E, poisson=NU))
        blk.fix(blk.nodes_in(ymax=1e-9), vx=0.0, vy=0.0)
        sim.run(steps=200)
        out.append(np.asarray(blk.elements()["stress"]))
    assert np.abs(out[0]).max() > 0
    assert np.abs(out[0] - out[1]).max() < 1e-12 * np.abs(out[0]).max()
