"""The continuum parts of a simulation: PCMM bodies and deformable blocks.

One step of a model with continua (:meth:`tdem.Simulation._one_step`):

    neighbour lists (engine, when the skin asks)
      -> PCMM candidates (only after a list build)            physics.pcmm.candidates
      -> PCMM elements, stresses, nodal forces, gathered     physics.pcmm.update
         (displacements -> rebuild_elements -> mark_dirty -> copies -> incidence
          -> record_slots -> stresses -> equation_of_state -> gather)
      -> Voronoi water: candidates, cells, pressures, forces  physics.pcmm.cells
      -> block element stresses and nodal forces            physics.blocks.update
      -> DEM contacts + element forces, leapfrog           tdem.step.step
      -> block nodes: damping, prescribed velocities, leapfrog   tdem.nodes

PCMM particles are particles of the engine (they move, collide and are output
with the others); what is added here is their element system and stress state.
Block nodes are not particles: they have their own arrays and integrator
(:mod:`tdem.nodes`), and blocks are output as meshes.
"""
import math

import numpy as np
import taichi as ti

from coupling import point_edge as pe
from physics import blocks as blk
from physics import pcmm
from physics.materials import (JWL, JWL_TYPE, MAT_G, MAT_K, MAT_RHO, MAT_TYPE, MAT_WIDTH,
                               Fluid, MohrCoulomb)
from physics.pcmm import cells as vcells

from . import backend
from .errors import CapacityError, InputError
from .launch import cached
from .mesh import nodal_masses
from .neighbors import F_BUILDS
from . import state as schema
from .nodes import RIGID_NODE, integrate_nodes, integrate_rigid, viscous_boundary
from .step import FIX_VX, FIX_VY

MAX_CANDIDATES = 1024

# the restore point of a run segment (the dynamic state): the per-particle arrays
# below are copied by one kernel (:func:`copy_particles`, in this order), the others
# one by one
_SNAP_PARTICLES = ("psig", "peps", "pstate", "pjwl", "xforce", "ccnt", "ecnt", "cand", "elem",
                   "esig")
_SNAP = _SNAP_PARTICLES + ("pflags", "npos", "nvel", "nforce", "nreact", "tsig", "tstate",
                           "nflags", "psedge", "psforce", "psbroken", "vsedge", "vsforce",
                           "vsbroken", "rstate", "nwork", "rwork", "rrule", "rcand", "rmax",
                           "earea", "ncov")
# (the last two: what the element system derives at each step that ``elements()``
# reads, element areas and N_e, so that a restored or loaded model reports them before
# its next step; files without them still load)
SAVED_DERIVED = ("earea", "ncov")
# what a checkpoint saves: the dynamic state and the nodes' initial positions (the rest
# is set up again from the host description)
SAVED = _SNAP + ("npos0", "nload")
# the Voronoi water's candidates (physics.pcmm.cells), where there is such water: kept
# with the snapshots and checkpoints as PCMM's are (the engine's cell grid they are
# found in is not)
_SNAP_CELLS = ("ccand", "cccnt", "cpflags")
SAVED = SAVED + _SNAP_CELLS


@cached
@ti.kernel
def copy_particles(a0: ti.types.ndarray(), a1: ti.types.ndarray(), a2: ti.types.ndarray(),
                   a3: ti.types.ndarray(), a4: ti.types.ndarray(), a5: ti.types.ndarray(),
                   a6: ti.types.ndarray(), a7: ti.types.ndarray(), a8: ti.types.ndarray(),
                   a9: ti.types.ndarray(), b0: ti.types.ndarray(), b1: ti.types.ndarray(),
                   b2: ti.types.ndarray(), b3: ti.types.ndarray(), b4: ti.types.ndarray(),
                   b5: ti.types.ndarray(), b6: ti.types.ndarray(), b7: ti.types.ndarray(),
                   b8: ti.types.ndarray(), b9: ti.types.ndarray(), serial: ti.template()):
    """Copy the arrays of ``_SNAP_PARTICLES`` (a*) into b*, one parallel loop over the
    particles (Taichi's generic ``copy_from`` indexes a 3-d array element by element,
    several times slower on the element slots)."""
    ti.loop_config(serialize=serial)
    for i in range(a0.shape[0]):
        b0[i] = a0[i]
        b1[i] = a1[i]
        b2[i] = a2[i]
        b3[i] = a3[i]
        b4[i] = a4[i]
        b5[i] = a5[i]
        b6[i] = a6[i]
        for k in range(a7.shape[1]):
            b7[i, k] = a7[i, k]
        for s in range(a8.shape[1]):
            b8[i, s, 0] = a8[i, s, 0]
            b8[i, s, 1] = a8[i, s, 1]
            b9[i, s] = a9[i, s]


def _arr(spec, shape, dtype=ti.f64):
    if spec == 0:
        return ti.ndarray(dtype, shape)
    return schema.ndarray(spec, dtype, shape)


