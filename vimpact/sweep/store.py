"""Where sweep results go: atomic part files, the table (one file or a dataset), metadata.

Layouts (``layout`` in the spec; ``"auto"``: a file up to
:data:`~vimpact.sweep.spec.FILE_LAYOUT_MAX_ROWS` rows, a dataset above):

- ``"file"``: one Parquet file ``OUT``. While the sweep runs, every finished
  chunk is a part file ``OUT.parts/part-<chunk>.parquet``; at the end the parts
  are combined (in row order) into ``OUT`` and the directory is removed.
- ``"dataset"``: a partitioned Parquet dataset, the directory ``OUT``: the part
  files ``OUT/part-<chunk>.parquet`` plus ``OUT/_common_metadata`` (the schema
  with the sweep metadata), written last: a dataset without it is unfinished.
  ``pyarrow.parquet.read_table(OUT)``, :meth:`vimpact.RestitutionTable.open`
  and ``vimpact table`` read it directly.

Memory is bounded by the chunk size in both layouts: a part is written as it
is finished, and the file layout is combined one part (one row group) at a time.

Every write is atomic (a temporary file in the same directory, fsync,
``os.replace``, fsync of the directory), so a run killed anywhere (kill -9)
leaves finished parts and no half-written file; a resumed run gives the
identical table. Each part stores the sweep hash (spec text, numerics,
package and schema version), its chunk and row range, and a small summary
(rows per status, rows and first row per kernel path) that the combination
merges without reading the data again.

Integrity: every part and every table is written with Parquet page checksums
(CRC-32 of each page), a content hash ``vimpact.content_sha256``
(:class:`ContentHash`: SHA-256 of the column values in a canonical form,
independent of the Parquet encoding) and a hash of the ``vimpact.*`` metadata
entries ``vimpact.metadata_sha256`` (:func:`metadata_hash`: the footer has no
checksum). A part is trusted only after
:func:`verify_part` has read it back (page checksums checked, hash
recomputed): ``--resume`` moves a part that fails to ``<parts>/_corrupt/`` (one
line on stderr names it and the reason) and computes it again; the combination
verifies every part, then the table it wrote (:func:`verify_table`), before it
removes any part. A table without a stored hash (written before it existed) is
accepted with the hash check skipped.

Metadata: the Parquet key-value metadata ``vimpact.<key>``; one codec
(:func:`encode_metadata`, :func:`decode_metadata`) decides which keys are JSON
(:data:`JSON_KEYS`) and which integers (:data:`INT_KEYS`); the sweep and
:mod:`vimpact.lookup.table` both use it.
"""

from __future__ import annotations

import contextlib
import errno
import hashlib
import json
import os
import shutil
import socket
import sys
from pathlib import Path

from vimpact.model.validation import InputError

#: Prefix of every key-value metadata key vimpact writes.
META_PREFIX = "vimpact."
#: Metadata keys stored as JSON.
JSON_KEYS = ("numerics", "units", "columns", "statuses", "paths", "rotation", "counts",
             "grid_tolerance", "grid_refinement", "interpolation_error", "grid_levels",
             "adaptive", "build")
#: Metadata keys stored as integers.
INT_KEYS = ("schema_version", "seed", "rows", "chunk", "row_start", "row_stop", "n_chunks",
            "chunk_size")
#: Parquet compression of every table and part written (zstd: the shipped adaptive
#: standard-solid table is 10.1 MB, 11.8 MB with snappy; the content hash is of the data,
#: not of the file's bytes, so it does not depend on it).
COMPRESSION = "zstd"
#: Name of the dataset file that holds the schema and the sweep metadata.
COMMON_METADATA = "_common_metadata"
#: Metadata key (without the prefix) of the content hash (:class:`ContentHash`).
CONTENT_HASH_KEY = "content_sha256"
#: Metadata key (without the prefix) of the hash of the other ``vimpact.*`` entries
#: (:func:`metadata_hash`).
METADATA_HASH_KEY = "metadata_sha256"
#: First line hashed by :class:`ContentHash`: names the definition (change it with it).
CONTENT_HASH_VERSION = "vimpact content sha256 v1"
#: Subdirectory of the parts directory that damaged parts are moved to.
CORRUPT_DIR = "_corrupt"


# ---- metadata codec --------------------------------------------------------------

def encode_value(key: str, value) -> str:
    """The stored text of metadata ``key``: JSON for :data:`JSON_KEYS`, else ``str``."""
    if key in JSON_KEYS:
        return value if isinstance(value, str) else json.dumps(value)
    if isinstance(value, bool):
        return json.dumps(value)
    return str(value)


def decode_value(key: str, text: str):
    """The value of metadata ``key`` from its stored text (inverse of :func:`encode_value`;
    a text that does not decode is returned as it is)."""
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
    """The ``vimpact.*`` entries of Parquet key-value metadata (bytes or str keys),
    without the prefix, decoded by :func:`decode_value`."""
    out = {}
    for k, v in (raw or {}).items():
        k = k.decode() if isinstance(k, bytes) else str(k)
        if not k.startswith(META_PREFIX):
            continue
        v = v.decode() if isinstance(v, bytes) else v
        out[k[len(META_PREFIX):]] = decode_value(k[len(META_PREFIX):], v)
    return out


def schema_path(path) -> Path:
    """The file whose schema holds the metadata of a table at ``path``: the file itself,
    or ``_common_metadata`` of a dataset directory."""
    path = Path(path)
    return path / COMMON_METADATA if path.is_dir() else path


