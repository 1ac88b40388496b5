"""Water whose pressure comes from each particle's Voronoi cell
(:class:`physics.materials.Fluid` with ``voronoi=True``).

The particles of such a body make no elements. Each one owns the part of the plane
nearer to it than to any other particle of its body (its Voronoi cell), cut off by
the tank's walls and by a disc of radius r_c = ``REACH`` × the mean radius of the
body's particles about its centre (which closes the cells of the free surface; one
radius for the whole body, so that in a polydisperse packing the small particles'
cells close the pores between the large ones as well). With A_i the cell's area
and A0_i = m_i/ρ0 its area at zero pressure (the cells of the initial packing: the
masses are ρ0 A0),

    p_i = K · max(A0_i/A_i − 1, 0),

the pressure of the equation of state p = K(1/V − 1) with V = A_i/A0_i, and no
tension. The forces are the exact gradient of the stored energy
Σ_i A0_i K (V_i − 1 − ln V_i) (V_i < 1):

    F_i = Σ_k p_k ∂A_k/∂x_i,
    ∂A_i/∂x_j = −(l_ij/d_ij)(c_ij − x_j)    (j ≠ i, a neighbour across face ij),
    ∂A_i/∂x_i = Σ_j (l_ij/d_ij)(c_ij − x_i) + Σ_arcs l n,

with l_ij, c_ij the length and midpoint of the face between the two cells, d_ij
the distance of the centres, and the last sum over the edges of the bounding disc
(which moves with the particle; outward normal n). So:

- a uniform pressure pushes no particle whose cell the neighbours close (the faces
  of a closed cell sum to zero), on any packing;
- a linear pressure field pushes particle i with −∇p·A_i exactly (the faces' moment
  Σ l n ⊗ (c − x_i) of a closed cell is A_i·I): the hydrostatic state with m_i = ρ
  A_i is an equilibrium of any packing, lattice or random;
- the cells and their areas change continuously as particles move past each
  other (a face appears or goes with zero length), so nothing jumps when the
  neighbourhood of a particle changes, as element deletion and creation do;
- momentum is kept: the energy does not change when every particle moves alike
  (where walls cut the cells, the sum of the forces is the push the walls' faces
  would take, and the walls give it back through the contact law).

The walls (the engine's segment walls, within the disc's reach) cut the cells and
carry no derivative: the particles are held off them by the contact law, which
takes the pressure the wall receives. A viscosity μ adds the force
μ Σ_j (l_ij/d_ij)(v_j − v_i) (the Voronoi Laplacian of the velocity; pairwise,
momentum-conserving, dissipative), and a shrinking cell the artificial bulk
viscosity of the elements (:func:`cells`). Same-body neighbours meet through no contact
law (:func:`physics.pcmm.nodal.gather` marks their pair slots and adds the
:func:`fluid_core_force`).

Cost: a cell is a polygon of at most MAX_VERTS vertices clipped by the bisector of
each candidate (same-body particles nearer than 2 r_c + skin, found
by :func:`physics.pcmm.candidates` with its own flags); its faces (at most
MAX_FACES) are kept for the force pass, which reads the faces of the neighbours
(no atomics, a fixed order).
"""
import math

import taichi as ti

from tdem.core.launch import cached
from tdem.core.layout import PROP_MASS, W_X0, W_X1, W_Y0, W_Y1

from ..materials import MAT_K, MAT_RHO, MAT_VISC
from .stress import bulk_viscosity

REACH = 2.5        # the bounding disc's radius, in mean particle radii of the body
SIDES = 24         # the bounding disc as a regular polygon
MAX_VERTS = 48
MAX_FACES = 24
NO_FACE = -1       # a face label: the bounding disc
WALL_FACE = -2     # a face label: a wall


