"""Files vimpact writes: atomic replacement, no symbolic links, an output lock.

Every write is atomic (a temporary file in the same directory, fsync,
``os.replace``, fsync of the directory), so a process killed anywhere (kill -9)
leaves no half-written file; a file vimpact creates or replaces is never reached
through a symbolic link (:func:`refuse_symlink`); a table is written with page
checksums and its content and metadata hashes (:func:`write_atomic`); one writer
at a time holds an output's lock (:class:`OutputLock`).
"""

from __future__ import annotations

import contextlib
import errno
import itertools
import os
import socket
from pathlib import Path

from vimpact.model.validation import InputError
from vimpact.tableformat.integrity import (
    CONTENT_HASH_KEY,
    PARALLEL_HASH_BYTES,
    ContentHash,
    Damaged,
    content_hash,
    first_line,
    with_metadata_hash,
)
from vimpact.tableformat.metadata import META_PREFIX

#: Parquet compression of every table and part written (zstd: the shipped adaptive
#: standard-solid table is 10.1 MB, 11.8 MB with snappy; the content hash is of the data,
#: not of the file's bytes, so it does not depend on it).
COMPRESSION = "zstd"
#: Values a Parquet column writer takes at a time: Arrow's default (1024) made the write
#: of a 1e5-row sweep table about 10 % slower in CPU; the pages and the file's bytes are
#: the same (a data page still closes at its size limit).
WRITE_BATCH_ROWS = 65536
#: Key-value metadata key of the Arrow schema that pyarrow stores in a Parquet footer.
ARROW_SCHEMA_KEY = b"ARROW:schema"
#: Rows of one Parquet row group at most: every table and part is written in row groups of
#: this many rows from its first row (one part or chunk after another), the last one
#: shorter. A sweep's one chunk is computed in pieces of at most this many rows, each
#: hashed, and each row group encoded, while the next pieces are computed
#: (:class:`TableStream`); the file is the same bytes either way. A table of at most this
#: many rows is one row group.
ROW_GROUP_ROWS = 25_000


def parquet_options(schema) -> dict:
    """Return the Parquet writer options of every table and part vimpact writes.

    Page checksums, :data:`COMPRESSION`, and dictionary encoding for the text columns
    only (status, path, model, error: a few distinct values each). A float column is
    written plain: its results are mostly distinct values, so a dictionary is tried
    and dropped page by page, which took 40 % of a sweep table's write time (and
    the file came out larger: 1.71 MB against 1.45 MB for 1e5 Kelvin-Voigt rows).
    Values go to the encoder :data:`WRITE_BATCH_ROWS` at a time.
    """
    import pyarrow as pa

    text = [f.name for f in schema if pa.types.is_string(f.type)
            or pa.types.is_large_string(f.type) or pa.types.is_dictionary(f.type)]
    return {"write_page_checksum": True, "compression": COMPRESSION, "use_dictionary": text,
            "write_batch_size": WRITE_BATCH_ROWS}


