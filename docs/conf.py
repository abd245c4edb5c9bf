"""Sphinx configuration of the vimpact documentation.

Build (warnings are errors)::

    .venv/bin/python -m sphinx -W --keep-going -b html docs docs/_build/html

Pages are Markdown (myst-parser); the API reference comes from the NumPy-style
docstrings (autodoc + napoleon); ``reference/cli.md`` gets the command-line
reference appended at build time from the argparse parsers (``_ext/cli_reference.py``).
"""

from __future__ import annotations

import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent
ROOT = DOCS.parent
sys.path.insert(0, str(DOCS / "_ext"))
sys.path.insert(0, str(ROOT))  # the package from this tree, also without an install

import vimpact  # noqa: E402

project = "vimpact"
author = "the vimpact authors"
copyright = "the vimpact authors"
release = vimpact.__version__
version = release

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "cli_reference",
    "optional_pages",
    "numpydoc_prose",
]

source_suffix = {".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "Thumbs.db", ".DS_Store", "README.md"]

# Markdown: $...$ maths, definition lists, ``(label)=`` targets; headings up to
# level 3 get anchors so pages can be cited as physics.md#kelvin-voigt-continuum.
myst_enable_extensions = ["dollarmath", "deflist", "colon_fence"]
myst_heading_anchors = 3

# API reference from NumPy-style docstrings
napoleon_google_docstring = False
napoleon_numpy_docstring = True
napoleon_use_rtype = False
# "Attributes" sections as :ivar: fields: NamedTuple and dataclass fields are
# documented by autodoc itself, and .. attribute:: entries would duplicate them
napoleon_use_ivar = True
autodoc_member_order = "bysource"
autodoc_typehints = "description"
autodoc_default_options = {"members": True, "show-inheritance": False}

html_theme = "alabaster"
html_title = f"vimpact {release}"
html_static_path: list[str] = []
