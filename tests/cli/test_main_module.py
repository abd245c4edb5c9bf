"""``python -m vimpact`` is the ``vimpact`` command: same exit code and one-line error.

Both ``__main__`` files and the console script are ``sys.exit(run())``, ``run`` being
``main`` with the command's garbage-collector thresholds. Each module runs as a real process with an
exit code that ``main`` returns (2: a bad value; without ``sys.exit`` the process would end
with 0): ``python -m vimpact.cli`` here, ``python -m vimpact`` in
tests/faults/test_catalogue_cli.py::test_installed_entry_point, which also runs the exit
that argparse raises inside ``main`` in a real process (2: an empty value; ``--version``'s
0 is the same exit, checked in-process here); ``main`` itself is tested in-process.
"""

import subprocess
import sys

import pytest

import vimpact
from vimpact.cli.main import main


def test_python_m_runs_the_command_line():
    proc = subprocess.run([sys.executable, "-m", "vimpact.cli", "simulate", "--Q1", "1",
                           "--nu", "2"], capture_output=True, text=True)
    assert proc.returncode == 2, (proc.returncode, proc.stderr)
    assert "--nu" in proc.stderr
    assert proc.stderr.count("\n") == 1 and proc.stdout == "", proc.stderr


def test_version_exits_0_and_a_bad_value_2_in_process(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0 and capsys.readouterr().out == f"vimpact {vimpact.__version__}\n"
    assert main(["simulate", "--Q1", "1", "--nu", "2"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--nu" in err


def test_the_command_sets_its_collector_and_main_leaves_the_callers(monkeypatch):
    """``run`` (the command's process) sets GC_THRESHOLDS, ``main`` (called from Python) does not;
    the console script and both ``__main__`` files go through ``run``."""
    import gc
    import importlib
    import tomllib
    from pathlib import Path

    cli = importlib.import_module("vimpact.cli.main")

    root = Path(__file__).resolve().parents[2]
    scripts = tomllib.loads((root / "pyproject.toml").read_text())["project"]["scripts"]
    assert scripts["vimpact"] == "vimpact.cli.main:run"
    for path in ("vimpact/__main__.py", "vimpact/cli/__main__.py"):
        assert "sys.exit(run())" in (root / path).read_text()
    before = gc.get_threshold()
    try:
        gc.set_threshold(700, 10, 10)
        assert main(["simulate", "--Q1", "1", "--nu", "2"]) == 2
        assert gc.get_threshold() == (700, 10, 10)
        monkeypatch.setattr(cli, "main", lambda: 7)
        assert cli.run() == 7
        assert gc.get_threshold() == cli.GC_THRESHOLDS != (700, 10, 10)
    finally:
        gc.set_threshold(*before)
