"""A sweep on a real Dask cluster survives losing a worker.

The cluster is made of the command-line entry points that ``vimpact[dask]``
installs, as separate processes on 127.0.0.1 only: ``dask scheduler`` and two
``dask worker`` processes (no nanny, one thread each, ``NUMBA_NUM_THREADS=1``
set before numba loads). ``vimpact sweep --scheduler ADDRESS`` runs as its own
process; once some chunks are saved, one worker is killed (SIGKILL). Dask
gives its tasks to the other worker, and the table equals the in-process one
byte for byte (a part the killed worker was writing is a temporary file that
the sweep removes).

The in-process reference run comes first: it warms numba's cache, which the
worker processes then only read (concurrent processes share the cache safely
once it is warm). Slow (process start-up, about a minute): ``pytest -m slow``.
"""

from __future__ import annotations

import importlib.util
import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from vimpact.sweep import parts_dir, run_sweep

# the cluster runs in other processes: whether distributed is installed is enough (importing
# it here would cost about 1 s at every collection, although the test is slow)
pytestmark = pytest.mark.skipif(importlib.util.find_spec("distributed") is None,
                                reason="distributed is not installed (vimpact[dask])")

SPEC = """model = "kelvin_voigt"
chunk_size = 2
[numerics]
preset = "fast"
continuum = false
steps = 4000
elements = 300
[grid]
Q1 = { start = 0.01, stop = 1, num = 12 }
nu = [0.3, 0.5]
"""
#: Seconds to wait for the cluster to come up, for parts to appear, for the sweep to end.
START_S, SWEEP_S = 180.0, 900.0


def dask_cli() -> str:
    exe = Path(sys.executable).with_name("dask")
    found = str(exe) if exe.exists() else shutil.which("dask")
    if found is None:
        pytest.skip("the dask command line (vimpact[dask]) is not installed")
    return found


def wait_for(predicate, seconds: float, what: str, procs=()):
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        if predicate():
            return
        for p in procs:
            assert p.poll() is None, f"{p.args[:3]} ended early while waiting for {what}"
        time.sleep(0.1)
    raise AssertionError(f"timed out after {seconds:g} s waiting for {what}")


@pytest.mark.slow
def test_sweep_on_a_dask_cluster_survives_a_killed_worker(tmp_path):
    spec = tmp_path / "cluster.toml"
    spec.write_text(SPEC)
    reference = run_sweep(spec, out=tmp_path / "reference.parquet", progress=False)  # warms
    dask = dask_cli()
    env = {**os.environ, "NUMBA_NUM_THREADS": "1", "PYTHONUNBUFFERED": "1"}
    sched_file = tmp_path / "scheduler.json"
    procs: list[subprocess.Popen] = []
    logs = []

    def start(args, name):
        log = open(tmp_path / f"{name}.log", "w")
        logs.append(log)
        proc = subprocess.Popen(args, cwd=tmp_path, env=env, stdout=log, stderr=log,
                                start_new_session=True)
        procs.append(proc)
        return proc

    try:
        scheduler = start([dask, "scheduler", "--host", "127.0.0.1", "--port", "0",
                           "--no-dashboard", "--scheduler-file", str(sched_file)], "scheduler")
        wait_for(lambda: sched_file.exists() and sched_file.stat().st_size > 0, START_S,
                 "the scheduler", [scheduler])
        address = json.loads(sched_file.read_text())["address"]
        assert address.startswith("tcp://127.0.0.1:")
        workers = [start([dask, "worker", address, "--nthreads", "1", "--no-nanny",
                          "--host", "127.0.0.1", "--no-dashboard", "--name", f"w{i}"],
                         f"worker{i}") for i in range(2)]
        wait_for(lambda: all("Registered to" in (tmp_path / f"worker{i}.log").read_text()
                             for i in range(2)), START_S, "two workers", procs)
        out = tmp_path / "cluster.parquet"
        sweep = start([sys.executable, "-m", "vimpact.cli", "sweep", str(spec), "--out",
                       str(out), "--scheduler", address], "sweep")
        parts = parts_dir(out)
        wait_for(lambda: len(list(parts.glob("part-*.parquet"))) >= 2, SWEEP_S,
                 "the first parts", [sweep, *workers])
        saved = len(list(parts.glob("part-*.parquet")))
        assert saved < 12, "the sweep finished before a worker could be killed"
        os.kill(workers[0].pid, signal.SIGKILL)
        workers[0].wait()
        assert sweep.wait(SWEEP_S) == 0, (tmp_path / "sweep.log").read_text()
        assert out.read_bytes() == reference.read_bytes()
        assert not parts.exists()
        assert "24 rows (ok 24)" in (tmp_path / "sweep.log").read_text()
    finally:
        for proc in reversed(procs):
            if proc.poll() is None:
                os.killpg(proc.pid, signal.SIGTERM)
                try:
                    proc.wait(30)
                except subprocess.TimeoutExpired:
                    os.killpg(proc.pid, signal.SIGKILL)
                    proc.wait()
        for log in logs:
            log.close()
