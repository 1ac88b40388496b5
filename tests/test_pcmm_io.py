"""Continuum output read back with VTK: PCMM elements (triangle cells with their
stress, weight 1/N_e and N_e), PCMM particles (stress, plastic shear strain, failure
mark, displacement) and FVM blocks (triangles on the current nodes with their
stress), each against the simulation's own arrays and against what a uniform
stretch must give (the prescribed displacement, a uniform stress, Hooke's law)."""
import numpy as np
from vtk.util.numpy_support import vtk_to_numpy

import tdem
from test_io import _cell_array, _point_array, _vtk_read

E, NU, RHO = 30e9, 0.25, 2500.0
VTK_TRIANGLE = 5


def _cells(grid, size):
    """Point ids of every cell (C, size), checking the cell type."""
    out = []
    for c in range(grid.GetNumberOfCells()):
        cell = grid.GetCell(c)
        assert cell.GetCellType() == VTK_TRIANGLE
        ids = cell.GetPointIds()
        out.append([ids.GetId(k) for k in range(size)])
    return np.array(out, dtype=np.int64)


def _areas(pts, tri):
    a, b, c = (pts[tri[:, k], :2] for k in range(3))
    u, w = b - a, c - a
    return 0.5 * np.abs(u[:, 0] * w[:, 1] - u[:, 1] * w[:, 0])


def test_pcmm_elements_and_particles_read_back(tmp_path):
    """A square-lattice Mohr–Coulomb body stretched in pure shear past its strength:
    every element file cell is an element of ``sim.elements`` with its stress; the
    weighted cell areas add up to the body's area (the superposition invariant, exact
    on a square lattice); the particles'
    stress, plastic shear strain, failure mark and displacement are those of the
    simulation, and the displacement is the prescribed motion."""
    lxx, lyy, steps = 2.0, -2.0, 40
    mat = tdem.MohrCoulomb(density=RHO, young=E, poisson=NU, cohesion=1e6, friction_angle=30.0,
                           tensile_strength=2e7)
    pos, rad = tdem.pack.regular(1.0, 0.6, 0.05)
    sim = tdem.Simulation(gravity=(0.0, 0.0), dt_fraction=0.5)
    v0 = pos * np.array([lxx, lyy])
    g = sim.add_particles(pos, rad, material=mat, tolerance=0.05, velocity=v0)
    sim.fix_particles(g.ids, vx=v0[:, 0], vy=v0[:, 1])
    sim.run(steps=steps)
    paths = sim.write_vtu(tmp_path / "s.vtu", walls=False, contacts=False)
    assert [p.rsplit("/", 1)[-1] for p in paths] == ["s.vtu", "s_elements.vtu"]
    p = sim.particles.numpy()
    e = sim.elements.numpy()
    n = len(p["radius"])

    ge = _vtk_read(tmp_path / "s_elements.vtu")
    tri = _cells(ge, 3)
    np.testing.assert_array_equal(tri, e["triangles"])
    pts = vtk_to_numpy(ge.GetPoints().GetData())
    np.testing.assert_array_equal(pts[:, :2], p["position"])
    stress = _cell_array(ge, "stress").reshape(-1, 3, 3)
    np.testing.assert_array_equal(stress[:, :2, :2], e["stress"])
    np.testing.assert_array_equal(stress[:, 2, 2], e["stress_zz"])
    weight = _cell_array(ge, "weight")
    # square lattice: the four triangles of each square, each created by two of its
    # corners (copies are cells too), cover it four times
    np.testing.assert_array_equal(_cell_array(ge, "n_cover"), 4)
    np.testing.assert_array_equal(weight, 0.25)
    x = p["position"]
    body = np.ptp(x[:, 0]) * np.ptp(x[:, 1])
    assert abs(np.sum(_areas(pts, tri) * weight) - body) < 1e-12 * body
    # uniform stress, past the strength: every element carries the same state
    assert np.ptp(stress[:, 0, 0]) < 1e-9 * np.abs(stress[:, 0, 0]).max()
    np.testing.assert_array_equal(_point_array(ge, "displacement")[:, :2], p["displacement"])

    gp = _vtk_read(tmp_path / "s.vtu")
    assert gp.GetNumberOfPoints() == n
    ps = _point_array(gp, "stress").reshape(n, 3, 3)
    np.testing.assert_array_equal(ps[:, :2, :2], p["stress"])
    np.testing.assert_array_equal(ps[:, 2, 2], p["stress_zz"])
    eps = _point_array(gp, "plastic_strain")
    np.testing.assert_array_equal(eps, p["plastic_strain"])
    assert eps.min() > 1e-4                       # failed in shear, every particle
    np.testing.assert_array_equal(_point_array(gp, "failed"), 1)
    np.testing.assert_array_equal(_point_array(gp, "elements"), p["elements"])
    np.testing.assert_array_equal(_point_array(gp, "pressure"), p["pressure"])
    np.testing.assert_allclose(
        p["pressure"], -(p["stress"][:, 0, 0] + p["stress"][:, 1, 1] + p["stress_zz"]) / 3.0,
        rtol=1e-12, atol=1e-12 * np.abs(p["stress"]).max())
    # the displacement is the prescribed motion: the constant velocity l·x0, 40 steps
    d = _point_array(gp, "displacement")[:, :2]
    np.testing.assert_allclose(d, v0 * steps * sim.dt, rtol=0, atol=1e-13)


