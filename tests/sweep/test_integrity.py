"""Integrity of part files and tables: a catalogue of injected faults and the outcome
each must have.

Parts (resume): a bit flip in a data page, a damaged page header, a truncated
part, a file that is not this chunk's part -> detected, moved to
``<parts>/_corrupt/`` with one stderr line, computed again, and the table equals a
clean run's byte for byte. A part of another sweep -> refused. Final table: the
same faults -> :func:`~vimpact.tableformat.integrity.verify_table` refuses with
``InputError``; ``--resume`` writes it again. Full disk (``ENOSPC`` midway) ->
one clear error, finished parts intact, a later resume completes. A second
sweep into the same output -> refused while the first lives, allowed once it
was killed. (kill -9 of a running sweep: ``tests/sweep/test_backends.py``.)
"""

import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from tests.oracles.content_hash import definition_hash
from tests.sweep import GRID_KV, faults, write
from vimpact import cli
from vimpact.model.validation import InputError
from vimpact.sweep import parts_dir, run_sweep, store
from vimpact.sweep.spec import load_spec
from vimpact.tableformat import files, integrity, metadata

ROOT = Path(__file__).resolve().parents[2]



@pytest.fixture(scope="module")
def clean(tmp_path_factory):
    """The spec and the table of an undisturbed run: what every faulty run must end with
    (and, kept aside, the parts of all its chunks)."""
    tmp = tmp_path_factory.mktemp("clean")
    spec = write(tmp, GRID_KV.format(chunk=2))
    parts = run_sweep(spec, out=tmp / "template.parquet", shard=(0, 1), progress=False)
    names = sorted(p.name for p in parts.glob("part-*.parquet"))
    assert names == ["part-00000.parquet", "part-00001.parquet", "part-00002.parquet"]
    return spec, run_sweep(spec, out=tmp / "clean.parquet", progress=False).read_bytes()


def parts_of(spec, out):
    """The parts of all chunks in place for ``out`` (as a run killed before combining
    leaves them): a copy of the ones the fixture computed."""
    template = parts_dir(spec.parent / "template.parquet")
    parts = parts_dir(out)
    shutil.copytree(template, parts)
    return parts


def counting():
    rows = []
    return rows, lambda done, total: rows.append(done)


# ---- the content hash ----------------------------------------------------------

def test_content_hash_is_independent_of_the_parquet_encoding(tmp_path):
    table = pa.table({"row": pa.array([0, 1, 2, 3], pa.int64()),
                      "e_z": [0.5, float("nan"), -0.0, 1e-300],
                      "status": ["ok", "ok", "invalid", "ok"],
                      "error": pa.array([None, None, "nu = 0.7", None], pa.string())})
    digest = integrity.content_hash(table)
    ways = [dict(compression="zstd", row_group_size=1), dict(compression="none",
            use_dictionary=False), dict(compression="snappy", use_dictionary=True)]
    for k, options in enumerate(ways):
        pq.write_table(table, tmp_path / f"{k}.parquet", **options)
        back = pq.read_table(tmp_path / f"{k}.parquet")
        assert integrity.content_hash(back) == digest
    big = table.cast(pa.schema([("row", pa.int64()), ("e_z", pa.float64()),
                                ("status", pa.large_string()), ("error", pa.large_string())]))
    assert integrity.content_hash(big) == digest
    pieces = integrity.ContentHash()
    for batch in table.to_batches(max_chunksize=3):
        pieces.update(batch)
    assert pieces.hexdigest() == digest
    # an all-null string column equals an Arrow null column (a pandas round trip makes one)
    nulls = pa.table({"error": pa.array([None, None], pa.string())})
    assert integrity.content_hash(nulls) == integrity.content_hash(pa.table({"error": pa.nulls(2)}))


