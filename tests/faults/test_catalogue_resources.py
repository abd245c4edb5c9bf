"""Resources and places a sweep may use.

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
from pathlib import Path

import pytest

from vimpact.cli.main import main
from vimpact.sweep import runner

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


#: the handshake timeout of the silent service's case (the default, SCHEDULER_TIMEOUT_S, is 5 s:
#: the refusal is the same, sooner)
SILENT_TIMEOUT_S = 1.0


@pytest.mark.parametrize("case", ["refused", "unknown-host", "http", "silent", "no-port",
                                  "port-range"])
def test_scheduler_that_does_not_answer_is_one_line_and_leaves_nothing(tmp_path, capsys, case,
                                                                        monkeypatch):
    pytest.importorskip("distributed")
    service = FakeService(case) if case in ("http", "silent") else None
    if case == "silent":  # nothing answers: the probe waits out connect_scheduler's timeout
        connect = runner.connect_scheduler
        monkeypatch.setattr(runner, "connect_scheduler",
                            lambda address: connect(address, timeout=SILENT_TIMEOUT_S))
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
    if case == "silent":
        assert f"gave no answer within {SILENT_TIMEOUT_S:g} s" in err, err
    nothing_written(tmp_path, "s.toml")


# ---- item 5: no symlink followed, nothing written outside the named output -----------

def victim(tmp_path: Path) -> Path:
    """A file outside the output that a symbolic link points to; must stay as it is."""
    target = tmp_path / "elsewhere" / "precious.txt"
    target.parent.mkdir()
    target.write_text("keep me")
    return target


@pytest.mark.parametrize("link", ["out.parquet", "out.parquet.lock", "out.parquet.parts"])
def test_sweep_refuses_a_symlink_where_it_writes(tmp_path, capsys, link):
    target = victim(tmp_path)
    (tmp_path / link).symlink_to(target if link != "out.parquet.parts" else target.parent)
    out = tmp_path / "out.parquet"
    code, _, err = run(["sweep", str(sweep_spec(tmp_path)), "--out", str(out)], capsys)
    one_line(code, err, f"--out = {str(out)!r}", "symbolic link")
    assert target.read_text() == "keep me" and sorted(p.name for p in target.parent.iterdir()) \
        == ["precious.txt"]


def test_lock_file_is_not_followed_even_past_the_check(tmp_path, monkeypatch):
    """The lock is opened with O_NOFOLLOW: a link made after the lstat check (here: the
    check switched off) is still not followed."""
    import errno

    from vimpact.tableformat import files
    target = victim(tmp_path)
    lock = files.OutputLock(tmp_path / "out.parquet")
    lock.path.symlink_to(target)
    monkeypatch.setattr(files, "refuse_symlink", lambda *a, **k: None)
    with pytest.raises(OSError) as info:
        lock._open()
    assert info.value.errno == errno.ELOOP and target.read_text() == "keep me"


def test_atomic_file_never_writes_through_a_planted_temporary(tmp_path):
    """A symbolic link planted at the temporary name is replaced, not written through."""
    from vimpact.tableformat import files
    target = victim(tmp_path)
    out = tmp_path / "t.csv"
    files._temporary(out).symlink_to(target)
    with files.atomic_file(out, "out", mode="w") as f:
        f.write("new")
    assert out.read_text() == "new" and target.read_text() == "keep me"
    assert not out.is_symlink() and not files._temporary(out).exists()


@pytest.mark.parametrize("output", ["../escaped.parquet", "sub/../../escaped.parquet",
                                    "/tmp/vimpact-escaped.parquet"])
def test_spec_output_stays_in_the_spec_folder(tmp_path, capsys, output):
    folder = tmp_path / "specs"
    folder.mkdir()
    code, _, err = run(["sweep", str(sweep_spec(folder, output))], capsys)
    one_line(code, err, f"output = {output!r}", "--out")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["specs"]
    nothing_written(folder, "s.toml")
    assert not Path("/tmp/vimpact-escaped.parquet").exists()


def test_plot_refuses_a_symlinked_out(tmp_path, capsys):
    target = victim(tmp_path)
    (tmp_path / "fig.png").symlink_to(target)
    code, _, err = run(["plot", "fig3_2", "--out", str(tmp_path / "fig.png")], capsys)
    one_line(code, err, "--out = ", "symbolic link")
    assert target.read_text() == "keep me"


def test_table_export_refuses_a_symlinked_out(tmp_path, capsys):
    from tests.lookup.test_table import make_table
    table = tmp_path / "kv.parquet"
    make_table(table, Q1=[0.01, 0.1, 1.0], nu=(0.3, 0.5))
    target = victim(tmp_path)
    (tmp_path / "curve.csv").symlink_to(target)
    code, _, err = run(["table", "export", str(table), "--out", str(tmp_path / "curve.csv"),
                        "--E", "1e8", "--nu", "0.4", "--eta", "100", "--R", "0.01", "--m",
                        "0.004", "--vz0-min", "0.1", "--vz0-max", "1", "--n", "3"], capsys)
    one_line(code, err, "--out = ", "symbolic link")
    assert target.read_text() == "keep me"


# ---- item 6: shards take a lock that a plain run respects -----------------------------

def test_plain_run_is_refused_while_shards_run_and_the_other_way(tmp_path, capsys, monkeypatch):
    from vimpact.tableformat import files
    # a shard waits this long for a lock held exclusively before it is refused (the
    # refusal is the same after any wait; 2 s by default)
    monkeypatch.setattr(files.OutputLock, "SHARED_WAIT_S", 0.1)
    spec, out = str(sweep_spec(tmp_path)), tmp_path / "out.parquet"
    with files.OutputLock(out, shared=True), files.OutputLock(out, shared=True):  # 2 shards
        code, _, err = run(["sweep", spec, "--out", str(out)], capsys)
        one_line(code, err, "another sweep is writing", "--shard")
        code, _, err = run(["sweep", spec, "--out", str(out), "--combine"], capsys)
        one_line(code, err, "another sweep is writing")
    with files.OutputLock(out):  # a plain run
        code, _, err = run(["sweep", spec, "--out", str(out), "--shard", "0/2"], capsys)
        one_line(code, err, "another sweep is writing", "pid")
    nothing_written(tmp_path, "s.toml")


def test_a_failed_part_write_says_make_room_only_for_a_full_disk(tmp_path):
    import errno

    from vimpact.sweep import load_spec, store
    spec = load_spec(sweep_spec(tmp_path))
    table = spec.schema().empty_table()
    with pytest.raises(OSError) as info:  # the parts folder is gone (removed by another run)
        store.write_part(spec, table, tmp_path / "gone", 0, {"counts": {}, "paths": {}})
    assert "make room" not in str(info.value) and "--resume" in str(info.value)
    full = store._kept(OSError(errno.ENOSPC, "No space left on device"), tmp_path)
    assert "make room" in str(full)


# ---- item 10: the end of a file-layout sweep needs room for the table and its parts ---

def test_combine_without_room_for_table_and_parts_is_refused_up_front(tmp_path, capsys,
                                                                      monkeypatch):
    """The combined table is written while its parts exist (they go only after it is
    verified): with less free disk than the parts' size the combination is refused
    before it writes, says how much it needs, and keeps the parts."""
    import shutil as real

    from vimpact.sweep import store
    spec, out = str(sweep_spec(tmp_path)), tmp_path / "out.parquet"
    assert run(["sweep", spec, "--out", str(out), "--shard", "0/1"], capsys)[0] == 0
    parts = sorted(store.parts_dir(out).glob("part-*.parquet"))
    size = sum(p.stat().st_size for p in parts)
    usage = real.disk_usage(tmp_path)
    monkeypatch.setattr(store.shutil, "disk_usage",
                        lambda p: usage._replace(free=size // 2))  # half the parts' size
    code, _, err = run(["sweep", spec, "--out", str(out), "--combine"], capsys)
    one_line(code, err, "not enough free disk", "MiB", "--resume")
    assert not out.exists() and sorted(store.parts_dir(out).glob("part-*.parquet")) == parts
    monkeypatch.undo()
    code, stdout, err = run(["sweep", spec, "--out", str(out), "--combine"], capsys)
    assert code == 0 and out.is_file() and not store.parts_dir(out).exists()


def test_simulate_trajectory_refuses_a_symlink(tmp_path, capsys):
    target = victim(tmp_path)
    (tmp_path / "traj.csv").symlink_to(target)
    code, _, err = run(["simulate", "--Q1", "0.1", "--nu", "0.5", "--trajectory",
                        str(tmp_path / "traj.csv")], capsys)
    one_line(code, err, "--trajectory = ", "symbolic link")
    assert target.read_text() == "keep me"


# ---- rows and chunks bounded before anything starts ---------------------------------

@pytest.mark.parametrize("top, words", [
    ("chunk_size = 64\nrows = 1000000000000", ["chunk_size = 64", "at least 1000000"]),
    ("chunk_size = 100000000\nrows = 1000", ["chunk_size = 100000000", "at most 1000000"]),
])
def test_chunk_count_and_size_are_bounded(tmp_path, capsys, top, words):
    """Before: 1e12 rows in chunks of 64 listed 1.6e10 chunks in memory (MemoryError)."""
    chunk, rows = top.split("\n")
    spec = tmp_path / "s.toml"
    spec.write_text(f'model = "kelvin_voigt"\nseed = 1\n{chunk}\n[random]\n{rows}\n'
                    "E_Pa = 1e7\neta_Pa_s = 1.0\nR_m = 0.1\nm_kg = 1.0\nv_z0_m_s = 1.0\n"
                    "nu = 0.5\n")
    code, _, err = run(["sweep", str(spec)], capsys)
    one_line(code, err, "s.toml", *words)
    nothing_written(tmp_path, "s.toml")
