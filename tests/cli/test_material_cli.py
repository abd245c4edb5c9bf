"""``vimpact material fit/show`` and ``--material``/``--temperature``: the file the fit
writes is the material simulate reads; bad input exits 2 with one line."""

from __future__ import annotations

import json

import numpy as np
import pytest

import vimpact as v
from tests.conftest import ROOT
from vimpact.cli.main import main

#: a series whose arms are near the contact time (3 ms, 30 ms): the continuum kernel runs
ARMS = [(2e7, 3e-3), (1e7, 3e-2)]
G_INF = 5e6
FREQ = np.geomspace(1.0 / (2 * np.pi * 0.1), 1.0 / (2 * np.pi * 1e-3), 20)
SPHERE = ["--R", "0.01", "--m", "0.004", "--vz0", "0.5"]


def _dma(f):
    w = 2 * np.pi * np.asarray(f)
    storage = G_INF + sum(G * (w * t) ** 2 / (1 + (w * t) ** 2) for G, t in ARMS)
    loss = sum(G * w * t / (1 + (w * t) ** 2) for G, t in ARMS)
    return storage, loss


def _csv(tmp_path, rows=None, header="frequency_Hz,storage_Pa,loss_Pa"):
    if rows is None:
        storage, loss = _dma(FREQ)
        rows = [f"{f:.17g},{s:.17g},{l:.17g}" for f, s, l in zip(FREQ, storage, loss)]
    path = tmp_path / "data.csv"
    path.write_text("# a comment\n" + header + "\n" + "\n".join(rows) + "\n", encoding="utf-8")
    return path


def _run(args, capsys):
    try:
        code = main(args)
    except SystemExit as exc:  # argparse's own checks
        code = exc.code
    out, err = capsys.readouterr()
    return code, out, err


def test_fit_writes_the_material_that_simulate_reads(tmp_path, capsys):
    out = tmp_path / "m.toml"
    code, text, err = _run(["material", "fit", str(_csv(tmp_path)), "--nu", "0.49",
                            "--per-decade", "1", "--T-ref", "250", "--wlf", "17.44", "51.6",
                            "--out", str(out)], capsys)
    assert code == 0, err
    assert "RMS relative residual" in text and f"wrote {out}" in text
    storage, loss = _dma(FREQ)
    fit = v.Material.from_dma(FREQ, storage, loss, 0.49, per_decade=1,
                              shift=v.ShiftLaw.wlf(250.0, 17.44, 51.6))
    assert v.load_material(out) == fit.material
    code, text, err = _run(["simulate", "--material", str(out), "--temperature", "262",
                            *SPHERE, "--numerics", "fast", "--json"], capsys)
    assert code == 0, err
    got = json.loads(text)
    want = v.simulate(v.Scene(fit.material.at_temperature(262.0), R=0.01, m=0.004, v_z0=0.5),
                      v.Numerics.preset("fast"))
    assert got["e_z"] == want.e_z and got["path"].startswith("continuum")


def test_relaxation_data_and_tensile_moduli(tmp_path, capsys):
    """A relaxation modulus of Young's moduli, converted to shear: G = E / (2 (1 + nu))."""
    t = np.geomspace(1e-3, 0.1, 15)
    E = 2 * 1.5 * (G_INF + sum(G * np.exp(-t / tau) for G, tau in ARMS))  # nu = 0.5
    rows = [f"{a:.17g},{b:.17g}" for a, b in zip(t, E)]
    out = tmp_path / "m.toml"
    code, text, err = _run(["material", "fit", str(_csv(tmp_path, rows, "time_s,modulus_Pa")),
                            "--nu", "0.5", "--tensile", "--out", str(out)], capsys)
    assert code == 0, err
    mat = v.load_material(out)
    fitted = mat.G_inf + sum(G * np.exp(-t / tau) for G, tau in mat.arms)
    assert np.allclose(fitted, E / 3.0, rtol=0.01)  # the shear modulus G = E / 3 at nu = 0.5


def test_show_prints_the_shift(tmp_path, capsys):
    out = tmp_path / "m.toml"
    assert _run(["material", "fit", str(_csv(tmp_path)), "--nu", "0.49", "--T-ref", "300",
                 "--arrhenius", "1e5", "--out", str(out)], capsys)[0] == 0
    code, text, err = _run(["material", "show", str(out), "--temperature", "310"], capsys)
    assert code == 0, err
    a_T = v.ShiftLaw.arrhenius(300.0, 1e5).shift_factor(310.0)
    assert f"a_T = {a_T:.4g}" in text and "Arrhenius, T_ref = 310 K" in text


def _rows_with(i, cell):
    storage, loss = _dma(FREQ)
    rows = [f"{f:.17g},{s:.17g},{l:.17g}" for f, s, l in zip(FREQ, storage, loss)]
    rows[i] = cell
    return rows


