"""The ``vimpact sweep`` subcommand: a TOML specification into a Parquet table.

Errors follow :mod:`vimpact.cli.main`: a bad spec, a bad output, bad parts or a
second sweep into the same output raise ``ValueError`` (one line on stderr,
exit code 2, printed by ``vimpact.cli.main.main``) before any work; Ctrl-C
leaves the finished chunks on disk, says how to resume and exits with 130.
"""

from __future__ import annotations

import argparse
import sys
import time


def _shard(text: str) -> tuple[int, int]:
    try:
        index, count = (int(x) for x in text.split("/"))
    except ValueError:  # argparse prints "argument --shard: <this>"
        raise argparse.ArgumentTypeError(f"{text!r} is not allowed: must be I/N, e.g. 0/4") from None
    return index, count


def add_parser(subparsers):
    """Add the ``sweep`` subcommand to ``subparsers`` (from ``add_subparsers``)."""
    p = subparsers.add_parser(
        "sweep", help="run a sweep specification (TOML) into a Parquet restitution table",
        description=(
            "Simulate every parameter set of a sweep specification (random physical "
            "draws or a grid in Q1, Q2, nu) and write a Parquet table: one row per "
            "impact, with units, numerics, seed and the spec in its metadata. A small "
            "sweep (up to 1e6 rows, or layout = \"file\") becomes one file; a large one a "
            "partitioned dataset (a directory of part files plus _common_metadata). "
            "Finished chunks are saved atomically as they complete, so an interrupted run "
            "(even kill -9) is continued with --resume. Chunks run in this process (numba "
            "threads), on a local Dask cluster (--workers N), on a running one "
            "(--scheduler ADDRESS), or as shards (--shard I/N, then --combine)."),
        epilog="Examples: vimpact sweep sweeps/kelvin_voigt_table.toml; "
               "vimpact sweep big.toml --workers 8; "
               "vimpact sweep big.toml --shard $SLURM_ARRAY_TASK_ID/16, then "
               "vimpact sweep big.toml --combine")
    p.add_argument("spec", metavar="SPEC", help="sweep specification, a TOML file")
    p.add_argument("--out", metavar="PATH",
                   help="output table, ending in .parquet (relative to the current directory; "
                        "default: the spec's 'output', relative to the spec's directory)")
    p.add_argument("--resume", action="store_true",
                   help="continue an interrupted run: compute only the missing chunks")
    where = p.add_mutually_exclusive_group()
    where.add_argument("--workers", type=int, metavar="N",
                       help="run the chunks on a local Dask cluster of N worker processes "
                            "(one thread each; needs vimpact[dask])")
    where.add_argument("--scheduler", metavar="ADDRESS",
                       help="run the chunks on a running Dask cluster, e.g. tcp://host:8786")
    split = p.add_mutually_exclusive_group()
    split.add_argument("--shard", type=_shard, metavar="I/N",
                       help="compute only the chunks c with c %% N == I and keep the parts "
                            "(e.g. one SLURM array task each); finish with --combine")
    split.add_argument("--combine", action="store_true",
                       help="write the table from the parts of all shards (every chunk must "
                            "be there)")
    p.set_defaults(func=cmd_sweep)
    return p


def cmd_sweep(args) -> int:
    """Run ``vimpact sweep`` and return the exit code (0, or 130 on Ctrl-C)."""
    from vimpact.sweep import SweepInterrupted, summary
    from vimpact.tablebuild.sweep import run_sweep  # the grid refined to a tolerance

    t0 = time.perf_counter()
    try:
        path = run_sweep(args.spec, out=args.out, resume=args.resume,
                         workers=args.workers, scheduler=args.scheduler, shard=args.shard,
                         combine=args.combine)
    except SweepInterrupted as exc:
        print(f"vimpact sweep: {exc}", file=sys.stderr)
        return 130
    except KeyboardInterrupt:  # before the first chunk started
        print("vimpact sweep: interrupted", file=sys.stderr)
        return 130
    elapsed = time.perf_counter() - t0
    if args.shard is not None:
        print(f"{path}: shard {args.shard[0]}/{args.shard[1]} done in {elapsed:.1f} s; "
              f"finish with: vimpact sweep {args.spec} --combine"
              + (f" --out {args.out}" if args.out else ""))
        return 0
    counts = summary(path)
    rows = sum(counts.values())
    statuses = ", ".join(f"{k} {v}" for k, v in sorted(counts.items()))
    print(f"{path}: {rows} rows ({statuses}) in {elapsed:.1f} s")
    return 0
