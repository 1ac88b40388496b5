"""What every case script shares: command line, output folder, summary, histories,
plots, and the list of cases the ``tdem`` command offers.

A case is a module ``cases/NAME.py`` with a ``main(argv=None)`` function; the first
line of its docstring is its one-line description (``tdem list``).
"""
import argparse
import ast
import contextlib
import json
import math
import pkgutil
import sys
import time
from pathlib import Path

import numpy as np

PRESETS = ("quick", "paper")
CASES_DIR = Path(__file__).resolve().parent


# ---------------------------------------------------------------- command line
# how the case was started, for its usage line (``tdem run`` sets "tdem run NAME")
COMMAND = None


#: wall time of each case's quick preset, seconds, as ``--help`` shows it; written by
#: ``python -m cases.report --write`` from the summaries (docs/cases.md)
# quick-times:start
QUICK_WALL_S = {
    "nine_disc": 10, "photoelastic": 23, "biaxial": 80, "elastic_gravity": 10,
    "uniaxial_compression": 18, "wave_bar": 38, "soil_cutting": 19,
    "contact_burst": 160, "water_blocks": 81, "plate_loading": 76,
    "ellipsoid_compression": 114, "impact_benchmarks": 24, "angle_of_repose": 720,
    "dam_break": 31, "bearing_capacity": 39, "rotating_drum": 62, "hopper_discharge": 74,
    "bonded_rock": 107, "wet_column": 108, "triaxial_3d": 240,
}
QUICK_MEASURED = "measured with --threads 1 on 2 CPU cores, 2026-12-06"
# quick-times:end


def duration(seconds):
    """'40 s', '1.5 min', '12 min'."""
    if seconds < 90:
        return f"{seconds:.0f} s"
    m = seconds / 60.0
    return f"{m:.1f} min" if m < 10 else f"{m:.0f} min"


def help_description(case, doc):
    """The --help description of a case: the first line of ``doc`` (its docstring) and
    the measured wall time of its quick preset."""
    first = (doc or "").strip().splitlines()[0] if (doc or "").strip() else ""
    t = QUICK_WALL_S.get(case)
    if t is None:
        return first
    return f"{first}\n\nquick preset: {duration(t)} ({QUICK_MEASURED})."


def parser(case, description=None):
    """The options every case takes: --preset, --arch, --out, --threads."""
    p = argparse.ArgumentParser(prog=COMMAND or f"python -m cases.{case}",
                                description=help_description(case, description),
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--preset", choices=PRESETS, default="quick",
                   help="quick: coarse (its measured time is above); "
                        "paper: the paper's full set of runs (default: quick)")
    p.add_argument("--arch", choices=("cpu", "gpu"), default=None,
                   help="Taichi back end (default: $TDEM_ARCH, else cpu)")
    p.add_argument("--out", default=None, metavar="DIR",
                   help=f"output folder (default: out/{case})")
    p.add_argument("--threads", type=int, default=None,
                   help="CPU threads (default: Taichi's choice or $TDEM_THREADS)")
    return p


def parse(case, argv=None, description=None, extra=None):
    """Parse ``argv`` (None: sys.argv[1:]); ``extra(parser)`` may add case options.
    Creates the output folder and returns (args, out: Path)."""
    p = parser(case, description)
    if extra is not None:
        extra(p)
    args = p.parse_args(argv)
    if args.threads is not None and args.threads < 1:
        p.error(f"--threads must be >= 1, got {args.threads}")
    try:
        out = output_dir(case, args.out)
    except OSError as e:
        p.error(f"--out {args.out or out_default(case)}: cannot write there "
                f"({e.strerror or e})")
    return args, out


def out_default(case):
    return str(Path("out") / case)


def output_dir(case, out=None):
    """The output folder, created; OSError where it cannot be (a file of that name, no
    permission)."""
    path = Path(out) if out else Path("out") / case
    path.mkdir(parents=True, exist_ok=True)
    probe = path / ".tdem-write-test"
    probe.write_bytes(b"")
    probe.unlink()
    return path


