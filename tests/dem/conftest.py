"""Runs shared by the DEM tests: the exports are the slow part (the fits, the figure), so
one run of ``vimpact dem`` feeds every check of what it wrote."""

import contextlib
import io
from pathlib import Path
from typing import NamedTuple

import pytest

from vimpact.cli.main import main


def cli(argv: list[str]) -> tuple[int, str, str]:
    """``vimpact`` in this process: (exit code, stdout, stderr)."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(argv)
    return code, out.getvalue(), err.getvalue()


class Run(NamedTuple):
    """One ``vimpact dem`` run: exit code, stdout, stderr, output folder and the
    :class:`vimpact.dem.export.Export` the command wrote its files and summary from."""

    status: int
    out: str
    err: str
    folder: Path
    export: object


def dem_run(folder: Path, toml: str, argv: list[str]) -> Run:
    """Write ``toml`` to ``folder/setup.toml`` and run ``vimpact dem`` on it with ``argv``
    (output in ``folder/out``), keeping the export it made."""
    from vimpact.dem import export as export_module

    src = folder / "setup.toml"
    src.write_text(toml)
    made = []

    def keep(*args, **kwargs):
        made.append(run_export(*args, **kwargs))
        return made[-1]

    run_export = export_module.export
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(export_module, "export", keep)
        status, out, err = cli(["dem", str(src), "--out", str(folder / "out"), *argv])
    return Run(status, out, err, folder / "out", made[-1] if made else None)


#: the codes the round trips run for real: their ``vimpact dem`` run is on the round trips'
#: set-up (tests/dem/test_round_trip.py), and the round trips run what that run wrote
ROUND_TRIP_CODES = ("lammps", "yade", "liggghts", "rebound")


@pytest.fixture(scope="session")
def code_run(tmp_path_factory):
    """``vimpact dem --for CODE``, run once per code and session: ``code_run(code) -> Run``.

    The codes of :data:`ROUND_TRIP_CODES` on the round trips' set-up (friction, the
    default impact angles), LAMMPS with ``--json`` and the report's figure; the others on
    ``WIRING`` (tests/dem/test_cli_dem.py: one impact angle, a cheap tangential search).
    Every run but LAMMPS' with ``--no-figure``. tests/dem/test_cli_dem.py checks the runs
    and their files; tests/dem/test_exported_files.py and the round trips read the same
    files and fits (the exports are the slow part)."""
    runs: dict[str, Run] = {}

    def run(code: str) -> Run:
        if code not in runs:
            from tests.dem.test_cli_dem import WIRING
            from tests.dem.test_round_trip import TOML

            toml = TOML if code in ROUND_TRIP_CODES else WIRING
            argv = ["--for", code] + (["--json"] if code == "lammps" else ["--no-figure"])
            runs[code] = dem_run(tmp_path_factory.mktemp(f"dem_{code}"), toml, argv)
        return runs[code]
    return run
