"""ParaView pictures of an output folder: a ``view.py`` script for ``pvpython``.

:class:`tdem.io.Output` writes ``view.py`` beside the ``.pvd`` indices of a series
(and ``tdem view DIR`` writes it for any folder of ``.pvd`` files). Run it with

    pvpython out/nine_disc/view.py             # a display: window-less, saves view.png
    xvfb-run -a pvpython out/nine_disc/view.py  # headless (no X display)
    paraview --script=out/nine_disc/view.py     # the same pipeline in the ParaView GUI

It opens the series and shows, at the last snapshot (``--time T`` for another):

- the particles as flat discs at their true radius (*Glyph With Custom Source*, a
  *Disk* of radius 0.5 scaled by the ``radius`` array × 2); over PCMM elements as
  rings, so that the elements stay visible;
- the PCMM elements and the blocks as triangles coloured by ``FIELD`` (default
  ``stress_yy``, Pa, tension-positive; ``pressure`` where the model has fluids or
  explosives), on a diverging scale symmetric about zero that covers the 1st to
  99th percentile of the values;
- the contacts as tubes whose radius is proportional to |normal force| (*Calculator*
  → *Threshold* |F_n| > 0 → *Extract Surface* → *Tube* varying its radius by that
  scalar), the largest ``TUBE`` × the median disc radius, coloured by ``normal_force``;
- the walls as thick lines, point–edge couplings as thin lines;

and, run as a program, saves a PNG screenshot (``view.png`` beside the script, or
``--png FILE``; ``--size W H``; ``--frames``: one PNG per snapshot). ``--info FILE``
writes what was shown (counts, bounds, ranges) as JSON. The settings at the top of
the script (series, field, sizes) may be edited by hand.

The placeholder cell of an empty file (no walls, no contacts yet; see
:mod:`tdem.io`) is removed by a *Threshold* on the file's index array, so that it
neither shows nor moves the camera.
"""
import contextlib
import os
import random
import select
import shutil
import subprocess
import sys
import time
from pathlib import Path

from .errors import InputError

SCRIPT_NAME = "view.py"

# the series a folder may hold, in drawing order, and the array whose value is >= 0
# on every real cell (the placeholder of an empty file has -1 there)
KINDS = ("elements", "blocks", "shapes", "particles", "couplings", "walls", "contacts",
         "bonds", "cracks")

# the default colour field of elements and blocks, and its unit
DEFAULT_FIELD = "stress_yy"
UNITS = {"stress": "Pa", "pressure": "Pa", "plastic_strain": "", "strain": "",
         "weight": "", "n_cover": "", "velocity": "m/s", "displacement": "m",
         "normal_force": "N/m", "shear_force": "N/m", "radius": "m", "mass": "kg/m",
         "omega": "rad/s", "force": "N/m", "torque": "N·m/m", "reaction": "N/m",
         "failed": "", "elements": ""}


def field_unit(name):
    """The unit of an output array (``stress_yy`` → ``Pa``); '' when it has none or is
    unknown."""
    name = str(name)
    if name in UNITS:
        return UNITS[name]
    base = name.rsplit("_", 1)[0]
    return UNITS.get(base, "")


def default_field(sim):
    """The colour field of a model's elements and blocks: ``pressure`` where a PCMM
    body or block is a fluid or an explosive (their deviatoric stress is nil or
    small), else ``stress_yy``."""
    for material, _tol in getattr(sim, "_slots", []):
        if type(material).__name__ in ("Fluid", "JWL"):
            return "pressure"
    return DEFAULT_FIELD


def _series_in(directory):
    return {k: f"{k}.pvd" for k in KINDS if (Path(directory) / f"{k}.pvd").exists()}


def view_script(series, field=DEFAULT_FIELD, disc_field=None, title="", png="view.png",
                size=(1600, 1200), tube=0.25, dim=2):
    """The text of a ``view.py`` for the ``series`` {kind: .pvd file name relative to
    the script} (kinds of :data:`KINDS`). ``field``: the colour of elements and blocks;
    ``disc_field``: a particle array to colour discs by (None: plain grey); ``tube``:
    the radius of the largest contact force's tube over the median disc radius."""
    unknown = sorted(set(series) - set(KINDS))
    if unknown:
        raise InputError(f"series: unknown kind {unknown[0]!r}; the kinds are {KINDS}")
    if not (isinstance(size, (tuple, list)) and len(size) == 2 and all(
            int(s) == s and s >= 16 for s in size)):
        raise InputError(f"size must be (width, height) in pixels, got {size!r}")
    if not float(tube) > 0:
        raise InputError(f"tube must be > 0 (a fraction of the median radius), got {tube!r}")
    settings = "\n".join([
        f"SERIES = {dict((k, series[k]) for k in KINDS if k in series)!r}",
        f"FIELD = {str(field)!r}  # colour of elements and blocks",
        f"FIELD_UNIT = {field_unit(field)!r}",
        f"DISC_FIELD = {disc_field!r}  # a particle array to colour the discs, or None",
        f"TITLE = {str(title)!r}",
        f"PNG = {str(png)!r}  # beside this script",
        f"SIZE = {[int(size[0]), int(size[1])]!r}  # pixels",
        f"TUBE = {float(tube)!r}  # largest contact tube radius / median disc radius",
        f"DIM = {int(dim)!r}  # 2: discs seen from +z; 3: spheres and mesh walls in perspective",
    ])
    return _HEADER + settings + "\n" + _BODY


