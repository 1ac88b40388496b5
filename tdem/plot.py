"""Plots of monitor histories: :func:`plot_history`.

    fig = tdem.plot_history(sim)                         # or "out/pile/monitors.h5"
    fig = tdem.plot_history("out/pile", names=["floor_force"], out="floor.png",
                            units={"floor_force": "kN/m"})

Monitors of the same unit share a panel, each a line labelled with its name (a vector
monitor one line per component, ``name[k]``); the y axis names the quantity and its
unit, the x axis is the simulated time in seconds. The unit of a monitor comes from
``units`` ({name: unit}), else from a unit written in its name (``"load [N]"``,
``"load (kN)"``), else from the words of its name (:func:`monitor_unit`:
``floor_force`` → N/m, ``sigma_v`` → Pa, ``kinetic_energy`` → J/m, ``top_uy`` → m);
a monitor whose unit is not known gets a panel of its own with its name on the axis.
SI units as everywhere in tdem: forces, energies, moments and masses are per metre of
thickness (N/m, J/m, N·m/m, kg/m).
"""
import re
from pathlib import Path

import numpy as np

from .errors import InputError

# words of a monitor's name → its unit, the first group with a match wins (stresses
# before velocities: ``sigma_v`` is a stress; ratios first: ``F_H_over_F_V``)
_WORDS = (
    ("", {"ratio", "over", "strain", "strains", "porosity", "coordination", "fraction",
          "void", "friction", "mu", "efficiency", "factor", "cn", "exx", "eyy", "exy",
          "evol", "damage"}),
    ("Pa", {"stress", "stresses", "sigma", "pressure", "sxx", "syy", "sxy", "szz", "tau",
            "modulus", "young", "kpa", "mpa", "cohesion"}),
    ("N·m/m", {"moment", "torque", "couple"}),
    ("N/m", {"force", "forces", "fx", "fy", "fz", "fn", "fs", "load", "loads", "reaction",
           "reactions", "thrust", "drag", "weight"}),
    ("J/m", {"energy", "kinetic", "potential", "gravitational", "dissipated", "work",
           "elastic", "ek", "ep"}),
    ("rad/s", {"omega", "spin"}),
    ("m/s", {"velocity", "velocities", "speed", "vx", "vy", "vz", "v"}),
    ("m", {"displacement", "displacements", "position", "height", "width", "length",
           "depth", "gap", "overlap", "settlement", "ux", "uy", "uz", "x", "y", "z",
           "elevation", "radius", "penetration"}),
    ("s", {"time", "period", "duration"}),
    ("kg/m", {"mass"}),
    ("deg", {"angle", "phi", "theta", "rotation"}),
)

QUANTITY = {"Pa": "stress", "N/m": "force", "N·m/m": "moment", "J/m": "energy",
            "m/s": "velocity", "rad/s": "angular velocity", "m": "length", "s": "time",
            "kg/m": "mass", "deg": "angle", "": "ratio"}

_UNIT_IN_NAME = re.compile(r"[\[(]\s*([^\[\]()]*?)\s*[\])]\s*$")


def monitor_unit(name):
    """The unit of a monitor from its name: a unit in brackets at its end (``"load
    [kN]"`` → ``"kN"``), else the first of its words (split at ``_``, spaces and
    punctuation, case ignored) with a known unit (``"floor_force"`` → ``"N/m"``,
    ``"sigma_v"`` → ``"Pa"``, ``"F_H_over_F_V"`` → ``""``, a ratio). None when
    nothing is known."""
    name = str(name)
    m = _UNIT_IN_NAME.search(name)
    if m:
        return m.group(1)
    words = [w for w in re.split(r"[^a-z0-9]+", name.lower()) if w]
    for unit, keys in _WORDS:
        if any(w in keys for w in words):
            return unit
    return None


def _histories(source):
    """{name: (times, values)} of a Simulation, a monitors.h5 file, a folder holding
    one, or such a dict."""
    if hasattr(source, "histories"):
        return source.histories()
    if isinstance(source, dict):
        return source
    from .io import read_monitors
    path = Path(source)
    if path.is_dir():
        path = path / "monitors.h5"
    if not path.exists():
        raise InputError(f"source: no monitor file {str(path)!r} (give a Simulation, a "
                         "monitors.h5 file, its folder or a dict {name: (times, values)})")
    return read_monitors(path)


