"""One place for every numba option used by the package.

All kernels are compiled through :func:`jit`, so that caching and the error
model are the same everywhere: ``cache=True`` (a fresh clone compiles once,
later runs load from ``__pycache__``) and ``error_model="numpy"`` (division by
zero gives inf/NaN like NumPy instead of raising, which the kernels check
explicitly). No ``fastmath``: the kernels rely on NaN checks. How numba's
threads wait between launches is set in :mod:`vimpact.kernels.threads`
before numba starts them.
"""

from __future__ import annotations

from typing import Literal

import numba


def jit(parallel: bool = False, inline: Literal["never", "always"] = "never"):
    """Return the decorator that compiles one of the package's numba kernels."""
    return numba.njit(cache=True, error_model="numpy", parallel=parallel, inline=inline)