def write_view_script(directory, series=None, field=None, disc_field=None, title=None,
                      sim=None, **kw):
    """Write ``directory/view.py`` (see the module's docstring) and return its path.

    ``series``: {kind: .pvd name} (None: the ``.pvd`` files found in ``directory``);
    ``field``: colour of elements and blocks (None: :func:`default_field` of ``sim``,
    else ``stress_yy``); ``title``: a caption (None: the folder's name). Other keywords
    go to :func:`view_script`."""
    directory = Path(directory)
    if series is None:
        series = _series_in(directory)
    if not series:
        raise InputError(f"directory: no .pvd series of tdem in {str(directory)!r} "
                         f"(expected some of {', '.join(k + '.pvd' for k in KINDS)})")
    if field is None:
        field = default_field(sim) if sim is not None else DEFAULT_FIELD
    if title is None:
        title = directory.resolve().name
    if sim is not None and "dim" not in kw:
        kw["dim"] = getattr(sim, "dim", 2)
    text = view_script(series, field=field, disc_field=disc_field, title=title, **kw)
    path = directory / SCRIPT_NAME
    tmp = directory / (SCRIPT_NAME + ".tmp")
    tmp.write_text(text)
    os.replace(tmp, path)
    return path


def script_settings(path):
    """The settings (upper-case names assigned a literal) of a ``view.py``."""
    import ast
    out = {}
    try:
        tree = ast.parse(Path(path).read_text())
    except (OSError, SyntaxError, ValueError):
        return out
    for node in tree.body:
        if isinstance(node, ast.Assign) and len(node.targets) == 1 and \
                isinstance(node.targets[0], ast.Name) and node.targets[0].id.isupper():
            try:
                out[node.targets[0].id] = ast.literal_eval(node.value)
            except ValueError:
                pass
    return out


def pvpython():
    """The ``pvpython`` (or ``pvbatch``) on PATH, or None."""
    return shutil.which("pvpython") or shutil.which("pvbatch")


def view_command(directory, args=()):
    """``[pvpython, DIR/view.py, *args]``; None without pvpython."""
    exe = pvpython()
    if exe is None:
        return None
    return [exe, str(Path(directory) / SCRIPT_NAME), *map(str, args)]


def _headless():
    return not os.environ.get("DISPLAY") and not os.environ.get("WAYLAND_DISPLAY")