def sim_options(args):
    """Keyword arguments of :class:`tdem.Simulation` that come from the command line."""
    return {"arch": args.arch, "threads": args.threads}


# ----------------------------------------------------------------- summary
#: the version of the summary.json layout (docs/cases.md, "summary.json")
SCHEMA = "tdem-case-summary/1"
#: keys of one check, in this order
CHECK_KEYS = ("name", "value", "target", "tolerance", "unit", "pass", "note")
#: keys every summary has
SUMMARY_KEYS = ("schema", "case", "preset", "pass", "checks", "wall_time_s", "threads",
                "tdem_version", "data")


def rel(x):
    """Tolerance: |value − target| ≤ x·|target|."""
    return {"rel": float(x)}


def absolute(x):
    """Tolerance: |value − target| ≤ x (in the check's unit)."""
    return {"abs": float(x)}


def between(min=None, max=None):
    """Tolerance: min ≤ value ≤ max (either bound may be left out); the target, if
    any, is the paper's value shown beside it."""
    t = {}
    if min is not None:
        t["min"] = float(min)
    if max is not None:
        t["max"] = float(max)
    if not t:
        raise ValueError("between() needs min or max")
    return t


#: tolerance of a text or true/false figure: the value must equal the target
EQUAL = {"equal": True}


def _number(v):
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def _passes_one(value, target, tolerance):
    if "equal" in tolerance:
        return value == target
    if not _number(value):
        return False
    if "rel" in tolerance or "abs" in tolerance:
        if not _number(target):
            return False
        bound = (tolerance["rel"] * abs(target) if "rel" in tolerance
                 else tolerance["abs"])
        return abs(value - target) <= bound * (1.0 + 1e-12)
    lo, hi = tolerance.get("min"), tolerance.get("max")
    return (lo is None or value >= lo) and (hi is None or value <= hi)


def passes(value, target, tolerance):
    """Whether ``value`` meets ``target`` within ``tolerance`` (None: no tolerance, a
    reported-only figure). A list value passes if every element does (against the
    matching element of a list target, or the one target). A value that could not be
    measured (None, NaN) fails."""
    if tolerance is None:
        return None
    value, target = _plain(value), _plain(target)
    if isinstance(value, list) and "equal" not in tolerance:
        if not value:
            return False
        targets = target if isinstance(target, list) else [target] * len(value)
        if len(targets) != len(value):
            return False
        return all(_passes_one(v, t, tolerance) for v, t in zip(value, targets))
    return bool(_passes_one(value, target, tolerance))


def check(name, value, target=None, tolerance=None, unit="", note=""):
    """One compared figure of ``summary.json``: its value beside its target, the
    tolerance it is compared with (:func:`rel`, :func:`absolute`, :func:`between`,
    :data:`EQUAL`; None: reported only) and whether it passes (None when reported
    only)."""
    if tolerance is not None:
        keys = set(tolerance)
        if not (keys in ({"rel"}, {"abs"}, {"equal"}) or (keys and keys <= {"min", "max"})):
            raise ValueError(f"check {name!r}: tolerance {tolerance!r} is not one of "
                             "{'rel'}, {'abs'}, {'min', 'max'}, {'equal'}")
        if keys & {"rel", "abs", "equal"} and target is None:
            raise ValueError(f"check {name!r}: a {sorted(keys)[0]} tolerance needs a target")
    return {"name": str(name), "value": _plain(value), "target": _plain(target),
            "tolerance": tolerance, "unit": unit, "pass": passes(value, target, tolerance),
            "note": note}


def overall_pass(checks):
    """True if every compared check passes, False if one fails, None if none compares."""
    compared = [c["pass"] for c in checks if c["pass"] is not None]
    return all(compared) if compared else None


