"""Prony series fitted to measurements: a DMA master curve or a relaxation modulus.

The fit (docs/physics.md#prony-fit) is a linear least-squares problem with
non-negative unknowns: the relaxation times are fixed in advance, log-spaced
over the span of the data (:func:`relaxation_times`, ``per_decade`` of them per
decade, both ends included), and only the moduli ``G_inf``, ``G_i`` (and the
dashpot ``eta0`` when asked) are fitted, by :func:`scipy.optimize.nnls`
(Lawson-Hanson). Non-negative moduli make the fitted material passive (it
dissipates energy at every frequency), which a free fit does not guarantee.
Every data point is weighted by the inverse of its value, so the fit minimises
the *relative* misfit over data that span decades of modulus; arms whose
modulus comes out 0 are dropped.

Closed forms fitted (shear moduli, ``omega = 2 pi f``)::

    G'(omega)  = G_inf + sum_i G_i omega^2 tau_i^2 / (1 + omega^2 tau_i^2)
    G''(omega) = sum_i G_i omega tau_i / (1 + omega^2 tau_i^2) (+ eta0 omega)
    G(t)       = G_inf + sum_i G_i exp(-t / tau_i)

The residual reported is the root mean square of the relative misfits
``(model - data) / data`` over every fitted value (``G'`` and ``G''`` both count
for a DMA curve), dimensionless.

Why SciPy's ``nnls`` and not a fitting package: the maintained one on PyPI,
pyvisco, solves the same non-negative problem with the same SciPy routine, but
it requires a Jupyter/Voila user-interface stack (jupyterlab, notebook,
voila, ipywidgets, ipympl) and works on its own DataFrame formats; the fit
itself is a few lines on top of a dependency vimpact already has.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from vimpact.model.material import Material
from vimpact.model.temperature import ShiftLaw
from vimpact.model.validation import InputError, message, require

#: Relaxation times per decade unless told otherwise: one per decade leaves a ripple of a
#: few percent in G'' of a smooth spectrum, two follow it to about 0.5 %.
DEFAULT_PER_DECADE = 2.0
#: Fewest data points a fit accepts (a DMA point counts once, with its G' and G'').
MIN_POINTS = 3
#: Allowed relaxation times per decade (at least one per two decades, at most 10).
PER_DECADE_RANGE = (0.5, 10.0)


class PronyFit(NamedTuple):
    """A fitted Prony material and how well it fits (``material, residual = fit``).

    Attributes
    ----------
    material : the fitted :class:`~vimpact.Material` (model ``"prony"``, moduli > 0)
    residual : RMS relative misfit of the fitted values, dimensionless
    """

    material: Material
    residual: float


def relaxation_times(lo: float, hi: float, per_decade: float) -> np.ndarray:
    """Return log-spaced relaxation times from ``lo`` to ``hi``, s.

    Log-spaced relaxation times from ``lo`` to ``hi`` (s, both included),
    ``per_decade`` per decade (rounded to a whole number of intervals, at least 1).
    """
    n = max(1, round(per_decade * math.log10(hi / lo)))
    return np.geomspace(lo, hi, n + 1)


def storage_loss(material: Material, frequency_Hz) -> tuple[np.ndarray, np.ndarray]:
    """``G'`` and ``G''`` (Pa) of ``material`` at the frequencies ``frequency_Hz`` (Hz)."""
    w = 2.0 * np.pi * np.asarray(frequency_Hz, dtype=float)
    storage = np.full_like(w, material.G_inf)
    loss = material.eta0 * w
    for G, tau in material.arms:
        wt = w * tau
        storage = storage + G * wt**2 / (1.0 + wt**2)
        loss = loss + G * wt / (1.0 + wt**2)
    return storage, loss


def relaxation_modulus(material: Material, time_s) -> np.ndarray:
    """``G(t) = G_inf + sum_i G_i exp(-t/tau_i)`` (Pa) of ``material`` at ``time_s`` (s).

    The dashpot's delta at ``t = 0`` is left out.
    """
    t = np.asarray(time_s, dtype=float)
    out = np.full_like(t, material.G_inf)
    for G, tau in material.arms:
        out = out + G * np.exp(-t / tau)
    return out


