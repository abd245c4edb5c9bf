"""The metadata codec of a vimpact table: Parquet key-value metadata <-> Python values.

Every entry vimpact writes is ``vimpact.<key>`` (:data:`META_PREFIX`). One codec
decides how a value is stored: the keys in :data:`JSON_KEYS` as JSON, those in
:data:`INT_KEYS` as decimal integers, booleans as JSON (``true``/``false``), any
other value as its ``str``. :func:`encode_metadata` and :func:`decode_metadata` are
an encode/decode pair: for values of those kinds (JSON keys: JSON values; integer
keys: ints; other keys: strings), ``decode_metadata(encode_metadata(values)) ==
values`` (``tests/tableformat/test_metadata.py``). The sweep writes with it and the
reader (:class:`vimpact.lookup.table.RestitutionTable`) decodes with it.
"""

from __future__ import annotations

import json
from pathlib import Path

#: Prefix of every key-value metadata key vimpact writes.
META_PREFIX = "vimpact."
#: Metadata keys stored as JSON.
JSON_KEYS = ("numerics", "units", "columns", "statuses", "paths", "rotation", "counts",
             "grid_tolerance", "grid_refinement", "interpolation_error", "grid_levels",
             "adaptive", "build", "kelvin_voigt_limit", "lam_range")
#: Metadata keys stored as integers.
INT_KEYS = ("schema_version", "seed", "rows", "chunk", "row_start", "row_stop", "n_chunks",
            "chunk_size")
#: Name of the dataset file that holds the schema and the sweep metadata.
COMMON_METADATA = "_common_metadata"


def encode_value(key: str, value) -> str:
    """Return the stored text of metadata ``key``: JSON for :data:`JSON_KEYS`, else ``str``."""
    if key in JSON_KEYS:
        return value if isinstance(value, str) else json.dumps(value)
    if isinstance(value, bool):
        return json.dumps(value)
    return str(value)


def decode_value(key: str, text: str):
    """Return the value of metadata ``key`` from its stored text.

    The inverse of :func:`encode_value`; a text that does not decode is returned as it
    is.
    """
    if key in JSON_KEYS:
        try:
            return json.loads(text)
        except json.JSONDecodeError:
            return text
    if key in INT_KEYS:
        try:
            return int(text)
        except ValueError:
            return text
    return text


def encode_metadata(values: dict) -> dict[bytes, bytes]:
    """Parquet key-value metadata (``vimpact.`` prefixed bytes) of ``values``."""
    return {(META_PREFIX + k).encode(): encode_value(k, v).encode() for k, v in values.items()}


def decode_metadata(raw: dict | None) -> dict:
    """Return the ``vimpact.*`` entries of Parquet key-value metadata, decoded.

    Keys may be bytes or str; they are returned without the prefix, each value
    decoded by :func:`decode_value`.
    """
    out = {}
    for k, v in (raw or {}).items():
        k = k.decode() if isinstance(k, bytes) else str(k)
        if not k.startswith(META_PREFIX):
            continue
        v = v.decode() if isinstance(v, bytes) else v
        out[k[len(META_PREFIX):]] = decode_value(k[len(META_PREFIX):], v)
    return out


def schema_path(path) -> Path:
    """Return the file whose schema holds the metadata of a table at ``path``.

    The file itself, or ``_common_metadata`` of a dataset directory.
    """
    path = Path(path)
    return path / COMMON_METADATA if path.is_dir() else path


def read_metadata(path) -> dict:
    """Return the sweep metadata of a table (file or dataset directory) or a part.

    Keys without the ``vimpact.`` prefix, decoded (``numerics``, ``units``, ``columns``,
    ``statuses``, ``paths``, ``rotation`` from JSON; ``schema_version``, ``seed``,
    ``rows`` ... as ints).
    """
    import pyarrow.parquet as pq
    target = schema_path(path)
    if Path(path).is_dir() and not target.exists():
        raise ValueError(f"{path} is an unfinished sweep dataset (no {COMMON_METADATA}): "
                         "finish it with `vimpact sweep SPEC --resume` (or --combine)")
    return decode_metadata(pq.read_schema(target).metadata)



__all__ = ["COMMON_METADATA", "INT_KEYS", "JSON_KEYS", "META_PREFIX", "decode_metadata",
           "decode_value", "encode_metadata", "encode_value", "read_metadata", "schema_path"]
