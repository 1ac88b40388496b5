"""Every Python example of the README runs as written (in a fresh process, in a
scratch folder) and leaves what it says it writes: the pile's VTU series, monitors
and a checkpoint that loads at t = 1.5 s with its 400 discs; the 3D bed's series; the
cut's series."""
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
BLOCKS = re.findall(r"```python\n(.*?)```", (ROOT / "README.md").read_text(), re.S)


def test_the_readme_has_its_three_examples():
    assert len(BLOCKS) == 3


@pytest.mark.parametrize("k", range(len(BLOCKS)))
def test_readme_example_runs(k, tmp_path):
    out = subprocess.run([sys.executable, "-c", BLOCKS[k]], cwd=tmp_path, capture_output=True,
                         text=True, timeout=600)
    assert out.returncode == 0, out.stderr[-3000:]
    if "out/pile" in BLOCKS[k]:
        assert (tmp_path / "out/pile/particles.pvd").exists()
        assert (tmp_path / "out/pile/monitors.h5").exists()
        assert (tmp_path / "out/pile/view.py").exists()
        assert (tmp_path / "out/pile/history.png").read_bytes()[:4] == b"\x89PNG"
        check = ("import tdem; s = tdem.Simulation.load('out/pile/end.h5'); "
                 "print(s.n_particles, s.time)")
        back = subprocess.run([sys.executable, "-c", check], cwd=tmp_path,
                              capture_output=True, text=True, timeout=300)
        n, t = back.stdout.split()[-2:]
        assert int(n) == 400 and float(t) == pytest.approx(1.5, abs=1e-3)
    if "out/bed" in BLOCKS[k]:
        # 3D: the bed's weight on the box (the last line prints the box's force first)
        assert (tmp_path / "out/bed/particles.pvd").exists()
        assert (tmp_path / "out/bed/walls.pvd").exists()
        import math

        import tdem
        n = len(tdem.pack.lattice3d((0, 0, 0), (0.1, 0.1, 0.1), 0.0051, kind="cubic"))
        weight = n * 2500 * 4.0 / 3.0 * math.pi * 0.005 * 0.004 * 0.003 * 9.81
        num = r"\s*(-?[0-9.]+(?:e[+-]?[0-9]+)?)"
        fz = float(re.search(r"\[" + num * 3 + r"\s*\]", out.stdout).group(3))
        assert -fz == pytest.approx(weight, rel=0.01)     # settled: the box carries it
    if "out/cut" in BLOCKS[k]:
        assert (tmp_path / "out/cut/particles.pvd").exists()
        assert (tmp_path / "out/cut/elements.pvd").exists()
