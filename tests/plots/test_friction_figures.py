"""The friction figures' data against the gross-slip closed form (docs/physics.md#coulomb-friction).

In gross slip the tangential impulse is mu times the normal one, so for a
solid sphere ``omega_end - omega0 = -mu (1 + e_z) v_z0 / (0.4 R)`` and
``psi2 = psi1 - 4 chi`` for an elastic sphere (Maw, Barber and Fawcett).
"""

import numpy as np
import pytest

from vimpact.lookup.friction import chi as mindlin_chi
from vimpact.plots import friction


def test_chung_ooi_large_angles_slide_as_the_closed_form_says():
    p = friction.CHUNG_OOI
    angles = np.array([80.0, 85.0])
    res = friction.chung_ooi_angles(angles)
    assert list(res["status"]) == ["ok", "ok"]
    v_z0 = p["speed_m_s"] * np.cos(np.radians(angles))
    # elastic: e_z = 1 to the numerics' accuracy (fast preset, ~1e-3)
    expected = -p["mu"] * 2.0 * v_z0 / (0.4 * p["R_m"])
    assert np.allclose(res["omega_end_rad_s"], expected, rtol=3e-3)


def test_mbf_exit_follows_the_sliding_line_beyond_4_chi():
    nu, theta_ratio = 0.3, 1.0
    chi = mindlin_chi(nu, theta_ratio)
    psi1 = np.array([4.0 * chi + 1.0, 4.0 * chi + 3.0])
    psi2 = friction._exit_incidence(nu, theta_ratio, 0.0, psi1)
    assert np.allclose(psi2, psi1 - 4.0 * chi, atol=5e-3 * psi1)


@pytest.mark.slow
@pytest.mark.parametrize("name", ["fig_mbf", "fig_beta_psi", "fig_chung_ooi"])
def test_friction_figures_draw(name, tmp_path):
    out = getattr(friction, name)(tmp_path / f"{name}.png")
    assert out.stat().st_size > 10_000
