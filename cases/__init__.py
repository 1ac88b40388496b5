"""Case scripts: ``python -m cases.NAME --preset quick|paper``."""
