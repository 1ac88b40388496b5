"""What every case script shares: command line, output folder, summary, histories,
plots, and the list of cases the ``tdem`` command offers.

A case is a module ``cases/NAME.py`` with a ``main(argv=None)`` function; the first
line of its docstring is its one-line description (``tdem list``).
"""
import argparse
import ast
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


def parser(case, description=None):
    """The options every case takes: --preset, --arch, --out, --threads."""
    p = argparse.ArgumentParser(prog=COMMAND or f"python -m cases.{case}",
                                description=description,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--preset", choices=PRESETS, default="quick",
                   help="quick: coarse, a minute or two on 2 CPU cores; "
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
def figure(value, target=None, unit="", note=""):
    """One figure of ``summary.json``: the value beside its target."""
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
    """Write ``out/summary.json`` (figures made with :func:`figure`, plus anything else)."""
    path = Path(out) / "summary.json"
    with open(path, "w") as f:
        json.dump(_plain(summary), f, indent=2)
        f.write("\n")
    return path


class Stopwatch:
    """Wall-clock seconds since creation (for the runtime in the summary)."""

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


def plot_histories(source, png, title=None):
    """PNG of monitor histories: ``tdem.io.plot_histories`` when the engine offers it,
    else one panel per monitor of ``source`` (a Simulation)."""
    try:
        from tdem.io import plot_histories as engine_plot
    except ImportError:
        engine_plot = None
    if engine_plot is not None:
        return engine_plot(source, png, title=title)
    hist = source.histories() if hasattr(source, "histories") else source
    plt = pyplot()
    names = [k for k, (t, v) in hist.items() if len(t)]
    fig, axes = plt.subplots(len(names) or 1, 1, figsize=(7, 2.2 * max(len(names), 1)),
                             sharex=True, squeeze=False)
    for ax, name in zip(axes[:, 0], names):
        t, v = hist[name]
        v = np.asarray(v)
        ax.plot(t, v.reshape(len(t), -1))
        ax.set_ylabel(name)
        ax.grid(alpha=0.3)
    axes[-1, 0].set_xlabel("time")
    if title:
        axes[0, 0].set_title(title)
    fig.tight_layout()
    fig.savefig(png, dpi=120)
    plt.close(fig)
    return png


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


def list_cases():
    """{name: one-line description} of the modules in ``cases`` with a ``main``."""
    found = {}
    for mod in sorted(pkgutil.iter_modules([str(CASES_DIR)]), key=lambda m: m.name):
        if mod.name.startswith("_") or mod.ispkg:
            continue
        desc, has_main = _case_info(CASES_DIR / f"{mod.name}.py")
        if has_main:
            found[mod.name] = desc
    return found

