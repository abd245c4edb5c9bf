"""Redraw the thesis figures from our own runs and restitution tables.

Every function writes one figure to ``out`` (format by extension: ``.png``,
``.svg``, ``.pdf``) and returns its path. Figures 3.2, 4.2 and 4.4 are
computed on the fly (a few small runs); figures 5.x read a restitution table
(:class:`vimpact.lookup.table.RestitutionTable`, a path to one, or a DataFrame of
its rows) made by the sweep spec named in :data:`FIGURES`.

Drawing uses matplotlib's object API (``Figure``, no pyplot state) with the
Agg canvas, so it works without a display and in threads. matplotlib and
scipy are imported only when a figure is drawn.

    from vimpact.plots.figures import plot_figure, FIGURE_NAMES
    plot_figure("fig5_2", "fig5_2.png", table="fig5_2_5_3.parquet")
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from pathlib import Path
from typing import NamedTuple

import numpy as np
import pandas as pd

from vimpact.engine.simulate import simulate, simulate_batch
from vimpact.lookup.interpolate import cluster_nodes, same_node
from vimpact.lookup.table import DATA_STATUSES, RestitutionTable
from vimpact.model.material import Material
from vimpact.model.numerics import Numerics
from vimpact.model.scene import Scene
from vimpact.plots.catalogue import CATALOGUE, FIGURE_NAMES, figure_name  # noqa: F401 - re-exported
from vimpact.plots.style import FORMATS, STYLE  # noqa: F401
from vimpact.plots.style import check_out as _check_out
from vimpact.plots.style import drawing as _drawing

__all__ = ["FIGURES", "FIGURE_NAMES", "FORMATS", "plot_figure", "figure_name",
           "fig3_2", "fig4_2", "fig4_4", "fig5_1", "fig5_2", "fig5_3", "fig5_4", "fig5_5"]

_DIMLESS = "(dimensionless)"
_Q1_LABEL = r"$Q_1$ " + _DIMLESS
_MARKERS = ("o", "s", "^", "D", "v", "P", "X", "*")


# --------------------------------------------------------------------------
# helpers
# --------------------------------------------------------------------------

def _as_table(table, name: str) -> RestitutionTable:
    if table is None:
        fig = FIGURES[name]
        raise ValueError(f"figure {name} needs a restitution table: make it with "
                         f"`vimpact sweep {fig.spec}` and pass it (--table TABLE, or table=)")
    if isinstance(table, RestitutionTable):
        opened = table
    elif isinstance(table, pd.DataFrame):
        opened = RestitutionTable(table)
    else:
        opened = RestitutionTable.open(table)
    if "psi" in opened.data.columns:  # the thesis's chapter 5 is full stick
        shown = str(table) if isinstance(table, (str, Path)) else "the given table"
        raise ValueError(f"table = {shown!r} is not allowed: figure {name} draws full-stick "
                         "restitution and this table has friction (a psi column); give a "
                         f"full-stick table, made by `vimpact sweep {FIGURES[name].spec}`")
    return opened


def _need_model(table: RestitutionTable, name: str, model: str) -> None:
    if table.model != model:
        raise ValueError(f"figure {name} needs a {model} table, this one is {table.model!r} "
                         f"(made by `vimpact sweep {FIGURES[name].spec}`)")


def _data(table: RestitutionTable, name: str) -> pd.DataFrame:
    ok = table.ok
    ok = ok[np.isfinite(ok["Q1"].to_numpy(float)) & (ok["Q1"].to_numpy(float) > 0)]
    if not len(ok):
        raise ValueError(f"figure {name}: the table has no data rows (status in "
                         f"{DATA_STATUSES}) with Q1 > 0")
    return ok


def _values(df: pd.DataFrame, column: str) -> np.ndarray:
    v = df[column].to_numpy(float)
    v = v[np.isfinite(v)]
    return cluster_nodes(v)[0] if len(v) else v


def _at(df: pd.DataFrame, column: str, value: float) -> pd.DataFrame:
    """Rows of ``df`` with ``column`` equal to ``value`` (up to round-off), sorted by Q1."""
    return df[same_node(df[column].to_numpy(float), value)].sort_values("Q1")


def _pick_nus(df: pd.DataFrame, wanted, name: str) -> list[float]:
    present = _values(df, "nu")
    nus = [float(n) for n in wanted if np.any(same_node(present, n))]
    if not nus:
        raise ValueError(f"figure {name} needs rows with nu = "
                         + ", ".join(f"{n:g}" for n in wanted) + "; the table has nu = "
                         + ", ".join(f"{n:g}" for n in present))
    return nus


def _default_nu(df: pd.DataFrame, nu) -> float:
    present = _values(df, "nu")
    if nu is not None:
        if not np.any(same_node(present, nu)):
            raise ValueError(f"nu = {nu!r} is not allowed: the table has nu = "
                             + ", ".join(f"{n:g}" for n in present))
        return float(nu)
    return 0.5 if np.any(same_node(present, 0.5)) else float(present.max())


#: Integrator tolerance of the drawn Kelvin-Voigt continuum curve: its e_z within 1e-7 of
#: the exact one (4e-8 at most over Q1 = 1e-3 ... 1e3; tests/plots/test_plots.py), far
#: below a pixel (about 1e-3 of the e_z axis), for 2/3 of the cost of rtol = 1e-10.
KV_CURVE_RTOL = 1e-8


def _kv_curve(q1_min: float, q1_max: float, n: int = 48) -> tuple[np.ndarray, np.ndarray]:
    """Kelvin-Voigt continuum ``e_z`` over ``[q1_min, q1_max]`` (log spaced).

    The curve is a scipy reference solution at ``rtol`` :data:`KV_CURVE_RTOL` (about 3 ms
    a point, 0.15 s a curve): figures 5.2 and 5.4 of tables over the same ``Q1`` range
    draw the same curve, so it is kept (read-only arrays, see :func:`_kv_curve_cached`).
    """
    return _kv_curve_cached(float(q1_min), float(q1_max), int(n))


@functools.lru_cache(maxsize=16)
def _kv_curve_cached(q1_min: float, q1_max: float, n: int) -> tuple[np.ndarray, np.ndarray]:
    from vimpact.reference.closed_forms import (
        kelvin_voigt_continuum,  # scipy: imported when drawing
    )

    q1 = np.geomspace(q1_min, q1_max, n)
    e_z = np.array(kelvin_voigt_continuum(q1, rtol=KV_CURVE_RTOL).e_z, dtype=float)
    q1.flags.writeable = e_z.flags.writeable = False  # shared by every later call
    return q1, e_z


def _table_numerics(table: RestitutionTable) -> Numerics:
    """Return the table's numerics (from its metadata), or the ``fast`` preset."""
    recorded = table.numerics
    if isinstance(recorded, dict):
        fields = Numerics.__dataclass_fields__
        try:
            return Numerics(**{k: v for k, v in recorded.items() if k in fields})
        except (TypeError, ValueError):
            pass
    return Numerics.preset("fast")


