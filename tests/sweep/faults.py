"""Fault injection for Parquet part files and tables: bit flips in data pages, damaged
page headers, truncation, foreign files, and a disk that fills up while writing.

Byte positions come from the file's own footer (``pyarrow.parquet`` column chunk
metadata), so a fault lands where it is meant to whatever the encoding:

- a column chunk starts with its first page header (at ``dictionary_page_offset``
  if there is a dictionary page, else ``data_page_offset``) and ends
  ``total_compressed_size`` bytes later; each page is a Thrift header (sizes,
  CRC, statistics) followed by ``compressed_page_size`` bytes of page data, which
  the CRC covers (the statistics in the header are not data);
- the footer (schema, key-value metadata, row group metadata) sits before the
  last 8 bytes (footer length + ``PAR1``).
"""

from __future__ import annotations

import errno
import io
import random
from dataclasses import dataclass
from pathlib import Path

import pyarrow.parquet as pq


@dataclass(frozen=True)
class Span:
    """Bytes ``start .. stop-1`` of a file."""
    start: int
    stop: int


@dataclass(frozen=True)
class ColumnChunk:
    """Where a column chunk's pages lie: its whole span, the header of its data page and
    the data (the compressed values, covered by the page CRC) of its data page and of
    its dictionary page (``None`` without one). Assumes one data page per chunk (the
    small test tables here have one)."""
    span: Span
    data_header: int
    data: Span
    dictionary: Span | None


def _compressed_page_size(path: Path, header: int) -> int:
    """``compressed_page_size`` (field 3) of the Thrift compact page header at
    ``header``: fields 1-3 are i32 varints in order (type, uncompressed, compressed)."""
    with open(path, "rb") as f:
        f.seek(header)
        raw = f.read(32)
    pos, values = 0, []
    for _field in (1, 2, 3):
        assert raw[pos] == (1 << 4) | 5, f"unexpected page header byte at {header + pos}"
        pos += 1
        shift = value = 0
        while True:
            byte = raw[pos]
            pos += 1
            value |= (byte & 0x7F) << shift
            shift += 7
            if not byte & 0x80:
                break
        values.append((value >> 1) ^ -(value & 1))  # zigzag
    return values[2]


def column_chunk(path: Path, column: str, row_group: int = 0) -> ColumnChunk:
    """Where the column chunk of ``column`` in ``row_group`` lies in the file."""
    meta = pq.ParquetFile(path).metadata
    group = meta.row_group(row_group)
    names = [group.column(i).path_in_schema for i in range(group.num_columns)]
    chunk = group.column(names.index(column))
    start = data_header = chunk.data_page_offset
    dictionary = None
    if chunk.has_dictionary_page and chunk.dictionary_page_offset is not None:
        start = chunk.dictionary_page_offset
        size = _compressed_page_size(path, start)
        dictionary = Span(data_header - size, data_header)
    stop = start + chunk.total_compressed_size
    data = Span(stop - _compressed_page_size(path, data_header), stop)
    assert data.start > data_header
    return ColumnChunk(Span(start, stop), data_header, data, dictionary)


def flip_bit(path: Path, offset: int, bit: int = 0) -> None:
    """Invert bit ``bit`` (0..7) of the byte at ``offset`` of ``path``, in place."""
    with open(path, "r+b") as f:
        f.seek(offset)
        byte = f.read(1)
        assert len(byte) == 1, f"offset {offset} is beyond the end of {path}"
        f.seek(offset)
        f.write(bytes([byte[0] ^ (1 << bit)]))


def flip_in_data_page(path: Path, column: str = "e_z", seed: int = 0, row_group: int = 0,
                      page: str = "data") -> tuple[int, int]:
    """Flip one random bit in the page data (past the header) of the data page
    (``page="data"``) or the dictionary page (``page="dictionary"``: the values of
    a dictionary-encoded column) of ``column``; returns ``(offset, bit)``."""
    chunk = column_chunk(path, column, row_group)
    span = chunk.data if page == "data" else chunk.dictionary
    assert span is not None, f"{column} has no {page} page"
    rng = random.Random(seed)
    offset = rng.randrange(span.start, span.stop)
    bit = rng.randrange(8)
    flip_bit(path, offset, bit)
    return offset, bit


