"""Water released against stacked concrete blocks (Feng, Li & Oñate 2015 §4.3, Figs. 25-27; paper: four columns stand, two topple).

Set-up (paper §4.3)
-------------------------------------
Tank: a floor 3 m long (y = 0, x from 0 to 3 m) with vertical walls at both ends.
Water 0.8 m wide and 1.4 m high against the left wall, held by a board at
x = 0.8 m that is removed at t = 0. PCMM particles of ``tdem.Fluid`` (G = 0,
the incremental element pressure; water particles repel each other through the
fluid core force, see ``physics.materials.Fluid``), ρ = 1000 kg/m³,
viscosity 1 Pa·s (a numerical value: the SPH-style artificial viscosity
α·h·c·ρ/8 with α = 0.003 in the quick preset; the real 1e-3 Pa·s does nothing
at this resolution), linear bulk viscosity b1 = 0.2 (damps the acoustic ringing of the
weakly compressible water on compression only). Blocks 10 × 10 cm, concrete
(ρ = 2400, E = 30 GPa, ν = 0.2; the paper gives no density: ``--block-density``,
and ``--sweep --densities`` below), stacked six high in columns side by side,
the first column's left side 1.15 m right of the water (x = 1.95 m).
Block-block and block-floor contacts: vertex-edge (``tdem.PointEdge``), c = 0,
φ = 25°, T = 0. Water-block contacts: point-edge, frictionless, with the water's
contact stiffness. Water-tank contacts: frictionless walls.

Decided here (the paper gives none of it):
- the tank floor for the blocks is a fixed rigid slab 0.1 m thick under y = 0,
  and its end walls fixed rigid slabs 0.1 m thick outside x = 0 and x = 3 m
  (blocks meet them through vertex-edge contacts with the block-block law; the
  water meets the tank's walls);
- columns are 1 mm apart (the paper: side by side), so that no block corner
  sits exactly on another block's corner;
- contact stiffness block-block K_n = 3e8 N/m per metre, K_s = K_n/(2(1 + ν))
  (a 6-block column settles by 5 µm; the concrete's E would cut the time step by
  about 10 and change nothing at this scale);
- blocks are rigid (3 degrees of freedom each) in both presets: a 10 cm
  concrete block under 1.4 m of water deforms by about 1e-7 m;
- initial state: the water settles to hydrostatic pressure behind the board
  with local damping 0.7 (``settle`` seconds, the blocks settle too), then the
  damping is switched off and the board is lifted at 50 m/s (out of the water
  in 0.03 s, much faster than the water's front moves): "removed at t = 0".
  Times are measured from the lift.

Presets
-------
- ``quick``: water on a square lattice R = 2 cm (20 × 35 = 700 particles),
  δ = R, K = 15 MPa (weakly compressible: c = 122 m/s, ten times the fastest
  water particle of the run, 12 m/s in the jets at the blocks; the dam-break
  front moves at about 2·sqrt(g·H) = 7.4 m/s; with K = 6 MPa,
  c = 77 m/s, the outcome was the same), 1.2 s after the lift.
- ``paper``: the paper's particle count on a square lattice, R = 7.1 mm
  (56 × 98 = 5488 particles; the paper: 5528 random discs of R = 3-8 mm),
  δ = R, K = 20 MPa (c = 141 m/s, above 10 × the fastest water of the quick
  runs; the paper's 2 GPa would need a time step 10 × shorter for no change in
  the flow), 4.8 s. Not a random packing: a random packing of Fluid particles
  loses volume as it flows (a column of R = 6-14 mm discs, δ = 5 mm, sank from
  0.49 to 0.33 m in 1.3 s), because the particles' volumes change only through
  the elements that exist, and the area of the triangles that are deleted as
  the discs slip into the pores of the packing is lost. 82 min on one thread
  (2026-12-05, both systems one after the other), 33 min with ``--parallel`` (one
  thread each, 2026-12-08; docs/validation.md); not for tests.
- ``--water cells`` (either preset): the water packed at random as the paper's
  is, as Voronoi cells (``tdem.Fluid(voronoi=True)``, ``physics.pcmm.cells``),
  which hold at rest and keep their area as they flow on any packing. Quick:
  R = 1.4-2.6 cm, 660 discs at 76 % of the column (192 s, 8 of 10 checks,
  docs/cases.md); paper: the paper's 5528 discs of R = 3-8 mm (50 % of the
  column; its widest pores stay empty: the cells cover 1.09 of the column's
  1.12 m²; 77-81 min a system to 2.4 s on one thread: two columns topple, four
  slide 0.62 m to the tank's end; docs/cases.md, docs/validation.md).

Outcome measure. "Stood", "slid" or "toppled" is decided from the top block of
the rightmost column (largest values over the run): toppled if its rotation
exceeds 20°; slid if it turned less than that but travelled more than one block
width (0.1 m) (the columns pushed along the floor as a wall); stood if it moved
less than 2 cm and turned less than 5°; otherwise "moved". The paper: four
columns stand (Fig. 26), two columns topple (Fig. 27). The two-column check is that
class (toppled); for four columns the class is reported only, and the check is the
paper's wording: the water "just causes little movement" of the four columns. That
is read (decided from the text before any run of the density sweep) as the top block
of the rightmost column moving less than half a block width, |dx| < 0.05 m, and
turning less than 5° (largest values over the run; ``four.little_movement_dx`` and
``four.little_movement_rotation``): moved less than half its width, each block
still stands on the block or floor it stood on, as in Fig. 26, where the columns
are where they started; a 5° tilt leans a block's top edge 9 mm over its 10 cm, far
from toppling (20° here, 45° to tip over a corner). Also reported: the
largest rise of any block's centre (a block tipping over a corner raises its
centre by at most (√2 − 1)/2 × 0.1 m = 2.1 cm, one riding onto another block by
up to a block height more: 12 cm; where two columns topple onto the tank's end
wall a block rides onto the pile there, one block height more: 22 cm; a larger rise
means a block thrown up, :func:`rise_limit`).

Result (quick preset) and why it differs from the paper
--------------------------------------------------------
Two columns topple (top block of the right column: max |dx| 0.61-0.70 m,
rotation 66-99° over the runs), as in the paper. Four columns do not topple but
slide as one wall along the floor (top block of the right column: 0.18-0.24 m by
1.2 s, slowing down, rotation at most 2.2°; all 24 blocks move together, none
rises more than 5 mm); the paper's four columns stand. The top block of the right
column moves 5 mm at 0.50-0.52 s (four) and 0.52-0.60 s (two; 0.574 s in the run of
2026-12-05, interpolated between the records), after the surge front reaches the first
column (Martin & Moyce's dam-break front: about 0.40 s) and has built up
enough push. Why four columns slide here: a plain estimate says a 25° floor
cannot hold them: the surge reaching the blocks is about h ≈ 0.6 m deep at
v ≈ 2.5 m/s (Ritter), a force of about ρgh²/2 + ρhv² ≈ 1.8 + 3.8 = 5.5 kN per
metre, against a frictional resistance of 24 blocks × 23.5 kg × 9.81 × tan 25°
≈ 2.6 kN; the paper's block-floor friction, block material and exact layout
(Fig. 25) are not given, and the result hangs on them. ``--sweep`` runs the four
columns over them (floor and block friction 25°, 35°, 45° and 25°, 45°; columns
1 mm and 10 mm apart; :data:`SWEEP`): none of the twelve stands; a 25° floor
always slides, rougher floors topple them or, with 45° blocks, leave the top
block 3.5 cm from where it stood (docs/cases.md, the table).

The blocks' density (not in the paper). ``--sweep --densities 2400 4000 5600 7800``
runs both systems at the preset's resolution for each block density (concrete to
steel, :data:`DENSITIES`), everything else at the preset's values; the table is in
docs/cases.md. Quick preset (2026-12-07): four columns slide 0.22 m at 2400 kg/m³
(not "little movement") and move 1.4 cm or less from 4000 up (within it); two
columns topple up to 5600 (at 4000 and 5600 only near the run's end, 1.14 s) and
at 7800 move 4.8 cm without toppling.

Blocks thrown up (resolved). An earlier version of the vertex–edge contacts
threw single upper blocks up at 3-5 m/s (to 1.1 m) within 0.1 s of the surge,
and both systems fell apart. The cause was the block contacts, not the water:
in columns stacked corner over corner, a bottom corner of a block shifted
sideways by a hair lies just outside the top edge of the block below and
crosses that block's side edge by less than its top edge; "the edge crossed
least" then gave it the side edge, with a horizontal normal, and the block
above lost its support there. Measured in the four-column run: the settled
stack held its 24 blocks on the top and bottom edges only (14.1 kN, the
weight above each joint); the first water touched the first column at
0.385-0.39 s, and at 0.39 s 8 corners of blocks in the same column met side
edges (4.9 kN), at 0.40 s 21 (44 kN, against 5.3 kN left on the top and
bottom edges; the blocks weigh 5.6 kN), at 0.42 s 19 (1.8 MN), the blocks of
a column swinging sideways against each other at growing amplitude (block
kinetic energy 0.9 J at 0.39 s, 160 J at 0.42 s, 2400 J at 0.45 s, blocks at
11 m/s), while at 0.39, 0.40 and 0.42 s no water particle pressed on a block.
One thrown block, the bottom block of the right column, left at 4.5 m/s
(0.51 s) from a corner 0.6 mm deep in the floor pushing with 262 kN (1100 times
its weight).
Vertex–edge contacts now follow the entrance rule (``coupling.point_edge``):
a vertex meets only an edge it can have entered through; with it no corner
meets a side edge of the block below, the blocks' kinetic energy peaks at
about 60 J (four columns), where no block rises more than 1 cm; the two toppled
columns pile up against the right wall, blocks landing on each other, and the
largest rise there is 1.5–9 cm by the run (on 2 threads the point–edge forces
are summed by atomic additions in a varying order, and the toppling amplifies
the round-off). The same blocks
without water had not shown it: their settled stack was exactly symmetric and
nothing shifted a corner.

Outputs (``--out DIR``, default out/water_blocks): per run (``four``, ``two``) a
VTU series (.pvd), snapshots at the paper's times (``fig26_four.png``,
``fig27_two.png``: water particles coloured by pressure, blocks outlined), block
displacement histories (``histories.h5``, ``block_displacements.png``),
``summary.json``.
"""
import math
import sys
from pathlib import Path

