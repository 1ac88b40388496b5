"""Exceptions raised by tdem: kept under this name for older imports; the classes are
those of :mod:`tdem.core.errors` (``tdem.errors.InputError is
tdem.core.errors.InputError``)."""
from tdem.core.errors import *  # noqa: F401,F403
from tdem.core.errors import __all__  # noqa: F401
