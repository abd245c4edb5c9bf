"""Element kernels loaded from numba's on-disk cache run their own specialization.

numba names a function's machine-code symbol after its qualified name and a
counter that restarts in every process. When every specialization of the
element factory shared one qualified name, a Verlet batch compiled in one
process and loaded from the cache in another, where the symplectic Euler impact
had just been compiled under the same count, ran the Euler impact's code: e_z
changed by 1.3e-4 ... 8e-4 with status ``ok`` (measured on the code before the
fix). The test makes that collision happen on purpose and requires the cached
batch to give the results it gave when it was compiled.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def _run(cache: Path, *args: str) -> dict:
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache)}
    done = subprocess.run([sys.executable, "-m", "tests.kernels.cache_symbols_run", *args],
                          cwd=ROOT, env=env, capture_output=True, text=True, timeout=900)
    assert done.returncode == 0, done.stderr[-2000:]
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_cached_batch_runs_its_own_impact_when_the_counter_collides(tmp_path):
    compiled = _run(tmp_path, "compile")
    assert all(path == "elements[verlet,dashpot]" for path in compiled["path"])
    (counter,) = set(compiled["counters"])
    loaded = _run(tmp_path, "load", str(counter))
    # the Euler impact was compiled under the Verlet impact's count in the second process
    assert counter in loaded["counters"]
    assert loaded["e_z"] == compiled["e_z"]
    assert loaded["status"] == compiled["status"]
