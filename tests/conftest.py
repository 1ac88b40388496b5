import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
if ROOT not in sys.path:
    sys.path.insert(0, ROOT)

# Small models run their loops on one thread by default (tdem.backend.serial_loops);
# the suite's models are small, so keep them on the parallel path that large models
# take. Tests of the size rule itself change this variable where they need to.
os.environ.setdefault("TDEM_SERIAL_BELOW", "0")

# The suite builds many small models, each compiling its own kernels: Taichi's
# optimisation level 0 builds them about 40 % faster and runs them a little slower
# (tdem.backend.opt_level); a run that sets TDEM_OPT_LEVEL itself keeps its choice.
os.environ.setdefault("TDEM_OPT_LEVEL", "0")
