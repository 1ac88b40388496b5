"""water_blocks --sweep: the grid of the parameters the paper does not give, and
that each run is built with them (the runs themselves are the case's; minutes each)."""
import numpy as np
import pytest

from cases import water_blocks as wb


def test_the_default_grid_is_every_combination_once():
    tasks = wb.sweep_tasks("quick")
    assert len(tasks) == 3 * 2 * 2
    keys = {(t["floor_friction"], t["block_friction"], t["column_gap"]) for t in tasks}
    assert len(keys) == len(tasks)
    assert {k[0] for k in keys} == {25.0, 35.0, 45.0}
    assert len({wb.task_name(t) for t in tasks}) == len(tasks)


def test_bad_grids_are_refused_naming_the_parameter():
    with pytest.raises(ValueError, match="floor_frict"):
        wb.sweep_tasks(grid={"floor_frict": (30.0,)})
    with pytest.raises(ValueError, match="block_friction has no values"):
        wb.sweep_tasks(grid={"block_friction": ()})


def test_a_run_is_built_with_its_parameters():
    cfg = dict(wb.PRESETS["quick"], floor_friction=40.0, block_friction=30.0,
               column_gap=0.01)
    m = wb.build(cfg, 4)
    x0 = sorted({c[0] for c in m["corners"]})
    assert np.diff(x0) == pytest.approx([wb.BLOCK + 0.01] * 3, rel=1e-12)
    floor = m["floor"]
    angles = {}
    for _, a, b, law in m["sim"]._couples:
        if b is floor or a is floor:
            angles.setdefault("floor", set()).add(law.friction_angle)
        elif a in m["blocks"] and b in m["blocks"]:
            angles.setdefault("blocks", set()).add(law.friction_angle)
    assert angles == {"floor": {40.0}, "blocks": {30.0}}


def test_the_table_reports_each_run():
    row = {"floor_friction": 35.0, "block_friction": 25.0, "column_gap": 0.001,
           "outcome": "slid", "top_dx_max_m": 0.2345, "top_rotation_max_deg": 1.62,
           "onset_s": 0.52, "columns_moved_0p1m": 4}
    lines = wb.sweep_table([row]).splitlines()
    assert len(lines) == 3
    assert lines[2] == "| 35° | 25° | 1 mm | slid | 0.234 m | 1.6° | 0.52 s | 4 of 4 |"


def test_motion_onset_is_interpolated_between_records():
    """The block's motion onset: where |dx| crosses 5 mm, linearly between the two
    records around it; the first record if it starts there; None if never."""
    t = [0.0, 0.02, 0.04, 0.06]
    assert wb.motion_onset(t, [0.0, 0.001, 0.009, 0.02]) == pytest.approx(0.03)
    assert wb.motion_onset(t, [0.0, -0.003, -0.007, 0.0]) == pytest.approx(0.03)
    assert wb.motion_onset(t, [0.006, 0.01, 0.02, 0.03]) == 0.0
    assert wb.motion_onset(t, [0.0, 0.001, 0.002, 0.003]) is None
