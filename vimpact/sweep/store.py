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
is finished, and the file layout is combined one part at a time
(a table of at most :data:`HOLD_ROWS` rows, no more than the largest chunk the
runner chooses, is held whole between the check of its parts and its write).
Row groups: :data:`~vimpact.tableformat.files.ROW_GROUP_ROWS` rows each from the
first row of each part (one for a part of at most that many rows), in a part and in
the table alike; a one-chunk sweep's table is written one row group at a time while
the next is computed (:func:`_write_streamed`), the same bytes as written whole.

Every write is atomic (a temporary file in the same directory, fsync,
``os.replace``, fsync of the directory), so a run killed anywhere (kill -9)
leaves finished parts and no half-written file; a resumed run gives the
identical table. Each part stores the sweep hash (spec text, numerics,
package and schema version), its chunk and row range, and a small summary
(rows per status, rows and first row per kernel path) that the combination
merges without reading the data again.

Integrity: every part and every table is written with Parquet page checksums (CRC-32
of each page), a content hash ``vimpact.content_sha256``
(:class:`~vimpact.tableformat.integrity.ContentHash`: SHA-256 of the column values in
a canonical form, independent of the Parquet encoding) and a hash of the ``vimpact.*``
metadata entries ``vimpact.metadata_sha256``
(:func:`~vimpact.tableformat.integrity.metadata_hash`: the footer has no checksum). A
part is trusted only after :func:`verify_part` has read it back (page checksums
checked, hash recomputed): ``--resume`` moves a part that fails to
``<parts>/_corrupt/`` (one line on stderr names it and the reason) and computes it
again; the combination verifies every part as it reads it (once: a part is read and
hashed once, unless the table is larger than :data:`HOLD_ROWS` rows, when it is read
once more to be written and its rows are hashed again as they are written), writes
the table with the content hash of the rows verified, and checks the footer it wrote
(metadata hash, content hash, rows) before it removes any part. The one chunk of a
one-chunk file-layout sweep is written straight to the table, its hash computed from
the rows in memory (no part). A table without a stored hash (written before it
existed) is accepted with the hash check skipped.

