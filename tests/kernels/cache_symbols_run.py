"""Run in a subprocess by ``test_cache_symbols.py`` (a fresh numba cache per test).

``python -m tests.kernels.cache_symbols_run compile`` runs a Verlet element batch
(compiled now, written to the cache) and prints its results and the numba
function counter its serial impact was compiled with. ``... load UID`` first
compiles the symplectic Euler impact with that same counter (as another process
can), then runs the Verlet batch again, now loaded from the cache.
"""

from __future__ import annotations

import gc
import itertools
import json
import sys

from numba.core import bytecode

import vimpact
from vimpact import Numerics, Scene

SCENES = [Scene.from_dimensionless(q1, 0.3, tangential="none") for q1 in (0.1, 1.0, 10.0)]
NUMERICS = dict(continuum=False, steps=300, elements=60)


def _impact_counters() -> list[int]:
    """Return the function counters of the element impacts compiled in this process."""
    found = []
    for obj in gc.get_objects():
        if type(obj).__name__ == "CPUDispatcher" and "element_impact" in obj.py_func.__qualname__:
            found += [int(c.fndesc.unique_name.rsplit("$", 1)[1]) for c in obj.overloads.values()]
    return found


def main(argv: list[str]) -> None:
    if argv[0] == "load":
        bytecode.FunctionIdentity._unique_ids = itertools.count(int(argv[1]))
        vimpact.simulate(SCENES[0], Numerics(integrator="symplectic_euler", **NUMERICS))
    batch = vimpact.simulate_batch(SCENES, Numerics(integrator="verlet", **NUMERICS))
    print(json.dumps({"e_z": batch["e_z"].tolist(), "status": batch["status"].tolist(),
                      "path": batch["path"].tolist(), "counters": _impact_counters()}))


if __name__ == "__main__":
    main(sys.argv[1:])
