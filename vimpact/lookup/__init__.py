"""Restitution tables: reading, describing, interpolating, e(v) curves."""
