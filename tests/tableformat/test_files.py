"""A table hashed while Parquet encodes it is the file hashed first, byte for byte."""

import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from tests.oracles.content_hash import definition_hash
from tests.sweep import faults
from vimpact.tableformat import files, integrity

pytestmark = pytest.mark.skipif(not hasattr(pq.ParquetWriter, "add_key_value_metadata"),
                                reason="pyarrow < 17: the table is hashed before it is written")


def _table(rows: int = 3000) -> pa.Table:
    """A sweep-like table: int64, float64 with NaN and nulls, text with nulls, metadata."""
    e_x = [None if k % 7 == 0 else k / 3.0 for k in range(rows)]
    table = pa.table({
        "row": pa.array(range(rows), pa.int64()),
        "e_z": [float("nan") if k % 11 == 0 else 1.0 / (k + 1) for k in range(rows)],
        "e_x": pa.array(e_x, pa.float64()),
        "status": ["ok" if k % 5 else "invalid" for k in range(rows)],
        "error": pa.array([None if k % 5 else f"row {k}" for k in range(rows)], pa.string())})
    return table.replace_schema_metadata({b"vimpact.spec": b'{"rows": 3000}',
                                          b"other": b"kept"})


def test_hashed_while_encoded_is_the_same_file(tmp_path, monkeypatch):
    """From PARALLEL_HASH_BYTES on, write_atomic hashes the rows on a thread while Parquet
    encodes them and adds the metadata (and the Arrow schema with it) when the file is
    closed: the file equals the one written after hashing, byte for byte, and reads back
    with the same schema, metadata and hashes."""
    table = _table()
    monkeypatch.setattr(files, "PARALLEL_HASH_BYTES", 2**62)  # hashed first
    first = files.write_atomic(table, tmp_path / "first.parquet")
    monkeypatch.setattr(files, "PARALLEL_HASH_BYTES", 0)  # hashed while encoded
    called = []
    real = files._write_hashing
    monkeypatch.setattr(files, "_write_hashing", lambda *a: called.append(1) or real(*a))
    during = files.write_atomic(table, tmp_path / "during.parquet")
    assert called == [1]
    assert first == during == definition_hash(table)
    assert (tmp_path / "first.parquet").read_bytes() == (tmp_path / "during.parquet").read_bytes()
    back = pq.read_table(tmp_path / "during.parquet")
    assert back.schema.equals(table.schema) and integrity.content_hash(back) == during
    meta = back.schema.metadata
    assert meta[b"other"] == b"kept" and meta[b"vimpact.content_sha256"] == during.encode()
    integrity.check_metadata_hash(meta)
    assert integrity.verify_table(tmp_path / "during.parquet").startswith("ok: 3000 rows")
    assert not list(tmp_path.glob(".*.tmp"))


def test_hashed_while_encoded_full_disk_keeps_the_earlier_file(tmp_path, monkeypatch):
    """A full disk midway: OSError naming the file, no temporary left, the file before
    unchanged."""
    path = tmp_path / "t.parquet"
    path.write_bytes(b"earlier")
    monkeypatch.setattr(files, "PARALLEL_HASH_BYTES", 0)
    monkeypatch.setattr(files, "open", faults.FullDisk(files_ok=0, bytes_into_next=100),
                        raising=False)
    with pytest.raises(OSError, match="No space left on device while writing .*t.parquet"):
        files.write_atomic(_table(), path)
    assert path.read_bytes() == b"earlier" and not list(tmp_path.glob(".*.tmp"))
