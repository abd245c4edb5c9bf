"""The package asks OpenMP's threads to sleep between launches, unless the user decided."""

import os
import subprocess
import sys


def _policy_after_import(env_value):
    env = dict(os.environ)
    env.pop("OMP_WAIT_POLICY", None)
    if env_value is not None:
        env["OMP_WAIT_POLICY"] = env_value
    code = "import os, vimpact; print(os.environ.get('OMP_WAIT_POLICY'))"
    return subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                          text=True, check=True).stdout.strip()


def test_passive_wait_policy_by_default():
    assert _policy_after_import(None) == "PASSIVE"


def test_user_wait_policy_kept():
    assert _policy_after_import("active") == "active"
