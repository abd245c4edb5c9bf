"""Sweep backends side by side, and a 1e6-row sweep: wall time against kernel time.

Run: ``vimpact bench sweep_backends [--quick] [--out DIR]`` (both parts), or from a
source checkout ``python -m benchmarks.sweep_backends [--part backends|large|both]
[--rows N] [--quick]``.

- ``backends``: the same random oblique Kelvin-Voigt sweep (``fast`` numerics)
  in-process on 2 numba threads and on a Dask ``LocalCluster`` of 2 worker
  processes x 1 thread, one run each, side by side (after a warm-up of both;
  the cluster's start-up is reported apart). Compare the ratio, not the seconds:
  the machine is shared and noisy. The two tables must be identical.
- ``large``: one 1e6-row random oblique sweep (``fast`` numerics, in-process):
  wall time, kernel time alone (seconds inside the numba kernels, from
  ``run_sweep(timings=...)``), their ratio (target <= 1.2), rows/s, Python
  overhead per row, and the peak resident memory of this process and its
  children (``resource.getrusage``).

- ``default``: a Kelvin-Voigt normal-only grid of 1e5 rows (default numerics) whose
  spec sets no ``chunk_size`` (the runner chooses it from the measured cost per row,
  :func:`vimpact.sweep.runner.choose_chunk_size`) against the same spec with
  ``chunk_size = 64`` (the fixed default before), in turns, and the chosen chunking on
  1 and on 2 numba threads; each against the kernel time of its own run and against
  ``simulate_batch`` on the same rows in one call (target: sweep wall <= 1.2x the kernel
  time; 2 threads never slower than 1), and the best chosen run's wall time split by
  stage over the one batch's kernel time (the engine beyond it, choosing the chunk
  size, writing, the rest). ``chosen_over_chosen_whole``: the chosen chunking as it
  runs (a chunk of more than ``ROW_GROUP_ROWS`` rows streamed in row groups) over the
  same chunk computed and written whole, in turns. The tables must be equal.

The cluster's start (``backends``: ``cluster_start_s``, and ``cluster_ready_s`` with its
workers' first sweep, which loads the kernels, less the same sweep in process) is what
``--workers`` on a small sweep is measured against
(:data:`vimpact.sweep.runner.CLUSTER_START_SECONDS`).

The repository's script writes ``benchmarks/results/sweep_backends.json`` (a
part not run keeps its earlier entry).
"""

from __future__ import annotations

import dataclasses
import os
import platform
import resource
import tempfile
import time
from pathlib import Path

import numpy as np

from .machine import max_threads

TITLE = "Sweeps: in-process against a Dask LocalCluster, and a large sweep's wall over kernel time"

SPEC = """
description = "benchmark: random oblique Kelvin-Voigt impacts"
model = "kelvin_voigt"
seed = 2026
chunk_size = {chunk}
[numerics]
preset = "fast"
[random]
rows = {rows}
E_Pa = [1e7, 1e10]
eta_Pa_s = [1e1, 1e5]
R_m = [0.01, 0.1]
m_kg = [1e-3, 0.1]
v_z0_m_s = [0.1, 10]
v_x0_m_s = [-5, 5]
omega0_rad_s = [-100, 100]
nu = [0.0, 0.5]
"""


