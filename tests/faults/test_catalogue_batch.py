"""Bad rows in a batch and impossible values reported as valid.

- the seed memory with finite friction is refused where the input is checked
  (``Scene``, batch columns, sweep specs, the command line), before any kernel:
  a bad row gets status ``invalid`` and the rest of the batch goes on;
- ``simulate_pair_batch``: a bad pair is a row with status ``invalid``;
- a passive scene never reports ``e_z``, ``e_x``, ``|beta_x|`` or
  ``energy_ratio`` above 1 (rounding is set to the bound); the seed memory's
  energy gain is status ``not_passive``, never ``ok``; a held spin's energy
  ratio counts the work that holds it (docs/physics.md#energy-and-passivity).

Every scene here runs on a kernel the default test run compiles anyway (the
docs' examples and tests/kernels/test_friction.py), so nothing new is compiled.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

import vimpact as v
from vimpact.cli.main import main
from vimpact.engine.pairs import simulate_pair_batch
from vimpact.model.pair import Body, Wall
from vimpact.model.validation import InputError

#: The doctest scene of docs/physics.md (continuum full stick; compiled by the docs tests).
OBLIQUE = v.Scene.from_dimensionless(0.1, nu=0.5)


# ---- item 3: the seed memory with finite friction ------------------------------------

def test_scene_refuses_seed_memory_with_friction():
    with pytest.raises(InputError, match=r"^mu = 0\.3 is not allowed: .*seed"):
        dataclasses.replace(OBLIQUE, tangential_memory="seed", mu=0.3)
    assert dataclasses.replace(OBLIQUE, tangential_memory="seed").mu == math.inf


def test_batch_keeps_going_past_a_seed_row_with_friction():
    cols = {"nu": [0.5, 0.5], "G_inf_Pa": [OBLIQUE.material.G_inf] * 2, "R_m": [1.0, 1.0],
            "m_kg": [1.0, 1.0], "v_z0_m_s": [1.0, 1.0], "v_x0_m_s": [1.0, 1.0],
            "eta0_Pa_s": [OBLIQUE.material.eta0] * 2,
            "tangential_memory": ["seed", "incremental"], "mu": [0.3, math.inf]}
    df = v.simulate_batch(cols)
    assert list(df.status) == ["invalid", "ok"]
    assert df.error[0].startswith("mu = 0.3 is not allowed") and "seed" in df.error[0]
    one = v.simulate(OBLIQUE)
    assert df.e_z[1] == one.e_z and df.beta_x[1] == one.beta_x
    assert math.isnan(df.e_z[0])


def test_cli_refuses_seed_memory_with_friction(capsys):
    code = main(["simulate", "--Q1", "0.1", "--nu", "0.5", "--mu", "0.3",
                 "--tangential-memory", "seed"])
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert "--mu = 0.3" in err and "KernelSpec" not in err


@pytest.mark.parametrize("table, key", [
    ("[grid]\nQ1 = 0.1\nnu = 0.5\npsi = [0, 1]\n", "grid.psi"),
    ("seed = 1\n[random]\nrows = 4\nE_Pa = 1e7\neta_Pa_s = 1.0\nR_m = 0.1\nm_kg = 1.0\n"
     "v_z0_m_s = 1.0\nv_x0_m_s = 1.0\nnu = 0.5\nmu = 0.3\n", "random.mu"),
])
def test_sweep_spec_refuses_seed_memory_with_friction(tmp_path, capsys, table, key):
    spec = tmp_path / "s.toml"
    head, _, rest = table.partition("[")
    spec.write_text(f'model = "kelvin_voigt"\ntangential_memory = "seed"\n{head}[{rest}')
    code = main(["sweep", str(spec)])
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert key in err and "seed" in err
    assert not list(tmp_path.glob("*.parts")) and not (tmp_path / "s.parquet").exists()


# ---- item 4: simulate_pair_batch with bad pairs ----------------------------------------

def test_pair_batch_keeps_going_past_bad_pairs():
    material = OBLIQUE.material
    good = (Body(material, R=1.0, m=1.0, v_z=1.0, v_x=1.0), Wall())
    receding = (Body(material, R=1.0, m=1.0, v_z=-1.0), Wall())
    df = simulate_pair_batch([good, receding, None, good])
    assert list(df.status) == ["ok", "invalid", "invalid", "ok"]
    assert "approach" in df.error[1] and df.error[1].startswith("pairs[1]")
    assert df.error[2].startswith("pairs[2] = None is not allowed")
    assert df.e_z[0] == df.e_z[3] == v.simulate(OBLIQUE).e_z
    assert df.loc[[1, 2], ["e_z", "v_z1", "J_z"]].isna().all().all()
    # momentum: the wall takes J_z = m (v_z1_end - v_z1) on body 1
    assert df.J_z[0] == pytest.approx(1.0 * (df.v_z1[0] - 1.0), rel=1e-12)


# ---- item 9: impossible values never reported as valid ---------------------------------

def elastic_friction_batch(n: int = 400) -> dict:
    """Random elastic scenes with Coulomb friction (element path) and normal-only rows."""
    rng = np.random.default_rng(1)
    cols = dict(nu=rng.uniform(0, 0.5, n), G_inf_Pa=10**rng.uniform(6, 10, n),
                R_m=10**rng.uniform(-3, 0, n), m_kg=10**rng.uniform(-3, 1, n),
                v_z0_m_s=10**rng.uniform(-2, 1, n), v_x0_m_s=rng.normal(size=n),
                omega0_rad_s=rng.normal(size=n) * 10, tangential=rng.choice(["auto", "none"], n))
    cols["mu"] = 10**rng.uniform(-1, 1, n)
    return cols


def test_passive_rows_stay_within_their_bounds():
    """Elastic: the normal impact is lossless (e_z = 1 up to the discretization) and
    no output of a passive scene may exceed its physical bound, not even by rounding
    (before: e_z up to 1 + 3e-7 and energy_ratio 1 + 1e-7 with status ok)."""
    df = v.simulate_batch(elastic_friction_batch(), "fast")
    finished = df.status.isin(["ok", "normal_only", "half_space", "vc0_zero"])
    assert finished.sum() > 300
    rows = df[finished]
    assert (rows.e_z <= 1.0).all() and (rows.e_z >= 1.0 - 1e-4).all()
    assert (rows.energy_ratio <= 1.0).all()
    assert (rows.beta_x.abs().fillna(0.0) <= 1.0).all() and (rows.e_x.fillna(0.0) <= 1.0).all()


def test_seed_memory_energy_gain_is_not_ok():
    """docs/physics.md's example: the seed memory on an elastic nu = 0 half-space
    leaves |beta_x| > 1 and more kinetic energy than it brought."""
    res = v.simulate(v.Scene.from_dimensionless(0.0, nu=0.0, tangential_memory="seed"))
    assert abs(res.beta_x) > 1.0 and res.energy_ratio > 1.0  # kept as the rule gives them
    assert res.status == "not_passive" and "not passive" in res.error
    assert res.status in v.STATUSES


@pytest.mark.parametrize("Q1", [0.0, 0.1])
def test_held_backspin_counts_the_work_that_holds_it(Q1):
    """rotation = False, nu = 0: chi = 1/2, so beta_x = e_z (docs/physics.md) and the
    contact dissipates (1 - e_z^2) of the normal and of the contact point's energy;
    with the holding work counted the energy ratio is that closed form (<= 1: before,
    the held spin's energy was counted but not its work, up to 4.85 with status ok)."""
    base = v.Scene.from_dimensionless(Q1, nu=0.0, rotation=False)
    scene = dataclasses.replace(base, v_x0=0.0, omega0=-5.0 / base.R)  # backspin, v_c0 = -5 v_z0
    res = v.simulate(scene)
    assert res.status == "ok" and res.beta_x == pytest.approx(res.e_z, abs=1e-4)
    m, v_z0, v_c0 = scene.m, scene.v_z0, scene.v_c0
    work = scene.R * scene.omega0 * m * (scene.v_x0 - res.v_x_end)
    lost = 0.5 * m * (v_z0**2 * (1 - res.e_z**2) + v_c0**2 * (1 - res.beta_x**2))
    energy_in = 0.5 * m * (v_z0**2 + scene.v_x0**2) + work
    assert res.energy_ratio <= 1.0
    assert res.energy_ratio == pytest.approx(1.0 - lost / energy_in, abs=1e-9)


# ---- item 7: a friction table is not a thesis chapter-5 table -------------------------

PSI_SPEC = """model = "kelvin_voigt"
chunk_size = 4
numerics = "fast"
[grid]
Q1 = 0.1
nu = 0.5
psi = [0.0, 2.0]
mu = 0.3
"""


@pytest.fixture(scope="module")
def psi_table(tmp_path_factory):
    """A 2-row friction table (psi grid, Kelvin-Voigt, the kernels of
    tests/sweep/test_friction_sweep.py)."""
    from vimpact.sweep import run_sweep
    folder = tmp_path_factory.mktemp("psi")
    (folder / "psi.toml").write_text(PSI_SPEC)
    return run_sweep(folder / "psi.toml", progress=False)


@pytest.mark.parametrize("figure", ["fig5_1", "fig5_2", "fig5_3", "fig5_4", "fig5_5"])
def test_chapter_5_figures_refuse_a_friction_table(psi_table, tmp_path, capsys, figure):
    out = tmp_path / "f.png"
    code = main(["plot", figure, "--table", str(psi_table), "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert f"--table = {str(psi_table)!r}" in err and "friction" in err
    assert not out.exists()


# ---- item 8: messages name the option as typed and the value --------------------------

KV_TABLE = str(Path(__file__).resolve().parents[2] / "sweeps" / "tables"
               / "kelvin_voigt_table.parquet")
EXPORT = ["--E", "1e8", "--nu", "0.4", "--eta", "100", "--R", "0.01", "--m", "0.004",
          "--vz0-min", "0.1", "--vz0-max", "1"]


def typed_errors(psi_table):
    psi = str(psi_table)
    return [
        ("lookup-psi-range", ["table", "lookup", psi, "--Q1", "0.1", "--nu", "0.5", "--psi",
                              "50"], ["--psi = 50"]),
        ("lookup-psi-negative", ["table", "lookup", psi, "--Q1", "0.1", "--nu", "0.5", "--psi",
                                 "-1"], ["--psi = -1"]),
        ("lookup-psi-missing", ["table", "lookup", psi, "--Q1", "0.1", "--nu", "0.5"],
         ["--psi is missing"]),
        ("lookup-Q1-range", ["table", "lookup", KV_TABLE, "--Q1", "1e9", "--nu", "0.4"],
         ["--Q1 = 1e+09"]),
        ("lookup-empty-list-value", ["table", "lookup", KV_TABLE, "--Q1", "0.1", "--nu",
                                     "0.5,,0.3"], ["--nu", "'0.5,,0.3'"]),
        ("export-out-folder", ["table", "export", KV_TABLE, "--out", "."] + EXPORT,
         ["--out = '.'"]),
        ("export-angle-90", ["table", "export", psi, "--out", "x.csv", "--angle-deg", "90",
                             "--mu", "0.3"] + EXPORT, ["--angle-deg = 90"]),
        ("export-angle-missing", ["table", "export", psi, "--out", "x.csv", "--mu", "0.3"]
         + EXPORT, ["--angle-deg is missing"]),
        ("export-mu-on-stick-table", ["table", "export", KV_TABLE, "--out", "x.csv", "--mu",
                                      "0.3", "--angle-deg", "30"] + EXPORT, ["--mu = 0.3"]),
        ("dem-not-utf8", ["dem", "bin.toml", "--for", "lammps"], ["bin.toml", "UTF-8"]),
        ("sweep-not-utf8", ["sweep", "bin.toml"], ["bin.toml", "UTF-8"]),
        ("scene-not-utf8", ["simulate", "--scene", "bin.toml"], ["bin.toml", "UTF-8"]),
        ("dem-out-is-a-file", ["dem", "afile.toml", "--for", "lammps", "--out", "afile.toml"],
         ["--out = 'afile.toml'", "a file"]),
        ("verify-n-1e9", ["table", "verify", KV_TABLE, "--n", "1000000000"],
         ["--n = 1000000000", "100000"]),
        ("verify-n-negative", ["table", "verify", KV_TABLE, "--n=-1"], ["--n = -1"]),
        ("verify-seed-negative", ["table", "verify", KV_TABLE, "--seed=-1"], ["--seed = -1"]),
        ("bench-compare-not-utf8", ["bench", "compare", "bin.toml", "bin.toml"],
         ["bin.toml", "UTF-8"]),
    ]


@pytest.mark.parametrize("case", range(17))
def test_messages_name_what_was_typed(psi_table, tmp_path, monkeypatch, capsys, case):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "bin.toml").write_bytes(b"\xff\xfe\x00 not text")
    (tmp_path / "afile.toml").write_text("")
    name, argv, words = typed_errors(psi_table)[case]
    try:
        code = main(argv)
    except SystemExit as exc:  # argparse's own checks
        code = exc.code
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1, (name, err)
    for word in words:
        assert word in err, (name, word, err)
    for internal in ("array(", "angle_deg", "[Errno", "codec"):
        assert internal not in err, (name, internal, err)
