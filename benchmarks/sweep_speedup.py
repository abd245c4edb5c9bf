"""Wall time, rows per second and parallel speedup of a sweep (1 thread vs all).

Run: ``python -m benchmarks.sweep_speedup [--spec SPEC] [--repeats N] [--quick]``.
Runs the sweep alternately on one numba thread and on all threads, side by
side in one process (the machine is shared and noisy: compare the ratio, not
the seconds), and writes ``benchmarks/results/sweep_speedup.json``.
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path

import numba
import numpy as np

from vimpact.sweep import load_spec, run_sweep, summary

from .machine import RESULTS, machine_info

DEFAULT_SPEC = Path(__file__).parents[1] / "sweeps" / "kelvin_voigt_table.toml"


def run(spec: Path, repeats: int) -> dict:
    all_threads = numba.config.NUMBA_NUM_THREADS
    times: dict[int, list[float]] = {1: [], all_threads: []}
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "warmup.parquet"
        run_sweep(spec, out=out, progress=False)  # compile / load the cache
        rows = sum(summary(out).values())
        for r in range(repeats):
            for nt in times:
                numba.set_num_threads(nt)
                path = Path(tmp) / f"t{nt}_{r}.parquet"
                t0 = time.perf_counter()
                run_sweep(spec, out=path, progress=False)
                times[nt].append(time.perf_counter() - t0)
    numba.set_num_threads(all_threads)
    med = {nt: float(np.median(ts)) for nt, ts in times.items()}
    return {
        "machine": machine_info(), "spec": str(spec), "rows": rows,
        "numerics": str(load_spec(spec).numerics), "repeats": repeats,
        "seconds": {str(k): v for k, v in times.items()},
        "median_seconds": {str(k): v for k, v in med.items()},
        "rows_per_second": {str(k): rows / v for k, v in med.items()},
        "speedup": med[1] / med[all_threads],
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--spec", type=Path, default=DEFAULT_SPEC)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--out", type=Path, default=RESULTS)
    args = parser.parse_args()
    data = run(args.spec, args.repeats)
    print(json.dumps(data["machine"]))
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "sweep_speedup.json").write_text(json.dumps(data, indent=1))
    print(f"{data['rows']} rows; median wall time by threads {data['median_seconds']}; "
          f"rows/s {data['rows_per_second']}; speedup {data['speedup']:.2f}x")


if __name__ == "__main__":
    main()