def _log_q1_axis(ax) -> None:
    ax.set_xscale("log")
    ax.set_xlabel(_Q1_LABEL)


# --------------------------------------------------------------------------
# chapter 3 and 4: computed on the fly
# --------------------------------------------------------------------------

def fig3_2(out, zeta=None) -> Path:
    """Draw thesis fig. 3.2, the linear spring-dashpot model.

    Thesis fig. 3.2: the linear spring-dashpot model, restitution ``e`` and
    contact time ``omega0 t*`` over the damping ratio ``zeta`` (log axis), all
    three regimes (:func:`vimpact.reference.closed_forms.linear_model_zeta`).
    """
    from vimpact.reference.closed_forms import linear_model_zeta

    zeta = np.geomspace(1e-2, 1e2, 600) if zeta is None else np.asarray(zeta, dtype=float)
    res = linear_model_zeta(zeta)
    with _drawing(out, 2, 1, figsize=(6.4, 6.0), sharex=True) as (fig, (ax_e, ax_t)):
        for ax in (ax_e, ax_t):
            ax.axvspan(zeta.min(), 1.0, color="tab:blue", alpha=0.06, lw=0)
            ax.axvspan(1.0, zeta.max(), color="tab:red", alpha=0.06, lw=0)
            ax.axvline(1.0, color="k", ls=":", lw=1.0)
        ax_e.plot(zeta, res.e, color="tab:blue", label=r"$e = \exp(-\delta t^*)$")
        ax_e.plot([1.0], [math.exp(-2.0)], "ko", label=r"critical $\zeta = 1$: $e = e^{-2}$")
        ax_e.set_ylabel(r"$e$ " + _DIMLESS)
        ax_e.set_ylim(0.0, 1.02)
        ax_e.text(0.03, 0.06, "underdamped\n" + r"$\zeta < 1$", transform=ax_e.transAxes)
        ax_e.text(0.97, 0.06, "overdamped\n" + r"$\zeta > 1$", transform=ax_e.transAxes,
                  ha="right")
        ax_e.legend(loc="upper right")
        ax_e.set_title("Linear spring-dashpot impact (thesis fig. 3.2)")
        ax_t.plot(zeta, res.t_star, color="tab:red", label=r"contact time $\omega_0 t^*$")
        ax_t.plot([1.0], [2.0], "ko", label=r"$\omega_0 t^* = 2$ at $\zeta = 1$")
        ax_t.axhline(math.pi, color="0.4", ls="--", lw=1.0, label=r"$\pi$ (undamped)")
        ax_t.set_ylabel(r"$\omega_0 t^*$ " + _DIMLESS)
        ax_t.set_xscale("log")
        ax_t.set_xlabel(r"damping ratio $\zeta = \delta / \omega_0$ " + _DIMLESS)
        ax_t.set_ylim(0.0, None)
        ax_t.legend(loc="upper right")
    return Path(out)


