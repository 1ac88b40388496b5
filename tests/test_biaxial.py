"""Biaxial tests with rolling resistance (Jiang, Yu & Harris 2005, §5): specimen
preparation, servo-controlled confinement, friction angles, and the Dask sweep.

The default tests use small specimens (a few hundred discs) so that they run in a
couple of minutes; the tests on the paper's 1008-disc specimen are marked slow.
"""
import math
import multiprocessing

import numpy as np
import pytest

import tdem
from cases import biaxial
from cases import _specimen as specimen

SIGMA = 200e3


# ------------------------------------------------------------------ helpers
@pytest.fixture(scope="module")
def small(tmp_path_factory):
    """A 300-disc specimen consolidated to 200 kPa, saved (each test loads a copy)."""
    spec = specimen.prepare(n=300, confining=SIGMA, seed=3)
    path = tmp_path_factory.mktemp("biaxial") / "small.h5"
    spec.save(path)
    return spec, path


def test_gradation_matches_the_paper():
    d = specimen.gradation(5000, seed=1)
    g = specimen.grading(d)
    assert d.min() >= 6e-3 and d.max() <= 9e-3
    assert g["d50"] == pytest.approx(7.6e-3, rel=0.02)
    assert g["cu"] == pytest.approx(1.3, abs=0.03)


def test_prepared_specimen_reaches_its_void_ratio(small):
    spec, _ = small
    e = spec.void_ratio()
    sh, sv = spec.stresses()
    print(f"void ratio {e:.4f} (target 0.25); friction steps {spec.history['friction']}; "
          f"sigma_h {sh:.0f} Pa, sigma_v {sv:.0f} Pa")
    assert abs(e - 0.25) <= 0.01
    # at rest under the isotropic stress, friction back to the material's value
    assert spec.law.friction == 0.5
    assert spec.history["friction"][-1] == 0.5
    assert abs(sh / SIGMA - 1.0) < 0.05 and abs(sv / SIGMA - 1.0) < 0.05
    # stiff contacts: no overlap reaches 1 % of the smallest diameter at 200 kPa
    c = spec.sim.contacts.numpy()
    assert c["overlap"].max() < 0.01 * 6e-3


def test_servo_holds_sigma_h_through_shearing(small):
    _, path = small
    spec = specimen.Specimen.load(path)
    r = specimen.shear(spec, strain_rate=1.0, axial_strain=0.08)
    hold = biaxial.sigma_h_hold(r)          # largest error of 0.5 %-strain averages
    ea = r["axial_strain"]
    print(f"sigma_h held within {100 * hold:.2f} % over {100 * ea[-1]:.1f} % axial strain")
    assert ea[-1] >= 0.08
    assert hold < 0.02
    # the mean over the whole shearing stage is on target too
    assert np.mean(r["sigma_h"][ea > 0.005]) == pytest.approx(SIGMA, rel=0.01)
    # the vertical stress rises above sigma_h: the specimen is sheared
    phi = specimen.friction_angles(r)
    assert 10.0 < phi["phi_peak"] < 40.0
    assert r["sigma_v"].max() > 1.5 * SIGMA


def test_shear_with_rolling_resistance_runs_and_is_stronger(small):
    _, path = small
    out = {}
    for name, rolling in (("none", None), ("m1", tdem.RollingResistance(delta=1.6, model=1))):
        spec = specimen.Specimen.load(path)
        r = specimen.shear(spec, rolling=rolling, strain_rate=1.0, axial_strain=0.05)
        out[name] = specimen.friction_angles(r)["phi_peak"]
    print(f"small specimen, 5 % strain: phi peak none {out['none']:.1f}, "
          f"Model 1 delta 1.6 {out['m1']:.1f}")
    assert out["m1"] > out["none"] + 5.0


