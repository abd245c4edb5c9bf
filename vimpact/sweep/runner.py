"""Run a sweep: chunks computed in-process, as shards, or as tasks on a Dask cluster.

Backends (:func:`run_sweep`):

- in-process (default): chunk after chunk, each one parallel batch over the
  numba threads (``prange``);
- ``workers=N``: a ``dask.distributed.LocalCluster`` of ``N`` worker processes
  with one thread each on this machine (``NUMBA_NUM_THREADS=1`` in their
  environment before numba loads); ``scheduler=ADDRESS``: a running cluster.
  Each chunk is a task that writes its own part file atomically and returns
  only a small summary. The kernels the spec needs are compiled once in this
  process first, so that the workers load them from numba's cache;
- ``shard=(I, N)``: only the chunks ``c % N == I`` (e.g. one SLURM array task
  each); the parts stay; ``combine=True`` then checks that every chunk is there
  and writes the table.

Every backend writes the same part files (:mod:`vimpact.sweep.store`), so they
can be mixed: a sweep started on a cluster can be resumed in-process, shards
can be combined anywhere, and the table is the same bit for bit.

``[grid] tolerance`` (:attr:`SweepSpec.grid_tolerance`): the grid is refined
before any chunk is made and the finished table's interpolation error measured,
by the table-build workflow above the sweep (:mod:`vimpact.tablebuild.sweep`,
which runs :func:`run_sweep` with its :class:`SweepStages`); a plain
:func:`run_sweep` refuses such a spec.

Python API::

    from vimpact.sweep import run_sweep
    path = run_sweep("sweeps/kelvin_voigt_table.toml", out=None, resume=False,
                     progress=None, workers=None, scheduler=None, shard=None,
                     combine=False)            # -> Path of the table (or of the parts)
"""

from __future__ import annotations

import dataclasses
import os
import socket
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from vimpact.model.validation import InputError
from vimpact.sweep import store
from vimpact.sweep.progress import Progress
from vimpact.sweep.spec import (
    AUTO_CHUNK_ROWS,
    AUTO_CHUNK_SECONDS,
    CHUNK_SIZE_FILE,
    MAX_CHUNKS,
    ONE_CHUNK_SECONDS,
    SweepSpec,
    load_spec,
)
from vimpact.tableformat import files
from vimpact.tableformat.integrity import ContentHash
from vimpact.tableformat.metadata import COMMON_METADATA, decode_metadata
from vimpact.tableformat.schema import (
    ADHESION_RESULTS,
    LABELS,
    OUTPUTS,
    RELATIVE,
    RESULTS,
    TANGENTIAL_OUTPUTS,
)


class SweepInterrupted(KeyboardInterrupt):
    """A sweep stopped by Ctrl-C (or a progress callback); finished chunks stay on disk."""

    def __init__(self, message: str, parts_dir: Path, done: int, total: int):
        super().__init__(message)
        self.message, self.parts_dir, self.done, self.total = message, parts_dir, done, total

    def __str__(self) -> str:
        return self.message


# ---- one chunk ---------------------------------------------------------------------

def run_batch(spec: SweepSpec, scene_cols: dict, timings: dict | None = None) -> dict:
    """Run scene columns of ``spec`` on the engine and return its result columns.

    What :func:`vimpact.simulate_batch` runs (validation, routing, kernels, SI results:
    :func:`vimpact.engine.simulate.run_columns`) without building its DataFrame: the
    sweep takes the NumPy columns as they are, ``status`` and ``path`` as
    :class:`~vimpact.engine.result.Coded` (integer codes and their names). ``timings``
    receives ``kernel_s`` (s in the kernels) and ``total_s`` (s of the whole call),
    summed over calls.
    """
    from vimpact.engine.columns import scene_columns
    from vimpact.engine.simulate import run_columns

    t0 = time.perf_counter()
    try:
        return run_columns(scene_columns(scene_cols), spec.numerics, timings=timings,
                           codes=True)[0]
    finally:
        if timings is not None:
            timings["total_s"] = timings.get("total_s", 0.0) + time.perf_counter() - t0


