"""Chung & Ooi (2011) impact benchmarks (cases/impact_benchmarks.py).

References: Hertz (contact time, peak force, peak overlap) for the elastic normal
impacts of Tests 1-2, the restitution asked for Test 3, and the Coulomb rigid-body
solution of the sliding regime for Tests 4-8 (rebound tangential velocity
v_t - mu (1 + e) v_n and spin change (5/2) mu (1 + e) v_n), module docstring.
"""
import json
import math

import pytest

from cases import _common as common
from cases import impact_benchmarks as ib


# ------------------------------------------------------------------ analytic parts
def test_equivalent_law_of_one_material_is_the_material():
    m = ib.MATERIALS["al_alloy"]
    young, nu = ib.equivalent_law(m, m)
    assert young == pytest.approx(m.young, rel=1e-12)
    assert nu == pytest.approx(m.poisson, rel=1e-12)


def test_equivalent_law_of_a_rigid_plane_has_the_pairs_moduli():
    m = ib.MATERIALS["al_oxide"]
    young, nu = ib.equivalent_law(m)
    assert (young, nu) == pytest.approx((2.0 * m.young, m.poisson), rel=1e-12)
    law = ib.tdem.HertzMindlin(young=young, poisson=nu)
    e_star, g_star = ib.pair_moduli(m)
    assert law.e_star == pytest.approx(m.young / (1 - m.poisson ** 2), rel=1e-12)
    assert (law.e_star, law.g_star) == pytest.approx((e_star, g_star), rel=1e-12)


def test_equivalent_law_of_two_materials_gives_their_e_star_and_g_star():
    a, b = ib.MATERIALS["steel"], ib.MATERIALS["nylon"]
    young, nu = ib.equivalent_law(a, b)
    law = ib.tdem.HertzMindlin(young=young, poisson=nu)
    assert (law.e_star, law.g_star) == pytest.approx(ib.pair_moduli(a, b), rel=1e-12)


def test_hertz_reference():
    """Test 1, glass: E* = E/(2(1 - nu^2)), R* = R/2, m* = m/2, v = 20 m/s."""
    m = ib.MATERIALS["glass"]
    r = 0.010
    mass = m.density * 4 / 3 * math.pi * r ** 3
    h = ib.hertz(m.young / (2 * (1 - m.poisson ** 2)), r / 2, mass / 2, 20.0)
    assert h["overlap"] == pytest.approx(2.741e-4, rel=1e-3)
    assert h["force"] == pytest.approx(1.0697e4, rel=1e-3)
    assert h["time"] == pytest.approx(2.9433 * h["overlap"] / 20.0, rel=1e-4)
    tau, f, u = ib.hertz_curve()
    assert tau[-1] == pytest.approx(1.0)
    assert f.max() == pytest.approx(1.0, abs=1e-4)
    assert tau[f.argmax()] == pytest.approx(0.5, abs=0.01)


def test_rigid_body_regimes():
    """Sliding from tan(theta) = 3.5 mu (1 + e): J_t = mu J_n, the slip never stops;
    below, the contact point stops (on a plane v_t' = (5/7) v_t)."""
    m, r, vn, mu, e = 1.0, 0.1, 1.0, 0.2, 0.5
    limit = 3.5 * mu * (1 + e)
    slide = ib.rigid_body(m, r, vn, 1.01 * limit * vn, mu, e)
    assert slide["sliding"] and slide["slip"] > 0
    assert slide["dv1"] == pytest.approx(-mu * (1 + e) * vn)
    assert slide["dwr1"] == pytest.approx(2.5 * mu * (1 + e) * vn)
    stick = ib.rigid_body(m, r, vn, 0.5 * limit * vn, mu, e)
    assert not stick["sliding"] and stick["slip"] == pytest.approx(0.0, abs=1e-12)
    assert 0.5 * limit * vn + stick["dv1"] == pytest.approx(5 / 7 * 0.5 * limit * vn)
    # two equal free spheres: the same threshold in the relative slip and normal speed
    two = ib.rigid_body(m, r, 2 * vn, 1.01 * limit * 2 * vn, mu, e, m, r)
    assert two["sliding"] and two["dv1"] == pytest.approx(-mu * (1 + e) * vn)
    assert two["dv2"] == pytest.approx(mu * (1 + e) * vn)


