"""The temperature figure: e_z(v) of the example polymer at five temperatures (slow:
45 impacts on the element path)."""

from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import ROOT
from vimpact import load_material
from vimpact.plots.temperature import TEMPERATURES_K, fig_temperature, restitution_curves


@pytest.mark.slow
def test_temperature_figure_renders_and_its_warm_limit_is_elastic(tmp_path):
    material = load_material(ROOT / "sweeps" / "materials" / "synthetic_rubber.toml")
    out = fig_temperature(tmp_path / "t.png", material)
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    curves = restitution_curves(material)
    assert set(curves) == set(TEMPERATURES_K)
    for e_z in curves.values():
        assert np.all((e_z > 0.0) & (e_z <= 1.0))
    # at 300 K every relaxation time is below 1e-6 s, far shorter than the ~1 ms contact:
    # the half-space is its relaxed elastic self and gives back the energy (e_z -> 1)
    assert max(tau for _, tau in material.at_temperature(300.0).arms) < 1e-6
    assert curves[300.0].min() > 0.99