def summary(case, preset, checks, data, wall_time_s, threads=None, paper=None, notes=None,
            variant=None):
    """The summary of one run (docs/cases.md, "summary.json"): the checks, the overall
    pass, what ran and how long, and the case's own data under ``data``. ``variant``:
    a name for a run that is not the preset as it stands (e.g. "cells-four": other
    water, one of its two systems); the validation report keeps it beside the
    preset's own run."""
    names = [c["name"] for c in checks]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise ValueError(f"checks named twice: {dup}")
    from tdem import __version__
    out = {
        "schema": SCHEMA, "case": case, "preset": preset,
        "pass": overall_pass(checks),
        "counts": {"checks": len(checks),
                   "passed": sum(c["pass"] is True for c in checks),
                   "failed": sum(c["pass"] is False for c in checks),
                   "reported": sum(c["pass"] is None for c in checks)},
        "checks": list(checks),
        "wall_time_s": float(wall_time_s), "threads": threads,
        "cpu_count": _cpu_count(), "tdem_version": __version__,
        "date": time.strftime("%Y-%m-%d"),
    }
    if paper:
        out["paper"] = paper
    if notes:
        out["notes"] = notes
    if variant:
        out["variant"] = str(variant)
    out["data"] = data
    return _plain(out)


def _cpu_count():
    try:
        import os
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        import os
        return os.cpu_count()


def validate(s):
    """Problems of a summary against the schema (an empty list: none)."""
    bad = []
    if not isinstance(s, dict):
        return ["not a JSON object"]
    for k in SUMMARY_KEYS:
        if k not in s:
            bad.append(f"missing key {k!r}")
    if s.get("schema") != SCHEMA:
        bad.append(f"schema {s.get('schema')!r}, expected {SCHEMA!r}")
    if s.get("preset") not in PRESETS:
        bad.append(f"preset {s.get('preset')!r}")
    checks = s.get("checks")
    if not isinstance(checks, list):
        return bad + ["checks is not a list"]
    names = set()
    for c in checks:
        if not isinstance(c, dict) or set(c) != set(CHECK_KEYS):
            bad.append(f"check {c!r}: keys must be {CHECK_KEYS}")
            continue
        if c["name"] in names:
            bad.append(f"check {c['name']!r} named twice")
        names.add(c["name"])
        try:
            expected = passes(c["value"], c["target"], c["tolerance"])
        except (TypeError, KeyError, AttributeError) as e:
            bad.append(f"check {c['name']!r}: tolerance {c['tolerance']!r} ({e})")
            continue
        if c["pass"] != expected:
            bad.append(f"check {c['name']!r}: pass {c['pass']!r}, but value, target and "
                       f"tolerance give {expected!r}")
    if s.get("pass") != overall_pass([c for c in checks if isinstance(c, dict)
                                      and "pass" in c]):
        bad.append(f"pass {s.get('pass')!r} is not all(check passes)")
    if not isinstance(s.get("wall_time_s"), (int, float)) or s["wall_time_s"] < 0:
        bad.append(f"wall_time_s {s.get('wall_time_s')!r}")
    return bad


def checks_by_name(s):
    """{name: check} of a summary."""
    return {c["name"]: c for c in s["checks"]}


def reached(run_end, paper_time):
    """Whether a run that ends at ``run_end`` reaches a paper figure at ``paper_time``
    (same clock): a figure the run does not reach is reported, not compared."""
    return run_end >= paper_time * (1.0 - 1e-9)


def figure(value, target=None, unit="", note=""):
    """A figure kept with the case's data (not a check): the value beside a target."""
    return {"value": _plain(value), "target": _plain(target), "unit": unit, "note": note}