def test_content_hash_follows_its_definition_with_and_without_nulls():
    """Columns with and without nulls (the latter hashed from their buffers as they
    are), several Arrow chunks, a slice at an offset: the digest of the definition."""
    table = pa.table({"row": pa.array(range(7), pa.int64()),
                      "e_z": [0.5, float("nan"), -0.0, 1e-300, 2.0, float("inf"), 3.0],
                      "e_x": [0.5, None, 1.0, None, 2.0, 0.0, None],
                      "ok": [True, False, None, True, True, False, True],
                      "status": ["ok", "ok", "invalid", None, "ok", "", "half_space"]})
    two_chunks = pa.concat_tables([table.slice(0, 3), table.slice(3)])
    for t in (table, two_chunks, table.slice(2, 4), two_chunks.slice(1, 5), table.slice(7)):
        assert integrity.content_hash(t) == definition_hash(t)


@pytest.mark.parametrize("shared_rows", [1, 4, 10**9], ids=["always", "mixed", "never"])
def test_content_hash_of_equal_columns_hashed_once_follows_its_definition(monkeypatch,
                                                                          shared_rows):
    """Streams fed the same bytes are hashed once and copied: columns equal throughout
    (zeros, NaN, a repeated string), equal in the first rows only, equal from a later
    piece on after differing before, a NaN of another payload, the same values in int64
    and float64 bytes, nulls in one of two otherwise equal columns; hashed whole, in
    pieces cut in several ways (pieces below ``SHARED_STREAM_ROWS`` rows fed stream by
    stream between shared ones), and as two hashes at once: the definition's digest."""
    monkeypatch.setattr(integrity, "SHARED_STREAM_ROWS", shared_rows)
    n = 12
    zeros, nan = np.zeros(n), np.full(n, np.nan)
    other_nan = nan.view(np.uint64).copy()
    other_nan[5] |= 1  # another NaN payload in one row: other bytes
    later = np.where(np.arange(n) < 5, np.arange(n, dtype=float), 0.0)  # = zeros from row 5
    first = np.where(np.arange(n) < 7, 0.0, 1.0)  # = zeros in rows 0..6 only
    short = np.where(np.arange(n) < 3, np.arange(n) + 1.0, 0.0)  # = zeros from row 3
    table = pa.table({
        "a": zeros, "b": zeros.copy(), "c": nan, "d": nan.copy(),
        "e": other_nan.view(np.float64), "f": later, "g": first, "h": later.copy(),
        "k": short,
        "i": pa.array(np.zeros(n, dtype=np.int64)), "j": pa.array([0.0] * 11 + [None]),
        "s": pa.array(["ok"] * n, pa.string()), "t": pa.array(["ok"] * n, pa.string()),
        "u": pa.array(["ok"] * 6 + [None] * 6, pa.string()),
        "w": pa.array([None] * n, pa.string())})
    digest = definition_hash(table)
    assert integrity.content_hash(table) == digest
    for cuts in ([0, 5, n], [0, 3, 7, 8, n], list(range(n + 1)), [0, 7, n], [0, 3, n]):
        pieces, also = integrity.ContentHash(), integrity.ContentHash()
        for lo, hi in zip(cuts[:-1], cuts[1:]):
            pieces.update(table.slice(lo, hi - lo), also=also if lo else None)
        assert pieces.hexdigest() == digest, cuts
        assert also.hexdigest() == definition_hash(table.slice(cuts[1])), cuts
    # the same digest on several hashing threads (streams fed side by side)
    monkeypatch.setattr(integrity, "PARALLEL_HASH_BYTES", 0)
    assert integrity._hash_threads(1) > 1 or integrity.MAX_HASH_THREADS == 1 \
        or len(integrity.os.sched_getaffinity(0)) == 1
    assert integrity.ContentHash().update(table, threads=4).hexdigest() == digest


@pytest.mark.parametrize("change", ["value", "nan payload", "null", "string", "name", "order"])
def test_content_hash_sees_every_change(change):
    table = pa.table({"a": [1.0, 2.0], "s": pa.array(["x", None], pa.string())})
    other = {
        "value": lambda: pa.table({"a": [1.0, 2.0000000000000004], "s": table["s"]}),
        "nan payload": lambda: pa.table({"a": [1.0, 2.0], "s": table["s"]}).set_column(
            0, "a", pa.array([float("nan"), 2.0])),
        "null": lambda: pa.table({"a": [1.0, 2.0], "s": pa.array(["x", ""], pa.string())}),
        "string": lambda: pa.table({"a": [1.0, 2.0], "s": pa.array(["y", None], pa.string())}),
        "name": lambda: pa.table({"b": [1.0, 2.0], "s": table["s"]}),
        "order": lambda: pa.table({"a": [2.0, 1.0], "s": table["s"]}),
    }[change]()
    assert integrity.content_hash(other) != integrity.content_hash(table)


