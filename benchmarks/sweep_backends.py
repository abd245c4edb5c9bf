"""Full-size run of the ``sweep_backends`` benchmark: writes
``benchmarks/results/sweep_backends.json`` (``python -m benchmarks.sweep_backends
[--part backends|large|default|both] [--rows N] [--quick]``; a part not run keeps its earlier entry,
and each part run stores the machine and load it ran at under its own ``machine`` key; the
top-level ``machine`` is that of the last run).

The code is :mod:`vimpact.bench.sweep_backends` (also ``vimpact bench sweep_backends``);
its names are re-exported here.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from vimpact.bench.sweep_backends import *  # noqa: F401,F403
from vimpact.bench.sweep_backends import backends, default_sweep, large, machine

RESULTS = Path(__file__).parent / "results"


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--part", choices=("backends", "large", "default", "both"),
                        default="both")
    parser.add_argument("--rows", type=int, default=1_000_000, help="rows of the large sweep")
    parser.add_argument("--quick", action="store_true", help="small sizes (a smoke run)")
    parser.add_argument("--out", type=Path, default=RESULTS)
    args = parser.parse_args(argv)
    path = args.out / ("sweep_backends_quick.json" if args.quick else "sweep_backends.json")
    data = json.loads(path.read_text()) if path.exists() else {}
    data["machine"] = machine()  # each part run below also keeps its own copy
    if args.part in ("backends", "both"):
        data["backends"] = backends(200 if args.quick else 2000, 20 if args.quick else 100)
        data["backends"]["machine"] = data["machine"]
        print(json.dumps(data["backends"], indent=1))
    if args.part in ("large", "both"):
        data["large"] = large(2000 if args.quick else args.rows, 500 if args.quick else 10_000)
        data["large"]["command"] = "python -m benchmarks.sweep_backends --part large"
        data["large"]["machine"] = data["machine"]
        print(json.dumps(data["large"], indent=1))
    if args.part in ("default", "both"):
        data["default"] = default_sweep(10_000 if args.quick else 100_000,
                                        1 if args.quick else 2)
        data["default"]["command"] = "python -m benchmarks.sweep_backends --part default"
        data["default"]["machine"] = data["machine"]
        print(json.dumps({k: x for k, x in data["default"].items()
                          if k not in ("runs", "thread_pairs")}, indent=1))
    args.out.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(data, indent=1))
    return data


if __name__ == "__main__":
    main()
