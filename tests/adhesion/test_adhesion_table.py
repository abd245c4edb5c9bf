"""The adhesive impact table (vimpact.lookup.adhesion, vimpact.tablebuild.adhesion).

Against what the table does not produce: direct simulation of physical scenes at the
same (lam, Q1) (other radius, mass, modulus), the elastic JKR sticking number from a
scipy quadrature, the stored verification reproduced by a second run; and the stuck
flag read as stuck (e_z = 0, not NaN) by the API and by `vimpact table lookup`.
"""

from __future__ import annotations

import contextlib
import dataclasses
import io
import json
import math
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import quad

import vimpact as v
from vimpact.cli.main import main
from vimpact.engine.adhesion import adhesion_for_number, simulate_adhesive
from vimpact.lookup.adhesion import AdhesionTable, is_adhesion_table
from vimpact.model.numerics import Numerics
from vimpact.tablebuild.adhesion import (
    sticking_numbers,
    verify_adhesion_table,
)

SHIPPED = Path(__file__).resolve().parents[2] / "sweeps" / "tables" / "adhesion_table.parquet"

#: Built with the ``fast`` preset (half the CPU of ``default``): its e_z is within 1e-3 of
#: the default numerics' over the table's range (200 random points), 20 times inside the
#: table's tolerance, to which its lookups are compared with scenes simulated at the
#: default numerics.
TINY = """model = "kelvin_voigt"
output = "tiny.parquet"
[numerics]
preset = "fast"
[grid]
lam = { start = 0.05, stop = 3, per_decade = 2 }
Q1 = { start = 0.1, stop = 1, per_decade = 1 }
nu = 0.5
tolerance = 2e-2
"""


@pytest.fixture(scope="module")
def tiny_build(tmp_path_factory) -> tuple[int, Path, str]:
    """`vimpact table build` of the tiny spec: (exit code, table, stderr).

    Built once through the command line, which calls :func:`build_adhesion_table`
    with the spec, ``n_verify`` and ``seed`` (``--n``, ``--seed``) and the progress
    lines on stderr."""
    spec = tmp_path_factory.mktemp("adh") / "tiny.toml"
    spec.write_text(TINY)
    err = io.StringIO()
    with contextlib.redirect_stderr(err):
        code = main(["table", "build", str(spec), "--n", "15", "--seed", "3"])
    return code, spec.parent / "tiny.parquet", err.getvalue()


@pytest.fixture(scope="module")
def tiny(tiny_build) -> Path:
    code, path, err = tiny_build
    assert code == 0, err
    return path


def physical(Q1: float, lam: float) -> v.Scene:
    """A physical Kelvin-Voigt scene (not the table's reference scene) with these numbers."""
    base = v.Scene(v.Material.kelvin_voigt(nu=0.3, G=2e6, eta=1.0), R=0.004, m=3e-4, v_z0=0.2,
                   tangential="none")
    s = dataclasses.replace(base, material=v.Material.kelvin_voigt(nu=0.3, G=2e6,
                                                                   eta=Q1 / base.Q1))
    return dataclasses.replace(s, adhesion=adhesion_for_number(s, lam), allow_large_contact=True)


def test_elastic_limit_sticking_number_is_jkr():
    """At Q1 -> 0 the sticking number is the elastic JKR one, lam_s = (2 w0)^(-3/10) with
    w0 the JKR work in JKR units (a scipy quadrature), to the element resolution (1 %)."""
    w0 = -quad(lambda s: (1.25 * s**3 - 15.0 / 8.0 * s**1.5) * (2.0 * s - 0.5 * s**-0.5),
               4.0 ** (-2.0 / 3.0), 1.0)[0]
    lam_s = sticking_numbers(np.array([1e-4]), Numerics(), rtol=1e-4)[0]
    assert lam_s == pytest.approx((2.0 * w0) ** -0.3, rel=1e-2)


def test_tiny_table_lookup_against_physical_scenes(tiny):
    """Stuck points read as stuck (e_z = 0, not NaN) and a physical scene there sticks;
    free points match a physical scene's e_z to the table's tolerance."""
    table = AdhesionTable.open(tiny)
    assert is_adhesion_table(tiny)
    for Q1, lam in ((0.2, 2.5), (0.5, 1.0), (0.15, 0.06), (0.7, 0.2), (0.3, 0.4)):
        res = table.lookup(Q1, lam)
        sim = simulate_adhesive(physical(Q1, lam))
        assert sim.status in ("ok", "stuck")
        assert res["stuck"] == sim.stuck
        assert math.isfinite(res["e_z"])
        if res["stuck"]:
            assert res["e_z"] == 0.0 and lam >= res["lam_s"]
        else:
            assert res["e_z"] == pytest.approx(sim.e_z, abs=2e-2)