import numpy as np

import tdem

from . import _common as common

CASE = "water_blocks"
WATER_W, WATER_H = 0.8, 1.4
TANK_L = 3.0
GAP_TO_BLOCKS = 1.15
BLOCK = 0.1
ROWS = 6
COLUMN_GAP = 1e-3
FRICTION = 25.0          # block-block and block-floor friction angle (degrees; the spec)
RHO_W = 1000.0
CONCRETE = {"density": 2400.0, "young": 30e9, "poisson": 0.2}
BLOCK_KN = 3e8
BOARD_SPEED = 50.0
WALL_TOP = 20.0          # height of the tank's side walls for the water (m)
PAPER_TIMES = {"four": [0.36, 0.68, 0.96, 1.28, 1.84, 4.08],
               "two": [0.40, 0.88, 1.28, 1.72, 2.08, 4.76]}
PAPER_OUTCOME = {"four": "stood", "two": "toppled"}
STOOD_DX, STOOD_ROT = 0.02, 5.0
TOPPLED_DX, TOPPLED_ROT = BLOCK, 20.0
#: the paper's four columns: the water "just causes little movement" of them, read as
#: the top block of the right column moving less than half a block width and turning
#: less than 5° (largest values over the run; the module docstring, "Outcome measure")
LITTLE_DX, LITTLE_ROT = 0.5 * BLOCK, 5.0
#: block densities of the density sweep (kg/m³): concrete 2400 to steel 7800
DENSITIES = (2400.0, 4000.0, 5600.0, 7800.0)
COLUMNS = {"four": 4, "two": 2}

PRESETS = {
    "quick": {"packing": "regular", "radius": 0.02, "tolerance": 0.02, "bulk": 15e6,
              "viscosity": 1.0, "b1": 0.2, "settle": 0.3, "duration": 1.2,
              "dt_fraction": 0.5, "vtu_interval": 0.1},
    "paper": {"packing": "regular", "radius": 0.0071, "tolerance": 0.0071, "bulk": 20e6,
              "viscosity": 1.0, "b1": 0.2, "settle": 0.3, "duration": 4.8,
              "dt_fraction": 0.5, "vtu_interval": 0.04},
}


#: ``--water cells``: water of Voronoi cells (``tdem.Fluid(voronoi=True)``), packed at
#: random as the paper's is (radii uniform in [rmin, rmax])
CELLS = {
    "quick": {"packing": "random", "rmin": 0.014, "rmax": 0.026, "count": 660,
              "tolerance": 0.02, "voronoi": True},
    "paper": {"packing": "random", "rmin": 0.003, "rmax": 0.008, "count": 5528,
              "tolerance": 0.0055, "voronoi": True},
}


def rise_limit(system):
    """The largest rise of a block's centre that is not a block thrown up: riding
    onto another block and tipping over a corner, 0.1 m + (√2 − 1)/2 × 0.1 m
    (four columns, which stand or slide); where columns topple onto the tank's end
    wall (``two``), onto a pile there one block height more."""
    tip = BLOCK * (1.0 + (math.sqrt(2.0) - 1.0) / 2.0)
    return tip + (BLOCK if system == "two" else 0.0)


