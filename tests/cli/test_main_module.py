"""``python -m vimpact`` is the ``vimpact`` command: same exit code and one-line error."""

import subprocess
import sys

import pytest


@pytest.mark.parametrize("module", ["vimpact", "vimpact.cli"])
def test_python_m_runs_the_command_line(module):
    bad = subprocess.run([sys.executable, "-m", module, "simulate", "--Q1", "1", "--nu", "2"],
                         capture_output=True, text=True)
    assert bad.returncode == 2 and bad.stderr.count("\n") == 1 and "--nu" in bad.stderr
    import vimpact

    version = subprocess.run([sys.executable, "-m", module, "--version"],
                             capture_output=True, text=True)
    assert version.returncode == 0 and vimpact.__version__ in version.stdout