def _label(unit):
    if unit is None:
        return None
    q = QUANTITY.get(unit)
    if q is None:   # a unit written by the user: its usual quantity where known
        q = {"N": "force", "kN": "force", "MN": "force", "kN/m": "force", "J": "energy",
             "kPa": "stress", "MPa": "stress",
             "GPa": "stress", "mm": "length", "cm": "length", "km": "length",
             "kJ": "energy", "MJ": "energy", "ms": "time"}.get(unit, "value")
    return f"{q} ({unit})" if unit else f"{q} (–)"


def plot_history(source, names=None, out="history.png", units=None, title=None,
                 panels="unit", dpi=120):
    """A matplotlib figure of monitor histories against time; saved to ``out`` (a PNG
    or any format matplotlib writes, from the suffix; None: not saved).

    ``source``: a :class:`~tdem.Simulation` (its :meth:`~tdem.Simulation.histories`),
    the path of a ``monitors.h5`` file or of the output folder holding it, or a dict
    {name: (times (K,), values (K, ...))}. ``names`` selects and orders the monitors
    (default: all). ``units``: {name: unit} overriding :func:`monitor_unit`.
    ``panels``: ``"unit"`` (monitors of one unit share a panel, with a legend) or
    ``"monitor"`` (a panel each). Returns the :class:`matplotlib.figure.Figure`; its
    lines hold the recorded times and values unchanged (``ax.lines[k].get_ydata()``).
    """
    from matplotlib.figure import Figure

    hist = _histories(source)
    if names is None:
        names = list(hist)
    else:
        names = [names] if isinstance(names, str) else list(names)
        missing = [n for n in names if n not in hist]
        if missing:
            raise InputError(f"names: no monitor called {missing[0]!r}; there are "
                             f"{sorted(hist)}")
    units = dict(units or {})
    bad = sorted(set(units) - set(hist))
    if bad:
        raise InputError(f"units: no monitor called {bad[0]!r}; there are {sorted(hist)}")
    if panels not in ("unit", "monitor"):
        raise InputError(f"panels must be 'unit' or 'monitor', got {panels!r}")

    # panels: [(unit, [names])] in the order of first appearance
    groups = []
    for name in names:
        unit = units[name] if name in units else monitor_unit(name)
        if panels == "unit" and unit is not None:
            for g in groups:
                if g[0] == unit and g[2]:
                    g[1].append(name)
                    break
            else:
                groups.append((unit, [name], True))
        else:
            groups.append((unit, [name], False))
    rows = max(len(groups), 1)
    fig = Figure(figsize=(7.0, 1.2 + 2.3 * rows))
    axes = fig.subplots(rows, 1, sharex=True, squeeze=False)[:, 0]
    for ax, (unit, members, _shared) in zip(axes, groups):
        for name in members:
            t, v = hist[name]
            t = np.asarray(t, dtype=float)
            v = np.asarray(v, dtype=float).reshape(len(t), -1) if len(t) else np.zeros((0, 1))
            if v.shape[1] == 1:
                ax.plot(t, v[:, 0], lw=1.3, label=name)
            else:
                for c in range(v.shape[1]):
                    ax.plot(t, v[:, c], lw=1.3, label=f"{name}[{c}]")
        ax.set_ylabel(_label(unit) if unit is not None else members[0])
        ax.grid(alpha=0.3)
        ax.legend(fontsize="small", loc="best")
    if not groups:
        axes[0].text(0.5, 0.5, "no monitors", ha="center", va="center",
                     transform=axes[0].transAxes)
    axes[-1].set_xlabel("time (s)")
    if title:
        axes[0].set_title(title)
    fig.tight_layout()
    if out is not None:
        Path(out).parent.mkdir(parents=True, exist_ok=True)
        fig.savefig(str(out), dpi=dpi)
    return fig