@contextlib.contextmanager
def _virtual_display(wait=30.0):
    """An Xvfb server on a display it picks itself (``-displayfd``: no race with other
    servers starting at the same moment); yields its name, ``":N"``."""
    r, w = os.pipe()
    proc = subprocess.Popen(["Xvfb", "-displayfd", str(w), "-screen", "0", "2048x2048x24",
                             "-nolisten", "tcp"], pass_fds=(w,),
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    os.close(w)
    try:
        text = b""
        end = time.monotonic() + wait
        while not text.endswith(b"\n"):
            ready, _, _ = select.select([r], [], [], max(0.0, end - time.monotonic()))
            chunk = os.read(r, 64) if ready else b""
            if not chunk:
                raise RuntimeError("Xvfb did not start (no display number)")
            text += chunk
        yield ":" + text.decode().strip()
    finally:
        os.close(r)
        proc.terminate()
        try:
            proc.wait(10)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


def _x_failed(proc):
    """pvpython stopped because it had no usable X display."""
    return proc.returncode != 0 and any(
        k in (proc.stderr or "") for k in ("bad X server connection", "Xvfb failed",
                                           "cannot open display", "Xvfb did not start",
                                           "XOpenGLRenderWindow"))


def _run_once(cmd, timeout, capture):
    out = subprocess.PIPE if capture else None
    if _headless() and shutil.which("Xvfb"):
        try:
            with _virtual_display() as display:
                env = dict(os.environ, DISPLAY=display)
                return subprocess.run(cmd, stdout=out, stderr=subprocess.PIPE, text=True,
                                      timeout=timeout, env=env)
        except RuntimeError as e:
            return subprocess.CompletedProcess(cmd, 1, "" if capture else None, str(e))
    if _headless() and shutil.which("xvfb-run"):
        cmd = ["xvfb-run", "-a", "-n", str(random.randint(100, 9999)), *cmd]
    return subprocess.run(cmd, stdout=out, stderr=subprocess.PIPE, text=True, timeout=timeout)


def display_problem():
    """Why pvpython cannot draw here (a sentence), or None: with no display it needs
    Xvfb (``Xvfb`` or ``xvfb-run``); Debian's pvpython, run headless without one,
    crashes (SIGSEGV) rather than saying so."""
    if _headless() and not (shutil.which("Xvfb") or shutil.which("xvfb-run")):
        return ("there is no display (DISPLAY is not set) and no Xvfb to make one: "
                "install it (apt-get install xvfb) or run where a display is")
    return None


def can_render():
    """Whether pvpython is installed and has a display (real or virtual) to draw on."""
    return pvpython() is not None and display_problem() is None


def run_view(directory, args=(), timeout=600, capture=True, attempts=3):
    """Run ``directory/view.py`` in pvpython with the script's options ``args``: with
    no display, on a virtual one (Xvfb, else ``xvfb-run -a``), tried again up to
    ``attempts`` times if pvpython could not open it. Returns the completed process
    (stderr always captured, stdout if ``capture``); RuntimeError without pvpython."""
    cmd = view_command(directory, args)
    if cmd is None:
        raise RuntimeError("pvpython is not on PATH: install ParaView (e.g. apt-get "
                           "install paraview xvfb) to render the pictures")
    problem = display_problem()
    if problem is not None:
        raise RuntimeError(f"pvpython cannot draw: {problem}")
    for _ in range(max(1, int(attempts))):
        proc = _run_once(cmd, timeout, capture)
        if not _x_failed(proc):
            break
    return proc


def render(directory, args=(), timeout=600, write=True, **kw):
    """Run ``directory/view.py`` in pvpython (headless where needed, see
    :func:`run_view`) with the script's options ``args`` (e.g. ``["--png", "a.png",
    "--time", "0.5"]``); ``write``: write the script first if it is missing (keywords as
    :func:`write_view_script`). Returns the completed process (stdout, stderr)."""
    directory = Path(directory)
    if write and not (directory / SCRIPT_NAME).exists():
        write_view_script(directory, **kw)
    return run_view(directory, args, timeout=timeout)


def main(argv=None):
    """``tdem view DIR [options of view.py]``: write ``DIR/view.py`` if it is missing
    (``--rewrite``: always) and run it in pvpython; without pvpython, say how."""
    import argparse
    p = argparse.ArgumentParser(
        prog="tdem view", description="Write DIR/view.py (a ParaView script for the "
        "series in DIR) and run it in pvpython, on a virtual display (Xvfb) where there "
        "is none: it saves DIR/view.png. Options after DIR go to view.py (--png FILE, "
        "--time T, --size W H, --field NAME, --frames, --info FILE).")
    p.add_argument("directory", metavar="DIR")
    p.add_argument("--rewrite", action="store_true", help="write view.py even if it exists "
                   "(keeping its FIELD unless --field is given)")
    p.add_argument("--field", default=None, help="colour field of elements and blocks "
                   "(default stress_yy)")
    ns, rest = p.parse_known_args(argv)
    d = Path(ns.directory)
    if not d.is_dir():
        print(f"tdem view: {ns.directory!r} is not a folder", file=sys.stderr)
        return 2
    script = d / SCRIPT_NAME
    try:
        if ns.rewrite or not script.exists():
            field = ns.field or (script_settings(script).get("FIELD") if script.exists()
                                 else None)
            write_view_script(d, field=field)
            print(f"wrote {script}")
    except InputError as e:
        print(f"tdem view: {e}", file=sys.stderr)
        return 2
    if ns.field is not None:
        rest = ["--field", ns.field, *rest]
    if view_command(d, rest) is None:
        print(f"pvpython is not on PATH. With ParaView installed: pvpython {script} "
              f"(headless: xvfb-run -a pvpython {script}), or open it in the GUI: "
              f"paraview --script={script}")
        return 1
    problem = display_problem()
    if problem is not None:
        print(f"tdem view: pvpython cannot draw: {problem}. The script is {script}: "
              f"open it in the ParaView GUI with paraview --script={script}",
              file=sys.stderr)
        return 1
    print(" ".join(view_command(d, rest)) + (" (on a virtual display)" if _headless()
                                               else ""), flush=True)
    proc = run_view(d, rest, timeout=None, capture=False)
    sys.stderr.write(proc.stderr or "")
    return proc.returncode


_HEADER = '''"""ParaView picture of this folder's tdem series (written by tdem.paraview).

    pvpython view.py [--png FILE] [--time T] [--size W H] [--field NAME] [--frames]
    xvfb-run -a pvpython view.py        # headless
    paraview --script=view.py           # the pipeline in the ParaView GUI

Discs at their true radius, PCMM elements and blocks coloured by FIELD, contacts as
tubes of radius proportional to |normal force|, walls as lines; run as a program it
saves a PNG (PNG below, beside this script). Edit the settings below as needed.
"""
'''

_BODY = r'''
import argparse
import json
import math
import os
import sys

from paraview.simple import (Calculator, ColorBy, Disk, ExtractSurface, GetActiveViewOrCreate,
                             GetAnimationScene, GetColorTransferFunction, GetScalarBar,
                             GlyphWithCustomSource, Hide, PVDReader, Render, SaveScreenshot,
                             Show, Sphere, TensorGlyph, Text, Threshold, Tube)

try:
    HERE = os.path.dirname(os.path.abspath(__file__))
except NameError:            # pasted into a Python shell: the current folder
    HERE = os.getcwd()
AS_PROGRAM = bool(sys.argv) and os.path.basename(sys.argv[0]) == "view.py"
# the array that is >= 0 on every real cell of a file (-1 on the placeholder of an
# empty one), and whether it is point or cell data
VALID = {"particles": ("POINTS", "id"), "walls": ("CELLS", "id"), "shapes": ("CELLS", "id"),
         "elements": ("CELLS", "owner"), "blocks": ("CELLS", "block"),
         "couplings": ("CELLS", "kind"), "bonds": ("CELLS", "id"),
         "cracks": ("POINTS", "id")}
BARS = []          # the colour bars shown, top to bottom


def options():
    p = argparse.ArgumentParser(prog="pvpython view.py", description=__doc__.split("\n")[0])
    p.add_argument("--png", default=None, help="screenshot (default: %s beside view.py)" % PNG)
    p.add_argument("--time", type=float, default=None,
                   help="simulated time to show, s (default: the last snapshot)")
    p.add_argument("--size", type=int, nargs=2, default=SIZE, metavar=("W", "H"))
    p.add_argument("--field", default=FIELD, help="colour of elements and blocks")
    p.add_argument("--frames", action="store_true",
                   help="one PNG per snapshot (PNG stem + _KKKKK.png)")
    p.add_argument("--no-text", action="store_true", help="no caption, no colour bars")
    p.add_argument("--info", default=None, help="write what was shown as JSON to this file")
    p.add_argument("--interactive", action="store_true",
                   help="open an interactive window after the screenshot")
    return p.parse_args(sys.argv[1:] if AS_PROGRAM else [])


def threshold(src, assoc, array, value, name, below=False):
    """Cells whose ``array`` is >= ``value`` (``below``: <= ``value``); ParaView 5.10+,
    ThresholdRange before."""
    th = Threshold(registrationName=name, Input=src)
    th.Scalars = [assoc, array]
    try:
        th.ThresholdMethod = "Below Lower Threshold" if below else "Above Upper Threshold"
        if below:
            th.LowerThreshold = value
        else:
            th.UpperThreshold = value
    except AttributeError:
        th.ThresholdRange = [-1e300, value] if below else [value, 1e300]
    return th


def disc_glyphs(src, disk, name, view, colour):
    """A ``disk`` (radius 0.5) at every point of ``src``, scaled by its ``radius``
    array x 2: a disc of the particle's radius."""
    g = GlyphWithCustomSource(registrationName=name, Input=src, GlyphSource=disk)
    g.ScaleArray = ["POINTS", "radius"]
    g.ScaleFactor = 2.0
    g.GlyphMode = "All Points"
    g.OrientationArray = ["POINTS", "No orientation array"]
    rep = Show(g, view)
    flat(rep)
    if DISC_FIELD:
        ColorBy(rep, ("POINTS", DISC_FIELD))
    else:
        rep.ColorArrayName = ["POINTS", ""]
        rep.AmbientColor = rep.DiffuseColor = colour
    return g


def union(a, b):
    """The union of two bounds (None: empty)."""
    if a is None or b is None:
        return a if b is None else b
    return [min(a[0], b[0]), max(a[1], b[1]), min(a[2], b[2]), max(a[3], b[3]),
            min(a[4], b[4]), max(a[5], b[5])]


def bounds(src, t):
    src.UpdatePipeline(t)
    b = list(src.GetDataInformation().GetBounds())
    return b if b[0] <= b[1] else None


def count(src, t):
    src.UpdatePipeline(t)
    info = src.GetDataInformation()
    return {"points": int(info.GetNumberOfPoints()), "cells": int(info.GetNumberOfCells())}


def array_range(src, assoc, name, t):
    src.UpdatePipeline(t)
    data = src.PointData if assoc == "POINTS" else src.CellData
    if name not in data.keys() or count(src, t)["cells"] == 0:
        return None
    return list(data[name].GetRange(-1 if data[name].GetNumberOfComponents() > 1 else 0))


def median_radius(src, t):
    """The median of the particles' radius array at time ``t``."""
    from paraview import servermanager
    from vtk.numpy_interface import dataset_adapter as dsa
    src.UpdatePipeline(t)
    data = dsa.WrapDataObject(servermanager.Fetch(src))
    r = data.PointData["radius"]
    try:
        import numpy
        return float(numpy.median(numpy.asarray(r)))
    except Exception:   # no numpy in this ParaView: the middle of the range
        lo, hi = src.PointData["radius"].GetRange()
        return 0.5 * (lo + hi)


def percentiles(src, where, name, t, q=(1.0, 99.0)):
    """The ``q`` percentiles of a scalar array of ``src`` at time ``t``; None without
    numpy or for a vector."""
    try:
        import numpy
        from paraview import servermanager
        from vtk.numpy_interface import dataset_adapter as dsa
    except ImportError:
        return None
    src.UpdatePipeline(t)
    data = dsa.WrapDataObject(servermanager.Fetch(src))
    a = numpy.asarray((data.CellData if where == "CELLS" else data.PointData)[name])
    if a.ndim != 1 or a.size == 0:
        return None
    return [float(v) for v in numpy.percentile(a, q)]


def association(src, name, t):
    src.UpdatePipeline(t)
    if name in src.CellData.keys():
        return "CELLS"
    if name in src.PointData.keys():
        return "POINTS"
    return None


def flat(rep):
    """Colours as they are on the colour bar: no shading of the flat things."""
    rep.Ambient, rep.Diffuse, rep.Specular = 1.0, 0.0, 0.0


def colour_bar(view, lut, title, show):
    bar = GetScalarBar(lut, view)
    bar.Title = title
    bar.ComponentTitle = ""
    bar.WindowLocation = "Any Location"
    bar.Orientation = "Vertical"
    bar.ScalarBarLength = 0.33
    bar.TitleColor = bar.LabelColor = [0.0, 0.0, 0.0]
    bar.TitleFontSize = bar.LabelFontSize = 14
    bar.RangeLabelFormat = "%-#.3g"
    bar.Visibility = int(bool(show))
    if show:
        BARS.append(bar)
    return bar


def main():
    args = options()
    view = GetActiveViewOrCreate("RenderView")
    view.ViewSize = list(args.size)
    try:
        view.UseColorPaletteForBackground = 0
    except AttributeError:
        pass
    view.Background = [1.0, 1.0, 1.0]
    view.OrientationAxesVisibility = 0
    try:
        view.UseFXAA = 1          # smoother thin rings and lines
    except AttributeError:
        pass

    readers = {}
    for kind, name in SERIES.items():
        path = os.path.join(HERE, name)
        if os.path.exists(path):
            readers[kind] = PVDReader(registrationName=name, FileName=path)
    if not readers:
        raise SystemExit("view.py: none of %s in %s" % (sorted(SERIES.values()), HERE))
    first = readers.get("particles") or next(iter(readers.values()))
    times = first.TimestepValues
    try:
        times = list(times)
    except TypeError:       # one snapshot: a number
        times = [times]
    times = [float(x) for x in times if x is not None] or [0.0]
    t = times[-1] if args.time is None else min(times, key=lambda x: abs(x - args.time))
    frame_times = times if args.frames else [t]
    scene = GetAnimationScene()
    scene.UpdateAnimationUsingDataTimeSteps()
    scene.AnimationTime = t

    shown, info = {}, {"time": t, "times": times, "size": list(args.size), "field": args.field}
    field_srcs = []

    # elements and blocks: triangles coloured by the field
    for kind in ("elements", "blocks"):
        if kind not in readers:
            continue
        assoc, arr = VALID[kind]
        src = threshold(readers[kind], assoc, arr, 0.0, kind + "_cells")
        rep = Show(src, view)
        rep.SetRepresentationType("Surface With Edges" if kind == "blocks" else "Surface")
        flat(rep)
        rep.EdgeColor = [0.35, 0.35, 0.35]
        where = association(src, args.field, t)
        if where is not None:
            ColorBy(rep, (where, args.field))
            field_srcs.append((src, where))
        else:
            rep.AmbientColor = rep.DiffuseColor = [0.75, 0.8, 0.9]
        shown[kind] = src
        info[kind] = count(src, t)

    # shaped particles (superellipses): their polygons, filled
    if "shapes" in readers:
        src = threshold(readers["shapes"], "CELLS", "id", 0.0, "shapes_cells")
        rep = Show(src, view)
        rep.SetRepresentationType("Surface With Edges")
        flat(rep)
        rep.AmbientColor = rep.DiffuseColor = [0.8, 0.8, 0.8]
        rep.EdgeColor = [0.45, 0.45, 0.45]
        shown["shapes"] = src
        info["shapes"] = count(src, t)

    # particles: discs at their true radius; particles of PCMM elements as rings over
    # them (their width set below, once the size of a pixel is known)
    rings = ring_disk = None
    r_typical = None
    if "particles" in readers:
        src = threshold(readers["particles"], "POINTS", "id", 0.0, "particles_valid")
        info["particles"] = count(src, t)
        rr = array_range(src, "POINTS", "radius", t)
        info["particles"]["radius"] = rr
        r_typical = median_radius(src, t) if rr else None
        info["particles"]["median_radius"] = r_typical
        free = src
        if "shape" in src.PointData.keys():     # shaped particles are drawn as polygons
            free = threshold(src, "POINTS", "shape", 0.5, "particles_discs", below=True)
        if "elements" in readers and "elements" in src.PointData.keys():
            bonded = threshold(src, "POINTS", "elements", 0.5, "particles_in_elements")
            free = threshold(src, "POINTS", "elements", 0.5, "particles_free", below=True)
            ring_disk = Disk(registrationName="ring", InnerRadius=0.46, OuterRadius=0.5,
                             CircumferentialResolution=64, RadialResolution=1)
            rings = disc_glyphs(bonded, ring_disk, "rings", view, [0.4, 0.4, 0.4])
            rings.GlyphTransform.Translate = [0.0, 0.0, 0.01]   # over the elements
            shown["rings"] = rings
            info["particles"]["in_elements"] = count(bonded, t)["points"]
        if DIM == 3:
            disk = Sphere(registrationName="sphere", Radius=0.5, ThetaResolution=24,
                          PhiResolution=16)
        else:
            disk = Disk(registrationName="disc", InnerRadius=0.0, OuterRadius=0.5,
                        CircumferentialResolution=64, RadialResolution=1)
        if DIM == 3 and "shape_tensor" in src.PointData.keys():
            # ellipsoids: a sphere of radius 0.5 stretched by the shape tensor's
            # eigenvalues (the diameters) along its eigenvectors
            discs = TensorGlyph(registrationName="ellipsoids", Input=src, GlyphType=disk)
            discs.Tensors = ["POINTS", "shape_tensor"]
            discs.ExtractEigenvalues = 1
            discs.ColorGlyphs = 0
            discs.ScaleFactor = 1.0
            rep = Show(discs, view)
            rep.ColorArrayName = ["POINTS", ""]
            rep.AmbientColor = rep.DiffuseColor = [0.8, 0.8, 0.8]
        else:
            discs = disc_glyphs(free, disk, "discs", view, [0.8, 0.8, 0.8])
        if DIM == 3:
            GetActiveViewOrCreate("RenderView")
            srep = Show(discs, view)
            srep.Interpolation = "Gouraud"
            srep.Ambient, srep.Diffuse = 0.25, 0.8
        else:
            discs.GlyphTransform.Translate = [0.0, 0.0, 0.01]
        shown["particles"] = discs
        info["discs"] = {"bounds": union(bounds(discs, t), bounds(rings, t) if rings else None)}

    # walls and couplings: lines
    for kind, width, colour in (("walls", 4.0, [0.1, 0.1, 0.1]),
                                ("couplings", 1.5, [0.1, 0.3, 0.8])):
        if kind not in readers:
            continue
        assoc, arr = VALID[kind]
        if DIM == 3 and kind == "walls":
            # mesh walls: translucent surfaces with their edges (no index array to
            # threshold on: the placeholder of a mesh-less file is one point)
            rep = Show(readers[kind], view)
            rep.SetRepresentationType("Surface With Edges")
            rep.ColorArrayName = ["POINTS", ""]
            rep.AmbientColor = rep.DiffuseColor = [0.55, 0.6, 0.7]
            rep.EdgeColor = [0.3, 0.3, 0.35]
            rep.Opacity = 0.25
            shown[kind] = readers[kind]
            info[kind] = count(readers[kind], t)
            continue
        src = threshold(readers[kind], assoc, arr, 0.0, kind + "_cells")
        rep = Show(src, view)
        flat(rep)
        rep.ColorArrayName = ["POINTS", ""]
        rep.AmbientColor = rep.DiffuseColor = colour
        rep.LineWidth = width
        try:
            rep.RenderLinesAsTubes = 1
        except AttributeError:
            pass
        shown[kind] = src
        info[kind] = count(src, t)

    # contacts: tubes of radius proportional to |normal force|
    tubes = None
    if "contacts" in readers:
        absf = Calculator(registrationName="abs_normal_force", Input=readers["contacts"])
        absf.AttributeType = "Point Data"
        absf.ResultArrayName = "abs_normal_force"
        absf.Function = "abs(normal_force)"
        loaded = threshold(absf, "POINTS", "abs_normal_force", 1e-300, "contacts_in_force")
        surf = ExtractSurface(registrationName="contact_lines", Input=loaded)
        fmax = 0.0
        for ft in frame_times:
            rng = array_range(surf, "POINTS", "abs_normal_force", ft)
            if rng:
                fmax = max(fmax, rng[1])
        info["contacts"] = count(surf, t)
        info["contacts"]["max_abs_normal_force"] = fmax
        if fmax > 0.0 and r_typical:
            scale = TUBE * r_typical / fmax
            rad = Calculator(registrationName="tube_radius", Input=surf)
            rad.AttributeType = "Point Data"
            rad.ResultArrayName = "tube_radius"
            rad.Function = "abs_normal_force*%r" % scale
            tubes = Tube(registrationName="contact_tubes", Input=rad)
            tubes.Scalars = ["POINTS", "tube_radius"]
            tubes.VaryRadius = "By Absolute Scalar"   # radius = the scalar
            tubes.Radius = 1.0
            tubes.NumberofSides = 16
            tubes.Capping = 1
            rep = Show(tubes, view)
            ColorBy(rep, ("POINTS", "normal_force"))
            lut = GetColorTransferFunction("normal_force")
            lut.ApplyPreset("Inferno (matplotlib)", True)
            lut.InvertTransferFunction()
            lut.RescaleTransferFunction(0.0, fmax)
            lut.AutomaticRescaleRangeMode = "Never"
            colour_bar(view, lut, "normal force (%s)" % ("N" if DIM == 3 else "N/m"),
                       not args.no_text)
            info["contacts"]["tube_bounds"] = bounds(tubes, t)
            info["contacts"]["tube_scale"] = scale
            shown["contacts"] = tubes

    # bonds: lines coloured by their normal force (blue compression, red tension);
    # cracks: dots coloured by mode (red tension, blue shear)
    if "bonds" in readers:
        src = threshold(readers["bonds"], "CELLS", "id", 0.0, "bonds_intact")
        rep = Show(src, view)
        flat(rep)
        rep.LineWidth = 2.0
        if DIM == 2:
            rep.Position = [0.0, 0.0, 0.02]          # over the discs
        ColorBy(rep, ("CELLS", "normal_force"))
        lut = GetColorTransferFunction("normal_force")
        lut.ApplyPreset("Cool to Warm", True)
        lut.InvertTransferFunction()
        rng = array_range(src, "CELLS", "normal_force", t)
        top = max(abs(rng[0]), abs(rng[1])) if rng else 1.0
        lut.RescaleTransferFunction(-top, top)
        colour_bar(view, lut, "bond normal force (%s)" % ("N" if DIM == 3 else "N/m"),
                   not args.no_text)
        shown["bonds"] = src
        info["bonds"] = count(src, t)
    if "cracks" in readers:
        src = threshold(readers["cracks"], "POINTS", "id", 0.0, "cracks_valid")
        rep = Show(src, view)
        rep.SetRepresentationType("Points")
        rep.PointSize = 7.0
        if DIM == 2:
            rep.Position = [0.0, 0.0, 0.03]          # over the discs and the bonds
        try:
            rep.RenderPointsAsSpheres = 1
        except AttributeError:
            pass
        ColorBy(rep, ("POINTS", "mode"))
        lut = GetColorTransferFunction("mode")
        lut.RGBPoints = [0.0, 0.85, 0.1, 0.1, 1.0, 0.1, 0.3, 0.9]   # tension red, shear blue
        lut.RescaleTransferFunction(0.0, 1.0)
        colour_bar(view, lut, "crack mode (0 tension, 1 shear)", not args.no_text)
        shown["cracks"] = src
        info["cracks"] = count(src, t)

    # one scale for the field over elements and blocks: its 1st to 99th percentile (a
    # stress concentration at a corner does not wash out the rest), symmetric about 0
    # for stresses and pressures
    if field_srcs:
        lo, hi = math.inf, -math.inf
        full = [math.inf, -math.inf]
        for ft in frame_times:
            for src, where in field_srcs:
                rng = array_range(src, where, args.field, ft)
                if rng:
                    full = [min(full[0], rng[0]), max(full[1], rng[1])]
                    rng = percentiles(src, where, args.field, ft) or rng
                    lo, hi = min(lo, rng[0]), max(hi, rng[1])
        if lo <= hi:
            info["field_full_range"] = full
            lut = GetColorTransferFunction(args.field)
            if args.field.startswith(("stress", "pressure")):
                # blue compression, red tension, white zero, whatever the range
                lut.ApplyPreset("Cool to Warm", True)
                lo, hi = -max(-lo, hi), max(-lo, hi)
            else:
                lut.ApplyPreset("Viridis (matplotlib)", True)
            if hi <= lo:
                hi = lo + 1.0
            lut.RescaleTransferFunction(lo, hi)
            lut.AutomaticRescaleRangeMode = "Never"
            unit = FIELD_UNIT if args.field == FIELD else ""
            colour_bar(view, lut, args.field + (" (%s)" % unit if unit else ""),
                       not args.no_text)
            info["field_range"] = [lo, hi]

    caption = None
    if not args.no_text:
        caption = Text(registrationName="caption")
        crep = Show(caption, view)
        crep.WindowLocation = "Upper Left Corner"
        crep.FontSize = 16
        crep.Color = [0.0, 0.0, 0.0]

    # the camera: looking down z onto the union of what is shown, a margin around it
    # (the bodies: particles, elements, blocks; walls may reach far beyond them)
    box = None
    bodies = [v for k, v in shown.items()
              if k in ("particles", "rings", "elements", "blocks", "shapes")]
    for src in bodies or list(shown.values()):
        for ft in frame_times:
            box = union(box, bounds(src, ft))
    if box is None:
        box = [-1.0, 1.0, -1.0, 1.0, 0.0, 0.0]
    w, h = max(box[1] - box[0], 1e-12), max(box[3] - box[2], 1e-12)
    bars = not args.no_text and (tubes is not None or field_srcs)
    usable = (0.80 if bars else 0.96, 0.90 if not args.no_text else 0.96)
    aspect = args.size[0] / float(args.size[1])
    scale = 0.5 * max(h / usable[1], w / (usable[0] * aspect))
    cx = 0.5 * (box[0] + box[1]) + (scale * aspect * (1.0 - usable[0]) * 0.8 if bars else 0.0)
    cy = 0.5 * (box[2] + box[3]) + (scale * (1.0 - usable[1]) * 0.5 if not args.no_text else 0.0)
    Render(view)            # paraview.simple resets the camera at the first render
    if DIM == 3:
        # 3D: a perspective view from the front, above and to the side, fitting the
        # bodies and the walls
        for src in shown.values():
            for ft in frame_times:
                box = union(box, bounds(src, ft))
        c = [0.5 * (box[0] + box[1]), 0.5 * (box[2] + box[3]), 0.5 * (box[4] + box[5])]
        size3 = max(box[1] - box[0], box[3] - box[2], box[5] - box[4], 1e-12)
        view.CameraFocalPoint = c
        view.CameraPosition = [c[0] + 1.6 * size3, c[1] - 2.2 * size3, c[2] + 1.3 * size3]
        view.CameraViewUp = [0.0, 0.0, 1.0]
        view.CameraViewAngle = 30.0
        view.ResetCamera(False)
        info["camera"] = {"focal_point": c, "bounds": box}
        return _finish(args, view, scene, caption, frame_times, info)
    view.InteractionMode = "2D"
    view.CameraParallelProjection = 1
    view.CameraFocalPoint = [cx, cy, 0.0]
    view.CameraPosition = [cx, cy, 10.0 * max(w, h)]
    view.CameraViewUp = [0.0, 1.0, 0.0]
    view.CameraParallelScale = scale
    info["camera"] = {"focal_point": [cx, cy], "parallel_scale": scale, "bounds": box}
    if ring_disk is not None:
        # rings about 1.2 pixels wide; none where a particle is under 8 pixels across
        pixel = 2.0 * scale / args.size[1]
        ring_disk.InnerRadius = min(0.485, max(0.3, 0.5 - 1.2 * pixel / (2.0 * r_typical)))
        if r_typical < 4.0 * pixel:
            Hide(rings, view)
        info["rings"] = {"inner_radius": ring_disk.InnerRadius,
                         "radius_pixels": r_typical / pixel}

    return _finish(args, view, scene, caption, frame_times, info)


def _finish(args, view, scene, caption, frame_times, info):
    """Colour bars placed, the screenshots saved, ``info`` written."""
    for k, bar in enumerate(BARS):
        bar.Position = [0.86, 0.55 - 0.42 * k]

    png = args.png or os.path.join(HERE, PNG)
    stem, ext = os.path.splitext(png)
    written = []
    for k, ft in enumerate(frame_times):
        scene.AnimationTime = ft
        view.ViewTime = ft
        if caption is not None:
            caption.Text = "%s   t = %.6g s" % (TITLE, ft) if TITLE else "t = %.6g s" % ft
        Render(view)
        if AS_PROGRAM:
            out = "%s_%05d%s" % (stem, k, ext or ".png") if args.frames else png
            SaveScreenshot(out, view, ImageResolution=list(args.size))
            written.append(out)
    info["png"] = written
    if args.info:
        with open(args.info, "w") as f:
            json.dump(info, f, indent=1)
    if written:
        print("view.py: wrote %s" % (written[0] if len(written) == 1 else
                                     "%d frames %s ... %s" % (len(written), written[0],
                                                               written[-1])))
    if AS_PROGRAM and args.interactive:
        from paraview.simple import Interact
        Interact(view)
    return info


main()
'''