def test_bad_input_names_the_argument(small, tmp_path):
    with pytest.raises(tdem.InputError, match="void_ratio"):
        specimen.prepare(n=50, void_ratio=-0.1)
    with pytest.raises(tdem.InputError, match="n must"):
        specimen.prepare(n=2)
    with pytest.raises(tdem.InputError, match="cu"):
        specimen.gradation(10, cu=0.9)
    with pytest.raises(tdem.InputError, match="strain_rate"):
        specimen.shear(small[0], strain_rate=0.0)
    with pytest.raises(tdem.InputError, match="rolling"):
        specimen.shear(small[0], rolling=0.4)
    with pytest.raises(tdem.InputError, match="model"):
        biaxial.check_material(3, 0.4)
    with pytest.raises(tdem.InputError, match="delta"):
        biaxial.check_material(1, -0.4)
    with pytest.raises(ValueError, match="confining"):
        biaxial.main(["--confining", "-5", "--out", str(tmp_path)])
    with pytest.raises(ValueError, match="all_deltas"):
        biaxial.main(["--all-deltas", "--out", str(tmp_path)])


def test_friction_angle_formula():
    ea = np.linspace(0.0, 0.1, 101)
    sv = np.full(101, 3.0)
    sv[50] = 5.0   # one record, kept as it is without smoothing
    r = {"axial_strain": ea, "sigma_v": sv, "sigma_h": np.ones(101)}
    phi = specimen.friction_angles(r, smoothing=0.0)
    assert phi["phi_peak"] == pytest.approx(math.degrees(math.asin(4.0 / 6.0)))
    assert phi["phi_residual"] == pytest.approx(30.0)       # sin phi = 2/4


def test_phi_table_means_ranges_and_the_papers_values():
    """The sweep's sweep.md: per δ and model the mean and range of φ over the
    confining stresses; δ = 0 (no rolling resistance) in both models' columns, the
    paper's text values beside (24.4/19.3° at δ = 0, 26.5/20.7° for Model 2 at 0.4)."""
    def t(model, delta, s, pk, rs):
        return {"task": {"model": model, "delta": delta, "confining": s},
                "phi": {"phi_peak": pk, "phi_residual": rs}}
    tests = [t(1, 0.0, 1e5, 24.0, 20.0), t(1, 0.0, 2e5, 26.0, 22.0),
             t(1, 0.4, 1e5, 30.0, 25.0), t(1, 0.4, 2e5, 31.0, 27.0),
             t(2, 0.4, 1e5, 25.0, 21.0)]
    lines = biaxial.phi_table(tests).splitlines()
    assert len(lines) == 4
    assert lines[2] == ("| 0 | 25.0° (24.0–26.0), paper 24.4° | 21.0° (20.0–22.0), paper "
                        "19.3° | 25.0° (24.0–26.0), paper 24.4° | 21.0° (20.0–22.0), "
                        "paper 19.3° |")
    assert lines[3] == ("| 0.4 | 30.5° (30.0–31.0), paper 29.0° | 26.0° (25.0–27.0), "
                        "paper 23.0° | 25.0° (25.0–25.0), paper 26.5° | 21.0° "
                        "(21.0–21.0), paper 20.7° |")


# ------------------------------------------------------------------ the sweep
# (the sweep's machinery, on the quicker of the two preparations)
TINY = {"n": 120, "strain_rate": 2.0, "axial_strain": 0.03, "seed": 5}


def test_dask_sweep_equals_serial_runs():
    pytest.importorskip("distributed", reason='Dask is an extra: pip install "tdem[sweep]"')
    tasks = biaxial.sweep_tasks(dict(TINY, materials=[(0, 0.0), (1, 0.4)]),
                                confining=(SIGMA,), preparation="friction")
    assert len(tasks) == 2
    swept = biaxial.run_sweep(tasks, workers=2)
    # the same tasks one after the other, in one fresh process
    ctx = multiprocessing.get_context("spawn")
    with ctx.Pool(1) as pool:
        serial = pool.apply(biaxial.run_serial, (tasks,))
    for a, b in zip(swept, serial):
        assert a["task"] == b["task"]
        print(f"{a['name']}: phi peak {a['phi']['phi_peak']:.6f} (Dask) "
              f"{b['phi']['phi_peak']:.6f} (serial)")
        assert a["phi"] == b["phi"]
        for k in ("sigma_v", "sigma_h", "axial_strain", "volumetric_strain"):
            np.testing.assert_array_equal(a["curves"][k], b["curves"][k])
    assert swept[0]["name"] == "none" and swept[1]["name"] == "model1_delta0.4"
    assert swept[0]["phi"] != swept[1]["phi"]


