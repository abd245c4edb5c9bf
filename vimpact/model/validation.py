"""Input checks with messages that name the parameter, its value and what is allowed.

One set of rules (:data:`RULES`) serves both ways in: the scalar checks of the
one-impact API (:func:`positive`, :func:`finite`, ...; they raise
:class:`InputError`) and the vectorized checks of the batch path
(:func:`check_column`; a bad row gets a reason, the others go on).
"""

from __future__ import annotations

import math
import numbers

import numpy as np


class InputError(ValueError):
    """Bad input: the message names the parameter, its value and what is allowed.

    A ``ValueError``, so ``except ValueError`` keeps working; the command line
    prints it as one line on stderr with exit code 2.
    """


#: rule name -> (vectorized test on a float array, what is allowed)
RULES = {
    "finite": (lambda x: np.isfinite(x), "a finite number"),
    "positive": (lambda x: np.isfinite(x) & (x > 0.0), "a finite number > 0"),
    "non_negative": (lambda x: np.isfinite(x) & (x >= 0.0), "a finite number >= 0"),
    "poisson_ratio": (lambda x: (x >= 0.0) & (x <= 0.5), "in [0, 0.5]"),
    # a friction coefficient: >= 0, inf meaning full stick
    "friction": (lambda x: (x >= 0.0) & ~np.isnan(x), "a number >= 0 (inf: full stick)"),
}


def is_none(values) -> np.ndarray:
    """Return elementwise ``value is None`` of an object array, bool.

    Elementwise ``value is None`` of an object array (e.g. the reasons column: no
    reason yet), as a bool array.
    """
    return np.equal(values, None)  # type: ignore[call-overload]  # (stubs: no None operand)


def unexplained(mask: np.ndarray, reasons: np.ndarray) -> np.ndarray:
    """Return the indices of the rows of ``mask`` whose reason is still ``None``.

    In ascending order, as ``np.flatnonzero(mask & is_none(reasons))``, but looking at
    the rows of ``mask`` only (bad rows are few; ``is_none`` of a whole batch costs
    about 1.3 ms per 1e5 rows, paid once per input column before).
    """
    rows = np.flatnonzero(mask)
    return rows[is_none(reasons[rows])] if rows.size else rows


def message(name: str, value, allowed: str) -> str:
    """Return the one wording of every input error."""
    return f"{name} = {value!r} is not allowed: must be {allowed}"


def require(name: str, value, ok: bool, allowed: str) -> None:
    """Raise :class:`InputError` naming ``name``, ``value`` and ``allowed`` unless ``ok``."""
    if not ok:
        raise InputError(message(name, value, allowed))


def _check(rule: str, name: str, value) -> float:
    x = _number(name, value)
    test, allowed = RULES[rule]
    require(name, value, bool(test(np.float64(x))), allowed)
    return x


def positive(name: str, value) -> float:
    """``value`` as a float, finite and > 0."""
    return _check("positive", name, value)


def non_negative(name: str, value) -> float:
    """``value`` as a float, finite and >= 0."""
    return _check("non_negative", name, value)


def finite(name: str, value) -> float:
    """``value`` as a finite float."""
    return _check("finite", name, value)


def poisson_ratio(name: str, value) -> float:
    """Poisson ratio in [0, 0.5]."""
    return _check("poisson_ratio", name, value)


def friction_coefficient(name: str, value) -> float:
    """Coulomb friction coefficient, >= 0 (``inf``: full stick)."""
    return _check("friction", name, value)


def one_of(name: str, value, choices) -> str:
    """``value`` must be one of ``choices``."""
    require(name, value, isinstance(value, str) and value in choices,
            "one of " + ", ".join(map(repr, choices)))
    return value


def flag(name: str, value) -> bool:
    """``value`` must be ``True`` or ``False``."""
    require(name, value, isinstance(value, (bool, np.bool_)), "True or False")
    return bool(value)


def _number(name: str, value) -> float:
    """Return a real number (not a string, not a bool) as a float."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise InputError(message(name, value, "a number"))
    try:
        return float(value)
    except OverflowError:  # an int beyond the float range
        raise InputError(message(name, value, "a finite number")) from None


def check_column(name: str, values, rule: str, reasons: np.ndarray) -> np.ndarray:
    """Vectorized check of one input column.

    Parameters
    ----------
    name : column name, used in the reasons
    values : array-like of the column (numbers; anything else is a bad row)
    rule : a key of :data:`RULES`
    reasons : object array of the batch, ``None`` for a good row so far; the
        first reason of a bad row is written here (later checks keep it)

    Returns
    -------
    The column as float64, with NaN where the row is bad.
    """
    raw = np.asarray(values)
    test, allowed = RULES[rule]
    if raw.ndim == 1 and raw.shape[0] > 1 and raw.strides[0] == 0 and raw.dtype.kind in "fiu":
        # one value in every row (a view of one element, e.g. a default): checked once
        one = raw[:1].astype(np.float64)
        with np.errstate(invalid="ignore"):
            if bool(test(one)[0]):
                return np.full(raw.shape[0], one[0])
    if raw.dtype.kind in "fiu":
        x = raw.astype(np.float64)
    else:  # object, strings, bools: element by element (rare)
        x = np.array([_float_or_nan(v) for v in raw.ravel()], dtype=np.float64)
    with np.errstate(invalid="ignore"):
        bad = ~test(x)
    if raw.dtype.kind == "b":
        bad[:] = True
    for i in unexplained(bad, reasons):
        reasons[i] = message(name, raw.ravel()[i].item() if hasattr(raw.ravel()[i], "item")
                             else raw.ravel()[i], allowed if raw.dtype.kind != "b" else "a number")
    if bad.any():  # (no bad row, the usual case: no second pass over the column)
        x[bad] = np.nan
    return x


def _float_or_nan(v) -> float:
    if isinstance(v, (bool, np.bool_)) or not isinstance(v, numbers.Real):
        return math.nan
    try:
        return float(v)
    except OverflowError:
        return math.nan
