"""The standard-solid band table's distance to the Kelvin-Voigt limit, measured.

The band table (``sweeps/standard_solid_band.toml``) continues the standard-solid
table down to ``Q2 = 1e-5``; below, the lookup answers with the Kelvin-Voigt table
(:mod:`vimpact.lookup.band`). That is right within the distance between the
standard solid at the band's lower end and its Kelvin-Voigt limit, which shrinks
linearly in ``Q2`` further down (docs/physics.md#standard-solid-limits). This
module measures that distance by direct simulation of both at random held-out
``(Q1, nu)`` and stores it in the band table (``vimpact.kelvin_voigt_limit``);
the lookup adds it to the Kelvin-Voigt table's error bound.

Run: ``python -m vimpact.tablebuild.band sweeps/tables/standard_solid_band.parquet``.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

from vimpact.lookup.table import RestitutionTable
from vimpact.model.validation import InputError
from vimpact.tablebuild.verify import BOUND_FACTOR, numerics_of, simulate_dimensionless

__all__ = ["kelvin_voigt_limit", "write_kelvin_voigt_limit"]


def kelvin_voigt_limit(table: RestitutionTable, n: int = 200, seed: int = 0,
                       simulate=None) -> dict:
    """Measure the distance of the standard solid to its Kelvin-Voigt limit at the table's lowest ``Q2``.

    Parameters
    ----------
    table : RestitutionTable
        An adaptive standard-solid table (the band).
    n : int
        Random held-out points, ``Q1`` log-uniform over the table's range and ``nu``
        uniform in the range of its nodes (each two direct simulations).
    seed : int
        Seed of the points.
    simulate : callable, optional
        The direct simulation (default
        :func:`vimpact.tablebuild.verify.simulate_dimensionless`).

    Returns
    -------
    dict
        ``Q2`` (the lower end, dimensionless), ``points``, ``seed``, ``max`` (output ->
        largest ``|standard solid - Kelvin-Voigt|``) and ``gap`` (output ->
        ``BOUND_FACTOR`` times it); JSON-serializable.

    Raises
    ------
    InputError
        For a table that is not an adaptive standard-solid one, or a failed impact.
    """
    if table.model != "standard_solid" or not table.is_adaptive:
        raise InputError(f"table = {str(table.path)!r} is not allowed: the Kelvin-Voigt "
                         "limit is measured on an adaptive standard-solid table")
    if not (isinstance(n, int) and n >= 1):
        raise InputError(f"n = {n!r} is not allowed: must be an integer >= 1")
    grid = table.adaptive_grid()
    (q1_lo, q1_hi), (q2_lo, _) = (grid.bounds[grid.axes.index(a)] for a in ("Q1", "Q2"))
    rng = np.random.default_rng(seed)
    Q1 = np.exp(rng.uniform(np.log(q1_lo), np.log(q1_hi), n))
    nu = rng.uniform(grid.tensor_nodes[0], grid.tensor_nodes[-1], n)
    sim = simulate or simulate_dimensionless
    numerics = numerics_of(table)
    sls = sim("standard_solid", Q1, nu, np.full(n, q2_lo), numerics=numerics)
    kv = sim("kelvin_voigt", Q1, nu, numerics=numerics)
    if not ((sls["status"] == "ok").all() and (kv["status"] == "ok").all()):
        raise InputError("the Kelvin-Voigt limit could not be measured: an impact failed")
    largest = {k: float(np.max(np.abs(sls[k].to_numpy(float) - kv[k].to_numpy(float))))
               for k in ("e_z", "beta_x", "e_x")}
    return {"Q2": float(q2_lo), "points": n, "seed": seed, "max": largest,
            "gap": {k: BOUND_FACTOR * v for k, v in largest.items()}}


def write_kelvin_voigt_limit(path, n: int = 200, seed: int = 0) -> dict:
    """Measure :func:`kelvin_voigt_limit` of the table at ``path`` and store it there.

    Returns the measurement (also metadata ``vimpact.kelvin_voigt_limit``).
    """
    table = RestitutionTable.open(path)
    result = kelvin_voigt_limit(table, n=n, seed=seed)
    table.metadata["vimpact.kelvin_voigt_limit"] = json.dumps(result)
    table.save(Path(path))
    return result


if __name__ == "__main__":  # pragma: no cover - the shipped table's measurement
    print(json.dumps(write_kelvin_voigt_limit(sys.argv[1]), indent=1))