def _plain(v):
    """numpy scalars and arrays to JSON-able Python values; NaN/inf to None."""
    if isinstance(v, dict):
        return {str(k): _plain(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_plain(x) for x in v]
    if isinstance(v, np.ndarray):
        return _plain(v.tolist())
    if isinstance(v, (np.bool_, bool)):
        return bool(v)
    if isinstance(v, (np.integer,)):
        return int(v)
    if isinstance(v, (float, np.floating)):
        v = float(v)
        return v if math.isfinite(v) else None
    return v


def write_summary(out, summary):
    """Write ``out/summary.json`` (made with :func:`summary`); refuses one that does not
    follow the schema."""
    summary = _plain(summary)
    bad = validate(summary)
    if bad:
        raise ValueError("summary.json does not follow the schema: " + "; ".join(bad))
    path = Path(out) / "summary.json"
    with open(path, "w") as f:
        json.dump(summary, f, indent=2)
        f.write("\n")
    return path


def print_checks(s, file=None):
    """One line per compared check, then the overall pass and the wall time."""
    file = file or sys.stdout
    for c in s["checks"]:
        if c["pass"] is None:
            continue
        print(f"  {'ok  ' if c['pass'] else 'FAIL'} {c['name']}: {format_value(c)} "
              f"(target {format_target(c)})", file=file)
    n = s["counts"]
    print(f"{s['case']} ({s['preset']}): {n['passed']} of {n['passed'] + n['failed']} checks "
          f"pass, {n['reported']} reported; pass = {s['pass']}; {s['wall_time_s']:.0f} s",
          file=file)


# ------------------------------------------------------ formatting of checks
_SCALE = {"N/m": (1e-3, "kN/m"), "deg": (1.0, "°")}


def _fmt(v, measured=False):
    """A number for a table: 4 significant digits (a measured value keeps its trailing
    zeros: 1.000), integers as they are."""
    if v is None:
        return "–"
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, str):
        return v
    if isinstance(v, list):
        return "[" + ", ".join(_fmt(x, measured) for x in v) + "]"
    if isinstance(v, dict):
        return ", ".join(f"{k} {_fmt(x, measured)}" for k, x in v.items())
    if isinstance(v, int) or v == 0:
        return str(int(v)) if float(v).is_integer() and abs(v) < 1e6 else f"{v:.4g}"
    text = f"{v:#.4g}" if measured and 1e-3 <= abs(v) < 1e5 else f"{v:.4g}"
    return text.rstrip(".")


def _magnitude(v):
    if isinstance(v, list):
        return max((_magnitude(x) for x in v), default=0.0)
    return abs(v) if _number(v) else 0.0


def _scaled(c):
    """(factor, unit) to show a check in: Pa as MPa or kPa, short times in ms."""
    unit = c.get("unit") or ""
    big = max(_magnitude(c.get("value")), _magnitude(c.get("target")))
    if unit == "Pa" and big > 0:
        return (1e-9, "GPa") if big >= 1e10 else (1e-6, "MPa") if big >= 1e5 else (1e-3, "kPa")
    if unit == "s" and 0 < big < 0.1:
        return 1e3, "ms"
    return _SCALE.get(unit, (1.0, unit))


def _times(v, k):
    if isinstance(v, list):
        return [_times(x, k) for x in v]
    if not _number(v) or k == 1.0:
        return v
    return v * k


def _with_unit(text, unit):
    if not unit or text == "–":
        return text
    return f"{text}{unit}" if unit == "°" else f"{text} {unit}"


def format_value(c):
    """The value of a check with its unit, for a table or a log line."""
    k, unit = _scaled(c)
    return _with_unit(_fmt(_times(c["value"], k), measured=True), unit)