def test_parts_and_tables_carry_checksums_and_hash(tmp_path, clean):
    spec, clean_bytes = clean
    parts = parts_of(spec, tmp_path / "t.parquet")
    for part in parts.glob("part-*.parquet"):
        meta = metadata.read_metadata(part)
        assert meta["content_sha256"] == integrity.content_hash(pq.read_table(part))
        assert store.verify_part(part, load_spec(spec)) is None
    out = run_sweep(spec, out=tmp_path / "t.parquet", resume=True, progress=False)
    assert out.read_bytes() == clean_bytes
    assert integrity.verify_table(out).endswith("content hash verified")
    assert metadata.read_metadata(out)["content_sha256"] == integrity.content_hash(pq.read_table(out))
    # the checksums are there: the same flip that passes an unchecked read is caught
    offset, bit = faults.flip_in_data_page(out, "e_z", seed=3)
    with pytest.raises(OSError, match="CRC|checksum"):
        pq.read_table(out, page_checksum_verification=True)


# ---- faults in a part, then --resume --------------------------------------------------

def rewrite(path, table):
    pq.write_table(table, path, write_page_checksum=True)


def changed_value(path):
    """One e_z value changed, the metadata (with both hashes) kept: a value changed after
    it was hashed, in pages with valid checksums."""
    table = pq.read_table(path)
    e_z = table["e_z"].to_pylist()
    e_z[0] += 2.2e-3
    rewrite(path, table.set_column(table.schema.get_field_index("e_z"), "e_z",
                                   pa.array(e_z)).replace_schema_metadata(table.schema.metadata))


def changed_metadata(key, value):
    """A ``vimpact.<key>`` entry changed, everything else (and the stored hashes) kept."""
    def damage(path):
        table = pq.read_table(path)
        meta = dict(table.schema.metadata)
        meta[f"vimpact.{key}".encode()] = value(meta[f"vimpact.{key}".encode()])
        rewrite(path, table.replace_schema_metadata(meta))
    return damage


def one_bit(text: bytes) -> bytes:
    return bytes([text[0] ^ 1]) + text[1:]


def other_chunk(path):
    """Part 1 copied over this part: a vimpact part of this sweep, the wrong chunk."""
    path.write_bytes((path.parent / "part-00001.parquet").read_bytes())


PART_FAULTS = {
    "bit flip in e_z data page, seed 0": lambda p: faults.flip_in_data_page(p, "e_z", seed=0),
    "bit flip in e_z data page, seed 1": lambda p: faults.flip_in_data_page(p, "e_z", seed=1),
    "bit flip in e_z data page, seed 2": lambda p: faults.flip_in_data_page(p, "e_z", seed=2),
    "bit flip in beta_x data page": lambda p: faults.flip_in_data_page(p, "beta_x", seed=4),
    "bit flip in status data page": lambda p: faults.flip_in_data_page(p, "status", seed=5),
    "bit flip in row data page": lambda p: faults.flip_in_data_page(p, "row", seed=6),
    # text columns are dictionary-encoded (numbers plain: files.parquet_options)
    "bit flip in status dictionary page (the values)":
        lambda p: faults.flip_in_data_page(p, "status", seed=7, page="dictionary"),
    "bit flip in path dictionary page (the values)":
        lambda p: faults.flip_in_data_page(p, "path", seed=8, page="dictionary"),
    "damaged page header of e_z (sizes)": lambda p: faults.damage_page_header(p, "e_z"),
    "damaged page header of row (page type)":
        lambda p: faults.damage_page_header(p, "row", pattern=b"\x06"),
    "truncated to half": lambda p: faults.truncate(p, 0.5),
    "truncated by one byte": lambda p: faults.truncate(p, 1 - 1 / p.stat().st_size),
    "truncated to nothing": lambda p: faults.truncate(p, 0.0),
    "non-vimpact Parquet file": faults.write_foreign_parquet,
    "not Parquet at all": lambda p: p.write_bytes(b"PAR1 this is not a Parquet file\n"),
    "another chunk's part": other_chunk,
    "a value changed after hashing": changed_value,
    "one bit of its sweep hash (else it would pass for another sweep's)":
        changed_metadata("sweep_hash", one_bit),
    "its row counts changed": changed_metadata("counts", lambda v: v.replace(b"2", b"3")),
}


