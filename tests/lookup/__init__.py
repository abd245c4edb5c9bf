"""Helpers shared by the lookup tests."""

from __future__ import annotations

import functools
from pathlib import Path

TABLES = Path(__file__).resolve().parents[2] / "sweeps" / "tables"


@functools.cache
def shipped(name: str):
    """The shipped table ``sweeps/tables/<name>.parquet``, opened (and checked) once for
    the whole session: reading, validating and hashing the standard-solid table's
    489,360 rows is ~0.4 s, and the tests that use it only read it."""
    from vimpact.lookup.table import RestitutionTable

    return RestitutionTable.open(TABLES / f"{name}.parquet")
