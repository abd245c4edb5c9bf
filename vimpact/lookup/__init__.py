"""Restitution tables: reading, describing, interpolating, e(v) curves.

The reader's public names, loaded lazily (``import vimpact.lookup`` imports no
pandas until one is used)::

    from vimpact.lookup import RestitutionTable, incidence

    table = RestitutionTable.open("table.parquet")
    table.lookup(Q1=0.1, nu=0.3)
"""

from __future__ import annotations

from vimpact import _lazy

#: public name -> module that defines it
_EXPORTS = {
    "AXES": "vimpact.lookup.columns",
    "DATA_STATUSES": "vimpact.lookup.columns",
    "LOOKUP_METHODS": "vimpact.lookup.columns",
    "LOOKUP_MODELS": "vimpact.lookup.columns",
    "OUTPUTS": "vimpact.lookup.columns",
    "SPEC_HINTS": "vimpact.lookup.columns",
    "LOG_AXES": "vimpact.lookup.interpolate",
    "MAX_CURVE_POINTS": "vimpact.lookup.curve",
    "RestitutionTable": "vimpact.lookup.table",
    "format_info": "vimpact.lookup.info",
    "incidence": "vimpact.lookup.query",
    "validate_table": "vimpact.lookup.validation",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str):
    return _lazy.load(__name__, _EXPORTS, globals(), name)


def __dir__() -> list[str]:
    return __all__
