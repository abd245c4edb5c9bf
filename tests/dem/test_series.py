"""Series combination of two generalized Maxwell materials (vimpact.model.series)."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import vimpact as v
from vimpact.model.pair import pair_material
from vimpact.model.series import operator_modulus, series_material

KV1 = v.Material.kelvin_voigt(nu=0.45, G=3e7, eta=600.0)     # tau 20 us
KV2 = v.Material.kelvin_voigt(nu=0.45, G=8e7, eta=400.0)     # tau 5 us
SLS = v.Material.standard_solid(nu=0.45, G1=2e7, G2=5e7, eta=100.0)
PRONY = v.Material.prony(nu=0.45, G_inf=1e7, arms=[(3e7, 1e-6), (2e7, 1e-4), (5e6, 1e-2)],
                         eta0=50.0)
PRONY2 = v.Material.prony(nu=0.45, G_inf=4e7, arms=[(1e7, 1e-4), (6e7, 3e-5)])
ELASTIC = v.Material.elastic(nu=0.45, G=7e7)


def _closed_form_two_kelvin_voigt(G1, eta1, G2, eta2):
    """Spring, dashpot, arm (modulus, time) of two Kelvin-Voigt bodies in series."""
    tau = (eta1 + eta2) / (G1 + G2)
    g = (G1 * eta2 - G2 * eta1) ** 2 / ((G1 + G2) * (eta1 + eta2) ** 2)
    return G1 * G2 / (G1 + G2), eta1 * eta2 / (eta1 + eta2), g, tau


def test_two_kelvin_voigt_bodies_match_the_closed_form():
    mat = series_material(KV1, KV2)
    G, eta, g, tau = _closed_form_two_kelvin_voigt(3e7, 600.0, 8e7, 400.0)
    assert mat.G_inf == pytest.approx(G, rel=1e-14)
    assert mat.eta0 == pytest.approx(eta, rel=1e-14)
    assert len(mat.arms) == 1
    assert mat.arms[0][0] == pytest.approx(g, rel=1e-10)
    assert mat.arms[0][1] == pytest.approx(tau, rel=1e-12)


def test_equal_relaxation_times_give_no_arm():
    mat = series_material(KV1, v.Material.kelvin_voigt(nu=0.45, G=6e7, eta=1200.0))
    assert mat.arms == () and mat.model == "kelvin_voigt"
    assert mat.G_inf == pytest.approx(2e7, rel=1e-14)
    assert mat.eta0 == pytest.approx(400.0, rel=1e-14)


@pytest.mark.parametrize("a, b", [(KV1, KV2), (KV1, SLS), (SLS, PRONY), (PRONY, PRONY2),
                                  (PRONY, KV2), (ELASTIC, PRONY), (PRONY, PRONY)])
def test_frequency_response_is_the_series_combination(a, b):
    mat = series_material(a, b)
    n_max = len(a.arms) + len(b.arms) + 1
    assert len(mat.arms) <= n_max
    assert all(G > 0 and tau > 0 for G, tau in mat.arms)
    assert (mat.eta0 > 0) == (a.eta0 > 0 and b.eta0 > 0)
    w = np.geomspace(1e-1, 1e9, 300)
    for s in (1j * w, w):  # steady oscillation and real Laplace variable
        M1, M2 = operator_modulus(a, s), operator_modulus(b, s)
        np.testing.assert_allclose(operator_modulus(mat, s), M1 * M2 / (M1 + M2), rtol=1e-9)


def _creep_of_prony(mat, t_end, n=400):
    """Strain (per unit stress, 1/Pa) of ``mat`` under a unit shear stress step, by integrating
    the generalized Maxwell body's ODEs: ``sigma = G_inf e + eta0 e' + sum s_i``,
    ``s_i' = G_i e' - s_i / tau_i`` (independent of the series code)."""
    arms = mat.arms
    G = np.array([a[0] for a in arms])
    tau = np.array([a[1] for a in arms])
    glassy = mat.G_inf + G.sum()
    if mat.eta0 > 0:
        # e' = (1 - G_inf e - sum s_i) / (eta0 + 0); s_i' = G_i e' - s_i/tau_i
        def rhs(_, y):
            e, s = y[0], y[1:]
            de = (1.0 - mat.G_inf * e - s.sum()) / mat.eta0
            return np.concatenate(([de], G * de - s / tau))
        y0 = np.zeros(1 + len(arms))
    else:
        # instantaneous response e(0+) = 1/glassy; then e' from the constraint
        def rhs(_, y):
            s = y[1:]
            # sigma = G_inf e + sum s_i = 1 with s_i' = G_i e' - s_i/tau_i
            de = np.sum(s / tau) / glassy
            return np.concatenate(([de], G * de - s / tau))
        y0 = np.concatenate(([1.0 / glassy], G / glassy))
    t = np.geomspace(t_end * 1e-6, t_end, n)
    # not stiff over t_end for the materials checked here (their times are a tenth of it):
    # the explicit DOP853 needs 740 evaluations where the implicit Radau took 8000 (to 1e-10)
    sol = solve_ivp(rhs, (0.0, t_end), y0, method="DOP853", t_eval=t, rtol=1e-10, atol=1e-20)
    return t, sol.y[0]


def _creep_kelvin_voigt(mat, t):
    """Closed-form creep compliance of a Kelvin-Voigt body, 1/Pa."""
    return (1.0 - np.exp(-t * mat.G_inf / mat.eta0)) / mat.G_inf


def test_combined_material_creeps_as_the_two_bodies_together():
    """Direct time-domain simulation: under one stress the combined material's strain is the
    sum of the two bodies' strains (closed-form Kelvin-Voigt creep)."""
    mat = series_material(KV1, KV2)
    t, e = _creep_of_prony(mat, 2e-4)
    want = _creep_kelvin_voigt(KV1, t) + _creep_kelvin_voigt(KV2, t)
    np.testing.assert_allclose(e, want, rtol=1e-6)


def test_pair_material_uses_the_series_and_keeps_refusing_unequal_nu():
    assert pair_material(KV1, KV2) == series_material(KV1, KV2)
    with pytest.raises(v.InputError, match="equal nu.*different"):
        pair_material(KV1, v.Material.kelvin_voigt(nu=0.3, G=8e7, eta=400.0))
    with pytest.raises(ValueError, match="equal nu"):
        series_material(KV1, v.Material.kelvin_voigt(nu=0.3, G=8e7, eta=400.0))
