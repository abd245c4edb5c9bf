"""The ``vimpact sweep`` subcommand: a TOML specification into a Parquet table.

Registered on the main parser by :func:`add_sweep_parser`. Errors follow
:mod:`vimpact.cli.main`: a bad spec or bad parts raise ``ValueError`` (one line on
stderr, exit code 2, printed by ``vimpact.cli.main.main``); Ctrl-C leaves the
finished chunks on disk, says how to resume and exits with 130.
"""

from __future__ import annotations

import sys
import time

from vimpact.sweep.spec import SweepInterrupted, run_sweep, summary


def add_parser(subparsers):
    """Add the ``sweep`` subcommand to ``subparsers`` (from ``add_subparsers``)."""
    p = subparsers.add_parser(
        "sweep", help="run a sweep specification (TOML) into a Parquet restitution table",
        description=(
            "Simulate every parameter set of a sweep specification (random physical "
            "draws or a grid in Q1, Q2, nu) and write one Parquet table: one row per "
            "impact, with units, numerics, seed and the spec in its metadata. Finished "
            "chunks are saved in OUT.parts/ as they complete, so an interrupted run can "
            "be continued with --resume."),
        epilog="Example: vimpact sweep sweeps/kelvin_voigt_table.toml")
    p.add_argument("spec", metavar="SPEC", help="sweep specification, a TOML file")
    p.add_argument("--out", metavar="PATH",
                   help="output table (relative to the current directory; default: the "
                        "spec's 'output', relative to the spec's directory)")
    p.add_argument("--resume", action="store_true",
                   help="continue an interrupted run: compute only the chunks missing in "
                        "OUT.parts/")
    p.set_defaults(func=cmd_sweep)
    return p


def cmd_sweep(args) -> int:
    """Handler of ``vimpact sweep``: returns the exit code (0, or 130 on Ctrl-C)."""
    t0 = time.perf_counter()
    try:
        path = run_sweep(args.spec, out=args.out, resume=args.resume)
    except SweepInterrupted as exc:
        print(f"vimpact sweep: {exc}", file=sys.stderr)
        return 130
    except KeyboardInterrupt:  # before the first chunk started
        print("vimpact sweep: interrupted", file=sys.stderr)
        return 130
    elapsed = time.perf_counter() - t0
    counts = summary(path)
    rows = sum(counts.values())
    statuses = ", ".join(f"{k} {v}" for k, v in sorted(counts.items()))
    print(f"{path}: {rows} rows ({statuses}) in {elapsed:.1f} s")
    return 0