# ------------------------------------------------------------------ Tests 1-3
@pytest.mark.parametrize("test, material", [(1, "glass"), (2, "mg_alloy")])
def test_normal_impact_against_hertz(test, material):
    r = ib.hertz_result(test, material, steps=200)
    h = r["hertz"]
    print(f"Test {test} {material}: t_c {r['contact_time']:.4g} / {h['time']:.4g}, "
          f"F {r['peak_force']:.4g} / {h['force']:.4g}, u {r['peak_overlap']:.4g} / "
          f"{h['overlap']:.4g}")
    assert r["contact_time"] == pytest.approx(h["time"], rel=0.02)
    assert r["peak_force"] == pytest.approx(h["force"], rel=0.02)
    assert r["peak_overlap"] == pytest.approx(h["overlap"], rel=0.02)
    assert r["rebound_ratio"] == pytest.approx(1.0, rel=0.03)


@pytest.mark.parametrize("material, e", [("al_oxide", 0.2), ("cast_iron", 0.6),
                                         ("al_oxide", 1.0)])
def test_restitution(material, e):
    r = ib.restitution_result(material, e)
    assert r["measured"] == pytest.approx(e, rel=0.03)


# ------------------------------------------------------------------ Tests 4-8
@pytest.mark.parametrize("test, material, angles", [
    (4, "al_oxide", (45.0, 65.0, 85.0)),
    (5, "steel", (70.0, 80.0)),
    (6, "nylon", (70.0, 80.0)),
    (7, "copper", (70.0, 80.0)),
    (8, "al_alloy", (70.0, 80.0)),
])
def test_sliding_regime(test, material, angles):
    """Rebound tangential velocity and spin change of sphere 1 within 5 % of the
    Coulomb sliding solution across the incident angles, restitution within 3 %."""
    pts = ib.oblique_series(test, material, angles)
    cfg = ib.TESTS[test]
    for p in pts:
        assert p["sliding"], p["angle"]
        th = p["theory"]
        assert th["sliding"]
        assert p["vx"] == pytest.approx(p["vx0"] + th["dv1"], rel=0.05)
        assert p["dwr"] == pytest.approx(th["dwr1"], rel=0.05)
        assert p["restitution"] == pytest.approx(cfg["restitution"], rel=0.03)
        assert p["slip"] > 0          # the contact points still slide when they part
    if test != 4:       # constant normal speed: the sliding spin change is one value
        assert max(p["dwr"] for p in pts) - min(p["dwr"] for p in pts) < 1e-3 * pts[0]["dwr"]


def test_test4_below_the_sliding_angle_is_not_compared():
    """At 10 degrees (tan < 3.5 mu (1 + e)) the contact sticks: rigid theory says
    v_t'/v_t = 5/7; the compliant contact gives a value near it, not the sliding one."""
    p = ib.oblique_point(4, "al_oxide", 10.0)
    assert not p["sliding"] and not p["theory"]["sliding"]
    ratio = p["vx"] / p["vt"]
    sliding_value = 1 - ib.TESTS[4]["friction"] * (1 + 0.98) / math.tan(math.radians(10))
    assert abs(ratio - 5 / 7) < abs(ratio - sliding_value)
    assert 0.6 < ratio < 0.8


def test_compliant_reference_reverses_the_slip_where_it_follows_the_normal_speed():
    """Where 4 G*/E* K m* = 1 (K = 7/(2m) on a plane: G*/E* = 1/14), the slip obeys the
    same equation as the normal speed, s(t) = s0 u'(t)/v_n: an elastic impact without a
    friction limit gives the slip back reversed, s' = -s0 (to the lever arm's R - u/2,
    u/R = 4e-4 here)."""
    m, r, vn, s0 = 1.0, 0.1, 0.2, 0.05
    e_star = 1e11
    vx, w, _, _, ratio = ib.compliant_impact(m, r, vn, [s0], [0.0], e_star, e_star / 14.0,
                                             0.0, 1e9)
    assert ratio[0] == pytest.approx(1.0, abs=1e-6)
    slip = vx[0] - w[0] * r
    assert slip == pytest.approx(-s0, rel=2e-3)
    # and an impact with too little stiffness to turn the slip keeps its sign
    vx, w, _, _, _ = ib.compliant_impact(m, r, vn, [s0], [0.0], e_star, e_star / 200.0,
                                         0.0, 1e9)
    assert vx[0] - w[0] * r > 0.0


