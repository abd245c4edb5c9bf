"""Runs shared by the DEM tests: the exports are the slow part, so one run of
``vimpact dem`` feeds every check of what it wrote."""

import contextlib
import io
from pathlib import Path

import pytest

from vimpact.cli.main import main


def cli(argv: list[str]) -> tuple[int, str, str]:
    """``vimpact`` in this process: (exit code, stdout, stderr)."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(argv)
    return code, out.getvalue(), err.getvalue()


@pytest.fixture(scope="session")
def wiring_run(tmp_path_factory):
    """``vimpact dem`` on ``WIRING`` (tests/dem/test_cli_dem.py) for a code, run once per
    code and session: ``wiring_run(code) -> (exit code, stdout, output folder)``.
    tests/dem/test_cli_dem.py checks the run and its files;
    tests/dem/test_exported_files.py reads the same files."""
    runs: dict[str, tuple[int, str, Path]] = {}

    def run(code: str) -> tuple[int, str, Path]:
        if code not in runs:
            d = tmp_path_factory.mktemp(f"wiring_{code}")
            (d / "setup.toml").write_text(wiring())
            status, out, _ = cli(["dem", str(d / "setup.toml"), "--for", code, "--out",
                                  str(d / code)])
            runs[code] = (status, out, d / code)
        return runs[code]
    return run


def wiring() -> str:
    """The set-up of the wiring runs (imported late: the test module imports :func:`cli`)."""
    from tests.dem.test_cli_dem import WIRING

    return WIRING