def thesis_scene() -> Scene:
    """Return the example of thesis fig. 4.2 (docs/physics.md#elastic-impact).

    Kelvin-Voigt ``E = 5e10 Pa``, ``nu = 0.5``, ``eta = 1e5 Pa s``, ``R = 0.2 m``, ``m =
    10 kg``, ``v_z0 = 10 m/s``, with ``v_x0 = 5 m/s`` and backspin ``omega0 = -10 rad/s``.
    """
    material = Material.kelvin_voigt(nu=0.5, E=5e10, eta=1e5)
    return Scene(material, R=0.2, m=10.0, v_z0=10.0, v_x0=5.0, omega0=-10.0)


def fig4_2(out, scene: Scene | None = None, numerics: Numerics | None = None) -> Path:
    """Draw thesis fig. 4.2, the velocities during one impact.

    Thesis fig. 4.2: normalized ``v_z/v_z0``, ``v_x/v_x0``, ``omega/omega0``
    during one impact over ``t / t_H`` (default: :func:`thesis_scene`).
    """
    scene = scene or thesis_scene()
    res = simulate(scene, numerics, trajectory=True)
    tr = res.trajectory
    assert tr is not None  # trajectory=True records it
    t = tr["t_s"].to_numpy() / res.t_hertz
    with _drawing(out) as (fig, ax):
        ax.axhline(0.0, color="k", lw=0.8)
        ax.plot(t, tr["v_z_m_s"] / scene.v_z0, label=r"$v_z / v_{z0}$")
        if scene.v_x0 != 0.0:
            ax.plot(t, tr["v_x_m_s"] / scene.v_x0, ls="--", label=r"$v_x / v_{x0}$")
        if scene.omega0 != 0.0:
            ax.plot(t, tr["omega_rad_s"] / scene.omega0, ls="-.", label=r"$\omega / \omega_0$")
        ax.axvline(res.t_contact / res.t_hertz, color="0.4", ls=":", lw=1.0,
                   label="end of contact")
        ax.set_xlabel(r"time $t / t_H$ " + _DIMLESS)
        ax.set_ylabel("normalized velocity " + _DIMLESS)
        mat = scene.material
        ax.set_title(f"One impact (thesis fig. 4.2): {mat.model.replace('_', '-')}, "
                     rf"$\nu$ = {mat.nu:g}, $Q_1$ = {res.Q1:.3g}")
        ax.text(0.02, 0.04, rf"$e_z$ = {res.e_z:.4f}, $e_x$ = {res.e_x:.4f}"
                "\n" + f"$v_{{z0}}$ = {scene.v_z0:g} m/s, $v_{{x0}}$ = {scene.v_x0:g} m/s, "
                rf"$\omega_0$ = {scene.omega0:g} rad/s", transform=ax.transAxes, fontsize=9.5,
                bbox=dict(fc="white", ec="0.7", alpha=0.9))
        ax.legend(loc="center right")
    return Path(out)