def fsync_dir(path: Path) -> None:
    """Fsync a directory (its entries survive a crash); a no-op where not possible."""
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
    """Raise :class:`InputError` if ``path`` is a symbolic link.

    A file vimpact creates or replaces is never reached through one (its target would be overwritten). The
    message names ``name = value`` (default: ``path``), as the user gave it.
    """
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
    temporary file is removed and an earlier ``path`` stays as it was.
    """
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


def write_frame(data, metadata: dict[str, str], path: Path) -> Path:
    """Write the DataFrame ``data`` with the Parquet key-value ``metadata`` (text) to ``path``.

    Through :func:`write_atomic`: atomically, with page checksums and fresh content
    and metadata hashes (stored hashes describe the file a table was read from, not
    these columns). Returns ``path``.
    """
    import pyarrow as pa

    arrow = pa.Table.from_pandas(data, preserve_index=False)
    meta = dict(arrow.schema.metadata or {})
    meta.update({k.encode(): v.encode() for k, v in metadata.items()})
    write_atomic(arrow.replace_schema_metadata(meta), Path(path))
    return Path(path)


def write_atomic(table, path: Path, *, schema_only: bool = False, more=(),
                 content_sha256: str | None = None, recheck: bool = False) -> str | None:
    """Write the ``pyarrow`` ``table`` (or only its schema) to ``path`` atomically.

    A temporary file in the same directory, fsync, ``os.replace``, fsync of the directory.

    Data is written with Parquet page checksums and the metadata
    ``vimpact.metadata_sha256`` (:func:`metadata_hash`, also for ``schema_only``,
    whenever there are ``vimpact.*`` entries) and
    ``vimpact.content_sha256`` (:class:`ContentHash`), computed here from
    ``table``, or given as ``content_sha256`` (required with ``more``: the hash of
    all rows, which the caller computed while verifying them). ``more``: further
    tables (same schema) appended one row group each, read one at a time, so that
    memory stays bounded by the largest of them. ``schema_only``: the schema with
    its metadata as it is (a dataset's ``_common_metadata``). ``recheck``: the rows
    are hashed again as they are written (``table`` and each of ``more``, one at a
    time) and ``path`` is replaced only if they give ``content_sha256``
    (:class:`~vimpact.tableformat.integrity.Damaged` otherwise): for rows read from
    files that were verified before, which could have changed since.

    A table of at least :data:`~vimpact.tableformat.integrity.PARALLEL_HASH_BYTES`
    whose hash is computed here is hashed while Parquet encodes it
    (:func:`_write_hashing`; pyarrow >= 17, else first).

    Returns the content hash written (``None`` for ``schema_only``). Raises ``OSError``
    naming ``path`` when the write fails (e.g. ``ENOSPC``, disk full); the temporary
    file is removed and an earlier ``path`` stays as it was.
    """
    import pyarrow.parquet as pq
    path = Path(path)
    if not schema_only and content_sha256 is None and not more and not recheck \
            and hasattr(pq.ParquetWriter, "add_key_value_metadata") \
            and table.nbytes >= PARALLEL_HASH_BYTES:
        return _write_hashing(table, path)
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
        table = with_metadata_hash(table)
    again = ContentHash() if recheck and not schema_only else None
    try:
        with atomic_file(path, str(path)) as f:
            if schema_only:
                pq.write_metadata(table.schema, f)
            elif more:
                with pq.ParquetWriter(f, table.schema, **parquet_options(table.schema)) \
                        as writer:
                    for k, piece in enumerate(itertools.chain([table], more)):
                        if again is not None:
                            again.update(piece)
                        writer.write_table(piece if k == 0 else
                                           piece.replace_schema_metadata(table.schema.metadata),
                                           row_group_size=ROW_GROUP_ROWS)
            else:
                if again is not None:
                    again.update(table)
                pq.write_table(table, f, row_group_size=ROW_GROUP_ROWS,
                               **parquet_options(table.schema))
            if again is not None and again.hexdigest() != content_sha256:
                raise Damaged(f"the rows written to {path} do not give the content hash "
                              f"{str(content_sha256)[:12]}... (data "
                              f"{again.hexdigest()[:12]}...): "
                              "a source changed while it was written; nothing was replaced")
    except OSError as exc:
        raise OSError(exc.errno, f"{exc.strerror or first_line(exc)} while writing "
                      f"{path}") from exc
    return content_sha256


def _write_hashing(table, path: Path) -> str:
    """Write ``table`` as :func:`write_atomic` does, hashing its rows while Parquet encodes them.

    Its row groups go through a :class:`TableStream` (the content hash on one thread,
    the pages on another, the key-value metadata with the hashes and the Arrow schema
    in the footer, :func:`_footer`). The file reads back as the one :func:`write_atomic`
    writes otherwise: the same columns, schema and metadata. Returns the content hash.
    """
    with TableStream(path, table.schema) as stream:
        for start in range(0, table.num_rows, ROW_GROUP_ROWS):
            stream.add(table.slice(start, ROW_GROUP_ROWS))
        return stream.finish(table.schema.metadata)


def _footer(schema, metadata, digest: str) -> dict:
    """Return the footer key-value metadata of a table written without a schema at the start.

    ``metadata`` (the table's key-value metadata), the content hash ``digest``, the
    metadata hash, and the Arrow schema with all of them (``ARROW:schema``, as the
    writer would store it).
    """
    import base64

    meta = dict(metadata or {})
    meta[(META_PREFIX + CONTENT_HASH_KEY).encode()] = digest.encode()
    meta = dict(with_metadata_hash(schema.with_metadata(meta)).metadata)
    stored = base64.b64encode(schema.with_metadata(meta).serialize())
    return {**meta, ARROW_SCHEMA_KEY: stored}


def _detached(call, *args, **kwargs):
    """Return ``call(*args, **kwargs)``; an ``OSError`` as a new one, without its traceback.

    The traceback of an error in a Parquet writer's call holds the writer (a local of
    its frames), and a writer freed after a failed write reports the error again,
    formatting a traceback from C: freed by a later garbage collection, that can
    happen inside a parse of Python source (an import), which CPython 3.11 before
    3.11.8 then fails (``AST constructor recursion depth mismatch``). With the error
    detached, the writer is freed where its owner lets it go.
    """
    failed = None
    try:
        return call(*args, **kwargs)
    except OSError as exc:
        failed = (exc.errno, exc.strerror or first_line(exc))
    del call, args, kwargs  # (the raised error's frame holds no writer)
    raise OSError(*failed)


class TableStream:
    """Write a table atomically from its rows as they are made (a context manager).

    ``add(piece)`` hands the next rows (a ``pyarrow`` table of ``schema``'s columns, any
    number of rows) to two threads of its own and returns at once (an error of a piece
    written before is raised here): one hashes the pieces in order as they come
    (:class:`ContentHash`: the hash of the rows does not depend on how they are cut),
    one encodes a row group into the file as soon as its :data:`ROW_GROUP_ROWS` rows are
    all there (its pieces joined: the same bytes as the rows added in one piece). The
    caller computes the next pieces while these are written, and the pieces wait in
    memory when the writing lags (at most the rows of the table, which the caller holds
    anyway). ``finish(metadata)`` writes the
    footer with the table's key-value ``metadata``, the content hash of all the pieces
    and the metadata hash (:func:`_footer`) and returns the content hash; the file then
    replaces ``path`` atomically when the ``with`` block ends (:func:`atomic_file`). An
    error or an interruption in the block leaves no file (an earlier ``path`` stays).
    :func:`write_atomic` writes a table of at least
    :data:`~vimpact.tableformat.integrity.PARALLEL_HASH_BYTES` through it (:func:`_write_hashing`).
    """

    def __init__(self, path, schema):
        self.path, self.schema = Path(path), schema.remove_metadata()
        self.hasher = ContentHash()
        self.rows = 0
        self._held: list = []  # the rows added but not yet handed to the encoder
        self._held_rows = 0
        self._pending: list = []  # the hashes and writes of the pieces added
        self._finished: str | None = None

    def __enter__(self) -> TableStream:
        from concurrent.futures import ThreadPoolExecutor

        import pyarrow.parquet as pq

        self._stack = contextlib.ExitStack()
        try:
            self._file = self._stack.enter_context(atomic_file(self.path, str(self.path)))
            self._writer = pq.ParquetWriter(self._file, self.schema, store_schema=False,
                                            **parquet_options(self.schema))
            # one thread each: the hash streams and the pages take the pieces in order
            self._hashing = self._stack.enter_context(ThreadPoolExecutor(1))
            self._encoding = self._stack.enter_context(ThreadPoolExecutor(1))
        except OSError as exc:
            self._stack.__exit__(type(exc), exc, exc.__traceback__)
            raise self._named(exc) from exc
        except BaseException as exc:
            self._stack.__exit__(type(exc), exc, exc.__traceback__)
            raise
        return self

    def _named(self, exc: OSError) -> OSError:
        return OSError(exc.errno, f"{exc.strerror or first_line(exc)} while writing "
                       f"{self.path}")

    def _wait(self) -> None:
        """Wait for every piece added; raise the first error."""
        from concurrent.futures import wait

        pending, self._pending = self._pending, []
        wait(pending)  # all done before an error of any is raised
        for job in pending:
            if not job.cancelled():  # (cancelled by _stop after an error)
                job.result()

    def _raise_done(self) -> None:
        """Raise the error of a piece already written, if any (the rest go on)."""
        if any(job.done() and job.exception() is not None for job in self._pending):
            self._stop()
            self._wait()

    def _stop(self) -> None:
        """Cancel the pieces not started yet."""
        for job in self._pending:
            job.cancel()

    def add(self, piece) -> None:
        """Hash ``piece`` (the next rows) and encode the row groups it completes, on the threads."""
        if self._finished is not None:
            raise ValueError(f"TableStream of {self.path}: add after finish")
        piece = piece.replace_schema_metadata(None)
        try:
            self._raise_done()
        except OSError as exc:
            raise self._named(exc) from exc
        if not piece.num_rows:
            return
        self.rows += piece.num_rows
        # side by side: the stream of the content hash (one thread: beside the
        # computation of the next piece) and the Parquet pages of a full row group
        self._pending.append(self._hashing.submit(self.hasher.update, piece, threads=1))
        self._held.append(piece)
        self._held_rows += piece.num_rows
        while self._held_rows >= ROW_GROUP_ROWS:
            self._encode(ROW_GROUP_ROWS)

    def _encode(self, rows: int) -> None:
        """Hand the first ``rows`` rows held (one row group) to the encoding thread."""
        import pyarrow as pa

        held = self._held[0] if len(self._held) == 1 else pa.concat_tables(self._held)
        self._held = [held.slice(rows)] if held.num_rows > rows else []
        self._held_rows = held.num_rows - rows
        self._pending.append(self._encoding.submit(_detached, self._writer.write_table,
                                                   held.slice(0, rows),
                                                   row_group_size=ROW_GROUP_ROWS))

    def finish(self, metadata) -> str:
        """Write the footer with ``metadata`` and the hashes; return the content hash."""
        try:
            if self._held_rows:  # the last row group (shorter)
                self._encode(self._held_rows)
            self._wait()
            digest = self.hasher.hexdigest()
            self._writer.add_key_value_metadata(_footer(self.schema, metadata, digest))
            _detached(self._writer.close)
        except OSError as exc:
            raise self._named(exc) from exc
        self._finished = digest
        return digest

    def __exit__(self, kind, exc, tb) -> None:
        self._stop()  # an error or an interruption in the block: what runs, ends
        for job in self._pending:
            try:
                job.result()
            except BaseException:  # noqa: BLE001 - the block's own error is raised
                pass
        self._pending = []
        if self._finished is None:
            # released here, not by a later garbage collection (the error's traceback
            # holds this stream): a writer whose close failed reports it again when freed
            writer, self._writer = self._writer, None
            try:
                writer.close()
            except Exception:  # noqa: BLE001 - the temporary file is removed anyway
                pass
            del writer
            if kind is None:  # left without finish(): nothing replaces path
                kind, exc = ValueError, ValueError(
                    f"TableStream of {self.path}: closed before finish(); nothing written")
                self._stack.__exit__(kind, exc, None)
                raise exc
        try:
            self._stack.__exit__(kind, exc, tb)
        except OSError as err:
            if kind is None:
                raise self._named(err) from err
            raise


def remove_temporaries(directory: Path, name: str = "") -> None:
    """Remove temporary files of writes cut short (kill -9) in ``directory``."""
    for stale in Path(directory).glob(f".{name}*.tmp"):
        try:
            stale.unlink()
        except FileNotFoundError:  # another process removed it
            pass


class OutputLock:
    """A lock on ``OUT.lock``.

    ``fcntl.flock``, released by the kernel when the process dies, even by kill -9.

    A plain run, ``--resume`` and ``--combine`` take it exclusively: a second sweep
    into the same output is refused. Shards (``shared=True``) take it shared: any
    number of shards run side by side, but not beside a plain run (either one that
    comes second is refused). A lock file left by a killed sweep does not block
    (nobody holds its lock); a lock taken on a file its holder removed meanwhile is
    taken again on the new one. The lock file is opened with ``O_NOFOLLOW`` (a
    symbolic link there is refused, never followed).
    """

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



__all__ = ["COMPRESSION", "ROW_GROUP_ROWS", "OutputLock", "TableStream", "atomic_file",
           "fsync_dir", "parquet_options", "refuse_symlink", "remove_temporaries",
           "write_atomic"]
