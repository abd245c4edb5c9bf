"""Adhesion in sweep specs: a ``lam`` grid axis and a drawn ``adhesion_J_m2``.

- the example spec sweeps/adhesion_kelvin_voigt.toml loads, and a tiny version of it runs;
  its rows are vimpact.simulate of the scenes the spec names;
- dimensional analysis: e_z of an elastic impact depends on the adhesion number lam alone,
  of a Kelvin-Voigt one on (lam, Q1): a physical scene with the same numbers as a grid
  row (on the grid's reference scene, other R, m, v_z0, E*) restitutes the same e_z
  (exactly, to rounding: the kernel runs in Hertz units);
- bad values name the key.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

import vimpact as v
from vimpact.engine.adhesion import adhesion_for_number, adhesion_number
from vimpact.sweep import load_spec
from vimpact.sweep.runner import compute_chunk

EXAMPLE = Path(__file__).resolve().parents[2] / "sweeps" / "adhesion_kelvin_voigt.toml"
E_STAR, R, M = 1.5e6, 0.01, 4e-3  # a rubber-like contact (test_adhesion.py)


def tiny(tmp_path: Path, model: str, grid: str) -> Path:
    path = tmp_path / "adhesion.toml"
    path.write_text(f'model = "{model}"\nchunk_size = 8\n[grid]\n{grid}\nnu = 0.5\n')
    return path


def test_example_spec_loads():
    spec = load_spec(EXAMPLE)
    assert spec.model == "kelvin_voigt" and list(spec.axes)[0] == "lam"
    assert spec.axes["lam"][0] == 0.0 and spec.has_adhesion
    for column in ("adhesion_J_m2", "lam", "F_tensile_max_N"):
        assert column in spec.columns() and column in spec.units()
    assert spec.units()["F_tensile_max_N"] == "N"


def test_tiny_adhesion_grid_runs_as_single_impacts(tmp_path):
    spec = load_spec(tiny(tmp_path, "kelvin_voigt", "lam = [0.0, 0.5, 3.0]\nQ1 = [0.01, 0.3]"))
    table = compute_chunk(spec, 0).to_pandas()
    params = spec.chunk_parameters(0)
    assert list(table.columns) == spec.columns() and len(table) == 6
    assert (table.status[:2] == "vc0_zero").all() and (table.F_tensile_max_N[:2] == 0.0).all()
    assert table.status[4] == "stuck" and table.e_z[4] == 0.0  # lam = 3 holds the sphere
    for i in range(6):
        scene = spec.scene(params, i)
        assert adhesion_number(scene) == pytest.approx(params["lam"][i], rel=1e-12, abs=0.0)
        single = v.simulate(scene)
        assert table.status[i] == single.status
        assert table.e_z[i] == pytest.approx(single.e_z, rel=1e-9, abs=1e-12)
        assert table.F_tensile_max_N[i] == pytest.approx(single.F_tensile_max, rel=1e-9)
        assert table.adhesion_J_m2[i] == pytest.approx(scene.adhesion, rel=1e-12)


@pytest.mark.parametrize("model, Q1", [("elastic", None), ("kelvin_voigt", 0.1)])
def test_e_z_collapses_on_lam(tmp_path, model, Q1):
    """A physical scene far from the grid's reference scene (R 100 times smaller, m 250
    times lighter, another E* and v_z0) with the grid row's lam (and Q1) has its e_z.

    Dimensional analysis says the normal impact depends on (lam, Q1, nu) alone; the
    kernel runs in Hertz units, so the code's collapse is exact to rounding, and this
    checks that the sweep's lam -> dgamma on the reference scene and the physical
    scene's dgamma -> lam are the same number at every scale."""
    grid = "lam = [0.5]" + ("" if Q1 is None else f"\nQ1 = [{Q1}]")
    spec = load_spec(tiny(tmp_path, model, grid))
    e_grid = compute_chunk(spec, 0).to_pandas().e_z[0]
    for v_z0 in (0.03, 0.3):
        G = E_STAR / 4.0
        if Q1 is None:
            mat = v.Material.elastic(nu=0.5, G=G)
        else:  # eta with this Q1 at this speed: Q1 = sqrt(15/32) (eta / G) / T
            hz = v.Scene(v.Material.elastic(nu=0.5, G=G), R=R, m=M, v_z0=v_z0).hertz
            mat = v.Material.kelvin_voigt(nu=0.5, G=G,
                                          eta=Q1 / math.sqrt(15.0 / 32.0) * G * float(hz.T))
        scene = v.Scene(mat, R=R, m=M, v_z0=v_z0, tangential="none", allow_large_contact=True)
        scene = dataclasses.replace(scene, adhesion=adhesion_for_number(scene, 0.5))
        if Q1 is not None:
            assert scene.Q1 == pytest.approx(Q1, rel=1e-12)
        assert v.simulate(scene).e_z == pytest.approx(e_grid, rel=1e-12)


def test_random_adhesion_draw(tmp_path):
    path = tmp_path / "random.toml"
    path.write_text('model = "elastic"\nseed = 3\ntangential = "none"\n[random]\nrows = 3\n'
                    f'nu = 0.5\nE_Pa = {E_STAR * 0.75}\nR_m = {R}\nm_kg = {M}\n'
                    'v_z0_m_s = [0.02, 0.2]\nadhesion_J_m2 = [0.1, 1.0]\n')
    spec = load_spec(path)
    table = compute_chunk(spec, 0).to_pandas()
    params = spec.chunk_parameters(0)
    assert np.all((table.adhesion_J_m2 >= 0.1) & (table.adhesion_J_m2 <= 1.0))
    for i in range(3):
        scene = spec.scene(params, i)
        assert scene.adhesion == table.adhesion_J_m2[i]
        assert table.lam[i] == pytest.approx(adhesion_number(scene), rel=1e-12)
        assert table.e_z[i] == v.simulate(scene).e_z


@pytest.mark.parametrize("grid, key", [("lam = [-1.0]", "grid.lam"),
                                       ("lam = [0.1]\npsi = [0.5]", "grid.lam")])
def test_bad_lam_names_the_key(tmp_path, grid, key):
    with pytest.raises(ValueError, match=key):
        load_spec(tiny(tmp_path, "elastic", grid))


def test_bad_random_adhesion_names_the_key(tmp_path):
    path = tmp_path / "random.toml"
    path.write_text('model = "elastic"\nseed = 3\n[random]\nrows = 3\nnu = 0.5\n'
                    'E_Pa = 1e6\nR_m = 0.01\nm_kg = 0.004\nv_z0_m_s = 0.1\n'
                    'adhesion_J_m2 = [-1.0, 1.0]\n')
    with pytest.raises(ValueError, match="random.adhesion_J_m2"):
        load_spec(path)


def test_lam_is_not_an_adaptive_axis(tmp_path):
    grid = ('lam = [0.1]\nQ1 = { start = 0.01, stop = 1, num = 2 }\ntolerance = 1e-3\n'
            'refine = "adaptive"')
    with pytest.raises(ValueError, match="grid.lam"):
        load_spec(tiny(tmp_path, "kelvin_voigt", grid))