def compute_chunk(spec: SweepSpec, chunk: int, timings: dict | None = None,
                  part: tuple[int, int] | None = None, params: dict | None = None,
                  summary: dict | None = None):
    """Simulate the rows of ``chunk`` and return them as a ``pyarrow`` table.

    ``part``: ``(lo, hi)``, only the chunk's rows ``lo`` to ``hi - 1`` (counted from its
    first row): the same rows as the whole chunk's table has there (a row's results do
    not depend on the other rows). ``params``: the chunk's parameter sets
    (:meth:`~vimpact.sweep.spec.SweepSpec.chunk_parameters`, made once for its parts;
    made here if ``None``, of a part's rows only).

    Columnar: the chunk's parameters (:mod:`vimpact.sweep.parameters`) become scene
    columns of the engine (:func:`run_batch`: what :func:`vimpact.simulate_batch` runs,
    without its DataFrame) and its result columns the table's, with NumPy and Arrow (no
    Python object per row but a row's status, path and error string). No row raises:
    an invalid scene gets status ``invalid``, a batch that raises ``failed``, each with
    NaN outputs and a message in ``error``.
    ``timings`` (a dict) receives ``kernel_s`` (s in the kernels) and ``total_s`` (s
    in the engine: validation, routing, kernels, results) summed over calls.
    ``summary`` (a dict) receives :func:`chunk_summary` of the table, counted from the
    status and path codes (no string compared).
    """
    import pyarrow as pa

    from vimpact.engine.result import STATUS_CODE, STATUS_NAMES
    from vimpact.engine.unpack import finished_codes
    from vimpact.sweep.parameters import engine_columns, part_rows

    start, stop = spec.chunk_rows(chunk)
    if params is None:  # (of the part's rows only, if a part)
        params = spec.chunk_parameters(chunk, part)
    elif part is not None:
        lo, hi = part_rows(part, stop - start, chunk)
        views: dict[int, np.ndarray] = {}  # one array of several inputs: one view of it
        params = {k: views.setdefault(id(v), v[lo:hi]) for k, v in params.items()}
    if part is not None:
        start, stop = start + part[0], start + part[1]
    n = stop - start
    batches, inputs = engine_columns(spec, params)
    outputs = RESULTS | (ADHESION_RESULTS if spec.has_adhesion else {})
    cols: dict[str, np.ndarray] = {"row": np.arange(start, stop, dtype=np.int64)}
    given = {**params, **inputs}
    taken: set[int] = set()
    for c in spec.columns():
        if c not in ("row",) + LABELS and c not in outputs:
            value = given.get(c)
            if value is None:
                cols[c] = np.full(n, np.nan)
            elif (isinstance(value, np.ndarray) and value.dtype == np.float64
                  and value.shape == (n,) and value.flags.c_contiguous
                  and value.flags.writeable and id(value) not in taken):
                # the chunk's own array (made for it by chunk_parameters or engine_columns,
                # which the engine only reads): the column as it is, no copy
                cols[c] = value
                taken.add(id(value))
            else:  # a view of one value, another type, or an array of another column
                cols[c] = np.array(np.broadcast_to(value, (n,)), dtype=np.float64)
    # statuses and paths as integer codes (STATUS_NAMES; path_names), text only in the
    # Arrow column; a row no batch reaches stays invalid; one batch of all the chunk's
    # rows in order (the usual case) hands over its result columns as they are
    status = np.full(n, STATUS_CODE["invalid"], dtype=np.int8)
    error = np.full(n, None, dtype=object)
    path = np.full(n, -1, dtype=np.int16)
    path_names: list[str] = []
    for rows, scene_cols in batches:
        if len(rows) == 0:
            continue
        whole = len(rows) == n and bool(np.all(rows == np.arange(n)))
        try:
            result = run_batch(spec, scene_cols, timings)
        except Exception as exc:  # noqa: BLE001 - recorded as the rows' status
            status[rows], error[rows] = STATUS_CODE["failed"], f"{type(exc).__name__}: {exc}"
            continue
        st = result["status"].codes
        batch_path = result["path"].codes_in(path_names)  # the batch's paths in the chunk's
        if whole:
            status, error, path = st, result["error"], batch_path
        else:
            status[rows], error[rows], path[rows] = st, result["error"], batch_path
        for name, source in outputs.items():
            if whole:  # (the result's own array: no copy)
                cols[name] = result[source]
            else:
                if name not in cols:
                    cols[name] = np.full(n, np.nan)
                cols[name][rows] = result[source]
        valid = st != STATUS_CODE["invalid"]
        if spec.mode == "random" and spec.model != "prony":
            cols["Q1"][rows] = result["Q1"]
            if spec.model == "standard_solid" and "G_arm1_Pa" not in scene_cols:
                cols["Q2"][rows] = np.where(valid, np.inf, np.nan)  # no arm (eta = 0): G2 idle
            elif spec.model == "standard_solid":
                cols["Q2"][rows] = result["Q2"]
            else:
                cols["Q2"][rows] = np.nan  # the Kelvin-Voigt limit G2 -> inf (never 0: log 0)
        if spec.mode == "grid" and spec.model == "elastic":
            cols["Q1"][rows] = np.where(valid, 0.0, np.nan)
    for name in outputs:  # no batch reached these rows (none, or every one raised)
        if name not in cols:
            cols[name] = np.full(n, np.nan)
    with np.errstate(divide="ignore", invalid="ignore"):
        for name, (num, den) in RELATIVE.items():
            cols[name] = cols[num] / cols[den]
    if spec.mode == "random":
        vc0 = params["v_x0_m_s"] + params["R_m"] * params["omega0_rad_s"]
    else:  # the reference scene's v_x0 (1, or psi's; 0 on a lam axis), omega0 = 0
        vc0 = inputs["v_x0_m_s"]
    guard_nan(cols, status, error, (vc0 == 0.0) | (spec.tangential == "none"),
              finished_codes(status))
    if summary is not None:
        summary.update(_coded_summary(status, path, path_names, start))
    labels = {"model": _repeated(inputs["model"], n),
              "path": _decoded(path, path_names), "status": _decoded(status, STATUS_NAMES),
              "error": pa.array(error, type=pa.string())}
    schema = spec.schema()
    arrays = [labels[c] if c in labels else pa.array(cols[c], type=f.type)
              for c, f in zip(spec.columns(), schema)]
    return pa.Table.from_arrays(arrays, schema=schema)


def _coded_summary(status: np.ndarray, path: np.ndarray, path_names: list[str],
                   start: int) -> dict:
    """Return :func:`chunk_summary` of rows ``start, start + 1, ...`` from their codes.

    ``status``: codes into :data:`~vimpact.engine.result.STATUS_NAMES`; ``path``: codes
    into ``path_names`` (``-1``: none). The same dict as from the table's text columns.
    """
    from vimpact.engine.result import STATUS_NAMES

    counts = np.bincount(status.astype(np.intp), minlength=len(STATUS_NAMES))
    per_status = {STATUS_NAMES[c]: int(counts[c]) for c in np.flatnonzero(counts)}
    per_path = {}
    if len(path_names):
        rows = np.bincount(path.astype(np.intp) + 1, minlength=len(path_names) + 1)[1:]
        for c in np.flatnonzero(rows):
            per_path[path_names[c]] = {"rows": int(rows[c]),
                                       "first_row": start + int(np.argmax(path == c))}
    return {"counts": dict(sorted(per_status.items())), "paths": dict(sorted(per_path.items()))}


def _decoded(codes: np.ndarray, names):
    """Return codes into ``names`` (``-1``: null) as a ``pyarrow`` string array.

    Through a dictionary array (or one repeated value): the same string column as from
    the names per row, without a Python string per row.
    """
    import pyarrow as pa

    n = len(codes)
    first = int(codes[0]) if n else -1
    if n and bool(np.all(codes == first)):  # one value (the usual case): no strings made
        return (pa.repeat(pa.scalar(names[first], type=pa.string()), n) if first >= 0
                else pa.nulls(n, type=pa.string()))
    missing = codes < 0
    return pa.DictionaryArray.from_arrays(
        codes, pa.array(list(names), type=pa.string()),
        mask=missing if missing.any() else None).cast(pa.string())


def _repeated(values: np.ndarray, n: int):
    """Return a string column as a ``pyarrow`` array; one repeated value without a loop.

    A view of one element (stride 0: :func:`~vimpact.sweep.parameters.engine_columns`'
    ``model``) is one value without comparing its rows.
    """
    import pyarrow as pa

    if n and isinstance(values[0], str) and (values.strides[0] == 0
                                             or bool(np.all(values == values[0]))):
        return pa.repeat(pa.scalar(values[0], type=pa.string()), n)
    return pa.array(values, type=pa.string())