def read_metadata(path) -> dict:
    """The sweep metadata of a table (file or dataset directory) or a part at ``path``:
    keys without the ``vimpact.`` prefix, decoded (``numerics``, ``units``, ``columns``,
    ``statuses``, ``paths``, ``rotation`` from JSON; ``schema_version``, ``seed``,
    ``rows`` ... as ints)."""
    import pyarrow.parquet as pq
    target = schema_path(path)
    if Path(path).is_dir() and not target.exists():
        raise ValueError(f"{path} is an unfinished sweep dataset (no {COMMON_METADATA}): "
                         "finish it with `vimpact sweep SPEC --resume` (or --combine)")
    return decode_metadata(pq.read_schema(target).metadata)


def summary(path) -> dict[str, int]:
    """Number of rows per status in the table (file or dataset) at ``path``."""
    import pyarrow.parquet as pq
    status = pq.read_table(path, columns=["status"]).column("status")
    counts = status.value_counts().to_pylist()
    return {c["values"]: int(c["counts"]) for c in sorted(counts, key=lambda c: c["values"])}


# ---- content hash ----------------------------------------------------------------

class ContentHash:
    """SHA-256 of a table's values in a canonical form, independent of the Parquet
    encoding (compression, dictionary or plain pages, row groups, Arrow chunks,
    ``string`` or ``large_string``, nullability flags).

    Definition (version :data:`CONTENT_HASH_VERSION`). Every column has three byte
    streams over its rows in row order:

    - validity: one byte per row, ``1`` a value, ``0`` a null;
    - values: fixed-width types (integers, floats, booleans as one byte) the
      value's little-endian bytes as stored (NaN payloads included), ``0`` for a
      null; strings and binaries the byte length as little-endian ``int64``, ``0``
      for a null; a column of Arrow type ``null`` eight zero bytes per row (the
      same as an all-null ``int64``, ``float64`` or string column);
    - data: strings and binaries the concatenated bytes of the values (UTF-8);
      empty for the other types.

    The hash is SHA-256 over the UTF-8 text ``"vimpact content sha256 v1\\n"``,
    ``"rows <n>\\n"``, then for each column in table order ``"column <name>\\n"``
    followed by the three 32-byte SHA-256 digests of its streams. Feeding the
    rows in pieces (:meth:`update` once per part or row group) gives the hash of
    the whole, so a table is hashed with memory bounded by its largest piece.
    Stored as the metadata ``vimpact.content_sha256`` (64 hex digits).
    """

    def __init__(self, names=None):
        self.names: list[str] | None = list(names) if names is not None else None
        self.rows = 0
        self._streams: list[tuple] = []

    def update(self, table) -> ContentHash:
        """Add the rows of the ``pyarrow`` table (or record batch) ``table``: same
        column names, in the same order, as the rows before."""
        names = list(table.column_names)
        if self.names is None:
            self.names = names
        if names != self.names:
            raise ValueError(f"content hash: columns {names} differ from {self.names}")
        if not self._streams:
            self._streams = [(hashlib.sha256(), hashlib.sha256(), hashlib.sha256())
                             for _ in names]
        for column, streams in zip(table.columns, self._streams):
            for stream, piece in zip(streams, _canonical(column)):
                stream.update(piece)
        self.rows += table.num_rows
        return self

    def hexdigest(self) -> str:
        """The hash (64 hex digits) of the rows added so far."""
        h = hashlib.sha256(f"{CONTENT_HASH_VERSION}\nrows {self.rows}\n".encode())
        names = self.names or []
        streams = self._streams or [(hashlib.sha256(),) * 3 for _ in names]
        for name, (valid, values, data) in zip(names, streams):
            h.update(f"column {name}\n".encode())
            for stream in (valid, values, data):
                h.update(stream.digest())
        return h.hexdigest()


def content_hash(table) -> str:
    """The :class:`ContentHash` of one ``pyarrow`` table (64 hex digits)."""
    return ContentHash().update(table).hexdigest()


def metadata_hash(raw: dict | None) -> str:
    """SHA-256 (64 hex digits) of the ``vimpact.*`` entries of Parquet key-value
    metadata ``raw`` (bytes or str keys and values) other than
    ``vimpact.metadata_sha256`` itself: over the entries sorted by key, each as the
    little-endian ``uint64`` byte length of the key, the key, the length of the
    value, the value (UTF-8). Stored as ``vimpact.metadata_sha256``, it makes a
    changed metadata entry (the sweep hash, the spec, units, the content hash)
    detectable: the page checksums do not cover the footer."""
    def as_bytes(x) -> bytes:
        return x if isinstance(x, bytes) else str(x).encode()
    own = (META_PREFIX + METADATA_HASH_KEY).encode()
    items = sorted((as_bytes(k), as_bytes(v)) for k, v in (raw or {}).items())
    h = hashlib.sha256()
    for key, value in items:
        if key.startswith(META_PREFIX.encode()) and key != own:
            for piece in (key, value):
                h.update(len(piece).to_bytes(8, "little"))
                h.update(piece)
    return h.hexdigest()


def _with_metadata_hash(schema_or_table):
    """``schema_or_table`` with ``vimpact.metadata_sha256`` set to :func:`metadata_hash`
    of its metadata."""
    meta = dict(schema_or_table.schema.metadata or {}) if hasattr(schema_or_table, "schema") \
        else dict(schema_or_table.metadata or {})
    meta[(META_PREFIX + METADATA_HASH_KEY).encode()] = metadata_hash(meta).encode()
    if hasattr(schema_or_table, "replace_schema_metadata"):
        return schema_or_table.replace_schema_metadata(meta)
    return schema_or_table.with_metadata(meta)


