"""One place for every numba option used by the package.

All kernels are compiled through :func:`jit`, so that caching and the error
model are the same everywhere: ``cache=True`` (a fresh clone compiles once,
later runs load from ``__pycache__``) and ``error_model="numpy"`` (division by
zero gives inf/NaN like NumPy instead of raising, which the kernels check
explicitly). No ``fastmath``: the kernels rely on NaN checks. ``nogil=True``:
a kernel touches no Python object, so a call releases the GIL and other Python
threads run beside it (a sweep encodes and hashes the rows already computed
while the kernel computes the next ones). numba's cache does not key on this
option: a cache compiled before it was set keeps holding the GIL until the
kernel's source changes or its ``__pycache__`` entries are removed. How numba's
threads wait between launches is set in :mod:`vimpact.kernels.threads`
before numba starts them.
"""

from __future__ import annotations

from typing import Any, Literal

import numba


def jit(parallel: bool = False, inline: Literal["never", "always"] = "never",
        internal: bool = False, nrt: bool = True, rewrites: bool = True):
    """Return the decorator that compiles one of the package's numba kernels.

    ``internal``: a function only other kernels call, never Python. numba then
    compiles no Python entry point for it (no argument unboxing, no C-callable
    wrapper), which every caller's module would otherwise carry along.

    ``nrt=False``: compiled without numba's reference counting, for a function
    that allocates nothing and returns no array (it only reads and writes arrays
    its caller holds): no increment and decrement around every array argument and
    view, less code to lower and optimize, and none of their atomic operations
    at run time. A function that allocates must keep it on.

    ``rewrites=False``: without numba's rewrite and dead-branch passes, for
    scalar code that has no array expressions and no branch on a global
    constant (the element kernels need dead-branch pruning: their effects are
    globals).
    """
    # (numba's type stubs do not list the wrapper options)
    wrappers: dict[str, Any] = {"no_cpython_wrapper": internal, "no_cfunc_wrapper": internal}
    if not nrt:
        wrappers["_nrt"] = False
    if not rewrites:
        wrappers["no_rewrites"] = True
    return numba.njit(cache=True, error_model="numpy", parallel=parallel, inline=inline,
                      nogil=True, **wrappers)
