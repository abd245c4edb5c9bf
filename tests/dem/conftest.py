"""Runs shared by the DEM tests: the exports are the slow part (the fits, the figure), so
one run of ``vimpact dem`` feeds every check of what it wrote."""

import contextlib
import io
from pathlib import Path
from typing import NamedTuple

import pytest

from vimpact.cli.main import main


def cli(argv: list[str]) -> tuple[int, str, str]:
    """``vimpact`` in this process: (exit code, stdout, stderr)."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(argv)
    return code, out.getvalue(), err.getvalue()


class Run(NamedTuple):
    """One ``vimpact dem`` run: exit code, stdout, stderr, output folder and the
    :class:`vimpact.dem.export.Export` the command wrote its files and summary from."""

    status: int
    out: str
    err: str
    folder: Path
    export: object


def dem_run(folder: Path, toml: str, argv: list[str]) -> Run:
    """Write ``toml`` to ``folder/setup.toml`` and run ``vimpact dem`` on it with ``argv``
    (output in ``folder/out``), keeping the export it made."""
    from vimpact.dem import export as export_module

    src = folder / "setup.toml"
    src.write_text(toml)
    made = []

    def keep(*args, **kwargs):
        made.append(run_export(*args, **kwargs))
        return made[-1]

    run_export = export_module.export
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(export_module, "export", keep)
        status, out, err = cli(["dem", str(src), "--out", str(folder / "out"), *argv])
    return Run(status, out, err, folder / "out", made[-1] if made else None)


#: the codes the round trips run for real: their ``vimpact dem`` run is on the round trips'
#: set-up (tests/dem/test_round_trip.py), and the round trips run what that run wrote
ROUND_TRIP_CODES = ("lammps", "yade", "liggghts", "rebound")


@pytest.fixture(scope="session")
def code_run(tmp_path_factory):
    """``vimpact dem --for CODE``, run once per code and session: ``code_run(code) -> Run``.

    The codes of :data:`ROUND_TRIP_CODES` on the round trips' set-up (friction, the
    default impact angles), LAMMPS with ``--json`` and the report's figure; the others on
    ``WIRING`` (tests/dem/test_cli_dem.py: one impact angle, a cheap tangential search).
    Every run but LAMMPS' with ``--no-figure``. tests/dem/test_cli_dem.py checks the runs
    and their files; tests/dem/test_exported_files.py and the round trips read the same
    files and fits (the exports are the slow part)."""
    runs: dict[str, Run] = {}

    def run(code: str) -> Run:
        if code not in runs:
            from tests.dem.test_cli_dem import WIRING
            from tests.dem.test_round_trip import TOML

            toml = TOML if code in ROUND_TRIP_CODES else WIRING
            argv = ["--for", code] + (["--json"] if code == "lammps" else ["--no-figure"])
            runs[code] = dem_run(tmp_path_factory.mktemp(f"dem_{code}"), toml, argv)
        return runs[code]
    return run


#: the LAMMPS worker's loop: for each folder read from stdin, the runner of
#: :func:`vimpact.dem.lammps.run_lammps_many` (its own code, passed as argv[1]) run as its
#: own process would run it there, then a line that ends the batch with its exit status
_WORKER = r"""
import os, sys
runner, lib = sys.argv[1], sys.argv[2]
for folder in sys.stdin:
    os.chdir(folder.rstrip("\n"))
    sys.argv = ["-c", lib, "runs.json"]
    status = 0
    try:
        exec(compile(runner, "<runner>", "exec"), {"__name__": "__main__"})
    except BaseException as exc:
        print(repr(exc), file=sys.stderr, flush=True)
        status = 1
    print("VIMPACT_BATCH_END", status, flush=True)
"""


class _LammpsWorker:
    """``subprocess`` for :mod:`vimpact.dem.lammps`: its runner goes to one long-lived
    worker process instead of a new Python (and LAMMPS, MPI) start per call, about 0.14 s
    each; anything else goes to :func:`subprocess.run`. The runs, their files and the
    parsing of their output are the module's own; each script still runs in a LAMMPS
    instance of its own."""

    def __init__(self):
        self.proc = None
        self.lines = None
        self.err = None

    def _start(self, runner: str, lib: str, env: dict) -> None:
        import queue
        import subprocess
        import sys
        import tempfile
        import threading

        self.err = tempfile.TemporaryFile(mode="w+")
        self.proc = subprocess.Popen([sys.executable, "-u", "-c", _WORKER, runner, lib],
                                     stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     stderr=self.err, text=True, env=env)
        self.lines = queue.Queue()
        out, lines = self.proc.stdout, self.lines

        def read():  # (a thread, so that a batch can time out)
            for line in out:
                lines.put(line)
            lines.put(None)
        threading.Thread(target=read, daemon=True).start()

    def run(self, cmd, *, cwd, env, capture_output, text, timeout):
        import queue
        import subprocess
        import sys
        import time

        from vimpact.dem import lammps

        if list(cmd[:3]) != [sys.executable, "-c", lammps._RUNNER] or cmd[4:] != ["runs.json"]:
            return subprocess.run(cmd, cwd=cwd, env=env, capture_output=capture_output,
                                  text=text, timeout=timeout)
        if self.proc is None or self.proc.poll() is not None:
            self._start(cmd[2], cmd[3], env)
        self.err.seek(0)
        self.err.truncate()
        self.proc.stdin.write(f"{cwd}\n")
        self.proc.stdin.flush()
        out, deadline = [], time.monotonic() + timeout
        while True:
            try:
                line = self.lines.get(timeout=max(deadline - time.monotonic(), 0.0))
            except queue.Empty:
                self.close()
                raise subprocess.TimeoutExpired(cmd, timeout) from None
            if line is None or line.startswith("VIMPACT_BATCH_END"):
                break
            out.append(line)
        self.err.seek(0)
        err = self.err.read()
        status = 1 if line is None else int(line.split()[1])
        if line is None:
            self.close()
        return subprocess.CompletedProcess(cmd, status, "".join(out), err)

    def close(self) -> None:
        if self.proc is not None:
            if self.proc.poll() is None:
                self.proc.stdin.close()
                try:
                    self.proc.wait(timeout=10)
                except Exception:
                    self.proc.kill()
            self.err.close()
            self.proc = None


@pytest.fixture(scope="session")
def _lammps_worker():
    worker = _LammpsWorker()
    yield worker
    worker.close()


@pytest.fixture
def one_lammps_process(_lammps_worker, monkeypatch):
    """The LAMMPS runs of a test go to one worker process shared by the session (the round
    trips check LAMMPS' numbers, not the start of its process); one test,
    tests/dem/test_round_trip.py::test_lammps_hertz_material_wall_is_a_body_of_the_particles_material,
    keeps :func:`vimpact.dem.lammps.run_lammps_many`'s own process."""
    one_lammps_process_in(monkeypatch, _lammps_worker)


def one_lammps_process_in(monkeypatch, worker: _LammpsWorker) -> None:
    """:func:`one_lammps_process` with this ``monkeypatch`` (for a module fixture)."""
    import types

    from vimpact.dem import lammps

    monkeypatch.setattr(lammps, "subprocess", types.SimpleNamespace(run=worker.run))