def _check_metadata_hash(raw: dict | None) -> None:
    """:class:`_Damaged` if ``raw`` stores a metadata hash that its entries do not give."""
    raw = raw or {}
    stored = raw.get((META_PREFIX + METADATA_HASH_KEY).encode())
    if stored is not None and stored.decode(errors="replace") != metadata_hash(raw):
        raise _Damaged("metadata hash mismatch (a vimpact.* metadata entry changed after "
                       "it was written)")


def _canonical(column) -> tuple[bytes, bytes, bytes]:
    """The validity, values and data bytes of one column (see :class:`ContentHash`)."""
    import numpy as np
    import pyarrow as pa
    import pyarrow.compute as pc

    if isinstance(column, pa.ChunkedArray):
        column = (column.combine_chunks() if column.num_chunks
                  else pa.array([], type=column.type))
    if pa.types.is_dictionary(column.type):
        column = column.dictionary_decode()
    n = len(column)
    kind = column.type
    if pa.types.is_null(kind):
        return bytes(n), bytes(8 * n), b""
    valid = np.asarray(column.is_valid().to_numpy(zero_copy_only=False), dtype=np.uint8)
    if (pa.types.is_string(kind) or pa.types.is_large_string(kind) or pa.types.is_binary(kind)
            or pa.types.is_large_binary(kind) or pa.types.is_string_view(kind)
            or pa.types.is_binary_view(kind)):
        filled = pc.fill_null(column, "" if "string" in str(kind) else b"")
        flat = filled.cast(pa.large_binary())
        offsets_buf, data_buf = flat.buffers()[1], flat.buffers()[2]
        offsets = np.frombuffer(offsets_buf, dtype="<i8")[flat.offset:flat.offset + n + 1]
        lengths = np.diff(offsets).astype("<i8")
        data = (data_buf.to_pybytes()[offsets[0]:offsets[-1]] if n and data_buf is not None
                else b"")
        return valid.tobytes(), lengths.tobytes(), data
    if pa.types.is_boolean(kind):
        values = np.asarray(pc.fill_null(column, False).to_numpy(zero_copy_only=False),
                            dtype=np.uint8)
        return valid.tobytes(), values.tobytes(), b""
    if pa.types.is_integer(kind) or pa.types.is_floating(kind):
        values = pc.fill_null(column, 0).to_numpy(zero_copy_only=False)
        values = values.astype(values.dtype.newbyteorder("<"), copy=False)
        return valid.tobytes(), values.tobytes(), b""
    raise ValueError(f"content hash: column type {kind} is not supported")


# ---- verification ------------------------------------------------------------------

class _Damaged(Exception):
    """A file that fails verification; the message says what failed (one line)."""


def _first_line(exc: BaseException) -> str:
    text = (str(exc).strip().splitlines() or [""])[0]
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__


def _open_checked(path: Path):
    """``pyarrow.parquet.ParquetFile`` of ``path`` with page checksum verification,
    or :class:`_Damaged` (missing, truncated, not Parquet, footer unreadable)."""
    import pyarrow.parquet as pq
    path = Path(path)
    try:
        size = path.stat().st_size
        with open(path, "rb") as f:
            head = f.read(4)
            f.seek(max(0, size - 4))
            tail = f.read(4)
    except OSError as exc:
        raise _Damaged(f"unreadable ({_first_line(exc)})") from None
    if size == 0:
        raise _Damaged("empty file (0 bytes)")
    if head != b"PAR1":
        raise _Damaged("not a Parquet file (no PAR1 magic at the start)")
    if tail != b"PAR1":
        raise _Damaged(f"truncated ({size} bytes, no Parquet footer at the end)")
    try:
        return pq.ParquetFile(path, page_checksum_verification=True)
    except Exception as exc:  # noqa: BLE001 - pyarrow raises several types for a bad footer
        raise _Damaged(f"footer unreadable ({_first_line(exc)})") from None


def _scan(path: Path, hasher: ContentHash | None = None) -> tuple[dict, str, int]:
    """Read every row group of the Parquet file ``path`` with page checksums checked.

    Returns the decoded ``vimpact.*`` metadata, the :class:`ContentHash` of the
    data and the number of rows; ``hasher`` (optional) receives the rows too.
    Raises :class:`_Damaged` for a file that cannot be read back or whose stored
    hash (if any) differs from its data."""
    pf = _open_checked(path)
    try:
        meta = decode_metadata(pf.schema_arrow.metadata)
    except Exception as exc:  # noqa: BLE001
        raise _Damaged(f"schema unreadable ({_first_line(exc)})") from None
    _check_metadata_hash(pf.schema_arrow.metadata)
    own = ContentHash(pf.schema_arrow.names)
    for group in range(pf.metadata.num_row_groups):
        try:
            table = pf.read_row_group(group)
        except Exception as exc:  # noqa: BLE001 - CRC, decompression, thrift errors
            why = _first_line(exc)
            what = "page checksum failed" if "checksum" in why.lower() else "data unreadable"
            raise _Damaged(f"{what} in row group {group} ({why})") from None
        own.update(table)
        if hasher is not None:
            hasher.update(table)
    digest = own.hexdigest()
    stored = meta.get(CONTENT_HASH_KEY)
    if stored is not None and stored != digest:
        raise _Damaged(f"content hash mismatch (stored {str(stored)[:12]}..., "
                       f"data {digest[:12]}...)")
    return meta, digest, own.rows


