"""``vimpact bench``: measure what accuracy and speed cost on this machine.

``vimpact bench NAME [--quick] [--out DIR]`` runs a benchmark and writes
``DIR/NAME.json`` and ``DIR/NAME.png``; ``vimpact bench list`` names them;
``vimpact bench compare OLD.json NEW.json [--json]`` compares two results
figure by figure against the noise of their repeats.
"""

from __future__ import annotations

import argparse
import json
import textwrap
from pathlib import Path


def add_parser(subparsers) -> argparse.ArgumentParser:
    """Register ``vimpact bench`` on ``subparsers``."""
    from vimpact.bench import BENCHMARKS

    bench = subparsers.add_parser(
        "bench", help="benchmarks: accuracy vs cost, throughput, overhead, import time",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description=textwrap.fill(
            "Run a benchmark on this machine: it prints a short table with the machine and "
            "writes OUT/NAME.json (medians over repeats and their spread) and OUT/NAME.png. "
            "'--quick' finishes in under a minute on 2 cores once the kernels are compiled "
            "(the first run compiles them). 'vimpact bench list' names the benchmarks; "
            "'vimpact bench compare OLD.json NEW.json' shows the ratio of every figure and "
            "flags what got slower or less accurate beyond the noise (exit code 0 either "
            "way).", 79) + "\n\nbenchmarks: " + ", ".join(BENCHMARKS),
        epilog="Examples: vimpact bench accuracy --quick; vimpact bench list; "
               "vimpact bench compare old/overhead.json bench-results/overhead.json")
    bench.add_argument("name", metavar="NAME",
                       help="a benchmark (see 'vimpact bench list'), 'list' or 'compare'")
    bench.add_argument("files", nargs="*", metavar="FILE",
                       help="compare only: OLD.json NEW.json")
    bench.add_argument("--quick", action="store_true",
                       help="small configuration (under a minute on 2 cores)")
    bench.add_argument("--out", type=Path, default=Path("bench-results"), metavar="DIR",
                       help="folder for NAME.json and NAME.png (default: ./bench-results)")
    bench.add_argument("--json", action="store_true",
                       help="compare only: print the comparison as JSON")
    bench.set_defaults(func=_cmd_bench)
    return bench


def _cmd_bench(a) -> int:
    from vimpact.model.validation import InputError

    if a.name == "compare":
        if len(a.files) != 2:
            raise InputError(f"compare needs two result files OLD.json NEW.json, got "
                             f"{len(a.files)}")
        return _compare(a.files[0], a.files[1], as_json=a.json)
    if a.files:
        raise InputError(f"unexpected argument(s) {' '.join(a.files)!r}: only "
                         "'vimpact bench compare' takes files")
    if a.name == "list":
        return _list()
    from vimpact.bench import load
    from vimpact.bench.machine import run_and_write

    module = load(a.name)
    run_and_write(a.name, module, a.quick, a.out)
    return 0


def _list() -> int:
    from vimpact.bench import BENCHMARKS, available, title

    width = max(len(name) for name in BENCHMARKS)
    for name, module in BENCHMARKS.items():
        text = title(name) if available(name) else f"(needs {module}: run from a source checkout)"
        print(f"{name:<{width}}  {text}")
    return 0


def _compare(old_path: str, new_path: str, as_json: bool) -> int:
    from vimpact.bench.compare import compare, format_table, load_result

    result = compare(load_result(old_path), load_result(new_path))
    if as_json:
        print(json.dumps(result, indent=1))
    else:
        print(format_table(result))
    return 0
