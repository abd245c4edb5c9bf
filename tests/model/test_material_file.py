"""Material files: written and read back exactly; named by scene files, sweep specs and
DEM set-ups, with their temperature; the shipped example is what its recipe makes."""

from __future__ import annotations

import importlib.util

import numpy as np
import pytest

from tests.conftest import ROOT
from vimpact import InputError, Material, ShiftLaw, load_material
from vimpact.model.fit import load_measurements
from vimpact.model.material_file import material_toml
from vimpact.model.scene_file import load_scene

EXAMPLE = ROOT / "sweeps" / "materials"
PRONY = Material.prony(nu=0.49, G_inf=5e6, arms=[(2e7, 3e-3), (1e7, 3e-2)], eta0=0.5)


@pytest.mark.parametrize("material", [
    PRONY,
    PRONY.with_shift(ShiftLaw.wlf(250.0, 17.44, 51.6)),
    PRONY.with_shift(ShiftLaw.arrhenius(300.0, 1.2e5)),
    Material.kelvin_voigt(nu=0.3, G=1e7, eta=20.0),
    Material.standard_solid(nu=0.4, G1=1e7, G2=3e7, eta=600.0),
    Material.elastic(nu=0.25, G=8e10),
])
def test_a_written_material_reads_back_exactly(material, tmp_path):
    path = tmp_path / "m.toml"
    path.write_text(material_toml(material, "a comment\non two lines"), encoding="utf-8")
    got = load_material(path)
    if material.model == "standard_solid":  # stored as G2 and eta = G2 tau
        assert got.arms[0][1] == pytest.approx(material.arms[0][1], rel=1e-15)
        got = Material(got.model, got.nu, got.G_inf, material.arms, got.eta0, got.shift)
    assert got == material


def test_the_example_data_are_what_their_recipe_makes():
    """sweeps/materials/synthetic_rubber_dma.csv is remade by its script (synthetic:
    a stated Prony series plus seeded 1 % scatter)."""
    spec = importlib.util.spec_from_file_location("recipe", EXAMPLE / "synthetic_rubber.py")
    recipe = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(recipe)
    kind, cols = load_measurements(EXAMPLE / "synthetic_rubber_dma.csv")
    assert kind == "dma" and cols["frequency_Hz"].size == 49
    gen = recipe.generating_material()
    assert gen.glassy_modulus == pytest.approx(1.0e9) and gen.G_inf == 1.0e6
    w = 2 * np.pi * cols["frequency_Hz"]
    wt = w[:, None] * np.array([tau for _, tau in gen.arms])
    g = np.array([G for G, _ in gen.arms])
    storage = gen.G_inf + (g * wt**2 / (1 + wt**2)).sum(axis=1)
    scatter = np.log(cols["storage_Pa"] / storage)  # exp(0.01 z), z standard normal
    assert 0.005 < scatter.std() < 0.015 and abs(scatter.mean()) < 0.005


def test_the_example_material_is_the_fit_of_the_example_data():
    kind, cols = load_measurements(EXAMPLE / "synthetic_rubber_dma.csv")
    fit = Material.from_dma(cols["frequency_Hz"], cols["storage_Pa"], cols["loss_Pa"], 0.49,
                            per_decade=2, shift=ShiftLaw.wlf(220.0, 17.44, 51.6))
    shipped = load_material(EXAMPLE / "synthetic_rubber.toml")
    assert shipped.shift == fit.material.shift and len(shipped.arms) == len(fit.material.arms)
    assert shipped.G_inf == pytest.approx(fit.material.G_inf, rel=1e-9)
    for a, b in zip(shipped.arms, fit.material.arms):
        assert a == pytest.approx(b, rel=1e-9)
    assert fit.residual < 0.02  # the data's scatter is 1 %


