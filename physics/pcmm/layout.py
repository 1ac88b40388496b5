"""Sizes and status indices shared by the PCMM kernels and the arrays that hold
their state (allocated with these sizes by :class:`tdem.continuum.Continuum`).

Module-level constants read inside kernels are compile-time constants."""
import taichi as ti

MAX_ELEMENTS = 12        # elements a particle can create (pruned gaps are >= 30 deg)
MAX_INCIDENT = 64        # slots of a particle's list of the elements containing it
SCAN_BLOCK = 1024        # particles per block of the prefix sum of record_slots

# indices in the int status array ``pflags`` of the engine-side system
P_NEED = 0       # largest number of Eq. 1 candidates of any particle
P_BUILDS = 1     # engine list build the candidates were made from (−1: none yet)
P_INC = 2        # largest number of elements containing one particle
P_EPOCH = 3      # the P_BUILDS value the current epoch began at (rebuild_elements)
P_NEW = 4        # 1: this step begins an epoch
P_REBUILT = 5    # particles that rebuilt their elements this step
P_RECOUNT = 6    # elements whose N_e was recounted this step
P_BUILT = 7      # 1: the candidates were rebuilt this step (the engine rebuilt its lists)
P_SOFT = 8       # 1: this step renews the epoch (displacements)
PFLAGS_SIZE = 9
PFLAGS_INIT = (0, -1, 0, 0, 1, 0, 0, 0, 0)


# a particle's list of the elements containing it (``inc``) holds one code each:
# owner << 6 | slot << 2 | which corner of the element the particle is
@ti.func
def inc_code(owner, slot, corner):
    """The code of the element in ``owner``'s ``slot`` of which the particle is
    corner ``corner`` (0–2)."""
    return (owner << 6) | (slot << 2) | corner


@ti.func
def inc_element(code):
    """The owner and the slot of the element a code of ``inc`` names."""
    return code >> 6, (code >> 2) & 15
