"""Gross slip in closed form (vimpact.lookup.friction) against direct simulation."""

import numpy as np
import pytest

from vimpact.lookup.friction import chi, gross_slip_beta_x, gross_slip_onset


def test_elastic_onset_is_maw_barber_fawcett():
    # e_z = 1: psi_g = 4 chi, and beta_x = -1 + 4 chi / psi (psi_2 = psi_1 - 4 chi)
    for nu in (0.0, 0.3, 0.5):
        c = chi(nu)
        assert gross_slip_onset(1.0, nu) == pytest.approx(4.0 * c)
        assert gross_slip_beta_x(10.0, 1.0, nu) == pytest.approx(-1.0 + 4.0 * c / 10.0)
    assert np.isnan(gross_slip_beta_x(1.0, 1.0, 0.5))  # below the onset: no closed form


@pytest.mark.slow
def test_closed_form_matches_simulation_above_the_onset_only():
    """Kelvin-Voigt impacts at incidences around psi_g: above it the simulation's
    beta_x is the closed form and the contact slips throughout; below it, it is not,
    and beta_x is below the closed form (the Coulomb bound)."""
    from vimpact.tablebuild.verify import simulate_dimensionless

    q1, nu = 0.1, np.array([0.3, 0.5])
    normal = simulate_dimensionless("kelvin_voigt", np.full(2, q1), nu)
    e_z = normal["e_z"].to_numpy()
    onset = gross_slip_onset(e_z, nu)
    for factor in (1.02, 1.5, 3.0):
        sim = simulate_dimensionless("kelvin_voigt", np.full(2, q1), nu, psi=factor * onset,
                                     mu=0.3)
        np.testing.assert_allclose(sim["beta_x"].to_numpy(),
                                   gross_slip_beta_x(factor * onset, e_z, nu), atol=2e-4)
        assert np.all(sim["gross_slip_fraction"].to_numpy() > 0.99)
    # below the onset the contact sticks part of the time: the tangential impulse is
    # less than mu times the normal one (|F_x| <= mu F_z), so beta_x falls below the
    # closed form, which is its upper bound at every psi
    sim = simulate_dimensionless("kelvin_voigt", np.full(2, q1), nu, psi=0.8 * onset, mu=0.3)
    closed = -1.0 + onset / (0.8 * onset)
    assert np.all(sim["beta_x"].to_numpy() < closed - 1e-3)
    assert np.all(sim["gross_slip_fraction"].to_numpy() < 0.99)


@pytest.mark.slow
def test_gross_slip_starts_below_psi_g_and_the_closed_form_holds_from_there():
    """The kink where microslip meets gross slip (found by bisection on the simulated
    gross-slip fraction) is below psi_g; just above it the simulation is the closed
    form, just below it beta_x is under the closed form (the Coulomb bound)."""
    from vimpact.tablebuild.friction import gross_slip_start
    from vimpact.tablebuild.verify import simulate_dimensionless

    q1, nu = np.array([0.01, 0.1, 1.0]), np.array([0.3, 0.3, 0.5])
    found = gross_slip_start("kelvin_voigt", q1, nu, rel_tol=1e-3)
    psi_s, psi_g = found["psi_s"], found["psi_g"]
    assert np.all(psi_s < psi_g) and np.all(psi_s > 0.5 * psi_g)
    above = simulate_dimensionless("kelvin_voigt", q1, nu, psi=psi_s * 1.001, mu=0.3)
    np.testing.assert_allclose(above["beta_x"].to_numpy(),
                               -1.0 + psi_g / (psi_s * 1.001), atol=1e-6)
    below = simulate_dimensionless("kelvin_voigt", q1, nu, psi=psi_s * 0.99, mu=0.3)
    assert np.all(below["beta_x"].to_numpy() < -1.0 + psi_g / (psi_s * 0.99))
    assert np.all(below["gross_slip_fraction"].to_numpy() < 1.0)