def density(value, name="block_density"):
    """``value`` as a block density (kg/m³, a finite number > 0: a float, or text as
    on the command line); :class:`tdem.errors.InputError` naming ``name`` and the
    value otherwise."""
    from tdem.errors import InputError
    if isinstance(value, bool):
        raise InputError(f"{name} must be a number > 0 (kg/m³), got {value!r}")
    try:
        rho = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a number > 0 (kg/m³), got {value!r}") from None
    if not (math.isfinite(rho) and rho > 0.0):
        raise InputError(f"{name} must be a number > 0 (kg/m³), got {value!r}")
    return rho


def water_particles(cfg):
    """Centres and radii of the water column [0, 0.8] × [0, 1.4]."""
    if cfg["packing"] == "regular":
        return tdem.pack.regular(WATER_W, WATER_H, cfg["radius"])
    rmin, rmax = cfg["rmin"], cfg["rmax"]
    mean_area = math.pi * (rmax ** 3 - rmin ** 3) / (3.0 * (rmax - rmin))
    frac = min(0.84, cfg["count"] * mean_area / (WATER_W * WATER_H))
    return tdem.pack.random(WATER_W, WATER_H, rmin, rmax, seed=1, target_fraction=frac)


def block_layout(columns, gap=COLUMN_GAP):
    """Lower-left corners of the blocks, column by column, bottom to top; ``gap``
    between columns (m)."""
    x0 = WATER_W + GAP_TO_BLOCKS
    return [(x0 + c * (BLOCK + gap), r * BLOCK) for c in range(columns)
            for r in range(ROWS)]


def square(x, y, s=BLOCK):
    v = np.array([[x, y], [x + s, y], [x + s, y + s], [x, y + s]], float)
    return v, np.array([[0, 1, 2], [0, 2, 3]])


def build(cfg, columns, arch=None, threads=None):
    sim = tdem.Simulation(gravity=(0.0, -9.81), dt_fraction=cfg["dt_fraction"],
                          local_damping=0.7, arch=arch, **({"threads": threads} if threads else {}))
    water = tdem.Fluid(density=RHO_W, bulk_modulus=cfg["bulk"], viscosity=cfg["viscosity"],
                       linear_viscosity=cfg["b1"], voronoi=cfg.get("voronoi", False))
    pos, rad = water_particles(cfg)
    wlaw = tdem.LinearContact(kn=3.0 * cfg["bulk"], ks=0.0, friction=0.0)
    g = sim.add_particles(pos, rad, material=water, tolerance=cfg["tolerance"], contact=wlaw)
    top = 2.0 * WATER_H
    sim.add_wall((0.0, 0.0), (TANK_L, 0.0), contact=wlaw)
    # the tank's sides for the water reach WALL_TOP: a splash thrown above them would
    # leave the tank and fall for ever
    sim.add_wall((0.0, WALL_TOP), (0.0, 0.0), contact=wlaw)
    sim.add_wall((TANK_L, 0.0), (TANK_L, WALL_TOP), contact=wlaw)
    board = sim.add_wall((WATER_W, 0.0), (WATER_W, top), contact=wlaw)
    concrete = tdem.Elastic(**CONCRETE)
    block_material = tdem.Elastic(**dict(CONCRETE, density=cfg.get("block_density",
                                                                   CONCRETE["density"])))
    fv, ft = tdem.mesh.rectangle(TANK_L, 0.1, 1, 1, origin=(0.0, -0.1))
    floor = sim.add_block(fv, ft, material=concrete, rigid=True)
    floor.fix(np.arange(len(fv)), vx=0.0, vy=0.0)
    # the tank's end walls for the blocks (walls act on particles only)
    ends = []
    for x0 in (-0.1, TANK_L):
        ev, et = tdem.mesh.rectangle(0.1, top + 0.1, 1, 1, origin=(x0, -0.1))
        e = sim.add_block(ev, et, material=concrete, rigid=True)
        e.fix(np.arange(len(ev)), vx=0.0, vy=0.0)
        ends.append(e)
    blocks = []
    gap = cfg.get("column_gap", COLUMN_GAP)
    for (x, y) in block_layout(columns, gap):
        v, t = square(x, y)
        blocks.append(sim.add_block(v, t, material=block_material, rigid=True))
    ks = BLOCK_KN / (2.0 * (1.0 + CONCRETE["poisson"]))
    kn = cfg.get("block_kn", BLOCK_KN)
    bb = tdem.PointEdge(kn=kn, ks=ks, friction_angle=cfg.get("block_friction", FRICTION),
                        cohesion=0.0, tensile_strength=0.0)
    bf = tdem.PointEdge(kn=kn, ks=ks, friction_angle=cfg.get("floor_friction", FRICTION),
                        cohesion=0.0, tensile_strength=0.0)
    wb = tdem.PointEdge(kn=cfg.get("water_block_kn", 3.0 * cfg["bulk"]), ks=0.0,
                        friction_angle=0.0)
    corners = block_layout(columns, gap)
    for k, b in enumerate(blocks):
        sim.couple(b, floor, bf)
        for e in ends:
            sim.couple(b, e, bb)
        sim.couple(g, b, wb)
        for m in range(k + 1, len(blocks)):
            sim.couple(b, blocks[m], bb)
    return {"sim": sim, "water": g, "blocks": blocks, "board": board, "floor": floor,
            "n": len(pos), "corners": corners, "radius": rad}


def in_tank(x, r):
    """Which water particles (centres ``x``, radii ``r``) are inside the tank: above
    its floor and between its side walls (a radius of give each way)."""
    return (x[:, 1] > -r) & (x[:, 0] > -r) & (x[:, 0] < TANK_L + r)


def gap_to_blocks(x, squares):
    """Distance (m) from each point of ``x`` (n, 2) to the nearest block outline, the
    blocks given by their corners ``squares`` (a list of (4, 2) arrays in order round
    the square); 0 inside a block."""
    from tdem.pack import _signed_distance
    x = np.asarray(x, dtype=float).reshape(-1, 2)
    best = np.full(len(x), np.inf)
    for sq in squares:       # the signed distance is positive inside
        best = np.minimum(best, np.maximum(-_signed_distance(x, np.asarray(sq, float))[0], 0.0))
    return best


def fastest_where(r, limit):
    """Where and when the fastest water particle of a run was (from its records), and
    for how many records the fastest exceeded ``limit``: words for a check's note."""
    v = np.asarray(r["vmax_water"], dtype=float)
    at = np.asarray(r.get("vmax_at", []), dtype=float).reshape(-1, 4)
    if not len(v) or len(at) != len(v):
        return "where: not recorded"
    k = int(np.argmax(v))
    x, y, gap, rad = at[k]
    over = int(np.count_nonzero(v > limit))
    return (f"fastest at t = {r['t'][k]:.2f} s, x = {x:.3f} m, y = {y:.3f} m, "
            f"{gap / rad:.1f} radii from the nearest block; above {limit:.1f} m/s in "
            f"{over} of {len(v)} records (0.02 s apart)")


