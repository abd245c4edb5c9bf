"""Sweeps: TOML specifications, parameters per chunk, runners and the Parquet store.

The public names are re-exported here::

    from vimpact.sweep import run_sweep, load_spec, read_metadata
"""

from vimpact.sweep.spec import (  # noqa: F401
    COLUMNS, SCHEMA_VERSION, SWEEP_STATUSES, Draw, SweepInterrupted, SweepSpec, compute_chunk,
    load_spec, parts_dir, read_metadata, run_sweep, summary)