# ------------------------------------------------------------------ the paper's specimen
@pytest.fixture(scope="module")
def paper_runs(tmp_path_factory):
    """The paper's 1008-disc specimen at 100, 200, 400 kPa, compressed to 15 % at
    0.5 /s with no rolling resistance, Model 1 at delta = 0.4, 0.8, 1.6 and Model 2
    at delta = 0.4 (200 kPa) and the three Fig. 12 materials at 100 and 400 kPa."""
    folder = tmp_path_factory.mktemp("biaxial_paper")
    runs = {}
    base = {"n": 1008, "strain_rate": 0.5, "axial_strain": 0.15, "seed": 0}
    plan = [(SIGMA, m, d) for m, d in ((0, 0.0), (1, 0.4), (1, 0.8), (1, 1.6), (2, 0.4))]
    plan += [(s, m, d) for s in (100e3, 400e3) for m, d in biaxial.MATERIALS]
    for s, m, d in plan:
        r = biaxial.run_test(dict(base, confining=s, model=m, delta=d), specimen_dir=folder)
        runs[(s, m, d)] = r
        print(f"{s / 1e3:g} kPa {r['name']}: {r['phi']['phi_peak']:.2f}/"
              f"{r['phi']['phi_residual']:.2f} deg, sigma_h within {100 * r['hold']:.2f} %")
    return runs


@pytest.mark.slow
def test_paper_specimen_void_ratio_and_servo(paper_runs):
    for r in paper_runs.values():
        assert abs(r["before"]["void_ratio"] - 0.25) <= 0.01
        assert r["hold"] < 0.02


@pytest.mark.slow
def test_no_rolling_resistance_peak_angle(paper_runs):
    phi = paper_runs[(SIGMA, 0, 0.0)]["phi"]["phi_peak"]
    assert 20.0 <= phi <= 29.0          # the paper: 24.4


@pytest.mark.slow
def test_model1_raises_phi_monotonically_with_delta(paper_runs):
    phis = [paper_runs[(SIGMA, m, d)]["phi"]["phi_peak"]
            for m, d in ((0, 0.0), (1, 0.4), (1, 0.8), (1, 1.6))]
    assert np.all(np.diff(phis) > 0), phis


@pytest.mark.slow
def test_model2_between_none_and_model1(paper_runs):
    """Mean peak phi over the three confining stresses at delta = 0.4."""
    def mean(m, d):
        return np.mean([paper_runs[(s, m, d)]["phi"]["phi_peak"]
                        for s in (100e3, SIGMA, 400e3)])
    none, m1, m2 = mean(0, 0.0), mean(1, 0.4), mean(2, 0.4)
    print(f"mean peak phi: none {none:.2f}, Model 2 {m2:.2f}, Model 1 {m1:.2f}")
    assert none < m2 < m1


def test_sweep_keeps_each_test_and_goes_on_after_an_interruption(tmp_path):
    """Each test's result is written as it ends; started again, the sweep reads the
    tests it finds (here: one marked in its file, so that reading it back is seen)
    and runs the others, with the same numbers as a run without interruption."""
    pytest.importorskip("distributed", reason='Dask is an extra: pip install "tdem[sweep]"')
    tasks = biaxial.sweep_tasks(dict(TINY, materials=[(0, 0.0), (1, 0.4)]),
                                confining=(SIGMA,), preparation="friction")
    keep = tmp_path / "tests"
    first = biaxial.run_sweep(tasks, workers=2, keep=keep)
    files = [biaxial.result_file(keep, t) for t in tasks]
    assert all(f.exists() for f in files)
    back = [biaxial.load_results(f)[0] for f in files]
    for a, b in zip(first, back):
        assert a["task"] == b["task"] and a["name"] == b["name"] and a["phi"] == b["phi"]
        assert a["before"] == b["before"] and a["hold"] == b["hold"]
        for k, v in a["curves"].items():
            np.testing.assert_array_equal(np.asarray(v), np.asarray(b["curves"][k]))
    # the interruption: the second test's file lost, the first one's marked
    files[1].unlink()
    import h5py
    with h5py.File(files[0], "r+") as f:
        g = f[f"sigma{SIGMA / 1e3:g}kPa/{first[0]['name']}"]
        g.attrs["wall_s"] = -1.0
    again = biaxial.run_sweep(tasks, workers=2, keep=keep)
    assert again[0]["wall_s"] == -1.0                  # read back, not run again
    assert again[1]["wall_s"] > 0.0 and files[1].exists()
    assert again[1]["phi"] == first[1]["phi"]          # run again: the same numbers
    np.testing.assert_array_equal(again[1]["curves"]["sigma_v"], first[1]["curves"]["sigma_v"])