@pytest.mark.parametrize("fault", list(PART_FAULTS))
def test_damaged_part_is_moved_aside_and_recomputed(tmp_path, clean, capsys, fault):
    spec, clean_bytes = clean
    out = tmp_path / "t.parquet"
    parts = parts_of(spec, out)
    victim = parts / ("part-00002.parquet" if fault == "another chunk's part"
                      else "part-00001.parquet")
    original = victim.read_bytes()
    PART_FAULTS[fault](victim)
    assert victim.read_bytes() != original
    reason = store.verify_part(victim, load_spec(spec))
    assert reason, f"{fault}: not detected"
    capsys.readouterr()
    rows, progress = counting()
    assert run_sweep(spec, out=out, resume=True, progress=progress) == out
    assert rows == [6]  # the two good chunks (4 rows) kept, the damaged one (2 rows) computed
    assert out.read_bytes() == clean_bytes
    warnings = [line for line in capsys.readouterr().err.splitlines() if victim.name in line]
    assert len(warnings) == 1 and "computing it again" in warnings[0] and reason in warnings[0]
    kept = parts / store.CORRUPT_DIR / victim.name
    assert kept.read_bytes() != original  # moved aside as it was, never deleted
    assert sorted(p.name for p in parts.rglob("*")) == [store.CORRUPT_DIR, victim.name]


def test_cli_resume_reports_the_damaged_part_on_one_line(tmp_path, clean, capsys):
    spec, clean_bytes = clean
    out = tmp_path / "cli.parquet"
    parts = parts_of(spec, out)
    faults.flip_in_data_page(parts / "part-00000.parquet", "e_z", seed=9)
    capsys.readouterr()
    assert cli.main(["sweep", str(spec), "--out", str(out), "--resume"]) == 0
    err = [line for line in capsys.readouterr().err.splitlines() if "part-00000" in line]
    assert len(err) == 1 and ("checksum" in err[0] or "hash" in err[0]), err
    assert out.read_bytes() == clean_bytes


def test_a_part_of_another_sweep_is_refused(tmp_path, clean):
    spec, _ = clean
    out = tmp_path / "t.parquet"
    parts = parts_of(spec, out)
    other = write(tmp_path, GRID_KV.format(chunk=2).replace("steps = 100", "steps = 101"), "other.toml")
    other_parts = run_sweep(other, out=tmp_path / "other.parquet", shard=(0, 1), progress=False)
    foreign = (other_parts / "part-00001.parquet").read_bytes()
    (parts / "part-00001.parquet").write_bytes(foreign)
    with pytest.raises(ValueError, match="another sweep") as info:
        run_sweep(spec, out=out, resume=True, progress=False)
    assert "part-00001.parquet" in str(info.value) and "remove" in str(info.value)
    assert (parts / "part-00001.parquet").read_bytes() == foreign  # left as it was
    assert not out.exists()


@pytest.mark.parametrize("seed", range(24))
def test_a_bit_flip_anywhere_in_a_part_is_caught_or_harmless(tmp_path, clean, seed):
    """Catalogue over the whole file (pages, headers, footer, metadata): a flip is
    detected (the part is computed again), refused (the sweep hash was hit: the part
    looks like another sweep's), or harmless (the data reads back unchanged)."""
    import random
    spec, _ = clean
    parts = parts_of(spec, tmp_path / "t.parquet")
    part = parts / "part-00001.parquet"
    before = pq.read_table(part)
    rng = random.Random(seed)
    faults.flip_bit(part, rng.randrange(part.stat().st_size), rng.randrange(8))
    kind, why = store._check_part(part, load_spec(spec))
    if kind == "ok":
        pd.testing.assert_frame_equal(pq.read_table(part).to_pandas(), before.to_pandas())
    else:
        assert kind in ("bad", "foreign") and why


