"""Sweeps: TOML specifications, parameters per chunk, runners and the Parquet store.

Modules: :mod:`~vimpact.sweep.spec` (TOML -> :class:`SweepSpec`),
:mod:`~vimpact.sweep.parameters` (parameter sets per chunk),
:mod:`~vimpact.sweep.runner` (in-process, shards, Dask),
:mod:`~vimpact.sweep.store` (part files, file or dataset; the table format itself:
:mod:`vimpact.tableformat`),
:mod:`~vimpact.sweep.progress`. The public names are re-exported here::

    from vimpact.sweep import run_sweep, load_spec, read_metadata
"""

from vimpact.sweep.runner import SweepInterrupted, chunk_summary, compute_chunk, run_sweep  # noqa: F401
from vimpact.sweep.spec import Draw, SweepSpec, load_spec  # noqa: F401
from vimpact.sweep.store import parts_dir, summary  # noqa: F401
from vimpact.tableformat.metadata import read_metadata  # noqa: F401
from vimpact.tableformat.schema import COLUMNS, SCHEMA_VERSION, SWEEP_STATUSES  # noqa: F401

__all__ = ["COLUMNS", "Draw", "SCHEMA_VERSION", "SWEEP_STATUSES", "SweepInterrupted",
           "SweepSpec", "chunk_summary", "compute_chunk", "load_spec", "parts_dir",
           "read_metadata", "run_sweep", "summary"]