def guard_nan(cols: dict, status: np.ndarray, error: np.ndarray, vc0_zero: np.ndarray,
              finished: np.ndarray) -> np.ndarray:
    """Allow NaN only with a status that explains it.

    ``status``: codes into :data:`vimpact.engine.result.STATUS_NAMES`, changed in
    place. A finished row with a NaN output that no
    status explains (``e_x``, ``beta_x`` are NaN when ``v_c0 = 0``) becomes
    ``non_finite`` with all outputs NaN and the columns named in ``error``.
    Returns the rows changed (bool).
    """
    explained = np.broadcast_to(np.asarray(vc0_zero, dtype=bool), finished.shape)
    # NaN in any output first (one OR per column), each column's own rows only then
    tangential = [c for c in OUTPUTS if c in TANGENTIAL_OUTPUTS]
    other = [c for c in OUTPUTS if c not in TANGENTIAL_OUTPUTS]
    nan_other = np.logical_or.reduce([np.isnan(cols[c]) for c in other])
    nan_tangential = np.logical_or.reduce([np.isnan(cols[c]) for c in tangential])
    bad = finished & (nan_other | (nan_tangential & ~explained))
    if not bad.any():
        return bad
    nothing = np.zeros(finished.shape, dtype=bool)
    bad_cols = {c: np.isnan(cols[c]) & finished
                & ~(explained if c in TANGENTIAL_OUTPUTS else nothing) for c in OUTPUTS}
    from vimpact.engine.result import STATUS_CODE, STATUS_NAMES

    for k in np.flatnonzero(bad):  # rare: the message names this row's columns
        names = ", ".join(c for c, m in bad_cols.items() if m[k])
        error[k] = f"NaN in {names} of a row with status {STATUS_NAMES[status[k]]!r}"
    status[bad] = STATUS_CODE["non_finite"]
    for c in OUTPUTS:
        cols[c][bad] = np.nan
    return bad


def chunk_summary(table) -> dict:
    """Return the small summary a part stores and a task returns.

    Rows per status (``counts``) and rows and first row per kernel path (``paths``),
    each sorted by name; counted by Arrow (a Python list of the paths cost 0.1 s per
    1e5 rows).
    """
    import pyarrow.compute as pc

    counts = {str(c["values"]): int(c["counts"])
              for c in pc.value_counts(table.column("status")).to_pylist()}
    path, rows = table.column("path"), table.column("row")
    paths = {}
    for c in pc.value_counts(pc.drop_null(path)).to_pylist():
        first = pc.index(path, c["values"]).as_py()
        paths[str(c["values"])] = {"rows": int(c["counts"]), "first_row": int(rows[first].as_py())}
    return {"counts": dict(sorted(counts.items())), "paths": dict(sorted(paths.items()))}


def explain_paths(spec: SweepSpec, first_rows: dict[str, int]) -> dict[str, list[str]]:
    """Why each kernel path ran: the routing reasons of its first row."""
    from vimpact.engine.routing import choose_path
    out = {}
    for name, row in first_rows.items():
        if spec.mode == "grid":  # the row's own axis values (not its whole chunk's)
            one = dataclasses.replace(spec, chunk_size=1)
            scene = one.scene(one.chunk_parameters(row), 0)
        else:  # (a random row's draws depend on its chunk's)
            chunk = row // spec.chunk_size
            scene = spec.scene(spec.chunk_parameters(chunk), row - chunk * spec.chunk_size)
        out[name] = list(choose_path(scene, spec.numerics).reasons)
    return out


def run_chunk(spec: SweepSpec, chunk: int, parts: str) -> dict:
    """Compute ``chunk``, write its part file atomically, return its summary (a task)."""
    summary: dict = {}
    table = compute_chunk(spec, chunk, None, None, None, summary)
    store.write_part(spec, table, Path(parts), chunk, summary)
    start, stop = spec.chunk_rows(chunk)
    return {"chunk": chunk, "rows": stop - start, **summary}


