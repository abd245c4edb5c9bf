"""How numba's worker threads wait between parallel launches (set before numba loads them).

Numba takes the first threading layer it finds of TBB, OpenMP and its own
workqueue. OpenMP's threads spin after a parallel region by default: on a
machine with more runnable processes than cores a short launch (64 rows of
a sweep chunk, some 0.3 ms of work) then waits for threads that spin on
cores somebody else needs, measured up to 100x the one-thread time
(``vimpact bench threads``). ``OMP_WAIT_POLICY=PASSIVE`` makes them sleep
instead, which costs nothing measurable on a quiet machine. TBB and the
workqueue layer do not spin; the workqueue layer is not taken by default
because it does not allow launches from several threads at once (a Dask
worker's threads).

OpenMP reads its environment when numba loads the layer, at the first
parallel launch, so :func:`configure` works as long as it runs before that;
the package calls it on import (``vimpact/__init__.py``). A value the user
set (``OMP_WAIT_POLICY``, ``NUMBA_THREADING_LAYER``) is kept.
"""

from __future__ import annotations

import os

#: environment defaults for numba's threads (the user's own values win)
THREAD_ENVIRONMENT = {"OMP_WAIT_POLICY": "PASSIVE"}


def configure(environ=os.environ) -> None:
    """Set :data:`THREAD_ENVIRONMENT` in ``environ`` where it is not set yet."""
    for key, value in THREAD_ENVIRONMENT.items():
        environ.setdefault(key, value)
