"""rotating_drum: its measures of the bed read known beds exactly (a tilted flat
segment, a bed turning rigidly), and the quick preset's regimes (slow)."""
import math

import numpy as np
import pytest

from cases import rotating_drum as rd


def _segment(tilt_deg, depth=0.04, d=0.004):
    """Spheres filling the circular segment of the drum below a chord tilted by
    ``tilt_deg`` (rising towards +x), on a lattice."""
    g = np.stack(np.meshgrid(np.arange(-0.1, 0.1, d), np.arange(-0.1, 0.1, d)), -1
                 ).reshape(-1, 2)
    t = math.radians(tilt_deg)
    n = np.array([math.sin(t), -math.cos(t)])            # from the axis into the bed
    inside = (np.hypot(g[:, 0], g[:, 1]) < 0.095) & (g @ n > rd.R_DRUM - depth - 0.005)
    x = np.zeros((int(inside.sum()), 3))
    x[:, :2] = g[inside]
    return x


@pytest.mark.parametrize("tilt", [0.0, 25.0, 40.0])
def test_angles_of_a_flat_tilted_bed(tilt):
    x = _segment(tilt)
    n = len(x)
    p = {"position": x, "velocity": np.zeros((n, 3)), "mass": np.ones(n),
         "radius": np.full(n, 0.002)}
    theta_c, theta_s, lz, ir = rd.angles(p)
    assert theta_c == pytest.approx(tilt, abs=0.5)        # the centroid's perpendicular
    assert theta_s == pytest.approx(tilt, abs=1.0)        # the lattice's steps
    assert lz == 0.0


def test_corotation_of_a_rigidly_turning_bed():
    x = _segment(30.0)
    n = len(x)
    w = 2.5
    v = np.zeros((n, 3))
    v[:, 0], v[:, 1] = -w * x[:, 1], w * x[:, 0]
    p = {"position": x, "velocity": v, "mass": np.linspace(1, 2, n),
         "radius": np.full(n, 0.002)}
    _, _, lz, ir = rd.angles(p)
    assert lz / ir / w == pytest.approx(1.0, rel=1e-12)


@pytest.mark.slow
def test_quick_preset_regimes(tmp_path):
    s = rd.main(["--preset", "quick", "--out", str(tmp_path)])
    assert s["pass"] is True