def fig4_4(out, steps=(50, 100, 500), scene: Scene | None = None, elements: int = 200) -> Path:
    """Draw thesis fig. 4.4, the phase plane of explicit Euler.

    Thesis fig. 4.4: phase plane ``v_z`` over ``u_z`` of an elastic impact,
    explicit Euler with ``steps`` time steps per Hertz time, against the exact
    curve ``v = sqrt(1 - u^(5/2))`` in Hertz units (``u / d``, ``v / v_z0``).

    Default scene: the fig. 4.2 sphere on an elastic half-space
    (``E = 5e10 Pa``, ``nu = 0.5``, ``R = 0.2 m``, ``m = 10 kg``, ``v_z0 = 10 m/s``).
    """
    if scene is None:
        scene = Scene(Material.elastic(nu=0.5, E=5e10), R=0.2, m=10.0, v_z0=10.0)
    with _drawing(out, figsize=(6.4, 5.0)) as (fig, ax):
        u = np.linspace(0.0, 1.0, 400)
        v = np.sqrt(np.clip(1.0 - u**2.5, 0.0, None))
        ax.plot(np.r_[u, u[::-1]], np.r_[v, -v[::-1]], color="k", lw=2.2,
                label=r"exact: $v = \pm\sqrt{1 - u^{5/2}}$")
        for k, n in enumerate(steps):
            res = simulate(scene, Numerics(integrator="euler", steps=int(n), elements=elements),
                           trajectory=True)
            tr = res.trajectory
            assert tr is not None  # trajectory=True records it
            ax.plot(tr["u_z_m"] / res.d_hertz, tr["v_z_m_s"] / scene.v_z0,
                    marker=_MARKERS[k % len(_MARKERS)], markevery=max(1, len(tr) // 25),
                    ms=4, lw=1.2, label=f"explicit Euler, {n} steps per $t_H$ "
                                        f"($e_z$ = {res.e_z:.4f})")
        ax.axhline(0.0, color="0.5", lw=0.8)
        ax.set_xlabel(r"indentation $u_z / d$ " + _DIMLESS)
        ax.set_ylabel(r"velocity $v_z / v_{z0}$ " + _DIMLESS)
        ax.set_title("Elastic impact, phase plane (thesis fig. 4.4)")
        ax.legend(loc="center left", bbox_to_anchor=(0.01, 0.5))  # inside the loop
    return Path(out)


# --------------------------------------------------------------------------
# chapter 5: from tables
# --------------------------------------------------------------------------

def fig5_1(table, out) -> Path:
    """Draw thesis fig. 5.1, restitution of random physical draws.

    Thesis fig. 5.1: ``e_z`` and ``e_x`` over ``Q1`` (log) for random
    physical draws (scatter; ``e_x`` coloured by ``nu``). Table:
    ``sweeps/fig5_1_kelvin_voigt_random.toml``.
    """
    table = _as_table(table, "fig5_1")
    df = _data(table, "fig5_1")
    q1 = df["Q1"].to_numpy(float)
    with _drawing(out, 1, 2, figsize=(10.0, 4.4), sharex=True) as (fig, (ax_z, ax_x)):
        ax_z.scatter(q1, df["e_z"], s=10, alpha=0.6, color="tab:blue", lw=0,
                     label=f"{len(df)} random draws")
        if table.model == "kelvin_voigt":
            q, e = _kv_curve(q1.min(), q1.max())
            ax_z.plot(q, e, color="k", lw=1.2, label="Kelvin-Voigt continuum")
        ax_z.set_ylabel(r"$e_z$ " + _DIMLESS)
        ax_z.set_ylim(0.0, 1.02)
        ax_z.legend(loc="lower left")
        ax_z.set_title("normal")
        ex = df["e_x"].to_numpy(float)
        nus = _values(df, "nu")
        if len(nus) > 1:  # e_x depends on nu: colour by it
            sc = ax_x.scatter(q1, ex, s=10, c=df["nu"].to_numpy(float), cmap="viridis",
                              vmin=0.0, vmax=0.5, lw=0, alpha=0.8)
            fig.colorbar(sc, ax=ax_x, label=r"$\nu$ " + _DIMLESS)
        else:
            ax_x.scatter(q1, ex, s=10, color="tab:orange", lw=0, alpha=0.7,
                         label=rf"$\nu$ = {nus[0]:g}" if len(nus) else None)
            if len(nus):
                ax_x.legend(loc="upper right")
        ax_x.set_ylabel(r"$e_x$ " + _DIMLESS)
        ax_x.set_ylim(0.0, None)
        ax_x.set_title("tangential")
        for ax in (ax_z, ax_x):
            _log_q1_axis(ax)
        fig.suptitle(f"Restitution of random physical draws ({table.model.replace('_', '-')}; "
                     "thesis fig. 5.1)")
    return Path(out)


def fig5_2(table, out, nus=(0.5, 0.0)) -> Path:
    """Draw thesis fig. 5.2, ``e_z`` over ``Q1`` (Kelvin-Voigt).

    Thesis fig. 5.2: ``e_z`` over ``Q1`` for ``nu`` = 0.5 and 0 (Kelvin-Voigt
    table), with the linear model's ``e`` at ``zeta = Q1`` and the Kelvin-Voigt
    continuum curve. Table: ``sweeps/fig5_2_3_kelvin_voigt_nu.toml``.
    """
    table = _as_table(table, "fig5_2")
    _need_model(table, "fig5_2", "kelvin_voigt")
    df = _data(table, "fig5_2")
    nus = _pick_nus(df, nus, "fig5_2")
    lo, hi = df["Q1"].min(), df["Q1"].max()
    from vimpact.reference.closed_forms import linear_model_zeta

    with _drawing(out) as (fig, ax):
        q, e = _kv_curve(lo, hi)
        ax.plot(q, e, color="k", lw=1.6, label="Kelvin-Voigt continuum (1-DOF ODE)")
        ax.plot(q, linear_model_zeta(q).e, color="tab:gray", ls="--",
                label=r"linear model, $e$ at $\zeta = Q_1$")
        for k, nu in enumerate(nus):
            rows = _at(df, "nu", nu)
            ax.plot(rows["Q1"], rows["e_z"], ls="none", marker=_MARKERS[k % len(_MARKERS)],
                    mfc="none" if k else None, ms=6 if k else 4.5,
                    label=rf"MDR, $\nu$ = {nu:g}")
        _log_q1_axis(ax)
        ax.set_ylabel(r"$e_z$ " + _DIMLESS)
        ax.set_ylim(0.0, 1.02)
        ax.set_title("Normal restitution, Kelvin-Voigt (thesis fig. 5.2)")
        ax.legend(loc="lower left")
    return Path(out)


def fig5_3(table, out, nus=(0.0, 0.25, 0.5)) -> Path:
    """Thesis fig. 5.3: ``e_x`` over ``Q1`` for ``nu`` = 0, 0.25, 0.5 (Kelvin-Voigt table).

    Table: ``sweeps/fig5_2_3_kelvin_voigt_nu.toml``.
    """
    table = _as_table(table, "fig5_3")
    _need_model(table, "fig5_3", "kelvin_voigt")
    df = _data(table, "fig5_3")
    nus = _pick_nus(df, nus, "fig5_3")
    with _drawing(out) as (fig, ax):
        for k, nu in enumerate(nus):
            rows = _at(df, "nu", nu)
            ax.plot(rows["Q1"], rows["e_x"], marker=_MARKERS[k % len(_MARKERS)], ms=4,
                    label=rf"$\nu$ = {nu:g}")
        _log_q1_axis(ax)
        ax.set_ylabel(r"$e_x$ " + _DIMLESS)
        ax.set_ylim(0.0, None)
        ax.set_title("Tangential restitution, Kelvin-Voigt (thesis fig. 5.3)")
        ax.legend(loc="best")
    return Path(out)


def _q2_family(df: pd.DataFrame, name: str, limit: int = 8) -> list[float]:
    q2 = _values(df, "Q2")
    if not len(q2):
        raise ValueError(f"figure {name} needs standard-solid rows (finite Q2)")
    if len(q2) > limit:  # keep the legend readable: evenly spaced in log Q2
        q2 = q2[np.unique(np.round(np.linspace(0, len(q2) - 1, limit)).astype(int))]
    return [float(x) for x in q2]


def _kelvin_voigt_rows(df: pd.DataFrame) -> np.ndarray:
    """Rows that are Kelvin-Voigt impacts: ``Q2`` 0 (the limit ``G2 -> inf``) or NaN."""
    q2 = df["Q2"].to_numpy(float) if "Q2" in df.columns else np.full(len(df), np.nan)
    return ~(q2 > 0)


def _family_plot(table, out, name: str, column: str, nu, kv_table=None) -> Path:
    table = _as_table(table, name)
    _need_model(table, name, "standard_solid")
    df = _data(table, name)
    nu = _default_nu(df, nu)
    df = df[same_node(df["nu"].to_numpy(float), nu)]
    q2_rows = df[~_kelvin_voigt_rows(df)]
    family = _q2_family(q2_rows, name)
    kv_rows = df[_kelvin_voigt_rows(df)]
    if kv_table is not None:
        kv_table = _as_table(kv_table, name)
        _need_model(kv_table, name, "kelvin_voigt")
        kv_rows = _data(kv_table, name)
        kv_rows = kv_rows[same_node(kv_rows["nu"].to_numpy(float), nu)]
        if not len(kv_rows):
            raise ValueError(f"figure {name}: the Kelvin-Voigt table has no rows with "
                             f"nu = {nu:g}")
    lo, hi = q2_rows["Q1"].min(), q2_rows["Q1"].max()
    with _drawing(out) as (fig, ax):
        import matplotlib

        cmap = matplotlib.colormaps["viridis"]
        for k, q2 in enumerate(family):
            rows = _at(q2_rows, "Q2", q2)
            ax.plot(rows["Q1"], rows[column], marker=_MARKERS[k % len(_MARKERS)], ms=4,
                    color=cmap(k / max(1, len(family) - 1) * 0.9),
                    label=rf"$Q_2$ = {q2:.3g}")
        if column == "e_z":
            q, e = _kv_curve(lo, hi)
            ax.plot(q, e, color="k", lw=2.4, zorder=1.5, label="Kelvin-Voigt (continuum)")
        else:
            kv = kv_rows.sort_values("Q1")
            label = "Kelvin-Voigt"
            if not len(kv):  # not in the tables: compute it at the table's Q1 values
                q1 = _values(q2_rows, "Q1")
                kv = simulate_batch([Scene.from_dimensionless(q, nu) for q in q1],
                                    _table_numerics(table))
                kv = kv[kv["status"].isin(DATA_STATUSES)].sort_values("Q1")
                label = "Kelvin-Voigt (computed, table numerics)"
            ax.plot(kv["Q1"], kv[column], color="k", lw=2.4, zorder=1.5, label=label)
        _log_q1_axis(ax)
        symbol = "e_z" if column == "e_z" else "e_x"
        ax.set_ylabel(rf"${symbol[0]}_{symbol[2]}$ " + _DIMLESS)
        ax.set_ylim(0.0, 1.02 if column == "e_z" else None)
        what = "Normal" if column == "e_z" else "Tangential"
        number = "5.4" if column == "e_z" else "5.5"
        ax.set_title(f"{what} restitution, standard solid, " + rf"$\nu$ = {nu:g}"
                     f" (thesis fig. {number})")
        ax.legend(loc="lower left" if column == "e_z" else "best", ncol=2)
    return Path(out)


def fig5_4(table, out, nu=None, kv_table=None) -> Path:
    """Draw thesis fig. 5.4, ``e_z`` over ``Q1`` (standard solid).

    Thesis fig. 5.4: ``e_z`` over ``Q1`` for a family of ``Q2`` (standard
    solid) with the Kelvin-Voigt curve (``Q2 -> 0``, continuum limit) in black.
    Table: ``sweeps/fig5_4_5_standard_solid_q2.toml (+ sweeps/fig5_4_5_kelvin_voigt.toml)``;
    ``nu`` default 0.5 if present
    (``kv_table`` is accepted for symmetry with :func:`fig5_5`).
    """
    return _family_plot(table, out, "fig5_4", "e_z", nu, kv_table)


def fig5_5(table, out, nu=None, kv_table=None) -> Path:
    """Draw thesis fig. 5.5, ``e_x`` over ``Q1`` (standard solid).

    Thesis fig. 5.5: ``e_x`` over ``Q1`` for a family of ``Q2`` (standard
    solid) with the Kelvin-Voigt curve in black: from ``kv_table`` (a
    Kelvin-Voigt table) if given, else from the table's own Kelvin-Voigt rows
    (``Q2`` 0 or NaN), else computed at the table's ``Q1`` values with its
    numerics. Table: ``sweeps/fig5_4_5_standard_solid_q2.toml
    (+ sweeps/fig5_4_5_kelvin_voigt.toml)``; ``nu`` default 0.5 if present.
    """
    return _family_plot(table, out, "fig5_5", "e_x", nu, kv_table)


# --------------------------------------------------------------------------
# dispatcher
# --------------------------------------------------------------------------

class Figure(NamedTuple):
    """A figure of the thesis.

    Its drawing function, a title, and the sweep spec of its table (``None`` when computed
    on the fly).
    """

    func: Callable
    title: str
    spec: str | None


def _lazy(module: str, name: str) -> Callable:
    """Return the figure ``name`` of ``module`` (imported when drawn)."""
    def draw(out):
        import importlib
        return getattr(importlib.import_module(module), name)(out)
    return draw


def _friction(name: str) -> Callable:
    """Return a figure of :mod:`vimpact.plots.friction` (imported when drawn)."""
    return _lazy("vimpact.plots.friction", name)


#: drawing function of each figure of :data:`vimpact.plots.catalogue.CATALOGUE`
_DRAW: dict[str, Callable] = {
    "fig3_2": fig3_2, "fig4_2": fig4_2, "fig4_4": fig4_4, "fig5_1": fig5_1, "fig5_2": fig5_2,
    "fig5_3": fig5_3, "fig5_4": fig5_4, "fig5_5": fig5_5,
    "fig_mbf": _friction("fig_mbf"), "fig_beta_psi": _friction("fig_beta_psi"),
    "fig_chung_ooi": _friction("fig_chung_ooi"),
    "fig_temperature": _lazy("vimpact.plots.temperature", "fig_temperature"),
    "fig_adhesion": _lazy("vimpact.plots.adhesion", "fig_adhesion"),
}
if set(_DRAW) != set(CATALOGUE):  # the catalogue (titles, specs) and the drawings agree
    raise ImportError(f"figures without a drawing or a catalogue entry: "
                      f"{sorted(set(_DRAW) ^ set(CATALOGUE))}")
FIGURES: dict[str, Figure] = {name: Figure(_DRAW[name], *CATALOGUE[name]) for name in CATALOGUE}


def plot_figure(name: str, out, table=None) -> Path:
    """Draw thesis figure ``name`` (see :data:`FIGURE_NAMES`) to ``out``.

    Figures 5.x need ``table`` (a :class:`RestitutionTable`, a path to a
    Parquet table, or a DataFrame of its rows); the others are computed on the
    fly and take none. Figures 5.4 and 5.5 also take a list of two tables, a
    standard-solid one and a Kelvin-Voigt one for the black curve.
    """
    key = figure_name(name)
    fig = FIGURES[key]
    _check_out(out)
    tables = [] if table is None else list(table) if isinstance(table, (list, tuple)) else [table]
    if fig.spec is None:
        if tables:
            raise ValueError(f"figure {key} is computed on the fly and takes no table")
        return fig.func(out)
    tables = [_as_table(t, key) for t in tables] or [_as_table(None, key)]
    if key in ("fig5_4", "fig5_5") and len(tables) == 2:
        models = sorted(t.model for t in tables)
        if models != ["kelvin_voigt", "standard_solid"]:
            raise ValueError(f"figure {key} takes one standard_solid table and optionally one "
                             f"kelvin_voigt table, got {' and '.join(models)}")
        ss, kv = sorted(tables, key=lambda t: t.model != "standard_solid")
        return fig.func(ss, out, kv_table=kv)
    if len(tables) > 1:
        raise ValueError(f"figure {key} takes one table, got {len(tables)}")
    return fig.func(tables[0], out)
