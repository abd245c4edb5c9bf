"""Tests of vimpact.sweep; :func:`write` puts a spec's text in a file."""


def write(tmp_path, text, name="spec.toml"):
    """Write ``text`` to ``tmp_path / name``; returns the path."""
    path = tmp_path / name
    path.write_text(text)
    return path
