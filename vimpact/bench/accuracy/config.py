"""The accuracy benchmark's configurations.

Tolerances, integrators, scenes and the (steps, elements) ladders of each integrator.
"""

from __future__ import annotations

import math
from typing import Any

TOLERANCES = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7)
#: every integrator the benchmark knows (a configuration's ``integrators`` picks from them)
INTEGRATORS = ("verlet", "symplectic_euler", "euler")
THESIS_TABLE_4_1 = {500: 1.1254, 1000: 0.5608, 5000: 0.1119, 10000: 0.0559}  # percent
THREADS = 2


def _pow2(start: int, stop: int) -> list[int]:
    out = [start]
    while out[-1] * 2 <= stop:
        out.append(out[-1] * 2)
    return out


def _sqrt2(start: int, stop: int) -> list[int]:
    """``start * 2^(k/2)`` up to ``stop``, rounded."""
    n = int(round(2 * math.log2(stop / start)))
    return [int(round(start * 2 ** (k / 2))) for k in range(n + 1)]


#: integrators, scenes, ladders, continuum tolerances, timing.
#: A ladder is the base grid ``steps x elements`` (factor 2, products capped)
#: and optionally a refinement: the factor-sqrt(2) grid in a band of
#: ``steps / elements`` where the front lies.
CONFIGS: dict[str, dict[str, Any]] = {
    "full": dict(
        integrators=INTEGRATORS,
        q1=[1e-3, 1e-2, 1e-1, 1.0, 10.0],
        kv_nu=[0.0, 0.5], sls_q2=[0.1, 10.0], sls_nu=0.5,
        ladders={
            "verlet": dict(steps=_pow2(125, 8000), elements=_pow2(25, 1600), cap=8000 * 1600,
                           refine=(_sqrt2(125, 8000), _sqrt2(25, 1600), (2.5, 40.0))),
            "symplectic_euler": dict(steps=_pow2(125, 32000), elements=_pow2(25, 1600),
                                     cap=16000 * 1600),
            "euler": dict(steps=_pow2(500, 128000), elements=_pow2(25, 1600), cap=32000 * 1600),
        },
        rtols=[1e-4, 1e-6, 1e-8, 1e-10, 1e-12],
        table_steps=list(THESIS_TABLE_4_1), for_tolerance=[1e-3, 1e-4, 1e-5, 1e-6],
        for_tolerance_scan=(1e-3, 1e-6, 19),
        model_checks=[1e-3, 1e-4, 1e-5],
        repeats=3, target_batch_seconds=0.2, max_copies=256,
    ),
    "quick": dict(
        # Verlet only and Kelvin-Voigt only: the explicit and semi-implicit Euler ladders
        # run the oblique scenes through parallel batch kernels that nothing else in the
        # default test run compiles, a standard solid would add two more element kernels
        # (about 50 s on a fresh clone); run(quick=True, integrators=INTEGRATORS) adds
        # the Euler ladders
        integrators=("verlet",),
        scenes=[(0.1, 0.5, None), (1.0, 0.0, None), (0.3, 0.25, None)],
        ladders={
            "verlet": dict(steps=[100, 200], elements=[20, 40], cap=200 * 40,
                           refine=([141], [28], (2.5, 40.0))),
            "symplectic_euler": dict(steps=[100, 200], elements=[20], cap=200 * 20),
            "euler": dict(steps=[200, 400], elements=[20], cap=400 * 20),
        },
        rtols=[1e-4, 1e-8],
        table_steps=[500, 1000], for_tolerance=[1e-3], for_tolerance_scan=(1e-3, 1e-4, 3),
        model_checks=[1e-3],
        repeats=1, target_batch_seconds=0.0, max_copies=1,
    ),
}



def _ladder(cfg, name) -> list[tuple[int, int, str]]:
    """Return (steps, elements, "base" or "refined") of one integrator, by steps."""
    lad = cfg["ladders"][name]
    base = {(s, e) for s in lad["steps"] for e in lad["elements"] if s * e <= lad["cap"]}
    out = {k: "base" for k in base}
    if "refine" in lad:
        steps, elements, (lo, hi) = lad["refine"]
        for s in steps:
            for e in elements:
                if lo <= s / e <= hi and s * e <= lad["cap"] and (s, e) not in out:
                    out[(s, e)] = "refined"
    return sorted((s, e, g) for (s, e), g in out.items())