def machine() -> dict:
    """Return the platform, Python, CPUs, load and date of the run."""
    return {"platform": platform.platform(), "python": platform.python_version(),
            "cpus": os.cpu_count(), "load_average_1min": os.getloadavg()[0],
            "date_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())}


def _spec(tmp: Path, name: str, rows: int, chunk: int) -> Path:
    path = tmp / f"{name}.toml"
    path.write_text(SPEC.format(rows=rows, chunk=chunk))
    return path


def backends(rows: int, chunk: int) -> dict:
    """Time one sweep in process and on a local Dask cluster, side by side."""
    import numba
    from distributed import Client

    from vimpact.sweep import run_sweep
    from vimpact.sweep.runner import local_cluster

    numba.set_num_threads(min(2, max_threads()))
    with tempfile.TemporaryDirectory() as folder:
        tmp = Path(folder)
        warm, spec = _spec(tmp, "warm", 8, 2), _spec(tmp, "sweep", rows, chunk)
        t0 = time.perf_counter()
        cluster = local_cluster(2)
        client = Client(cluster)
        start_s = time.perf_counter() - t0
        try:
            address = cluster.scheduler_address
            t0 = time.perf_counter()
            run_sweep(warm, out=tmp / "w1.parquet", progress=False)
            warm_in = time.perf_counter() - t0
            t0 = time.perf_counter()  # the workers load the kernels (numba's cache)
            run_sweep(warm, out=tmp / "w2.parquet", progress=False, scheduler=address)
            warm_dask = time.perf_counter() - t0
            t0 = time.perf_counter()
            a = run_sweep(spec, out=tmp / "inprocess.parquet", progress=False)
            t_in = time.perf_counter() - t0
            t0 = time.perf_counter()
            b = run_sweep(spec, out=tmp / "dask.parquet", progress=False, scheduler=address)
            t_dask = time.perf_counter() - t0
            identical = a.read_bytes() == b.read_bytes()
        finally:
            client.close()
            cluster.close()
    return {"rows": rows, "chunk_size": chunk, "numerics": "fast",
            "in_process_2_threads_s": t_in, "dask_2_workers_x_1_thread_s": t_dask,
            "dask_over_in_process": t_dask / t_in, "cluster_start_s": start_s,
            "first_sweep_s": {"in_process": warm_in, "dask": warm_dask},
            # what --workers costs before its first chunk runs at speed
            "cluster_ready_s": start_s + warm_dask - warm_in,
            "rows_per_s": {"in_process": rows / t_in, "dask": rows / t_dask},
            "tables_identical": identical}


def large(rows: int, chunk: int) -> dict:
    """Time a large in-process sweep against its kernel time."""
    from vimpact.sweep import run_sweep, summary

    with tempfile.TemporaryDirectory() as folder:
        tmp = Path(folder)
        spec = _spec(tmp, "large", rows, chunk)
        timings: dict = {}
        t0 = time.perf_counter()
        out = run_sweep(spec, out=tmp / "large.parquet", timings=timings)
        wall = time.perf_counter() - t0
        counts = summary(out)
        size = sum(p.stat().st_size for p in ([out] if out.is_file() else out.iterdir()))
    self_kb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    children_kb = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    kernel = timings.get("kernel_s", float("nan"))
    return {"rows": rows, "chunk_size": chunk, "numerics": "fast", "wall_s": wall,
            "kernel_s": kernel, "engine_s": timings.get("total_s"),
            "wall_over_kernel": wall / kernel, "rows_per_s": rows / wall,
            "overhead_us_per_row": 1e6 * (wall - kernel) / rows,
            "peak_rss_mb": {"self": self_kb / 1024, "children": children_kb / 1024},
            "table_bytes": size, "statuses": counts}


DEFAULT_SPEC = """
description = "benchmark: Kelvin-Voigt normal-only grid"
model = "kelvin_voigt"
tangential = "none"
{chunk}
[grid]
Q1 = {{ start = 1e-3, stop = 1.0, num = {q1} }}
nu = {{ start = 0.0, stop = 0.5, num = 100 }}
"""


def default_sweep(rows: int = 100_000, repeats: int = 2, thread_pairs: int = 4) -> dict:
    """Time the default (chosen) chunking against ``chunk_size = 64``, and 1 vs 2 threads.

    Each configuration ``repeats`` times in turns after a warm-up; per run the wall time,
    the kernel and engine time of its chunks, the time to choose the chunk size and to
    write (``run_sweep(timings=...)``) and the chunk size it used; each round starts with
    one ``simulate_batch`` call on all the sweep's rows (the kernel at its best: one
    launch). Ratios are taken within a round (the load changes between rounds);
    ``chosen_over_kernel_by_stage`` splits the best chosen run's wall time by stage.
    1 against 2 threads: besides the rounds, ``thread_pairs`` more chosen sweeps per
    round on each, back to back in alternating order (``one_thread_over_two``: the median
    over all pairs of the 1-thread wall time over the 2-thread one; on a shared machine
    the load moves between two runs, so one pair per round says little).
    """
    import numba

    from vimpact.engine.simulate import simulate_batch
    from vimpact.sweep import load_spec, read_metadata, run_sweep
    from vimpact.sweep.parameters import engine_columns
    from vimpact.tableformat import files

    threads = min(2, max_threads())
    q1 = max(1, rows // 100)
    runs: dict[str, list[dict]] = {"chosen": [], "chunk_64": [], "chosen_1_thread": [],
                                   "chosen_whole": []}
    pairs: list[dict] = []
    with tempfile.TemporaryDirectory() as folder:
        tmp = Path(folder)
        chosen = tmp / "chosen.toml"
        chosen.write_text(DEFAULT_SPEC.format(chunk="", q1=q1))
        fixed = tmp / "fixed.toml"
        fixed.write_text(DEFAULT_SPEC.format(chunk="chunk_size = 64", q1=q1))
        warm = tmp / "warm.toml"
        warm.write_text(DEFAULT_SPEC.format(chunk="", q1=2))
        run_sweep(warm, out=tmp / "warm.parquet", progress=False)
        spec = load_spec(chosen)
        params = dataclasses.replace(spec, chunk_size=spec.rows).chunk_parameters(0)
        cols = engine_columns(spec, params)[0][0][1]
        batches: list[dict] = []
        tables = {}
        try:
            for r in range(repeats):
                numba.set_num_threads(threads)
                batch: dict = {}
                simulate_batch(cols, spec.numerics, timings=batch)
                batches.append(batch)
                for name, path, nt in (("chosen", chosen, threads), ("chunk_64", fixed, threads),
                                       ("chosen_1_thread", chosen, 1),
                                       ("chosen_whole", chosen, threads)):
                    numba.set_num_threads(nt)
                    out = tmp / f"{name}_{r}.parquet"
                    timings: dict = {}
                    # chosen_whole: the chunk computed and written whole (one row group
                    # as large as the sweep), as before it was streamed in row groups
                    row_group = files.ROW_GROUP_ROWS
                    if name == "chosen_whole":
                        files.ROW_GROUP_ROWS = max(row_group, spec.rows)
                    t0 = time.perf_counter()
                    try:
                        run_sweep(path, out=out, progress=False, timings=timings)
                    finally:
                        files.ROW_GROUP_ROWS = row_group
                    wall = time.perf_counter() - t0
                    runs[name].append({"wall_s": wall, "kernel_s": timings["kernel_s"],
                                       "engine_s": timings["total_s"],
                                       # a streamed chunk: the wall time of its pieces,
                                       # computed side by side (engine_s sums them)
                                       "engine_wall_s": timings.get("pieces_wall_s",
                                                                    timings["total_s"]),
                                       "choose_s": timings.get("choose_s", 0.0),
                                       "write_s": timings.get("write_s", 0.0), "threads": nt,
                                       "chunk_size": read_metadata(out)["chunk_size"],
                                       "one_batch_kernel_s": batch["kernel_s"]})
                    tables[name] = out
                for k in range(thread_pairs):
                    walls = {}
                    for nt in ((threads, 1) if k % 2 == 0 else (1, threads)):
                        numba.set_num_threads(nt)
                        t0 = time.perf_counter()
                        run_sweep(chosen, out=tmp / f"pair_{r}_{k}_{nt}.parquet",
                                  progress=False)
                        walls[nt] = time.perf_counter() - t0
                    pairs.append({"one_thread_s": walls[1], "two_threads_s": walls[threads]})
        finally:
            numba.set_num_threads(max_threads())
        import pyarrow.parquet as pq

        frames = [pq.read_table(p).to_pandas() for p in tables.values()]
        equal = all(f.equals(frames[0]) for f in frames[1:])

    def ratio(name: str, key: str) -> float:
        """Return the smallest over the rounds of wall time / ``key`` of the round."""
        return min(x["wall_s"] / x[key] for x in runs[name])

    def turns(a: str, b: str) -> float:
        """Return the median over the rounds of the wall time of ``a`` / that of ``b``."""
        return float(np.median([x["wall_s"] / y["wall_s"] for x, y in zip(runs[a], runs[b])]))

    def shares(name: str) -> dict:
        """Return where the wall time of the best round of ``name`` went, over one batch's kernel.

        Each stage over the kernel time of the round's one ``simulate_batch`` call (the
        headline's unit: the stages add up to ``wall / one_batch_kernel_s``; a chunk
        streamed in row groups runs its pieces side by side, so its own kernel seconds
        overlap). ``engine_python``: the engine's wall time (for a streamed chunk the
        wall time spent waiting for its pieces, their tables included) beyond that
        kernel time; ``choose``: the chunk size; ``write``: content hashes, parts, the
        table and its checks (for a streamed chunk what the computation did not cover);
        ``rest``: the spec, the lock, the chunk's table columns, the progress.
        """
        x = min(runs[name], key=lambda r: r["wall_s"] / r["one_batch_kernel_s"])
        k = x["one_batch_kernel_s"]
        engine = x.get("engine_wall_s", x["engine_s"])
        rest = x["wall_s"] - engine - x["choose_s"] - x["write_s"]
        return {"kernel": 1.0, "engine_python": (engine - k) / k,
                "choose": x["choose_s"] / k, "write": x["write_s"] / k, "rest": rest / k}

    result = {"rows": spec.rows, "threads": threads, "repeats": repeats, "runs": runs,
              "one_batch": batches, "tables_equal": equal}
    for name in runs:
        result[f"{name}_wall_over_kernel"] = ratio(name, "kernel_s")
        result[f"{name}_wall_over_one_batch_kernel"] = ratio(name, "one_batch_kernel_s")
        # the best round flatters on a shared machine (a round whose kernel call was slow):
        # the median over the rounds beside it
        result[f"{name}_wall_over_one_batch_kernel_median"] = float(np.median(
            [x["wall_s"] / x["one_batch_kernel_s"] for x in runs[name]]))
    result["chosen_over_kernel_by_stage"] = shares("chosen")
    result["chunk_64_over_chosen"] = turns("chunk_64", "chosen")
    # the chunk streamed in row groups (two computed side by side, each written while
    # the next is computed) against the same chunk computed and written whole
    result["chosen_over_chosen_whole"] = turns("chosen", "chosen_whole")
    result["thread_pairs"] = pairs
    result["one_thread_over_two"] = float(np.median(
        [x["wall_s"] / y["wall_s"] for x, y in zip(runs["chosen_1_thread"], runs["chosen"])]
        + [p["one_thread_s"] / p["two_threads_s"] for p in pairs]))
    result["target_wall_over_kernel"] = 1.2
    return result


def run(quick: bool) -> dict:
    """Measure both parts.

    Both parts (``quick``: 200 rows side by side, a 2000-row large sweep;
    full: 2000 rows side by side, a 1e6-row large sweep).
    """
    return {"machine": machine(),
            "backends": backends(200 if quick else 2000, 20 if quick else 100),
            "large": large(2000 if quick else 1_000_000, 500 if quick else 10_000),
            "default": default_sweep(10_000 if quick else 100_000, 1 if quick else 2)}


def plot(data: dict, path) -> None:
    """Rows per second of each backend, and the large sweep's wall and kernel time."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from vimpact.bench.machine import save_figure

    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    b, big = data["backends"], data["large"]
    axes[0].bar(["in-process\n2 threads", "Dask\n2 workers x 1"],
                [b["rows_per_s"]["in_process"], b["rows_per_s"]["dask"]], color=["C0", "C1"])
    axes[0].set(ylabel="rows / s", title=f"same sweep, {b['rows']} rows ({b['numerics']})")
    axes[1].bar(["wall", "kernel"], [big["wall_s"], big["kernel_s"]], color=["C2", "C3"])
    axes[1].set(ylabel="s", title=f"{big['rows']:.0e}-row sweep: wall / kernel = "
                f"{big['wall_over_kernel']:.2f}")
    save_figure(fig, path)


def figures(data: dict) -> dict:
    """Return the headline numbers of a sweep-backends run.

    Dask over in-process time, the large sweep's wall over kernel time, its
    rows/s and Python overhead per row.
    """
    from vimpact.bench.machine import figure

    b, big = data["backends"], data["large"]
    extra = {}
    if "default" in data:
        d = data["default"]
        # over one simulate_batch call's kernel time (a streamed chunk's own kernel
        # seconds overlap: pieces side by side)
        extra = {"default_sweep_wall_over_kernel": figure(
                     d.get("chosen_wall_over_one_batch_kernel", d["chosen_wall_over_kernel"]),
                     "-"),
                 "default_sweep_wall_over_kernel_median": figure(
                     d.get("chosen_wall_over_one_batch_kernel_median"), "-"),
                 "default_sweep_chunk_64_over_chosen": figure(d["chunk_64_over_chosen"], "-",
                                                              better="higher"),
                 "default_sweep_one_thread_over_two": figure(d["one_thread_over_two"], "-",
                                                             better="higher")}
    if "cluster_ready_s" in b:
        extra["cluster_ready_s"] = figure(b["cluster_ready_s"], "s")
    return {**extra, "cluster_start_s": figure(b["cluster_start_s"], "s"),
            "dask_over_in_process": figure(b["dask_over_in_process"], "-"),
            "large_wall_over_kernel": figure(big["wall_over_kernel"], "-"),
            "large_rows_per_s": figure(big["rows_per_s"], "1/s", better="higher"),
            "large_overhead_us_per_row": figure(big["overhead_us_per_row"], "us/row")}
