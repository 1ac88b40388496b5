"""The summary.json schema of the cases (cases/_common.py, docs/cases.md) and the
tables that cases.report makes from it."""
import json

import pytest

from cases import _common as common
from cases import report


# ------------------------------------------------------------------ checks
@pytest.mark.parametrize("value, target, tol, expected", [
    (0.394, 0.39, {"rel": 0.05}, True),          # 1.0 % off
    (0.42, 0.39, {"rel": 0.05}, False),          # 7.7 % off
    (-0.105e6, -0.11e6, {"rel": 0.05}, True),    # relative to |target|
    (24.1, 24.4, {"abs": 2.0}, True),
    (27.3, 35.8, {"abs": 2.0}, False),
    (0.52, None, {"min": 0.40, "max": 0.60}, True),
    (0.61, None, {"min": 0.40, "max": 0.60}, False),
    (0.019, None, {"max": 0.05}, True),
    (1.5, None, {"min": 1.0}, True),
    (0.99, None, {"min": 1.0}, False),
    ("slid", "stood", {"equal": True}, False),
    ("toppled", "toppled", {"equal": True}, True),
    (True, True, {"equal": True}, True),
    ([2.1, 5.6], [2.0, 6.0], {"abs": 1.0}, True),    # element by element
    ([2.1, 7.5], [2.0, 6.0], {"abs": 1.0}, False),
    ([0.8], [2.0, 6.0], {"abs": 1.0}, False),        # one band formed where two should
    (None, 0.46e-3, {"rel": 0.1}, False),            # not measured: fails
    (float("nan"), 0.3, {"abs": 0.05}, False),
    (0.2, 0.15, None, None),                          # reported only
])
def test_passes(value, target, tol, expected):
    assert common.passes(value, target, tol) is expected
    c = common.check("x", value, target, tol)
    assert c["pass"] is expected
    assert list(c) == list(common.CHECK_KEYS)


def test_check_refuses_a_tolerance_it_cannot_read():
    with pytest.raises(ValueError, match="tolerance"):
        common.check("x", 1.0, 1.0, {"rel": 0.1, "abs": 0.1})
    with pytest.raises(ValueError, match="needs a target"):
        common.check("x", 1.0, None, common.rel(0.1))
    with pytest.raises(ValueError):
        common.between()


def _summary(checks):
    return common.summary("wave_bar", "quick", checks, {"models": {"regular": {"count": 1}}},
                          52.4, threads=1)


def test_overall_pass_is_all_of_the_compared_checks():
    ok = common.check("a", 10.04, 10.0, common.rel(0.1), "m/s")
    bad = common.check("b", 2.32, 1.4, common.absolute(0.14), "m")
    info = common.check("c", 3900, 5043, None, "particles")
    assert _summary([ok, info])["pass"] is True
    s = _summary([ok, bad, info])
    assert s["pass"] is False
    assert s["counts"] == {"checks": 3, "passed": 1, "failed": 1, "reported": 1}
    assert _summary([info])["pass"] is None       # nothing compared
    assert common.validate(s) == []
    for key in common.SUMMARY_KEYS:
        assert key in s
    assert s["schema"] == common.SCHEMA and s["wall_time_s"] == pytest.approx(52.4)
    assert s["data"]["models"]["regular"]["count"] == 1
    assert json.loads(json.dumps(s)) == s          # plain JSON


def test_validate_finds_a_summary_that_does_not_follow_the_schema():
    ok = common.check("a", 10.04, 10.0, common.rel(0.1), "m/s")
    s = _summary([ok])
    s["checks"][0]["pass"] = False                 # does not follow from the numbers
    assert any("pass False" in p for p in common.validate(s))
    s = _summary([ok])
    s["pass"] = False
    assert any("all(check passes)" in p for p in common.validate(s))
    s = _summary([ok])
    del s["checks"][0]["unit"]
    assert common.validate(s)
    s = _summary([ok])
    del s["data"]
    assert "missing key 'data'" in common.validate(s)
    with pytest.raises(ValueError, match="named twice"):
        _summary([ok, ok])


def test_write_summary_refuses_a_broken_summary(tmp_path):
    s = _summary([common.check("a", 10.04, 10.0, common.rel(0.1), "m/s")])
    common.write_summary(tmp_path, s)
    assert json.loads((tmp_path / "summary.json").read_text()) == s
    s["pass"] = None
    with pytest.raises(ValueError, match="schema"):
        common.write_summary(tmp_path, s)


