"""Lazy public names of a package (PEP 562): a name is imported when first used.

``vimpact`` and ``vimpact.lookup`` export names defined in their submodules without
importing those (and numba, pandas, pyarrow) until a name is used.
"""

from __future__ import annotations

import importlib
from typing import Any


def load(package: str, exports: dict[str, str], namespace: dict[str, Any], name: str) -> Any:
    """Return the public ``name`` of ``package``, imported from its module in ``exports``.

    Stored in the package's ``namespace`` (its ``globals()``), so that later look-ups
    do not come here. An unknown name raises ``AttributeError`` as a module does.
    """
    module = exports.get(name)
    if module is None:
        raise AttributeError(f"module {package!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    namespace[name] = value
    return value