@ti.func
def _clip(px: ti.template(), py: ti.template(), lab: ti.template(), nv, a, b, label):
    """Cut the convex polygon (px, py; nv vertices counter-clockwise; lab[k] labels
    the edge from vertex k to k + 1) by the half-plane a·y ≤ b; the new edge is
    labelled ``label``. Returns the new vertex count."""
    qx = ti.Vector([0.0] * MAX_VERTS)
    qy = ti.Vector([0.0] * MAX_VERTS)
    ql = ti.Vector([0] * MAX_VERTS, dt=ti.i32)
    nq = 0
    for k in range(nv):
        k1 = (k + 1) % nv
        c = ti.Vector([px[k], py[k]])
        d = ti.Vector([px[k1], py[k1]])
        sc = a.dot(c) - b
        sd = a.dot(d) - b
        if sc <= 0.0:
            if nq < MAX_VERTS:
                qx[nq] = c[0]
                qy[nq] = c[1]
                ql[nq] = lab[k]
                nq += 1
            if sd > 0.0 and nq < MAX_VERTS:
                e = c + sc / (sc - sd) * (d - c)
                qx[nq] = e[0]
                qy[nq] = e[1]
                ql[nq] = label
                nq += 1
        elif sd <= 0.0 and nq < MAX_VERTS:
            e = c + sc / (sc - sd) * (d - c)
            qx[nq] = e[0]
            qy[nq] = e[1]
            ql[nq] = lab[k]
            nq += 1
    for k in range(nq):
        px[k] = qx[k]
        py[k] = qy[k]
        lab[k] = ql[k]
    return nq


@cached
@ti.kernel
def cells(pos: ti.types.ndarray(), vel: ti.types.ndarray(), prop: ti.types.ndarray(),
          cmat: ti.types.ndarray(), crad: ti.types.ndarray(),
          matp: ti.types.ndarray(), cand: ti.types.ndarray(), ccnt: ti.types.ndarray(),
          wall: ti.types.ndarray(), nwalls: ti.i32, carea: ti.types.ndarray(),
          cpres: ti.types.ndarray(), cq: ti.types.ndarray(), cnf: ti.types.ndarray(),
          cfj: ti.types.ndarray(),
          cfl: ti.types.ndarray(), cfc: ti.types.ndarray(), cbnd: ti.types.ndarray(),
          cflags: ti.types.ndarray(), serial: ti.template()):
    """Each cell particle's cell: its area (``carea``), pressure (``cpres``), faces
    (``cnf`` of them: neighbour ``cfj``, length ``cfl``, midpoint ``cfc``) and Σ l n
    over its arcs (``cbnd``); ``crad``: each particle's r_c. ``cflags[0]``: the
    largest face count met (a cell with more faces than MAX_FACES is an error the
    host raises at the end of the run segment).

    ``cq``: the artificial bulk viscosity of a shrinking cell, q = ρ L r (b1 c + b2
    L r) with r = −(dA/dt)/A, L = sqrt(A) (the elements' form,
    :func:`physics.pcmm.stress.bulk_viscosity`); dA/dt = Σ_k ∂A/∂x_k · v_k from the
    same faces. It pushes as the pressure does and is not part of it."""
    ti.loop_config(serialize=serial)
    for i in range(cmat.shape[0]):
        M = cmat[i]
        if M >= 0:
            xi = pos[i]
            rc = crad[i]
            px = ti.Vector([0.0] * MAX_VERTS)
            py = ti.Vector([0.0] * MAX_VERTS)
            lab = ti.Vector([0] * MAX_VERTS, dt=ti.i32)
            for k in ti.static(range(SIDES)):
                px[k] = xi[0] + rc * ti.static(math.cos(2.0 * math.pi * k / SIDES))
                py[k] = xi[1] + rc * ti.static(math.sin(2.0 * math.pi * k / SIDES))
                lab[k] = NO_FACE
            nv = SIDES
            for w in range(nwalls):
                a = ti.Vector([wall[w, W_X0], wall[w, W_Y0]])
                b = ti.Vector([wall[w, W_X1], wall[w, W_Y1]])
                t = b - a
                tt = t.dot(t)
                s = 0.0
                if tt > 0.0:
                    s = ti.math.clamp((xi - a).dot(t) / tt, 0.0, 1.0)
                foot = a + s * t
                if (xi - foot).norm() < rc and tt > 0.0:
                    # the wall's line, xi on the kept side
                    nrm = ti.Vector([t[1], -t[0]])
                    if nrm.dot(xi - a) > 0.0:
                        nrm = -nrm
                    nv = _clip(px, py, lab, nv, nrm, nrm.dot(a), WALL_FACE)
            for q in range(ccnt[i]):
                j = cand[i, q]
                d = pos[j] - xi
                if d.norm() < rc + crad[j]:
                    nv = _clip(px, py, lab, nv, d, d.dot(xi + 0.5 * d), j)
            area = 0.0
            bnd = ti.Vector([0.0, 0.0])
            nf = 0
            rate = 0.0      # dA/dt
            vi = vel[i]
            for k in range(nv):
                k1 = (k + 1) % nv
                area += 0.5 * (px[k] * py[k1] - px[k1] * py[k])
                t = ti.Vector([px[k1] - px[k], py[k1] - py[k]])
                if lab[k] == NO_FACE:
                    bnd += ti.Vector([t[1], -t[0]])
                elif lab[k] >= 0:
                    j = lab[k]
                    mid = ti.Vector([0.5 * (px[k] + px[k1]), 0.5 * (py[k] + py[k1])])
                    ln = t.norm()
                    rate += ln / (pos[j] - xi).norm() * ((mid - xi).dot(vi)
                                                        - (mid - pos[j]).dot(vel[j]))
                    if nf < MAX_FACES:
                        cfj[i, nf] = j
                        cfl[i, nf] = ln
                        cfc[i, nf] = mid
                    nf += 1
            rate += bnd.dot(vi)
            ti.atomic_max(cflags[0], nf)
            cnf[i] = ti.min(nf, MAX_FACES)
            carea[i] = area
            cbnd[i] = bnd
            rho = matp[M, MAT_RHO]
            a0 = prop[i][PROP_MASS] / rho
            cpres[i] = matp[M, MAT_K] * ti.max(a0 / area - 1.0, 0.0) if area > 0.0 else 0.0
            # the elements' form, with the cell's relative area change over the
            # step for their volumetric strain increment (per unit time here)
            q = bulk_viscosity(matp, M, ti.Vector([rate / area if area > 0.0 else 0.0,
                                                   0.0, 0.0]), 1.0, area)
            cq[i] = q