def format_target(c):
    """The target and tolerance of a check, e.g. '0.39 ± 5 %', '≤ 0.05', '= toppled'."""
    k, unit = _scaled(c)
    t, tol = _times(c["target"], k), c["tolerance"]
    u = lambda text: _with_unit(text, unit)      # noqa: E731
    if tol is None:
        return "–" if t is None else f"{u(_fmt(t))} (reported)"
    if "equal" in tol:
        return f"= {_fmt(t)}"
    if "rel" in tol:
        return f"{u(_fmt(t))} ± {100 * tol['rel']:g} %"
    if "abs" in tol:
        if tol["abs"] == 0:
            return f"= {u(_fmt(t))}"
        return f"{_fmt(t)} ± {u(_fmt(tol['abs'] * k))}"
    lo, hi = tol.get("min"), tol.get("max")
    if lo is not None and hi is not None:
        rng = f"{_fmt(lo * k)}–{u(_fmt(hi * k))}"
    elif lo is not None:
        rng = f"≥ {u(_fmt(lo * k))}"
    else:
        rng = f"≤ {u(_fmt(hi * k))}"
    if t is None or t in (lo * k if lo is not None else None, hi * k if hi is not None else None):
        return rng
    return f"{rng} (paper {u(_fmt(t))})"


class Stopwatch:
    """Wall-clock seconds since creation (for the run time in the summary)."""

    def __init__(self):
        self.t0 = time.perf_counter()

    def __call__(self):
        return time.perf_counter() - self.t0


# ----------------------------------------------------------------- histories
def save_histories(path, runs):
    """Write the monitor histories of several runs to one HDF5 file.

    ``runs``: {run name: {monitor name: (times, values)}} (``sim.histories()``) or
    {run name: {series name: array}}. Groups ``/run/monitor`` hold datasets ``time``
    and ``value``; plain arrays become datasets ``/run/series``.
    """
    import h5py
    with h5py.File(path, "w") as f:
        for run, series in runs.items():
            g = f.require_group(run)
            for name, data in series.items():
                if isinstance(data, tuple) and len(data) == 2:
                    h = g.require_group(name)
                    h.create_dataset("time", data=np.asarray(data[0], dtype=float))
                    h.create_dataset("value", data=np.asarray(data[1], dtype=float))
                else:
                    g.create_dataset(name, data=np.asarray(data, dtype=float))
    return path


def plot_histories(source, png, title=None, names=None, components=None, units=None,
                   scales=None, time_label="time (s)", time_scale=1.0):
    """PNG of monitor histories, one panel per monitor, every axis with its unit.

    ``source``: a Simulation or {monitor: (times, values)}. ``names``: {monitor: label
    of its axis} (default: the monitor's name); ``components``: {monitor: [names of
    its components]} for the legend of a vector-valued monitor; ``units``: {monitor:
    unit} (shown in brackets; "–" for a pure number); ``scales``: {monitor: factor}
    that the values are multiplied by to be in that unit. ``time_scale`` multiplies
    the times (1e3 with ``time_label="time (ms)"``)."""
    hist = source.histories() if hasattr(source, "histories") else source
    names, components, units = names or {}, components or {}, units or {}
    scales = scales or {}
    plt = pyplot()
    keys = [k for k, (t, v) in hist.items() if len(t)]
    fig, axes = plt.subplots(len(keys) or 1, 1, figsize=(7, 1.0 + 2.2 * max(len(keys), 1)),
                             sharex=True, squeeze=False)
    for ax, key in zip(axes[:, 0], keys):
        t, v = hist[key]
        t = np.asarray(t, dtype=float) * time_scale
        v = np.asarray(v, dtype=float).reshape(len(t), -1) * scales.get(key, 1.0)
        comp = components.get(key) or ([key] if v.shape[1] == 1 else
                                       [f"{key} {c + 1}" for c in range(v.shape[1])])
        for c in range(v.shape[1]):
            ax.plot(t, v[:, c], lw=1.2, label=comp[c])
        if v.shape[1] > 1:
            ax.legend(fontsize=8, loc="best")
        unit = units.get(key)
        label = names.get(key, key.replace("_", " "))
        ax.set_ylabel(f"{label} ({unit})" if unit else label, fontsize=9)
        ax.grid(alpha=0.3)
    axes[-1, 0].set_xlabel(time_label)
    if title:
        axes[0, 0].set_title(title, fontsize=10)
    fig.tight_layout()
    return save(fig, png, dpi=120)


