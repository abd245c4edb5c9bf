"""Write the tables of a few sweeps, to compare two versions of the code byte for byte.

``python -m benchmarks.sweep_tables OUTDIR`` (from a source checkout) writes, with the
code of the checkout it runs in, the default sweep of ``vimpact bench sweep_backends``
(1e5 rows, one chunk, streamed in row groups) and in 64-row chunks, and the grid and
random specs of ``tests/sweep`` (each also in row groups of 5 rows). Run it in two
checkouts and compare the files (``cmp A/x.parquet B/x.parquet``): a change to how the
tables are computed or written that must not change them (content, content hash, file
layout) leaves every file the same bytes.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from tests.sweep import GRID_KV
from tests.sweep.test_pipelined import GRID, RANDOM
from vimpact.bench.sweep_backends import DEFAULT_SPEC
from vimpact.sweep import run_sweep
from vimpact.tableformat import files

SPECS = {"default_1e5": DEFAULT_SPEC.format(chunk="", q1=1000),
         "default_chunk64": DEFAULT_SPEC.format(chunk="chunk_size = 64", q1=20),
         "grid_kv": GRID_KV.format(chunk=4), "grid_normal": GRID.format(tangential="none"),
         "grid_oblique": GRID.format(tangential="auto"), "random_standard_solid": RANDOM}


def main(argv=None) -> list[Path]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path, help="directory for the tables")
    out = parser.parse_args(argv).out
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for name, text in SPECS.items():
        spec = out / f"{name}.toml"
        spec.write_text(text)
        written.append(run_sweep(spec, out=out / f"{name}.parquet", progress=False))
        if name != "default_1e5":  # the small ones in several row groups too
            row_group, files.ROW_GROUP_ROWS = files.ROW_GROUP_ROWS, 5
            try:
                written.append(run_sweep(spec, out=out / f"{name}_rg5.parquet",
                                         progress=False))
            finally:
                files.ROW_GROUP_ROWS = row_group
    for path in written:
        print(path)
    return written


if __name__ == "__main__":
    main()