# ------------------------------------------------------------------ formatting
@pytest.mark.parametrize("check, value, target", [
    (common.check("p", 0.2645e-3, 0.46e-3, common.rel(0.1), "s"), "0.2645 ms", "0.46 ms ± 10 %"),
    (common.check("p", 438.9e6, 1369e6, None, "Pa"), "438.9 MPa", "1369 MPa (reported)"),
    (common.check("p", -6.5e3, None, None, "Pa"), "-6.500 kPa", "–"),
    (common.check("p", 32.31e9, 32e9, None, "Pa"), "32.31 GPa", "32 GPa (reported)"),
    (common.check("p", 24.11, 24.4, common.absolute(2.0), "deg"), "24.11°", "24.4 ± 2°"),
    (common.check("p", 0.0191, None, common.between(max=0.05)), "0.01910", "≤ 0.05"),
    (common.check("p", 0.52, None, common.between(0.4, 0.6), "s"), "0.5200 s", "0.4–0.6 s"),
    (common.check("p", 1e-8, 0.9, common.between(max=0.9), "%"), "1e-08 %", "≤ 0.9 %"),
    (common.check("p", "slid", "stood", common.EQUAL), "slid", "= stood"),
    (common.check("p", 1, 2, common.absolute(0)), "1", "= 2"),
    (common.check("p", None, 0.3, common.absolute(0.05), "m"), "–", "0.3 ± 0.05 m"),
])
def test_format(check, value, target):
    assert common.format_value(check) == value
    assert common.format_target(check) == target


# ------------------------------------------------------------------ report
def _given():
    checks = [common.check("regular.peak_velocity", 10.04, 10.0, common.rel(0.1), "m/s"),
              common.check("regular.arrival_time", 2.85e-3, 2.83e-3, common.rel(0.05), "s"),
              common.check("random.peak_stress", 70e6, 89.4e6, common.rel(0.1), "Pa"),
              common.check("random.count", 3900, 5043, None, "particles")]
    s = _summary(checks)
    s["cpu_count"], s["date"] = 2, "2026-12-04"
    return s


def test_report_renders_a_summary_into_its_rows():
    s = _given()
    assert report.render_row(s) == (
        "| `wave_bar` | a velocity pulse along a 20 m bar (Feng et al.) "
        "| 52 s | 2 of 3 | FAIL |")
    assert report.render_check(s["checks"][2]) == (
        "| random.peak_stress | 70.00 MPa | 89.4 MPa ± 10 % | FAIL |")
    assert report.render_check(s["checks"][3]) == (
        "| random.count | 3900 particles | 5043 particles (reported) | – |")
    table = report.render_checks(s)
    assert table.splitlines()[0].startswith(
        "`wave_bar`, quick preset (52 s, --threads 1 on 2 CPU cores, 2026-12-04): 2 of 3 "
        "compared checks pass, 1 reported only")
    assert "| regular.arrival_time | 2.850 ms | 2.83 ms ± 5 % | pass |" in table
    overview = report.render_overview({"wave_bar": s})
    assert "measured with --threads 1 on 2 CPU cores, 2026-12-04" in overview
    assert overview.splitlines()[-1] == report.render_row(s)


def test_report_rewrites_only_the_marked_blocks(tmp_path):
    s = _given()
    docs = tmp_path / "cases.md"
    docs.write_text("# Cases\n\nkept\n<!-- results:start -->\nold\n<!-- results:end -->\n"
                    "between\n<!-- results:wave_bar:start -->\nold table\n"
                    "<!-- results:wave_bar:end -->\nafter\n")
    code = tmp_path / "common.py"
    code.write_text("x = 1\n# quick-times:start\nQUICK_WALL_S = {}\n# quick-times:end\ny = 2\n")
    changed = report.update({"wave_bar": s}, None, docs, code)
    text = changed[docs]
    assert text.startswith("# Cases\n\nkept\n<!-- results:start -->\n")
    assert report.render_row(s) in text and "old" not in text
    assert "between\n<!-- results:wave_bar:start -->\n`wave_bar`, quick preset" in text
    assert text.endswith("<!-- results:wave_bar:end -->\nafter\n")
    assert changed[code] == ('x = 1\n# quick-times:start\nQUICK_WALL_S = {\n    "wave_bar": 52,\n}\n'
                             'QUICK_MEASURED = "measured with --threads 1 on 2 CPU cores, '
                             '2026-12-04"\n# quick-times:end\ny = 2\n')
    docs.write_text(text)
    code.write_text(changed[code])
    assert report.update({"wave_bar": s}, None, docs, code) == {}     # up to date