def start_output(sim, directory, every):
    """``sim.output(directory, every=every)`` (VTU series with ``.pvd``, ``monitors.h5``);
    None, with a note on stderr, if this build of the engine has no output writer."""
    try:
        return sim.output(str(directory), every=every)
    except (ImportError, AttributeError) as e:
        print(f"note: no VTU series written ({e})", file=sys.stderr)
        return None


def finish_output(output):
    """Close the writer returned by :func:`start_output` (if it has anything to close)."""
    fn = getattr(output, "close", None)
    if callable(fn):
        fn()


def pyplot():
    """matplotlib.pyplot on the non-interactive Agg back end."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def save(fig, png, dpi=130):
    """Save a figure trimmed to its content (no empty margins) and close it."""
    import matplotlib.pyplot as plt
    fig.savefig(png, dpi=dpi, bbox_inches="tight", pad_inches=0.05)
    plt.close(fig)
    return png


# --------------------------------------------------------- force-vector picture
def force_vector_plot(ax, positions, radii, contacts, walls=(), max_width=None,
                      color="k", disc_color="0.55", label_walls=None):
    """Draw C&S's force-vector picture (their Fig. 5b) on ``ax``.

    Each contact is a bar through its contact point along the direction of the
    contact force, as long as the sum of the two radii (R_i on one side of the
    contact point, R_j on the other; a disc–wall bar is one radius long, from the
    wall into the disc), its width proportional to the magnitude of the force
    (``max_width`` for the largest; default 0.6 × the smallest radius). Discs are
    drawn as circles, walls as thick lines.

    ``contacts``: ``sim.contacts.numpy()``; ``walls``: a list of (2, 2) endpoint arrays.
    Returns the force that ``max_width`` stands for.
    """
    from matplotlib.collections import PatchCollection
    from matplotlib.patches import Circle, Polygon

    positions = np.asarray(positions)
    radii = np.asarray(radii)
    ax.add_collection(PatchCollection([Circle(p, r) for p, r in zip(positions, radii)],
                                      facecolor="none", edgecolor=disc_color, linewidth=0.8))
    for k, e in enumerate(walls):
        e = np.asarray(e)
        ax.plot(e[:, 0], e[:, 1], color="0.2", linewidth=3, solid_capstyle="butt")
        if label_walls is not None:
            m = e.mean(axis=0)
            ax.annotate(label_walls[k], m, fontsize=9, ha="center", va="center",
                        bbox=dict(boxstyle="round", fc="w", ec="0.5"))
    pairs = np.asarray(contacts["pairs"])
    fn = np.asarray(contacts["normal"])
    fs = np.asarray(contacts["shear"])
    n = np.asarray(contacts["direction"])
    pts = np.asarray(contacts["point"])
    mag = np.hypot(fn, fs)
    fmax = float(mag.max()) if len(mag) else 0.0
    if max_width is None:
        max_width = 0.6 * float(radii.min())
    polys = []
    for (i, j), nk, fnk, fsk, pk, mk in zip(pairs, n, fn, fs, pts, mag):
        if mk <= 0.0 or fmax <= 0.0:
            continue
        t = np.array([-nk[1], nk[0]])
        d = fnk * nk - fsk * t           # force on j (the second) by i
        d = d / np.linalg.norm(d)
        half_w = 0.5 * max_width * mk / fmax
        side = np.array([-d[1], d[0]]) * half_w
        if j >= 0:
            a = pk - d * radii[i]
            b = pk + d * radii[j]
        else:  # wall: from the contact point into the disc, one radius long
            a = pk - d * radii[i] * np.sign(d @ nk)
            b = pk
        polys.append(Polygon([a + side, b + side, b - side, a - side]))
    ax.add_collection(PatchCollection(polys, facecolor=color, edgecolor="none"))
    ax.set_aspect("equal")
    ax.autoscale_view()
    return fmax


def contact_between(contacts, i, j):
    """(F_n, F_s) of the contact between particles i and j, or (0.0, 0.0) if none.

    The engine stores each pair once (lower index first). Swapping the order flips
    both n and t, and the force on i, -F_n n + F_s t, keeps the same F_n and F_s, so
    the values hold in the frame of (i, j) as asked.
    """
    p = contacts["pairs"]
    m = (p[:, 0] == i) & (p[:, 1] == j)
    if m.any():
        k = int(np.argmax(m))
        return float(contacts["normal"][k]), float(contacts["shear"][k])
    m = (p[:, 0] == j) & (p[:, 1] == i)
    if m.any():
        k = int(np.argmax(m))
        return float(contacts["normal"][k]), float(contacts["shear"][k])
    return 0.0, 0.0


# ----------------------------------------------------------------- case list
def _case_info(path):
    """(description, has main) read from the module's source without importing it."""
    try:
        tree = ast.parse(path.read_text(encoding="utf-8"))
    except (OSError, SyntaxError):
        return None, False
    has_main = any(isinstance(node, ast.FunctionDef) and node.name == "main"
                   for node in tree.body)
    doc = ast.get_docstring(tree) or ""
    first = doc.strip().splitlines()[0].strip() if doc.strip() else ""
    return first, has_main