def _dask_task(spec: SweepSpec, chunk: int, parts: str) -> dict:
    """:func:`run_chunk` on a Dask worker; reports the worker's numba threads."""
    import numba
    try:
        from distributed import get_worker
        threads = numba.config.NUMBA_NUM_THREADS  # type: ignore[attr-defined]  # set at import
        per_worker = max(1, threads // max(1, get_worker().state.nthreads))
    except Exception:  # noqa: BLE001 - not on a worker (tests call it directly)
        per_worker = numba.get_num_threads()
    if numba.get_num_threads() > per_worker:  # a cluster we did not start: no oversubscription
        numba.set_num_threads(per_worker)
    out = run_chunk(spec, chunk, parts)
    out["numba_threads"] = numba.get_num_threads()
    out["pid"] = os.getpid()
    return out


# ---- stages: what a workflow above the sweep adds -----------------------------------

def _as_is(spec: SweepSpec, parts: Path, log: Callable[[str], None] | None) -> SweepSpec:
    """Return the spec to chunk when no workflow prepares it: the spec itself.

    A grid with a ``tolerance`` is refused (its refinement is the table-build
    workflow's).
    """
    tol = getattr(spec, "grid_tolerance", None)
    if tol is not None and spec.mode == "grid":
        raise InputError(f"grid.tolerance = {tol!r} is not allowed in a plain sweep of "
                         f"{spec.path.name}: a grid refined to a tolerance is built by "
                         "vimpact.tablebuild.sweep.run_sweep (`vimpact sweep SPEC` runs it)")
    return spec


def _done(spec: SweepSpec, out: Path, log: Callable[[str], None] | None, again: bool) -> None:
    """Nothing to add to a finished table."""


@dataclasses.dataclass(frozen=True)
class SweepStages:
    """What a workflow above the sweep adds to a run of :func:`run_sweep`.

    The sweep makes, checks and combines the chunks of a spec; a workflow (the table
    build, :mod:`vimpact.tablebuild.sweep`) may change the spec before the chunks
    are made and add to the table once it is written, without the sweep knowing it.

    Attributes
    ----------
    prepare : ``prepare(spec, parts, log) -> spec``: the spec whose chunks are made,
        called under the output's lock before any chunk (default: the spec itself;
        a grid with ``tolerance`` is refused)
    finish : ``finish(spec, out, log, again)``: called after the table ``out`` is
        written, and with ``again=True`` when a run finds it already complete
    kept : names of the workflow's own files in the parts directory: they leave it
        while the parts are combined (the directory must then hold only parts) and
        come back if the combination fails
    """

    prepare: Callable[..., SweepSpec] = _as_is
    finish: Callable[..., None] = _done
    kept: tuple[str, ...] = ()


#: A plain sweep: the spec as it is, nothing added.
PLAIN = SweepStages()


def _stderr_log(progress) -> Callable[[str], None] | None:
    if progress is False:
        return None
    return lambda line: print(f"vimpact sweep: {line}", file=sys.stderr, flush=True)


# ---- the sweep ---------------------------------------------------------------------

def run_sweep(spec_path, out=None, resume: bool = False,
              progress: Callable[[int, int], None] | None | bool = None, *,
              workers: int | None = None, scheduler: str | None = None,
              shard: tuple[int, int] | None = None, combine: bool = False,
              chunk_order=None, timings: dict | None = None,
              stages: SweepStages = PLAIN) -> Path:
    """Run the sweep of a TOML specification and write its Parquet table.

    Parameters
    ----------
    spec_path : the specification (format: :mod:`vimpact.sweep.spec`)
    out : output path (relative to the current directory); default the spec's
        ``output`` (relative to the spec's directory). Must end in ``.parquet``.
    resume : continue an interrupted run: compute only the chunks missing in the
        parts. Without it, existing parts are an error.
    progress : ``None`` (default) a bar on a terminal, a line every ~10 s otherwise
        (:mod:`vimpact.sweep.progress`); a callable is called as
        ``progress(rows_done, rows_total)`` after every chunk (a sweep of one chunk
        of more than :data:`~vimpact.tableformat.files.ROW_GROUP_ROWS` rows: after
        every row group of it); ``False`` nothing.
    workers : run the chunks as tasks on a new Dask ``LocalCluster`` of this many
        single-threaded worker processes
    scheduler : address of a running Dask scheduler to run the chunks on
    shard : ``(I, N)``: compute only the chunks ``c % N == I`` and leave the parts
    combine : only combine the parts into the table (every chunk must be there)
    chunk_order : in-process only: the order to compute the chunks in (default
        ascending); the table does not depend on it
    timings : in-process only: a dict that receives, in s, ``kernel_s`` (in the
        kernels) and ``total_s`` (in the engine, :func:`run_batch`) summed over the
        chunks, ``choose_s`` (the chunk size: read, or measured and recorded) and
        ``write_s`` (content hashes, parts, the table and its checks)
    stages : what a workflow above the sweep adds (:class:`SweepStages`; default
        none: a grid with ``tolerance`` is refused, see
        :func:`vimpact.tablebuild.sweep.run_sweep`)

    Returns
    -------
    The path of the table (for ``shard``: of the parts directory).

    Raises
    ------
    ValueError
        for a bad spec or output, parts of another run, parts without ``resume``,
        missing chunks at ``combine``, a second sweep into the same output;
        :class:`~vimpact.model.validation.InputError` (a ``ValueError``) for a
        ``[grid] tolerance`` without the table-build stages, before anything is
        written.
    SweepInterrupted
        (a ``KeyboardInterrupt``) on Ctrl-C: finished chunks stay; the message
        says how to resume.
    """
    spec = load_spec(spec_path)
    out_name = "--out" if out is not None else f"output (in {spec.path})"
    out = Path(out) if out is not None else spec.output
    layout = spec.table_layout
    if workers is not None and scheduler is not None:
        raise ValueError("give --workers or --scheduler, not both")
    if workers is not None:
        check_workers(workers)
    if shard is not None:
        index, count = shard
        if not (isinstance(index, int) and isinstance(count, int) and 0 <= index < count):
            raise ValueError(f"--shard = {index}/{count} is not allowed: must be I/N with "
                             "0 <= I < N")
        if combine:
            raise ValueError("give --shard or --combine, not both")
    store.check_output(out, layout, out_name)
    parts = store.parts_dir(out, layout)
    if scheduler is not None and not combine:  # before anything is written
        scheduler = connect_scheduler(scheduler)
    try:
        if shard is not None:  # shards run side by side (SLURM array): a shared lock
            with files.OutputLock(out, shared=True):
                return _run(spec, spec_path, out, parts, True, progress, workers, scheduler,
                            shard, False, chunk_order, timings, stages)
        with files.OutputLock(out):
            return _run(spec, spec_path, out, parts, resume, progress, workers, scheduler, None,
                        combine, chunk_order, timings, stages)
    finally:
        if scheduler is not None and not isinstance(scheduler, str):
            scheduler.close()


def _run(spec, spec_path, out, parts, resume, progress, workers, scheduler, shard, combine,
         chunk_order, timings, stages: SweepStages) -> Path:
    layout = spec.table_layout
    log = _stderr_log(progress)
    files.remove_temporaries(out.parent, out.name)  # a final write cut short
    if store.is_complete(spec, out) and (resume or combine or shard is not None):
        stages.finish(spec, out, log, True)  # e.g. cut short after the table was written
        return out
    done: dict[int, Path] = {}
    if parts.exists() and not parts.is_dir():
        raise ValueError(f"{parts} is in the way: it should be the directory of the "
                         "finished chunks; remove it")
    if getattr(spec, "grid_refine", "tensor") == "adaptive":
        raise InputError(f'grid.refine = "adaptive" is not allowed for a sweep of '
                         f"{spec.path.name}: an adaptive table is built cell by cell, not in "
                         f"chunks; build it with `vimpact table build {spec.path}`")
    if spec.mode == "grid" and "lam" in spec.axes and spec.grid_tolerance is not None:
        raise InputError(f"grid.tolerance with a lam axis is not allowed for a sweep of "
                         f"{spec.path.name}: it specifies an adhesive lookup table (the "
                         "sticking boundary and e_z below it); build it with `vimpact table "
                         f"build {spec.path}`")
    spec = stages.prepare(spec, parts, log)
    if workers is not None:
        units = workers
    elif scheduler is not None and not isinstance(scheduler, str):
        units = max(1, sum(scheduler.nthreads().values()))
    else:
        units = shard[1] if shard is not None else 1
    t0 = time.perf_counter()
    spec = chunked(spec, parts, not combine, units, log)
    _timed(timings, "choose_s", t0)
    if parts.exists():
        # --combine: store.combine verifies the parts (a part read once)
        done = {} if combine else store.existing_parts(spec, parts)
        if done and not (resume or combine):
            raise ValueError(
                f"{parts} holds {len(done)} finished chunk(s) of an earlier run: use --resume "
                f"(resume=True) to continue it, or remove {parts} to start over")
        if layout == "dataset" and (parts / COMMON_METADATA).exists():
            (parts / COMMON_METADATA).unlink()  # stale: rewritten at the end
    if combine:
        _combine(spec, parts, out, log, stages)
        return out
    todo = [c for c in range(spec.n_chunks) if c not in done]
    if shard is not None:
        todo = [c for c in todo if c % shard[1] == shard[0]]
    if chunk_order is not None:
        order = [int(c) for c in chunk_order]
        todo = [c for c in order if c in set(todo)]
    rows_done = sum(spec.chunk_rows(c)[1] - spec.chunk_rows(c)[0] for c in done)
    bar = Progress(spec.rows, rows_done, spec.path.stem, progress)
    finished = False
    fresh: list | None = None
    whole = ContentHash()  # of the rows in ``fresh``
    try:
        if workers is not None and todo:
            too_small = small_for_cluster(spec, todo, workers)
            if too_small:
                print(f"vimpact sweep: {too_small}", file=sys.stderr, flush=True)
        if workers is not None or scheduler is not None:
            parts.mkdir(parents=True, exist_ok=True)
            _run_dask(spec, todo, parts, bar, done, workers, scheduler)
        else:
            # a small file-layout table is written from its chunks in memory (parts
            # not read back); one chunk goes straight to the table (no part, no parts
            # directory)
            if shard is None and layout == "file" and todo == list(range(spec.n_chunks)) \
                    and (spec.n_chunks == 1 or spec.rows <= store.HOLD_ROWS):
                fresh = []
            if spec.n_chunks > 1 or fresh is None:
                parts.mkdir(parents=True, exist_ok=True)
            if fresh is not None and spec.n_chunks == 1 and spec.rows > files.ROW_GROUP_ROWS:
                # one chunk of several row groups: each written while the next is computed
                _stream_one_chunk(spec, parts, out, log, stages, bar, timings)
                finished = True
                bar.close()
                return out
            for chunk in todo:
                summary: dict = {}
                table = compute_chunk(spec, chunk, timings, None, None, summary)
                t0 = time.perf_counter()
                own = None  # a part's hash and the table's from one canonical form
                if fresh is not None:
                    fresh.append((table, summary))
                    if spec.n_chunks > 1:
                        own = ContentHash().update(table, also=whole).hexdigest()
                    # (one chunk: hashed while its table is encoded, store.combine)
                if spec.n_chunks > 1 or fresh is None:
                    store.write_part(spec, table, parts, chunk, summary, own)
                    done[chunk] = store.part_path(parts, chunk, spec.n_chunks)
                _timed(timings, "write_s", t0)
                start, stop = spec.chunk_rows(chunk)
                bar.update(stop - start)
        finished = True
        bar.close()
        if shard is not None:
            return parts
        t0 = time.perf_counter()
        _combine(spec, parts, out, log, stages, fresh,
                 whole.hexdigest() if fresh is not None and spec.n_chunks > 1 else None)
        _timed(timings, "write_s", t0)
    except KeyboardInterrupt:
        bar.close(finished)
        hint = f"vimpact sweep {spec_path}" + (f" --out {out}" if out != spec.output else "")
        raise SweepInterrupted(
            f"interrupted: {len(done)} of {spec.n_chunks} chunks are saved in {parts}; "
            f"resume with: {hint} --resume", parts, len(done), spec.n_chunks) from None
    return out


#: Row groups of a streamed chunk computed at once at most (:func:`_stream_one_chunk`):
#: while one is in the kernels (which release the GIL), the other's Python (validation,
#: results, its table) runs, and their kernels fill each other's idle threads.
PIECES_IN_FLIGHT = 2
#: numba threading layers that take parallel launches from several threads at once
#: (the workqueue layer aborts the process on one).
CONCURRENT_LAYERS = ("tbb", "omp")


def _launches_side_by_side() -> bool:
    """Whether numba's threading layer takes parallel launches from two threads at once.

    Unknown before this process's first parallel launch: ``False`` then.
    """
    import numba

    try:
        return numba.threading_layer() in CONCURRENT_LAYERS
    except ValueError:  # no parallel launch yet: the layer is not chosen
        return False


def _stream_one_chunk(spec: SweepSpec, parts: Path, out: Path, log, stages: SweepStages,
                      bar: Progress, timings: dict | None) -> None:
    """Compute the one chunk of a file-layout sweep in row groups, writing each under the next.

    The chunk's rows in pieces of :data:`~vimpact.tableformat.files.ROW_GROUP_ROWS`
    (:func:`compute_chunk` ``part``), :data:`PIECES_IN_FLIGHT` at a time on threads of
    their own (one, until numba's threading layer is known to take launches from several
    threads, :data:`CONCURRENT_LAYERS`, and with one numba thread), sharing this
    thread's numba threads (two pieces on two threads: one each, so that neither waits
    at the end of a launch for the other thread's last rows), as many again queued
    behind them, so that a thread that finishes its piece takes the next at once (not
    after the pieces before it are taken), the first ones while the table's file and
    writer are set up; each piece, in row order, is hashed and
    encoded into the table on other threads while the next ones are computed
    (:func:`vimpact.sweep.store.combine` ``pieces``): the same table, byte for byte, as
    written from the whole chunk. Finer pieces (half a row group, or a quarter of the
    last, for a shorter tail once the kernels end) cost more CPU (the fixed Python and
    hashing of every piece) than their shorter tail saved on 2 cores. No part: an
    interruption keeps nothing, as for one chunk written whole (the pieces running are
    finished first, the ones queued are not started). ``timings``: ``kernel_s`` and
    ``total_s`` summed over the pieces (pieces side by side: more than the wall time
    they took); ``pieces_wall_s`` the wall time spent waiting for the pieces (with their
    tables); ``write_s`` the time spent writing that the computation did not cover.
    """
    from collections import deque
    from concurrent.futures import ThreadPoolExecutor

    import numba

    start, stop = spec.chunk_rows(0)
    size = files.ROW_GROUP_ROWS
    bounds = [(lo, min(stop - start, lo + size)) for lo in range(0, stop - start, size)]
    threads = numba.get_num_threads()  # (numba's count is per Python thread)
    inside = 0.0  # s computing the pieces (within the write's time)
    # a random chunk's draws follow each other: made once for its pieces; a grid's
    # parameter sets are made by each piece for its own rows (2.7-5 ms for 1e5 rows
    # before the first piece could start)
    params = spec.chunk_parameters(0) if spec.mode != "grid" else None

    def piece(lo: int, hi: int, own_threads: int):
        numba.set_num_threads(own_threads)
        own: dict = {}
        summary: dict = {}
        table = compute_chunk(spec, 0, own, (lo, hi), params, summary)
        return table, summary, own

    todo = deque(bounds)
    running: deque = deque()  # ((lo, hi), future) of the pieces submitted, in row order

    def submit(pool) -> None:
        limit = min(PIECES_IN_FLIGHT, threads) if _launches_side_by_side() else 1
        ahead = 2 * limit if limit > 1 else 1  # (the pool runs `limit` of them)
        while todo and len(running) < ahead:  # the threads shared between the pieces
            running.append((todo[0], pool.submit(piece, *todo.popleft(),
                                                 max(1, threads // limit))))

    def pieces(pool):
        nonlocal inside
        t0 = time.perf_counter()
        while todo or running:
            submit(pool)
            (lo, hi), future = running.popleft()
            table, summary, own = future.result()
            for key, value in own.items():
                if timings is not None:
                    timings[key] = timings.get(key, 0.0) + value
            inside += time.perf_counter() - t0
            yield table, summary
            bar.update(hi - lo)
            t0 = time.perf_counter()

    t0 = time.perf_counter()
    with ThreadPoolExecutor(PIECES_IN_FLIGHT) as pool:
        submit(pool)  # the first pieces start while the table's file and writer are made
        made = pieces(pool)
        try:
            _combine(spec, parts, out, log, stages, pieces=made)
        finally:
            made.close()  # (an error or an interruption: no piece is started after it)
            for _, future in running:  # queued, not started: never started
                future.cancel()
    if timings is not None:
        timings["write_s"] = timings.get("write_s", 0.0) + time.perf_counter() - t0 - inside
        timings["pieces_wall_s"] = timings.get("pieces_wall_s", 0.0) + inside


def _timed(timings: dict | None, key: str, t0: float) -> None:
    """Add the seconds since ``t0`` to ``timings[key]`` (if ``timings`` is a dict)."""
    if timings is not None:
        timings[key] = timings.get(key, 0.0) + time.perf_counter() - t0


def _combine(spec: SweepSpec, parts: Path, out: Path, log, stages: SweepStages,
             fresh=None, fresh_digest: str | None = None, pieces=None) -> None:
    """Run :func:`vimpact.sweep.store.combine`, then ``stages.finish``.

    ``fresh``: the ``(table, summary)`` of every chunk, computed in this process:
    the table is written from them (:func:`vimpact.sweep.store.combine`), with the
    content hash ``fresh_digest`` of their rows. ``pieces``: the ``(table, summary)``
    of the row groups of a one-chunk sweep, computed as they are asked for.

    The stages' own files
    (``stages.kept``) leave the parts directory first (the directory must hold only
    parts to be removed, a dataset only its parts); they are put back if the
    combination fails, so that ``--resume`` still finds them.
    """
    saved = {}
    for name in (*stages.kept, CHUNK_SIZE_FILE):
        kept = Path(parts) / name
        if kept.is_file():
            saved[name] = kept.read_text()
            kept.unlink()
    try:
        store.combine(spec, parts, out, lambda first: explain_paths(spec, first), fresh,
                      fresh_digest, pieces)
    except BaseException:
        if Path(parts).is_dir():
            for name, text in saved.items():
                with files.atomic_file(Path(parts) / name, str(Path(parts) / name),
                                       mode="w") as f:  # never through a symlink
                    f.write(text)
        raise
    stages.finish(spec, out, log, False)


# ---- chunk size: chosen from the measured cost of the rows --------------------------

#: A cost probe runs rows until their batches took this long, s (or :data:`PROBE_ROWS`).
PROBE_SECONDS = 0.02
#: Rows of a cost probe at most.
PROBE_ROWS = 4096
#: Chunks per worker (or shard) at least when the runner chooses the chunk size: the
#: tasks then even out between workers that finish at different times.
CHUNKS_PER_WORKER = 4


def seconds_per_row(spec: SweepSpec, probe_chunks: int = 8,
                    enough: float = 0.0) -> tuple[float, int]:
    """Measure what a row of ``spec`` costs in the engine (:func:`run_batch`), s.

    Rows of ``probe_chunks`` places spread over the sweep, run as one batch as a chunk
    runs them (their kernels compiled or loaded first, :func:`warm_kernels`): first 8
    per place, then, if that took less than :data:`PROBE_SECONDS`, as many as take
    about that long at the cost measured (at least twice as many, at most
    :data:`PROBE_ROWS` rows or the whole sweep), so that a batch's fixed cost is a small
    part of the time taken. Returns the wall time per row of the last batch and its rows.
    A first batch whose time per row is at most ``enough`` (s) is the answer: with the
    batch's fixed cost in it, the true cost is lower still (what a caller that only
    asks "at most this?" needs).
    """
    from vimpact.sweep.parameters import engine_columns

    warm_kernels(spec)
    per_place = 8
    most = max(8, -(-PROBE_ROWS // probe_chunks))
    while True:
        probe = dataclasses.replace(spec, chunk_size=per_place)
        places = np.unique(np.linspace(0, probe.n_chunks - 1,
                                       min(probe_chunks, probe.n_chunks)).astype(int))
        pieces = [probe.chunk_parameters(int(chunk)) for chunk in places]
        params = {k: np.concatenate([p[k] for p in pieces]) for k in pieces[0]}
        rows = len(params["nu"])
        timings: dict = {}
        for _, cols in engine_columns(probe, params)[0]:
            try:
                run_batch(spec, cols, timings)
            except Exception:  # noqa: BLE001 - the chunk will record it
                pass
        took = timings.get("total_s", 0.0)
        if took >= PROBE_SECONDS or rows >= min(PROBE_ROWS, spec.rows) or per_place >= most \
                or took <= enough * rows:
            return max(took, 1e-9) / max(rows, 1), rows
        # straight to the rows that take PROBE_SECONDS at this cost (a tenth more)
        per_place = min(most, max(2 * per_place,
                                  int(1.1 * per_place * PROBE_SECONDS / max(took, 1e-9))))


def choose_chunk_size(spec: SweepSpec, units: int = 1) -> dict:
    """Choose the rows per chunk of ``spec`` from the measured cost of its rows.

    About :data:`~vimpact.sweep.spec.AUTO_CHUNK_SECONDS` of work per chunk
    (:func:`seconds_per_row`), within :data:`~vimpact.sweep.spec.AUTO_CHUNK_ROWS` and the
    sweep's rows, at most ``MAX_CHUNKS`` chunks, and with ``units`` workers or shards at least
    :data:`CHUNKS_PER_WORKER` chunks each where the rows allow it. One process (``units =
    1``) makes a sweep of at most :data:`~vimpact.sweep.spec.ONE_CHUNK_SECONDS` of work
    (and at most ``AUTO_CHUNK_ROWS[1]`` rows) one chunk.

    Returns
    -------
    dict
        ``chunk_size``, ``seconds_per_row`` (s), ``probe_rows`` (what was measured)
        and ``units``: the record :func:`chunked` stores.
    """
    lo, hi = AUTO_CHUNK_ROWS
    # a sweep that is surely one chunk needs no precise cost (the first batch bounds it)
    one = units == 1 and spec.rows <= hi
    cost, probed = seconds_per_row(spec, enough=ONE_CHUNK_SECONDS / spec.rows if one else 0.0)
    size = int(min(hi, max(lo, AUTO_CHUNK_SECONDS / cost)))
    if units > 1:
        size = min(size, max(lo, -(-spec.rows // (CHUNKS_PER_WORKER * units))))
    elif one and cost * spec.rows <= ONE_CHUNK_SECONDS:
        size = spec.rows
    size = max(min(size, spec.rows), -(-spec.rows // MAX_CHUNKS), 1)
    return {"chunk_size": size, "seconds_per_row": cost, "probe_rows": probed, "units": units}


def recorded_chunk_size(spec: SweepSpec, parts: Path) -> int | None:
    """Return the chunk size an earlier run of ``spec`` chose, or ``None``.

    From :data:`~vimpact.sweep.spec.CHUNK_SIZE_FILE` in ``parts`` (a run of the same
    sweep hash and rows), else from the metadata of a part of this sweep.
    """
    import json

    import pyarrow.parquet as pq

    try:
        record = json.loads((Path(parts) / CHUNK_SIZE_FILE).read_text())
        if record.get("sweep_hash") == spec.sweep_hash and record.get("rows") == spec.rows:
            return int(record["chunk_size"])
    except (OSError, ValueError, TypeError, KeyError, AttributeError):
        pass
    for part in sorted(Path(parts).glob("part-*.parquet")) if Path(parts).is_dir() else ():
        try:
            meta = decode_metadata(pq.read_schema(part).metadata)
        except Exception:  # noqa: BLE001 - a damaged part: existing_parts reports it
            continue
        if meta.get("sweep_hash") == spec.sweep_hash and isinstance(meta.get("chunk_size"), int):
            return int(meta["chunk_size"])
    return None


def _record_chunk_size(parts: Path, record: dict) -> int:
    """Store ``record`` as ``parts/CHUNK_SIZE_FILE`` unless a run got there first.

    Shards start side by side: the first record stays. Returns the chunk size in the
    file either way.
    """
    import json

    parts.mkdir(parents=True, exist_ok=True)
    final = parts / CHUNK_SIZE_FILE
    tmp = parts / f".{CHUNK_SIZE_FILE}.{socket.gethostname()}.{os.getpid()}.tmp"
    with open(tmp, "w") as f:
        json.dump(record, f)
        f.flush()
        os.fsync(f.fileno())
    try:
        os.link(tmp, final)  # atomic, and never over a file another run wrote
        store.fsync_dir(parts)
    except FileExistsError:
        return int(json.loads(final.read_text())["chunk_size"])
    finally:
        tmp.unlink()
    return int(record["chunk_size"])


def chunked(spec: SweepSpec, parts: Path, choose: bool = True, units: int = 1,
            log: Callable[[str], None] | None = None) -> SweepSpec:
    """Return ``spec`` with the chunk size its chunks are made with.

    A spec that sets ``chunk_size`` (or a random one, whose draws depend on it) as it
    is; a grid without: the size an earlier run of the sweep recorded in ``parts``
    (:func:`recorded_chunk_size`), else, if ``choose``, one chosen now
    (:func:`choose_chunk_size`) and recorded before any chunk is made, so that
    ``--resume``, shards and ``--combine`` cut the same chunks. One chunk of all the
    rows is not recorded (nor is a parts directory made for it): its part, if a
    backend writes one, holds its size in its metadata, and without a part there is
    nothing to cut the same way.
    """
    if not spec.chooses_chunk_size:
        return spec
    size = recorded_chunk_size(spec, parts)
    if size is None:
        if not choose:
            return spec
        record = {**choose_chunk_size(spec, units), "sweep_hash": spec.sweep_hash,
                  "rows": spec.rows}
        size = record["chunk_size"]
        if size < spec.rows:
            size = _record_chunk_size(parts, record)
        if log is not None:
            log(f"{size} rows per chunk, chosen from {record['seconds_per_row'] * 1e6:.3g} us "
                f"per row measured (about {AUTO_CHUNK_SECONDS:g} s of work per chunk at most; "
                "chunk_size in the spec sets it)")
    return dataclasses.replace(spec, chunk_size=size)


#: Seconds to start a local Dask cluster of two workers and have them load the kernels,
#: about: ``vimpact bench sweep_backends`` measures it (``cluster_ready_s``: 2.3 s on 2
#: cores, the start alone 1.0 s quiet and 2.2 s under load)
CLUSTER_START_SECONDS = 3.0


def small_for_cluster(spec: SweepSpec, todo: list[int], workers: int) -> str | None:
    """Return why ``--workers`` does not pay for ``todo``, or ``None`` when it may.

    A sweep whose chunks take less time in process (:func:`seconds_per_row` on all
    threads) than starting a cluster (:data:`CLUSTER_START_SECONDS`) finishes sooner
    without one.
    """
    cost, _ = seconds_per_row(spec, probe_chunks=4)
    rows = sum(spec.chunk_rows(c)[1] - spec.chunk_rows(c)[0] for c in todo)
    work = cost * rows
    if work >= CLUSTER_START_SECONDS:
        return None
    return (f"--workers {workers}: this sweep ({rows} rows, about {work:.2g} s of work in "
            f"process) is too small to pay for starting a cluster (about "
            f"{CLUSTER_START_SECONDS:g} s); without --workers it runs sooner")


def warm_kernels(spec: SweepSpec, rows_per_chunk: int = 2, chunks: int = 4) -> None:
    """Compile (or load from numba's cache) the kernels the spec needs, in this process.

    A few rows of a few chunks spread over the sweep, run as one batch, so that workers
    find them cached.
    """
    from vimpact.sweep.parameters import engine_columns

    picks = np.unique(np.linspace(0, spec.n_chunks - 1, min(chunks, spec.n_chunks)).astype(int))
    pieces = [spec.chunk_parameters(int(chunk)) for chunk in picks]
    params = {k: np.concatenate([p[k][:rows_per_chunk] for p in pieces]) for k in pieces[0]}
    for _, cols in engine_columns(spec, params)[0]:
        try:
            run_batch(spec, cols)
        except Exception:  # noqa: BLE001 - the task will record it
            pass


#: Local Dask workers per usable core at most (``--workers``): a worker is one process
#: with one numba thread, so more than a few per core only adds memory and switching.
WORKERS_PER_CORE = 4
#: Memory one local Dask worker process needs at least (Python, Dask, numba, pyarrow and
#: a chunk), bytes: ``--workers`` is bounded by the available memory over this.
WORKER_MEMORY_BYTES = 400 * 2**20


def _usable_cores() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def _available_memory() -> int | None:
    """Bytes of memory available for new processes (Linux ``MemAvailable``), or None."""
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):
        return None


def max_local_workers() -> tuple[int, str]:
    """Return the most local Dask workers this machine takes (``--workers``) and why.

    :data:`WORKERS_PER_CORE` per usable core, and no more than the available memory
    holds at :data:`WORKER_MEMORY_BYTES` each (at least 1).
    """
    cores = _usable_cores()
    limit, why = WORKERS_PER_CORE * cores, f"{WORKERS_PER_CORE} per core, {cores} cores"
    memory = _available_memory()
    if memory is not None:
        fit = max(1, memory // WORKER_MEMORY_BYTES)
        why += (f"; {memory / 2**30:.1f} GiB available memory at about "
                f"{WORKER_MEMORY_BYTES / 2**30:.2g} GiB per worker")
        limit = min(limit, int(fit))
    return limit, why


def check_workers(workers) -> int:
    """Return ``--workers`` as an int in ``[1, max_local_workers()]``.

    Raises :class:`InputError` before anything starts otherwise.
    """
    limit, why = max_local_workers()
    if isinstance(workers, bool) or not isinstance(workers, int) or not 1 <= workers <= limit:
        raise InputError(f"--workers = {workers!r} is not allowed: must be an integer from 1 "
                         f"to {limit} on this machine ({why})")
    return workers


def local_cluster(workers: int):
    """Start a ``dask.distributed.LocalCluster`` of ``workers`` processes.

    One thread each and ``NUMBA_NUM_THREADS=1`` in their environment (set by the nanny before the worker
    process imports anything, so numba starts with one thread).
    """
    from distributed import LocalCluster
    return LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                        env={"NUMBA_NUM_THREADS": "1"}, dashboard_address=None)


#: Seconds a ``--scheduler`` address has to accept a connection and answer the Dask
#: handshake (an ``identity`` request) before the sweep is refused.
SCHEDULER_TIMEOUT_S = 5.0


def _scheduler_error(address, why: str) -> InputError:
    return InputError(f"--scheduler = {address!r} is not allowed: {why}")


def _probe_scheduler(address: str, timeout: float) -> None:
    """Refuse ``address`` unless a Dask scheduler answers its handshake in time.

    Within ``timeout`` seconds: a refused port, an unknown host, a service that is not Dask
    (that sends something else, or nothing) each give one :class:`InputError`.
    """
    import asyncio
    import concurrent.futures

    from distributed.comm import connect
    from distributed.comm.addressing import parse_address, parse_host_port

    try:
        scheme, location = parse_address(address)
        host, port = parse_host_port(location) if scheme in ("tcp", "tls") else (None, None)
    except (ValueError, TypeError) as exc:
        raise _scheduler_error(address, f"must be a Dask scheduler address such as "
                                        f"tcp://host:8786 ({exc})") from None
    if host is not None and not (isinstance(port, int) and 0 < port < 65536):
        raise _scheduler_error(address, f"port {port} is not a TCP port (1 to 65535)")
    if host is not None:  # a plain TCP connection first: a clear, quick answer
        try:
            socket.create_connection((host, port), timeout=timeout).close()
        except socket.gaierror as exc:
            raise _scheduler_error(address, f"unknown host {host!r} ({exc.strerror})") from None
        except (OSError, OverflowError) as exc:
            why = ("nothing answered" if isinstance(exc, TimeoutError)
                   else getattr(exc, "strerror", None) or str(exc))
            raise _scheduler_error(address, f"cannot connect to {host}:{port} ({why}; waited "
                                            f"at most {timeout:g} s)") from None

    if scheme != "tcp":  # the handshake below is plain TCP; other schemes: Client's timeout
        return

    async def identity():
        comm = await asyncio.wait_for(connect(address, timeout=timeout), timeout)
        try:
            await asyncio.wait_for(comm.write({"op": "identity", "reply": True}), timeout)
            return await asyncio.wait_for(comm.read(), timeout)
        finally:
            comm.abort()

    with concurrent.futures.ThreadPoolExecutor(1) as pool:  # its own event loop
        try:
            reply = pool.submit(asyncio.run, identity()).result()
        except (Exception, MemoryError) as exc:  # noqa: BLE001 - any answer but Dask's
            reply = {"error": "no answer" if isinstance(exc, TimeoutError) else
                     f"an answer that is not Dask's ({type(exc).__name__})"}
    if not (isinstance(reply, dict) and reply.get("type") == "Scheduler"):
        got = reply.get("error", "another server's answer") if isinstance(reply, dict) \
            else "another server's answer"
        raise _scheduler_error(address, f"no Dask scheduler there: its handshake gave {got} "
                                        f"within {timeout:g} s")


def connect_scheduler(address, timeout: float = SCHEDULER_TIMEOUT_S):
    """Return a ``distributed.Client`` of the Dask scheduler at ``address``.

    Or :class:`InputError` (one line naming ``--scheduler`` and the address) within about
    ``timeout`` seconds when none answers there; nothing is written before.
    """
    if not isinstance(address, str) or not address.strip():
        raise _scheduler_error(address, "must be a Dask scheduler address such as "
                                        "tcp://host:8786")
    try:
        from distributed import Client
    except ImportError:
        raise ValueError("--workers / --scheduler need Dask: pip install 'vimpact[dask]'") \
            from None
    _probe_scheduler(address, timeout)
    try:
        return Client(address, timeout=timeout)
    except (OSError, TimeoutError) as exc:
        raise _scheduler_error(address, f"the Dask scheduler stopped answering ({exc})") \
            from None


def _run_dask(spec, todo, parts, bar, done, workers, scheduler) -> None:
    """Chunks as tasks on a Dask cluster, at most a few per worker in flight."""
    try:
        from distributed import Client, as_completed
    except ImportError:
        raise ValueError("--workers / --scheduler need Dask: pip install 'vimpact[dask]'") \
            from None
    warm_kernels(spec)
    cluster = None
    if workers is not None:
        cluster = local_cluster(workers)
        client = Client(cluster)
    else:
        client = scheduler if not isinstance(scheduler, str) else connect_scheduler(scheduler)
    try:
        slots = 4 * max(1, sum(client.nthreads().values()))
        pending = iter(todo)
        futures = as_completed()
        for chunk in pending:
            futures.add(client.submit(_dask_task, spec, chunk, str(parts), pure=False))
            if futures.count() >= slots:
                break
        for future in futures:
            result = future.result()
            done[result["chunk"]] = store.part_path(parts, result["chunk"], spec.n_chunks)
            bar.update(result["rows"])
            nxt = next(pending, None)
            if nxt is not None:
                futures.add(client.submit(_dask_task, spec, nxt, str(parts), pure=False))
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


__all__ = ["PLAIN", "SweepInterrupted", "SweepStages", "check_workers", "choose_chunk_size",
           "chunk_summary", "chunked", "compute_chunk", "connect_scheduler", "explain_paths",
           "guard_nan", "local_cluster", "max_local_workers", "recorded_chunk_size",
           "run_batch", "run_chunk", "run_sweep", "seconds_per_row", "small_for_cluster", "warm_kernels"]