def damage_page_header(path: Path, column: str = "e_z", row_group: int = 0,
                       pattern: bytes = b"\xff\xff\xff\xff") -> int:
    """Overwrite bytes of the data page header of ``column`` just after its first byte
    (page type and sizes in Thrift's compact encoding) with ``pattern``; returns the
    offset."""
    header = column_chunk(path, column, row_group).data_header
    with open(path, "r+b") as f:
        f.seek(header + 1)
        f.write(pattern)
    return header + 1


def truncate(path: Path, keep: float = 0.5) -> int:
    """Cut ``path`` to the fraction ``keep`` of its size (as a write cut short by a full
    disk without the atomic rename would leave it); returns the new size."""
    size = int(Path(path).stat().st_size * keep)
    with open(path, "r+b") as f:
        f.truncate(size)
    return size


def write_foreign_parquet(path: Path, rows: int = 3) -> None:
    """A valid Parquet file that no vimpact sweep wrote (no ``vimpact.*`` metadata)."""
    import pyarrow as pa
    pq.write_table(pa.table({"x": list(range(rows)), "y": [0.5] * rows}), path)


class FullDisk:
    """``open`` for :mod:`vimpact.tableformat.files` (every atomic write) on a disk that fills up: the first
    ``files_ok`` files opened for writing are written in full, the next one gets
    ``bytes_into_next`` bytes and then ``OSError(ENOSPC)`` from ``write`` (midway
    through the file), and every later write fails at once (the disk stays full).
    Use ``monkeypatch.setattr(files, "open", FullDisk(...), raising=False)``; reads
    go to the real ``open``. ``failures`` counts the ``ENOSPC`` raised."""

    def __init__(self, files_ok: int, bytes_into_next: int = 100):
        self.files_ok = files_ok
        self.capacity: int | None = None  # bytes left once the last good file is done
        self.bytes_into_next = bytes_into_next
        self.opened = 0
        self.failures = 0

    def __call__(self, file, mode="r", *args, **kwargs):
        real = open(file, mode, *args, **kwargs)
        if "w" not in mode and "a" not in mode and "+" not in mode:
            return real
        self.opened += 1
        if self.opened <= self.files_ok:
            return real
        if self.capacity is None:
            self.capacity = self.bytes_into_next
        return _Limited(real, self)


class _Limited(io.RawIOBase):
    def __init__(self, real, disk: FullDisk):
        self.real, self.disk = real, disk

    def writable(self) -> bool:
        return True

    def write(self, data) -> int:
        data = bytes(data)
        room = self.disk.capacity
        if len(data) > room:
            if room > 0:
                self.real.write(data[:room])
                self.disk.capacity = 0
            self.disk.failures += 1
            raise OSError(errno.ENOSPC, "No space left on device")
        self.disk.capacity -= len(data)
        return self.real.write(data)

    def flush(self) -> None:
        if not self.real.closed:
            self.real.flush()

    def fileno(self) -> int:
        return self.real.fileno()

    def tell(self) -> int:
        return self.real.tell()

    def close(self) -> None:
        if not self.closed:
            self.real.close()
        super().close()


# ---- a survey: random bit flips over a whole part ------------------------------------

def flip_survey(part: Path, spec, flips: int = 200, seed: int = 0) -> dict:
    """Flip one random bit of a copy of the part file ``part`` (anywhere: pages,
    headers, footer), ``flips`` times, and classify each outcome, with the checks of
    :func:`vimpact.sweep.store.existing_parts` now and with the footer-only check
    resume used before (schema readable, this sweep's hash and chunk):

    ``now``: ``detected`` (moved aside and computed again), ``refused`` (looks like
    another sweep's part), ``harmless`` (passes, data read back unchanged),
    ``undetected`` (passes with changed data: must stay 0).
    ``footer_only``: ``caught`` (footer unreadable or not this sweep's),
    ``crash_later`` (passes, then reading the data raises), ``harmless``,
    ``silently_wrong`` (passes with changed data); ``max_abs_e_z_change`` over those.
    """
    import shutil
    import tempfile

    import numpy as np
    import pandas as pd

    from vimpact.sweep import store
    from vimpact.tableformat import metadata

    original = pq.read_table(part).to_pandas()
    rng = random.Random(seed)
    now = dict(detected=0, refused=0, harmless=0, undetected=0)
    old = dict(caught=0, crash_later=0, harmless=0, silently_wrong=0)
    worst = 0.0
    with tempfile.TemporaryDirectory() as tmp:
        copy = Path(tmp) / part.name
        for _ in range(flips):
            shutil.copyfile(part, copy)
            flip_bit(copy, rng.randrange(copy.stat().st_size), rng.randrange(8))
            kind, _why = store._check_part(copy, spec)
            try:
                back = pq.read_table(copy).to_pandas()
                same = back.shape == original.shape and back.equals(original)
            except Exception:  # noqa: BLE001
                back, same = None, False
            if kind == "ok":
                now["harmless" if same else "undetected"] += 1
            else:
                now["detected" if kind == "bad" else "refused"] += 1
            try:  # the check resume made before: the footer only
                meta = metadata.decode_metadata(pq.read_schema(copy).metadata)
                footer_ok = meta.get("sweep_hash") == spec.sweep_hash \
                    and meta.get("chunk") == int(part.stem.split("-")[1])
            except Exception:  # noqa: BLE001
                footer_ok = False
            if not footer_ok:
                old["caught"] += 1
            elif back is None:
                old["crash_later"] += 1
            elif same:
                old["harmless"] += 1
            else:
                old["silently_wrong"] += 1
                if back.shape == original.shape:
                    d = np.abs(back["e_z"].to_numpy() - original["e_z"].to_numpy())
                    worst = max(worst, float(np.nanmax(d)) if np.isfinite(d).any() else np.inf)
    return {"flips": flips, "now": now, "footer_only": old, "max_abs_e_z_change": worst,
            "pandas": pd.__version__}


