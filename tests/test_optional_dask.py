"""Dask is an optional extra (tdem[sweep]): tdem and the cases import without it, and
the sweep says how to install it."""
import subprocess
import sys
import textwrap

import pytest


def test_tdem_imports_without_dask_and_the_sweep_names_the_extra(tmp_path):
    # a child process in which importing dask or distributed fails
    code = textwrap.dedent("""
        import sys
        sys.modules["dask"] = None
        sys.modules["distributed"] = None
        import tdem
        from cases import biaxial
        assert "dask" not in sys.modules or sys.modules["dask"] is None
        try:
            biaxial.run_sweep([], workers=1)
        except ImportError as e:
            print("ERROR:", e)
        from cases import water_blocks
        rc = water_blocks.main(["--sweep", "--out", sys.argv[1]])
        assert rc == 2, rc
        sys.exit(biaxial.main(["--sweep", "--out", sys.argv[1]]))
    """)
    out = subprocess.run([sys.executable, "-c", code, str(tmp_path)], capture_output=True,
                         text=True, timeout=300)
    assert out.returncode == 2, out.stderr[-2000:]
    assert 'ERROR: the sweep runs on Dask' in out.stdout
    assert 'pip install "tdem[sweep]"' in out.stdout
    assert 'biaxial --sweep: the sweep runs on Dask' in out.stderr
    assert 'water_blocks --sweep: the sweep runs on Dask' in out.stderr
    assert 'pip install "tdem[sweep]"' in out.stderr


def test_the_extras_of_the_package():
    tomllib = pytest.importorskip("tomllib")
    from pathlib import Path
    meta = tomllib.loads((Path(__file__).parents[1] / "pyproject.toml").read_text())
    project = meta["project"]
    assert not any(d.startswith(("dask", "distributed")) for d in project["dependencies"])
    assert project["optional-dependencies"]["sweep"] == ["dask[distributed]"]
    assert "dask[distributed]" in project["optional-dependencies"]["test"]
