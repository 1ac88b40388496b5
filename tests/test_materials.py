"""Continuum materials (physics/materials.py): parameters, table rows and the
Mohr–Coulomb + tension cut-off correction of Feng, Li & Oñate (2015), Eq. 12.

Stress tension-positive, s = (σxx, σyy, σxy, σzz); principal σ1 ≤ σ2 ≤ σ3;
f_s = σ1 − σ3 N_φ + 2c sqrt(N_φ) ≥ 0 and f_t = σ3 − T ≤ 0 inside.
Reference material: E = 30 GPa, ν = 0.25, c = 3 MPa, φ = 40°, T = 1 MPa.
"""
import math

import numpy as np
import pytest
import taichi as ti

import tdem
from physics.materials import MAT_WIDTH, Elastic, Fluid, Material, MohrCoulomb, mc_correct_state
from tdem import backend
from tdem.errors import InputError

E, NU, C, PHI, T = 30e9, 0.25, 3e6, 40.0, 1e6


@ti.kernel
def _correct(matp: ti.types.ndarray(), m: ti.i32, failed: ti.i32, s: ti.types.ndarray(),
             out: ti.types.ndarray(), eps: ti.types.ndarray(), flag: ti.types.ndarray()):
    for i in range(s.shape[0]):
        v = ti.Vector([s[i, 0], s[i, 1], s[i, 2], s[i, 3]])
        o, e, f = mc_correct_state(v, matp, m, failed)
        for k in ti.static(range(4)):
            out[i, k] = o[k]
        eps[i] = e
        flag[i] = f


def correct(materials, trials, m=0, failed=0):
    """Run mc_correct over trial stresses (N, 4) with material m of the table."""
    backend.init()
    matp = np.array([mat.row() for mat in materials], dtype=np.float64)
    s = np.ascontiguousarray(np.atleast_2d(trials), dtype=np.float64)
    out = np.zeros_like(s)
    eps = np.zeros(len(s))
    flag = np.zeros(len(s), dtype=np.int32)
    _correct(matp, m, failed, s, out, eps, flag)
    return out, eps, flag


def principal(s):
    """Sorted principal stresses (N, 3) of stress vectors (N, 4)."""
    s = np.atleast_2d(s)
    cen = 0.5 * (s[:, 0] + s[:, 1])
    rad = np.hypot(0.5 * (s[:, 0] - s[:, 1]), s[:, 2])
    return np.sort(np.stack([cen - rad, cen + rad, s[:, 3]], axis=1), axis=1)


def from_principal(a, b, z, theta_deg):
    """Stress vector with in-plane principals a ≤ b, b at angle θ from x, σzz = z."""
    t = math.radians(2.0 * theta_deg)
    cen, rad = 0.5 * (a + b), 0.5 * (b - a)
    return np.array([cen + rad * math.cos(t), cen - rad * math.cos(t), rad * math.sin(t), z])


def yield_values(mat, s):
    p = principal(s)
    nphi = mat.n_phi
    fs = p[:, 0] - p[:, 2] * nphi + 2.0 * mat.cohesion * math.sqrt(nphi)
    ft = p[:, 2] - mat.tension
    return fs, ft


def moduli(mat):
    K, G = mat.bulk, mat.shear
    return K + 4.0 * G / 3.0, K - 2.0 * G / 3.0


def mc(**kw):
    args = dict(density=2500, young=E, poisson=NU, cohesion=C, friction_angle=PHI,
                tensile_strength=T)
    args.update(kw)
    return MohrCoulomb(**args)


