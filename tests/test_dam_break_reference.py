"""The volume-of-fluid reference of the dam break (docs/reference/dam_break_vof.py,
OpenFOAM interFoam; tables committed beside it), and why 10 % against Martin &
Moyce at every time is not a fair aim for a column released at once.

- The table the case and the tests use (cases.dam_break.VOF_FRONT) is the 2.5 mm
  run's, to its printed digits.
- The reference is converged: the 5 mm and 2.5 mm meshes within 1.5 % of each other
  from T = 0.3 to 3.4 (measured 0.9 %; 10 mm: 1.6 %).
- Every variant of the instantly released column leads the measurements by more
  than 9 % at every time, and by more than 15 % at T = 1.22: the problem as posed
  (ν = 1e-3, free-slip; +13.5, +17.1, +14.0, +12.3, +10.7 % at T = 0.83, 1.22, 2.0,
  2.55, 3.35), water's viscosity with free-slip or no-slip walls (+16.3 … +12.5,
  +15.4 … +12.2 %), and water at the experiment's own scale with no-slip walls and
  surface tension (+13.4, +16.5, +13.2, +11.2, +9.5 %). What slows the measured
  front is in none of them (the gate's lift); so the particle models are held to
  the reference (tests/test_voronoi_water.py, tests/test_dam_break_case.py), and
  their lead on the measurements is reported.
"""
from pathlib import Path

import numpy as np
import pytest

from cases import dam_break

HERE = Path(__file__).resolve().parents[1] / "docs" / "reference"
PROBLEM = "dam_break_vof_dx2.5mm_nu0.001_slip.csv"
VARIANTS = [PROBLEM, "dam_break_vof_dx5mm_nu0.001_slip.csv",
            "dam_break_vof_dx5mm_nu1e-06_slip.csv", "dam_break_vof_dx5mm_nu1e-06_noslip.csv",
            "dam_break_vof_a57.15mm_sigma0.07_dx0.95mm_nu1e-06_noslip.csv"]


def table(name):
    """(T, Z) columns of a reference table."""
    d = np.loadtxt(HERE / name, delimiter=",", skiprows=2)
    return d[:, 1], d[:, 2]


def test_case_table_is_the_reference_run():
    T, Z = table(PROBLEM)
    for t, z in dam_break.VOF_FRONT:
        assert z == pytest.approx(np.interp(t, T, Z), abs=6e-4), t
    T, Z = table(VARIANTS[-1])
    for t, z in dam_break.VOF_FRONT_WATER:
        assert z == pytest.approx(np.interp(t, T, Z), abs=6e-4), t


def test_reference_is_converged():
    T = np.arange(0.3, 3.4 + 1e-9, 0.05)
    fine = np.interp(T, *table(PROBLEM))
    coarse = np.interp(T, *table("dam_break_vof_dx5mm_nu0.001_slip.csv"))
    assert np.max(np.abs(coarse / fine - 1.0)) < 0.015


@pytest.mark.parametrize("name", VARIANTS)
def test_a_column_released_at_once_leads_martin_and_moyce(name):
    T, Z = table(name)
    lead = {t: np.interp(t, T, Z) / z - 1.0 for t, z in dam_break.MARTIN_MOYCE}
    assert min(lead.values()) > 0.09
    assert lead[1.219] > 0.15
