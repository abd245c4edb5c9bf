"""Size classes: a radius range split into types until the residual meets a target."""

import math

import pytest

from tests.dem.test_cli_dem import TOML
from vimpact.cli.main import main
from vimpact.dem.export import export_to_residual
from vimpact.dem.problem import problem_from_toml

RANGE = TOML.replace("radius = 0.004", "radius = [0.003, 0.006]")


def test_classes_split_the_range_geometrically_and_keep_friction():
    problem = problem_from_toml(RANGE.replace("default = 0.5", 'default = 0.5\n"b-floor" = 0.7'))
    split = problem.with_size_classes(3)
    names = [t.name for t in split.types]
    assert names == ["a", "b_1", "b_2", "b_3"]
    q = 2.0 ** (1.0 / 3.0)
    for k, t in enumerate(split.types[1:]):
        lo, mid, hi = t.radii
        assert lo == pytest.approx(0.003 * q**k, rel=1e-12)
        assert hi == pytest.approx(0.003 * q ** (k + 1), rel=1e-12)
        assert mid == pytest.approx(math.sqrt(lo * hi), rel=1e-12)
    assert split.walls[0].index == 5
    assert split.contact("b_2", "floor").mu == 0.7 and split.contact("b_1", "b_3").mu == 0.5
    assert len(split.contacts) == 4 * 5 // 2 + 4


def test_lammps_residual_target_is_met_by_splitting(tmp_path):
    problem = problem_from_toml(RANGE, "classes")
    one, met1, _ = export_to_residual(problem, "lammps", 1.0, tangential=False)  # one class
    worst1 = max(f.res_e_z.max_abs for f in one.fits)
    assert met1 and one.problem.size_classes == 1 and worst1 > 0.05
    target = worst1 / 3.0
    ex, met, needed = export_to_residual(problem, "lammps", target, tmp_path, tangential=False,
                                         figure=False)
    worst = max(f.res_e_z.max_abs for f in ex.fits)
    assert met and worst <= target and needed == ex.problem.size_classes > 1
    assert "pair_coeff 2 3" in (tmp_path / "lammps_pair.in").read_text()


def test_cli_says_how_many_classes(tmp_path, capsys):
    src = tmp_path / "setup.toml"
    src.write_text(RANGE)
    assert main(["dem", str(src), "--for", "liggghts", "--out", str(tmp_path),
                 "--residual", "1.0", "--no-figure"]) == 0
    assert "size classes: 1 per size-range type (2 particle types)" in capsys.readouterr().out