def _check_part(path: Path, spec, hasher: ContentHash | None = None) -> tuple[str, str | None]:
    """``("ok", None)``, ``("foreign", why)`` for a part of another sweep (its own
    vimpact metadata, another sweep hash) or ``("bad", why)``."""
    path = Path(path)
    try:
        pf = _open_checked(path)
        meta = decode_metadata(pf.schema_arrow.metadata)
    except _Damaged as exc:
        return "bad", str(exc)
    except Exception as exc:  # noqa: BLE001
        return "bad", f"schema unreadable ({_first_line(exc)})"
    try:  # first: a damaged sweep hash must not pass for another sweep's
        _check_metadata_hash(pf.schema_arrow.metadata)
    except _Damaged as exc:
        return "bad", str(exc)
    got = meta.get("sweep_hash")
    if not got:
        return "bad", "not a part of a vimpact sweep (no vimpact.sweep_hash metadata)"
    if got != spec.sweep_hash:
        return "foreign", (f"belongs to another sweep (a different spec, numerics or vimpact "
                           f"version: hash {str(got)[:12]} != {spec.sweep_hash[:12]})")
    chunk = meta.get("chunk")
    if not isinstance(chunk, int) or not 0 <= chunk < spec.n_chunks \
            or path.name != part_path(path.parent, chunk, spec.n_chunks).name:
        return "bad", f"holds chunk {chunk}, not the chunk its name says"
    start, stop = spec.chunk_rows(chunk)
    if (meta.get("row_start"), meta.get("row_stop"), meta.get("n_chunks")) \
            != (start, stop, spec.n_chunks):
        return "bad", (f"row range {meta.get('row_start')}..{meta.get('row_stop')} is not "
                       f"chunk {chunk}'s {start}..{stop}")
    if CONTENT_HASH_KEY not in meta:
        return "bad", "no content hash (written before parts were verified)"
    if list(pf.schema_arrow.names) != list(spec.columns()):
        return "bad", "its columns are not this sweep's"
    if rows_in_footer(pf) != stop - start:
        return "bad", f"holds {rows_in_footer(pf)} rows, chunk {chunk} has {stop - start}"
    try:
        _, _, rows = _scan(path, hasher)
    except _Damaged as exc:
        return "bad", str(exc)
    if rows != stop - start:
        return "bad", f"holds {rows} rows, chunk {chunk} has {stop - start}"
    return "ok", None


def rows_in_footer(pf) -> int:
    """Number of rows a ``pyarrow.parquet.ParquetFile``'s footer declares."""
    return int(pf.metadata.num_rows)


def verify_part(path, spec) -> str | None:
    """Why the part file ``path`` cannot be used by the sweep ``spec``, or ``None``.

    Checks, in order: readable Parquet with its footer (not truncated); its
    metadata equal to its stored metadata hash; vimpact sweep metadata with this
    sweep's hash; the chunk and row range its name says;
    a stored content hash; this sweep's columns; every page read back with its
    checksum verified; the content hash recomputed from the data equal to the
    stored one; the chunk's number of rows. Returns a one-line reason such as
    ``"page checksum failed in row group 0 (...)"`` or ``"truncated (...)"``.
    """
    return _check_part(Path(path), spec)[1]


def verify_table(path) -> str:
    """Check that the table at ``path`` (a Parquet file, or a dataset directory) reads
    back as it was written; raise :class:`~vimpact.model.validation.InputError` naming
    the file and what failed otherwise.

    Checks: the file exists, is Parquet and not truncated (footer present); it has
    ``vimpact.*`` metadata (else: foreign), equal to its ``vimpact.metadata_sha256``
    (:func:`metadata_hash`) where stored; every page reads back, with its CRC-32
    verified where the writer stored one (vimpact writes them since
    ``vimpact.content_sha256`` exists); the :class:`ContentHash` recomputed from the
    data equals ``vimpact.content_sha256``. A dataset: ``_common_metadata``
    present, no file other than its parts, every part checked so, their rows
    adding up to ``vimpact.rows``, and the hash over the parts in order equal to
    the one in ``_common_metadata``.

    A table without a stored content hash (written before vimpact stored one, e.g.
    a shipped table not yet regenerated) is accepted with the hash check skipped;
    the returned text says so. Memory: one row group (part) at a time.

    Returns
    -------
    str
        What was checked, e.g. ``"ok: 612 rows, 1 row group(s), content hash
        verified"`` or ``"... no content hash stored (an older table): hash check
        skipped"``.
    """
    path = Path(path)
    where = f"table = {str(path)!r} is not allowed"
    if not path.exists():
        raise InputError(f"{where}: no such file or directory")
    try:
        if path.is_dir():
            rows, groups, stored = _verify_dataset(path)
        else:
            meta, _, rows = _scan(path)
            if not meta:
                raise _Damaged("not a vimpact table (no vimpact.* metadata)")
            groups = _open_checked(path).metadata.num_row_groups
            stored = CONTENT_HASH_KEY in meta
    except _Damaged as exc:
        raise InputError(f"{where}: it fails the integrity check: {exc}") from None
    text = f"ok: {rows} rows, {groups} row group(s), page checksums checked where stored, "
    return text + ("content hash verified" if stored else
                   "no content hash stored (an older table): hash check skipped")


