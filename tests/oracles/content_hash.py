"""The table content hash written out from its definition, row by row in plain Python.

An independent reference for the vectorized :class:`vimpact.tableformat.integrity.ContentHash`
(``vimpact content sha256 v1``): per column its name, then the SHA-256 of its validity
bytes, of its fixed-width values (int64 / float64 little-endian, a boolean as one byte,
a string as its int64 byte length; 0 where null) and of its string bytes.
"""

from __future__ import annotations

import hashlib
import struct

import pyarrow as pa


def definition_hash(table: pa.Table) -> str:
    """Return the content hash of ``table`` computed from the definition, one value at a time."""
    h = hashlib.sha256(f"vimpact content sha256 v1\nrows {table.num_rows}\n".encode())
    for name, column in zip(table.column_names, table.columns):
        kind = column.type
        valid, values, data = b"", b"", b""
        for x in column.to_pylist():
            valid += b"\x01" if x is not None else b"\x00"
            if pa.types.is_string(kind):
                raw = (x or "").encode()
                values += struct.pack("<q", len(raw))
                data += raw
            elif pa.types.is_boolean(kind):
                values += b"\x01" if x else b"\x00"
            elif pa.types.is_floating(kind):
                values += struct.pack("<d", 0.0 if x is None else x)
            else:
                values += struct.pack("<q", 0 if x is None else x)
        h.update(f"column {name}\n".encode())
        for stream in (valid, values, data):
            h.update(hashlib.sha256(stream).digest())
    return h.hexdigest()