# ------------------------------------------------------------------ parameters
def test_derived_moduli_and_wave_speed():
    el = Elastic(density=2500, young=E, poisson=NU)
    assert el.bulk == pytest.approx(E / (3 * (1 - 2 * NU)), rel=1e-15)   # 20 GPa
    assert el.shear == pytest.approx(E / (2 * (1 + NU)), rel=1e-15)      # 12 GPa
    assert el.p_wave_speed == pytest.approx(math.sqrt((20e9 + 16e9) / 2500), rel=1e-14)
    w = Fluid(density=1000, bulk_modulus=2e9)
    assert w.shear == 0.0 and w.bulk == 2e9
    assert w.p_wave_speed == pytest.approx(math.sqrt(2e9 / 1000), rel=1e-15)
    m = mc()
    assert m.n_phi == pytest.approx((1 + math.sin(math.radians(40))) /
                                    (1 - math.sin(math.radians(40))), rel=1e-15)
    assert m.compressive_strength == pytest.approx(
        2 * C * math.cos(math.radians(40)) / (1 - math.sin(math.radians(40))), rel=1e-14)


def test_rows_and_round_trip():
    mats = [Elastic(), mc(dilation_angle=10, brittle=True, residual_cohesion=1e6,
                          residual_tensile_strength=0.5e6), Fluid(viscosity=1e-3)]
    for mat in mats:
        r = mat.row()
        assert len(r) == MAT_WIDTH and all(isinstance(v, float) for v in r)
        back = Material.from_dict(mat.to_dict())
        assert back == mat and back.row() == r
    assert [m.row()[0] for m in mats] == [0.0, 1.0, 2.0]
    r = mats[1].row()
    assert r[4] == C and r[5] == T and r[8] == 1.0 and r[9] == 1e6 and r[10] == 0.5e6
    assert r[7] == pytest.approx(mats[1].n_psi) and r[3] == mats[1].shear
    assert mats[2].row()[3] == 0.0 and mats[2].row()[11] == 1e-3
    assert tdem.InputError is InputError


def test_tension_cut_off_is_capped_at_apex():
    """T > c/tan φ is capped (FLAC): c = 1 MPa, φ = 40° → T_max = 1.19175 MPa."""
    m = mc(cohesion=1e6, tensile_strength=5e6)
    cap = 1e6 / math.tan(math.radians(40))
    assert m.tensile_strength == 5e6                       # the value given is kept
    assert m.tension == pytest.approx(cap, rel=1e-15) and m.row()[5] == m.tension
    assert mc(friction_angle=0, tensile_strength=5e6).tension == 5e6   # φ = 0: no cap


BAD = [
    (Elastic, "density", 0), (Elastic, "density", -1.0), (Elastic, "density", float("nan")),
    (Elastic, "young", 0), (Elastic, "young", -3e9), (Elastic, "young", "stiff"),
    (Elastic, "poisson", 0.5), (Elastic, "poisson", -1.0), (Elastic, "poisson", 0.7),
    (MohrCoulomb, "cohesion", -1.0), (MohrCoulomb, "friction_angle", 90),
    (MohrCoulomb, "friction_angle", -5), (MohrCoulomb, "tensile_strength", -1e6),
    (MohrCoulomb, "dilation_angle", -1), (MohrCoulomb, "dilation_angle", 45),
    (MohrCoulomb, "brittle", "yes"), (MohrCoulomb, "residual_cohesion", -1),
    (MohrCoulomb, "residual_cohesion", 4e6), (MohrCoulomb, "residual_tensile_strength", 4e6),
    (MohrCoulomb, "poisson", 0.5), (MohrCoulomb, "density", 0),
    (Fluid, "density", -1000), (Fluid, "bulk_modulus", 0), (Fluid, "viscosity", -1e-3),
]


@pytest.mark.parametrize("cls, arg, value", BAD, ids=[f"{c.__name__}-{a}-{v}" for c, a, v in BAD])
def test_bad_input_names_argument_and_value(cls, arg, value):
    with pytest.raises(InputError) as e:
        cls(**{arg: value})
    assert arg in str(e.value) and repr(value) in str(e.value)


def test_no_shear_strength_at_all_is_rejected():
    with pytest.raises(InputError, match="cohesion"):
        mc(cohesion=0, friction_angle=0)