def _verify_dataset(path: Path) -> tuple[int, int, bool]:
    common = path / COMMON_METADATA
    if not common.is_file():
        raise _Damaged(f"an unfinished sweep dataset (no {COMMON_METADATA})")
    try:
        import pyarrow.parquet as pq
        raw = pq.read_schema(common).metadata
        meta = decode_metadata(raw)
    except Exception as exc:  # noqa: BLE001
        raise _Damaged(f"{COMMON_METADATA} unreadable ({_first_line(exc)})") from None
    try:
        _check_metadata_hash(raw)
    except _Damaged as exc:
        raise _Damaged(f"{COMMON_METADATA}: {exc}") from None
    if not meta:
        raise _Damaged(f"not a vimpact table (no vimpact.* metadata in {COMMON_METADATA})")
    parts = []
    for entry in sorted(path.iterdir()):
        if entry.name.startswith((".", "_")):
            continue  # not read as data (pyarrow ignores these names too)
        if not (entry.is_file() and entry.name.startswith("part-")
                and entry.name.endswith(".parquet")):
            raise _Damaged(f"{entry.name} is not one of its parts (move it out of the "
                           "dataset directory)")
        parts.append(entry)
    whole = ContentHash()
    for part in parts:
        try:
            _scan(part, whole)
        except _Damaged as exc:
            raise _Damaged(f"part {part.name}: {exc}") from None
        except ValueError as exc:  # other columns than the parts before
            raise _Damaged(f"part {part.name}: {exc}") from None
    if isinstance(meta.get("rows"), int) and meta["rows"] != whole.rows:
        raise _Damaged(f"its parts hold {whole.rows} rows, its metadata says {meta['rows']}")
    stored = meta.get(CONTENT_HASH_KEY)
    if stored is not None and stored != whole.hexdigest():
        raise _Damaged(f"content hash over the parts mismatch (stored {str(stored)[:12]}..., "
                       f"data {whole.hexdigest()[:12]}...)")
    return whole.rows, len(parts), stored is not None


# ---- atomic files ----------------------------------------------------------------

def fsync_dir(path: Path) -> None:
    """fsync a directory (its entries survive a crash); a no-op where not possible."""
    try:
        fd = os.open(path, os.O_RDONLY)
    except OSError:  # pragma: no cover - not possible on every platform
        return
    try:
        os.fsync(fd)
    except OSError:  # pragma: no cover
        pass
    finally:
        os.close(fd)


def refuse_symlink(path, name: str = "--out", value=None) -> None:
    """:class:`InputError` if ``path`` is a symbolic link: a file vimpact creates or
    replaces is never reached through one (its target would be overwritten). The
    message names ``name = value`` (default: ``path``), as the user gave it."""
    if os.path.islink(path):
        it = "it is" if value is None else f"{path} is"
        raise InputError(f"{name} = {str(path if value is None else value)!r} is not allowed: "
                         f"{it} a symbolic link (to {os.readlink(path)!r}); vimpact does not "
                         "write through one: give a regular file's path or a new name")


def _temporary(path: Path) -> Path:
    return path.with_name(f".{path.name}.{socket.gethostname()}.{os.getpid()}.tmp")


@contextlib.contextmanager
def atomic_file(path, name: str = "--out", mode: str = "wb"):
    """Yield a file object whose content replaces ``path`` atomically on success.

    The content goes to a new temporary file in ``path``'s directory, created with
    ``O_CREAT | O_EXCL | O_NOFOLLOW`` (never an existing file, never through a
    symbolic link); it is fsynced and renamed onto ``path`` (``os.replace``), then
    the directory is fsynced. ``path`` itself must not be a symbolic link
    (:func:`refuse_symlink`, ``name`` is how the user gave it). On an error the
    temporary file is removed and an earlier ``path`` stays as it was."""
    path = Path(path)
    refuse_symlink(path, name)
    tmp = _temporary(path)
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_NOFOLLOW", 0) \
        | getattr(os, "O_CLOEXEC", 0)
    try:
        fd = os.open(tmp, flags, 0o644)
    except FileExistsError:  # a temporary of a write cut short (this pid, reused)
        os.unlink(tmp)
        fd = os.open(tmp, flags, 0o644)
    try:
        with open(fd, mode) as f:  # the builtin on the descriptor (tests fill the disk here)
            yield f
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    finally:
        if os.path.lexists(tmp):
            tmp.unlink()
    fsync_dir(path.parent)


def write_atomic(table, path: Path, *, schema_only: bool = False, more=(),
                 content_sha256: str | None = None) -> None:
    """Write the ``pyarrow`` ``table`` (or only its schema) to ``path``: a temporary
    file in the same directory, fsync, ``os.replace``, fsync of the directory.

    Data is written with Parquet page checksums and the metadata
    ``vimpact.metadata_sha256`` (:func:`metadata_hash`, also for ``schema_only``,
    whenever there are ``vimpact.*`` entries) and
    ``vimpact.content_sha256`` (:class:`ContentHash`), computed here from
    ``table``, or given as ``content_sha256`` (required with ``more``: the hash of
    all rows, which the caller computed while verifying them). ``more``: further
    tables (same schema) appended one row group each, read one at a time, so that
    memory stays bounded by the largest of them. ``schema_only``: the schema with
    its metadata as it is (a dataset's ``_common_metadata``).

    Raises ``OSError`` naming ``path`` when the write fails (e.g. ``ENOSPC``, disk
    full); the temporary file is removed and an earlier ``path`` stays as it was.
    """
    import pyarrow.parquet as pq
    path = Path(path)
    if not schema_only:
        if content_sha256 is None:
            if more:
                raise ValueError("write_atomic: give content_sha256 (the hash of all rows) "
                                 "with more")
            content_sha256 = content_hash(table)
        meta = dict(table.schema.metadata or {})
        meta[(META_PREFIX + CONTENT_HASH_KEY).encode()] = content_sha256.encode()
        table = table.replace_schema_metadata(meta)
    if any(k.startswith(META_PREFIX.encode()) if isinstance(k, bytes) else
           str(k).startswith(META_PREFIX) for k in (table.schema.metadata or {})):
        table = _with_metadata_hash(table)
    try:
        with atomic_file(path, str(path)) as f:
            if schema_only:
                pq.write_metadata(table.schema, f)
            elif more:
                with pq.ParquetWriter(f, table.schema, write_page_checksum=True,
                                      compression=COMPRESSION) as writer:
                    writer.write_table(table)
                    for other in more:
                        writer.write_table(other.replace_schema_metadata(table.schema.metadata))
            else:
                pq.write_table(table, f, write_page_checksum=True, compression=COMPRESSION)
    except OSError as exc:
        raise OSError(exc.errno, f"{exc.strerror or _first_line(exc)} while writing "
                      f"{path}") from exc


