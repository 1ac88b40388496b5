"""The command line: help at every level, the usage line a user typed, and a clear
refusal of an output folder that cannot be written."""
import pytest

from tdem import cli


def test_run_help_lists_the_cases(capsys):
    assert cli.main(["run", "--help"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("usage: tdem run CASE")
    for name in ("nine_disc", "biaxial", "contact_burst"):
        assert f"  {name} " in out


def test_case_help_shows_the_tdem_command(capsys):
    with pytest.raises(SystemExit) as e:
        cli.main(["run", "nine_disc", "--help"])
    assert e.value.code == 0
    assert capsys.readouterr().out.startswith("usage: tdem run nine_disc [-h] [--preset")


def test_output_folder_that_is_a_file_is_refused(tmp_path, capsys):
    f = tmp_path / "taken"
    f.write_text("x")
    with pytest.raises(SystemExit) as e:
        cli.main(["run", "nine_disc", "--out", str(f)])
    assert e.value.code == 2
    err = capsys.readouterr().err
    assert f"--out {f}: cannot write there" in err and "Traceback" not in err
