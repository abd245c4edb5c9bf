"""The repository side of the benchmarks: full-size runs that write the
committed results in ``benchmarks/results/``.

The measuring code lives in the installed package (:mod:`vimpact.bench`,
also behind ``vimpact bench``); the scripts here only call it, so the
README's charts and the command cannot disagree. :func:`repository_main`
is their shared command line; :func:`bench_main` stays for scripts that pass
their own ``run`` and ``plot``.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from vimpact.bench.machine import (  # noqa: F401  (re-exported for the scripts)
    figure,
    load_average,
    machine_info,
    machine_line,
    median_time,
    module_at_commit,
    progress,
    save_figure,
    time_samples,
    use_agg,
)

RESULTS = Path(__file__).parent / "results"


def repository_main(name: str, argv: list[str] | None = None,
                    png_stem: str | None = None) -> dict:
    """``python -m benchmarks.NAME [--quick] [--out DIR]``: run the registered
    benchmark ``name`` (full size unless ``--quick``), print the machine, its
    report and figures, write ``DIR/NAME[_quick].json`` and the chart
    ``DIR/PNG_STEM[_quick].png`` (default ``benchmarks/results``, ``PNG_STEM
    = NAME``); returns the data."""
    from vimpact.bench import load
    from vimpact.bench.machine import run_and_write

    module = load(name)
    parser = argparse.ArgumentParser(description=(module.__doc__ or name).splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="small configuration (CI)")
    parser.add_argument("--out", type=Path, default=RESULTS, help="results folder")
    args = parser.parse_args(argv)
    sfx = "_quick" if args.quick else ""
    data, _, _ = run_and_write(name, module, args.quick, args.out, json_name=f"{name}{sfx}.json",
                               png_name=f"{png_stem or name}{sfx}.png", details=True)
    return data


def bench_main(doc: str, run, plot, stem: str, png_stem: str | None = None,
               argv: list[str] | None = None) -> dict:
    """The command line of a script with its own ``run(quick)`` and ``plot(data,
    path)``: ``--quick`` and ``--out`` (default ``benchmarks/results``); prints
    the machine, writes ``STEM[_quick].json`` and ``PNG_STEM[_quick].png``,
    returns the data. (A benchmark in the registry, :data:`vimpact.bench.BENCHMARKS`,
    uses :func:`repository_main` instead.)"""
    parser = argparse.ArgumentParser(description=doc.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="tiny configuration (CI)")
    parser.add_argument("--out", type=Path, default=RESULTS, help="results folder")
    args = parser.parse_args(argv)
    data = run(args.quick)
    print(machine_line(data["machine"]))
    args.out.mkdir(parents=True, exist_ok=True)
    sfx = "_quick" if args.quick else ""
    (args.out / f"{stem}{sfx}.json").write_text(json.dumps(data, indent=1, allow_nan=False))
    plot(data, args.out / f"{png_stem or stem}{sfx}.png")
    return data