def test_the_report_is_not_a_case():
    assert "report" not in common.list_cases()
    assert set(report.cases()) == set(common.list_cases())


def test_help_gives_the_measured_quick_time():
    text = common.help_description("wave_bar", "Wave propagation in a rock bar.")
    assert text.startswith("Wave propagation in a rock bar.\n\nquick preset: ")
    assert f"{common.QUICK_WALL_S['wave_bar']:.0f} s" in text and "2 CPU cores" in text
    assert common.duration(52.4) == "52 s" and common.duration(501) == "8.3 min"


def test_validation_report_keeps_runs_and_lists_their_figures(tmp_path):
    """--archive copies a run's summary and plots to CASE/PRESET; the validation
    report lists each kept run (wall time, checks passed, the paper preset's time
    aim) and each figure beside the paper's, and links its plots."""
    s = _given()
    s["preset"], s["wall_time_s"] = "paper", 5400.0
    s["case"] = "soil_cutting"
    run = tmp_path / "run"
    run.mkdir()
    (run / "summary.json").write_text(json.dumps(s))
    (run / "fig19.png").write_bytes(b"png")
    root = tmp_path / "validation"
    dest = report.archive(run, root)
    assert dest == root / "soil_cutting" / "paper"
    assert json.loads((dest / "summary.json").read_text()) == s
    assert (dest / "fig19.png").read_bytes() == b"png"
    runs = report.kept(root)
    assert [(c, p, plots) for c, p, _, plots in runs] == [("soil_cutting", "paper",
                                                           ["fig19.png"])]
    text = report.render_validation(runs)
    row = [ln for ln in text.splitlines() if ln.startswith("| [`soil_cutting`]")]
    assert row == ["| [`soil_cutting`](#soil_cutting-paper-preset) | paper | 90 min | "
                   "--threads 1 on 2 CPU cores, 2026-12-04 | 2 of 3 | FAIL | "
                   "≤ 120 min on 2 cores: met |"]
    assert report.render_check(s["checks"][3]) in text
    assert "![fig19.png](validation/soil_cutting/paper/fig19.png)" in text
    s["wall_time_s"] = 7300.0
    (dest / "summary.json").write_text(json.dumps(s))
    assert "≤ 120 min on 2 cores: over" in report.render_validation(report.kept(root))
    # a folder without a finished run is refused, naming it
    with pytest.raises(ValueError, match="no summary.json"):
        report.archive(tmp_path, root)


def test_a_variant_is_kept_beside_its_preset(tmp_path):
    """A run with a variant (not the preset as it stands) is kept in CASE/PRESET-VARIANT
    beside the preset's own run, listed after it under its own name, without the
    preset's time aim."""
    root = tmp_path / "validation"
    for variant, wall in ((None, 5400.0), ("cells-four", 9000.0)):
        s = _given()
        s["preset"], s["wall_time_s"], s["case"] = "paper", wall, "soil_cutting"
        if variant:
            s["variant"] = variant
        run = tmp_path / f"run{variant}"
        run.mkdir()
        (run / "summary.json").write_text(json.dumps(s))
        report.archive(run, root)
    runs = report.kept(root)
    assert [f for _, f, _, _ in runs] == ["paper", "paper-cells-four"]
    rows = [ln for ln in report.render_validation(runs).splitlines()
            if ln.startswith("| [`soil_cutting`]")]
    # (the links are the headings' anchors, as GitHub and MyST make them)
    assert rows[0].startswith("| [`soil_cutting`](#soil_cutting-paper-preset) | paper | 90 min")
    assert rows[0].endswith("≤ 120 min on 2 cores: met |")
    assert rows[1].startswith("| [`soil_cutting`](#soil_cutting-paper-cells-four) | "
                              "paper, cells-four | 150 min")
    assert rows[1].endswith("| FAIL |  |")