def remove_temporaries(directory: Path, name: str = "") -> None:
    """Remove temporary files of writes cut short (kill -9) in ``directory``."""
    for stale in Path(directory).glob(f".{name}*.tmp"):
        try:
            stale.unlink()
        except FileNotFoundError:  # another process removed it
            pass


# ---- parts -------------------------------------------------------------------------

def parts_dir(out, layout: str = "file") -> Path:
    """Directory of the finished chunks of a run writing ``out``: ``OUT.parts`` for the
    file layout, ``OUT`` itself for a dataset."""
    out = Path(out)
    return out if layout == "dataset" else out.with_name(out.name + ".parts")


def part_path(parts: Path, chunk: int, n_chunks: int) -> Path:
    """The part file of ``chunk`` (zero-padded so that name order is chunk order)."""
    width = max(5, len(str(n_chunks - 1)))
    return Path(parts) / f"part-{chunk:0{width}d}.parquet"


def existing_parts(spec, parts: Path) -> dict[int, Path]:
    """Finished chunks in ``parts``, each verified (:func:`verify_part`), after removing
    temporaries of writes cut short.

    A part that fails (damaged, truncated, not a vimpact part, the wrong chunk) is
    treated as missing: it is moved to ``<parts>/_corrupt/`` (never deleted) with
    one line on stderr naming it and the reason, and ``--resume`` computes it
    again. Parts of another sweep (their own vimpact metadata with another sweep
    hash) are refused (``ValueError``): the output is probably the wrong one. In a
    dataset directory a file that is not one of its parts is refused too (it
    would be read as table rows).
    """
    return _existing_parts(spec, parts)


def _existing_parts(spec, parts: Path, hasher: ContentHash | None = None) -> dict[int, Path]:
    """:func:`existing_parts`; ``hasher`` receives the rows of the good parts in chunk
    order (the content hash of the table when no chunk is missing)."""
    found: dict[int, Path] = {}
    if not parts.is_dir():
        return found
    remove_temporaries(parts)
    if spec.table_layout == "dataset":
        for entry in sorted(parts.iterdir()):
            if entry.name.startswith((".", "_")) or (
                    entry.is_file() and entry.name.startswith("part-")
                    and entry.name.endswith(".parquet")):
                continue
            raise ValueError(f"{entry} is in the way: it is not a part of this sweep and "
                             f"would be read as rows of the dataset {parts}; move it away")
    for path in sorted(parts.glob("part-*.parquet")):
        kind, why = _check_part(path, spec, hasher)
        if kind == "foreign":
            raise ValueError(f"{path} {why}; remove {parts} to start over")
        if kind == "bad":
            try:
                aside = move_aside(path)
            except FileNotFoundError:  # another process (a shard) moved or replaced it
                continue
            print(f"vimpact sweep: {path.name} {_as_phrase(why)}; moved to {aside}, "
                  "computing it again", file=sys.stderr)
            continue
        found[int(path.name[len("part-"):-len(".parquet")])] = path
    return found


def _as_phrase(why: str) -> str:
    """``"is truncated (...)"``, ``"fails: content hash mismatch (...)"``: a reason as the
    rest of a sentence whose subject is the file."""
    starts = ("truncated", "empty", "not ", "unreadable")
    return ("is " if why.startswith(starts) else "fails: ") + why


def move_aside(path: Path) -> Path:
    """Move a damaged file to ``<its directory>/_corrupt/`` (a new name if one is there
    already) and return where it went; nothing is deleted."""
    path = Path(path)
    target_dir = path.parent / CORRUPT_DIR
    target_dir.mkdir(exist_ok=True)
    target = target_dir / path.name
    k = 1
    while target.exists():
        target = target_dir / f"{path.stem}.{k}{path.suffix}"
        k += 1
    os.replace(path, target)
    fsync_dir(path.parent)
    return target


def write_part(spec, table, parts: Path, chunk: int, summary_: dict) -> Path:
    """Write the table of ``chunk`` atomically with the sweep metadata, its row range,
    its summary (``counts``, ``paths``), page checksums and its content hash.

    A failed write (e.g. disk full) raises ``OSError`` saying that the finished
    parts are kept and how to continue."""
    start, stop = spec.chunk_rows(chunk)
    meta = {**spec.metadata(), "chunk": chunk, "row_start": start, "row_stop": stop,
            "n_chunks": spec.n_chunks, **summary_}
    path = part_path(parts, chunk, spec.n_chunks)
    try:
        write_atomic(table.replace_schema_metadata(encode_metadata(meta)), path)
    except OSError as exc:
        raise _kept(exc, parts) from exc
    return path


def _kept(exc: OSError, parts: Path) -> OSError:
    """The error of a failed write, saying that the finished parts are kept; "make
    room" only when the disk (or a quota) is full."""
    full = exc.errno in (errno.ENOSPC, errno.EDQUOT)
    return OSError(exc.errno, f"{exc.strerror or _first_line(exc)}; the finished chunks are "
                   f"kept in {parts}: {'make room and ' if full else ''}continue with --resume")