class Continuum:
    """Arrays and kernels of the PCMM bodies and blocks of one simulation.

    Parameters
    ----------
    pos, rad : (N, 2), (N,) the particles (all of them)
    pmat : (N,) material slot of each particle, −1 for a plain DEM disc
    slots : list of (material, tolerance) per slot (blocks' slots have tolerance None)
    blocks : list of :class:`tdem.simulation.Block`
    """

    def __init__(self, pos, rad, pmat, slots, blocks, capacity=16, couples=(), walls=None,
                 mixed=True):
        self.n = len(rad)
        self.slots = slots
        self.blocks = blocks
        self._crit_driven = math.inf   # the driven nodes' critical step (when they move)
        self._tol = None               # the Eq. 1 cut-offs uploaded last
        self._load_fn = False          # loads or fixes given as functions of time
        self._fix_fn = False
        self.has_pcmm = bool((pmat >= 0).any())
        self.walls = np.zeros((0, 4)) if walls is None else np.asarray(walls, float)[:, :4]
        # the Fluid bodies of Voronoi cells (physics.pcmm.cells): their slot per particle
        cslots = [s for s, (m, _) in enumerate(slots) if isinstance(m, Fluid) and m.voronoi]
        self.cmat = np.where(np.isin(pmat, cslots), pmat, -1).astype(np.int32)
        self.has_cells = bool((self.cmat >= 0).any())
        self._cells_need = 0
        # the longest Eq. 1 cut-off, 2·max R + max δ (the candidate search's reach)
        self.reach_length = 2.0 * float(np.max(rad, initial=0.0)) + max(
            (t for _, t in slots if t is not None), default=0.0)
        self.capacity = capacity
        self.masses = None
        self._crit = math.inf
        self._initial_elements(pos, rad, pmat)
        a = self.a = {}
        n, E = max(self.n, 1), pcmm.MAX_ELEMENTS
        nm = max(len(slots), 1)
        a["rad"] = ti.ndarray(ti.f64, (n,))
        a["pmat"] = ti.ndarray(ti.i32, (n,))
        # the radii the element rules see (a swelling JWL particle's grow,
        # physics.pcmm.swell), as they were when the candidates were made, and the
        # largest grown one (0 while none has grown)
        a["rrule"] = ti.ndarray(ti.f64, (n,))
        a["rcand"] = ti.ndarray(ti.f64, (n,))
        a["rmax"] = ti.ndarray(ti.f64, (1,))
        a["rmax"].fill(0.0)
        if self.n:
            a["rad"].from_numpy(np.asarray(rad, dtype=np.float64))
            a["pmat"].from_numpy(pmat.astype(np.int32))
            a["rrule"].from_numpy(np.asarray(rad, dtype=np.float64))
            a["rcand"].from_numpy(np.asarray(rad, dtype=np.float64))
        a["matp"] = ti.ndarray(ti.f64, (nm, MAT_WIDTH))
        a["mtol"] = ti.ndarray(ti.f64, (nm,))
        self.upload_materials()
        a["ccnt"] = ti.ndarray(ti.i32, (n,))
        a["ncnt"] = ti.ndarray(ti.i32, (n,))
        a["elem"] = ti.ndarray(ti.i32, (n, E, 2))
        a["ecnt"] = ti.ndarray(ti.i32, (n,))
        a["earea"] = ti.ndarray(ti.f64, (n, E))
        a["ncov"] = ti.ndarray(ti.i32, (n, E))
        a["esig"] = _arr(4, (n, E))
        a["efor"] = _arr(8, (2 * n * E,))     # records, packed (pcmm.record_slots)
        a["ebase"] = ti.ndarray(ti.i32, (n,))
        a["ecomp"] = ti.ndarray(ti.i32, (n,))     # computed elements per particle
        a["ecomp"].fill(0)
        a["eoff"] = ti.ndarray(ti.i32, (n // pcmm.SCAN_BLOCK + 2,))
        a["eidx"] = ti.ndarray(ti.i32, (n, E))
        a["eidx"].fill(-1)     # no stress pass yet: every slot's stress is in esig
        # the stresses of the computed elements in record order, this step's and last
        # step's (physics.pcmm.copies)
        a["sigc"] = _arr(4, (n * E,))
        a["sigp"] = _arr(4, (n * E,))
        a["ede"] = _arr(7, (n, E))
        a["psig"] = _arr(4, (n,))
        a["pmix"] = _arr(2, (n,))       # the particles' means of the mixed discretization
        a["peps"] = _arr(3, (n,))
        a["pstate"] = _arr(4, (n,))
        # JWL particles: relative volume V, energy E per initial volume, lighting time,
        # pressure, initial volume m/ρ0 (physics.materials.JWL)
        a["pjwl"] = _arr(6, (n,))
        self._init_jwl(pmat)
        a["xforce"] = _arr(2, (n,))
        a["pinc"] = ti.ndarray(ti.i32, (n, pcmm.MAX_INCIDENT))
        a["picnt"] = ti.ndarray(ti.i32, (n,))
        a["piwt"] = ti.ndarray(ti.i32, (n,))
        a["emult"] = ti.ndarray(ti.i32, (n, E))
        a["emult"].fill(1)     # no copies known yet: every slot holds its own stress
        a["elem_old"] = ti.ndarray(ti.i32, (n, E, 2))
        a["esig_old"] = _arr(4, (n, E))
        a["ecnt_old"] = ti.ndarray(ti.i32, (n,))
        # lazy rebuild bookkeeping (physics.pcmm.rebuild_elements)
        a["xref"] = _arr(2, (n,))
        a["pu"] = _arr(2, (n,))
        a["unb"] = ti.ndarray(ti.f64, (n,))
        a["pbud"] = ti.ndarray(ti.f64, (n,))
        a["prb"] = ti.ndarray(ti.i32, (n,))
        a["pdirty"] = ti.ndarray(ti.i32, (n,))
        a["pfail"] = ti.ndarray(ti.i32, (n,))     # pstate[i][1] > 0, for the stress pass
        a["esrc"] = ti.ndarray(ti.i32, (n, E))
        a["ecopy"] = ti.ndarray(ti.i32, (n, E))
        a["ebud"] = ti.ndarray(ti.f64, (n, E))
        self._full = True
        a["pflags"] = ti.ndarray(ti.i32, (pcmm.PFLAGS_SIZE,))
        a["pflags"].from_numpy(np.array(pcmm.PFLAGS_INIT, np.int32))
        self._alloc_lists()
        if self.has_cells:
            self._alloc_cells()
        self._setup_blocks()
        self._setup_couples(couples)
        self.nr = {}
        self.carry_stress = True
        # the nodal mixed discretization (physics.fvm), compiled in where a material
        # takes it (physics.materials.mixes: Mohr–Coulomb)
        self.mixed = bool(mixed) and any(isinstance(m, MohrCoulomb) for m, _ in slots)
        self.snap = {}

    # ------------------------------------------------------------------ set-up
    def _init_jwl(self, pmat):
        """V = 1, E = E0, never lit (t_l = +inf), p = 0, V0 = m/ρ0 for JWL particles,
        no volume change pending."""
        st = np.zeros((max(self.n, 1), 6))
        st[:, 0] = 1.0
        st[:, 2] = np.inf
        st[:, 4] = 1.0
        for s, (mat, _) in enumerate(self.slots):
            if isinstance(mat, JWL):
                sel = np.flatnonzero(pmat == s)
                st[sel, 1] = mat.E0
                st[sel, 4] = self.masses[sel] / mat.density
            elif isinstance(mat, Fluid):   # relative volume and V0 of the Fluid EOS
                sel = np.flatnonzero(pmat == s)
                st[sel, 4] = self.masses[sel] / mat.density
        self.a["pjwl"].from_numpy(st)
        self.jwl_ids = np.flatnonzero(np.isin(pmat, [s for s, (m, _) in enumerate(self.slots)
                                                    if isinstance(m, JWL)]))
        # the update kernel's JWL/EOS passes also carry the Fluid equation of state
        self.eos = len(self.jwl_ids) > 0 or any(isinstance(m, Fluid) and m.equation_of_state
                                                for m, _ in self.slots)

    def light(self, ids, times):
        """Set the lighting times t_l of JWL particles ``ids``."""
        st = self.a["pjwl"].to_numpy()
        st[ids, 2] = times
        self.a["pjwl"].from_numpy(st)

    def jwl_state(self):
        """Per-particle JWL state: relative volume, energy per initial volume,
        lighting time, pressure, initial volume, and the volume change of the last
        step by the elements that pushed over it (N, 6; :func:`physics.pcmm.volumes`);
        rows of non-JWL particles are unused (the Fluid equation of state uses
        columns 0, 3, 4 and 5)."""
        return self.a["pjwl"].to_numpy()[:self.n]

    def _initial_elements(self, pos, rad, pmat):
        """Eq. 5 masses and the shortest element altitude of each PCMM body, from
        its element system in the initial configuration."""
        self.masses = np.full(self.n, np.nan)
        self._crad = np.zeros(self.n)
        for s, (mat, tol) in enumerate(self.slots):
            if tol is None:
                continue
            ids = np.flatnonzero(pmat == s)
            if len(ids) == 0:
                continue
            if isinstance(mat, Fluid) and mat.voronoi:
                self._initial_cells(ids, pos, rad, mat, tol)
                continue
            es = pcmm.ElementSystem(pos[ids], rad[ids], tol).build()
            self.masses[ids] = es.masses(mat.density)
            self.capacity = max(self.capacity, 1 << int(es.neighbour_need).bit_length())
            tri = es.numpy()["triangles"]
            if len(tri):
                alt = blk.altitudes(pos[ids], tri)
                self._crit = min(self._crit, float(alt.min()) / mat.p_wave_speed)

    def _initial_cells(self, ids, pos, rad, mat, tol):
        """A Fluid body of Voronoi cells: masses ρ0 × the initial cells' areas (the
        body at zero pressure), the Eq. 1 capacity, the step bound (the smallest
        radius over the sound speed)."""
        from scipy.spatial import cKDTree
        x, r = np.ascontiguousarray(pos[ids], float), np.ascontiguousarray(rad[ids], float)
        tree = cKDTree(x)
        rc = vcells.REACH * float(r.mean())
        self._crad[ids] = rc
        pairs = tree.query_pairs(2.0 * rc, output_type="ndarray")
        cand, cnt = _symmetric_lists(len(r), pairs)
        eq1 = tree.query_pairs(2.0 * float(r.max()) + tol, output_type="ndarray")
        _, ecount = _symmetric_lists(len(r), eq1)
        self.capacity = max(self.capacity, 1 << int(ecount.max(initial=1)).bit_length())
        k = len(r)
        prop = ti.ndarray(ti.types.vector(3, ti.f64), (k,))
        prop.from_numpy(np.column_stack([r, np.zeros(k), np.zeros(k)]))
        cells = _cell_run(x, prop, np.zeros(k, np.int32), np.array([[mat.density, 1.0]]),
                          cand, cnt, self.walls, crad=np.full(k, rc))
        _check_faces(cells["faces"])
        area = cells["area"]
        self.masses[ids] = mat.density * area
        self._crit = min(self._crit, float(r.min()) / mat.p_wave_speed)

    def _alloc_cells(self):
        """The arrays of the Voronoi cells (physics.pcmm.cells); ``cap`` candidates."""
        a, n = self.a, max(self.n, 1)
        a["cmat"] = ti.ndarray(ti.i32, (n,))
        a["cmat"].from_numpy(np.resize(self.cmat, n) if self.n else np.full(1, -1, np.int32))
        nm = max(len(self.slots), 1)
        tol = np.zeros(nm)
        rad = np.asarray(self.a["rad"].to_numpy()[:self.n])
        water = self.cmat[:self.n] >= 0
        rcmax = float(self._crad[water].max())
        # the candidates' cut-off R_i + R_j + δ covers the two discs' reach 2 r_c
        tol[:] = max(2.0 * rcmax - 2.0 * float(rad[water].min()), 0.0)
        self.cell_reach_length = 2.0 * rcmax
        a["crad"] = ti.ndarray(ti.f64, (n,))
        a["crad"].from_numpy(np.resize(self._crad, n) if self.n else np.zeros(1))
        a["cmtol"] = ti.ndarray(ti.f64, (nm,))
        a["cmtol"].from_numpy(tol)
        a["crc"] = ti.ndarray(ti.f64, (n,))
        a["crmax"] = ti.ndarray(ti.f64, (1,))
        a["crmax"].fill(0.0)
        a["cpflags"] = ti.ndarray(ti.i32, (pcmm.PFLAGS_SIZE,))
        a["cpflags"].from_numpy(np.array(pcmm.PFLAGS_INIT, np.int32))
        self._cells_cap(64)
        a["carea"] = ti.ndarray(ti.f64, (n,))
        a["cpres"] = ti.ndarray(ti.f64, (n,))
        a["cpres"].fill(0.0)
        a["cq"] = ti.ndarray(ti.f64, (n,))
        a["cq"].fill(0.0)
        a["cnf"] = ti.ndarray(ti.i32, (n,))
        a["cfj"] = ti.ndarray(ti.i32, (n, vcells.MAX_FACES))
        a["cfl"] = ti.ndarray(ti.f64, (n, vcells.MAX_FACES))
        a["cfc"] = _arr(2, (n, vcells.MAX_FACES))
        a["cbnd"] = _arr(2, (n,))
        a["cflags"] = ti.ndarray(ti.i32, (1,))
        a["cflags"].fill(0)

    def _cells_cap(self, cap):
        a, n = self.a, max(self.n, 1)
        a["ccand"] = ti.ndarray(ti.i32, (n, cap))
        a["cccnt"] = ti.ndarray(ti.i32, (n,))
        a["cccnt"].fill(0)
        a["cpflags"].from_numpy(np.array(pcmm.PFLAGS_INIT, np.int32))

    def _alloc_lists(self):
        n, cap = max(self.n, 1), self.capacity
        a = self.a
        old = a.get("cand")
        a["cand"] = ti.ndarray(ti.i32, (n, cap))
        a["nbr"] = ti.ndarray(ti.i32, (n, cap))
        a["ring"] = ti.ndarray(ti.i32, (n, cap))
        a["rang"] = ti.ndarray(ti.f64, (n, cap))
        if old is not None:
            # forces a candidate build and a full element rebuild at the next step
            a["pflags"].from_numpy(np.array(pcmm.PFLAGS_INIT, np.int32))
            self._full = True

    def _setup_blocks(self):
        a = self.a
        verts, tris, tmat, mass, size = [], [], [], [], []
        off = 0
        for b in self.blocks:
            b._offset = off
            verts.append(b.vertices)
            tris.append(b.triangles + off)
            # rigid blocks carry no stress: their triangles are skipped (material −1)
            tmat.append(np.full(len(b.triangles), -1 if b.rigid else b.slot, np.int32))
            mass.append(nodal_masses(b.vertices, b.triangles, b.material.density))
            alt = blk.altitudes(b.vertices, b.triangles)
            ns = np.full(len(b.vertices), np.inf)
            for k in range(3):
                np.minimum.at(ns, b.triangles[:, k], alt)
            size.append(ns)
            step = float(alt.min()) / b.material.p_wave_speed
            if not b.kinematic() and not b.rigid:
                # a block whose every node has a prescribed velocity moves as told
                # whatever its stiffness: it does not limit the step (unless nothing does)
                self._crit = min(self._crit, step)
            else:
                self._crit_driven = min(self._crit_driven, step)
            off += len(b.vertices)
        self.nv = off
        nv, nt = max(off, 1), max(sum(len(t) for t in tris), 1)
        self.nt = sum(len(t) for t in tris)
        for k, spec in (("npos", 2), ("npos0", 2), ("nvel", 2), ("nforce", 2), ("nreact", 2),
                        ("nvfix", 2), ("nmass", 0), ("nsize", 0)):
            a[k] = _arr(spec, (nv,))
        a["nfix"] = ti.ndarray(ti.i32, (nv,))
        # the work done on each node since the start (tdem.nodes.integrate_nodes) and
        # its kinetic energy at the start
        a["nwork"] = _arr(6, (nv,))
        a["nload"] = _arr(2, (nv,))      # applied loads (Block.apply_force, apply_pressure)
        a["nmix"] = _arr(2, (nv,))       # nodal means of the mixed discretization
        a["tri"] = schema.ndarray(3, ti.i32, (nt,))
        a["tmat"] = ti.ndarray(ti.i32, (nt,))
        a["tsig"] = _arr(4, (nt,))
        a["tstate"] = _arr(4, (nt,))
        a["tfor"] = _arr(6, (nt,))
        a["nflags"] = ti.ndarray(ti.i32, (2,))
        if off == 0:
            a["inc_start"] = ti.ndarray(ti.i32, (2,))
            a["inc"] = ti.ndarray(ti.i32, (1,))
            self._setup_rigid(np.zeros(0))
            return
        x = np.concatenate(verts)
        t = np.concatenate(tris)
        a["npos"].from_numpy(x)
        a["npos0"].from_numpy(x)
        nvel = np.concatenate([b.velocity for b in self.blocks])
        a["nvel"].from_numpy(nvel)
        a["nmass"].from_numpy(np.concatenate(mass))
        work = np.zeros((off, 6))
        work[:, 5] = 0.5 * np.concatenate(mass) * np.einsum("ij,ij->i", nvel, nvel)
        a["nwork"].from_numpy(work)
        a["nsize"].from_numpy(np.concatenate(size))
        a["tri"].from_numpy(t.astype(np.int32))
        a["tmat"].from_numpy(np.concatenate(tmat))
        self._setup_rigid(np.concatenate(mass))
        start, inc = blk.incidence(t, off)
        a["inc_start"] = ti.ndarray(ti.i32, (len(start),))
        a["inc_start"].from_numpy(start)
        a["inc"] = ti.ndarray(ti.i32, (len(inc),))
        a["inc"].from_numpy(inc)
        self.apply_node_fixes(0.0, initial=True)
        self.apply_node_loads(0.0, initial=True)

    def _setup_couples(self, couples):
        """Point–edge couples: rows (point, couple) with the blocks' boundary edges,
        one law row per couple (stiffnesses resolved by the simulation). Particle
        rows ("p" arrays) and block-vertex rows ("v" arrays: both ways for a pair of
        blocks) are kept apart: their points live in different arrays."""
        self.nq = {"p": 0, "v": 0}
        self.reach = {"p": 0.0, "v": 0.0}
        rows = {"p": ([], [], [], [], [], [], []), "v": ([], [], [], [], [], [], [])}
        # each block's boundary edges are listed once per kind, whatever the number of
        # couples that reach them (the broad phase bins each edge once); ``_old_edges``
        # maps the layout of checkpoints before version 4 (the edges copied for every
        # couple) onto this one
        listed = {"p": {}, "v": {}}
        self._old_edges = {"p": [], "v": []}
        for ids, a, block, law, kn, ks in couples:
            if a is None:           # particles ids against block
                pairs = [("p", np.asarray(ids, np.int64), None, block)]
            else:                   # vertices of a against edges of block, and back
                pairs = [("v", None, a, block), ("v", None, block, a)]
            for kind, pid, src, dst in pairs:
                parts, cpl, ranges, edges, laws, rad, nbr = rows[kind]
                k = len(laws)
                be = _boundary_edges(dst.triangles) + dst._offset
                if id(dst) not in listed[kind]:
                    e0 = sum(len(x) for x in edges)
                    listed[kind][id(dst)] = e0
                    edges.append(be)
                e0 = listed[kind][id(dst)]
                self._old_edges[kind].append(np.arange(e0, e0 + len(be)))
                if kind == "p":
                    pts = pid
                    r = self._radius_of(pid)
                    nb = -np.ones((len(pid), 2), np.int64)
                else:
                    sb = _boundary_edges(src.triangles)
                    vs = np.unique(sb)
                    ln = np.linalg.norm(src.vertices[sb[:, 1]] - src.vertices[sb[:, 0]], axis=1)
                    trib = np.zeros(len(src.vertices))
                    np.add.at(trib, sb[:, 0], 0.5 * ln)
                    np.add.at(trib, sb[:, 1], 0.5 * ln)
                    pts = vs + src._offset
                    r = -trib[vs]
                    # each vertex's neighbours on its own boundary (the entrance rule)
                    prev = np.full(len(src.vertices), -1, np.int64)
                    nxt = np.full(len(src.vertices), -1, np.int64)
                    prev[sb[:, 1]] = sb[:, 0]
                    nxt[sb[:, 0]] = sb[:, 1]
                    nb = np.column_stack([prev[vs], nxt[vs]]) + src._offset
                parts.append(np.asarray(pts, np.int32))
                cpl.append(np.full(len(pts), k, np.int32))
                ranges.append((e0, e0 + len(be)))
                laws.append(law.row(kn, ks))
                rad.append(np.asarray(r, float))
                nbr.append(nb.astype(np.int32))
        a = self.a
        for kind, (parts, cpl, ranges, edges, laws, rad, nbr) in rows.items():
            n = int(sum(len(p) for p in parts))
            self.nq[kind] = n
            q = max(n, 1)
            ne = max(sum(len(e) for e in edges), 1)
            a[kind + "part"] = ti.ndarray(ti.i32, (q,))
            a[kind + "cpl"] = ti.ndarray(ti.i32, (q,))
            a[kind + "rad"] = ti.ndarray(ti.f64, (q,))
            a[kind + "range"] = ti.ndarray(ti.i32, (max(len(ranges), 1), 2))
            a[kind + "edges"] = ti.ndarray(ti.i32, (ne, 2))
            a[kind + "nbr"] = ti.ndarray(ti.i32, (q, 2))
            a[kind + "nbr"].from_numpy(-np.ones((q, 2), np.int32))
            a[kind + "law"] = ti.ndarray(ti.f64, (max(len(laws), 1), pe.LAW_WIDTH))
            a[kind + "sedge"] = ti.ndarray(ti.i32, (q, pe.SLOTS))
            a[kind + "sforce"] = _arr(2, (q, pe.SLOTS))
            a[kind + "sbroken"] = ti.ndarray(ti.i32, (q, pe.SLOTS))
            a[kind + "sedge"].from_numpy(-np.ones((q, pe.SLOTS), np.int32))
            # broad-phase grid (coupling.point_edge.bin_edges)
            a[kind + "gpar"] = ti.ndarray(ti.f64, (pe.GPAR_SIZE,))
            a[kind + "gcnt"] = ti.ndarray(ti.i32, (pe.GRID * pe.GRID,))
            # a cell holds at most every edge: with that many slots (few edges) the
            # lists never overflow and the step needs no read-back
            a[kind + "gedge"] = ti.ndarray(ti.i32, (pe.GRID * pe.GRID,
                                                    min(max(ne, 1), 256)))
            a[kind + "gneed"] = ti.ndarray(ti.i32, (1,))
            # how far from an edge a point can touch it: R of a particle, the deepest
            # crossing of a vertex (VERTEX_DEPTH × its tributary length)
            far = float(np.max(np.abs(np.concatenate(rad)))) if n else 0.0
            self.reach[kind] = far if kind == "p" else pe.VERTEX_DEPTH * far
            if n:
                a[kind + "part"].from_numpy(np.concatenate(parts))
                a[kind + "cpl"].from_numpy(np.concatenate(cpl))
                a[kind + "rad"].from_numpy(np.concatenate(rad))
                a[kind + "range"].from_numpy(np.array(ranges, np.int32))
                a[kind + "edges"].from_numpy(np.concatenate(edges).astype(np.int32))
                a[kind + "nbr"].from_numpy(np.concatenate(nbr))
                a[kind + "law"].from_numpy(np.array(laws, float))

    def edges_from_version_3(self, kind, sedge):
        """Contact slots' edge indices of a checkpoint before version 4 (the edges
        copied for every couple, in couple order) in this layout."""
        old = self._old_edges[kind]
        table = np.concatenate(old) if old else np.zeros(0, np.int64)
        sedge = np.asarray(sedge)
        out = np.where(sedge >= 0, table[np.clip(sedge, 0, max(len(table) - 1, 0))]
                       if len(table) else -1, -1)
        return out.astype(sedge.dtype)

    def _radius_of(self, ids):
        return self.a["rad"].to_numpy()[ids] if self.n else np.zeros(len(ids))

    def _setup_rigid(self, mass):
        """Rigid blocks: rows (first node, node count, mass, inertia about the centre)
        and state (centre, velocity, angle, angular velocity); their nodes are
        flagged so that the node integrator leaves them to :func:`integrate_rigid`."""
        a = self.a
        rows, state = [], []
        for b in self.blocks:
            if not b.rigid:
                continue
            if b._fixes and not b.kinematic():
                raise InputError(f"a rigid block moves as one body: fix all its nodes (a "
                                 f"driven block) or none; block {b.index} has some fixed")
            if b.kinematic():
                continue
            m = mass[b._offset:b._offset + len(b.vertices)]
            mt = float(m.sum())
            cen = (m @ b.vertices) / mt
            inertia = float(m @ np.sum((b.vertices - cen) ** 2, axis=1))
            v0 = b.velocity.mean(axis=0)
            rows.append([b._offset, len(b.vertices), mt, inertia])
            state.append([cen[0], cen[1], v0[0], v0[1], 0.0, 0.0])
        self.nrigid = len(rows)
        a["rbody"] = ti.ndarray(ti.f64, (max(len(rows), 1), 4))
        a["rstate"] = ti.ndarray(ti.f64, (max(len(rows), 1), 6))
        # the work of the nodal forces, gravity and damping since the start, and the
        # kinetic energy at the start (tdem.nodes.integrate_rigid)
        a["rwork"] = ti.ndarray(ti.f64, (max(len(rows), 1), 5))
        a["rref"] = _arr(2, (max(self.nv, 1),))
        if rows:
            a["rbody"].from_numpy(np.array(rows, float))
            a["rstate"].from_numpy(np.array(state, float))
            work = np.zeros((len(rows), 5))
            nwork = a["nwork"].to_numpy()
            for q, (r, st) in enumerate(zip(rows, state)):
                work[q, 4] = 0.5 * r[2] * (st[2] ** 2 + st[3] ** 2) + 0.5 * r[3] * st[5] ** 2
                nwork[int(r[0]):int(r[0]) + int(r[1]), 5] = 0.0   # counted with the body
            a["rwork"].from_numpy(work)
            a["nwork"].from_numpy(nwork)
            ref = np.zeros((self.nv, 2))
            for r, s in zip(rows, state):
                o, k = int(r[0]), int(r[1])
                x = np.concatenate([bb.vertices for bb in self.blocks])[o:o + k]
                ref[o:o + k] = x - np.array(s[:2])
            a["rref"].from_numpy(ref)

    def upload_materials(self):
        rows = np.zeros((max(len(self.slots), 1), MAT_WIDTH))
        tol = np.zeros(max(len(self.slots), 1))
        for s, (mat, t) in enumerate(self.slots):
            rows[s] = mat.row()
            tol[s] = 0.0 if t is None else t
        self.a["matp"].from_numpy(rows)
        self.a["mtol"].from_numpy(tol)
        if self._tol is not None and not np.array_equal(tol, self._tol):
            self._full = True        # the Eq. 1 cut-offs changed: rebuild every element
        self._tol = tol

    def apply_node_fixes(self, t, initial=False):
        """Upload prescribed node velocities (all, or the functions of time at t)."""
        if self.nv == 0:
            return False
        if initial:
            self._nfix = np.zeros(self.nv, np.int32)
            self._nvfix = np.zeros((self.nv, 2))
        any_fn = False
        for b in self.blocks:
            for ids, vx, vy in b._fixes:
                g = ids + b._offset
                for bit, col, v in ((FIX_VX, 0, vx), (FIX_VY, 1, vy)):
                    if v is None:
                        continue
                    if initial:
                        self._nfix[g] |= bit
                    if callable(v):
                        any_fn = True
                        self._nvfix[g, col] = np.broadcast_to(np.asarray(v(t), float), g.shape)
                    elif initial:
                        self._nvfix[g, col] = v
        if initial:
            for b in self.blocks:
                if b.rigid and not b.kinematic():
                    self._nfix[b._offset:b._offset + len(b.vertices)] |= RIGID_NODE
            self.a["nfix"].from_numpy(self._nfix)
            self._fix_fn = any_fn
        self.a["nvfix"].from_numpy(self._nvfix)
        return any_fn

    def apply_node_loads(self, t, initial=False):
        """Upload the blocks' applied loads (Block.apply_force, apply_pressure) at time
        t; returns whether some are functions of time (then uploaded every step)."""
        if self.nv == 0:
            return False
        load = np.zeros((self.nv, 2))
        any_fn = False
        for b in self.blocks:
            for ids, *vals in b._loads:
                g = ids + b._offset
                for col, v in enumerate(vals):
                    if v is None:
                        continue
                    if callable(v):
                        any_fn = True
                        v = np.broadcast_to(np.asarray(v(t), float), g.shape)
                    load[g, col] += v
        self.a["nload"].from_numpy(load)
        if initial:
            self._load_fn = any_fn
        return any_fn

    # ------------------------------------------------------------------ stepping
    def critical_dt(self):
        """Shortest element altitude / c_p over the initial PCMM elements and the
        block triangles (the Courant step of the element model)."""
        if math.isinf(self._crit):
            return self._crit_driven
        return self._crit

    # ---------------------------------------------------- the stages of one step
    # (the order is in Simulation._one_step; each stage owns what it writes)
    def prescribed(self, sim):
        """Stage: node velocities and loads given by functions of time, uploaded."""
        if self._fix_fn_nodes():
            self.apply_node_fixes(sim._time)
        if self.nv and self._load_fn:
            self.apply_node_loads(sim._time)

    def pcmm_elements(self, sim, dt, reach):
        """Stage: PCMM candidates (after a list build) and the element update, forces
        into ``xforce`` (physics.pcmm)."""
        if not self.has_pcmm:
            return
        a, e = self.a, sim._a
        pcmm.candidates(e["pos"], a["rrule"], a["rcand"], a["rmax"], a["pmat"], a["mtol"],
                        a["cand"], a["ccnt"],
                        e["cell_count"], e["cell_start"], e["sorted"], e["gridp"],
                        e["gridn"], e["flags"], a["pflags"], F_BUILDS,
                        float(sim.skin), int(reach))
        # everything is rebuilt at the first two steps (cskip's first-step marks
        # go at the second) and after a restore
        pcmm.update(a, e, float(dt), float(sim._time), int(sim.steps == 0),
                    self._full or sim.steps <= 1, self.carry_stress, self.eos, sim._serial(),
                    self.mixed)
        self._full = False

    def cell_pressure(self, sim, reach):
        """Stage, after the PCMM update (which gave the cell particles their core
        forces and pair marks): the Voronoi cells' candidates (only after a list
        build), areas, pressures and forces, added to ``xforce``
        (physics.pcmm.cells)."""
        if not self.has_cells:
            return
        a, e = self.a, sim._a
        serial = sim._serial()
        # (a particle with more candidates than slots keeps the first ones; status()
        # finds it at the end of the run segment, which is then run again with more)
        pcmm.candidates(e["pos"], a["rad"], a["crc"], a["crmax"], a["cmat"], a["cmtol"],
                        a["ccand"], a["cccnt"], e["cell_count"], e["cell_start"],
                        e["sorted"], e["gridp"], e["gridn"], e["flags"], a["cpflags"],
                        F_BUILDS, float(sim.skin), int(reach))
        walls = e.get("wall")
        nw = len(sim._walls_host)
        if walls is None or nw == 0:
            walls = a.get("cnowall")
            if walls is None:
                walls = a["cnowall"] = ti.ndarray(ti.f64, (1, 4))
            nw = 0
        vcells.cells(e["pos"], e["vel"], e["prop"], a["cmat"], a["crad"], a["matp"], a["ccand"],
                     a["cccnt"], walls, nw, a["carea"], a["cpres"], a["cq"], a["cnf"], a["cfj"],
                     a["cfl"], a["cfc"], a["cbnd"], a["cflags"], serial)
        vcells.cell_forces(e["pos"], e["vel"], a["cmat"], a["matp"], a["ccand"], a["cccnt"],
                           a["cpres"], a["cq"], a["cnf"], a["cfj"], a["cfl"], a["cfc"],
                           a["cbnd"], a["xforce"], a["psig"], serial)

    def cell_state(self):
        """The Voronoi cells now: area (N,), pressure (N,), body slot (N,; −1 for
        particles of no such body); zeros when there are none."""
        if not self.has_cells:
            z = np.zeros(self.n)
            return {"area": z, "pressure": z, "cmat": np.full(self.n, -1)}
        a = self.a
        return {"area": a["carea"].to_numpy()[:self.n], "pressure": a["cpres"].to_numpy()[:self.n],
                "cmat": self.cmat[:self.n].copy()}

    def eos_volumes(self, sim, dt):
        """Stage, after the particles moved: each particle with an equation of state
        keeps the volume change of the step by the elements that pushed over it
        (physics.pcmm.volumes), for the next step's update."""
        if self.has_pcmm and self.eos:
            pcmm.volumes(self.a, sim._a, float(dt), sim._serial())
            if self.swells:
                a, e = self.a, sim._a
                pcmm.swell(a["pmat"], a["matp"], a["rad"], a["rrule"], a["rcand"], a["rmax"],
                           a["mtol"], a["pjwl"], a["cand"], a["ccnt"], a["pbud"], e["pos"], e["xref"],
                           e["flags"], float(sim.skin), sim._serial())

    @property
    def swells(self):
        """Whether a JWL body of this model swells (:class:`physics.materials.JWL`)."""
        return any(isinstance(m, JWL) and m.swelling for m, _ in self.slots)

    def block_stresses(self, sim, dt):
        """Stage: block triangles' stresses and their nodal forces into ``nforce``."""
        if not self.nv:
            return
        a = self.a
        blk.update(a["npos"], a["nvel"], a["tri"], a["tmat"], a["matp"], a["tsig"],
                   a["tstate"], a["tfor"], a["inc_start"], a["inc"], a["nmix"],
                   a["nforce"], float(dt), self.mixed, sim._serial())

    def point_edge(self, sim, dt):
        """Stage: particle–block and block–block point–edge contacts (coupling/),
        forces into ``xforce`` and ``nforce``."""
        a, e = self.a, sim._a
        if self.nq["p"]:
            if not self.has_pcmm:
                a["xforce"].fill(0.0)
            self._bin_edges("p", sim._serial())
            pe.point_edge(e["pos"], e["vel"], a["prad"], a["npos"], a["nvel"], a["ppart"],
                          a["pcpl"], a["prange"], a["pedges"], a["pnbr"], a["plaw"], a["psedge"],
                          a["psforce"], a["psbroken"], a["xforce"], a["nforce"],
                          a["pgpar"], a["pgcnt"], a["pgedge"], float(dt), sim._serial())
        if self.nq["v"]:
            self._bin_edges("v", sim._serial())
            pe.point_edge(a["npos"], a["nvel"], a["vrad"], a["npos"], a["nvel"], a["vpart"],
                          a["vcpl"], a["vrange"], a["vedges"], a["vnbr"], a["vlaw"], a["vsedge"],
                          a["vsforce"], a["vsbroken"], a["nforce"], a["nforce"],
                          a["vgpar"], a["vgcnt"], a["vgedge"], float(dt), sim._serial())

    def viscous_boundaries(self, sim):
        """Stage: non-reflecting (viscous) boundary tractions into the same forces."""
        a, e = self.a, sim._a
        for kind, vel, force in (("p", e.get("vel"), a["xforce"]), ("v", a["nvel"], a["nforce"])):
            nr = self.nr.get(kind, 0)
            if nr:
                if kind == "p" and not self.has_pcmm and not self.nq["p"]:
                    a["xforce"].fill(0.0)
                viscous_boundary(vel, force, a["nr" + kind + "ids"], a["nr" + kind + "coef"])

    def _bin_edges(self, kind, serial):
        """The broad-phase grid of the edges of ``kind``'s couples, its cell lists
        grown until every cell's edges fit (``serial``: the loops on one thread)."""
        a = self.a
        r = self.reach[kind]
        while True:
            pe.bin_edges(a["npos"], a[kind + "edges"], r, 2.0 * r,
                         pe.VERTEX_END if kind == "v" else 0.0, a[kind + "gpar"],
                         a[kind + "gcnt"], a[kind + "gedge"], a[kind + "gneed"], serial)
            cap = a[kind + "gedge"].shape[1]
            if cap >= a[kind + "edges"].shape[0]:
                return
            need = int(a[kind + "gneed"].to_numpy()[0])
            if need <= cap:
                return
            a[kind + "gedge"] = ti.ndarray(ti.i32, (pe.GRID * pe.GRID,
                                                    1 << int(need).bit_length()))

    def set_non_reflecting(self, kind, ids, coef):
        """Rows of the viscous boundary: ``kind`` "p" (particles) or "v" (block nodes)."""
        self.nr = getattr(self, "nr", {})
        a = self.a
        old_ids = a[f"nr{kind}ids"].to_numpy() if self.nr.get(kind) else np.zeros(0, np.int32)
        old_coef = a[f"nr{kind}coef"].to_numpy() if self.nr.get(kind) else np.zeros((0, 4))
        ids = np.concatenate([old_ids, np.asarray(ids, np.int32)])
        coef = np.concatenate([old_coef, np.asarray(coef, float)])
        a[f"nr{kind}ids"] = ti.ndarray(ti.i32, (len(ids),))
        a[f"nr{kind}ids"].from_numpy(ids.astype(np.int32))
        a[f"nr{kind}coef"] = ti.ndarray(ti.f64, (len(ids), 4))
        a[f"nr{kind}coef"].from_numpy(coef)
        self.nr[kind] = len(ids)

    @property
    def adds_forces(self):
        """Whether the particles get forces from here (elements, point–edge contacts,
        viscous boundaries)."""
        return self.has_pcmm or self.nq["p"] > 0 or getattr(self, "nr", {}).get("p", 0) > 0

    def _fix_fn_nodes(self):
        return self.nv and self._fix_fn

    def integrate(self, sim):
        """Stage: block nodes and rigid blocks move (tdem.nodes)."""
        if self.nv:
            a = self.a
            if self.nrigid:
                integrate_rigid(a["npos"], a["nvel"], a["nforce"], a["nmass"], a["rbody"],
                                a["rstate"], a["rref"], a["rwork"], a["nload"],
                                sim._a["simp"])
            integrate_nodes(a["npos"], a["nvel"], a["nmass"], a["nforce"], a["nfix"],
                            a["nvfix"], a["nsize"], a["nreact"], a["nwork"], a["nload"],
                            sim._a["simp"], a["nflags"], sim._serial())

    def status(self):
        """(candidate slots needed, first unstable node or −1)."""
        flags = self.a["pflags"].to_numpy()
        if flags[pcmm.P_INC] > pcmm.MAX_INCIDENT:
            raise CapacityError(f"a PCMM particle belongs to {int(flags[pcmm.P_INC])} elements, "
                                f"more than {pcmm.MAX_INCIDENT}: is the tolerance far larger "
                                "than the radii?")
        need = int(flags[pcmm.P_NEED]) if self.has_pcmm else 0
        if self.has_cells:
            self._cells_need = int(self.a["cpflags"].to_numpy()[pcmm.P_NEED])
            _check_faces(int(self.a["cflags"].to_numpy()[0]))
        bad = -1
        if self.nv:
            b = int(self.a["nflags"].to_numpy()[0])
            bad = b if b < self.nv else -1
        return need, bad

    def short(self, need):
        """Whether the last run segment lacked candidate slots: PCMM's (``need``, from
        :meth:`status`) or the water cells'."""
        return need > self.capacity or (
            self.has_cells and self._cells_need > self.a["ccand"].shape[1])

    def grow(self, need):
        """More candidate slots where :meth:`short` found too few (the segment is run
        again)."""
        if need > self.capacity:
            new = 1 << int(need).bit_length()
            if new > MAX_CANDIDATES:
                raise CapacityError(f"a PCMM particle has {need} Eq. 1 candidates, more than "
                                    f"{MAX_CANDIDATES}: is the tolerance far larger than the "
                                    "radii?")
            self.capacity = new
            self._alloc_lists()
            self.snap.pop("cand", None)
        if self.has_cells and self._cells_need > self.a["ccand"].shape[1]:
            if self._cells_need > MAX_CANDIDATES:
                raise CapacityError(f"a water particle has {self._cells_need} cell candidates, "
                                    f"more than {MAX_CANDIDATES}: are its radii far apart?")
            self._cells_cap(1 << int(self._cells_need).bit_length())

    def sync_copies(self):
        """Bring every slot's element stress (``esig``) up to date from the last stress
        pass (kept lazily on the device, see :func:`physics.pcmm.copies`), before the
        element stresses are read or saved."""
        if self.has_pcmm:
            pcmm.sync_copies(self.a["ecnt"], self.a["emult"], self.a["ecopy"], self.a["esig"],
                             self.a["sigc"], self.a["eidx"])

    def take_snapshot(self):
        self.sync_copies()
        for k in _SNAP:
            src = self.a[k]
            dst = self.snap.get(k)
            if dst is None or tuple(dst.shape) != tuple(src.shape):
                dst = self.snap[k] = (schema.ndarray(src.n, src.dtype, tuple(src.shape))
                                      if hasattr(src, "n") else
                                      ti.ndarray(src.dtype, tuple(src.shape)))
            if k not in _SNAP_PARTICLES:
                dst.copy_from(src)
        for k in _SNAP_CELLS if self.has_cells else ():
            src = self.a[k]
            dst = self.snap.get(k)
            if dst is None or tuple(dst.shape) != tuple(src.shape):
                dst = self.snap[k] = ti.ndarray(src.dtype, tuple(src.shape))
            dst.copy_from(src)
        serial = backend.serial_loops(self.n, True)
        copy_particles(*[self.a[k] for k in _SNAP_PARTICLES],
                       *[self.snap[k] for k in _SNAP_PARTICLES], serial)

    def restore_snapshot(self):
        whole = all(self.snap.get(k) is not None and
                    tuple(self.snap[k].shape) == tuple(self.a[k].shape) for k in _SNAP_PARTICLES)
        for k in _SNAP:
            dst = self.a[k]
            src = self.snap.get(k)
            if src is not None and tuple(src.shape) == tuple(dst.shape) and not (
                    whole and k in _SNAP_PARTICLES):
                dst.copy_from(src)
        if whole:
            serial = backend.serial_loops(self.n, True)
            copy_particles(*[self.snap[k] for k in _SNAP_PARTICLES],
                           *[self.a[k] for k in _SNAP_PARTICLES], serial)
        if self.snap.get("cand") is None:
            self.a["pflags"].from_numpy(np.array(pcmm.PFLAGS_INIT, np.int32))
        if self.has_cells:
            if all(self.snap.get(k) is not None and tuple(self.snap[k].shape) ==
                   tuple(self.a[k].shape) for k in _SNAP_CELLS):
                for k in _SNAP_CELLS:
                    self.a[k].copy_from(self.snap[k])
            else:       # (grown since: found again)
                self.a["cpflags"].from_numpy(np.array(pcmm.PFLAGS_INIT, np.int32))
        # the map of copies belongs to the elements before the restore: every restored
        # slot holds its own (synced) stress until the next step maps them again
        self.a["emult"].fill(1)
        self.a["eidx"].fill(-1)
        self._full = True

    # ------------------------------------------------------------------ reading
    def _slots_of_elements(self):
        """(owner, slot, inv, src) of every element slot: ``inv`` the triangle each
        slot holds (copies of a triangle share it), ``src`` the slot whose element is
        computed (the copy with ``emult`` > 0), per triangle."""
        a = self.a
        ecnt = a["ecnt"].to_numpy()
        owner = np.repeat(np.arange(self.n), ecnt)
        slot = np.arange(len(owner)) - np.repeat(np.cumsum(ecnt) - ecnt, ecnt)
        elem = a["elem"].to_numpy()[owner, slot]
        mult = a["emult"].to_numpy()[owner, slot]
        key = np.sort(np.column_stack([owner, elem]), axis=1)
        _, first, inv = np.unique(key, axis=0, return_index=True, return_inverse=True)
        inv = inv.ravel()
        comp = np.flatnonzero(mult > 0)
        src = np.empty(len(first), np.int64)
        src[inv[comp]] = comp
        return owner, slot, elem, inv, src

    def synced_cover(self):
        """N_e of every element slot, copies given their computed copy's (what a
        checkpoint saves: a loaded model, whose copies are not mapped yet, reads it
        from any copy)."""
        owner, slot, _, inv, src = self._slots_of_elements()
        ncov = self.a["ncov"].to_numpy()
        ncov[owner, slot] = ncov[owner, slot][src[inv]]
        return ncov

    def elements(self):
        """PCMM elements now (copies included): triangles (E, 3), owner, area, n_cover,
        weight (1/N_e), stress (E, 2, 2), stress_zz (E,)."""
        a = self.a
        self.sync_copies()
        owner, slot, elem, inv, src = self._slots_of_elements()
        ncov = a["ncov"].to_numpy()[owner, slot]
        sig = a["esig"].to_numpy()[owner, slot]
        # copies of a triangle are computed once (the copy with emult > 0): fill the others
        ncov = ncov[src[inv]]
        sig = sig[src[inv]]
        return {"triangles": np.column_stack([owner, elem]).astype(np.int64),
                "owner": owner.astype(np.int64),
                "area": a["earea"].to_numpy()[owner, slot],
                "n_cover": ncov.astype(np.int64),
                "weight": 1.0 / np.maximum(ncov, 1),
                "stress": _tensor(sig), "stress_zz": sig[:, 3].copy()}

    def strain_energy(self):
        """Elastic strain energy (J/m) stored in the PCMM elements and the blocks'
        triangles: Σ w A (p²/2K + s:s/4G) over the elements, with the stress's mean p
        and deviator s (σ_zz included, plane strain), the element's area A and, for
        PCMM elements, their weight w = 1/N_e (as in their nodal forces). This is
        ½ σ:ε for the elastic part of the strain; JWL products keep theirs as internal
        energy (``energy()["explosive"]``), a Fluid (G = 0) only its pressure part.
        Rigid blocks store none."""
        total = 0.0
        rows = np.array([m.row() for m, _ in self.slots]) if self.slots else np.zeros((0, MAT_WIDTH))
        if self.has_pcmm:
            e = self.elements()
            if len(e["owner"]):
                mat = self.a["pmat"].to_numpy()[e["owner"]]
                total += _stored(e["stress"], e["stress_zz"], rows[mat], e["area"] * e["weight"])
        if self.has_cells:
            # Σ A0 K (V − 1 − ln V) over the compressed cells (physics.pcmm.cells)
            c = self.cell_state()
            sel = np.flatnonzero(c["cmat"] >= 0)
            if len(sel):
                a0 = self.masses[sel] / rows[c["cmat"][sel], MAT_RHO]
                v = c["area"][sel] / a0
                k = rows[c["cmat"][sel], MAT_K]
                total += float(np.sum(np.where(v < 1.0, a0 * k * (v - 1.0 - np.log(
                    np.minimum(v, 1.0))), 0.0)))
        if self.nt:
            x = self.a["npos"].to_numpy()
            for b in self.blocks:
                if b.rigid:
                    continue
                el = self.block_elements(b)
                t = b.triangles + b._offset
                d1, d2 = x[t[:, 1]] - x[t[:, 0]], x[t[:, 2]] - x[t[:, 0]]
                area = 0.5 * np.abs(d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0])
                row = np.broadcast_to(np.asarray(b.material.row(), float), (len(t), MAT_WIDTH))
                total += _stored(el["stress"], el["stress_zz"], row, area)
        return total

    def core_energy(self, pos):
        """Potential energy (J/m) of the core force between same-body Fluid or JWL
        neighbours (:func:`physics.pcmm.fluid_core_force`): Σ ½ K (λ(R_i + R_j) −
        d)² over the Eq. 1 pairs closer than λ(R_i + R_j), each pair once; ``pos``
        the particles' positions. It is zero unless two such particles overlap by a
        quarter of their radii (a detonation's products thrown back from a wall)."""
        if not self.has_pcmm:
            return 0.0
        slots = [s for s, (m, _) in enumerate(self.slots) if isinstance(m, (Fluid, JWL))]
        if not slots:
            return 0.0
        pmat = self.a["pmat"].to_numpy()[:self.n]
        ncnt = self.a["ncnt"].to_numpy()[:self.n]
        nbr = self.a["nbr"].to_numpy()[:self.n]
        rad = self.a["rad"].to_numpy()[:self.n]
        ii = np.flatnonzero(np.isin(pmat, slots) & (ncnt > 0))
        if not len(ii):
            return 0.0
        cols = np.arange(nbr.shape[1])
        keep = cols[None, :] < ncnt[ii, None]
        i = np.broadcast_to(ii[:, None], keep.shape)[keep]
        j = nbr[ii][keep]
        i, j = i[j > i], j[j > i]
        dc = pcmm.FLUID_CORE * (rad[i] + rad[j])
        gap = np.maximum(dc - np.linalg.norm(pos[j] - pos[i], axis=1), 0.0)
        k = np.array([m.bulk if isinstance(m, (Fluid, JWL)) else 0.0 for m, _ in self.slots])
        return float(np.sum(0.5 * k[pmat[i]] * gap * gap))

    def restart_work(self):
        """The work account of the nodes and rigid blocks starts now (zero work, the
        kinetic energy now as the start's)."""
        a = self.a
        v = a["nvel"].to_numpy()
        nw = np.zeros((len(v), 6))
        free = (a["nfix"].to_numpy() & RIGID_NODE) == 0
        nw[:, 5] = np.where(free, 0.5 * a["nmass"].to_numpy() * np.einsum("ij,ij->i", v, v), 0.0)
        a["nwork"].from_numpy(nw)
        if self.nrigid:
            st = a["rstate"].to_numpy()
            body = a["rbody"].to_numpy()
            rw = np.zeros(a["rwork"].shape)
            rw[:, 4] = 0.5 * body[:, 2] * (st[:, 2] ** 2 + st[:, 3] ** 2) \
                + 0.5 * body[:, 3] * st[:, 5] ** 2
            a["rwork"].from_numpy(rw)

    def work_sums(self):
        """(work of the nodal forces, gravity, damping, constraints and loads on the
        block nodes and rigid blocks since the start (J/m), their kinetic energy
        ½ m v² now at the half step, and at the start)."""
        w = np.zeros(5)
        ke = ke0 = 0.0
        if self.nv:
            a = self.a
            nw = a["nwork"].to_numpy()
            free = (a["nfix"].to_numpy() & RIGID_NODE) == 0
            v = a["nvel"].to_numpy()[free]
            w += nw[:, :5].sum(axis=0)
            ke += 0.5 * float(a["nmass"].to_numpy()[free] @ np.einsum("ij,ij->i", v, v))
            ke0 += float(nw[:, 5].sum())
            if self.nrigid:
                rw = a["rwork"].to_numpy()[:self.nrigid]
                st = a["rstate"].to_numpy()[:self.nrigid]
                body = a["rbody"].to_numpy()[:self.nrigid]
                w[:3] += rw[:, :3].sum(axis=0)
                w[4] += rw[:, 3].sum()
                ke += float(np.sum(0.5 * body[:, 2] * (st[:, 2] ** 2 + st[:, 3] ** 2)
                                   + 0.5 * body[:, 3] * st[:, 5] ** 2))
                ke0 += float(rw[:, 4].sum())
        return w, ke, ke0

    def particle_fields(self):
        """Continuum state per particle: stress (N, 4), strain (N, 3), plastic shear
        strain, failed, element count."""
        a = self.a
        st = a["pstate"].to_numpy()
        return {"stress4": a["psig"].to_numpy(), "strain": a["peps"].to_numpy(),
                "plastic_strain": st[:, 0].copy(), "failed": st[:, 1] > 0.5,
                "elements": st[:, 2].astype(np.int64), "pmat": a["pmat"].to_numpy()}

    def point_edge_contacts(self, pos):
        """Point–edge contacts now: point (C, 2) (particle centre or vertex), foot (C, 2)
        (its projection on the edge), normal (C,) F_n compression-positive, shear (C,),
        broken (C,) bool, kind (C,) 0 particle–block, 1 vertex–edge. ``pos``: the
        particles' positions."""
        a = self.a
        npos = a["npos"].to_numpy()
        out = {k: [] for k in ("point", "foot", "normal", "shear", "broken", "kind")}
        for kind, src in (("p", pos), ("v", npos)):
            if not self.nq[kind]:
                continue
            se = a[kind + "sedge"].to_numpy()
            sf = a[kind + "sforce"].to_numpy()
            sb = a[kind + "sbroken"].to_numpy()
            part = a[kind + "part"].to_numpy()
            edges = a[kind + "edges"].to_numpy()
            q, k = np.nonzero(se >= 0)
            x = src[part[q]]
            xi, xj = npos[edges[se[q, k], 0]], npos[edges[se[q, k], 1]]
            t = xj - xi
            s = np.einsum("ij,ij->i", x - xi, t) / np.einsum("ij,ij->i", t, t)
            out["point"].append(x)
            out["foot"].append(xi + s[:, None] * t)
            out["normal"].append(sf[q, k, 0])
            out["shear"].append(sf[q, k, 1])
            out["broken"].append(sb[q, k] > 0)
            out["kind"].append(np.full(len(q), 0 if kind == "p" else 1))
        empty = {"point": np.zeros((0, 2)), "foot": np.zeros((0, 2)), "normal": np.zeros(0),
                 "shear": np.zeros(0), "broken": np.zeros(0, bool), "kind": np.zeros(0, int)}
        return {k: (np.concatenate(v) if v else empty[k]) for k, v in out.items()}

    def block_nodes(self, b):
        a = self.a
        sl = slice(b._offset, b._offset + len(b.vertices))
        pos = a["npos"].to_numpy()[sl]
        return {"position": pos, "velocity": a["nvel"].to_numpy()[sl],
                "force": a["nforce"].to_numpy()[sl], "reaction": a["nreact"].to_numpy()[sl],
                "mass": a["nmass"].to_numpy()[sl],
                "displacement": pos - a["npos0"].to_numpy()[sl]}

    def block_elements(self, b):
        a = self.a
        first = sum(len(o.triangles) for o in self.blocks[:self.blocks.index(b)])
        sl = slice(first, first + len(b.triangles))
        sig = a["tsig"].to_numpy()[sl]
        st = a["tstate"].to_numpy()[sl]
        return {"triangles": b.triangles.copy(), "stress": _tensor(sig),
                "stress_zz": sig[:, 3].copy(), "plastic_strain": st[:, 0].copy(),
                "failed": st[:, 1] > 0.5}


def _boundary_edges(triangles):
    from .mesh import boundary_edges
    return boundary_edges(triangles)


def _stored(sig, szz, rows, weight):
    """Σ weight · (p²/2K + s:s/4G) of stresses (E, 2, 2) and σ_zz (E,) with material rows
    (E, MAT_WIDTH); JWL rows count nothing, G = 0 rows their pressure part only."""
    k, g, kind = rows[:, MAT_K], rows[:, MAT_G], rows[:, MAT_TYPE]
    p = (sig[:, 0, 0] + sig[:, 1, 1] + szz) / 3.0
    ss = ((sig[:, 0, 0] - p) ** 2 + (sig[:, 1, 1] - p) ** 2 + (szz - p) ** 2
          + 2.0 * sig[:, 0, 1] ** 2)
    w = np.where(k > 0, p * p / (2.0 * np.where(k > 0, k, 1.0)), 0.0) \
        + np.where(g > 0, ss / (4.0 * np.where(g > 0, g, 1.0)), 0.0)
    w = np.where(kind == JWL_TYPE, 0.0, w)
    return float(np.sum(weight * w))


def _tensor(s4):
    out = np.zeros((len(s4), 2, 2))
    out[:, 0, 0], out[:, 1, 1] = s4[:, 0], s4[:, 1]
    out[:, 0, 1] = out[:, 1, 0] = s4[:, 2]
    return out


def _symmetric_lists(n, pairs):
    """Each index's partners (N, cap; −1 padded) and their count from a pair list."""
    a = np.concatenate([pairs[:, 0], pairs[:, 1]]).astype(np.int64)
    b = np.concatenate([pairs[:, 1], pairs[:, 0]]).astype(np.int64)
    o = np.argsort(a, kind="stable")
    a, b = a[o], b[o]
    cnt = np.bincount(a, minlength=n)
    start = np.cumsum(cnt) - cnt
    lists = np.full((n, max(int(cnt.max(initial=0)), 1)), -1, np.int32)
    lists[a, np.arange(len(a)) - start[a]] = b
    return lists, cnt.astype(np.int32)


def _cell_run(pos, prop, cmat, matp_rows, cand, cnt, walls, vel=None, crad=None):
    """The cells of particles ``pos`` (one body, candidates ``cand``; ``matp_rows``
    (ρ0, K, b1) per body, ``vel`` their velocities, default at rest; ``crad`` their
    discs' radii, default REACH × the mean radius) with the kernel
    of the step (the set-up's, before the engine's arrays exist): area, pressure and
    bulk viscosity per particle."""
    from physics.materials import MAT_B1
    n = len(pos)
    A = {}
    A["pos"] = _arr(2, (n,))
    A["pos"].from_numpy(pos)
    A["vel"] = _arr(2, (n,))
    A["vel"].from_numpy(np.zeros((n, 2)) if vel is None else np.asarray(vel, float))
    A["cmat"] = ti.ndarray(ti.i32, (n,))
    A["cmat"].from_numpy(cmat)
    A["crad"] = ti.ndarray(ti.f64, (n,))
    if crad is None:
        crad = np.full(n, vcells.REACH * float(np.mean(prop.to_numpy()[:, 0])))
    A["crad"].from_numpy(np.asarray(crad, float))
    mr = np.atleast_2d(np.asarray(matp_rows, float))
    rows = np.zeros((len(mr), MAT_WIDTH))
    rows[:, MAT_RHO] = mr[:, 0]
    rows[:, MAT_K] = mr[:, 1]
    if mr.shape[1] > 2:
        rows[:, MAT_B1] = mr[:, 2]
    A["matp"] = ti.ndarray(ti.f64, rows.shape)
    A["matp"].from_numpy(rows)
    A["cand"] = ti.ndarray(ti.i32, cand.shape)
    A["cand"].from_numpy(cand)
    A["cnt"] = ti.ndarray(ti.i32, (n,))
    A["cnt"].from_numpy(cnt)
    w = np.zeros((max(len(walls), 1), 4))
    w[:len(walls)] = walls
    A["wall"] = ti.ndarray(ti.f64, w.shape)
    A["wall"].from_numpy(w)
    out = {k: ti.ndarray(ti.f64, (n,)) for k in ("area", "pres", "q")}
    nf = ti.ndarray(ti.i32, (n,))
    fj = ti.ndarray(ti.i32, (n, vcells.MAX_FACES))
    fl = ti.ndarray(ti.f64, (n, vcells.MAX_FACES))
    fc = _arr(2, (n, vcells.MAX_FACES))
    bnd = _arr(2, (n,))
    flags = ti.ndarray(ti.i32, (1,))
    flags.fill(0)
    vcells.cells(A["pos"], A["vel"], prop, A["cmat"], A["crad"], A["matp"], A["cand"], A["cnt"],
                 A["wall"], len(walls), out["area"], out["pres"], out["q"], nf, fj, fl, fc,
                 bnd, flags, False)
    return {**{k: v.to_numpy() for k, v in out.items()}, "faces": int(flags.to_numpy()[0])}


def _check_faces(faces):
    """A Voronoi cell with more faces than its slots hold is an error."""
    if faces > vcells.MAX_FACES:
        raise CapacityError(f"a water particle's Voronoi cell has {faces} faces, more than "
                            f"{vcells.MAX_FACES}: are its neighbours' radii far smaller than "
                            "its own?")
