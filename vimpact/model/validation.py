"""Input checks with messages that name the parameter, its value and what is allowed."""

from __future__ import annotations

import math


class InputError(ValueError):
    """Bad input: the message names the parameter, its value and what is allowed.

    A ``ValueError``, so ``except ValueError`` keeps working; the command line
    prints it as one line on stderr with exit code 2.
    """


def require(name: str, value, ok: bool, allowed: str) -> None:
    """Raise ``ValueError("name = value: must be allowed")`` unless ``ok``."""
    if not ok:
        raise InputError(f"{name} = {value!r} is not allowed: must be {allowed}")


def positive(name: str, value) -> float:
    """``value`` as a float, finite and > 0."""
    x = _number(name, value)
    require(name, value, math.isfinite(x) and x > 0.0, "a finite number > 0")
    return x


def non_negative(name: str, value) -> float:
    """``value`` as a float, finite and >= 0."""
    x = _number(name, value)
    require(name, value, math.isfinite(x) and x >= 0.0, "a finite number >= 0")
    return x


def finite(name: str, value) -> float:
    """``value`` as a finite float."""
    x = _number(name, value)
    require(name, value, math.isfinite(x), "a finite number")
    return x


def poisson_ratio(name: str, value) -> float:
    """Poisson ratio in [0, 0.5]."""
    x = _number(name, value)
    require(name, value, 0.0 <= x <= 0.5, "in [0, 0.5]")
    return x


def one_of(name: str, value, choices) -> str:
    """``value`` must be one of ``choices``."""
    require(name, value, value in choices, "one of " + ", ".join(map(repr, choices)))
    return value


def _number(name: str, value) -> float:
    try:
        return float(value)
    except (TypeError, ValueError):
        raise InputError(f"{name} = {value!r} is not allowed: must be a number") from None