# ------------------------------------------------------------------ layered preparation
def test_layer_heights_follow_the_undercompaction_criterion():
    """h_i = (1 + e)[A_1 + ... + A_(i-1) + (1 + U_i) A_i]/W with U_i falling linearly
    from U_1 to 0: the last layer closes the specimen at the target void ratio."""
    areas = np.array([1.0, 1.2, 0.9, 1.1]) * 1e-3
    h = specimen.layer_heights(areas, 0.2, 0.25, 0.15)
    u = np.array([0.15, 0.10, 0.05, 0.0])
    below = np.concatenate([[0.0], np.cumsum(areas)[:-1]])
    np.testing.assert_allclose(h, 1.25 * (below + (1 + u) * areas) / 0.2, rtol=1e-14)
    assert h[-1] * 0.2 / areas.sum() - 1.0 == pytest.approx(0.25, rel=1e-14)
    assert np.all(np.diff(h) > 0)


@pytest.fixture(scope="module")
def layered():
    return specimen.prepare_layers(n=240, layers=4, seed=2, undercompaction=0.2, speed=1.0,
                                   check_every=50,
                                   compaction_friction=biaxial.COMPACTION_FRICTION)


def test_layered_specimen_is_made_at_its_void_ratio_and_is_homogeneous(layered):
    spec = layered
    e = spec.void_ratio()
    print(f"layers: heights {spec.history['layer_height']}, stresses "
          f"{spec.history['layer_stress']}, band void ratios {spec.history['band_void_ratio']}")
    assert e == pytest.approx(0.25, abs=1e-6)
    assert spec.width == pytest.approx(0.18, rel=1e-12)
    # every disc inside the box, and the material's friction throughout
    p = spec.sim.particles.numpy()
    x, r = p["position"], p["radius"]
    x0, x1, y0, y1 = spec.box()
    # (wall overlaps under the compaction stress are a few per cent of a radius)
    out = np.max([x0 - (x[:, 0] - r), x[:, 0] + r - x1, y0 - (x[:, 1] - r),
                  x[:, 1] + r - y1], axis=0) / r
    print(f"largest wall overlap {out.max():.3f} radii")
    assert out.max() < 0.1
    assert spec.law.friction == 0.5 and spec.history["compaction_friction"] == 0.245
    # the bands' void ratios, from the exact disc areas inside them, average to e
    # (less what the discs' overlaps with the walls put outside the box)
    bands = np.array(spec.history["band_void_ratio"])
    solid = 1.0 / (1.0 + bands)
    assert np.mean(solid) == pytest.approx(1.0 / (1.0 + e), rel=1e-3)
    # (layers under two rows thick here; the bands at the top and bottom walls hold
    # the wall's extra void, a row of discs against a flat face: up to 0.33 measured
    # at the top, the last layer pressed with no under-compaction)
    assert np.all(np.abs(bands[1:-1] - 0.25) < 0.05)
    assert np.all(np.abs(bands - 0.25) < 0.1)


def test_layered_specimen_consolidates_denser_at_a_higher_stress(layered, tmp_path):
    """One layered specimen brought to 100 and to 400 kPa: both at rest under their
    stress, the second denser (the same fabric, pressed harder)."""
    path = tmp_path / "layered.h5"
    layered.save(path)
    e = {}
    for s in (100e3, 400e3):
        spec = specimen.Specimen.load(path)
        spec.consolidate(s, max_speed=0.5)
        sh, sv = spec.stresses()
        assert abs(sh / s - 1.0) < 0.05 and abs(sv / s - 1.0) < 0.05
        e[s] = spec.void_ratio()
    print(f"void ratio {e[100e3]:.4f} at 100 kPa, {e[400e3]:.4f} at 400 kPa")
    assert e[400e3] < e[100e3]
    assert abs(e[100e3] - 0.25) < 0.03