@cached
@ti.kernel
def cell_forces(pos: ti.types.ndarray(), vel: ti.types.ndarray(), cmat: ti.types.ndarray(),
                matp: ti.types.ndarray(), cand: ti.types.ndarray(), ccnt: ti.types.ndarray(),
                cpres: ti.types.ndarray(), cq: ti.types.ndarray(), cnf: ti.types.ndarray(),
                cfj: ti.types.ndarray(),
                cfl: ti.types.ndarray(), cfc: ti.types.ndarray(), cbnd: ti.types.ndarray(),
                xforce: ti.types.ndarray(), psig: ti.types.ndarray(), serial: ti.template()):
    """F_i = p_i ∂A_i/∂x_i + Σ_j p_j ∂A_j/∂x_i (the module docstring) plus the
    viscous force, added to ``xforce``, with p + q for p (``cq``, the bulk
    viscosity); the particle's stress (−p, −p, 0, −p) into ``psig``. The second
    sum runs over i's candidates and reads each one's own face with i (the two
    discs can cut a face differently, or away from one cell); the viscosity takes
    the mean of the two cells' lengths of a face, so that it is the same for both
    particles."""
    ti.loop_config(serialize=serial)
    for i in range(cmat.shape[0]):
        M = cmat[i]
        if M >= 0:
            xi = pos[i]
            vi = vel[i]
            pi = cpres[i] + cq[i]
            mu = matp[M, MAT_VISC]
            f = pi * cbnd[i]
            for k in range(cnf[i]):
                f += pi * cfl[i, k] / (pos[cfj[i, k]] - xi).norm() * (cfc[i, k] - xi)
            for q in range(ccnt[i]):
                j = cand[i, q]
                lji = 0.0
                cji = ti.Vector([0.0, 0.0])
                for kk in range(cnf[j]):
                    if cfj[j, kk] == i:
                        lji = cfl[j, kk]
                        cji = cfc[j, kk]
                lij = 0.0
                for k in range(cnf[i]):
                    if cfj[i, k] == j:
                        lij = cfl[i, k]
                if lji > 0.0 or lij > 0.0:
                    d = (pos[j] - xi).norm()
                    if lji > 0.0:
                        f -= (cpres[j] + cq[j]) * lji / d * (cji - xi)
                    f += mu * 0.5 * (lij + lji) / d * (vel[j] - vi)
            xforce[i] = xforce[i] + f
            pe = cpres[i]
            psig[i] = ti.Vector([-pe, -pe, 0.0, -pe])
