"""What every benchmark shares: the machine it ran on (printed and stored with
every result), median timing, figure output and the command line."""

from __future__ import annotations

import argparse
import json
import os
import platform
import time
from pathlib import Path

import numba
import numpy as np

import vimpact

RESULTS = Path(__file__).parent / "results"


def machine_info() -> dict:
    cpu = platform.processor() or ""
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return {
        "cpu": cpu,
        "cores": os.cpu_count(),
        "numba_threads": numba.config.NUMBA_NUM_THREADS,
        "python": platform.python_version(),
        "numpy": np.__version__,
        "numba": numba.__version__,
        "vimpact": vimpact.__version__,
        "platform": platform.platform(),
    }


def median_time(fn, repeats: int) -> float:
    """Median wall time of ``fn()`` over ``repeats`` calls, s."""
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return float(np.median(times))


def save_figure(fig, path) -> None:
    """Write ``fig`` to ``path`` (120 dpi) and close it."""
    import matplotlib.pyplot as plt

    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def bench_main(doc: str, run, plot, stem: str, png_stem: str | None = None,
               argv: list[str] | None = None) -> dict:
    """The command line every benchmark shares: ``--quick`` (tiny, for CI) and
    ``--out`` (default ``benchmarks/results``); prints the machine, writes
    ``STEM[_quick].json`` and the plot ``PNG_STEM[_quick].png``, returns the data."""
    parser = argparse.ArgumentParser(description=doc.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="tiny configuration (CI)")
    parser.add_argument("--out", type=Path, default=RESULTS, help="results folder")
    args = parser.parse_args(argv)
    data = run(args.quick)
    print(json.dumps(data["machine"]))
    args.out.mkdir(parents=True, exist_ok=True)
    sfx = "_quick" if args.quick else ""
    (args.out / f"{stem}{sfx}.json").write_text(json.dumps(data, indent=1, allow_nan=False))
    plot(data, args.out / f"{png_stem or stem}{sfx}.png")
    return data
