"""Stored values of the scipy continuum oracle for the continuum kernel's default tests.

The oracle, :func:`vimpact.reference.continuum_scipy.maxwell_continuum_reference`
(``solve_ivp`` and ``brentq``, no code shared with the kernel), takes 0.3-0.4 s of
CPU a scene; its values for the fixed scenes below are deterministic, so they are
computed once by the oracle and stored in ``data/continuum_maxwell.json`` with the
scene, the oracle's settings and the command that writes the file again::

    python -m tests.oracles.continuum_data

Nothing in the file comes from the kernel under test. The default tests compare
the kernel with the stored values; a ``slow`` test computes every stored value
again with the oracle and checks that it is the stored one (so the file cannot go
stale unnoticed), and the default run checks that the stored scenes and settings
are the ones defined here.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from vimpact.model.hertz import Q1_PER_TAU
from vimpact.reference.continuum_scipy import maxwell_continuum_reference

DATA = Path(__file__).resolve().parent / "data" / "continuum_maxwell.json"
COMMAND = "python -m tests.oracles.continuum_data"

#: the stored outputs of each scene, as the oracle names them
KEYS = ("e_z", "beta_x", "t_contact", "u_max")

#: (tau0, g, tau, nu, mu_t): the explicit (DOP853) oracle's scenes
SCENES: list[tuple[float, list[float], list[float], float, float]] = [
    (0.2, [], [], 0.5, 3.5),  # Kelvin-Voigt
    (0.0, [1.0], [0.4], 0.3, 1.0 + 1.0 / 0.4),  # standard solid
    (0.1, [2.0, 0.5, 0.3], [0.05, 0.5, 3.0], 0.3, 3.5),  # 3-arm Prony with dashpot
]

#: (tau0, g, tau, nu, mu_t): the stiff scenes, for the implicit (LSODA) oracle
STIFF_SCENES: list[tuple[float, list[float], list[float], float, float]] = [
    # standard solid Q2 = 1e-3, Q1 = 0.01: the arm (g = 1000) is 1.5e-5 T
    (0.0, [1000.0], [1e-3 * 0.01 / Q1_PER_TAU], 0.5, 3.5),
    # glassy arm in transition (g = 516, tau = 5.5e-4 T): the costliest kind
    (0.0, [515.85], [5.4718e-4], 0.4447, 2.589),
    # a rubber-like spectrum: 7 arms from 1e-6 T to 1e3 T, glassy/relaxed 1e3, dashpot
    (0.01, [142.7] * 7, list(10.0 ** np.linspace(-6, 3, 7)), 0.3, 3.5),
]

#: The explicit oracle's rtol: 1e-12 (error <= 1.6e-12 against rtol 1e-14 on these
#: scenes: e_z, beta_x, t_contact, u_max), 1e-10 on the scene with a dashpot and arms
#: (error 1.6e-11 there), both 60x below the tolerance the kernel is held to.
def oracle_rtol(tau0: float, g: list[float]) -> float:
    """The explicit oracle's rtol for a scene (see the comment above)."""
    return 1e-10 if (tau0 > 0.0 and len(g) > 0) else 1e-12


#: The implicit oracle's rtol on STIFF_SCENES: its error there, against LSODA at rtol
#: 1e-13, is at most 3.0e-8 on e_z, beta_x, t_contact (1.7e-8, 3.0e-8, 5.9e-9 for the
#: three scenes; 3.4e-9 at rtol 1e-10, 7e-11 at 1e-12), 33x below the tolerance 1e-6
#: the kernel is held to, at 40 % of the cost of rtol 1e-12.
STIFF_ORACLE_RTOL = 1e-9


def kappa_of(nu: float) -> float:
    """``kappa = 2 (1 - nu) / (2 - nu)`` of docs/physics.md."""
    return 2.0 * (1.0 - nu) / (2.0 - nu)


def cases() -> list[dict[str, Any]]:
    """Every stored case without its values: name, scene and the oracle's settings."""
    out = []
    for i, (tau0, g, tau, nu, mu_t) in enumerate(SCENES):
        out.append(dict(name=f"scene{i}", tau0=tau0, g=g, tau=tau, nu=nu, mu_t=mu_t,
                        method="DOP853", rtol=oracle_rtol(tau0, g)))
    for i, (tau0, g, tau, nu, mu_t) in enumerate(STIFF_SCENES):
        out.append(dict(name=f"stiff{i}", tau0=tau0, g=g, tau=tau, nu=nu, mu_t=mu_t,
                        method="LSODA", rtol=STIFF_ORACLE_RTOL))
    return out


def oracle_values(case: dict[str, Any]) -> dict[str, float]:
    """The oracle's outputs for one case (0.3-0.4 s of CPU)."""
    ref = maxwell_continuum_reference(case["tau0"], case["g"], case["tau"],
                                      kappa_of(case["nu"]), case["mu_t"],
                                      rtol=case["rtol"], method=case["method"])
    return {key: float(getattr(ref, key)) for key in KEYS}


def stored() -> dict[str, dict[str, Any]]:
    """The stored cases (scene, settings and ``values``) by name."""
    data = json.loads(DATA.read_text())
    return {case["name"]: case for case in data["cases"]}


def write() -> None:
    """Compute every case with the oracle and write the file."""
    data = {
        "about": "values of vimpact.reference.continuum_scipy.maxwell_continuum_reference "
                 "(scipy), not of the kernel; kernel units (u / d, t / T, v / v_z0)",
        "command": COMMAND,
        "cases": [dict(case, values=oracle_values(case)) for case in cases()],
    }
    DATA.parent.mkdir(exist_ok=True)
    DATA.write_text(json.dumps(data, indent=1) + "\n")


if __name__ == "__main__":
    write()