def test_block_read_back(tmp_path):
    """An FVM block stretched uniformly: the block file's triangles are the mesh on
    the current nodes, its cell stress that of ``block.elements()`` and Hooke's law
    of the stretch (1e-6), its node displacement and reaction those of the block."""
    v, t = tdem.mesh.rectangle(2.0, 1.0, 8, 4, pattern="cross")
    sim = tdem.Simulation(gravity=(0.0, 0.0), dt_fraction=0.5)
    b = sim.add_block(v, t, material=tdem.Elastic(density=RHO, young=E, poisson=NU), velocity=(0.0, 0.0))
    lxx, lyy = 1.0, 0.3
    b.fix(np.arange(len(v)), vx=v[:, 0] * lxx, vy=v[:, 1] * lyy)
    sim.run(steps=1)                      # first step: nodes at rest, then moving
    sim.run(steps=30)
    paths = sim.write_vtu(tmp_path / "b.vtu", walls=False, contacts=False)
    assert any(p.endswith("b_blocks.vtu") for p in paths)
    g = _vtk_read(tmp_path / "b_blocks.vtu")
    nd, el = b.nodes(), b.elements()
    np.testing.assert_array_equal(_cells(g, 3), el["triangles"])
    pts = vtk_to_numpy(g.GetPoints().GetData())
    np.testing.assert_array_equal(pts[:, :2], nd["position"])
    span = np.ptp(nd["position"], axis=0)
    assert abs(np.sum(_areas(pts, el["triangles"])) - span[0] * span[1]) < 1e-12 * span[0] * span[1]
    s = _cell_array(g, "stress").reshape(-1, 3, 3)
    np.testing.assert_array_equal(s[:, :2, :2], el["stress"])
    np.testing.assert_array_equal(s[:, 2, 2], el["stress_zz"])
    dt = sim.dt
    k = np.arange(30)
    exx = np.sum(lxx * dt / (1.0 + (k + 0.5) * dt * lxx))
    eyy = np.sum(lyy * dt / (1.0 + (k + 0.5) * dt * lyy))
    K, G = E / (3 * (1 - 2 * NU)), E / (2 * (1 + NU))
    lam = K - 2 * G / 3
    want_xx = lam * (exx + eyy) + 2 * G * exx
    want_yy = lam * (exx + eyy) + 2 * G * eyy
    assert np.abs(s[:, 0, 0] - want_xx).max() < 1e-6 * abs(want_xx)
    assert np.abs(s[:, 1, 1] - want_yy).max() < 1e-6 * abs(want_xx)
    np.testing.assert_allclose(_cell_array(g, "pressure"),
                               -(s[:, 0, 0] + s[:, 1, 1] + s[:, 2, 2]) / 3.0, rtol=1e-12)
    np.testing.assert_array_equal(_point_array(g, "displacement")[:, :2], nd["displacement"])
    np.testing.assert_array_equal(_point_array(g, "reaction")[:, :2], nd["reaction"])
    np.testing.assert_allclose(nd["displacement"], nd["position"] - v, rtol=0, atol=1e-15)
