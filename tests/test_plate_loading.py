"""The plate_loading case: its bookkeeping of when each contact formed, and (slow) the
quick preset against the paper's statements."""
import json

import numpy as np
import pytest

from cases import _common as common
from cases import plate_loading as pl


def test_states_by_plate_stress():
    assert [pl.state_of(s) for s in (0.0, 49.9e3, 50e3, 249e3, 250e3, 9e5)] == [0, 0, 1, 1, 2, 2]


def test_a_contact_keeps_the_state_it_formed_in_until_it_opens():
    tags = pl.Tags()
    tags.update(np.array([[0, 1], [2, -1]]), 0)
    tags.update(np.array([[1, 0], [2, -1], [3, 4]]), 1)     # (1, 0) is the pair (0, 1)
    assert tags.of(np.array([[0, 1], [2, -1], [3, 4]])).tolist() == [0, 0, 1]
    tags.update(np.array([[3, 4]]), 2)                      # (0, 1) and the wall opened
    tags.update(np.array([[3, 4], [0, 1]]), 2)              # (0, 1) forms again
    assert tags.of(np.array([[3, 4], [0, 1]])).tolist() == [1, 2]
    assert tags.formed == [2, 1, 1]


@pytest.mark.slow
def test_quick_preset_reports_the_load_shares(tmp_path):
    pl.main(["--preset", "quick", "--out", str(tmp_path), "--threads", "2"])
    s = json.loads((tmp_path / "summary.json").read_text())
    assert common.validate(s) == []
    for bed, b in s["data"]["beds"].items():
        shares = list(b["load_share"].values())
        assert sum(shares) == pytest.approx(1.0, abs=1e-9)
        assert 250 <= b["particles"] <= 370
        assert b["nonconverged_contacts"] == 0
        c = common.checks_by_name(s)[f"{bed}.load_share_final"]
        assert c["value"] == pytest.approx(b["load_share"]["final"])
        assert c["tolerance"] == {"max": 0.20}
    assert len(s["checks"]) == 12
