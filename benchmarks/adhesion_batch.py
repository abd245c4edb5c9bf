"""Adhesive rows of a batch: the parallel batch kernel against a loop of single-scene calls.

``python -m benchmarks.adhesion_batch [--rows N] [--repeats K]`` writes
``benchmarks/results/adhesion_batch.json``: the median wall time of
:func:`vimpact.kernels.adhesion.adhesive_batch` (prange over the rows) and of a
Python loop calling :func:`vimpact.kernels.adhesion.adhesive_impact` per row, on
the same kernel inputs (elastic and Kelvin-Voigt scenes at several speeds and
adhesion numbers), measured side by side in one run, and their ratio. Both are
compiled before timing.
"""

from __future__ import annotations

import argparse
import json

import numpy as np

import vimpact as v
from vimpact.engine.adhesion import adhesion_for_number, kernel_inputs
from vimpact.engine.columns import SceneColumns
from vimpact.kernels import adhesion as kernel

from .machine import RESULTS, load_average, machine_info, median_time


def scenes(rows: int) -> list[v.Scene]:
    """Elastic and Kelvin-Voigt rubber-like contacts, speeds 0.02..0.5 m/s, lam 0.1..1."""
    out = []
    for i in range(rows):
        eta = 0.0 if i % 2 == 0 else 30.0
        mat = (v.Material.elastic(nu=0.5, G=3.75e5) if eta == 0.0
               else v.Material.kelvin_voigt(nu=0.5, G=3.75e5, eta=eta))
        s = v.Scene(mat, R=0.01, m=4e-3, v_z0=float(np.geomspace(0.02, 0.5, rows)[i]),
                    tangential="none", allow_large_contact=True)
        lam = float(np.geomspace(0.1, 1.0, rows)[(i * 7) % rows])
        out.append(v.Scene(mat, R=s.R, m=s.m, v_z0=s.v_z0, tangential="none",
                           allow_large_contact=True, adhesion=adhesion_for_number(s, lam)))
    return out


def main(argv: list[str] | None = None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--rows", type=int, default=16)
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args(argv)
    cols = SceneColumns.from_scenes(scenes(args.rows))
    a = kernel_inputs(cols, v.Numerics())
    n = len(cols)

    def batch():
        out = np.zeros((n, kernel.N_ADH_OUT))
        kernel.adhesive_batch(a["tau0"], a["g"], a["tau"], a["n_arms"], a["lam"], a["h"],
                              a["n_elem"], a["dxi"], a["max_steps"], out)
        return out

    def loop():
        out = np.zeros((n, kernel.N_ADH_OUT))
        for i in range(n):
            k = int(a["n_arms"][i])
            kernel.adhesive_impact(float(a["tau0"][i]), a["g"][i, :k].copy(),
                                   a["tau"][i, :k].copy(), float(a["lam"][i]), float(a["h"][i]),
                                   int(a["n_elem"][i]), float(a["dxi"][i]),
                                   int(a["max_steps"][i]), out[i])
        return out

    assert np.array_equal(batch(), loop())  # compiles both; the same numbers
    load_before = load_average()
    t_batch = median_time(batch, args.repeats)
    t_loop = median_time(loop, args.repeats)
    result = {"rows": n, "repeats": args.repeats, "batch_s": t_batch, "loop_s": t_loop,
              "loop_over_batch": t_loop / t_batch, "load_before": load_before,
              "load_after": load_average(), "machine": machine_info()}
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "adhesion_batch.json").write_text(json.dumps(result, indent=2) + "\n")
    print(json.dumps({k: result[k] for k in ("rows", "batch_s", "loop_s", "loop_over_batch",
                                              "load_before")}))
    return result


if __name__ == "__main__":
    main()