def fit_dma(frequency_Hz, storage_Pa, loss_Pa, nu: float, *,
            per_decade: float = DEFAULT_PER_DECADE, dashpot: bool = False,
            shift: ShiftLaw | None = None) -> PronyFit:
    """Fit a Prony series to shear storage and loss moduli (:meth:`Material.from_dma`).

    The relaxation times run from ``1 / omega_max`` to ``1 / omega_min``
    (``omega = 2 pi f``). Raises :class:`~vimpact.model.validation.InputError`
    naming the argument for bad data: not 1-D numbers, lengths that differ,
    NaN or inf, a frequency <= 0, a modulus <= 0, fewer than :data:`MIN_POINTS`
    distinct frequencies.
    """
    f, storage, loss = _columns({"frequency_Hz": frequency_Hz, "storage_Pa": storage_Pa,
                                 "loss_Pa": loss_Pa})
    per_decade = _per_decade(per_decade)
    w = 2.0 * np.pi * f
    taus = relaxation_times(1.0 / w.max(), 1.0 / w.min(), per_decade)
    wt = w[:, None] * taus[None, :]
    top = np.hstack([np.ones((len(w), 1)), wt**2 / (1.0 + wt**2)])
    bottom = np.hstack([np.zeros((len(w), 1)), wt / (1.0 + wt**2)])
    if dashpot:
        top = np.hstack([top, np.zeros((len(w), 1))])
        bottom = np.hstack([bottom, w[:, None]])
    A = np.vstack([top / storage[:, None], bottom / loss[:, None]])
    _enough(A, "frequency_Hz", per_decade)
    x, residual = _nnls(A)
    return PronyFit(_material(nu, x, taus, dashpot, shift, "the lowest frequencies"), residual)


def fit_relaxation(time_s, modulus_Pa, nu: float, *,
                   per_decade: float = DEFAULT_PER_DECADE,
                   shift: ShiftLaw | None = None) -> PronyFit:
    """Fit a Prony series to a shear relaxation modulus (:meth:`Material.from_relaxation`).

    The relaxation times run from the first to the last time of the data.
    Raises :class:`~vimpact.model.validation.InputError` as :func:`fit_dma`
    (a time <= 0 and a modulus <= 0 are refused).
    """
    t, G = _columns({"time_s": time_s, "modulus_Pa": modulus_Pa})
    per_decade = _per_decade(per_decade)
    taus = relaxation_times(t.min(), t.max(), per_decade)
    A = np.hstack([np.ones((len(t), 1)), np.exp(-t[:, None] / taus[None, :])]) / G[:, None]
    _enough(A, "time_s", per_decade)
    x, residual = _nnls(A)
    return PronyFit(_material(nu, x, taus, False, shift, "the longest times"), residual)


def _per_decade(value) -> float:
    lo, hi = PER_DECADE_RANGE
    ok = isinstance(value, (int, float)) and not isinstance(value, bool) and lo <= value <= hi
    require("per_decade", value, ok, f"a number of relaxation times per decade in [{lo:g}, {hi:g}]")
    return float(value)


def _columns(data: dict) -> tuple[np.ndarray, ...]:
    """Return the data as 1-D float arrays of one length, finite and > 0, sorted by the first."""
    out = []
    for name, values in data.items():
        try:
            x = np.asarray(values, dtype=float)
        except (TypeError, ValueError):
            raise InputError(message(name, values, "a sequence of numbers")) from None
        require(name, values, x.ndim == 1, "a one-dimensional sequence of numbers")
        bad = np.flatnonzero(~np.isfinite(x) | ~(x > 0.0))
        if bad.size:
            raise InputError(message(f"{name}[{bad[0]}]", float(x[bad[0]]),
                                     "a finite number > 0"))
        out.append(x)
    lengths = {name: len(x) for name, x in zip(data, out)}
    require("lengths", lengths, len(set(lengths.values())) == 1, "equal (one value per point)")
    first = next(iter(data))
    n = len(np.unique(out[0]))
    require(f"{first} (number of distinct values)", n, n >= MIN_POINTS, f">= {MIN_POINTS}")
    order = np.argsort(out[0], kind="stable")
    return tuple(x[order] for x in out)


