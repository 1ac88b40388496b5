"""The ParaView script of an output folder (tdem.paraview): written beside every series,
naming the series' files and arrays; run in real pvpython (when installed) it reads
the particles, walls and contacts of the model and draws discs at their radius,
contacts as force-scaled tubes and walls as lines into a PNG of the asked size."""
import ast
import json
import math
import shutil

import numpy as np
import pytest

import tdem
from tdem import paraview
from tdem.cli import main as cli

R, BIG = 0.01, 0.02
SPACING = 1.98 * R          # a 3 x 3 square lattice with overlaps: contacts in force
KN = 1e6


def settings(path):
    """The assignments of the settings block of a view.py, as Python values."""
    out = {}
    for node in ast.parse(path.read_text()).body:
        if isinstance(node, ast.Assign) and isinstance(node.targets[0], ast.Name) and \
                node.targets[0].id.isupper():
            try:
                out[node.targets[0].id] = ast.literal_eval(node.value)
            except ValueError:
                pass
    return out


@pytest.fixture(scope="module")
def lattice(tmp_path_factory):
    """Nine overlapping discs on a floor and against a left wall, and a big disc
    alone; output every 2 steps, 2 steps."""
    out = tmp_path_factory.mktemp("lattice")
    sim = tdem.Simulation(gravity=(0.0, 0.0))
    law = tdem.LinearContact(kn=KN, friction=0.5)
    xy = np.array([(i * SPACING, j * SPACING) for j in range(3) for i in range(3)])
    sim.add_particles(xy, R, density=2500, contact=law)
    sim.add_particles([[0.1, 0.02]], BIG, density=2500, contact=law)
    sim.add_wall((-0.03, -0.99 * R), (0.06, -0.99 * R), contact=law)      # floor
    sim.add_wall((-0.99 * R, 0.06), (-0.99 * R, -0.03), contact=law)      # left
    sim.output(out, every=2)
    sim.run(steps=2)
    return sim, out


def test_view_script_is_written_with_the_series_and_arrays(lattice):
    sim, out = lattice
    script = out / "view.py"
    assert script.exists()
    text = script.read_text()
    compile(text, str(script), "exec")
    s = settings(script)
    assert s["SERIES"] == {"particles": "particles.pvd", "walls": "walls.pvd",
                           "contacts": "contacts.pvd"}
    for name in s["SERIES"].values():
        assert (out / name).exists()
    assert s["FIELD"] == "stress_yy" and s["FIELD_UNIT"] == "Pa"
    assert s["TITLE"] == out.name and s["PNG"] == "view.png" and s["SIZE"] == [1600, 1200]
    assert s["TUBE"] == 0.25
    # discs at their radius: a disk of radius 0.5 scaled by radius x 2
    assert text.count("OuterRadius=0.5") == 2                 # filled discs and rings
    assert 'g.ScaleArray = ["POINTS", "radius"]' in text
    assert "g.ScaleFactor = 2.0" in text
    # contacts: |normal force| > 0, Extract Surface, then Tube varying its radius
    chain = ['Function = "abs(normal_force)"', "ExtractSurface(", "Tube(",
             'VaryRadius = "By Absolute Scalar"']
    where = [text.index(c) for c in chain]
    assert where == sorted(where)
    assert 'ColorBy(rep, ("POINTS", "normal_force"))' in text
    assert "SaveScreenshot(" in text