#: modules of ``cases`` with a ``main`` that are tools, not cases
NOT_CASES = ("report",)


def list_cases():
    """{name: one-line description} of the modules in ``cases`` with a ``main``."""
    found = {}
    for mod in sorted(pkgutil.iter_modules([str(CASES_DIR)]), key=lambda m: m.name):
        if mod.name.startswith("_") or mod.ispkg or mod.name in NOT_CASES:
            continue
        desc, has_main = _case_info(CASES_DIR / f"{mod.name}.py")
        if has_main:
            found[mod.name] = desc
    return found



# ----------------------------------------------------------------- Dask sweeps
SWEEP_INSTALL = 'pip install "tdem[sweep]"'


def dask_distributed():
    """(Client, LocalCluster) of ``distributed``, imported on first use: Dask is an
    optional extra of tdem. ImportError naming the install command when it is missing."""
    try:
        from distributed import Client, LocalCluster
    except ImportError as e:
        raise ImportError(f"the sweep runs on Dask (dask.distributed), which is not "
                          f"installed: {SWEEP_INSTALL} (or pip install "
                          f'"dask[distributed]") ({e})') from None
    return Client, LocalCluster


def say(text):
    """A progress line, shown at once also when the output goes to a file."""
    print(text, flush=True)


def gather_in_order(futures, name, line, each=None, offset=0, total=None):
    """The results of Dask ``futures`` in their order, printing "``name``: count
    ``line(result)``" as each one ends (a sweep's progress; the count starts after
    ``offset`` results found before, out of ``total``). ``each(k, result)`` is
    called as result k ends (e.g. to keep it on disk)."""
    from distributed import as_completed
    index = {f.key: k for k, f in enumerate(futures)}
    results = [None] * len(futures)
    total = len(futures) + offset if total is None else total
    for done, f in enumerate(as_completed(futures), 1):
        r = f.result()
        k = index[f.key]
        results[k] = r
        if each is not None:
            each(k, r)
        say(f"{name}: {done + offset}/{total} {line(r)}")
    return results


@contextlib.contextmanager
def dask_client(scheduler=None, workers=2):
    """A Dask client of the cluster at ``scheduler``, or of a ``distributed.LocalCluster``
    of ``workers`` processes with one thread each (started here, closed on exit)."""
    Client, LocalCluster = dask_distributed()
    cluster = None
    if scheduler is None:
        cluster = LocalCluster(n_workers=int(workers), threads_per_worker=1, processes=True,
                               dashboard_address=None, env={"TDEM_THREADS": "1"})
        client = Client(cluster)
    else:
        client = Client(scheduler)
    try:
        yield client
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