def test_preparation_is_checked():
    with pytest.raises(tdem.InputError, match="preparation"):
        biaxial.specimen_key({"n": 10, "confining": 1e5, "preparation": "vibration"})
    with pytest.raises(tdem.InputError, match="layers"):
        specimen.prepare_layers(n=20, layers=0)


def test_sweep_over_seeds_and_rates():
    cfg = dict(TINY, materials=[(0, 0.0), (1, 0.4)])
    tasks = biaxial.sweep_tasks(cfg, confining=(100e3, 400e3), seeds=(0, 1, 2),
                                rates=(1.0, 0.25))
    assert len(tasks) == 3 * 2 * 2 * 2
    assert sorted({t["seed"] for t in tasks}) == [0, 1, 2]
    at = {(t["strain_rate"], t["confining"]) for t in tasks}
    # the inertial number of the rate at 200 kPa kept: rate ∝ sqrt(σ)
    assert at == {(1.0 * math.sqrt(0.5), 100e3), (1.0 * math.sqrt(2.0), 400e3),
                  (0.25 * math.sqrt(0.5), 100e3), (0.25 * math.sqrt(2.0), 400e3)}
    assert {round(biaxial.rate_at_200kpa(t), 12) for t in tasks} == {1.0, 0.25}
    for bad, match in (({"rates": (0.0,)}, "strain rates"), ({"seeds": (-1,)}, "seeds"),
                       ({"seeds": (1.5,)}, "seeds"), ({"confining": (float("nan"),)},
                                                      "confining")):
        with pytest.raises(tdem.InputError, match=match):
            biaxial.sweep_tasks(cfg, **bad)
    with pytest.raises(tdem.InputError, match="seeds: only with --sweep"):
        biaxial.main(["--seeds", "1", "2"])


def _test_result(seed, s, pk, rs, rate=0.1):
    """A no-rolling test at confining stress ``s`` whose peak and residual stresses
    give exactly these angles."""
    out = {"task": {"model": 0, "delta": 0.0, "confining": s, "seed": seed,
                    "strain_rate": rate * math.sqrt(s / 200e3)}, "name": "none", "phi": {}}
    for key, phi in (("peak", pk), ("residual", rs)):
        k = math.sin(math.radians(phi))
        sv = s * (1 + k) / (1 - k)
        out["phi"].update({f"phi_{key}": phi})
        if key == "peak":
            out["phi"].update(sigma_v_peak=sv, sigma_h_at_peak=s)
        else:
            out["phi"].update(sigma_v_residual=sv, sigma_h_residual=s)
    return out


def test_spread_table_means_deviations_and_envelope_slopes():
    """sweep.md over several specimens: φ as mean ± standard deviation (range, count)
    over the seeds; each seed's envelope slope fitted to its own tests."""
    r = _test_result
    res = [r(0, 100e3, 22.0, 18.0), r(0, 400e3, 22.0, 18.0),
           r(1, 100e3, 24.0, 20.0), r(1, 400e3, 24.0, 20.0)]
    text = biaxial.spread_table(res)
    assert "| none | 0.1 | 100 | 23.0° ± 1.4 (22.0–24.0, 2) | 19.0° ± 1.4 (18.0–20.0, 2) | " \
           "24.4° / 19.3° |" in text
    # each seed's envelope passes through the origin at its own angle: slopes 22 and 24
    assert "| none | 0.1 | 23.0° ± 1.4 (22.0–24.0, 2) | 19.0° ± 1.4 (18.0–20.0, 2) |" in text