def _enough(A: np.ndarray, name: str, per_decade: float) -> None:
    """Refuse a fit with more unknowns than fitted values (it would match any data)."""
    values, unknowns = A.shape
    require(f"{name} (number of points)", values // (2 if name == "frequency_Hz" else 1),
            values >= unknowns, f"enough for {unknowns} unknown moduli ({values} fitted values "
            f"now); give more points or fewer relaxation times per decade (per_decade = "
            f"{per_decade:g})")


def _nnls(A: np.ndarray) -> tuple[np.ndarray, float]:
    """Solve the non-negative least-squares problem of a fit.

    Non-negative ``x`` minimising ``|A x - 1|`` (rows already divided by the data)
    and the RMS relative residual. Columns are scaled to unit norm for the solver.
    """
    from scipy.optimize import nnls

    norms = np.linalg.norm(A, axis=0)
    norms[norms == 0.0] = 1.0
    y, _ = nnls(A / norms, np.ones(A.shape[0]), maxiter=50 * A.shape[1])
    x = y / norms
    return x, float(np.sqrt(np.mean((A @ x - 1.0) ** 2)))


def _material(nu, x, taus, dashpot, shift, where) -> Material:
    G_inf = float(x[0])
    require("G_inf (fitted relaxed modulus, Pa)", G_inf, G_inf > 0.0,
            f"> 0: the data show no relaxed plateau; add data at {where}")
    moduli = x[1:1 + len(taus)]
    arms = [(float(G), float(tau)) for G, tau in zip(moduli, taus) if G > 0.0]
    eta0 = float(x[-1]) if dashpot else 0.0
    mat = Material.prony(nu=nu, G_inf=G_inf, arms=arms, eta0=eta0)
    return mat.with_shift(shift) if shift is not None else mat


#: Columns of a measurement file, by kind: a DMA master curve, a relaxation modulus.
MEASUREMENT_COLUMNS = {"dma": ("frequency_Hz", "storage_Pa", "loss_Pa"),
                       "relaxation": ("time_s", "modulus_Pa")}


def load_measurements(path) -> tuple[str, dict[str, np.ndarray]]:
    """Read a measurement file: CSV with a header row, ``#`` lines are comments.

    The header names the kind: ``frequency_Hz, storage_Pa, loss_Pa`` (a DMA master
    curve of the shear moduli) or ``time_s, modulus_Pa`` (a shear relaxation
    modulus), in any order; other columns are refused. Returns the kind (``"dma"``
    or ``"relaxation"``) and the columns. Raises ``ValueError`` naming the file,
    the line and the column for a value that is not a finite number > 0.
    """
    import csv
    from pathlib import Path

    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise InputError(f"{path}: measurement file not found") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: cannot read the measurement file: {exc}") from None
    rows = [(i, r) for i, r in enumerate(csv.reader(text.splitlines()), start=1)
            if r and not r[0].lstrip().startswith("#") and any(c.strip() for c in r)]
    if not rows:
        raise InputError(f"{path}: no header row (expected the columns "
                         + " or ".join(", ".join(c) for c in MEASUREMENT_COLUMNS.values()) + ")")
    header = [c.strip() for c in rows[0][1]]
    kind = next((k for k, cols in MEASUREMENT_COLUMNS.items() if sorted(cols) == sorted(header)),
                None)
    if kind is None:
        raise InputError(f"{path}: " + message("columns", ", ".join(header), " or ".join(
            ", ".join(c) for c in MEASUREMENT_COLUMNS.values()) + " (shear moduli)"))
    data: dict[str, list[float]] = {c: [] for c in header}
    for line, row in rows[1:]:
        if len(row) != len(header):
            raise InputError(f"{path}: line {line}: " + message(
                "row", ",".join(row), f"{len(header)} values ({', '.join(header)})"))
        for name, cell in zip(header, row):
            try:
                x = float(cell)
            except ValueError:
                x = None
            if x is None or not (math.isfinite(x) and x > 0.0):
                raise InputError(f"{path}: line {line}: " + message(
                    name, cell.strip(), "a finite number > 0"))
            data[name].append(x)
    return kind, {c: np.array(data[c]) for c in MEASUREMENT_COLUMNS[kind]}


__all__ = ["DEFAULT_PER_DECADE", "MEASUREMENT_COLUMNS", "MIN_POINTS", "PER_DECADE_RANGE",
           "PronyFit", "fit_dma", "fit_relaxation", "load_measurements", "relaxation_modulus",
           "relaxation_times", "storage_loss"]
