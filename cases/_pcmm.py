"""Shared helpers of the PCMM precision tests of Feng, Li & Oñate (2015) §3
(elastic_gravity, uniaxial_compression, wave_bar): the regular / cross / random
PCMM particle models and the FVM block models of one rectangular body, boundary
selections, read-outs at monitoring points, the run loop and common plots; and the
frictionless tank of the water cases (:func:`water_tank`).

A model is described by a small dict ``spec``:

- ``{"kind": "regular" | "cross", "radius": R, "tolerance": δ, "inset": None | 0,
  "fit": False}`` (a square or hexagonal lattice built from R by ``tdem.pack``;
  ``inset`` None puts the outermost centres R from the edges, 0 puts them on the
  edges; cross ``fit`` True shrinks the spacings so that the rows end on the edges);
- ``{"kind": "random", "rmin": .., "rmax": .., "tolerance": δ, "fraction": 0.8,
  "overlap_tol": 1e-3, "edge_centres": False, "edge_radius": None, "fill_holes": False,
  "seed": 0}`` (``tdem.pack.random``; ``edge_centres`` True puts the boundary discs'
  centres on the edges, ``edge_radius`` gives them one radius; a fraction above jamming needs a larger ``overlap_tol``;
  ``fill_holes`` True adds discs into the holes of the element cover of δ,
  ``pcmm_tolerance``);
- ``{"kind": "fvm", "cells": (nx, ny), "pattern": "regular" | "cross"}``
  (``tdem.mesh.rectangle`` block).
"""
import math
import time

import numpy as np

import tdem

from . import _common as common

COLORS = {"regular": "C0", "cross": "C1", "random": "C2", "fvm": "C3", "fvm_cross": "C4"}


def water_tank(sim, width, height, bulk_modulus):
    """A tank's floor (y = 0, x from 0 to ``width``) and two sides ``height`` high:
    frictionless segment walls of the particle–wall law k_n = 3K for water of bulk
    modulus K (``bulk_modulus``), as the water cases and tests use."""
    wall = tdem.LinearContact(kn=3.0 * bulk_modulus, ks=0.0, friction=0.0)
    sim.add_wall((0.0, 0.0), (width, 0.0), contact=wall)
    sim.add_wall((0.0, height), (0.0, 0.0), contact=wall)
    sim.add_wall((width, 0.0), (width, height), contact=wall)
# open markers of different shapes, so that models that agree stay visible on top of
# each other
MARKERS = {"regular": "s", "cross": "^", "random": "o", "fvm": "D", "fvm_cross": "v"}
LABELS = {"regular": "PCMM regular", "cross": "PCMM cross", "random": "PCMM random",
          "fvm": "FVM regular mesh", "fvm_cross": "FVM cross mesh"}


def wave_speeds(mat):
    """(bar speed sqrt(E/(ρ(1-ν²))) of a plane-strain bar, P-wave speed sqrt((K+4G/3)/ρ))."""
    E, nu, rho = mat.young, mat.poisson, mat.density
    K = E / (3.0 * (1.0 - 2.0 * nu))
    G = E / (2.0 * (1.0 + nu))
    return math.sqrt(E / (rho * (1.0 - nu * nu))), math.sqrt((K + 4.0 * G / 3.0) / rho)


