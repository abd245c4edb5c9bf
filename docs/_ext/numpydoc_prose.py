"""Sphinx extension: NumPy-style entries whose text after the colon is prose, not a type.

The project's docstrings write ``name : what it is, unit`` in their
Parameters/Attributes/Returns sections (the physics first; the type is in the
signature). napoleon would read the prose as a type and set every word of it
as a type name. Before napoleon runs, this hook moves such text into the
entry's description (``name`` alone, then the prose indented below), and
leaves real types (``float``, ``np.ndarray``, ``float | None``,
``int, optional``) where they are. It changes how the docs render, not what
the docstrings say, and hides no warning.
"""

from __future__ import annotations

import re

_SECTIONS = {"parameters", "other parameters", "attributes", "returns", "yields",
             "keyword arguments"}
_TYPE_TOKEN = r"[A-Za-z_][\w.]*(?:\[[^\]]*\])?"
_TYPE = re.compile(rf"^{_TYPE_TOKEN}(?:\s*(?:\||or)\s*{_TYPE_TOKEN})*"
                   r"(?:,\s*(?:optional|default\b.*))?$")
_ENTRY = re.compile(r"^(\s*)(\*{0,2}[\w][\w, *]*?)\s+:\s+(.+)$")


def is_type(text: str) -> bool:
    """Whether the text after ``name :`` reads as a type (not as prose)."""
    text = text.strip().strip("`")
    return bool(_TYPE.match(text)) and len(text.split()) <= 4


def prose_to_description(lines: list[str]) -> list[str]:
    """The docstring lines with prose moved out of the type slot (see module docstring)."""
    out, section, base = [], None, None
    for k, line in enumerate(lines):
        nxt = lines[k + 1] if k + 1 < len(lines) else ""
        stripped = line.strip()
        if stripped and nxt.strip() and set(nxt.strip()) == {"-"} and len(nxt.strip()) >= 3:
            section = stripped.lower() if stripped.lower() in _SECTIONS else None
            base = len(line) - len(line.lstrip())
            out.append(line)
            continue
        m = _ENTRY.match(line) if section else None
        if m and len(m.group(1)) == base and not is_type(m.group(3)):
            out.append(f"{m.group(1)}{m.group(2)}")
            out.append(f"{m.group(1)}    {m.group(3)}")
            continue
        out.append(line)
    return out


def _process(app, what, name, obj, options, lines: list[str]) -> None:
    lines[:] = prose_to_description(lines)


def setup(app):
    # before napoleon (priority 500), which turns the sections into fields
    app.connect("autodoc-process-docstring", _process, priority=400)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
