"""Run impacts: scenes in, results out.

Data flow: scenes (``Scene`` objects or input columns) ->
:class:`~vimpact.engine.columns.SceneColumns` (validated, vectorized) ->
routing by masks (:func:`~vimpact.engine.routing.route`) -> kernel arrays per
path (:mod:`~vimpact.engine.pack`) -> one parallel kernel call per path ->
SI result columns (:mod:`~vimpact.engine.unpack`) -> ``DataFrame`` (batch) or
:class:`~vimpact.engine.result.ImpactResult` (one impact).
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from vimpact.engine.columns import SceneColumns, scene_columns
from vimpact.engine.pack import element_arrays, interleave, run_path
from vimpact.engine.result import RESULT_FIELDS, STATUS_NAMES, Coded, ImpactResult
from vimpact.engine.routing import CONTINUUM_STICK, choose_path, route
from vimpact.engine.unpack import unpack, unpack_row
from vimpact.kernels import layout
from vimpact.model.hertz import HERTZ_TIME_FACTOR
from vimpact.model.numerics import MAX_ELEMENTS_IN_ROW, MAX_STEPS_PER_T_H, Numerics
from vimpact.model.scene import HALF_SPACE_LIMIT, TANGENTIAL_MEMORY, Scene
from vimpact.model.validation import InputError, message, require

if TYPE_CHECKING:  # pandas (0.3 s to import) is loaded only where a DataFrame is made
    import pandas as pd

#: Rows of a recorded trajectory at most (the last row always holds the end state).
MAX_TRAJECTORY_ROWS = 1_000_000
#: Trajectory rows per Hertz time on the element path.
TRAJECTORY_ROWS_PER_T_H = 500


class HalfSpaceError(InputError):
    """The contact grew beyond the half-space limit ``a_max > 0.2 R``."""


#: ``Numerics()`` made and validated once (it is frozen), not on every call
_DEFAULT_NUMERICS = Numerics()


def _numerics(numerics) -> Numerics:
    if numerics is None:
        return _DEFAULT_NUMERICS
    if isinstance(numerics, str):
        return Numerics.preset(numerics)
    require("numerics", numerics, isinstance(numerics, Numerics),
            "a vimpact.Numerics or a preset name")
    return numerics


def run_columns(cols: SceneColumns, numerics: Numerics, n_rec: int = 0, rec_every: int = 1,
                timings: dict | None = None, codes: bool = False
                ) -> tuple[dict[str, Any], np.ndarray, np.ndarray]:
    """Route, pack, run and unpack a batch.

    The result columns, the trajectory buffer ``(n, n_rec, N_REC)`` (kernel units) and the
    rows written in it. ``codes``: ``status`` and ``path`` as
    :class:`~vimpact.engine.result.Coded` (integer codes and their names) instead of
    object arrays of ``str`` (:func:`~vimpact.engine.unpack.unpack`).

    Rows the full-stick continuum kernel hands back (its assumptions broke, or
    its step limit) run again on the element kernel their effects call for.
    Rows with a work of adhesion run on the adhesive kernel
    (:func:`vimpact.engine.adhesion.result_columns`; no trajectory: none written).
    """
    adhesive = cols.adhesive
    if adhesive.any():
        from vimpact.engine.adhesion import result_columns

        rest, adh = np.flatnonzero(~adhesive), np.flatnonzero(adhesive)
        t0 = time.perf_counter()
        parts: list[dict[str, Any]] = [result_columns(cols.take(adh), numerics)]
        if timings is not None:  # (the conversion to SI is included: it is small)
            timings["kernel_s"] = timings.get("kernel_s", 0.0) + time.perf_counter() - t0
        if codes:
            parts[0]["status"] = Coded.encode(parts[0]["status"], STATUS_NAMES)
            parts[0]["path"] = Coded.encode(parts[0]["path"])
        rec = np.zeros((len(cols), n_rec, layout.N_REC))
        written = np.zeros(len(cols), dtype=np.int64)
        if len(rest):
            result, rec[rest], written[rest] = run_columns(cols.take(rest), numerics, n_rec,
                                                           rec_every, timings, codes)
            parts.append(result)
        order = np.argsort(np.concatenate([adh, rest]), kind="stable")
        return ({name: _concatenate([p[name] for p in parts], order) for name in parts[0]},
                rec, written)
    out, rec, paths, explicit_euler, steps_per_T, refused = _run(
        cols, numerics, n_rec, rec_every, timings)
    written = out[:, layout.OUT_N_REC].astype(np.int64)
    return (unpack(cols, out, paths, explicit_euler, steps_per_T, refused, codes), rec,
            written)


def _concatenate(pieces: list, order: np.ndarray):
    """Return result columns (arrays, or :class:`Coded` with their own names) joined, in ``order``."""
    if not isinstance(pieces[0], Coded):
        return np.concatenate(pieces)[order]
    names: list[str] = []
    codes = [p.codes_in(names) for p in pieces]  # each piece's codes in the joined names
    return Coded(np.concatenate(codes)[order], tuple(names))


def _run(cols: SceneColumns, numerics: Numerics, n_rec: int, rec_every: int,
         timings: dict | None
         ) -> tuple[np.ndarray, np.ndarray, Coded, np.ndarray, np.ndarray, np.ndarray]:
    """Route, pack and run a batch; return the kernel rows and what unpack takes.

    Route, pack and run: the kernel rows ``out``, the trajectory buffer, and per
    row the path (:class:`~vimpact.engine.result.Coded`, ``-1`` where none ran),
    explicit Euler, steps per ``T`` and refusal that
    :func:`~vimpact.engine.unpack.unpack` takes (:func:`run_columns`).
    """
    n = len(cols)
    routes = route(cols, numerics)
    out = np.zeros((n, layout.N_OUT))
    rec = np.zeros((n, n_rec, layout.N_REC))
    path_codes = np.full(n, -1, dtype=np.int16)  # (-1: no path, an invalid row)
    path_list: list[str] = []
    explicit_euler = np.zeros(n, dtype=bool)
    steps_per_T = np.zeros(n)
    refused = np.empty(n, dtype=object)
    kernel_s = 0.0
    # one row runs on a serial kernel (run_path): no thread to count or to set
    threads = _threads() if n > 1 else 1
    if n == 1:  # (one scene: simulate(); np.flatnonzero costs more than the rest of this)
        queue = [(routes.paths[0], _ROW_0)] if routes.paths else []
    else:
        queue = [(path, np.flatnonzero(routes.group == k)) for k, path in enumerate(routes.paths)]
    while queue:
        path, idx = queue.pop(0)
        arrays = None
        if path.spec is not None:
            arrays = element_arrays(_rows(cols, idx), numerics, path.spec)
            per_t_H = HERTZ_TIME_FACTOR / arrays["h"]
            if len(idx) == 1:  # (the same test on the row's scalars: cheaper on one row)
                n_costly = int(per_t_H[0] > MAX_STEPS_PER_T_H
                               or arrays["n_elem"][0] > MAX_ELEMENTS_IN_ROW)
                costly = _ONE_COSTLY[n_costly]
            else:
                costly = ((per_t_H > MAX_STEPS_PER_T_H)
                          | (arrays["n_elem"] > MAX_ELEMENTS_IN_ROW))
                n_costly = int(np.count_nonzero(costly))  # (cheaper than any() and flatnonzero)
            for j in np.flatnonzero(costly) if n_costly else ():
                refused[idx[j]] = ("too_costly",
                    f"this scene needs {per_t_H[j]:.3g} steps per Hertz time and "
                    f"{numerics.row_width / arrays['dxi'][j]:.3g} elements (refined for its "
                    "stiffest mode): more than "
                    f"the limits {MAX_STEPS_PER_T_H:.0e} and {MAX_ELEMENTS_IN_ROW:.0e}")
            why = numerics.element_refusal(path.name, path.spec.tangential
                                           and path.spec.memory == TANGENTIAL_MEMORY.index("seed"))
            if why is not None:
                for j in np.flatnonzero(~costly):
                    refused[idx[j]] = ("tolerance_unreachable", why)
                costly = np.ones(len(costly), dtype=bool)  # (new: _ONE_COSTLY is read-only)
                n_costly = len(costly)
            if len(idx) == 1:  # (one row: scalar stores, the same numbers)
                explicit_euler[idx[0]] = path.spec.integrator == layout.EULER
                steps_per_T[idx[0]] = 1.0 / arrays["h"][0]
            else:
                explicit_euler[idx] = path.spec.integrator == layout.EULER
                steps_per_T[idx] = 1.0 / arrays["h"]
            if n_costly:
                idx = idx[~costly]
                arrays = {key: value[~costly] for key, value in arrays.items()}
                if len(idx) == 0:
                    continue
        dealt = False  # the whole batch in order, dealt to the threads (interleave)
        if n_rec == 0 and len(idx) > threads:
            dealt = _all_in_order(cols, idx)
            order = interleave(len(idx), threads)
            idx = idx[order]
            if arrays is not None:
                arrays = {key: value[order] for key, value in arrays.items()}
        # (the kernel reads a few columns of the rows, the element inputs none: taken
        # when read)
        sub = _taken(cols, idx)
        whole = sub is cols  # all rows in order: the kernel writes the batch's own buffers
        sub_out = out if whole else np.zeros((len(idx), layout.N_OUT))
        sub_rec = rec if whole else np.zeros((len(idx), n_rec, layout.N_REC))
        t0 = time.perf_counter()
        if 1 < len(idx) < threads:  # a thread per row at most: waking idle ones only costs
            import numba

            numba.set_num_threads(len(idx))
            try:
                run_path(path, sub, numerics, sub_rec, rec_every, sub_out, arrays)
            finally:
                numba.set_num_threads(threads)
        else:  # (one row: a serial kernel, whatever the thread count)
            run_path(path, sub, numerics, sub_rec, rec_every, sub_out, arrays)
        kernel_s += time.perf_counter() - t0
        if dealt:  # (idx is interleave(n, threads): a strided copy per thread, no scatter)
            start = 0
            for k in range(threads):
                stop = start + len(range(k, n, threads))
                out[k::threads] = sub_out[start:stop]
                start = stop
        elif not whole:
            out[idx] = sub_out
            if n_rec:
                rec[idx] = sub_rec
        if path.name not in path_list:
            path_list.append(path.name)
        path_codes[idx] = path_list.index(path.name)
        if path.kind == CONTINUUM_STICK:
            status = sub_out[:, layout.OUT_STATUS]
            back = (status == layout.STATUS_ASSUMPTION) | (status == layout.STATUS_TIME_LIMIT)
            if back.any():
                rows = idx[back]
                again = route(cols.take(rows), numerics.with_(continuum=False))
                queue.extend((p, rows[again.group == k]) for k, p in enumerate(again.paths))
    if timings is not None:
        timings["kernel_s"] = timings.get("kernel_s", 0.0) + kernel_s
    return out, rec, Coded(path_codes, tuple(path_list)), explicit_euler, steps_per_T, refused


def _read_only(a: np.ndarray) -> np.ndarray:
    a.flags.writeable = False
    return a


#: the row index of a one-row batch, and its "too costly" masks (shared: never written)
_ROW_0 = _read_only(np.zeros(1, dtype=np.int64))
_ONE_COSTLY = (_read_only(np.zeros(1, dtype=bool)), _read_only(np.ones(1, dtype=bool)))


def _threads() -> int:
    """Numba's thread count for the next parallel launch (>= 1)."""
    import numba

    return max(1, numba.get_num_threads())


