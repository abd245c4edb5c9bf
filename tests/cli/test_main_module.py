"""``python -m vimpact`` is the ``vimpact`` command: same exit code and one-line error.

Each module runs once as a real process (both ``__main__`` files are ``sys.exit(main())``),
one with an exit code that ``main`` returns (2: a bad value), one with the exit that argparse
raises inside ``main`` (0: ``--version``); ``main`` itself is tested in-process.
"""

import subprocess
import sys

import pytest

import vimpact
from vimpact.cli.main import main


@pytest.mark.parametrize("module, argv, code, stream, text", [
    pytest.param("vimpact", ["simulate", "--Q1", "1", "--nu", "2"], 2, "stderr", "--nu",
                 id="vimpact-bad-value"),
    pytest.param("vimpact.cli", ["--version"], 0, "stdout", vimpact.__version__,
                 id="vimpact.cli-version"),
])
def test_python_m_runs_the_command_line(module, argv, code, stream, text):
    proc = subprocess.run([sys.executable, "-m", module, *argv], capture_output=True, text=True)
    assert proc.returncode == code, (proc.returncode, proc.stderr)
    assert text in getattr(proc, stream)
    if code:
        assert proc.stderr.count("\n") == 1 and proc.stdout == "", proc.stderr


def test_version_exits_0_and_a_bad_value_2_in_process(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0 and capsys.readouterr().out == f"vimpact {vimpact.__version__}\n"
    assert main(["simulate", "--Q1", "1", "--nu", "2"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--nu" in err
