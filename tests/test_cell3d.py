"""tdem.TriaxialCell: a cubical cell of six servo-controlled walls (3D).

- A simple cubic lattice of equal spheres (radius R, linear normal stiffness k_n,
  frictionless) in the cell: one contact per sphere per axis carries k_n δ with
  δ = 2R ε over an area (2R)², so σ = k_n ε/(2R) on each axis, independently of the
  others. The walls' law has k_n,w = 2 k_n: a wall is the mirror plane between a
  sphere and its image, half of a k_n spring, so that the chain of n spheres between
  two walls is n springs k_n in series, the lattice's own stiffness (with k_n,w =
  k_n the walls' modulus would read n/(n + 1) of it). Isotropic consolidation to p
  strains every axis by p·2R/k_n; compressed axially at constant σ3 the lattice
  stiffens by k_n/(2R) along z and the lateral walls do not move.
- A random pack of a few hundred frictional spheres, consolidated isotropically and
  compressed to 6 % axial strain, dilating: the lateral walls hold σ3 within 1 %
  (means over 0.5 % of axial strain; every single record within 2 %), and on the
  constant-p path the mean stress stays within 1 % of p.
"""
import math

import numpy as np
import pytest

import tdem
from tdem.cell import friction_angles, hold_error

R = 0.005           # lattice spheres' radius (m)
KN = 1.0e5          # N/m
P = 1.0e4           # Pa: ε = p 2R/k_n = 1e-3


@pytest.fixture(scope="module")
def lattice():
    n = 4
    side = 2 * R * n
    sim = tdem.Simulation(dim=3, gravity=(0.0, 0.0, 0.0), local_damping=0.7, progress=False)
    law = tdem.LinearContact(kn=KN, ks=KN, friction=0.0)
    wall_law = tdem.LinearContact(kn=2.0 * KN, ks=0.0, friction=0.0)
    x = tdem.pack.lattice3d((0, 0, 0), (side, side, side), R, kind="cubic")
    assert len(x) == n ** 3
    sim.add_particles(x, R, density=2500.0, contact=law)
    cell = tdem.TriaxialCell(sim, (0, 0, 0), (side, side, side), wall_law, margin=2 * R)
    # (the walls' law is twice as stiff as the spheres', and so is the time step short
    # enough for it: the servo's gain per step then needs relaxation below 0.5, which
    # sets the walls ringing on this lattice; 0.2–0.4 settle it in 2,500–3,000 steps)
    cell.consolidate(P, tolerance=0.002, volume_tolerance=1e-6, relaxation=0.3)
    return cell, side


def test_cubic_lattice_isotropic_modulus(lattice):
    """σ = k_n ε/(2R) on each axis: the modulus p/ε from the walls' positions within
    1 %, the walls' and the measured (Love–Weber, inner 2 × 2 × 2 spheres) stress
    within 1 % of p."""
    cell, side = lattice
    eps = 1.0 - cell.lengths / side
    modulus = P / eps
    np.testing.assert_allclose(modulus, KN / (2 * R), rtol=0.01)
    np.testing.assert_allclose(cell.wall_stresses(), P, rtol=0.01)
    measured = cell.measured_stress()
    np.testing.assert_allclose(np.diag(measured), P, rtol=0.01)
    assert np.abs(measured - np.diag(np.diag(measured))).max() < 1e-6 * P
    # bulk modulus of the lattice: p/ε_v = k_n/(6R) to first order
    ev = 1.0 - cell.volume / side ** 3
    assert P / ev == pytest.approx(KN / (6 * R), rel=0.01)


def test_cubic_lattice_axial_modulus_at_constant_sigma3(lattice):
    """Compressed along z at constant σ3 = p: dσ1/dε_a = k_n/(2R) within 3 %; the
    lateral walls hold σ3 and stay where they are (no Poisson effect in a simple
    cubic lattice)."""
    cell, side = lattice
    lx0 = cell.lengths[:2].copy()
    res = cell.compress(strain_rate=0.05, axial_strain=0.003, record_every=20)
    ea, s1 = res["axial_strain"], res["sigma1"]
    late = ea > 0.001                       # past the start-up transient
    slope = np.polyfit(ea[late], s1[late], 1)[0]
    assert slope == pytest.approx(KN / (2 * R), rel=0.03)
    assert s1[-1] == pytest.approx(P + KN / (2 * R) * ea[-1], rel=0.03)
    assert hold_error(res, window=0.001) < 0.01
    np.testing.assert_allclose(cell.lengths[:2], lx0, rtol=1e-5)


@pytest.fixture(scope="module")
def dense_pack():
    side = 0.035
    x, r = tdem.pack.random3d((0, 0, 0), (side,) * 3, 0.0020, 0.0030, seed=1,
                              target_fraction=0.45)
    sim = tdem.Simulation(dim=3, gravity=(0.0, 0.0, 0.0), local_damping=0.7, progress=False)
    law = tdem.LinearContact(kn=1e5, ks=1e5, friction=0.0)
    sim.add_particles(x, r, density=2650.0, contact=law)
    cell = tdem.TriaxialCell(sim, (0, 0, 0), (side,) * 3,
                             tdem.LinearContact(kn=1e5, ks=0.0, friction=0.0))
    cell.consolidate(1e5)             # frictionless: dense
    law.update(friction=0.3)
    cell.consolidate(1e5)
    return cell, law