class Model:
    """One model (PCMM particles or FVM block) of the rectangle origin + [0,W]×[0,H]
    in its own :class:`tdem.Simulation`."""

    def __init__(self, name, spec, W, H, material, sim_kwargs, origin=(0.0, 0.0)):
        self.name, self.spec, self.W, self.H = name, dict(spec), W, H
        self.material = material
        self.origin = np.asarray(origin, dtype=float)
        t0 = time.perf_counter()
        self.sim = tdem.Simulation(**sim_kwargs)
        kind = spec["kind"]
        self.is_fvm = kind == "fvm"
        if self.is_fvm:
            nx, ny = spec["cells"]
            v, t = tdem.mesh.rectangle(W, H, nx, ny, pattern=spec.get("pattern", "regular"),
                                       origin=origin)
            self.block = self.sim.add_block(v, t, material=material)
            self.x0 = np.asarray(v, dtype=float)
            self.r = None
            self.count = {"elements (triangles)": len(t), "cells": nx * ny, "nodes": len(v)}
        else:
            if kind == "regular":
                pos, r = tdem.pack.regular(W, H, spec["radius"], origin=origin,
                                           inset=spec.get("inset"))
            elif kind == "cross":
                pos, r = tdem.pack.cross(W, H, spec["radius"], origin=origin,
                                         inset=spec.get("inset"), fit=spec.get("fit", False))
            elif kind == "random":
                frac = spec.get("fraction", 0.8)
                while True:   # lower the fraction by 0.02 until the packer succeeds
                    try:
                        pos, r = tdem.pack.random(W, H, spec["rmin"], spec["rmax"],
                                                  seed=spec.get("seed", 0),
                                                  target_fraction=frac, origin=origin,
                                                  edge_centres=spec.get("edge_centres", False),
                                                  edge_radius=spec.get("edge_radius"),
                                                  overlap_tol=spec.get("overlap_tol", 1e-3),
                                                  pcmm_tolerance=spec["tolerance"] if spec.get(
                                                      "fill_holes", False) else None)
                        break
                    except tdem.InputError:
                        if frac <= 0.6:
                            raise
                        frac = round(frac - 0.02, 2)
                self.fraction = frac
            else:
                raise ValueError(f"unknown model kind {kind!r}")
            self.group = self.sim.add_particles(pos, r, material=material,
                                                tolerance=spec["tolerance"])
            self.x0 = np.asarray(pos, dtype=float)
            self.r = np.asarray(r, dtype=float)
            self.count = {"particles": len(pos)}
            if kind == "random":
                self.count["area_fraction"] = self.fraction
        self.build_s = time.perf_counter() - t0

    # ------------------------------------------------------------ selections
    def edge(self, side, depth=None):
        """Indices (particles or block nodes) on a side of the body: "left", "right",
        "bottom", "top". PCMM: the particles whose disc reaches within ``depth``
        (default half the largest radius) of the outermost centre line; FVM: the
        nodes on the side."""
        x = self.x0
        axis = 0 if side in ("left", "right") else 1
        lo = side in ("left", "bottom")
        if self.is_fvm:
            c = x[:, axis]
            ref = c.min() if lo else c.max()
            return np.flatnonzero(np.abs(c - ref) <= 1e-9 * max(self.W, self.H))
        c = x[:, axis]
        d = 0.5 * self.r.max() if depth is None else depth
        if lo:
            ref = (c - self.r).min()
            return np.flatnonzero(c - self.r <= ref + d)
        ref = (c + self.r).max()
        return np.flatnonzero(c + self.r >= ref - d)

    def fix(self, ids, vx=0.0, vy=None):
        if self.is_fvm:
            self.block.fix(ids, vx=vx, vy=vy)
        else:
            self.sim.fix_particles(ids, vx=vx, vy=vy)

    # ------------------------------------------------------------ state
    def state(self):
        """dict: ref (reference positions of the kinematic points), displacement,
        velocity, force, reaction (FVM), and sref (points of the stress values), stress
        (K,2,2) tension-positive."""
        if self.is_fvm:
            n = self.block.nodes()
            e = self.block.elements()
            tri = np.asarray(e["triangles"])
            return {"ref": self.x0, "displacement": np.asarray(n["displacement"]),
                    "velocity": np.asarray(n["velocity"]), "force": np.asarray(n["force"]),
                    "reaction": np.asarray(n["reaction"]),
                    "sref": self.x0[tri].mean(axis=1), "stress": np.asarray(e["stress"])}
        p = self.sim.particles.numpy()
        return {"ref": self.x0, "displacement": np.asarray(p["displacement"]),
                "velocity": np.asarray(p["velocity"]), "force": np.asarray(p["force"]),
                "reaction": None, "sref": self.x0, "stress": np.asarray(p["stress"])}

    def spacing(self):
        """A typical distance between neighbouring points."""
        if self.is_fvm:
            nx, ny = self.spec["cells"]
            return max(self.W / nx, self.H / ny)
        return 2.0 * float(self.r.mean())

    def first_step(self):
        """Run one step (the elements are created at the first step) and keep the
        initial PCMM element triangles for :func:`plot_models`."""
        self.sim.run(steps=1)
        self.init_tri = self.pcmm_elements()[0]

    def pcmm_elements(self):
        """(triangles, covered area Σ S/N) of the PCMM element system (None for FVM)."""
        if self.is_fvm:
            return None, None
        e = self.sim.elements.numpy()
        return np.asarray(e["triangles"]), float(np.sum(np.asarray(e["area"]) /
                                                        np.asarray(e["n_cover"])))


def linear_fit_at(points, values, x0, h, min_points=6):
    """Value at ``x0`` of the least-squares linear fit a + b·dx + c·dy of ``values``
    (K, ...) over the ``points`` within ``h`` of x0 (h is widened until there are
    ``min_points``). Exact for a linear field, robust for random packings."""
    points = np.asarray(points, dtype=float)
    values = np.asarray(values, dtype=float)
    d = np.hypot(points[:, 0] - x0[0], points[:, 1] - x0[1])
    hh = h
    for _ in range(20):
        sel = np.flatnonzero(d <= hh)
        if len(sel) >= min_points:
            break
        hh *= 1.3
    A = np.column_stack([np.ones(len(sel)), points[sel, 0] - x0[0], points[sel, 1] - x0[1]])
    v = values[sel].reshape(len(sel), -1)
    coef, *_ = np.linalg.lstsq(A, v, rcond=None)
    return coef[0].reshape(values.shape[1:])