class _Taken:
    """The rows ``idx`` of ``cols``, each column taken when it is first read.

    What :func:`~vimpact.engine.pack.run_path` reads of the rows of a continuum path
    (``dashpot_time``, ``T``, the arms, ...): a column (stored or derived, all row by
    row) taken from ``cols`` when asked for, the same values as from ``cols.take(idx)``
    without copying the columns nobody reads (17 of them, some 20 ms per 1e5 rows).
    """

    def __init__(self, cols: SceneColumns, idx: np.ndarray):
        self._cols, self._idx = cols, idx

    def __len__(self) -> int:
        return len(self._idx)

    def __getattr__(self, name: str):
        value = getattr(self._cols, name)[self._idx]
        setattr(self, name, value)  # (read once)
        return value


def _taken(cols: SceneColumns, idx: np.ndarray) -> SceneColumns:
    """:func:`_rows`, each column taken when first read (:class:`_Taken`)."""
    if _all_in_order(cols, idx):
        return cols
    return cols.take(idx) if len(idx) <= 1 else cast(SceneColumns, _Taken(cols, idx))


def _all_in_order(cols: SceneColumns, idx: np.ndarray) -> bool:
    """Whether ``idx`` is all the rows of ``cols`` in order."""
    return len(idx) == len(cols) and (len(idx) <= 1 or (
        idx[0] == 0 and idx[-1] == len(idx) - 1 and bool(np.all(np.diff(idx) == 1))))


