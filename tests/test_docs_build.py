"""The documentation builds from a clean checkout: Sphinx (MyST Markdown and the
reference pages from the docstrings, docs/conf.py) with warnings as errors."""
import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[1]


def test_the_docs_build_with_warnings_as_errors(tmp_path):
    out = tmp_path / "html"
    r = subprocess.run([sys.executable, "-m", "sphinx", "-E", "-W", "--keep-going", "-q",
                        "-b", "html", str(ROOT / "docs"), str(out)],
                       capture_output=True, text=True, cwd=ROOT, timeout=600)
    assert r.returncode == 0, r.stderr[-4000:]
    ref = (out / "reference.html").read_text()
    # the reference pages carry the docstrings of the public API
    for name in ("add_particles", "WetContact", "Granular", "TriaxialCell", "random3d"):
        assert name in ref, name
    for page in ("guide", "api", "design", "cases", "pcmm", "validation"):
        assert (out / f"{page}.html").stat().st_size > 5000, page
