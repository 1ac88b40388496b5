"""The core of tdem: what every layer may import.

The layers point one way: :mod:`physics` (contact laws, shapes, materials, PCMM) and
:mod:`coupling` import from ``tdem`` only through this package, and the engine (the
rest of ``tdem``) imports from all three. The core holds no model and imports nothing
above it:

- :mod:`tdem.core.errors`: the exceptions raised by tdem;
- :mod:`tdem.core.backend`: Taichi initialisation, once per process, and the loop
  settings that follow from it (one-thread loops, chunks of the pair loop);
- :mod:`tdem.core.launch`: kernel launches that skip Taichi's per-call checks;
- :mod:`tdem.core.arrays`: device arrays that are freed when dropped;
- :mod:`tdem.core.layout`: the columns of the engine's tables that kernels outside
  the engine read or write (status flags, step parameters, particle properties,
  wall rows).

The older names still work: ``tdem.backend`` and ``tdem.launch`` are these very
modules (their settings are module state), ``tdem.errors`` names the same classes.

Importing this package runs ``tdem/__init__.py`` first (it is a subpackage of
``tdem``), which loads the engine, and the engine imports :mod:`physics` and
:mod:`coupling`; those two packages therefore import ``tdem`` before their own
modules (their ``__init__``), so that the engine loads them in its order.
"""