def _rows(cols: SceneColumns, idx: np.ndarray) -> SceneColumns:
    """Return the rows ``idx`` of ``cols``, without a copy when they are all of it.

    ``cols.take(idx)``, or ``cols`` itself if ``idx`` is all its rows in order
    (one path for the whole batch, as for a single impact: no copy).
    """
    return cols if _all_in_order(cols, idx) else cols.take(idx)


def simulate_batch(scenes, numerics: Numerics | str | None = None, *,
                   timings: dict | None = None) -> pd.DataFrame:
    """Simulate many impacts in parallel (numba ``prange`` over rows, one call per kernel).

    Parameters
    ----------
    scenes : sequence of Scene, pandas.DataFrame or mapping of array_like
        The impacts: :class:`vimpact.Scene` objects, or scene columns of equal
        length (names and units in :mod:`vimpact.engine.columns`: ``nu``,
        ``G_inf_Pa``, ``R_m``, ``m_kg``, ``v_z0_m_s`` required; ``eta0_Pa_s``,
        ``G_arm<i>_Pa``, ``tau_arm<i>_s``, ``v_x0_m_s``, ``omega0_rad_s``,
        ``Theta_kg_m2`` or ``theta_ratio``, ``tangential``, ``tangential_memory``,
        ``rotation``, ``mu``, ``model``, ``adhesion_J_m2`` optional). A row with a
        work of adhesion > 0 runs on the adhesive normal-impact kernel
        (docs/physics.md#adhesion): status ``stuck`` if the sphere did not separate,
        ``F_tensile_max`` the largest pulling force (0 in rows without adhesion).
    numerics : Numerics or str, optional
        Discretization (default ``Numerics()``) or a preset name.
    timings : dict, optional
        If given, receives ``kernel_s`` (s in the kernels) and ``total_s`` (s, the
        whole call).

    Returns
    -------
    pandas.DataFrame
        One row per scene, in order, with the columns of :class:`vimpact.ImpactResult`
        (units in :data:`vimpact.UNITS`) and ``error``. A row that fails (bad input:
        status ``invalid`` with the reason in ``error``; half-space exceeded, time
        limit, ...) gets its status and NaN outputs; the others are unaffected.
        Nothing is raised for a bad row. ``error`` has pandas' string dtype; a row
        without an error has a missing value there (``isna`` is True).
    """
    import pandas as pd

    t0 = time.perf_counter()
    numerics = _numerics(numerics)
    cols = scene_columns(scenes)
    if len(cols) == 0:
        frame = pd.DataFrame({name: [] for name in RESULT_FIELDS})
    else:
        result, _, _ = run_columns(cols, numerics, timings=timings)
        frame = pd.DataFrame(result, copy=False)
    # one dtype whether or not a row failed (pandas infers object for all-None)
    frame["error"] = frame["error"].astype("str")
    if timings is not None:
        timings["total_s"] = timings.get("total_s", 0.0) + time.perf_counter() - t0
    return frame


