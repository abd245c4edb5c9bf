"""Tests of vimpact.sweep; :func:`write` puts a spec's text in a file."""

#: Kelvin-Voigt on its continuum path, 6 rows in chunks of ``{chunk}``: seconds
GRID_KV = """
model = "kelvin_voigt"
chunk_size = {chunk}
[numerics]
steps = 100
elements = 20
[grid]
Q1 = [0.01, 0.1, 1.0]
nu = [0.3, 0.5]
"""


def write(tmp_path, text, name="spec.toml"):
    """Write ``text`` to ``tmp_path / name``; returns the path."""
    path = tmp_path / name
    path.write_text(text)
    return path