# ---- the final table ---------------------------------------------------------------

TABLE_FAULTS = {
    "bit flip in e_z data page": (lambda p: faults.flip_in_data_page(p, "e_z", seed=0),
                                  "checksum"),
    "bit flip in e_z data page of the last row group":
        (lambda p: faults.flip_in_data_page(p, "e_z", seed=1, row_group=2), "row group 2"),
    "damaged page header": (lambda p: faults.damage_page_header(p, "e_z"), "row group 0"),
    "a value changed after hashing": (changed_value, "content hash mismatch"),
    "units changed": (changed_metadata("units", lambda v: v.replace(b'"Pa"', b'"kPa"')),
                      "metadata hash mismatch"),
    "stored content hash changed": (changed_metadata("content_sha256", one_bit),
                                    "metadata hash mismatch"),
    "truncated": (lambda p: faults.truncate(p, 0.9), "truncated"),
    "empty": (lambda p: faults.truncate(p, 0.0), "empty"),
    "not a vimpact table": (faults.write_foreign_parquet, "not a vimpact table"),
}


@pytest.mark.parametrize("fault", list(TABLE_FAULTS))
def test_verify_table_refuses_a_damaged_table(tmp_path, clean, fault):
    spec, clean_bytes = clean
    out = tmp_path / "t.parquet"
    out.write_bytes(clean_bytes)
    assert integrity.verify_table(out).startswith("ok: 6 rows, 3 row group(s)")
    damage, what = TABLE_FAULTS[fault]
    damage(out)
    with pytest.raises(InputError) as info:
        integrity.verify_table(out)
    message = str(info.value)
    assert str(out) in message and what in message and "\n" not in message


