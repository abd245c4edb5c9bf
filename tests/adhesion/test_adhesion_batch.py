"""Adhesive rows on the batch path (vimpact.simulate_batch, docs/physics.md#adhesion).

- every adhesive row of a mixed batch equals vimpact.simulate of its scene (the scalar
  path, a separate SI conversion), and the non-adhesive rows equal a batch without the
  adhesive rows;
- the largest tensile force of an elastic sphere that separates is the JKR pull-off
  force 3/2 pi dgamma R (closed form), closer under refinement;
- bad and oblique adhesion inputs are invalid rows whose reason names adhesion_J_m2.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

import vimpact as v
from vimpact.engine.result import RESULT_FIELDS, UNITS

E_STAR, R, M, DGAMMA = 1.5e6, 0.01, 4e-3, 0.5  # Pa, m, kg, J/m^2 (as test_adhesion.py)
ELASTIC = v.Material.elastic(nu=0.5, E=E_STAR * 0.75)
KELVIN_VOIGT = v.Material.kelvin_voigt(nu=0.5, E=E_STAR * 0.75, eta=30.0)
F_PULL_OFF = 1.5 * math.pi * DGAMMA * R  # N, JKR pull-off force


def adhesive(material, v_z0: float, dgamma: float = DGAMMA) -> v.Scene:
    return v.Scene(material, R=R, m=M, v_z0=v_z0, adhesion=dgamma, tangential="none")


def same(a, b) -> bool:
    """Equal, or both missing (NaN, or a null error: None or pandas' NaN of a str column)."""
    if pd.isna(a) and pd.isna(b):
        return True
    return a == b


def test_mixed_batch_rows_equal_single_simulate():
    standard_solid = v.Material.standard_solid(nu=0.4, G1=0.5e6, G2=1e6, eta=20.0)
    scenes = [adhesive(ELASTIC, 0.01),  # sticks
              v.Scene(ELASTIC, R=R, m=M, v_z0=0.05),  # no adhesion
              adhesive(ELASTIC, 0.05),
              adhesive(KELVIN_VOIGT, 0.05),
              v.Scene(KELVIN_VOIGT, R=R, m=M, v_z0=0.05, v_x0=0.02),  # oblique, no adhesion
              adhesive(standard_solid, 0.05)]
    df = v.simulate_batch(scenes)
    assert list(df.columns) == list(RESULT_FIELDS) and UNITS["F_tensile_max"] == "N"
    for i, s in enumerate(scenes):
        single = v.simulate(s).to_dict()
        for name in RESULT_FIELDS:
            assert same(single[name], df[name][i]), (i, name, single[name], df[name][i])
    assert df.status[0] == "stuck" and df.e_z[0] == 0.0
    assert (df.path[[0, 2, 3, 5]] == "adhesion[verlet,normal]").all()
    assert (df.F_tensile_max[[0, 2, 3, 5]] > 0.0).all()
    # without adhesion: a finished row has no tensile force (0, not NaN)
    assert (df.F_tensile_max[[1, 4]] == 0.0).all()
    plain = v.simulate_batch([scenes[1], scenes[4]])
    pd.testing.assert_frame_equal(df.iloc[[1, 4]].reset_index(drop=True), plain)


def test_separating_elastic_sphere_pulls_with_the_jkr_pull_off_force():
    """On the elastic JKR curve the least force is -3/2 pi dgamma R (whatever the load
    path); a sphere that separates passes it, so F_tensile_max -> 3/2 pi dgamma R."""
    scenes = [adhesive(ELASTIC, x) for x in (0.02, 0.05)]
    coarse = v.simulate_batch(scenes, "fast").F_tensile_max / F_PULL_OFF - 1.0
    default = v.simulate_batch(scenes).F_tensile_max / F_PULL_OFF - 1.0
    assert (np.abs(default) < 0.01).all()
    assert (np.abs(default) < np.abs(coarse)).all()


def test_columns_input_adhesion_column():
    cols = {"nu": [0.5] * 5, "G_inf_Pa": [E_STAR * 0.25] * 5, "R_m": [R] * 5,
            "m_kg": [M] * 5, "v_z0_m_s": [0.05] * 5, "tangential": ["none"] * 5,
            "adhesion_J_m2": [DGAMMA, -1.0, math.nan, 0.0, "a lot"]}
    df = v.simulate_batch(cols)
    assert df.status[0] == "normal_only" and df.path[0] == "adhesion[verlet,normal]"
    assert df.e_z[0] == v.simulate(adhesive(ELASTIC, 0.05)).e_z
    for i in (1, 2, 4):
        assert df.status[i] == "invalid" and "adhesion_J_m2" in df.error[i], df.error[i]
        assert math.isnan(df.e_z[i]) and math.isnan(df.F_tensile_max[i])
    assert df.status[3] == "normal_only" and df.F_tensile_max[3] == 0.0
    # no adhesion column: adhesion 0 everywhere, the rows as without the column
    del cols["adhesion_J_m2"]
    no_column = v.simulate_batch(cols)
    assert (no_column.F_tensile_max == 0.0).all()
    for name in RESULT_FIELDS:
        assert same(no_column[name][3], df[name][3]), name


@pytest.mark.parametrize("extra", [{"v_x0_m_s": 0.01}, {"omega0_rad_s": 1.0}])
def test_oblique_adhesive_row_is_invalid(extra):
    cols = {"nu": [0.5], "G_inf_Pa": [E_STAR * 0.25], "R_m": [R], "m_kg": [M],
            "v_z0_m_s": [0.05], "adhesion_J_m2": [DGAMMA], **{k: [x] for k, x in extra.items()}}
    df = v.simulate_batch(cols)
    assert df.status[0] == "invalid"
    assert "adhesion_J_m2" in df.error[0] and "normal only" in df.error[0]