def block_state(b):
    """Centre (2,) and rotation (deg, counter-clockwise) of a rigid square block."""
    x = b.nodes()["position"]
    c = x.mean(axis=0)
    e = x[1] - x[0]
    return c, math.degrees(math.atan2(e[1], e[0]))


ONSET_DX = 0.005          # the top block has started to move when it has moved this far (m)


def motion_onset(t, dx):
    """When |dx| first reached ONSET_DX, interpolated linearly between the two records
    around it (records are 0.02 s apart); None if it never did."""
    t, a = np.asarray(t, float), np.abs(np.asarray(dx, float))
    k = np.flatnonzero(a > ONSET_DX)
    if not len(k):
        return None
    k = int(k[0])
    if k == 0 or a[k] == a[k - 1]:
        return float(t[k])
    return float(t[k - 1] + (ONSET_DX - a[k - 1]) / (a[k] - a[k - 1]) * (t[k] - t[k - 1]))


def classify(dx, rot):
    if abs(rot) > TOPPLED_ROT:
        return "toppled"
    if abs(dx) > TOPPLED_DX:
        return "slid"
    if abs(dx) < STOOD_DX and abs(rot) < STOOD_ROT:
        return "stood"
    return "moved"


def _draw(ax, snap, prange):
    x, r, p = snap["x"], snap["r"], snap["p"]
    from matplotlib.collections import EllipseCollection
    sc = EllipseCollection(2 * r, 2 * r, np.zeros(len(r)), units="xy", offsets=x,
                           offset_transform=ax.transData, cmap="viridis", linewidths=0)
    sc.set_array(p * 1e-3)
    sc.set_clim(prange[0] * 1e-3, prange[1] * 1e-3)
    ax.add_collection(sc)
    for v in snap["blocks"]:
        ax.fill(v[:, 0], v[:, 1], facecolor="0.85", edgecolor="k", lw=0.6)
    ax.plot([0, 0, TANK_L, TANK_L], [WATER_H * 1.1, 0, 0, WATER_H * 1.1], "k-", lw=1.2)
    ax.set_xlim(-0.05, TANK_L + 0.05)
    ax.set_ylim(-0.05, WATER_H * 1.05)
    ax.set_aspect("equal")
    ax.tick_params(labelsize=7)
    ax.set_xlabel("x (m)", fontsize=7)
    ax.set_ylabel("y (m)", fontsize=7)
    when = (" (a time of the paper's snapshots)" if snap["paper_t"] is not None
            else " (no paper snapshot: its later ones lie beyond this run)")
    ax.set_title(f"t = {snap['t']:.2f} s{when}", fontsize=8)
    return sc


def plot_snapshots(snaps, png, title):
    plt = common.pyplot()
    fig, axes = plt.subplots(3, 2, figsize=(9, 6.4), layout="constrained")
    prange = (0.0, RHO_W * 9.81 * WATER_H)
    sc = None
    for ax, snap in zip(axes.ravel(), snaps):
        sc = _draw(ax, snap, prange)
    for ax in axes.ravel()[len(snaps):]:
        ax.axis("off")
    if sc is not None:
        fig.colorbar(sc, ax=axes.ravel().tolist(), label="water pressure (kPa)", shrink=0.6)
    fig.suptitle(title, fontsize=10)
    common.save(fig, png, dpi=110)


