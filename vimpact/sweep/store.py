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

Metadata: the Parquet key-value metadata ``vimpact.<key>``; one codec
(:func:`encode_metadata`, :func:`decode_metadata`) decides which keys are JSON
(:data:`JSON_KEYS`) and which integers (:data:`INT_KEYS`); the sweep and
:mod:`vimpact.lookup.table` both use it.
"""

from __future__ import annotations

import json
import os
import socket
from pathlib import Path

#: Prefix of every key-value metadata key vimpact writes.
META_PREFIX = "vimpact."
#: Metadata keys stored as JSON.
JSON_KEYS = ("numerics", "units", "columns", "statuses", "paths", "rotation", "counts")
#: Metadata keys stored as integers.
INT_KEYS = ("schema_version", "seed", "rows", "chunk", "row_start", "row_stop", "n_chunks",
            "chunk_size")
#: Name of the dataset file that holds the schema and the sweep metadata.
COMMON_METADATA = "_common_metadata"


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


def write_atomic(table, path: Path, *, schema_only: bool = False, more=()) -> None:
    """Write the ``pyarrow`` ``table`` (or only its schema) to ``path``: a temporary
    file in the same directory, fsync, ``os.replace``, fsync of the directory.
    ``more``: further tables (same schema) appended one row group each, read one
    at a time, so that memory stays bounded by the largest of them."""
    import pyarrow.parquet as pq
    path = Path(path)
    tmp = path.with_name(f".{path.name}.{socket.gethostname()}.{os.getpid()}.tmp")
    try:
        with open(tmp, "wb") as f:
            if schema_only:
                pq.write_metadata(table.schema, f)
            elif more:
                with pq.ParquetWriter(f, table.schema) as writer:
                    writer.write_table(table)
                    for other in more:
                        writer.write_table(other.replace_schema_metadata(table.schema.metadata))
            else:
                pq.write_table(table, f)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()
    fsync_dir(path.parent)


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
    """Finished chunks in ``parts`` (removing temporaries of writes cut short);
    refuses parts of another sweep."""
    import pyarrow.parquet as pq
    found: dict[int, Path] = {}
    if not parts.is_dir():
        return found
    remove_temporaries(parts)
    for path in sorted(parts.glob("part-*.parquet")):
        try:
            meta = decode_metadata(pq.read_schema(path).metadata)
        except Exception:  # noqa: BLE001 - an unreadable part is computed again
            import sys
            print(f"vimpact sweep: {path} is unreadable; computing it again", file=sys.stderr)
            path.unlink()
            continue
        got = meta.get("sweep_hash", "")
        if got != spec.sweep_hash:
            raise ValueError(
                f"{path} belongs to another sweep (a different spec, numerics or vimpact "
                f"version: hash {got[:12] or 'missing'} != {spec.sweep_hash[:12]}); "
                f"remove {parts} to start over")
        chunk = meta.get("chunk")
        if not isinstance(chunk, int) or not 0 <= chunk < spec.n_chunks \
                or path != part_path(parts, chunk, spec.n_chunks):
            raise ValueError(f"{path} does not fit this sweep (chunk {chunk}); "
                             f"remove {parts} to start over")
        found[chunk] = path
    return found


def write_part(spec, table, parts: Path, chunk: int, summary_: dict) -> Path:
    """Write the table of ``chunk`` atomically with the sweep metadata, its row range
    and its summary (``counts``, ``paths``)."""
    start, stop = spec.chunk_rows(chunk)
    meta = {**spec.metadata(), "chunk": chunk, "row_start": start, "row_stop": stop,
            "n_chunks": spec.n_chunks, **summary_}
    path = part_path(parts, chunk, spec.n_chunks)
    write_atomic(table.replace_schema_metadata(encode_metadata(meta)), path)
    return path


def is_complete(spec, out: Path) -> bool:
    """``out`` is the finished table of ``spec`` (same sweep hash)."""
    import pyarrow.parquet as pq
    target = schema_path(out)
    if not target.is_file():
        return False
    try:
        meta = decode_metadata(pq.read_schema(target).metadata)
    except Exception:  # noqa: BLE001
        return False
    return meta.get("sweep_hash") == spec.sweep_hash and "paths" in meta


def combine(spec, parts: Path, out: Path, explain_paths) -> None:
    """Finish the table from the parts: check that every chunk is there and that they
    add up to rows ``0 .. rows-1``; merge the part summaries into the ``paths``
    metadata (``explain_paths(first_rows) -> {path: reasons}``); then write ``OUT``
    (file: the parts concatenated, parts removed) or ``OUT/_common_metadata``
    (dataset)."""
    import shutil

    import pyarrow.parquet as pq

    found = existing_parts(spec, parts)
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
    meta = encode_metadata({**spec.metadata(), "paths": paths})
    if spec.table_layout == "dataset":
        write_atomic(spec.schema().empty_table().replace_schema_metadata(meta),
                     out / COMMON_METADATA, schema_only=True)
        return
    # one row group per part, read one at a time: memory bounded by the chunk size
    first = pq.read_table(found[0]).replace_schema_metadata(meta)
    rest = (pq.read_table(found[c]) for c in range(1, spec.n_chunks))
    out.parent.mkdir(parents=True, exist_ok=True)
    write_atomic(first, out, more=rest)
    shutil.rmtree(parts)


# ---- the output: checks and lock ----------------------------------------------------

def check_output(out: Path, layout: str) -> None:
    """Refuse an output that cannot be written, before any work: not ``.parquet``, a
    directory where a file is to go (or a file where a dataset is to go), or a place
    without write permission."""
    out = Path(out)
    if out.suffix != ".parquet":
        raise ValueError(f"--out = {str(out)!r} is not allowed: the table's name must end "
                         "in .parquet")
    if layout == "file" and out.is_dir():
        raise ValueError(f"--out = {str(out)!r} is not allowed: it is a directory, and this "
                         "sweep writes one file (layout = \"file\")")
    if layout == "dataset" and out.exists() and not out.is_dir():
        raise ValueError(f"--out = {str(out)!r} is not allowed: it is a file, and this sweep "
                         "writes a dataset directory (layout = \"dataset\")")
    existing = out if (layout == "dataset" and out.is_dir()) else out.parent
    while not existing.exists():
        existing = existing.parent
    if not existing.is_dir() or not os.access(existing, os.W_OK | os.X_OK):
        raise ValueError(f"--out = {str(out)!r} is not allowed: {existing} is not a "
                         "writable directory")


class OutputLock:
    """An exclusive lock on ``OUT.lock`` (``fcntl.flock``, released by the kernel when the
    process dies, even by kill -9): a second sweep into the same output is refused."""

    def __init__(self, out: Path):
        self.path = Path(out).with_name(Path(out).name + ".lock")
        self.fd: int | None = None

    def __enter__(self) -> "OutputLock":
        import fcntl
        self.path.parent.mkdir(parents=True, exist_ok=True)
        fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            try:
                holder = os.read(fd, 200).decode(errors="replace").strip() or "unknown"
            finally:
                os.close(fd)
            raise ValueError(f"another sweep is writing {self.path.with_suffix('')} "
                             f"({holder}); wait for it, or stop it first") from None
        os.ftruncate(fd, 0)
        os.write(fd, f"pid {os.getpid()} on {socket.gethostname()}".encode())
        self.fd = fd
        return self

    def __exit__(self, *exc) -> None:
        if self.fd is not None:
            try:
                self.path.unlink()
            except FileNotFoundError:
                pass
            os.close(self.fd)
            self.fd = None


__all__ = ["COMMON_METADATA", "INT_KEYS", "JSON_KEYS", "META_PREFIX", "OutputLock",
           "check_output", "combine", "decode_metadata", "decode_value", "encode_metadata",
           "encode_value", "existing_parts", "fsync_dir", "is_complete", "part_path",
           "parts_dir", "read_metadata", "remove_temporaries", "summary", "write_atomic",
           "write_part"]
