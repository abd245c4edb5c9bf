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
    for field in (1, 2, 3):
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
    """``open`` for :mod:`vimpact.sweep.store` on a disk that fills up: the first
    ``files_ok`` files opened for writing are written in full, the next one gets
    ``bytes_into_next`` bytes and then ``OSError(ENOSPC)`` from ``write`` (midway
    through the file), and every later write fails at once (the disk stays full).
    Use ``monkeypatch.setattr(store, "open", FullDisk(...), raising=False)``; reads
    go to the real ``open``. ``failures`` counts the ``ENOSPC`` raised."""

    def __init__(self, files_ok: int, bytes_into_next: int = 100):
        self.files_ok = files_ok
        self.capacity: int | None = None  # bytes left once the last good file is done
        self.bytes_into_next = bytes_into_next
        self.opened = 0
        self.failures = 0

    def __call__(self, file, mode="r", *args, **kwargs):
        real = io.open(file, mode, *args, **kwargs)
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
