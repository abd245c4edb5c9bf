"""Sphinx extension: toctree entries for pages that other work may not have delivered yet.

A page listed in :data:`OPTIONAL` is dropped from the index's toctree when its
file does not exist, so the build stays free of warnings either way; once the
file lands it appears in the navigation without an edit here.
"""

from __future__ import annotations

from pathlib import Path

#: optional pages (doc names relative to docs/) listed in index.md's toctree
OPTIONAL = ("dem",)


def _drop_missing(app, docname: str, source: list[str]) -> None:
    if docname != app.config.root_doc:
        return
    srcdir = Path(app.srcdir)
    lines = source[0].splitlines()
    keep = [ln for ln in lines
            if not (ln.strip() in OPTIONAL and not (srcdir / f"{ln.strip()}.md").exists())]
    source[0] = "\n".join(keep) + "\n"


def _always_reread_root(app, env, added, changed, removed) -> list[str]:
    """Whether an optional page exists can change between builds: re-read the index."""
    return [app.config.root_doc]


def setup(app):
    app.connect("source-read", _drop_missing)
    app.connect("env-get-outdated", _always_reread_root)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