def test_table_info_refuses_a_damaged_table(tmp_path, clean, capsys):
    """What the user runs: ``vimpact table info`` on the clean table, then on a flipped one."""
    _, clean_bytes = clean
    out = tmp_path / "t.parquet"
    out.write_bytes(clean_bytes)
    assert cli.main(["table", "info", str(out)]) == 0
    capsys.readouterr()
    faults.flip_in_data_page(out, "e_z", seed=1)
    assert cli.main(["table", "info", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and str(out) in err[0] and "checksum" in err[0]


def test_resume_rewrites_a_damaged_final_table(tmp_path, clean, capsys):
    spec, clean_bytes = clean
    out = tmp_path / "t.parquet"
    out.write_bytes(clean_bytes)
    faults.flip_in_data_page(out, "e_z", seed=2)
    damaged = out.read_bytes()
    rows, progress = counting()
    assert run_sweep(spec, out=out, resume=True, progress=progress) == out
    assert rows == [2, 4, 6] and out.read_bytes() == clean_bytes
    assert out.with_name("t.parquet.corrupt").read_bytes() == damaged
    assert "t.parquet" in capsys.readouterr().err


def test_a_table_without_a_hash_is_accepted_with_the_check_skipped(tmp_path, clean):
    spec, clean_bytes = clean
    (tmp_path / "new.parquet").write_bytes(clean_bytes)
    table = pq.read_table(tmp_path / "new.parquet")
    meta = {k: v for k, v in table.schema.metadata.items()
            if k not in (b"vimpact.content_sha256", b"vimpact.metadata_sha256")}
    old = tmp_path / "old.parquet"
    pq.write_table(table.replace_schema_metadata(meta), old)  # as vimpact wrote before
    assert integrity.verify_table(old).endswith("hash check skipped")
    assert store.is_complete(load_spec(spec), old)


def test_the_shipped_tables_pass(tmp_path):
    """Every shipped table reads back with its content hash. ``once``: a table the
    session's lookup tests opened (which verifies it in full) is not hashed a second
    time if the file is unchanged since (tests/lookup/test_open_cost.py checks that a
    file changed after that first check is still refused)."""
    shipped = sorted((ROOT / "sweeps" / "tables").glob("*.parquet"))
    assert shipped
    for table in shipped:
        text = integrity.verify_table(table, once=True)
        assert text.startswith("ok:") and "content hash verified" in text, text


def test_dataset_layout_damaged_part_is_refused_then_recomputed(tmp_path, clean, capsys):
    spec, clean_bytes = clean
    ds_spec = write(tmp_path, 'layout = "dataset"\n' + GRID_KV.format(chunk=2), "dataset.toml")
    out = run_sweep(ds_spec, out=tmp_path / "ds.parquet", progress=False)
    assert integrity.verify_table(out).endswith("content hash verified")
    (tmp_path / "clean.parquet").write_bytes(clean_bytes)
    pd.testing.assert_frame_equal(pd.read_parquet(out), pd.read_parquet(tmp_path / "clean.parquet"))
    # one hash for the same rows, whether one file or a dataset of parts
    assert metadata.read_metadata(out)["content_sha256"] \
        == metadata.read_metadata(tmp_path / "clean.parquet")["content_sha256"]
    faults.flip_in_data_page(out / "part-00001.parquet", "e_z", seed=0)
    with pytest.raises(InputError, match="part-00001.parquet"):
        integrity.verify_table(out)
    rows, progress = counting()
    assert run_sweep(ds_spec, out=out, resume=True, progress=progress) == out
    assert rows == [6]
    assert integrity.verify_table(out).endswith("content hash verified")
    assert (out / store.CORRUPT_DIR / "part-00001.parquet").exists()
    # a stray file in the dataset would be read as rows: refused, by name
    faults.write_foreign_parquet(out / "stray.parquet")
    with pytest.raises(InputError, match="stray.parquet"):
        integrity.verify_table(out)


# ---- full disk --------------------------------------------------------------------

@pytest.mark.parametrize("files_ok, what", [(1, "a part"), (3, "the table")])
def test_full_disk_one_clear_error_then_resume(tmp_path, clean, monkeypatch, capsys, files_ok,
                                               what):
    """The disk fills up midway through writing the second part, or the final table."""
    spec, clean_bytes = clean
    out = tmp_path / "t.parquet"
    disk = faults.FullDisk(files_ok=files_ok, bytes_into_next=100)
    monkeypatch.setattr(files, "open", disk, raising=False)
    assert cli.main(["sweep", str(spec), "--out", str(out)]) == 2
    err = [line for line in capsys.readouterr().err.splitlines() if "rows/s" not in line]
    assert len(err) == 1 and "No space left on device" in err[0] and "--resume" in err[0]
    assert disk.failures >= 1
    parts = parts_dir(out)
    assert not out.exists() and not list(tmp_path.glob(".*.tmp"))
    assert not list(parts.glob(".*.tmp"))
    kept = sorted(parts.glob("part-*.parquet"))
    assert len(kept) == (1 if what == "a part" else 3)
    for part in kept:  # intact
        assert store.verify_part(part, load_spec(spec)) is None
    monkeypatch.undo()
    capsys.readouterr()
    assert cli.main(["sweep", str(spec), "--out", str(out), "--resume"]) == 0
    assert out.read_bytes() == clean_bytes


# ---- a second sweep into the same output -------------------------------------------

HOLD = """
import sys, time
from vimpact.tableformat.files import OutputLock
with OutputLock(sys.argv[1]):
    print("locked", flush=True)
    time.sleep(60)
"""


def test_a_second_process_is_refused_until_the_first_is_killed(tmp_path, clean, capsys):
    spec, clean_bytes = clean
    out = tmp_path / "t.parquet"
    holder = subprocess.Popen([sys.executable, "-c", HOLD, str(out)], cwd=ROOT,
                              stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "locked"
        for extra in ([], ["--resume"]):
            assert cli.main(["sweep", str(spec), "--out", str(out), *extra]) == 2
            err = capsys.readouterr().err
            assert "another sweep is writing" in err and f"pid {holder.pid}" in err
        with pytest.raises(ValueError, match="another sweep is writing"):
            run_sweep(spec, out=out, progress=False)
    finally:
        holder.kill()  # SIGKILL: no clean-up in the holder
        holder.wait()
    assert out.with_name("t.parquet.lock").exists()  # left behind, but nobody holds it
    assert cli.main(["sweep", str(spec), "--out", str(out)]) == 0
    assert out.read_bytes() == clean_bytes
