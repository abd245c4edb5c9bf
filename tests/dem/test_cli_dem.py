"""`vimpact dem`: files for every code, bad input in one line with exit 2."""

from pathlib import Path

import pytest

from vimpact.cli.main import main
from vimpact.dem.export import CODES

TOML = """
[speeds]
min = 0.1
max = 1.0
n = 4
[types.a]
density = 1200.0
radius = 0.005
[types.a.material]
model = "kelvin_voigt"
nu = 0.45
G = 3e7
eta = 600.0
[types.b]
density = 1300.0
radius = 0.004
[types.b.material]
model = "elastic"
nu = 0.45
G = 9e7
[walls.floor]
material = "rigid"
[friction]
default = 0.5
"""

#: the same set-up with one impact angle: for tests of the wiring (files, names, lines), not of
#: the fits' quality, so that the tangential searches have 4 oblique targets, not 24 (the
#: codes the round trips run are run on the round trips' set-up: tests/dem/conftest.py)
WIRING = TOML.replace("n = 4\n", "n = 4\nangles_deg = [45.0]\n", 1)

FILES = {"lammps": ["lammps_settings.in", "lammps_pair.in", "lammps_walls.in"],
         "liggghts": ["liggghts_settings.in", "liggghts.in"],
         "mercurydpm": ["mercurydpm_species.cpp"], "yade": ["yade_materials.py"],
         "mfix": ["mfix.dat"], "rebound": ["vimpact_restitution.py"]}


def check_written(code: str, out: Path, figure: bool = False) -> None:
    """The code's files and its report are written; the report names every contact and
    says what the code cannot represent, and links its figure or says that none was drawn."""
    for name in FILES[code] + [f"report_{code}.md"]:
        assert (out / name).stat().st_size > 0, name
    assert (out / f"report_{code}.png").exists() == figure
    report = (out / f"report_{code}.md").read_text()
    assert "a-b" in report and "a-floor" in report and "b-floor" in report
    assert (f"](report_{code}.png)" in report) == figure
    assert ("No figure was drawn (`--no-figure`)." in report) != figure
    table = report.split("## Notes")[0]
    if code == "rebound":
        assert "not represented" in table
    else:  # every other code gets tangential constants and a beta_x residual
        assert "not represented" not in table


@pytest.mark.parametrize("code", [c for c in CODES if c != "lammps"])
def test_writes_input_and_report_for_every_code(code, code_run):
    """With ``--no-figure``. LAMMPS (with the figure): :func:`test_writes_lammps_input_and_report`."""
    run = code_run(code)
    assert run.status == 0
    check_written(code, run.folder)
    assert "e_z residual" in run.out
    assert f"wrote {run.folder / f'report_{code}.md'}" in run.out
    assert "report_" + code + ".png" not in run.out


def test_writes_lammps_input_and_report(code_run):
    """One pair_coeff per type pair, one wall fix per particle type; the report's figure
    is a PNG of one panel column per contact, e_z above beta_x (the oblique impacts)."""
    import struct

    from vimpact.dem.report import PANEL_IN

    status, _, _, out, _ = code_run("lammps")
    assert status == 0
    check_written("lammps", out, figure=True)
    text = (out / "lammps_pair.in").read_text()
    assert [ln.split()[1:3] for ln in text.splitlines() if ln.startswith("pair_coeff")] == \
        [["1", "1"], ["1", "2"], ["2", "2"]]
    walls = (out / "lammps_walls.in").read_text().splitlines()
    assert sum(ln.startswith("fix wall_floor_") for ln in walls) == 2
    settings = (out / "lammps_settings.in").read_text()
    assert "units si" in settings and "timestep" in text
    png = (out / "report_lammps.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and png[12:16] == b"IHDR"
    width, height = struct.unpack(">II", png[16:24])
    dpi = 110  # report.figure's
    assert (width, height) == (round(5 * PANEL_IN[0] * dpi), round(2 * PANEL_IN[1] * dpi))


@pytest.mark.parametrize("edit, words", [
    (("G = 9e7", "G = -9e7"), "G"),
    (('model = "elastic"\nnu = 0.45', 'model = "kelvin_voigt"\neta = 100.0\nnu = 0.3'),
     "equal nu"),
    (("min = 0.1", "min = 2.0"), "speeds"),
    (("density = 1200.0", 'density = "heavy"'), "density"),
])
def test_bad_input_is_one_line_and_exit_2(edit, words, tmp_path, capsys):
    src = tmp_path / "bad.toml"
    src.write_text(TOML.replace(*edit, 1))
    assert main(["dem", str(src), "--for", "lammps", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and words in err


def test_missing_file_is_exit_2(tmp_path, capsys):
    assert main(["dem", str(tmp_path / "nope.toml"), "--for", "mfix"]) == 2
    assert capsys.readouterr().err.count("\n") == 1


def test_json_output_is_the_fits_and_progress_goes_to_stderr(tmp_path, capsys):
    import json

    src = tmp_path / "setup.toml"
    src.write_text(TOML)
    assert main(["dem", str(src), "--for", "liggghts", "--out", str(tmp_path), "--json",
                 "--steps-per-contact", "40", "--no-figure"]) == 0
    cap = capsys.readouterr()
    data = json.loads(cap.out)  # strict JSON: no NaN or Infinity
    assert data["code"] == "liggghts"
    assert {c["contact"] for c in data["contacts"]} == {"a-a", "a-b", "a-floor", "b-b", "b-floor"}
    assert all(c["residual_e_z"]["rms"] <= c["residual_e_z"]["max_abs"] for c in data["contacts"])
    assert "vimpact curves 5/5" in cap.err
    assert "/ 40 steps" not in (tmp_path / "liggghts.in").read_text()
    assert "40 steps per shortest contact" in (tmp_path / "liggghts.in").read_text()


def test_steps_per_contact_only_for_codes_with_a_time_step(tmp_path, capsys):
    src = tmp_path / "setup.toml"
    src.write_text(TOML)
    assert main(["dem", str(src), "--for", "rebound", "--steps-per-contact", "50"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--steps-per-contact" in err


def test_json_gives_the_tangential_residual_over_the_impact_angles(code_run):
    """With friction, the beta_x residual is over oblique impacts at the set-up's angles
    (the default angles when it gives none), and the JSON says so."""
    import json

    from vimpact.dem.fit import DEFAULT_ANGLES_DEG

    status, out, _, folder, _ = code_run("lammps")
    assert status == 0
    data = json.loads(out)
    for c in data["contacts"]:
        basis = c["beta_x_fitted_to"]
        assert basis["friction"] == 0.5
        assert basis["angles_deg"] == list(DEFAULT_ANGLES_DEG)
        assert 0.0 < c["residual_beta_x"]["rms"] <= c["residual_beta_x"]["max_abs"] < 0.1
    report = (folder / "report_lammps.md").read_text()
    assert "impact angles 5, 15, 30, 45, 60, 75 deg" in report


def test_the_figure_has_a_beta_row_when_any_contact_represents_beta():
    """A contact fitted over its oblique impacts only (no full-stick curve: MercuryDPM's
    with friction) still gets the beta_x row; none represented: no row."""
    from types import SimpleNamespace as Fit

    from vimpact.dem.report import beta_row

    oblique_only = Fit(res_beta_x="residual", beta_x=None, beta_oblique=[0.1])
    absent = Fit(res_beta_x=None, beta_x=None, beta_oblique=None)
    assert beta_row([oblique_only, oblique_only])
    assert beta_row([absent, oblique_only])
    assert not beta_row([absent, absent])
