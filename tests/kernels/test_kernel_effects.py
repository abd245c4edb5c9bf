"""Which compiled element kernel runs the rows of a :class:`KernelSpec`, and the
effects read at run time.

Friction and full stick share one kernel where the tangential problem has
incremental memory (the row's ``mu`` decides, ``inf`` sticks); the kernel body
can read the dashpot from the row too (``tau0 > 0``; the specialization
benchmark times it). A flag must take the same arithmetic path as a kernel
compiled for that one value: the kernels compiled with the effect fixed are the
oracle, compared bit for bit on random rows (trajectories included). Those
extra compiles are what the shared kernels save, so that comparison is a slow
test.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from vimpact.kernels.elements import (
    EULER,
    N_OUT,
    N_REC,
    RUNTIME,
    SYMPLECTIC_EULER,
    VERLET,
    KernelSpec,
    element_impact,
    impact_kernel,
    kernel_effects,
)
from vimpact.kernels.layout import OUT_T_CONTACT


def test_shared_kernels():
    for integrator in (EULER, SYMPLECTIC_EULER, VERLET):
        for arms in (False, True):
            for dashpot in (False, True):
                stick = KernelSpec(integrator, True, 0, arms, dashpot, False)
                fric = KernelSpec(integrator, True, 0, arms, dashpot, True)
                assert kernel_effects(stick) == kernel_effects(fric)
                assert kernel_effects(fric) == (integrator, True, 0, arms, dashpot, RUNTIME)
                # seed memory: no friction code at all; normal only: no tangential code
                seed = KernelSpec(integrator, True, 1, arms, dashpot, False)
                assert kernel_effects(seed) == (integrator, True, 1, arms, dashpot, 0)
                normal = KernelSpec(integrator, False, 1, arms, dashpot, False)
                assert kernel_effects(normal) == (integrator, False, 0, arms, dashpot, 0)
    assert element_impact(KernelSpec(VERLET, True, 0, False, True, False)) is element_impact(
        KernelSpec(VERLET, True, 0, False, True, True))


def test_friction_with_seed_memory_is_refused():
    with pytest.raises(ValueError, match="memory=1, friction=True"):
        kernel_effects(KernelSpec(VERLET, True, 1, False, True, True))
    with pytest.raises(ValueError, match="incremental memory"):
        impact_kernel((VERLET, True, 1, False, True, RUNTIME))


def _rows(rng, n, arms, dashpot, friction):
    """Random kernel-unit rows: (tau0, g, tau, kappa, mu_t, mu, h, n_elem, dxi, max_steps)."""
    rows = []
    for _ in range(n):
        nu = rng.uniform(0.0, 0.5)
        n_arms = rng.integers(1, 3) if arms else 0
        g = rng.uniform(0.3, 3.0, n_arms)
        tau = 10.0 ** rng.uniform(-2.0, 1.0, n_arms)
        tau0 = 10.0 ** rng.uniform(-3.0, 0.0) if dashpot else 0.0
        # friction rows: gross slip, stick-slip and near stick; stick rows: mu = inf
        mu = 10.0 ** rng.uniform(-1.5, 1.5) if friction else math.inf
        h = 2.9432751843 / rng.uniform(200.0, 500.0)
        dxi = 1.0 / rng.uniform(30.0, 60.0)
        rows.append((tau0, g, tau, 2.0 * (1.0 - nu) / (2.0 - nu), 1.0 + 1.0 / rng.uniform(0.2, 2.0),
                     mu, h, int(math.ceil(1.3 / dxi)), dxi, int(60.0 / h)))
    return rows


def _run(kernel, row):
    out = np.zeros(N_OUT)
    rec = np.zeros((30, N_REC))
    kernel(*row, rec, np.int64(11), out)
    return out, rec


def test_stick_rows_of_the_shared_kernel_are_the_stick_kernel_bit_for_bit():
    """The default run's share of the slow comparison below: one kernel compiled without
    friction (elastic, Verlet: the cheapest to compile) against the package's shared
    kernel on stick rows (``mu = inf``), trajectories included."""
    rng = np.random.default_rng(7)
    shared = element_impact(KernelSpec(VERLET, True, 0, False, False, False))
    special = impact_kernel((VERLET, True, 0, False, 0, 0))
    assert shared is not special
    for row in _rows(rng, 4, False, False, False):
        out_s, rec_s = _run(special, row)
        out_r, rec_r = _run(shared, row)
        assert out_s[OUT_T_CONTACT] > 0.0  # an impact ran, not an untouched row
        np.testing.assert_array_equal(out_r, out_s)
        np.testing.assert_array_equal(rec_r, rec_s)


@pytest.mark.slow
@pytest.mark.parametrize("integrator", [VERLET, SYMPLECTIC_EULER, EULER])
@pytest.mark.parametrize("arms", [False, True])
@pytest.mark.parametrize("tangential,memory", [(True, 0), (True, 1), (False, 0)])
def test_runtime_flags_are_the_specialized_kernel_bit_for_bit(integrator, arms, tangential,
                                                              memory):
    rng = np.random.default_rng([integrator, arms, tangential, memory])
    incremental = tangential and memory == 0
    frictions = (0, 1) if incremental else (0,)
    # the dashpot read from the row (both run-time flags; the benchmark's kernel)
    both = impact_kernel((integrator, tangential, memory, arms, RUNTIME,
                          RUNTIME if incremental else 0))
    for dashpot in (0, 1):
        # the package's kernel: friction from the row where the memory is incremental
        shared = element_impact(KernelSpec(integrator, tangential, memory, arms, bool(dashpot)))
        for friction in frictions:
            special = impact_kernel((integrator, tangential, memory, arms, dashpot, friction))
            for row in _rows(rng, 3, arms, dashpot, friction):
                out_s, rec_s = _run(special, row)
                for kernel in (shared, both):
                    out_r, rec_r = _run(kernel, row)
                    np.testing.assert_array_equal(out_r, out_s)
                    np.testing.assert_array_equal(rec_r, rec_s)