def _write(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


SCENE = """
[scene]
material = "m.toml"
temperature_K = 262.0
R_m = 0.01
m_kg = 0.004
v_z0_m_s = 0.5
"""


def test_a_scene_file_names_a_material_file_and_its_temperature(tmp_path):
    law = ShiftLaw.wlf(250.0)
    _write(tmp_path, "m.toml", material_toml(PRONY.with_shift(law)))
    scene, _ = load_scene(_write(tmp_path, "s.toml", SCENE))
    want = PRONY.with_shift(law).at_temperature(262.0)
    got = scene.material
    assert (got.model, got.nu, got.G_inf, got.arms, got.eta0) == \
        (want.model, want.nu, want.G_inf, want.arms, want.eta0)
    assert scene.R == 0.01 and scene.v_z0 == 0.5


@pytest.mark.parametrize("edit, match", [
    (lambda s: s.replace('material = "m.toml"\n', ""), r"scene.temperature_K = 262.0 is not "
     r"allowed: must come with a material file"),
    (lambda s: s.replace("temperature_K = 262.0", "temperature_K = -4.0"),
     r"scene.temperature_K = -4.0 is not allowed: must be an absolute temperature in kelvin"),
    (lambda s: s.replace("temperature_K = 262.0", "temperature_K = 150.0"),
     r"must be above T_ref - C2"),
    (lambda s: s + "G_Pa = 1e6\n", "scene.G_Pa cannot be combined with scene.material"),
    (lambda s: 'model = "kelvin_voigt"\n' + s, r"model = 'kelvin_voigt' is not allowed: must be "
     r"'prony'"),
    (lambda s: s.replace("m.toml", "missing.toml"), r"scene.material = 'missing.toml' is not "
     "allowed"),
])
def test_bad_material_keys_of_a_scene_file(tmp_path, edit, match):
    _write(tmp_path, "m.toml", material_toml(PRONY.with_shift(ShiftLaw.wlf(250.0))))
    with pytest.raises(ValueError, match=match) as exc:
        load_scene(_write(tmp_path, "s.toml", edit(SCENE)))
    assert str(exc.value).startswith(str(tmp_path / "s.toml"))


@pytest.mark.parametrize("shift, match", [
    ('law = "vogel"\nT_ref_K = 300.0', r"m.toml: material.shift.law = 'vogel' is not allowed: "
     r"must be one of 'wlf', 'arrhenius'"),
    ('law = "wlf"\nT_ref_K = 0.0\nC1 = 17.44\nC2_K = 51.6', r"T_ref \(reference temperature, "
     r"K\) = 0.0 is not allowed"),
    ('law = "wlf"\nT_ref_K = 220.0\nC1 = 17.44', r"material.shift.C2_K = None is not allowed: "
     "must be given"),
    ('law = "arrhenius"\nT_ref_K = 220.0\nC1 = 17.44', r"material.shift key = 'C1' is not "
     "allowed"),
])
def test_bad_shift_tables(tmp_path, shift, match):
    text = material_toml(PRONY) + "\n[shift]\n" + shift + "\n"
    with pytest.raises(InputError, match=match):
        load_material(_write(tmp_path, "m.toml", text))


def test_a_sweep_spec_names_a_material_file(tmp_path):
    from vimpact.sweep import load_spec

    law = ShiftLaw.arrhenius(300.0, 1.0e5)
    material = _write(tmp_path, "m.toml", material_toml(PRONY.with_shift(law)))
    spec = load_spec(_write(tmp_path, "sw.toml", """
seed = 1
[random]
rows = 3
material = "m.toml"
temperature_K = 310.0
R_m = 0.01
m_kg = 0.004
v_z0_m_s = [0.1, 1.0]
"""))
    assert spec.model == "prony"
    params = spec.chunk_parameters(0)
    want = PRONY.with_shift(law).at_temperature(310.0)
    for i in range(3):
        got = spec.scene(params, i).material
        assert got.arms == want.arms and got.G_inf == want.G_inf and got.eta0 == want.eta0
    before = spec.sweep_hash
    material.write_text(material_toml(PRONY.with_shift(ShiftLaw.arrhenius(300.0, 2.0e5))))
    assert load_spec(tmp_path / "sw.toml").sweep_hash != before  # the file's text counts


def test_a_dem_setup_names_a_material_file_at_its_temperature(tmp_path):
    from vimpact.dem.problem import load_problem

    law = ShiftLaw.wlf(250.0)
    _write(tmp_path, "m.toml", material_toml(PRONY.with_shift(law)))
    text = """
temperature_K = 262.0
[speeds]
min = 0.1
max = 1.0
[types.ball]
density = 1000.0
radius = 0.01
material = "m.toml"
[walls.floor]
material = "rigid"
"""
    setup = _write(tmp_path, "dem.toml", text)
    got = load_problem(setup).types[0].material
    assert got == PRONY.with_shift(law).at_temperature(262.0)
    assert load_problem(setup, temperature=270.0).types[0].material == \
        PRONY.with_shift(law).at_temperature(270.0)
    with pytest.raises(InputError, match=r"--temperature = 0.0 is not allowed: must be an "
                                         "absolute temperature in kelvin"):
        load_problem(setup, temperature=0.0)
    _write(tmp_path, "m.toml", material_toml(PRONY))
    with pytest.raises(InputError, match=r"types.ball.material at temperature_K = 262.0 K: "
                                         r"temperature \(K\) = 262.0 is not allowed: must be used "
                                         "only with a material that has a temperature shift law"):
        load_problem(setup)


def test_the_shipped_dem_setup_reads_the_example_material():
    from vimpact.dem.problem import load_problem

    problem = load_problem(ROOT / "sweeps" / "dem" / "synthetic_rubber.toml")
    shipped = load_material(EXAMPLE / "synthetic_rubber.toml")
    assert problem.types[0].material == shipped.at_temperature(260.0)