def test_cell_holds_sigma3_while_it_shears(dense_pack):
    cell, law = dense_pack
    assert 200 <= cell.sim.n_particles <= 400
    n0 = cell.porosity()
    res = cell.compress(strain_rate=0.5, axial_strain=0.06, record_every=20, measure_every=25)
    lateral = res["sigma"][:, :2]
    assert hold_error(res) < 0.01
    assert np.abs(lateral / 1e5 - 1.0).max() < 0.02
    assert np.all(res["target"] == 1e5)
    phi = friction_angles(res)
    # a dense pack mobilises friction and dilates
    assert phi["phi_peak"] > 15.0
    assert res["volumetric_strain"][-1] < 0.0
    assert res["q"].max() > 0.5e5
    assert cell.porosity() > n0
    # the measured stress of the inner region follows the walls' axial stress
    assert len(res["measured_sigma"]) >= 2
    k = np.searchsorted(res["axial_strain"], res["measured_axial_strain"])
    k = np.minimum(k, len(res["axial_strain"]) - 1)
    ratio = res["measured_sigma"][:, 2, 2] / res["sigma1"][k]
    assert np.all((ratio > 0.8) & (ratio < 1.3))


def test_cell_holds_the_mean_stress(dense_pack):
    """The constant-p path from where the σ3 test ended (the tests share the pack):
    p = (σ1 + σ2 + σ3)/3 within 1 % (means over 0.5 % of axial strain)."""
    cell, law = dense_pack
    cell.consolidate(1e5)
    res = cell.compress(strain_rate=0.5, axial_strain=0.04, hold="p", record_every=20)
    assert hold_error(res) < 0.01
    assert np.abs(res["p"] / 1e5 - 1.0).max() < 0.03
    assert res["q"].max() > 0.3e5
    assert res["sigma3"][-1] < 0.95e5         # the lateral walls gave way


def test_cell_refuses_bad_input():
    sim2 = tdem.Simulation(progress=False)
    law = tdem.LinearContact(kn=1e5)
    with pytest.raises(tdem.InputError, match="sim must be a 3D"):
        tdem.TriaxialCell(sim2, (0, 0, 0), (1, 1, 1), law)
    sim = tdem.Simulation(dim=3, gravity=(0.0, 0.0, 0.0), progress=False)
    with pytest.raises(tdem.InputError, match="upper must exceed lower"):
        tdem.TriaxialCell(sim, (0, 0, 0), (1, 0, 1), law)
    with pytest.raises(tdem.InputError, match="overhang"):
        tdem.TriaxialCell(sim, (0, 0, 0), (1, 1, 1), law, overhang=-1)
    with pytest.raises(tdem.InputError, match="margin"):
        tdem.TriaxialCell(sim, (0, 0, 0), (1, 1, 1), law, margin="a")
    x = tdem.pack.lattice3d((0, 0, 0), (0.04, 0.04, 0.04), R, kind="cubic")
    sim.add_particles(x, R, density=2500.0, contact=law)
    cell = tdem.TriaxialCell(sim, (0, 0, 0), (0.04, 0.04, 0.04), law)
    assert len(cell.walls) == 6
    for bad, match in (({"p": -1.0}, "p must be a positive"),
                       ({"p": 1e4, "relaxation": 1.5}, "relaxation must lie in"),
                       ({"p": 1e4, "chunk": 0}, "chunk must be a whole number")):
        with pytest.raises(tdem.InputError, match=match):
            cell.consolidate(**bad)
    with pytest.raises(tdem.InputError, match="stress must be given"):
        cell.compress(0.1, 0.01)
    for bad, match in (({"hold": "q"}, "hold must be one of"),
                       ({"strain_rate": 0.0}, "strain_rate must be a positive"),
                       ({"axial_strain": 1.0}, r"axial_strain must lie in \(0, 1\)"),
                       ({"integral_gain": 2.0}, "integral_gain"),
                       ({"record_every": 2.5}, "record_every must be a whole number"),
                       ({"measure_every": 0}, "measure_every")):
        args = {"strain_rate": 0.1, "axial_strain": 0.01, "stress": 1e4, **bad}
        with pytest.raises(tdem.InputError, match=match):
            cell.compress(**args)
    with pytest.raises(tdem.InputError, match="margin=.*leaves no box"):
        cell.measured_stress(margin=0.05)
    assert sim.steps == 0
    assert math.isfinite(cell.void_ratio())


def test_triaxial_3d_case_small(tmp_path):
    """cases/triaxial_3d.py end to end on a small specimen: its summary follows the
    schema, σ3 is held within 1 %, the plots are written."""
    from cases import _common as common
    from cases import triaxial_3d
    s = triaxial_3d.main(["--material", "none", "--spheres", "150", "--axial-strain", "0.03",
                          "--out", str(tmp_path)])
    assert common.validate(s) == []
    checks = common.checks_by_name(s)
    assert checks["hold_none"]["pass"] is True
    assert checks["hold_none"]["value"] < 0.01
    assert s["variant"] == "none-spheres-150-axial_strain-0.03"
    for png in ("triaxial_curves.png", "friction_angles.png"):
        assert (tmp_path / png).stat().st_size > 10000
    with pytest.raises(tdem.InputError, match="spheres must be a positive"):
        triaxial_3d.main(["--spheres", "-5", "--out", str(tmp_path)])