@pytest.mark.parametrize("make, args, words", [
    (lambda p: _csv(p, _rows_with(2, "-1.0,1e6,1e5")), [], "line 5: frequency_Hz = '-1.0'"),
    (lambda p: _csv(p, _rows_with(0, "1.0,1e6")), [], "line 3: row = '1.0,1e6' is not allowed"),
    (lambda p: _csv(p, _rows_with(4, "1.0,nan,1e5")), [], "line 7: storage_Pa = 'nan'"),
    (lambda p: _csv(p, _rows_with(1, "1.0,1e6,abc")), [], "line 4: loss_Pa = 'abc'"),
    (lambda p: _csv(p, _dma_rows(2)), [], "frequency_Hz (number of distinct values) = 2"),
    (lambda p: _csv(p, _dma_rows(20, step=9)), ["--per-decade", "4"], "data.csv: frequency_Hz (number "
     "of points) = 3 is not allowed: must be enough for 10 unknown moduli"),
    (lambda p: _csv(p, header="frequency,storage,loss"), [], "columns = 'frequency, storage"),
    (lambda p: _csv(p), ["--T-ref", "0", "--wlf", "17.44", "51.6"], "--T-ref = 0.0"),
    (lambda p: _csv(p), ["--wlf", "17.44", "51.6"], "--wlf needs the reference temperature"),
    (lambda p: _csv(p), ["--T-ref", "220"], "--T-ref = 220 needs a shift law"),
    (lambda p: _csv(p), ["--per-decade", "50"], "--per-decade = 50.0 is not allowed"),
    (lambda p: p / "absent.csv", [], "absent.csv: measurement file not found"),
])
def test_bad_fit_input_exits_2_with_one_line(tmp_path, capsys, make, args, words):
    data = make(tmp_path)
    code, out, err = _run(["material", "fit", str(data), "--nu", "0.49",
                           "--out", str(tmp_path / "m.toml"), *args], capsys)
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and words in err, err
    assert not (tmp_path / "m.toml").exists()


def _dma_rows(n, step=1):
    f = FREQ[:n:step]
    storage, loss = _dma(f)
    return [f"{a:.17g},{s:.17g},{l:.17g}" for a, s, l in zip(f, storage, loss)]


def _material(tmp_path, shift='law = "wlf"\nT_ref_K = 250.0\nC1 = 17.44\nC2_K = 51.6'):
    path = tmp_path / "m.toml"
    path.write_text('model = "prony"\nnu = 0.49\nG_inf = 5e6\narms = [[2e7, 3e-3]]\n'
                    + (f"[shift]\n{shift}\n" if shift else ""), encoding="utf-8")
    return path


@pytest.mark.parametrize("shift, args, words", [
    (None, ["--temperature", "300"], "must be used only with a material that has a "
     "temperature shift law"),
    ('law = "wlf"\nT_ref_K = 250.0\nC1 = 17.44\nC2_K = 51.6', ["--temperature", "-5"],
     "--temperature = -5.0 is not allowed: must be an absolute temperature in kelvin"),
    ('law = "wlf"\nT_ref_K = 250.0\nC1 = 17.44\nC2_K = 51.6', ["--temperature", "190"],
     "--temperature = 190.0 is not allowed: must be above T_ref - C2 = 198.4 K"),
    ('law = "vft"\nT_ref_K = 250.0', [], "material.shift.law = 'vft' is not allowed: must be "
     "one of 'wlf', 'arrhenius'"),
    ('law = "wlf"\nT_ref_K = 250.0\nC1 = 17.44\nC2_K = 51.6', ["--nu", "0.3"],
     "--nu cannot be combined with --material"),
])
def test_bad_material_input_to_simulate_exits_2_with_one_line(tmp_path, capsys, shift, args,
                                                              words):
    code, out, err = _run(["simulate", "--material", str(_material(tmp_path, shift)), *SPHERE,
                           *args], capsys)
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and words in err, err


def test_temperature_needs_a_material_file(capsys):
    code, _, err = _run(["simulate", "--E", "1e7", "--nu", "0.3", "--eta", "1", *SPHERE,
                         "--temperature", "300"], capsys)
    assert code == 2 and "--temperature = 300 needs --material FILE" in err


def test_dem_temperature_option_is_checked(tmp_path, capsys):
    code, _, err = _run(["dem", str(ROOT / "sweeps/dem/synthetic_rubber.toml"), "--for", "lammps",
                         "--temperature", "0", "--out", str(tmp_path)], capsys)
    assert code == 2 and err.count("\n") == 1 and "--temperature = 0.0 is not allowed" in err


def test_a_sweep_of_a_material_file_at_a_temperature(tmp_path, capsys):
    """``vimpact sweep``: [random] names the material file and temperature_K; the table's
    arm columns are the file's times times a_T, and its e_z is simulate()'s."""
    import pandas as pd

    from vimpact.model.material_file import material_toml

    law = v.ShiftLaw.wlf(250.0, 17.44, 51.6)
    material = v.Material.prony(nu=0.49, G_inf=G_INF, arms=ARMS).with_shift(law)
    (tmp_path / "m.toml").write_text(material_toml(material), encoding="utf-8")
    spec = tmp_path / "sweep.toml"
    spec.write_text('seed = 3\n[numerics]\npreset = "fast"\n[random]\nrows = 2\n'
                    'material = "m.toml"\ntemperature_K = 262.0\nR_m = 0.01\nm_kg = 0.004\n'
                    'v_z0_m_s = [0.2, 0.5]\n', encoding="utf-8")
    out = tmp_path / "t.parquet"
    code, _, err = _run(["sweep", str(spec), "--out", str(out)], capsys)
    assert code == 0, err
    table = pd.read_parquet(out)
    shifted = material.at_temperature(262.0)
    for k, (G, tau) in enumerate(shifted.arms, start=1):
        assert (table[f"G_arm{k}_Pa"] == G).all() and (table[f"tau_arm{k}_s"] == tau).all()
    for row in table.itertuples():
        res = v.simulate(v.Scene(shifted, R=0.01, m=0.004, v_z0=row.v_z0_m_s),
                         v.Numerics.preset("fast"))
        assert row.e_z == pytest.approx(res.e_z, abs=1e-12)