def test_pcmm_and_fluid_models_get_their_field(tmp_path):
    class Model:
        _slots = [(tdem.Elastic(density=2500, young=1e9, poisson=0.25), 0.01)]
    assert paraview.default_field(Model) == "stress_yy"
    Model._slots.append((tdem.Fluid(density=1000, bulk_modulus=2e9), 0.01))
    assert paraview.default_field(Model) == "pressure"
    for kind in ("particles", "elements", "blocks", "couplings", "contacts"):
        (tmp_path / f"{kind}.pvd").write_text("<VTKFile/>")
    path = paraview.write_view_script(tmp_path, sim=Model)
    s = settings(path)
    assert s["SERIES"] == {"elements": "elements.pvd", "blocks": "blocks.pvd",
                           "particles": "particles.pvd", "couplings": "couplings.pvd",
                           "contacts": "contacts.pvd"}
    assert s["FIELD"] == "pressure" and s["FIELD_UNIT"] == "Pa"
    assert paraview.field_unit("stress_xy") == "Pa"
    assert paraview.field_unit("plastic_strain") == ""
    with pytest.raises(ValueError, match="no .pvd series"):
        paraview.write_view_script(tmp_path / "nothing_here" if
                                   (tmp_path / "nothing_here").mkdir() is None else None)
    with pytest.raises(ValueError, match="size"):
        paraview.view_script({"particles": "particles.pvd"}, size=(0, 10))


def test_tdem_view_without_pvpython_says_how(lattice, tmp_path, monkeypatch, capsys):
    sim, out = lattice
    d = tmp_path / "copy"
    shutil.copytree(out, d)
    (d / "view.py").unlink()
    monkeypatch.setenv("PATH", str(tmp_path / "no-bin"))
    assert cli(["view", str(d)]) == 1
    said = capsys.readouterr().out
    assert f"wrote {d / 'view.py'}" in said
    assert f"xvfb-run -a pvpython {d / 'view.py'}" in said
    assert settings(d / "view.py")["SERIES"]["contacts"] == "contacts.pvd"


def test_tdem_view_without_a_display_says_how(lattice, tmp_path, monkeypatch, capsys):
    """Headless with ParaView but no Xvfb: pvpython would crash (SIGSEGV); tdem view
    says what is missing instead, and rendering raises the same."""
    sim, out = lattice
    d = tmp_path / "copy"
    shutil.copytree(out, d)
    fake = tmp_path / "bin"
    fake.mkdir()
    (fake / "pvpython").write_text("#!/bin/sh\nexit 139\n")
    (fake / "pvpython").chmod(0o755)
    monkeypatch.setenv("PATH", str(fake))
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    assert not paraview.can_render()
    assert cli(["view", str(d)]) == 1
    err = capsys.readouterr().err
    assert "no display" in err and "apt-get install xvfb" in err
    with pytest.raises(RuntimeError, match="no Xvfb"):
        paraview.render(d, ["--png", str(d / "v.png")])


@pytest.mark.skipif(not paraview.can_render(), reason="ParaView (pvpython) with a display "
                    "or Xvfb not installed")
