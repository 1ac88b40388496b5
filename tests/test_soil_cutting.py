"""Soil cutting (Feng, Li & Oñate 2015 §4.1): a short undamped quick-preset run shows a
shear band ahead of the blade and the soil surface at P1 heaving up."""
import json

from cases import soil_cutting as sc


def test_soil_cutting_quick_short(tmp_path):
    s = sc.run("quick", out=tmp_path, duration=1.0)
    f = s["figures"]
    assert (tmp_path / "summary.json").exists()
    assert json.loads((tmp_path / "summary.json").read_text())["case"] == "soil_cutting"
    for png in ("fig18_plastic_strain.png", "fig19_displacement.png",
                "fig20_bulk_stress.png", "blade_force.png"):
        assert (tmp_path / png).exists()
    # at least one band of high plastic strain crosses the strip ahead of the blade
    assert f["bands_max_count"]["value"] >= 1
    # P1 (x = 0.75 m) heaves as the blade (about 0.48 m of travel) pushes the soil up
    assert f["P1_end"]["value"] > f["P1_start"]["value"] + 0.005   # 5 mm: 10 x the gravity settlement
    # undamped, the soil moves with the blade: a handful of particles at most (squeezed
    # out under the cutting edge) faster than twice the blade's speed
    sp = f["speed_end"]["value"]
    assert sp["above_2x_blade"] <= 5 and sp["median"] < 0.5
    # P4 stays compressive (tension-positive bulk stress)
    assert f["P4_final_bulk_stress"]["value"] < 0.0
