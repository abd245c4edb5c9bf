"""Element kernels loaded from numba's on-disk cache run their own specialization.

numba names a function's machine-code symbol after its qualified name and a
counter that restarts in every process. When every specialization of the
element factory shared one qualified name, a Verlet batch compiled in one
process and loaded from the cache in another, where the symplectic Euler impact
had just been compiled under the same count, ran the Euler impact's code: e_z
changed by 1.3e-4 ... 8e-4 with status ``ok`` (measured on the code before the
fix). The test makes that collision happen on purpose and requires the cached
batch to give the results it gave when it was compiled (slow: two processes that
compile in a fresh cache, about 7 s). The default run checks what prevents it:
every kernel of a different effects key has a qualified name of its own.
"""

from __future__ import annotations

import itertools
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from vimpact.kernels.elements import (
    EULER,
    SYMPLECTIC_EULER,
    VERLET,
    KernelSpec,
    batch_kernel,
    impact_kernel,
    kernel_effects,
)

ROOT = Path(__file__).resolve().parents[2]


def _run(cache: Path, *args: str) -> dict:
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache)}
    done = subprocess.run([sys.executable, "-m", "tests.kernels.cache_symbols_run", *args],
                          cwd=ROOT, env=env, capture_output=True, text=True, timeout=900)
    assert done.returncode == 0, done.stderr[-2000:]
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_every_effects_key_names_its_kernels_apart():
    """numba keys symbols and cache entries on the qualified name: one per effects key.

    All keys routing can give (every :class:`KernelSpec` numba is asked to
    compile); the dispatchers are made, nothing is compiled.
    """
    keys = set()
    for integrator, tangential, memory, arms, dashpot, friction in itertools.product(
            (EULER, SYMPLECTIC_EULER, VERLET), (False, True), (0, 1), (False, True),
            (False, True), (False, True)):
        spec = KernelSpec(integrator, tangential, memory, arms, dashpot, friction)
        if friction and tangential and memory != 0:
            continue  # refused by kernel_effects (friction needs incremental memory)
        keys.add(kernel_effects(spec))
    impacts = {impact_kernel(k).py_func.__qualname__ for k in keys}
    batches = {batch_kernel(k).py_func.__qualname__ for k in keys}
    assert len(impacts) == len(batches) == len(keys) > 20
    assert not impacts & batches


@pytest.mark.slow
def test_cached_batch_runs_its_own_impact_when_the_counter_collides(tmp_path):
    compiled = _run(tmp_path, "compile")
    assert all(path == "elements[verlet,dashpot]" for path in compiled["path"])
    (counter,) = set(compiled["counters"])
    loaded = _run(tmp_path, "load", str(counter))
    # the Euler impact was compiled under the Verlet impact's count in the second process
    assert counter in loaded["counters"]
    assert loaded["e_z"] == compiled["e_z"]
    assert loaded["status"] == compiled["status"]