def test_pvpython_draws_discs_at_their_radius_and_tubes(lattice, tmp_path):
    sim, out = lattice
    W, H = 640, 480
    png, info_path = tmp_path / "v.png", tmp_path / "info.json"
    proc = paraview.render(out, ["--png", png, "--size", W, H, "--info", info_path,
                                 "--no-text"], timeout=300)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-3000:]
    info = json.loads(info_path.read_text())
    p = sim.particles.numpy()
    pos, rad = p["position"], p["radius"]
    c = sim.contacts.numpy()
    loaded = np.abs(c["normal"]) > 0
    print({k: info[k] for k in ("particles", "discs", "contacts", "walls")})
    assert info["time"] == pytest.approx(sim.time, rel=1e-9)
    assert info["particles"]["points"] == len(rad) == 10
    assert info["particles"]["radius"] == pytest.approx([R, BIG], rel=1e-12)
    # the discs' extent: centres +- their own radius (the big one sets x max)
    lo, hi = (pos - rad[:, None]).min(0), (pos + rad[:, None]).max(0)
    assert info["discs"]["bounds"][:4] == pytest.approx([lo[0], hi[0], lo[1], hi[1]],
                                                         abs=1e-6)
    assert info["walls"]["cells"] == 2
    assert info["contacts"]["cells"] == int(loaded.sum()) == 12 + 3 + 3
    fmax = float(np.abs(c["normal"]).max())
    assert info["contacts"]["max_abs_normal_force"] == pytest.approx(fmax, rel=1e-9)
    # the largest tube's radius is 0.25 x the median radius (its z extent; 16 sides)
    tube_r = info["contacts"]["tube_bounds"][5]
    assert tube_r == pytest.approx(0.25 * R, rel=0.03)

    import matplotlib.image as mpimg
    img = mpimg.imread(str(png))
    assert img.shape[:2] == (H, W)
    rgb = img[:, :, :3]
    cam = info["camera"]
    (fx, fy), s = cam["focal_point"], cam["parallel_scale"]

    def pixel(x, y):
        col = int(round(W / 2 + (x - fx) / (2 * s) * H))
        row = int(round(H / 2 - (y - fy) / (2 * s) * H))
        return rgb[row, col]

    grey, white = np.array([0.8, 0.8, 0.8]), np.array([1.0, 1.0, 1.0])
    d = math.sqrt(0.5)
    for k, (x, y) in enumerate(pos):       # inside each disc, off the contact tubes
        r = rad[k]
        for sx, sy in ((1, 1), (-1, 1), (1, -1), (-1, -1)):
            assert pixel(x + sx * d * 0.85 * r, y + sy * d * 0.85 * r) == \
                pytest.approx(grey, abs=0.02)
    for i in range(2):                     # the gaps between four discs of the lattice
        for j in range(2):
            assert pixel((i + 0.5) * SPACING, (j + 0.5) * SPACING) == \
                pytest.approx(white, abs=0.02)
    x, y = pos[-1]                         # the big disc: grey to 0.9 R, white at 1.15 R
    for sx in (1, -1):
        assert pixel(x + sx * 0.9 * BIG, y) == pytest.approx(grey, abs=0.02)
        assert pixel(x, y + sx * 0.9 * BIG) == pytest.approx(grey, abs=0.02)
    assert pixel(x - 1.15 * BIG, y) == pytest.approx(white, abs=0.02)
    assert pixel(x, y + 1.15 * BIG) == pytest.approx(white, abs=0.02)
    assert pixel(0.05, -0.99 * R).max() < 0.3          # the floor: a dark line
    assert pixel(SPACING, 0.5 * SPACING).max() < 0.9   # a contact tube: coloured, not grey
    # the share of drawn pixels: the discs' area over the frame's, plus the walls
    drawn = (rgb.min(axis=2) < 0.98).mean()
    frame = (2 * s) ** 2 * W / H
    discs = math.pi * (9 * R ** 2 + BIG ** 2) - 12 * 2 * (R ** 2 * math.acos(SPACING / (2 * R))
                                                            - SPACING / 2 * math.sqrt(
                                                                R ** 2 - SPACING ** 2 / 4))
    # the walls (4 pixels wide) within the frame, which the bodies set
    x0, x1, y0, y1 = fx - s * W / H, fx + s * W / H, fy - s, fy + s
    inside = (min(x1, 0.06) - max(x0, -0.03)) + (min(y1, 0.06) - max(y0, -0.03))
    walls_px = 4.0 * inside / (2 * s) * H
    expected = discs / frame + walls_px / (W * H)
    print(f"drawn {drawn:.4f}, expected {expected:.4f}")
    assert drawn == pytest.approx(expected, rel=0.05)


@pytest.mark.skipif(not paraview.can_render(), reason="ParaView (pvpython) with a display "
                    "or Xvfb not installed")
def test_tdem_view_renders_the_png(lattice, capsys):
    sim, out = lattice
    png = out / "view.png"
    assert cli(["view", str(out), "--size", "320", "240", "--time", "0"]) == 0
    import matplotlib.image as mpimg
    assert mpimg.imread(str(png)).shape[:2] == (240, 320)