def test_sweep_checks_compare_rate_by_rate_and_slopes_only_over_several_stresses(tmp_path):
    """A sweep over rates at one confining stress (the rate study): each rate compared
    on its own (pooled, a fit through tests at one stress read 90° before), and no
    envelope slope from one stress; over three stresses the slope is fitted (22° here,
    through the origin). rescore() makes a kept sweep's checks again from its summary."""
    res = [_test_result(s, 200e3, pk, pk - 4.0, rate)
           for rate, pk in ((1.0, 26.0), (0.1, 20.0)) for s in (0, 1)]
    checks = {c["name"]: c for c in biaxial.sweep_checks(res)}
    assert set(checks) == {"mean_phi_peak_none_rate1", "mean_phi_residual_none_rate1",
                           "mean_phi_peak_none_rate0.1", "mean_phi_residual_none_rate0.1"}
    assert checks["mean_phi_peak_none_rate1"]["value"] == pytest.approx(26.0)
    assert checks["mean_phi_peak_none_rate0.1"]["value"] == pytest.approx(20.0)
    assert "no envelope slope" in checks["mean_phi_peak_none_rate0.1"]["note"]
    three = [_test_result(0, s, 22.0, 18.0) for s in (100e3, 200e3, 400e3)]
    checks = {c["name"]: c for c in biaxial.sweep_checks(three)}
    assert checks["envelope_phi_peak_none"]["value"] == pytest.approx(22.0, abs=1e-9)
    assert checks["envelope_phi_peak_none"]["pass"] is False        # the paper: 24.4 ± 2
    # rescore: a kept summary's checks made again from its tests
    from cases import _common as common
    kept = common.summary("biaxial", "paper", [], {"mode": "sweep", "tests": [
        {"task": r["task"], "phi": r["phi"]} for r in res]}, 12.0, threads=1)
    common.write_summary(tmp_path, kept)
    again = biaxial.rescore(tmp_path)
    assert again["counts"]["checks"] == 4 and again["wall_time_s"] == 12.0


def test_materials_of_a_sweep_are_parsed_and_checked():
    assert biaxial.parse_material("1:0.4") == (1, 0.4)
    assert biaxial.parse_material("0:0") == (0, 0.0)
    with pytest.raises(tdem.InputError, match="MODEL:DELTA.*'1-0.4'"):
        biaxial.parse_material("1-0.4")
    with pytest.raises(tdem.InputError, match="model must be 0"):
        biaxial.parse_material("3:0.4")
    with pytest.raises(tdem.InputError, match="delta must be 0 without"):
        biaxial.parse_material("0:0.4")


def test_local_damping_of_the_compression_is_checked_and_named_in_the_results(tmp_path):
    tasks = biaxial.sweep_tasks(dict(TINY, materials=[(0, 0.0)]), confining=(1e5,),
                                local_damping=0.3)
    assert tasks[0]["local_damping"] == 0.3
    assert biaxial.result_file(tmp_path, tasks[0]).name.endswith("_damping0.3.h5")
    plain = biaxial.sweep_tasks(dict(TINY, materials=[(0, 0.0)]), confining=(1e5,))[0]
    assert "damping" not in biaxial.result_file(tmp_path, plain).name
    with pytest.raises(tdem.InputError, match="local_damping must lie in"):
        biaxial.run_test(dict(tasks[0], local_damping=1.2), spec=object())


def test_results_of_several_specimens_of_one_test_are_kept_apart(tmp_path):
    def r(seed, rate, pk):
        return {"task": {"model": 0, "delta": 0.0, "confining": 2e5, "seed": seed,
                         "strain_rate": rate}, "name": "none",
                "curves": {"axial_strain": np.linspace(0, 0.1, 5), "sigma_h_target": 2e5},
                "phi": {"phi_peak": pk, "phi_residual": pk - 3}, "before": {"void_ratio": 0.25},
                "hold": 0.001, "wall_s": 1.0}
    res = [r(0, 0.1, 20.0), r(1, 0.1, 21.0), r(0, 0.5, 22.0)]
    back = biaxial.load_results(biaxial.save_results(tmp_path / "s.h5", res))
    assert sorted((b["task"]["seed"], b["task"]["strain_rate"], b["phi"]["phi_peak"])
                  for b in back) == [(0, 0.1, 20.0), (0, 0.5, 22.0), (1, 0.1, 21.0)]
    assert {b["name"] for b in back} == {"none"}