def is_complete(spec, out: Path) -> bool:
    """``out`` is the finished table of ``spec`` (same sweep hash) and passes
    :func:`verify_table`. A finished table that fails is not complete: one line on
    stderr says why; a file is moved to ``<out>.corrupt`` (a dataset keeps its
    place: :func:`existing_parts` moves its damaged parts aside), so that the run
    writes it again."""
    import pyarrow.parquet as pq
    target = schema_path(out)
    if not target.is_file():
        return False
    try:
        meta = decode_metadata(pq.read_schema(target).metadata)
    except Exception:  # noqa: BLE001
        return False
    # a sweep records its kernels' paths; an adaptive table (`vimpact table build`) is
    # made cell by cell and has none
    made = "paths" in meta or meta.get("mode") == "adaptive"
    if not (meta.get("sweep_hash") == spec.sweep_hash and made):
        return False
    try:
        verify_table(out)
    except InputError as exc:
        note = ""
        if Path(out).is_file():
            aside = Path(out).with_name(Path(out).name + ".corrupt")
            os.replace(out, aside)
            note = f"; moved to {aside}"
        print(f"vimpact sweep: {exc}{note}; computing it again", file=sys.stderr)
        return False
    return True


def combine(spec, parts: Path, out: Path, explain_paths) -> None:
    """Finish the table from the parts: verify every part (:func:`existing_parts`:
    a damaged one is moved aside and reported missing), check that every chunk is
    there and that they add up to rows ``0 .. rows-1``; merge the part summaries
    into the ``paths`` metadata (``explain_paths(first_rows) -> {path: reasons}``);
    then write ``OUT`` (file: the parts concatenated with page checksums and the
    content hash of all rows) or ``OUT/_common_metadata`` (dataset, with the
    content hash over its parts), verify what was written (:func:`verify_table`)
    and only then remove the parts (file layout; damaged parts moved aside stay
    in ``<parts>/_corrupt``)."""
    import pyarrow.parquet as pq

    whole = ContentHash()
    found = _existing_parts(spec, parts, whole)
    missing = [c for c in range(spec.n_chunks) if c not in found]
    if missing:
        shown = ", ".join(map(str, missing[:10])) + (" ..." if len(missing) > 10 else "")
        raise ValueError(f"{parts}: {len(missing)} of {spec.n_chunks} chunks are missing "
                         f"({shown}); compute them with --resume (or the missing --shard)")
    paths: dict = {}
    expected = 0
    for chunk in range(spec.n_chunks):
        meta = decode_metadata(pq.read_schema(found[chunk]).metadata)
        if (meta.get("row_start"), meta.get("row_stop")) != spec.chunk_rows(chunk) \
                or meta["row_start"] != expected:
            raise ValueError(f"{parts}: the parts do not add up to rows 0..{spec.rows - 1}; "
                             f"remove {parts} to start over")
        expected = meta["row_stop"]
        for name, entry in meta.get("paths", {}).items():
            if name not in paths:
                paths[name] = {"rows": 0, "first_row": entry["first_row"]}
            paths[name]["rows"] += entry["rows"]
    reasons = explain_paths({name: e["first_row"] for name, e in paths.items()})
    paths = {name: {**e, "reasons": reasons[name]} for name, e in paths.items()}
    digest = whole.hexdigest()
    if spec.table_layout == "dataset":
        meta = encode_metadata({**spec.metadata(), "paths": paths, CONTENT_HASH_KEY: digest})
        write_atomic(spec.schema().empty_table().replace_schema_metadata(meta),
                     out / COMMON_METADATA, schema_only=True)
        _verify_written(out, parts)
        return
    meta = encode_metadata({**spec.metadata(), "paths": paths})
    # one row group per part, read one at a time: memory bounded by the chunk size

    def read(chunk):
        return pq.read_table(found[chunk], page_checksum_verification=True)
    first = read(0).replace_schema_metadata(meta)
    rest = (read(c) for c in range(1, spec.n_chunks))
    out.parent.mkdir(parents=True, exist_ok=True)
    check_room(out, parts, sum(found[c].stat().st_size for c in range(spec.n_chunks)))
    try:
        write_atomic(first, out, more=rest, content_sha256=digest)
    except OSError as exc:
        raise _kept(exc, parts) from exc
    _verify_written(out, parts)
    for chunk in range(spec.n_chunks):
        found[chunk].unlink()
    remove_temporaries(parts)
    try:
        parts.rmdir()
    except OSError:  # something else is there (damaged parts moved aside): kept
        print(f"vimpact sweep: {parts} is kept: it holds files that are not finished parts "
              f"({', '.join(sorted(p.name for p in parts.iterdir()))})", file=sys.stderr)
    fsync_dir(parts.parent)


#: Free disk kept beyond the parts' size when a file-layout table is combined, bytes.
COMBINE_MARGIN_BYTES = 2**20


def check_room(out: Path, parts: Path, parts_bytes: int) -> None:
    """Refuse to combine a file-layout table when its folder lacks the room: the table
    (about the size of its parts) is written while the parts still exist, and they are
    removed only after it is verified, so the end of a sweep needs about twice the
    table's size. ``OSError`` (``ENOSPC``) saying how much, before anything is written."""
    need = parts_bytes + COMBINE_MARGIN_BYTES
    free = shutil.disk_usage(out.parent).free
    if free < need:
        raise OSError(errno.ENOSPC, f"not enough free disk to combine {out}: it needs about "
                      f"{need / 2**20:.1f} MiB in {out.parent} (the size of its parts, which "
                      f"are removed only after the table is verified), {free / 2**20:.1f} MiB "
                      f"are free; the finished chunks are kept in {parts}: make room and "
                      "continue with --resume")


