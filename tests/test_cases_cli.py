"""The ``tdem`` command and the case scripts it runs."""
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from cases import _common as common
from tdem import cli

ROOT = Path(__file__).resolve().parents[1]


def test_list_names_the_cases(capsys):
    assert cli.main(["list"]) == 0
    out = capsys.readouterr().out
    assert "nine_disc" in out and "photoelastic" in out
    line = next(l for l in out.splitlines() if l.startswith("nine_disc"))
    assert "Cundall" in line


def test_python_m_tdem_list():
    r = subprocess.run([sys.executable, "-m", "tdem", "list"], cwd=ROOT, capture_output=True,
                       text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert "nine_disc" in r.stdout and "photoelastic" in r.stdout


def test_unknown_case_exits_2(capsys):
    assert cli.main(["run", "no_such_case"]) == 2
    err = capsys.readouterr().err
    assert "no_such_case" in err and "nine_disc" in err and "photoelastic" in err


def test_no_command_exits_2(capsys):
    assert cli.main([]) == 2


def _summary(out):
    with open(out / "summary.json") as f:
        return json.load(f)


def test_photoelastic_quick(tmp_path):
    out = tmp_path / "pe"
    assert cli.main(["run", "photoelastic", "--preset", "quick", "--out", str(out)]) == 0
    s = _summary(out)
    assert common.validate(s) == []
    ratio = common.checks_by_name(s)["F_H_over_F_V"]
    assert ratio["target"] == pytest.approx(0.39)
    assert ratio["tolerance"] == {"rel": 0.05}
    assert abs(ratio["value"] - 0.39) <= 0.1
    table = s["data"]["table1"]["stage_A"]
    walls = table["walls"]
    assert len(walls) == 4
    for w in walls:
        assert {"F1", "F2", "e_over_half_L_percent"} <= set(w)
    # equilibrium of the walls' forces (the discs are at rest)
    assert abs(sum(w["F1"] for w in walls)) < 0.01 * table["F_V"]
    assert abs(sum(w["F2"] for w in walls)) < 0.01 * table["F_V"]
    assert (out / "fig11_force_vectors.png").stat().st_size > 0
    assert list(out.glob("*.pvd"))


def test_nine_disc_quick(tmp_path):
    out = tmp_path / "nd"
    assert cli.main(["run", "nine_disc", "--preset", "quick", "--out", str(out)]) == 0
    s = _summary(out)
    assert common.validate(s) == []
    c = common.checks_by_name(s)
    amp = c["undamped_amplitude_over_F_eq"]["value"]
    assert 0.02 <= amp <= 0.25   # C&S about 0.15; set by dt (cases.nine_disc docstring)
    assert c["undamped_amplitude_over_F_eq"]["target"] == pytest.approx(0.15)
    assert abs(c["damped_final_over_F_eq_from_undamped_mean"]["value"] - 1) < 0.02
    assert c["damped_final_over_F_eq_from_undamped_mean"]["pass"] is True
    assert c["fig7a_amplitude_ratio_fast_over_slow"]["value"] > 1
    # the closed forms of the module docstring, within 1 %
    for name in ("F_eq", "F_eq_smooth"):
        assert c[name]["value"] == pytest.approx(c[name]["target"], rel=0.01), name
    for png in ("fig5b_force_vectors.png", "fig6_damping.png", "fig7_loading_speed.png",
                "fig9_distortion.png"):
        assert (out / png).stat().st_size > 0
    assert (out / "histories.h5").exists()
    assert list(out.glob("*.pvd"))


def test_water_blocks_duration_is_checked(tmp_path):
    """water_blocks --duration must be a positive time: refused, naming it, before
    anything is built or written."""
    from cases import water_blocks
    from tdem.errors import InputError
    with pytest.raises(InputError, match="duration"):
        water_blocks.main(["--duration", "0", "--out", str(tmp_path / "wb")])
    assert not (tmp_path / "wb" / "summary.json").exists()


# (three processes building the water and the blocks, about 45 s on 2 cores; the case
# itself is checked in the default run by tests/test_water_blocks.py)
@pytest.mark.slow
def test_water_blocks_systems_in_parallel_give_the_same_run(tmp_path):
    """water_blocks --parallel runs the two block systems in two processes: on one
    thread each, every record of both systems equals the run one after the other,
    to the bit, and the summary is the same but for the wall time."""
    runs = {}
    for name, extra in (("seq", []), ("par", ["--parallel"])):
        r = subprocess.run([sys.executable, "-m", "cases.water_blocks", "--threads", "1",
                            "--duration", "0.04", "--out", str(tmp_path / name), *extra],
                           cwd=ROOT, capture_output=True, text=True, timeout=600)
        assert r.returncode == 0, r.stderr[-2000:]
        runs[name] = json.loads((tmp_path / name / "summary.json").read_text())
    for name in ("four", "two"):
        seq = h5_records(tmp_path / "seq" / "histories.h5", name)
        par = h5_records(tmp_path / "par" / "histories.h5", name)
        assert seq.keys() == par.keys() and len(seq["time"]) >= 2
        for k in seq:
            assert np.array_equal(seq[k], par[k]), k
    assert runs["seq"]["checks"] == runs["par"]["checks"]


def h5_records(path, name):
    import h5py
    with h5py.File(path, "r") as f:
        g = f[name]
        return {k: g[k][()] for k in g}
