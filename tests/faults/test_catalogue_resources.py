"""Issue 26: resources and places a sweep may use.

- ``--workers`` is bounded by the machine (cores and available memory), checked
  before anything starts;
- ``--scheduler`` at a refused port, an unknown host or a service that is not a
  Dask scheduler fails with one line naming ``--scheduler`` after a short
  handshake, and leaves nothing behind (no ``OUT.parts``, no ``OUT.lock``);
- nothing a sweep or an export creates follows a symlink, and nothing is
  written outside the output the user named;
- shards take a lock that a plain run into the same output respects.

Every case stops before a kernel runs, except the shard cases, which run the
tiny sweep of docs/howto (its kernels are compiled by the docs tests).
"""

from __future__ import annotations

import socket
import threading
import time
from pathlib import Path

import pytest

from vimpact.cli.main import main
from vimpact.sweep import runner

ROOT = Path(__file__).resolve().parents[2]

SPEC = """model = "kelvin_voigt"
chunk_size = 4
numerics = "fast"
[grid]
Q1 = [0.01, 0.1, 1.0]
nu = [0.3, 0.5]
"""


def sweep_spec(tmp_path: Path, output: str | None = None) -> Path:
    path = tmp_path / "s.toml"
    path.write_text((f'output = "{output}"\n' if output else "") + SPEC)
    return path


def run(argv, capsys) -> tuple[int, str, str]:
    try:
        code = main(argv)
    except SystemExit as exc:
        code = exc.code
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def one_line(code: int, err: str, *words: str) -> None:
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err, err
    for word in words:
        assert word in lines[0], (word, lines[0])


def nothing_written(folder: Path, *keep: str) -> None:
    left = sorted(p.name for p in folder.iterdir() if p.name not in keep)
    assert left == [], left


# ---- item 1: --workers bounded by the machine -------------------------------------

@pytest.mark.parametrize("workers", ["1000000000", "100000"])
def test_workers_beyond_the_machine_are_refused_before_work(tmp_path, capsys, workers):
    code, out, err = run(["sweep", str(sweep_spec(tmp_path)), "--workers", workers], capsys)
    one_line(code, err, f"--workers = {workers}", "cores")
    nothing_written(tmp_path, "s.toml")


def test_workers_bound_follows_cores_and_memory(monkeypatch):
    monkeypatch.setattr(runner, "_usable_cores", lambda: 2)
    monkeypatch.setattr(runner, "_available_memory", lambda: 100 * 2**30)
    assert runner.max_local_workers()[0] == 2 * runner.WORKERS_PER_CORE
    monkeypatch.setattr(runner, "_available_memory", lambda: 3 * runner.WORKER_MEMORY_BYTES)
    assert runner.max_local_workers()[0] == 3
    monkeypatch.setattr(runner, "_available_memory", lambda: 1000)
    assert runner.max_local_workers()[0] == 1  # one worker is always allowed
    with pytest.raises(ValueError, match="--workers = 2 is not allowed"):
        runner.check_workers(2)


# ---- item 2: --scheduler that is not a scheduler ------------------------------------

class FakeService:
    """A TCP service on 127.0.0.1 that is not Dask: it answers with HTTP text, or says
    nothing and keeps the connection open."""

    def __init__(self, mode: str):
        self.sock = socket.socket()
        self.sock.bind(("127.0.0.1", 0))
        self.sock.listen(8)
        self.mode, self.conns = mode, []
        self.address = f"tcp://127.0.0.1:{self.sock.getsockname()[1]}"
        threading.Thread(target=self._serve, daemon=True).start()

    def _serve(self):
        while True:
            try:
                conn, _ = self.sock.accept()
            except OSError:
                return
            if self.mode == "http":
                conn.sendall(b"HTTP/1.1 400 Bad Request\r\nContent-Length: 0\r\n\r\n" * 3)
            self.conns.append(conn)

    def close(self):
        self.sock.close()
        for conn in self.conns:
            conn.close()


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def run_guarded(argv, capsys, limit_s: float = 120.0):
    """``run`` in a thread: a hang (before: past 120 s) fails the test instead of
    stalling the run."""
    result = {}
    thread = threading.Thread(target=lambda: result.update(r=run(argv, capsys)), daemon=True)
    thread.start()
    thread.join(limit_s)
    assert not thread.is_alive(), f"vimpact {' '.join(argv)} still running after {limit_s} s"
    return result["r"]


@pytest.mark.parametrize("case", ["refused", "unknown-host", "http", "silent", "no-port",
                                  "port-range"])
def test_scheduler_that_does_not_answer_is_one_line_and_leaves_nothing(tmp_path, capsys, case):
    pytest.importorskip("distributed")
    service = FakeService(case) if case in ("http", "silent") else None
    address = {"refused": f"tcp://127.0.0.1:{free_port()}",
               "unknown-host": "tcp://no-such-host.invalid:8786",
               "no-port": "tcp://127.0.0.1", "port-range": "tcp://127.0.0.1:99999"}.get(
        case, service.address if service else None)
    try:
        code, out, err = run_guarded(["sweep", str(sweep_spec(tmp_path)), "--scheduler",
                                      address], capsys)
    finally:
        if service is not None:
            service.close()
    one_line(code, err, f"--scheduler = {address!r}")
    assert "EiB" not in err
    nothing_written(tmp_path, "s.toml")