def run_to_equilibrium(model, probe, chunk, min_steps, max_steps, rtol=1e-4):
    """Run ``chunk`` steps at a time until ``probe(model)`` changes by less than
    ``rtol`` (relative) over two consecutive chunks, at least ``min_steps`` and at most
    ``max_steps``. Returns (steps, converged, last relative change)."""
    sim = model.sim
    prev = None
    quiet = 0
    change = float("nan")
    while sim.steps < max_steps:
        sim.run(steps=chunk)
        val = float(probe(model))
        if prev is not None:
            change = abs(val - prev) / max(abs(val), 1e-300)
            quiet = quiet + 1 if change < rtol else 0
        prev = val
        if sim.steps >= min_steps and quiet >= 2:
            return sim.steps, True, change
    return sim.steps, False, change


def select_models(all_models, models):
    """The (name, spec) pairs of ``all_models`` (dict) named in ``models`` (None: all)."""
    if models is None:
        return list(all_models.items())
    unknown = [m for m in models if m not in all_models]
    if unknown:
        raise ValueError(f"unknown models {unknown}; choose from {list(all_models)}")
    return [(k, all_models[k]) for k in models]


def run_all(selected, run_model):
    """Run ``run_model(name, spec)`` for every (name, spec) of ``selected``, FVM models
    first (so that both kinds of kernels are compiled at the start of the process),
    and return the models in the order given."""
    order = sorted(range(len(selected)), key=lambda k: selected[k][1]["kind"] != "fvm")
    done = {}
    for k in order:
        done[k] = run_model(*selected[k])
    return [done[k] for k in range(len(selected))]


def plot_models(models_xy, png, title=None):
    """Side-by-side pictures of the models' particles / meshes (paper Figs. 7, 11, 14)
    and the PCMM element systems (Figs. 8, 12). ``models_xy``: list of Model (built,
    run for at least one step so that PCMM elements exist)."""
    plt = common.pyplot()
    from matplotlib.collections import PatchCollection
    from matplotlib.patches import Circle
    n = len(models_xy)
    W, H = models_xy[0].W, models_xy[0].H
    wide = W / H > 3
    if wide:
        fig, axes = plt.subplots(n, 1, figsize=(7, 1.9 * n + 0.6), squeeze=False,
                                 layout="constrained")
    else:
        fig, axes = plt.subplots(1, n, figsize=(3.2 * n, 2.6 * H / W + 1.0), squeeze=False,
                                 layout="constrained")
    for ax, m in zip(axes.ravel(), models_xy):
        if m.is_fvm:
            tri = np.asarray(m.block.triangles)
            ax.triplot(m.x0[:, 0], m.x0[:, 1], tri, lw=0.3, color="k")
            ax.set_title(f"{LABELS.get(m.name, m.name)}: {len(tri)} triangles", fontsize=9)
        else:
            tri = getattr(m, "init_tri", None)
            if tri is None:
                tri, _ = m.pcmm_elements()
            ax.add_collection(PatchCollection([Circle(p, r) for p, r in zip(m.x0, m.r)],
                                              facecolor="none", edgecolor="0.6", lw=0.3))
            if tri is not None and len(tri):
                ax.triplot(m.x0[:, 0], m.x0[:, 1], tri, lw=0.3, color="C3")
            ax.set_title(f"{LABELS.get(m.name, m.name)}: {len(m.x0)} particles, "
                         f"{0 if tri is None else len(tri)} elements", fontsize=9)
        ax.set_aspect("equal")
        ax.autoscale_view()
        if wide:
            ax.set_xlim(m.origin[0], m.origin[0] + min(W, 2.0))
        ax.set_xlabel("x (m)", fontsize=8)
        ax.set_ylabel("y (m)", fontsize=8)
        ax.tick_params(labelsize=8)
    if title:
        fig.suptitle(title, fontsize=10)
    return common.save(fig, png)


def rel(a, b):
    """|a - b| / |b| (None if b is 0)."""
    return abs(a - b) / abs(b) if b else None


def count_check(m, paper_count, what=None):
    """Reported-only check of a model's particle count (FVM: cells, or ``what``: a key
    of ``m.count``) beside the paper's, which does not always follow from its radii
    (spec: report it beside the paper's)."""
    what = what or ("cells" if m.is_fvm else "particles")
    unit = "triangles" if what.startswith("elements") else what
    return common.check(f"{m.name}.count", m.count[what], paper_count, None, unit,
                        f"{LABELS.get(m.name, m.name)}: {unit} beside the paper's count")


def finish(case, preset, checks, data, out, hist, plot, watch, threads=None, paper=None,
           notes=None):
    """The end of a case's ``run``: histories, plots (``plot()``), then the summary
    (:func:`cases._common.summary`) written to ``out/summary.json`` and returned."""
    common.save_histories(out / "histories.h5", hist)
    plot()
    s = common.summary(case, preset, checks, data, watch(), threads=threads, paper=paper,
                       notes=notes)
    common.write_summary(out, s)
    return s


def main(case, run, doc, argv=None):
    """Command line of a PCMM case: ``run`` with the parsed options, then its checks."""
    args, out = common.parse(case, argv, description=doc.splitlines()[0])
    s = run(args.preset, out, arch=args.arch, threads=args.threads)
    common.print_checks(s)
    print(f"summary: {out / 'summary.json'}")
    return 0