def plot_displacements(results, png):
    plt = common.pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8))
    for name, res in results.items():
        t, dx, rot = res["t"], res["dx_top"], res["rot_top"]
        axes[0].plot(t, dx, label=f"{name} columns: top block, right column")
        axes[1].plot(t, rot, label=f"{name} columns: top block, right column")
    axes[0].axhline(TOPPLED_DX, color="r", ls=":", lw=0.8,
                    label=f"|dx| > {TOPPLED_DX} m: slid (if not toppled)")
    axes[0].axhline(STOOD_DX, color="g", ls=":", lw=0.8, label=f"|dx| < {STOOD_DX} m: stood")
    axes[1].axhline(TOPPLED_ROT, color="r", ls=":", lw=0.8,
                    label=f"|rotation| > {TOPPLED_ROT:g}°: toppled")
    axes[1].axhline(STOOD_ROT, color="g", ls=":", lw=0.8,
                    label=f"|rotation| < {STOOD_ROT:g}°: stood")
    axes[0].set_ylabel("horizontal displacement (m)")
    axes[1].set_ylabel("rotation (°, counter-clockwise +)")
    for ax in axes:
        ax.set_xlabel("time after the board is removed (s)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle("Water and blocks: top block of the rightmost column", fontsize=10)
    fig.tight_layout()
    common.save(fig, png, dpi=120)


def run_one(cfg, columns, name, out, arch=None, threads=None, folder=None):
    """One run: ``name`` "four" or "two" (the paper's snapshot times); output in
    ``out/folder`` (default ``out/name``)."""
    m = build(cfg, columns, arch=arch, threads=threads)
    sim, blocks, board = m["sim"], m["blocks"], m["board"]
    t0 = cfg["settle"]
    sim.run(until=t0)
    sim.local_damping = 0.0
    board.velocity = (0.0, BOARD_SPEED)
    top = blocks[-1]             # top block of the rightmost column
    c_ref, a_ref = block_state(top)
    refs = [block_state(b)[0] for b in blocks]
    sub = out / (folder or name)
    sub.mkdir(parents=True, exist_ok=True)
    output = common.start_output(sim, sub, max(1, int(round(cfg["vtu_interval"] / sim.dt))))
    T = cfg["duration"]
    times = np.round(np.arange(0.02, T + 1e-9, 0.02), 6)
    paper_t = PAPER_TIMES[name]
    snap_t = [tp for tp in paper_t if tp <= T + 1e-9]
    if len(snap_t) < len(paper_t):     # a shorter run: the rest evenly up to its end
        extra = np.linspace(snap_t[-1] if snap_t else 0.0, T, len(paper_t) - len(snap_t) + 1)[1:]
        snap_t += [float(e) for e in extra]
    stops = sorted(set(np.round(np.concatenate([times, snap_t]), 6)))
    rec = {"t": [], "dx_top": [], "rot_top": [], "dx_all": [], "vmax_water": [], "rise": [],
           "outside": [], "vmax_at": []}
    snaps = []
    status = "completed"
    clock = common.Stopwatch()
    said = 0.0
    for tc in stops:
        try:
            sim.run(until=t0 + tc)
        except tdem.InstabilityError as e:
            status = f"unstable: {e}"
            print(f"{name}: {status}", file=sys.stderr)
            break
        c, a = block_state(top)
        rec["t"].append(sim.time - t0)
        rec["dx_top"].append(c[0] - c_ref[0])
        rec["rot_top"].append(a - a_ref)
        cs = [block_state(b)[0] for b in blocks]
        rec["dx_all"].append([cb[0] - r[0] for cb, r in zip(cs, refs)])
        rec["rise"].append(max(cb[1] - r[1] for cb, r in zip(cs, refs)))
        p = sim.particles.numpy()
        ids = m["water"].ids
        inside = in_tank(p["position"][ids], p["radius"][ids])
        speed = np.linalg.norm(p["velocity"][ids], axis=1)
        rec["vmax_water"].append(float(speed[inside].max()) if inside.any() else 0.0)
        if inside.any():         # where the fastest water is: its place, gap to a block
            k = np.flatnonzero(inside)[np.argmax(speed[inside])]
            xk = p["position"][ids][k]
            sq = [b.nodes()["position"][[0, 1, 2, 3]] for b in blocks]
            rec["vmax_at"].append([xk[0], xk[1], float(gap_to_blocks(xk, sq)[0]),
                                   float(p["radius"][ids][k])])
        else:
            rec["vmax_at"].append([np.nan] * 4)
        rec["outside"].append(int(np.count_nonzero(~inside)))
        if tc >= said + 0.1 - 1e-9 or tc >= T - 1e-9:     # a line every 0.1 s of the run
            said = tc
            el = clock()
            common.say(f"{name}: t = {tc:.2f} of {T:g} s, top block dx = "
                       f"{rec['dx_top'][-1]:+.3f} m, rotation {rec['rot_top'][-1]:+.1f} deg; "
                       f"{common.duration(el)} so far, about "
                       f"{common.duration(el * (T - tc) / tc)} left")
        if any(abs(tc - s) < 1e-6 for s in snap_t):
            k = snap_t.index(min(snap_t, key=lambda s: abs(s - tc)))
            at_paper = k < len(paper_t) and abs(snap_t[k] - paper_t[k]) < 1e-6
            snaps.append({"t": sim.time - t0, "paper_t": paper_t[k] if at_paper else None,
                          "x": p["position"][ids].copy(), "r": p["radius"][ids].copy(),
                          "p": p["pressure"][ids].copy(),
                          "blocks": [b.nodes()["position"][[0, 1, 2, 3]].copy() for b in blocks]})
    common.finish_output(output)
    res = {k: np.asarray(v) for k, v in rec.items()}
    res["snaps"] = snaps
    res["status"] = status
    res["n"] = m["n"]
    res["dt"] = sim.dt
    p = sim.particles.numpy()
    xw = p["position"][m["water"].ids]
    res["water_right_of_blocks"] = float(np.mean(xw[:, 0] > m["corners"][-1][0] + BLOCK))
    return res


def run(preset="quick", out=None, arch=None, threads=None, duration=None, runs=("four", "two"),
        water="elements", parallel=False, block_density=None):
    """Run the case; returns the summary dict (also written to ``out/summary.json``).
    ``water``: "elements" (the presets' lattice water) or "cells" (:data:`CELLS`).
    ``parallel``: run the systems at once, one process each (each with ``threads``
    threads; the same results as one after the other). ``block_density``: the
    blocks' density (kg/m³; default concrete's 2400, the paper gives none)."""
    clock = common.Stopwatch()
    cfg = dict(PRESETS[preset])
    if water == "cells":
        cfg.update(CELLS[preset])
    elif water != "elements":
        from tdem.errors import InputError
        raise InputError(f"water must be 'elements' or 'cells', got {water!r}")
    if duration is not None:
        cfg["duration"] = float(duration)
    rho_b = CONCRETE["density"] if block_density is None else density(block_density)
    cfg["block_density"] = rho_b
    out = common.output_dir(CASE, out)
    columns = COLUMNS
    if parallel and len(runs) > 1:
        import concurrent.futures
        import multiprocessing
        with concurrent.futures.ProcessPoolExecutor(
                max_workers=len(runs), mp_context=multiprocessing.get_context("spawn")) as pool:
            futures = {name: pool.submit(run_one, cfg, columns[name], name, out, arch, threads)
                       for name in runs}
            results = {name: f.result() for name, f in futures.items()}
    else:
        results = {name: run_one(cfg, columns[name], name, out, arch, threads)
                   for name in runs}
    hist = {name: {"time": r["t"], "dx_top": r["dx_top"], "rot_top": r["rot_top"],
                   "vmax_water": r["vmax_water"], "vmax_at": r["vmax_at"]}
            for name, r in results.items()}
    common.save_histories(out / "histories.h5", hist)
    plot_displacements(results, out / "block_displacements.png")
    for name, r in results.items():
        fig = "fig26_four.png" if name == "four" else "fig27_two.png"
        plot_snapshots(r["snaps"], out / fig,
                       f"Water and {name}-column block system ({preset} preset; paper Fig. "
                       f"{26 if name == 'four' else 27})")
    checks = []
    c = math.sqrt(cfg["bulk"] / RHO_W)
    for name, r in results.items():
        rise_bound = rise_limit(name)
        dx = float(r["dx_top"][-1]) if len(r["dx_top"]) else float("nan")
        dxm = float(np.max(np.abs(r["dx_top"]))) if len(r["dx_top"]) else float("nan")
        rotm = float(np.max(np.abs(r["rot_top"]))) if len(r["rot_top"]) else float("nan")
        outcome = classify(dxm, rotm)
        how = (f"top block of the rightmost column: toppled if |rotation| > {TOPPLED_ROT}°, "
               f"slid if not but |dx| > {TOPPLED_DX} m, stood if |dx| < {STOOD_DX} m and "
               f"|rotation| < {STOOD_ROT}° (largest values over the run), else moved")
        if name == "four":
            # the paper's words, not a class: the water "just causes little movement"
            checks += [
                common.check(f"{name}.outcome", outcome, None, None, "",
                             f"{how}; reported only: the paper's four columns stand "
                             "(Fig. 26), compared as little_movement_dx/_rotation"),
                common.check(
                    f"{name}.little_movement_dx", dxm, None, common.between(max=LITTLE_DX),
                    "m", "the paper (§4.3): the water 'just causes little movement' of the "
                    "four columns, read (decided before any run) as the top block of the "
                    f"rightmost column moving less than half a block width, {LITTLE_DX:g} "
                    "m (largest |dx| over the run): the columns stay on their own "
                    "footprints, as in Fig. 26. The paper gives no block density; the "
                    "sweep over it (--sweep --densities, docs/cases.md) shows concrete's "
                    "2400 kg/m³ sliding 0.22 m at the quick preset and 4000 kg/m³ and up "
                    "moving 1.4 cm or less"),
                common.check(
                    f"{name}.little_movement_rotation", rotm, None,
                    common.between(max=LITTLE_ROT), "deg",
                    "with little_movement_dx: and no toppling, the top block of the "
                    f"rightmost column turning less than {LITTLE_ROT:g}° (largest over the "
                    "run: its top edge then leans 9 mm over the block's 10 cm, a quarter "
                    "of the 20° that counts as toppled)"),
            ]
        else:
            checks.append(common.check(
                f"{name}.outcome", outcome, PAPER_OUTCOME[name], common.EQUAL, "",
                f"{how}; paper Fig. 27"))
        checks += [
            common.check(
                f"{name}.motion_onset", motion_onset(r["t"], r["dx_top"]), None,
                common.between(0.40, 0.60), "s",
                "first time the top block of the rightmost column moved 5 mm (interpolated "
                "between the records, 0.02 s apart): after the "
                "dam-break front's arrival at the blocks (Martin & Moyce, x/a = 2.44 at "
                "T = 2.0: 0.40 s; the paper's Fig. 26a shows the water there at 0.36 s), "
                "before 0.60 s (decided here: the surge builds up its push within 0.2 s)"),
            common.check(
                f"{name}.block_rise_max", float(np.max(r["rise"])) if len(r["rise"]) else None,
                None, common.between(max=rise_bound), "m",
                "largest rise of any block's centre above its start: riding onto another "
                "block and tipping over a corner raise it by at most 0.1 m + (sqrt(2) - 1)/2 "
                "x 0.1 m = 0.121 m; where the columns topple onto the tank's end wall a "
                "block rides up onto the pile there, over a block that leans on another "
                "(the quick preset: 0.147 m, at rest on the pile at 1.2 s), one block "
                "height more, 0.221 m; more would be a block thrown up (the contact "
                "failure this check was made for threw them 1 m)"),
            common.check(
                f"{name}.water_vmax", float(np.max(r["vmax_water"])) if len(r["vmax_water"])
                else None, None, common.between(max=c / 10.0), "m/s",
                f"largest speed of a water particle in the tank; weakly compressible water "
                f"needs c >= 10 x the largest flow speed (weakly compressible water), "
                f"c = {c:.0f} m/s; {fastest_where(r, c / 10.0)}"),
            common.check(
                f"{name}.water_left_tank", int(np.max(r["outside"])) if len(r["outside"])
                else None, 0, common.EQUAL, "",
                "most water particles outside the tank (below its floor or beyond its side "
                f"walls, {WALL_TOP:g} m high) at any record: none may leave it"),
            common.check(f"{name}.top_dx_max", dxm, None, None, "m",
                         "largest |dx| of the top block of the rightmost column"),
            common.check(f"{name}.top_rotation_max", rotm, None, None, "deg",
                         "largest |rotation| of the top block of the rightmost column"),
            common.check(f"{name}.top_dx_final", dx, None, None, "m", "at the end of the run"),
            common.check(f"{name}.water_right_of_blocks", r["water_right_of_blocks"], None,
                         None, "", "fraction of water particles right of the blocks at the "
                                   "end (the paper's two-column run: the water fills the "
                                   "bottom of the tank)"),
        ]
    data = {
        "model": {"water_particles": {k: r["n"] for k, r in results.items()},
                  "paper_water_particles": 5528, "packing": cfg["packing"],
                  "water": water,
                  "bulk_modulus_Pa": cfg["bulk"], "sound_speed_m_s": c,
                  "front_speed_2sqrt_gH": 2.0 * math.sqrt(9.81 * WATER_H),
                  "blocks": "rigid", "block_contact_kn": BLOCK_KN,
                  "block_density_kg_m3": rho_b,
                  "block_mass_kg_per_m": rho_b * BLOCK * BLOCK,
                  "dt_s": {k: r["dt"] for k, r in results.items()},
                  "settle_s": cfg["settle"], "duration_s": cfg["duration"],
                  "status": {k: r["status"] for k, r in results.items()}},
    }
    variant = "-".join(([water] if water != "elements" else [])
                       + ([] if set(results) == {"four", "two"} else list(results)))
    if cfg["duration"] != PRESETS[preset]["duration"]:
        variant = "-".join(filter(None, [variant, f"{cfg['duration']:g}s"]))
    if rho_b != CONCRETE["density"]:
        variant = "-".join(filter(None, [variant, f"rho{rho_b:g}"]))
    summary = common.summary(
        CASE, preset, checks, data, clock(), threads=threads, variant=variant or None,
        paper="Feng, Li & Oñate (2015), §4.3, Figs. 25-27",
        notes="weakly compressible water (K in data.model); rigid blocks; times from the "
              "board's removal; the outcome measure is in the checks' notes")
    common.write_summary(out, summary)
    return summary


# ------------------------------------------------------------------ the sweep
#: the parameters the paper does not give, and the values the sweep tries (four columns)
SWEEP = {"floor_friction": (25.0, 35.0, 45.0), "block_friction": (25.0, 45.0),
         "column_gap": (0.001, 0.01)}


def sweep_tasks(preset="quick", arch=None, grid=None):
    """One task per combination of ``grid`` (default :data:`SWEEP`), four columns."""
    grid = SWEEP if grid is None else grid
    for name, values in grid.items():
        if name not in SWEEP:
            raise ValueError(f"grid: unknown parameter {name!r} (known: {', '.join(SWEEP)})")
        if not values:
            raise ValueError(f"grid: {name} has no values")
    keys = list(grid)
    combos = [[]]
    for k in keys:
        combos = [c + [float(v)] for c in combos for v in grid[k]]
    return [dict(zip(keys, c), preset=preset, arch=arch) for c in combos]


def density_tasks(preset="quick", arch=None, densities=DENSITIES, runs=("four", "two")):
    """The density sweep: one task per block density (kg/m³, :func:`density`; each
    value once, in the order given) and block system of ``runs``, everything else
    at the preset's values."""
    from tdem.errors import InputError
    if isinstance(densities, (str, bytes)) or not hasattr(densities, "__iter__"):
        raise InputError(f"densities must be a list of numbers > 0 (kg/m³), got {densities!r}")
    rhos = list(dict.fromkeys(density(v, "densities") for v in densities))
    if not rhos:
        raise InputError(f"densities has no values, got {densities!r}")
    for name in runs:
        if name not in COLUMNS:
            raise InputError(f"runs: unknown block system {name!r} (known: four, two)")
    return [{"block_density": rho, "columns": COLUMNS[name], "preset": preset, "arch": arch}
            for rho in rhos for name in dict.fromkeys(runs)]


def system_name(columns):
    return {c: n for n, c in COLUMNS.items()}[int(columns)]


def task_name(task):
    if "block_density" in task:
        return "{}_rho{:g}".format(system_name(task.get("columns", 4)), task["block_density"])
    return "floor{:g}_block{:g}_gap{:g}mm".format(
        task.get("floor_friction", FRICTION), task.get("block_friction", FRICTION),
        1e3 * task.get("column_gap", COLUMN_GAP))


def sweep_task(task, out):
    """Run the task's block system (``columns``, default four) with its parameters
    (:data:`SWEEP`, ``block_density``); returns its row."""
    clock = common.Stopwatch()
    cfg = dict(PRESETS[task["preset"]])
    cfg["vtu_interval"] = cfg["duration"]           # the first and the last state only
    for k in (*SWEEP, "block_density"):
        if k in task:
            cfg[k] = task[k]
    columns = int(task.get("columns", 4))
    name = system_name(columns)
    r = run_one(cfg, columns, name, Path(out), arch=task.get("arch"), threads=1,
                folder=task_name(task))
    dxm = float(np.max(np.abs(r["dx_top"]))) if len(r["dx_top"]) else float("nan")
    rotm = float(np.max(np.abs(r["rot_top"]))) if len(r["rot_top"]) else float("nan")
    dx_all = np.asarray(r["dx_all"])
    return {**{k: task.get(k, d) for k, d in (("floor_friction", FRICTION),
                                             ("block_friction", FRICTION),
                                             ("column_gap", COLUMN_GAP),
                                             ("block_density", CONCRETE["density"]))},
            "system": name, "outcome": classify(dxm, rotm), "top_dx_max_m": dxm,
            "top_rotation_max_deg": rotm,
            "little_movement": bool(dxm < LITTLE_DX and rotm < LITTLE_ROT),
            "onset_s": motion_onset(r["t"], r["dx_top"]),
            "columns_moved_0p1m": int(np.sum(np.max(np.abs(dx_all), axis=0)
                                              .reshape(columns, ROWS).max(axis=1)
                                              > TOPPLED_DX)) if len(dx_all) else 0,
            "status": r["status"], "wall_s": clock(),
            "t": [float(v) for v in r["t"]], "dx_top": [float(v) for v in r["dx_top"]],
            "rot_top": [float(v) for v in r["rot_top"]]}


def sweep_table(rows):
    """The rows as a Markdown table (docs and the summary's notes)."""
    lines = ["| floor friction | block friction | column gap | outcome | top block: largest "
             "dx | largest rotation | moves 5 mm at | columns moved > 0.1 m |",
             "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    for r in rows:
        onset = "–" if r["onset_s"] is None else f"{r['onset_s']:.2f} s"
        lines.append(f"| {r['floor_friction']:g}° | {r['block_friction']:g}° | "
                     f"{1e3 * r['column_gap']:g} mm | {r['outcome']} | "
                     f"{r['top_dx_max_m']:.3f} m | {r['top_rotation_max_deg']:.1f}° | {onset} | "
                     f"{r['columns_moved_0p1m']} of 4 |")
    return "\n".join(lines) + "\n"


def density_table(rows):
    """The density sweep's rows as a Markdown table."""
    lines = ["| block density | system | outcome | top block: largest \\|dx\\| | largest "
             f"rotation | moves 5 mm at | little movement (< {LITTLE_DX:g} m, "
             f"< {LITTLE_ROT:g}°) | columns moved > 0.1 m |",
             "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    for r in rows:
        onset = "–" if r["onset_s"] is None else f"{r['onset_s']:.2f} s"
        n = COLUMNS[r["system"]]
        lines.append(f"| {r['block_density']:g} kg/m³ | {r['system']} columns | "
                     f"{r['outcome']} | {r['top_dx_max_m']:.3f} m | "
                     f"{r['top_rotation_max_deg']:.1f}° | {onset} | "
                     f"{'yes' if r['little_movement'] else 'no'} | "
                     f"{r['columns_moved_0p1m']} of {n} |")
    return "\n".join(lines) + "\n"


def _sweep_member(out, **task):
    """One member of the sweep's ensemble: :func:`sweep_task` writing under ``out``."""
    return sweep_task(task, out)


def run_sweep(tasks, out, workers=2, scheduler=None):
    """Run ``tasks`` with :func:`tdem.ensemble` (a ``distributed.LocalCluster`` of
    ``workers`` processes with one thread each, or the cluster at ``scheduler``),
    printing each run as it ends; returns the rows in task order. Each run is kept
    in ``out/sweep`` as it ends (its table there too), and a sweep started again
    with the same ``out`` runs only the runs not done. A run that raises is a row
    with ``status`` "error" and its traceback in ``error``; the others go on."""
    import functools

    import tdem
    common.dask_distributed()          # no Dask: say how to install it, before anything
    count = [0]

    def line(r):
        count[0] += 1
        if r["status"] != "ok":
            text = r["error"].strip().splitlines()
            common.say(f"water_blocks sweep: {count[0]}/{len(tasks)} {task_name(r)}: error "
                       f"({text[-1] if text else ''})")
            return
        common.say(f"water_blocks sweep: {count[0]}/{len(tasks)} {task_name(r)}: "
                   f"{r['outcome']} (dx {r['top_dx_max_m']:.3f} m, rotation "
                   f"{r['top_rotation_max_deg']:.1f}°, {r['wall_s'] / 60:.1f} min)")

    res = tdem.ensemble(functools.partial(_sweep_member, str(out)), tasks,
                        client=scheduler, workers=None if scheduler else workers,
                        threads=1, out=Path(out) / "sweep", progress=False, on_result=line)
    return res.rows


def plot_sweep(rows, png):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    gaps = sorted({r["column_gap"] for r in rows})
    floors = sorted({r["floor_friction"] for r in rows})
    fig, axes = plt.subplots(1, len(gaps), figsize=(6.5 * len(gaps), 4.8), squeeze=False,
                             sharey=True)
    colours = plt.cm.viridis(np.linspace(0.0, 0.85, len(floors)))
    for ax, gap in zip(axes[0], gaps):
        for r in rows:
            if r["column_gap"] != gap:
                continue
            c = colours[floors.index(r["floor_friction"])]
            ls = "-" if r["block_friction"] == min(x["block_friction"] for x in rows) else "--"
            ax.plot(r["t"], r["dx_top"], ls, color=c,
                    label=f"floor {r['floor_friction']:g}°, blocks {r['block_friction']:g}°: "
                          f"{r['outcome']}")
        ax.axhline(TOPPLED_DX, color="grey", lw=0.8, ls=":")
        ax.set_title(f"four columns, {1e3 * gap:g} mm apart")
        ax.set_xlabel("time after the board's removal (s)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    axes[0][0].set_ylabel("top block of the right column: dx (m)")
    fig.suptitle("water_blocks: the parameters the paper does not give (paper: four columns "
                 "stand)")
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    plt.close(fig)


def plot_density_sweep(rows, png):
    """The top block of the right column, displacement and rotation against time,
    one line per density; four columns left, two right."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    systems = [s for s in COLUMNS if any(r["system"] == s for r in rows)]
    rhos = sorted({r["block_density"] for r in rows})
    colours = plt.cm.viridis(np.linspace(0.0, 0.85, len(rhos)))
    fig, axes = plt.subplots(2, len(systems), figsize=(6.5 * len(systems), 7.5),
                             squeeze=False, sharex=True)
    for j, name in enumerate(systems):
        for r in rows:
            if r["system"] != name:
                continue
            c = colours[rhos.index(r["block_density"])]
            label = f"{r['block_density']:g} kg/m³: {r['outcome']}"
            axes[0][j].plot(r["t"], np.abs(r["dx_top"]), color=c, label=label)
            axes[1][j].plot(r["t"], np.abs(r["rot_top"]), color=c, label=label)
        if name == "four":
            axes[0][j].axhline(LITTLE_DX, color="g", lw=0.8, ls=":",
                               label=f"{LITTLE_DX:g} m: the paper's 'little movement'")
            axes[1][j].axhline(LITTLE_ROT, color="g", lw=0.8, ls=":",
                               label=f"{LITTLE_ROT:g}°: the paper's 'little movement'")
        axes[1][j].axhline(TOPPLED_ROT, color="r", lw=0.8, ls=":",
                           label=f"{TOPPLED_ROT:g}°: toppled")
        axes[0][j].set_title(f"{name} columns (paper: "
                             f"{'little movement' if name == 'four' else 'topple'})")
        axes[1][j].set_xlabel("time after the board's removal (s)")
        for ax in (axes[0][j], axes[1][j]):
            ax.grid(alpha=0.3)
            ax.legend(fontsize=7)
    axes[0][0].set_ylabel("top block of the right column: |dx| (m)")
    axes[1][0].set_ylabel("top block of the right column: |rotation| (°)")
    fig.suptitle("water_blocks: the blocks' density (not in the paper)")
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    plt.close(fig)


def _extra(p):
    p.add_argument("--water", choices=("elements", "cells"), default="elements",
                   help="elements: the presets' water on a square lattice (PCMM elements); "
                        "cells: water of Voronoi cells (tdem.Fluid(voronoi=True)) packed at "
                        "random, R = 1.4-2.6 cm (quick) or the paper's 5528 discs of 3-8 mm "
                        "(paper)")
    p.add_argument("--runs", nargs="+", choices=("four", "two"), default=("four", "two"),
                   help="which block systems to run (default both, one after the other)")
    p.add_argument("--parallel", action="store_true",
                   help="run the block systems at once, one process each (--threads "
                        "threads each; the same records as one after the other)")
    p.add_argument("--duration", type=float, default=None, metavar="S",
                   help="seconds after the board's removal (default: the preset's)")
    p.add_argument("--sweep", action="store_true",
                   help="four columns over the parameters the paper does not give (floor "
                        "and block friction, column gap; cases.water_blocks.SWEEP) at the "
                        "preset's resolution, on Dask")
    p.add_argument("--densities", nargs="+", default=None, metavar="RHO",
                   help="with --sweep: sweep the blocks' density instead (kg/m³, e.g. "
                        "2400 4000 5600 7800), both block systems (or --runs), everything "
                        "else at the preset's values")
    p.add_argument("--block-density", default=None, metavar="RHO",
                   help="the blocks' density of a single run (kg/m³; default concrete's "
                        "2400: the paper gives none)")
    p.add_argument("--workers", type=int, default=2,
                   help="with --sweep: worker processes of the local cluster (default 2)")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="with --sweep: address of an existing Dask scheduler")


def main_sweep(args, out):
    import json
    from tdem.errors import InputError
    if args.workers < 1:
        raise InputError(f"workers must be >= 1, got {args.workers!r}")
    try:
        common.dask_distributed()
    except ImportError as e:
        print(f"water_blocks --sweep: {e}", file=sys.stderr)
        return 2
    by_density = args.densities is not None
    if by_density:
        tasks = density_tasks(args.preset, args.arch, args.densities,
                              tuple(dict.fromkeys(args.runs)))
        rhos = dict.fromkeys(t["block_density"] for t in tasks)
        what = (f"runs of block densities {', '.join(f'{r:g}' for r in rhos)} kg/m³ "
                f"({' and '.join(dict.fromkeys(args.runs))} columns)")
    else:
        tasks = sweep_tasks(args.preset, args.arch)
        what = "runs of four columns"
    print(f"water_blocks sweep ({args.preset}): {len(tasks)} {what} on "
          f"{args.scheduler or f'{args.workers} local workers'}", flush=True)
    rows = run_sweep(tasks, out, workers=args.workers, scheduler=args.scheduler)
    (out / "sweep.json").write_text(json.dumps(
        [{k: v for k, v in r.items() if k not in ("t", "dx_top", "rot_top")} for r in rows],
        indent=1))
    ok = [r for r in rows if r["status"] == "ok"]
    table = density_table(ok) if by_density else sweep_table(ok)
    (out / "sweep.md").write_text(table)
    if ok:
        (plot_density_sweep if by_density else plot_sweep)(ok, out / "sweep.png")
    print(table)
    print(f"sweep: {out / 'sweep.md'}, {out / 'sweep.png'}")
    if len(ok) < len(rows):
        print(f"water_blocks sweep: {len(rows) - len(ok)} of {len(rows)} runs failed "
              f"(their tracebacks: {out / 'sweep' / 'results.csv'})", file=sys.stderr)
        return 1
    return 0


def main(argv=None):
    from tdem.errors import InputError
    args, out = common.parse(CASE, argv, description=__doc__.splitlines()[0], extra=_extra)
    if args.densities is not None:
        if not args.sweep:
            raise InputError(f"--densities {' '.join(args.densities)}: only with --sweep "
                             "(a single run's density: --block-density)")
        for v in args.densities:
            density(v, "--densities")
    if args.block_density is not None:
        rho = density(args.block_density, "--block-density")
        if args.sweep:
            raise InputError(f"--block-density {args.block_density}: not with --sweep "
                             "(sweep the density with --densities)")
    else:
        rho = None
    if args.sweep:
        return main_sweep(args, out)
    if args.duration is not None and not args.duration > 0.0:
        raise InputError(f"duration must be > 0, got {args.duration!r}")
    s = run(args.preset, out, arch=args.arch, threads=args.threads, water=args.water,
            duration=args.duration, runs=tuple(dict.fromkeys(args.runs)),
            parallel=args.parallel, block_density=rho)
    common.print_checks(s)
    print(f"summary: {out / 'summary.json'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