def overhead(rows: int = 200_000, repeats: int = 3) -> dict:
    """CPU seconds (best of ``repeats``, side by side) of writing and reading a table of
    ``rows`` rows shaped like a sweep's (1 int64, 30 float64, 3 string columns): plain
    ``pyarrow.parquet`` vs :func:`vimpact.tableformat.files.write_atomic` (page checksums,
    content hash, fsync) and :func:`vimpact.tableformat.integrity.verify_table` (every page
    read with its CRC checked, hash recomputed)."""
    import tempfile
    import time

    import numpy as np
    import pyarrow as pa

    from vimpact.tableformat import files, integrity

    rng = np.random.default_rng(0)
    cols = {"row": pa.array(np.arange(rows, dtype=np.int64))}
    cols.update({f"x{k}": pa.array(rng.random(rows)) for k in range(30)})
    cols["path"] = pa.array(np.where(rng.random(rows) < 0.5, "continuum_kv", "elements"))
    cols["status"] = pa.array(np.full(rows, "ok"))
    cols["error"] = pa.nulls(rows, pa.string())
    table = pa.table(cols).replace_schema_metadata({b"vimpact.model": b"kelvin_voigt"})

    def best(fn):
        times = []
        for _ in range(repeats):
            t0 = time.process_time()
            fn()
            times.append(time.process_time() - t0)
        return min(times)
    with tempfile.TemporaryDirectory() as tmp:
        plain, checked = Path(tmp) / "plain.parquet", Path(tmp) / "checked.parquet"
        out = {"rows": rows,
               "write_plain_s": best(lambda: pq.write_table(table, plain)),
               "write_checked_s": best(lambda: files.write_atomic(table, checked)),
               "read_plain_s": best(lambda: pq.read_table(plain)),
               "verify_s": best(lambda: integrity.verify_table(checked)),
               "hash_only_s": best(lambda: integrity.content_hash(table)),
               "bytes_plain": plain.stat().st_size, "bytes_checked": checked.stat().st_size}
    out["write_ratio"] = out["write_checked_s"] / out["write_plain_s"]
    out["verify_vs_read_ratio"] = out["verify_s"] / out["read_plain_s"]
    return out


if __name__ == "__main__":  # python -m tests.sweep.faults SPEC [FLIPS] | --overhead [ROWS]
    import json
    import sys
    import tempfile

    from vimpact.sweep import run_sweep
    from vimpact.sweep.spec import load_spec

    if sys.argv[1] == "--overhead":
        print(json.dumps(overhead(int(sys.argv[2]) if len(sys.argv) > 2 else 200_000),
                         indent=1))
        sys.exit(0)
    spec_path = Path(sys.argv[1])
    flips = int(sys.argv[2]) if len(sys.argv) > 2 else 200
    with tempfile.TemporaryDirectory() as tmp:
        parts = run_sweep(spec_path, out=Path(tmp) / "survey.parquet", shard=(0, 1),
                          progress=False)
        first = sorted(parts.glob("part-*.parquet"))[0]
        print(json.dumps(flip_survey(first, load_spec(spec_path), flips), indent=1))
