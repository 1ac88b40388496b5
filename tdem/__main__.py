"""``python -m tdem list`` / ``python -m tdem run CASE ...``: see :mod:`tdem.cli`."""
import sys

from .cli import main

sys.exit(main())