def simulate(scene: Scene, numerics: Numerics | str | None = None, *,
             trajectory: bool = False) -> ImpactResult:
    """Simulate one impact.

    Parameters
    ----------
    scene : Scene
        The impact.
    numerics : Numerics or str, optional
        Discretization (default ``Numerics()``: about 1e-4 on e_z, e_x) or a preset
        name (``"fast"``, ``"default"``, ``"precise"``, ``"thesis"``).
    trajectory : bool, optional
        Also record the time series (``ImpactResult.trajectory``, a DataFrame with
        columns ``t_s, u_z_m, v_z_m_s, v_x_m_s, omega_rad_s, F_z_N, F_x_N, a_m,
        slip_width_m``, SI units; about 500 rows per Hertz time on the element path,
        one row per accepted step on the continuum path).

    Returns
    -------
    ImpactResult
        The outcome, SI units (:data:`vimpact.UNITS`).

    Raises
    ------
    InputError
        if ``scene`` is not a :class:`Scene`, ``numerics`` is not valid, or its
        ``tolerance`` is below what the path this scene needs can reach (the
        message names the smallest it reaches).
    HalfSpaceError
        if the contact half-width exceeds ``0.2 R`` and the scene does not
        allow it (``Scene.allow_large_contact``).
    """
    if not isinstance(scene, Scene):
        raise InputError(message("scene", scene, "a vimpact.Scene"))
    numerics = _numerics(numerics)
    if scene.adhesion > 0.0:  # its own kernel, normal only (docs/physics.md#adhesion)
        res = _adhesive(scene, numerics, trajectory)
    else:
        res = _simulate(scene, numerics, trajectory)
    if res.status == "tolerance_unreachable":
        raise InputError(res.error)
    if res.status == "half_space" and not scene.allow_large_contact:
        raise HalfSpaceError(
            f"a_max = {res.a_max:.4g} m is not allowed: must be <= 0.2 R = "
            f"{HALF_SPACE_LIMIT * scene.R:.4g} m (R = {scene.R:.4g} m; half-space model; "
            "allow_large_contact=True or --allow-large-contact accepts it)")
    return res


