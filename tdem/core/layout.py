"""Columns of the engine's tables that kernels outside the engine read or write.

The engine's state arrays are declared in ``tdem.state``; the meaning of the columns
of some of them is shared with :mod:`physics` and :mod:`coupling` kernels (the PCMM
element rebuild raises the engine's rebuild flag, the PCMM cells clip against the
walls, element kernels read a particle's radius and mass), so the columns are
declared here, below every layer. The engine modules that used to hold them re-export
them under the same names (``tdem.neighbors.F_*``, ``P_*``; ``tdem.state.PROP_*``;
``tdem.step.W_*``).

The columns of the tables owned by :mod:`physics` stay there: the law table
(``physics.contact_law.COL_*``), the PCMM flags (``physics.pcmm.layout.P_*``), the
material rows (``physics.materials.MAT_*``).
"""

# indices in the int status array ``flags`` (tdem.neighbors)
F_REBUILD = 0    # 1: lists must be rebuilt before the next force computation
F_NEED = 1       # largest number of slots any particle needed (half or reverse list)
F_WALL_NEED = 2  # largest number of wall slots any particle needed
F_BAD = 3        # smallest index of an unstable particle (n if none)
F_BUILDS = 4     # number of list builds so far
F_NONCONV = 5    # shaped-particle contact evaluations whose iteration stopped short
F_TBIN_NEED = 6  # 3D: entries the triangle bins needed (more than their capacity: the
                 # build looked at every triangle; the host grows the bins)
F_TBIN_TOTAL = 7  # 3D: entries of the triangle bins at the last build
F_SWEEP = 8      # sort-and-sweep (tdem.sweep): 1 while its pair set matches its sorted
                 # axes; 0 asks the next build to make the set again from the axes
F_FAST = 9       # 1 + the largest index of a particle that moved more than its radius in
                 # one step (0: none so far; tdem.step.step raises it, the host reports it)
F_PUSH = 10      # 1 + the largest index of a particle that the forces of a step pushed
                 # past what a stable step does (tdem.step.step; 0: none): folded into
                 # F_BAD and cleared by the status check (tdem.step.check_stability)
FLAGS_SIZE = 11

# columns of the float parameter array ``simp`` (the step's and the search's)
P_DT, P_GX, P_GY, P_ALPHA, P_ALPHA_LOCAL, P_SKIN, P_NWALLS = 0, 1, 2, 3, 4, 5, 6
P_PX0, P_PLX, P_PY0, P_PLY = 7, 8, 9, 10      # periodic axes: start, length (0: none)
P_GZ, P_PZ0, P_PLZ = 11, 12, 13                # 3D: gravity, periodic z axis
P_CHUNK = 14                                    # particles per chunk of the step's pair loop
SIMP_SIZE = 16

# columns of the particle property vector ``prop`` (tdem.state)
PROP_RADIUS, PROP_MASS, PROP_INERTIA = 0, 1, 2
PROP_WIDTH = 3

# columns of the wall array (2D; tdem.step): p0, p1, translation velocity, angular
# velocity, centre, law. W_INVLL = 1/|p1 − p0|²; W_DISP = largest displacement of the
# wall since the lists were built; servo control: W_SERVO_K > 0 switches it on
# (stiffness of one contact), target force W_SERVO_F along the unit direction
# (W_SERVO_DX, W_SERVO_DY), relaxation, speed limit. In 3D the wall table holds the
# triangles of the mesh walls instead (columns T_*, tdem.neighbors).
(W_X0, W_Y0, W_X1, W_Y1, W_VX, W_VY, W_OMEGA, W_CX, W_CY, W_LAW, W_INVLL, W_DISP,
 W_SERVO_K, W_SERVO_F, W_SERVO_DX, W_SERVO_DY, W_SERVO_ALPHA, W_SERVO_VMAX) = range(18)
WALL_WIDTH = 18