# ------------------------------------------------------------------ correction
def test_random_trials_end_on_or_inside_the_surface():
    """4000 random trials per material → every corrected stress has
    f_s ≥ −1e-9·scale and f_t ≤ 1e-9·scale; failing trials end on the surface
    (max(−f_s, f_t) = 0 within 1e-9·scale); inside ones come back bitwise."""
    rng = np.random.default_rng(7)
    n = 4000
    mats = [mc(), mc(dilation_angle=20), mc(friction_angle=30, tensile_strength=1e7),
            mc(friction_angle=0, tensile_strength=2e6), mc(poisson=-0.3, dilation_angle=40)]
    for k, mat in enumerate(mats):
        trials = rng.normal(0.0, 1.0, (n, 4)) * np.array([1.5e7, 1.5e7, 6e6, 1.5e7])
        trials[: n // 4] -= 2e7                       # some confined ones
        trials[n // 4: n // 2] += 5e6                 # some in tension
        trials[n // 2: n // 2 + 200, 3] = trials[n // 2: n // 2 + 200, 1]   # σzz = σyy edges
        out, eps, flag = correct(mats, trials, m=k)
        scale = np.abs(principal(trials)).max(axis=1) + mat.cohesion
        fs0, ft0 = yield_values(mat, trials)
        inside = (fs0 >= 0) & (ft0 <= 0)
        assert 0 < inside.sum() < n
        fs, ft = yield_values(mat, out)
        assert (fs >= -1e-9 * scale).all(), (k, (fs / scale).min())
        assert (ft <= 1e-9 * scale).all(), (k, (ft / scale).max())
        on = np.maximum(-fs, ft)[~inside] / scale[~inside]
        assert np.abs(on).max() < 1e-9, k
        assert np.array_equal(out[inside], trials[inside])           # bitwise
        assert (flag[inside] == 0).all() and (eps[inside] == 0).all()
        assert (flag[~inside] > 0).all()
        assert (eps[flag == 1] > 0).all() and (eps >= 0).all()


def test_flac_shear_return_by_hand():
    """ψ = 0, trial principals (−30, −5.5, −2) MPa, θ = 25°: FLAC's formulas give
    λ = f_s/(2G(1 + N_φ)), σ1 = σ1ᴵ − 2Gλ, σ2 unchanged, σ3 = σ3ᴵ + 2Gλ."""
    mat = mc()
    a1, a2 = moduli(mat)
    nphi, npsi = mat.n_phi, mat.n_psi
    s1, s2, s3 = -30e6, -5.5e6, -2e6
    fs = s1 - s3 * nphi + 2 * C * math.sqrt(nphi)
    assert fs < 0
    lam = fs / ((a1 - a2 * npsi) - (a2 - a1 * npsi) * nphi)
    e1 = s1 - lam * (a1 - a2 * npsi)
    e2 = s2 - lam * a2 * (1 - npsi)
    e3 = s3 - lam * (a2 - a1 * npsi)
    assert lam == pytest.approx(fs / (2 * mat.shear * (1 + nphi)), rel=1e-12)
    trial = from_principal(s1, s3, s2, 25.0)
    out, eps, flag = correct([mat], trial)
    expect = from_principal(e1, e3, e2, 25.0)
    np.testing.assert_allclose(out[0], expect, rtol=1e-9, atol=1e-9 * 30e6)
    assert flag[0] == 1
    # FLAC's Δe^ps with Δε1 = λ, Δε3 = −λ N_ψ
    d1, d3 = lam, -lam * npsi
    dm = (d1 + d3) / 3
    want = math.sqrt(0.5 * (d1 - dm) ** 2 + 0.5 * dm ** 2 + 0.5 * (d3 - dm) ** 2)
    assert eps[0] == pytest.approx(want, rel=1e-9) and want > 0


def test_shear_return_with_sigma_zz_as_each_principal():
    """The same (σ1, σ3) pair with σzz as minor, intermediate and major stress."""
    mat = mc()
    a1, a2 = moduli(mat)
    nphi = mat.n_phi
    # principal values (−30, −12, −2) MPa; the shear return touches σ1 and σ3 only
    vals = (-30e6, -12e6, -2e6)
    fs = vals[0] - vals[2] * nphi + 2 * C * math.sqrt(nphi)
    lam = fs / ((a1 - a2) - (a2 - a1) * nphi)
    new = (vals[0] - lam * (a1 - a2), vals[1], vals[2] - lam * (a2 - a1))
    for zpos in range(3):
        inplane = [v for q, v in enumerate(vals) if q != zpos]
        new_in = [v for q, v in enumerate(new) if q != zpos]
        trial = from_principal(inplane[0], inplane[1], vals[zpos], -40.0)
        out, eps, flag = correct([mat], trial)
        expect = from_principal(new_in[0], new_in[1], new[zpos], -40.0)
        np.testing.assert_allclose(out[0], expect, rtol=1e-9, atol=1e-9 * 30e6)
        assert flag[0] == 1


def test_flac_tension_return_by_hand():
    """Trial principals (−1, 0, 3) MPa, σ3 in-plane, T = 1 MPa: h > 0 → tension:
    σ3 = T, σ1 and σ2 lowered by (σ3ᴵ − T)·α2/α1 = 2 MPa·ν/(1 − ν) = 0.6667 MPa."""
    mat = mc()
    a1, a2 = moduli(mat)
    assert a2 / a1 == pytest.approx(NU / (1 - NU), rel=1e-14)
    trial = from_principal(-1e6, 3e6, 0.0, 60.0)
    out, eps, flag = correct([mat], trial)
    d = (3e6 - T) * a2 / a1
    expect = from_principal(-1e6 - d, T, -d, 60.0)
    np.testing.assert_allclose(out[0], expect, rtol=1e-9, atol=1e-9 * 3e6)
    assert flag[0] == 2 and eps[0] == 0.0
    fs, ft = yield_values(mat, out)
    assert fs[0] > 0 and ft[0] == pytest.approx(0.0, abs=1e-9 * 3e6)


def test_corner_near_apex_by_hand():
    """Trial σ1 = σᴾ + 0.5 MPa, σ2 = σᴾ + 3 MPa (σzz), σ3 = T + 5 MPa, ψ = 0,
    σᴾ = T N_φ − 2c sqrt(N_φ). FLAC's tension return alone would leave σ1 < σᴾ
    (shear violated); the stress returns to the apex of the (σ1, σ3) lines:
    σ1 = σᴾ, σ3 = T, with γ_s, γ_t ≥ 0 from
      σ1ᴵ + 2G γ_s − α2 γ_t = σᴾ,  σ3ᴵ − 2G γ_s − α1 γ_t = T,  σ2 = σ2ᴵ − α2 γ_t."""
    mat = mc()
    a1, a2 = moduli(mat)
    G, nphi = mat.shear, mat.n_phi
    sp = T * nphi - 2 * C * math.sqrt(nphi)
    s1, s2, s3 = sp + 0.5e6, sp + 3e6, T + 5e6
    # FLAC's domain: tension, and the tension return alone violates shear
    h = s3 - T + (math.sqrt(1 + nphi ** 2) + nphi) * (s1 - sp)
    assert h > 0 and s1 - (s3 - T) * a2 / a1 < sp
    A = np.array([[2 * G, -a2], [-2 * G, -a1]])
    gs, gt = np.linalg.solve(A, [sp - s1, T - s3])
    assert gs > 0 and gt > 0
    e2 = s2 - a2 * gt
    assert sp < e2 < T
    trial = from_principal(s1, s3, s2, 10.0)
    out, eps, flag = correct([mat], trial)
    expect = from_principal(sp, T, e2, 10.0)
    np.testing.assert_allclose(out[0], expect, rtol=1e-9, atol=1e-9 * 1e7)
    assert flag[0] == 1 and eps[0] == pytest.approx(gs, rel=1e-9)  # Δe^ps = γ_s for ψ = 0


def test_elastic_and_fluid_rows_unchanged():
    rng = np.random.default_rng(1)
    trials = rng.normal(0, 1e8, (500, 4))
    for k in (0, 2):
        out, eps, flag = correct([Elastic(), mc(), Fluid()], trials, m=k)
        assert np.array_equal(out, trials) and (eps == 0).all() and (flag == 0).all()


def test_dilation_changes_mean_stress_as_the_flow_rule_says():
    """Shear return: Δσ_mean = −K·Δε_v^p, Δε_v^p = λ(1 − N_ψ). ψ = 0: mean stress
    unchanged (to 1e-12 relative); ψ = 20°: the formula's value (−0.561 MPa for
    the trial principals (−30, −5.5, −2) MPa), to 1e-9."""
    trial = from_principal(-30e6, -2e6, -5.5e6, 0.0)
    for psi in (0.0, 20.0):
        mat = mc(dilation_angle=psi)
        a1, a2 = moduli(mat)
        nphi, npsi = mat.n_phi, mat.n_psi
        s1, s3 = -30e6, -2e6
        lam = (s1 - s3 * nphi + 2 * C * math.sqrt(nphi)) / \
            ((a1 - a2 * npsi) - (a2 - a1 * npsi) * nphi)
        out, eps, flag = correct([mat], trial)
        dmean = (out[0, 0] + out[0, 1] + out[0, 3] - trial[0] - trial[1] - trial[3]) / 3
        want = -mat.bulk * lam * (1 - npsi)
        if psi == 0.0:
            assert abs(dmean) < 1e-12 * 30e6
        else:
            # plastic dilation Δε_v^p = λ(1 − N_ψ) > 0 (λ < 0) makes the mean more compressive
            assert lam * (1 - npsi) > 0 and want < -1e5
            assert dmean == pytest.approx(want, rel=1e-9)
        fs, ft = yield_values(mat, out)
        assert abs(fs[0]) < 1e-9 * 30e6


def test_brittle_softening_uses_residual_strength():
    """A failed particle of a brittle material checks against c_r, T_r."""
    mat = mc(brittle=True, residual_cohesion=1e6, residual_tensile_strength=0.2e6)
    trial = from_principal(-12e6, -1e6, -4e6, 0.0)
    out0, _, flag0 = correct([mat], trial, failed=0)
    assert flag0[0] == 0 and np.array_equal(out0[0], trial)       # intact: inside
    out1, eps1, flag1 = correct([mat], trial, failed=1)
    assert flag1[0] == 1 and eps1[0] > 0
    p = principal(out1)[0]
    fs = p[0] - p[2] * mat.n_phi + 2e6 * math.sqrt(mat.n_phi)
    assert abs(fs) < 1e-9 * 12e6
    # a non-brittle material ignores the flag
    out2, _, flag2 = correct([mc()], trial, failed=1)
    assert flag2[0] == 0


def test_uniaxial_plane_strain_peak_is_the_mc_strength():
    """Strain-driven uniaxial compression in plane strain (Δε_yy = −2e-6 a step,
    σxx = 0 kept on the corrected stress by solving for Δε_xx, σzz from plane strain):
    the corrected |σyy| never exceeds 2c cos φ/(1 − sin φ) = 12.867 MPa by more
    than 1e-9 relative, and reaches it (plateau within 1e-6)."""
    mat = mc(tensile_strength=1e6)
    a1, a2 = moduli(mat)
    ucs = 2 * C * math.cos(math.radians(PHI)) / (1 - math.sin(math.radians(PHI)))
    s = np.zeros(4)
    peak = 0.0
    for step in range(700):
        dy = -2e-6

        def trial(dx):
            return s + np.array([a1 * dx + a2 * dy, a2 * dx + a1 * dy, 0.0, a2 * (dx + dy)])

        # σxx(corrected) is piecewise linear in Δε_xx: secant iterations
        x0, x1 = 0.0, -(s[0] + a2 * dy) / a1
        f0 = correct([mat], trial(x0))[0][0, 0]
        for _ in range(30):
            out = correct([mat], trial(x1))[0][0]
            f1 = out[0]
            if abs(f1) < 1e-9 * ucs or f1 == f0:
                break
            x0, x1, f0 = x1, x1 - f1 * (x1 - x0) / (f1 - f0), f1
        assert abs(out[0]) < 1e-6 * ucs
        s = out
        peak = max(peak, -s[1])
        assert -s[1] <= ucs * (1 + 1e-9)
    assert peak == pytest.approx(ucs, rel=1e-6)