def _simulate(scene: Scene, numerics: Numerics, trajectory: bool) -> ImpactResult:
    """One non-adhesive impact on the batch path (:func:`simulate` checks its status)."""
    cols = SceneColumns.from_scenes([scene])
    n_rec, rec_every = 0, 1
    if trajectory:
        path = choose_path(scene, numerics)
        if path.spec is None:
            n_rec = 100_000  # one row per accepted ODE step (a hand-over records on elements)
        else:
            a = element_arrays(cols, numerics, path.spec)
            per_t_H = HERTZ_TIME_FACTOR / a["h"][0]
            rec_every = max(1, int(per_t_H) // TRAJECTORY_ROWS_PER_T_H)
            n_rec = int(a["max_steps"][0] // rec_every) + 2
        n_rec = min(n_rec, MAX_TRAJECTORY_ROWS)
    out, rec, paths, explicit_euler, steps_per_T, refused = _run(
        cols, numerics, n_rec, rec_every, None)
    code = int(paths.codes[0])  # (-1: refused, no path ran)
    row = unpack_row(cols, out[0], paths.names[code] if code >= 0 else None,
                     bool(explicit_euler[0]),
                     float(steps_per_T[0]), refused[0])
    traj = None
    if trajectory:
        traj = _trajectory(scene, rec[0, :int(out[0, layout.OUT_N_REC])])
    return ImpactResult(trajectory=traj, **row)


def _adhesive(scene: Scene, numerics: Numerics, trajectory: bool) -> ImpactResult:
    """One adhesive impact (:mod:`vimpact.engine.adhesion`; no trajectory yet)."""
    from vimpact.engine.adhesion import impact_result

    require("trajectory", trajectory, not trajectory, "False for an adhesive scene "
            "(adhesion > 0): its kernel records no trajectory yet")
    return impact_result(scene, numerics)


def explain(scene: Scene, numerics: Numerics | str | None = None) -> str:
    """Which kernel :func:`simulate` runs for ``scene`` and why (text, several lines)."""
    return choose_path(scene, _numerics(numerics)).explain()


def _trajectory(s: Scene, rec: np.ndarray) -> pd.DataFrame:
    """Physical time series from kernel records."""
    import pandas as pd

    hz = s.hertz
    vc = rec[:, layout.REC_VC] if s.computes_tangential else np.ones(len(rec))
    v_x, omega = s.tangential_end_state(vc)
    force_n = s.m * s.v_z0 / hz.T
    force_t = s.m * s.v_c0 / hz.T
    return pd.DataFrame({
        "t_s": rec[:, layout.REC_T] * hz.T,
        "u_z_m": rec[:, layout.REC_U] * hz.d,
        "v_z_m_s": rec[:, layout.REC_V] * s.v_z0,
        "v_x_m_s": v_x,
        "omega_rad_s": omega,
        "F_z_N": rec[:, layout.REC_FZ] * force_n,
        "F_x_N": rec[:, layout.REC_FX] * force_t,
        "a_m": rec[:, layout.REC_B] * hz.a_H,
        "slip_width_m": rec[:, layout.REC_SLIP] * hz.a_H,
    })