@pytest.mark.parametrize("test, material", [(6, "al_alloy"), (8, "nylon"), (4, "al_alloy")])
def test_compliant_reference_gives_the_coulomb_solution_where_the_contact_slides(
        test, material):
    angles = (75.0, 85.0)
    ref = ib.compliant_series(test, material, angles)
    for a, c in zip(angles, ref):
        th = ib.oblique_point_theory(test, material, a)
        assert th["sliding"]
        assert c["vx"] == pytest.approx(th["vx"], rel=5e-3, abs=1e-4 * th["vt"])
        assert c["wr"] == pytest.approx(th["wr"], rel=5e-3)


@pytest.mark.parametrize("test, material, angles", [
    (4, "al_oxide", (10.0, 25.0)),
    (5, "polyethylene", (10.0,)),
    (6, "al_alloy", (15.0, 30.0)),
    (7, "copper", (20.0,)),
    (8, "nylon", (20.0,)),
])
def test_sticking_regime_against_the_compliant_reference(test, material, angles):
    """Below the sliding regime the DEM rebound (tangential velocity and change of w R
    of sphere 1) is within 2 % of the initial slip of the compliant reference (0.9 % at
    most measured across Tests 4-8)."""
    pts = ib.oblique_series(test, material, angles)
    for p in pts:
        assert not p["sliding"]
        c = p["compliant"]
        assert abs(p["vx"] - c["vx"]) <= 0.02 * p["s0"], p["angle"]
        assert abs(p["wr"] - c["wr"]) <= 0.02 * p["s0"], p["angle"]
    by = {c["name"]: c for c in ib.sticking_checks(test, material, pts)}
    assert by[f"test{test}.{material}.sticking_spin_change"]["pass"] is True
    assert len(by[f"test{test}.{material}.sticking_rebound_tangential_velocity"]["value"]) == \
        len(angles)


def test_test7_counter_rotating_spheres_do_not_slide():
    p = ib.oblique_point(7, "al_alloy", 60.0, counter=True)
    assert p["theory"] is None and not p["sliding"]
    assert -p["wr"] / p["vt"] == pytest.approx(1.0, abs=1e-6)
    assert abs(p["vx"]) < 1e-9


def test_sliding_checks_compare_only_the_sliding_points():
    pts = ib.oblique_series(6, "al_alloy", (20.0, 75.0))
    checks = ib.sliding_checks(6, "al_alloy", pts)
    by = {c["name"]: c for c in checks}
    v = by["test6.al_alloy.sliding_rebound_tangential_velocity"]
    assert len(v["value"]) == 1 and v["pass"] is True
    assert by["test6.al_alloy.normal_restitution"]["pass"] is True
    assert len(by["test6.al_alloy.normal_restitution"]["value"]) == 2


# ------------------------------------------------------------------ the case
# (the whole quick preset: the tests above check its physics one by one, in the default run)
@pytest.mark.slow
def test_quick_preset_writes_a_passing_summary(tmp_path):
    s = ib.main(["--preset", "quick", "--out", str(tmp_path)])
    with open(tmp_path / "summary.json") as f:
        written = json.load(f)
    assert common.validate(written) == []
    assert written["pass"] is True, [c["name"] for c in written["checks"] if not c["pass"]]
    assert s["counts"]["failed"] == 0
    names = {c["name"] for c in written["checks"]}
    for test in range(1, 9):
        assert any(n.startswith(f"test{test}.") for n in names), test
    for test in range(4, 9):
        assert any(n.startswith(f"test{test}.") and ".sticking_" in n for n in names), test
    for png in ("test1_2_hertz", "test3_restitution", "test4_oblique", "test5_normalised",
                "test6_spin_plane", "test7_two_spheres", "test8_two_sizes"):
        assert (tmp_path / f"{png}.png").stat().st_size > 10_000
    assert (tmp_path / "histories.h5").exists()
