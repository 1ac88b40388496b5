"""Particle–block and block–block point–edge contacts (planned)."""
