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
import importlib.util
import json
import subprocess
import sys
import tempfile
from pathlib import Path
from types import ModuleType

from vimpact.bench.machine import (  # noqa: F401  (re-exported for the scripts)
    figure,
    load_average,
    machine_info,
    machine_line,
    median_time,
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


def module_at_commit(commit: str, path: str) -> ModuleType | None:
    """The repository's module ``path`` (e.g. ``vimpact/kernels/elements.py``) as of
    ``commit``, for a benchmark that times a kernel before and after a change; ``None``
    without git (not a source checkout). The source is written under the temporary
    folder with a stable name, so that numba's cache beside it survives the run."""
    try:
        src = subprocess.run(["git", "show", f"{commit}:{path}"], cwd=RESULTS.parent.parent,
                             capture_output=True, text=True, check=True).stdout
    except (OSError, subprocess.CalledProcessError):
        return None
    folder = Path(tempfile.gettempdir()) / "vimpact_bench_before"
    folder.mkdir(exist_ok=True)
    name = f"{Path(path).stem}_{commit[:10]}"
    file = folder / f"{name}.py"
    if not file.exists() or file.read_text() != src:
        file.write_text(src)
    spec = importlib.util.spec_from_file_location(name, file)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # numba's cache finds the module again by name
    lent = _lend_moved_names()
    try:
        spec.loader.exec_module(module)
    finally:
        for home, attr in lent:
            delattr(home, attr)
    return module


#: Names an earlier commit's kernel imports from a module they have since left:
#: ``{old module: {name: module that defines it now}}``.
MOVED_NAMES = {"vimpact.kernels.layout": {"_record": "vimpact.kernels.record"}}


def _lend_moved_names() -> list[tuple[ModuleType, str]]:
    """Put each moved name back on its old module while an old kernel is imported
    (the modules themselves keep no alias); return what was lent."""
    lent = []
    for old, names in MOVED_NAMES.items():
        home = importlib.import_module(old)
        for attr, new in names.items():
            if not hasattr(home, attr):
                setattr(home, attr, getattr(importlib.import_module(new), attr))
                lent.append((home, attr))
    return lent
