"""Case water_blocks, quick preset (Feng et al. 2015 §4.3, Figs. 25-27).

Runs both block systems (four and two columns) and checks the numbers the case
reports against measured values, with tolerances:

- the water front reaches the blocks when a dam break says it should, and the
  top block of the rightmost column moves (|dx| > 5 mm) after it: between 0.40
  s (Martin & Moyce's dam-break front, x/a = 2.44 for a = 0.8 m, arrives at
  T = t·sqrt(2g/a) ≈ 2.0, t ≈ 0.40 s; the paper's Fig. 26a shows the water at
  the blocks at 0.36 s) and 0.60 s (the surge has to build up a push beyond the
  blocks' friction first); measured 0.52 s (four) and 0.56 s (two);
- the outcome of this model as it stands: two columns topple, as in the paper
  (measured max |dx| 0.61 m, rotation 66°); four columns slide along the floor
  as one wall without turning (the paper: they stand; measured 0.22-0.24 m,
  rotation at most 1.6°; a 25° floor cannot hold them against the surge, see
  the case docstring, "Result");
- no block is thrown up: no block's centre rises above its start by more than
  riding onto another block and tipping over its corner could raise it, one
  block height plus (√2 − 1)/2 × 0.1 m, 12 cm (an earlier vertex–edge rule threw
  blocks to 1.1 m). The two toppling columns pile against the right wall, blocks
  landing on each other, and how they pile changes from run to run: on 2 threads
  the point–edge forces are summed by atomic additions, whose order varies, and
  the toppling amplifies the round-off; four runs of the same code gave the
  largest rise 1.5, 3.7, 7.4 and 8.9 cm (four columns: 0.3–0.6 cm);
- the water stays weakly compressible: its fastest particle below c/5 (c =
  122 m/s; measured 8.8 m/s; the runs completed).
Measured run time: 175-250 s for both runs on 2 shared cores with two threads, 460-500 s
with --threads 1 (hence slow).
"""
import math

import pytest

from cases import _common as common
from cases import water_blocks

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def result(tmp_path_factory):
    out = tmp_path_factory.mktemp("water_blocks")
    s = water_blocks.run("quick", out)
    return s, out


def test_outputs(result):
    s, out = result
    for f in ("summary.json", "fig26_four.png", "fig27_two.png", "block_displacements.png",
              "histories.h5"):
        assert (out / f).exists()
    assert s["data"]["model"]["status"] == {"four": "completed", "two": "completed"}
    assert common.validate(s) == []


def test_arrival_time(result):
    s, _ = result
    for name in ("four", "two"):
        c = common.checks_by_name(s)[f"{name}.motion_onset"]
        assert 0.40 < c["value"] < 0.60, (name, c["value"])
        assert c["tolerance"] == {"min": 0.40, "max": 0.60} and c["pass"] is True


def test_outcome(result):
    s, _ = result
    f = common.checks_by_name(s)
    assert f["two.outcome"]["value"] == "toppled" and f["two.outcome"]["pass"] is True
    assert f["two.top_dx_max"]["value"] > 0.3
    assert f["two.top_rotation_max"]["value"] > 30.0
    # differs from the paper (four columns stand): the wall slides; see the docstring
    assert f["four.outcome"]["value"] == "slid" and f["four.outcome"]["target"] == "stood"
    assert f["four.outcome"]["pass"] is False and s["pass"] is False
    assert 0.1 < f["four.top_dx_max"]["value"] < 0.4
    assert f["four.top_rotation_max"]["value"] < 5.0


def test_no_block_thrown_up(result):
    s, _ = result
    bound = water_blocks.BLOCK * (1.0 + (math.sqrt(2.0) - 1.0) / 2.0)     # 12.1 cm
    for name in ("four", "two"):
        assert common.checks_by_name(s)[f"{name}.block_rise_max"]["value"] < bound, name


def test_weakly_compressible(result):
    s, _ = result
    c = s["data"]["model"]["sound_speed_m_s"]
    assert c == pytest.approx(math.sqrt(15e6 / 1000.0))
    for name in ("four", "two"):
        assert common.checks_by_name(s)[f"{name}.water_vmax"]["value"] < c / 5.0