def test_verification_is_reproduced(tiny):
    """The stored held-out error is what a second verification measures (same seed)."""
    table = AdhesionTable.open(tiny)
    stored = table.meta("interpolation_error")
    assert stored["points"] == 30 and stored["seed"] == 3
    assert verify_adhesion_table(table, n=stored["n"], seed=stored["seed"]) == stored


def test_cli_lookup_info_verify(tiny, capsys):
    assert main(["table", "lookup", str(tiny), "--Q1", "0.5", "--lam", "0.06,2.5",
                 "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)["rows"]
    assert [r["stuck"] for r in rows] == [False, True]
    assert rows[1]["e_z"] == 0.0 and 0.0 < rows[0]["e_z"] < 1.0
    assert main(["table", "lookup", str(tiny), "--Q1", "0.5", "--lam", "2.5"]) == 0
    text = capsys.readouterr().out
    assert "True" in text and "nan" not in text
    assert main(["table", "info", str(tiny)]) == 0
    assert "sticking lam_s" in capsys.readouterr().out
    assert main(["table", "verify", str(tiny), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["measured"] == out["stored"]


@pytest.mark.parametrize("args, text", [
    ([], "--lam is missing"),
    (["--lam", "0.1", "--Q2", "1"], "--Q2 is not allowed"),
    (["--lam", "50"], "lam = 50"),
    (["--lam", "0.1,0.2", "--Q1", "0.2,0.3,0.4"], "one length"),
])
def test_cli_lookup_bad_input_exits_2(tiny, capsys, args, text):
    argv = ["table", "lookup", str(tiny)] + (["--Q1", "0.5"] if "--Q1" not in args else [])
    assert main(argv + args) == 2
    err = capsys.readouterr().err
    assert text in err and "Traceback" not in err and len(err.strip().splitlines()) == 1


@pytest.mark.parametrize("args, text", [(["--n", "1000000000"], "--n = 1000000000"),
                                        (["--seed=-1"], "--seed = -1")])
def test_cli_verify_bad_input_exits_2(tiny, capsys, args, text):
    assert main(["table", "verify", str(tiny), *args]) == 2
    err = capsys.readouterr().err
    assert text in err and len(err.strip().splitlines()) == 1


def test_cli_build(tiny_build):
    """`vimpact table build` on a spec with a lam axis writes an adhesive table."""
    code, path, err = tiny_build
    assert code == 0 and is_adhesion_table(path)
    assert "stuck misread" in err


def test_sweep_refuses_an_adhesive_table_spec(tmp_path, capsys):
    """`vimpact sweep` would write a restitution grid over the table's file: refused."""
    spec = tmp_path / "tiny.toml"
    spec.write_text(TINY)
    assert main(["sweep", str(spec)]) == 2
    assert "vimpact table build" in capsys.readouterr().err
    assert not (tmp_path / "tiny.parquet").exists()


def test_lam_on_a_restitution_table_exits_2(capsys):
    table = SHIPPED.parent / "kelvin_voigt_table.parquet"
    assert main(["table", "lookup", str(table), "--Q1", "0.1", "--nu", "0.5",
                 "--lam", "0.1"]) == 2
    assert "--lam is not allowed" in capsys.readouterr().err


def test_shipped_table_against_direct_simulation():
    """The shipped table: at a few points off its nodes, stuck as a physical scene is,
    and e_z within its stored measured error."""
    table = AdhesionTable.open(SHIPPED)
    bound = table.error_bound()["e_z"]
    assert bound < 1e-2
    for Q1, lam in ((2e-3, 0.7), (0.05, 0.03), (0.4, 0.3), (3.0, 0.05), (20.0, 0.012),
                    (0.01, 5.0), (50.0, 0.5)):
        res = table.lookup(Q1, lam)
        sim = simulate_adhesive(physical(Q1, lam))
        assert res["stuck"] == sim.stuck
        assert res["e_z"] == pytest.approx(sim.e_z, abs=bound)


@pytest.mark.slow
def test_shipped_table_verification_is_reproduced():
    """`vimpact table verify` on the shipped table measures what its build stored."""
    table = AdhesionTable.open(SHIPPED)
    stored = table.meta("interpolation_error")
    assert verify_adhesion_table(table, n=stored["n"], seed=stored["seed"]) == stored