Metadata: the Parquet key-value metadata ``vimpact.<key>``, written and read with the
one codec of :mod:`vimpact.tableformat.metadata`, which the reader
(:mod:`vimpact.lookup.table`) uses too. The table format itself (codec, content and
metadata hashes, :func:`~vimpact.tableformat.integrity.verify_table`, atomic writes
and the output lock) lives in :mod:`vimpact.tableformat`; this module holds what is
the sweep's own: its parts, their checks and their combination into the table.
"""

from __future__ import annotations

import errno
import os
import shutil
import sys
from pathlib import Path
from typing import cast

from vimpact.model.validation import InputError
from vimpact.sweep.spec import AUTO_CHUNK_ROWS
from vimpact.tableformat.files import (
    TableStream,
    fsync_dir,
    refuse_symlink,
    remove_temporaries,
    write_atomic,
)
from vimpact.tableformat.integrity import (
    CONTENT_HASH_KEY,
    ContentHash,
    Damaged,
    check_metadata_hash,
    first_line,
    open_checked,
    rows_in_footer,
    scan,
    verify_table,
)
from vimpact.tableformat.metadata import (
    COMMON_METADATA,
    decode_metadata,
    encode_metadata,
    schema_path,
)

#: Subdirectory of the parts directory that damaged parts are moved to.
CORRUPT_DIR = "_corrupt"


def summary(path) -> dict[str, int]:
    """Return the number of rows per status in the table (file or dataset) at ``path``."""
    import pyarrow.parquet as pq
    status = pq.read_table(path, columns=["status"]).column("status")
    counts = status.value_counts().to_pylist()
    return {c["values"]: int(c["counts"]) for c in sorted(counts, key=lambda c: c["values"])}


# ---- part verification---------------------------------------------------------------

def _check_part(path: Path, spec, hasher: ContentHash | None = None,
                keep: list | None = None) -> tuple[str, str | None]:
    """Check a part: ``("ok", None)``, ``("foreign", why)`` or ``("bad", why)``.

    ``"foreign"``: a part of another sweep (its own vimpact metadata, another sweep
    hash). ``hasher`` receives its rows, ``keep`` its row groups (:func:`scan`).
    """
    path = Path(path)
    try:
        pf = open_checked(path)
        meta = decode_metadata(pf.schema_arrow.metadata)
    except Damaged as exc:
        return "bad", str(exc)
    except Exception as exc:  # noqa: BLE001
        return "bad", f"schema unreadable ({first_line(exc)})"
    try:  # first: a damaged sweep hash must not pass for another sweep's
        check_metadata_hash(pf.schema_arrow.metadata)
    except Damaged as exc:
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
        _, _, rows = scan(path, hasher, keep)
    except Damaged as exc:
        return "bad", str(exc)
    if rows != stop - start:
        return "bad", f"holds {rows} rows, chunk {chunk} has {stop - start}"
    return "ok", None


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


# ---- parts -------------------------------------------------------------------------

def parts_dir(out, layout: str = "file") -> Path:
    """Return the directory of the finished chunks of a run writing ``out``.

    ``OUT.parts`` for the file layout, ``OUT`` itself for a dataset.
    """
    out = Path(out)
    return out if layout == "dataset" else out.with_name(out.name + ".parts")


def part_path(parts: Path, chunk: int, n_chunks: int) -> Path:
    """Return the part file of ``chunk`` (zero-padded so that name order is chunk order)."""
    width = max(5, len(str(n_chunks - 1)))
    return Path(parts) / f"part-{chunk:0{width}d}.parquet"


def existing_parts(spec, parts: Path) -> dict[int, Path]:
    """Return the finished chunks in ``parts``, each verified (:func:`verify_part`).

    Temporaries of writes cut short are removed first.

    A part that fails (damaged, truncated, not a vimpact part, the wrong chunk) is
    treated as missing: it is moved to ``<parts>/_corrupt/`` (never deleted) with
    one line on stderr naming it and the reason, and ``--resume`` computes it
    again. Parts of another sweep (their own vimpact metadata with another sweep
    hash) are refused (``ValueError``): the output is probably the wrong one. In a
    dataset directory a file that is not one of its parts is refused too (it
    would be read as table rows).
    """
    return _existing_parts(spec, parts)


def _existing_parts(spec, parts: Path, hasher: ContentHash | None = None,
                    keep: list | None = None) -> dict[int, Path]:
    """Return :func:`existing_parts`, the good parts' rows fed to ``hasher``.

    ``hasher`` receives the rows of the good parts in chunk order (the content hash
    of the table when no chunk is missing); ``keep`` their rows (one ``pyarrow``
    table per good part, in chunk order).
    """
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
        groups: list | None = [] if keep is not None else None
        kind, why = _check_part(path, spec, hasher, groups)
        if kind == "foreign":
            raise ValueError(f"{path} {why}; remove {parts} to start over")
        if kind == "bad":
            assert why is not None  # _check_part says why a part is bad
            try:
                aside = move_aside(path)
            except FileNotFoundError:  # another process (a shard) moved or replaced it
                continue
            print(f"vimpact sweep: {path.name} {_as_phrase(why)}; moved to {aside}, "
                  "computing it again", file=sys.stderr)
            continue
        found[int(path.name[len("part-"):-len(".parquet")])] = path
        if keep is not None and groups is not None:
            import pyarrow as pa
            keep.append(pa.concat_tables(groups))
    return found


def _as_phrase(why: str) -> str:
    """Return a reason as the rest of a sentence whose subject is the file.

    E.g. ``"is truncated (...)"``, ``"fails: content hash mismatch (...)"``.
    """
    starts = ("truncated", "empty", "not ", "unreadable")
    return ("is " if why.startswith(starts) else "fails: ") + why


def move_aside(path: Path) -> Path:
    """Move a damaged file to ``<its directory>/_corrupt/`` and return where it went.

    It gets a new name if one is there already; nothing is deleted.
    """
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


def write_part(spec, table, parts: Path, chunk: int, summary_: dict,
               content_sha256: str | None = None) -> Path:
    """Write the table of ``chunk`` atomically.

    With the sweep metadata, its row range, its summary (``counts``, ``paths``),
    page checksums and its content hash (``content_sha256``: computed by the caller
    from ``table``, e.g. together with the whole table's; computed here if ``None``).

    A failed write (e.g. disk full) raises ``OSError`` saying that the finished
    parts are kept and how to continue.
    """
    start, stop = spec.chunk_rows(chunk)
    meta = {**spec.metadata(), "chunk": chunk, "row_start": start, "row_stop": stop,
            "n_chunks": spec.n_chunks, **summary_}
    path = part_path(parts, chunk, spec.n_chunks)
    try:
        write_atomic(table.replace_schema_metadata(encode_metadata(meta)), path,
                     content_sha256=content_sha256)
    except OSError as exc:
        raise _kept(exc, parts) from exc
    return path


def _kept(exc: OSError, parts: Path) -> OSError:
    """Return the error of a failed write, saying that the finished parts are kept.

    "make room" only when the disk (or a quota) is full.
    """
    full = exc.errno in (errno.ENOSPC, errno.EDQUOT)
    return OSError(exc.errno, f"{exc.strerror or first_line(exc)}; the finished chunks are "
                   f"kept in {parts}: {'make room and ' if full else ''}continue with --resume")


def is_complete(spec, out: Path) -> bool:
    """Tell whether ``out`` is the finished table of ``spec``.

    Same sweep hash, and it passes :func:`verify_table`. A finished table that fails
    is not complete: one line on stderr says why; a file is moved to ``<out>.corrupt`` (a dataset keeps its
    place: :func:`existing_parts` moves its damaged parts aside), so that the run
    writes it again.
    """
    import pyarrow.parquet as pq
    target = schema_path(out)
    if not target.is_file():
        return False
    try:
        meta = decode_metadata(pq.read_schema(target).metadata)
    except Exception:  # noqa: BLE001
        return False
    # a sweep records its kernels' paths; an adaptive or adhesive table (`vimpact table
    # build`) is made cell by cell and has none
    made = "paths" in meta or meta.get("mode") in ("adaptive", "adhesion")
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


#: Rows of a file-layout table whose parts :func:`combine` holds in memory from their
#: check to the write (one read of each part); a larger table is read twice, one part
#: at a time (as many rows as the largest chunk the runner chooses).
HOLD_ROWS = AUTO_CHUNK_ROWS[1]


def combine(spec, parts: Path, out: Path, explain_paths, fresh=None,
            fresh_digest: str | None = None, pieces=None) -> None:
    """Finish the table from the parts.

    Verify every part (:func:`existing_parts`:
    a damaged one is moved aside and reported missing), check that every chunk is
    there and that they add up to rows ``0 .. rows-1``; merge the part summaries
    into the ``paths`` metadata (``explain_paths(first_rows) -> {path: reasons}``);
    then write ``OUT`` (file: the parts concatenated with page checksums and the
    content hash of all rows) or ``OUT/_common_metadata`` (dataset, with the
    content hash over its parts), check what was written (:func:`_check_written`)
    and only then remove the parts (file layout; damaged parts moved aside stay
    in ``<parts>/_corrupt``).

    Each part is read and hashed once to be verified (its own hash and the table's
    from one canonical form); the file layout reads it once more to write it (one
    part in memory at a time), hashing the rows again as they are written: the
    table replaces nothing unless they give the hash verified before (a part
    changed in between). A sweep of one part keeps it in memory from the check: one
    read (and so do the parts of a table of at most :data:`HOLD_ROWS` rows: memory
    stays bounded by a chunk, or by that many rows). ``fresh``: ``(table, summary)``
    of every chunk of a file-layout table, just computed in this process (at most
    :data:`HOLD_ROWS` rows, or one chunk), in chunk order: the table is written from
    them with its content hash computed from the rows in memory (``fresh_digest``, if
    the caller computed it from them as they were made, else here) and the parts are
    not read (:func:`_write_fresh`); a one-chunk sweep has no part. ``pieces``: the
    ``(table, summary)`` of each row group of a one-chunk file-layout table in row
    order, computed as they are asked for: each is written while the next is computed
    (:func:`_write_streamed`).
    """
    import pyarrow.parquet as pq

    if pieces is not None:
        _write_streamed(spec, parts, out, explain_paths, pieces)
        return
    if fresh is not None:
        _write_fresh(spec, parts, out, explain_paths, fresh, fresh_digest)
        return
    whole = ContentHash()
    held: list | None = [] if spec.table_layout == "file" and (
        spec.n_chunks == 1 or spec.rows <= HOLD_ROWS) else None
    found = _existing_parts(spec, parts, whole, held)
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
    paths = _explained(paths, explain_paths)
    digest = whole.hexdigest()
    if spec.table_layout == "dataset":
        meta = encode_metadata({**spec.metadata(), "paths": paths, CONTENT_HASH_KEY: digest})
        write_atomic(spec.schema().empty_table().replace_schema_metadata(meta),
                     out / COMMON_METADATA, schema_only=True)
        _check_written(out / COMMON_METADATA, parts, spec.rows, digest)
        return
    meta = encode_metadata({**spec.metadata(), "paths": paths})
    # a part's row groups (ROW_GROUP_ROWS rows from its first row), one part read at a
    # time: memory bounded by the chunk size

    def read(chunk):
        if held is not None:  # read for its check
            return held[chunk]
        return pq.read_table(found[chunk], page_checksum_verification=True)
    first = read(0).replace_schema_metadata(meta)
    rest = (read(c) for c in range(1, spec.n_chunks))
    out.parent.mkdir(parents=True, exist_ok=True)
    check_room(out, parts, sum(found[c].stat().st_size for c in range(spec.n_chunks)))
    try:
        write_atomic(first, out, more=rest, content_sha256=digest, recheck=held is None)
    except OSError as exc:
        raise _kept(exc, parts) from exc
    except Damaged as exc:
        raise ValueError(f"{exc}; the parts in {parts} are kept: run again with "
                         "--resume") from None
    _check_written(out, parts, spec.rows, digest)
    for chunk in range(spec.n_chunks):
        found[chunk].unlink()
    _remove_parts_dir(parts)


def _explained(paths: dict, explain_paths) -> dict:
    """Return the ``paths`` metadata with each path's routing reasons."""
    reasons = explain_paths({name: e["first_row"] for name, e in paths.items()})
    return {name: {**e, "reasons": reasons[name]} for name, e in paths.items()}


def _remove_parts_dir(parts: Path) -> None:
    """Remove the parts directory of a finished file-layout table (kept if not empty)."""
    remove_temporaries(parts)
    try:
        parts.rmdir()
    except FileNotFoundError:
        pass
    except OSError:  # something else is there (damaged parts moved aside): kept
        print(f"vimpact sweep: {parts} is kept: it holds files that are not finished parts "
              f"({', '.join(sorted(p.name for p in parts.iterdir()))})", file=sys.stderr)
    fsync_dir(parts.parent)


def _write_fresh(spec, parts: Path, out: Path, explain_paths, fresh: list,
                 digest: str | None = None) -> None:
    """Write a file-layout table from its chunks in memory, all just computed.

    ``fresh``: ``(table, summary)`` of every chunk in chunk order. The content hash
    is computed from the rows in memory (``digest``: given by the caller, who computed
    it from them; computed here if ``None``, for one chunk while its table is encoded:
    :func:`~vimpact.tableformat.files.write_atomic`), the parts (if any) are not read: the
    table is the one :func:`combine` would make from them, byte for byte, and they are
    removed once it is written and its footer checked. One chunk has no part: a
    failed write (disk full) keeps nothing, the chunk is computed again by the next
    run.
    """
    tables = [table for table, _ in fresh]
    if spec.table_layout != "file" or len(fresh) != spec.n_chunks \
            or [t.num_rows for t in tables] != [b - a for a, b in map(
                spec.chunk_rows, range(spec.n_chunks))]:
        raise ValueError(f"a file-layout table is written from memory only from all its "
                         f"chunks ({spec.n_chunks} chunk(s), layout {spec.table_layout!r}, "
                         f"{len(fresh)} given)")
    paths = _explained(_merged_paths(summary_ for _, summary_ in fresh), explain_paths)
    if digest is None and len(tables) > 1:
        whole = ContentHash()
        for table in tables:
            whole.update(table)
        digest = whole.hexdigest()
    meta = encode_metadata({**spec.metadata(), "paths": paths})
    out.parent.mkdir(parents=True, exist_ok=True)
    written = [part_path(parts, c, spec.n_chunks) for c in range(spec.n_chunks)
               if spec.n_chunks > 1]
    if written:
        check_room(out, parts, sum(p.stat().st_size for p in written))
    try:
        # (one table without a digest: hashed while it is encoded, write_atomic)
        digest = cast(str, write_atomic(tables[0].replace_schema_metadata(meta), out,
                                        more=tables[1:], content_sha256=digest))
    except OSError as exc:
        if written:
            raise _kept(exc, parts) from exc
        full = exc.errno in (errno.ENOSPC, errno.EDQUOT)
        raise OSError(exc.errno, f"{exc.strerror or first_line(exc)}; the sweep's one chunk "
                      f"was to be written straight to {out}, nothing is kept: "
                      f"{'make room and ' if full else ''}run it again") from exc
    _check_written(out, parts if written else None, spec.rows, digest)
    for path in written:
        path.unlink()
    if parts.is_dir():
        _remove_parts_dir(parts)


def _merged_paths(summaries) -> dict:
    """Return the ``paths`` of chunk summaries in row order, merged: rows summed, first row kept."""
    paths: dict = {}
    for summary_ in summaries:
        for name, entry in summary_["paths"].items():
            if name not in paths:
                paths[name] = {"rows": 0, "first_row": entry["first_row"]}
            paths[name]["rows"] += entry["rows"]
    return paths


def _write_streamed(spec, parts: Path, out: Path, explain_paths, pieces) -> None:
    """Write a one-chunk file-layout table from its row groups as they are computed.

    ``pieces``: ``(table, summary)`` of each row group in row order
    (:data:`~vimpact.tableformat.files.ROW_GROUP_ROWS` rows each but the last), computed
    when the loop asks for the next: each is hashed and encoded on a thread
    (:class:`~vimpact.tableformat.files.TableStream`) while the next is computed. The
    table is the one :func:`_write_fresh` writes from the whole chunk, byte for byte
    (the same row groups, metadata and content hash). No part: an interruption or a
    failed write (disk full) keeps nothing, the chunk is computed again by the next run.
    """
    if spec.table_layout != "file" or spec.n_chunks != 1:
        raise ValueError(f"a table is written from its row groups as they are computed only "
                         f"for one chunk of a file layout ({spec.n_chunks} chunk(s), layout "
                         f"{spec.table_layout!r})")
    out.parent.mkdir(parents=True, exist_ok=True)
    summaries = []
    try:
        with TableStream(out, spec.schema()) as stream:
            for table, summary_ in pieces:
                stream.add(table)
                summaries.append(summary_)
            if stream.rows != spec.rows:
                raise ValueError(f"{out}: {stream.rows} rows computed, the sweep has "
                                 f"{spec.rows}; nothing written")
            # one chunk's summary lists its paths by name (chunk_summary)
            paths = _explained(dict(sorted(_merged_paths(summaries).items())), explain_paths)
            digest = stream.finish(encode_metadata({**spec.metadata(), "paths": paths}))
    except OSError as exc:
        full = exc.errno in (errno.ENOSPC, errno.EDQUOT)
        raise OSError(exc.errno, f"{exc.strerror or first_line(exc)}; the sweep's one chunk "
                      f"was to be written straight to {out}, nothing is kept: "
                      f"{'make room and ' if full else ''}run it again") from exc
    _check_written(out, None, spec.rows, digest)
    if parts.is_dir():
        _remove_parts_dir(parts)


#: Free disk kept beyond the parts' size when a file-layout table is combined, bytes.
COMBINE_MARGIN_BYTES = 2**20


def check_room(out: Path, parts: Path, parts_bytes: int) -> None:
    """Refuse to combine a file-layout table when its folder lacks the room.

    The table (about the size of its parts) is written while the parts still exist, and they are
    removed only after it is verified, so the end of a sweep needs about twice the
    table's size. ``OSError`` (``ENOSPC``) saying how much, before anything is written.
    """
    need = parts_bytes + COMBINE_MARGIN_BYTES
    free = shutil.disk_usage(out.parent).free
    if free < need:
        raise OSError(errno.ENOSPC, f"not enough free disk to combine {out}: it needs about "
                      f"{need / 2**20:.1f} MiB in {out.parent} (the size of its parts, which "
                      f"are removed only after the table is verified), {free / 2**20:.1f} MiB "
                      f"are free; the finished chunks are kept in {parts}: make room and "
                      "continue with --resume")


def _check_written(out: Path, parts: Path | None, rows: int, digest: str) -> None:
    """Check the footer of a table (or ``_common_metadata``) just written.

    ``ValueError`` if it fails, saying that the ``parts`` it was made from are kept
    (``None``: written from memory, nothing kept).

    The file ends with a Parquet footer that reads, its metadata gives its stored
    metadata hash, it stores the content hash ``digest`` (computed from the verified
    parts, or from the rows in memory, as they were written) and, a file, ``rows``
    rows. The data are not read back: :func:`verify_table` does that for a reader.
    """
    try:
        pf = open_checked(out)
        raw = pf.schema_arrow.metadata
        check_metadata_hash(raw)
        meta = decode_metadata(raw)
        if meta.get(CONTENT_HASH_KEY) != digest:
            raise Damaged(f"content hash {str(meta.get(CONTENT_HASH_KEY))[:12]}... stored, "
                          f"{digest[:12]}... written")
        if out.name != COMMON_METADATA and rows_in_footer(pf) != rows:
            raise Damaged(f"{rows_in_footer(pf)} rows in its footer, {rows} written")
    except Damaged as exc:
        after = ("run the sweep again" if parts is None else f"it was just written from "
                 f"the parts in {parts}, which are kept: run again with --resume")
        raise ValueError(f"{out} fails its check: {exc}; {after}") from None


# ---- the output: checks and lock ----------------------------------------------------

def check_output(out: Path, layout: str, name: str = "--out") -> None:
    """Refuse an output that cannot be written, before any work.

    Not ``.parquet``, a directory where a file is to go (or a file where a dataset is to go), or a place
    without write permission. ``name``: how the user gave the output (``--out``, or
    the spec's ``output`` key), for the message.
    """
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


__all__ = ["CORRUPT_DIR", "check_output", "combine", "existing_parts", "is_complete",
           "move_aside", "part_path", "parts_dir", "summary", "verify_part", "write_part"]