def _verify_written(out: Path, parts: Path) -> None:
    """:func:`verify_table` of a table just written; the parts are kept if it fails."""
    try:
        verify_table(out)
    except InputError as exc:
        raise ValueError(f"{exc}; it was just written from the parts in {parts}, which are "
                         "kept: run again with --resume") from None


# ---- the output: checks and lock ----------------------------------------------------

def check_output(out: Path, layout: str, name: str = "--out") -> None:
    """Refuse an output that cannot be written, before any work: not ``.parquet``, a
    directory where a file is to go (or a file where a dataset is to go), or a place
    without write permission. ``name``: how the user gave the output (``--out``, or
    the spec's ``output`` key), for the message."""
    out = Path(out)
    for path in (out, out.with_name(out.name + ".parts"), out.with_name(out.name + ".lock")):
        refuse_symlink(path, name, out)
    if out.suffix != ".parquet":
        raise ValueError(f"{name} = {str(out)!r} is not allowed: the table's name must end "
                         "in .parquet")
    if layout == "file" and out.is_dir():
        raise ValueError(f"{name} = {str(out)!r} is not allowed: it is a directory, and this "
                         "sweep writes one file (layout = \"file\")")
    if layout == "dataset" and out.exists() and not out.is_dir():
        raise ValueError(f"{name} = {str(out)!r} is not allowed: it is a file, and this sweep "
                         "writes a dataset directory (layout = \"dataset\")")
    existing = out if (layout == "dataset" and out.is_dir()) else out.parent
    while not existing.exists():
        existing = existing.parent
    if not existing.is_dir() or not os.access(existing, os.W_OK | os.X_OK):
        raise ValueError(f"{name} = {str(out)!r} is not allowed: {existing} is not a "
                         "writable directory")


class OutputLock:
    """A lock on ``OUT.lock`` (``fcntl.flock``, released by the kernel when the process
    dies, even by kill -9).

    A plain run, ``--resume`` and ``--combine`` take it exclusively: a second sweep
    into the same output is refused. Shards (``shared=True``) take it shared: any
    number of shards run side by side, but not beside a plain run (either one that
    comes second is refused). A lock file left by a killed sweep does not block
    (nobody holds its lock); a lock taken on a file its holder removed meanwhile is
    taken again on the new one. The lock file is opened with ``O_NOFOLLOW`` (a
    symbolic link there is refused, never followed)."""

    #: Seconds a shard waits for a shared lock that another shard briefly holds
    #: exclusively (while it removes the lock file on its way out).
    SHARED_WAIT_S = 2.0

    def __init__(self, out: Path, shared: bool = False):
        self.path = Path(out).with_name(Path(out).name + ".lock")
        self.shared = shared
        self.fd: int | None = None

    def _open(self) -> int:
        refuse_symlink(self.path, "lock file")
        try:
            return os.open(self.path, os.O_RDWR | os.O_CREAT | getattr(os, "O_NOFOLLOW", 0)
                           | getattr(os, "O_CLOEXEC", 0), 0o644)
        except OSError as exc:
            if exc.errno == errno.ELOOP:  # made a symlink between the check and the open
                refuse_symlink(self.path, "lock file")
            raise

    def __enter__(self) -> OutputLock:
        import fcntl
        import time
        self.path.parent.mkdir(parents=True, exist_ok=True)
        fd = self._open()
        mode = fcntl.LOCK_SH if self.shared else fcntl.LOCK_EX
        deadline = time.monotonic() + (self.SHARED_WAIT_S if self.shared else 0.0)
        while True:
            try:
                fcntl.flock(fd, mode | fcntl.LOCK_NB)
                break
            except OSError:
                if time.monotonic() < deadline:
                    time.sleep(0.05)
                    continue
                try:
                    holder = os.read(fd, 200).decode(errors="replace").strip() or \
                        "shards (vimpact sweep --shard) are writing its parts"
                finally:
                    os.close(fd)
                raise ValueError(f"another sweep is writing {self.path.with_suffix('')} "
                                 f"({holder}); wait for it, or stop it first") from None
        try:
            same = os.fstat(fd).st_ino == os.stat(self.path, follow_symlinks=False).st_ino
        except FileNotFoundError:
            same = False
        if not same:  # the holder removed the file between our open and flock: try again
            os.close(fd)
            return self.__enter__()
        if not self.shared:  # shards leave it empty: several hold it
            os.ftruncate(fd, 0)
            os.write(fd, f"pid {os.getpid()} on {socket.gethostname()}".encode())
        self.fd = fd
        return self

    def __exit__(self, *exc) -> None:
        import fcntl
        if self.fd is None:
            return
        try:
            if self.shared:  # the last shard out removes the file; the others leave it
                fcntl.flock(self.fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            self.path.unlink()
        except (FileNotFoundError, BlockingIOError):
            pass
        finally:
            os.close(self.fd)
            self.fd = None


__all__ = ["COMMON_METADATA", "CONTENT_HASH_KEY", "CONTENT_HASH_VERSION", "CORRUPT_DIR",
           "ContentHash", "INT_KEYS", "JSON_KEYS", "METADATA_HASH_KEY", "META_PREFIX",
           "OutputLock", "atomic_file", "check_output", "metadata_hash", "refuse_symlink",
           "combine", "content_hash", "decode_metadata", "decode_value", "encode_metadata",
           "encode_value", "existing_parts", "fsync_dir", "is_complete", "move_aside",
           "part_path", "parts_dir", "read_metadata", "remove_temporaries", "rows_in_footer",
           "summary", "verify_part", "verify_table", "write_atomic", "write_part"]
