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


@pytest.fixture(scope="session")
def wiring_run(tmp_path_factory):
    """``vimpact dem --no-figure`` on ``WIRING`` (tests/dem/test_cli_dem.py) for a code, run
    once per code and session: ``wiring_run(code) -> Run``.
    tests/dem/test_cli_dem.py checks the run and its files;
    tests/dem/test_exported_files.py reads the same files and fits."""
    runs: dict[str, Run] = {}

    def run(code: str) -> Run:
        if code not in runs:
            runs[code] = dem_run(tmp_path_factory.mktemp(f"wiring_{code}"), wiring(),
                                 ["--for", code, "--no-figure"])
        return runs[code]
    return run


@pytest.fixture(scope="session")
def round_trip_lammps(tmp_path_factory):
    """``vimpact dem --for lammps --json`` on the round trips' set-up (tests/dem/test_round_trip.py:
    friction, the default impact angles), with the report's figure: the LAMMPS file and
    figure checks, the JSON checks and the LAMMPS round trips all read this one run (the
    LAMMPS fit is the slowest of the codes)."""
    from tests.dem.test_round_trip import TOML

    return dem_run(tmp_path_factory.mktemp("round_trip_lammps"), TOML,
                   ["--for", "lammps", "--json"])


@pytest.fixture(scope="session")
def round_trip_targets():
    """The round trips' set-up and vimpact's curves of its contacts (normal, tangential and
    oblique), computed once for the Yade, LIGGGHTS and REBOUND exports."""
    from tests.dem.test_round_trip import TOML
    from vimpact.dem.fit import compute_targets
    from vimpact.dem.problem import problem_from_toml

    problem = problem_from_toml(TOML, "round-trip")
    return problem, {c.key: compute_targets(problem, c, tangential=True) for c in problem.contacts}


def wiring() -> str:
    """The set-up of the wiring runs (imported late: the test module imports :func:`cli`)."""
    from tests.dem.test_cli_dem import WIRING

    return WIRING
