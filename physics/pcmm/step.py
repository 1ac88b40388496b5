"""One PCMM step, in the order the data flows (:func:`update`).

The stages are the kernels of :mod:`physics.pcmm.rebuild` (0–1d),
:mod:`physics.pcmm.stress` (2) and :mod:`physics.pcmm.nodal` (3); the candidates
(:func:`physics.pcmm.candidates`) are made before, after each neighbour-list build.
"""
from .nodal import gather
from .rebuild import copies, displacements, incidence, mark_dirty, rebuild_elements, record_slots
from .stress import eos_volumes, equation_of_state, stresses


def update(a, e, dt, time, first, full, carry, eos, serial, mixed=True):
    """One PCMM step (Feng, Li & Oñate 2015, §2: steps 1–5 and Eqs. 15–16) for the
    particles of x_n moving at v_{n−1/2}, in the order the data flows. ``a``: the continuum's arrays
    (:class:`tdem.continuum.Continuum`), ``e``: the engine's (positions, velocities,
    pair lists and slots). ``first``: the first step of the run; ``full``: rebuild
    everything (first step, after a restore); ``carry``: an element that existed
    last step continues from its own stress; ``eos``: there are particles with an
    equation of state; ``mixed``: the nodal mixed discretization of the elements
    whose material takes it (:func:`physics.pcmm.stress.stresses`).

    pstate[i] = (plastic shear strain, failed (0/1), elements containing i, −).
    """
    full = int(bool(full) or bool(first))
    a["sigp"], a["sigc"] = a["sigc"], a["sigp"]       # last step's stresses, this step's
    displacements(e["pos"], a["pmat"], a["xref"], a["pu"], a["pflags"], full, serial)
    rebuild_elements(e["pos"], a["rrule"], a["pmat"], a["matp"], a["mtol"], a["cand"], a["ccnt"],
                     a["nbr"], a["ncnt"], a["ring"], a["rang"], a["elem"], a["ecnt"],
                     a["earea"], a["esig"], a["sigp"], a["eidx"], a["elem_old"], a["esig_old"],
                     a["ecnt_old"],
                     a["esrc"], a["emult"], a["ecopy"], a["pu"], a["pbud"], a["prb"],
                     a["pflags"], serial)
    mark_dirty(a["pmat"], a["nbr"], a["ncnt"], a["pu"], a["prb"], a["pdirty"], a["unb"],
               a["pstate"], a["pfail"], e["pos"], a["xref"], a["pflags"], serial)
    copies(a["pmat"], a["elem"], a["ecnt"], a["emult"], a["ecopy"], a["pdirty"], a["prb"],
           a["esig"], a["sigp"], a["eidx"], a["ecomp"], serial)
    incidence(a["pmat"], a["nbr"], a["ncnt"], a["elem"], a["ecnt"], a["emult"], a["pinc"],
              a["picnt"], a["piwt"], a["pdirty"], a["pflags"], serial)
    record_slots(a["ecomp"], a["ebase"], a["eoff"], serial)
    stresses(e["pos"], e["vel"], a["pmat"], a["matp"], a["elem"], a["ecnt"], a["emult"],
             a["pinc"], a["picnt"], a["ncov"], a["ebud"], a["esig"], a["sigp"], a["sigc"],
             a["efor"], a["ede"],
             a["psig"], a["pfail"], a["rad"], a["elem_old"], a["esig_old"], a["ecnt_old"],
             a["esrc"], a["prb"], a["pdirty"], a["unb"], a["pu"], a["pflags"], a["ebase"],
             a["eidx"], a["pmix"], dt, carry, eos, bool(mixed), serial)
    if eos:
        equation_of_state(a["pmat"], a["matp"], a["rad"], e["pos"], a["elem"], a["ecnt"],
                          a["emult"], a["pinc"], a["picnt"], a["ncov"], a["sigc"],
                          a["efor"], a["eidx"], a["ede"], a["pjwl"], dt, time, first, serial)
    gather(e["pos"], a["rad"], a["pmat"], a["matp"], a["nbr"], a["ncnt"], a["elem"],
           a["pinc"], a["picnt"], a["piwt"], a["efor"], a["eidx"], a["psig"], a["peps"],
           a["pstate"],
           a["xforce"], a["pjwl"], e["nbr"], e["ncnt"], e["cskip"], e["hist"], e["prop"],
           a["pdirty"], a["pflags"], int(first), eos, serial)


def volumes(a, e, dt, serial):
    """The end of a step (the particles at x_{n+1}, moving at v_{n+1/2}): the volume
    change of each particle with an equation of state by the elements that pushed
    over the step (:func:`physics.pcmm.stress.eos_volumes`), kept for the next
    step's update."""
    eos_volumes(a["pmat"], a["matp"], e["pos"], e["vel"], a["elem"], a["emult"],
                a["pinc"], a["picnt"], a["ncov"], a["pjwl"], dt, serial)
