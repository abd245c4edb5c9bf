"""Prony fits to DMA and relaxation data against closed forms written out here.

The synthetic data are made in this file from the closed forms of a generalized
Maxwell solid (not with the package's own evaluation):

    G'(w)  = G_inf + sum g_i w^2 tau_i^2 / (1 + w^2 tau_i^2)
    G''(w) = sum g_i w tau_i / (1 + w^2 tau_i^2) (+ eta0 w)
    G(t)   = G_inf + sum g_i exp(-t / tau_i)
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from vimpact import InputError, Material, ShiftLaw
from vimpact.model.fit import relaxation_times

RNG = np.random.default_rng(5)
#: a known series: 19 times, 3 per decade from 1e-4 s to 1e2 s, moduli 2..10 MPa
TAUS = np.geomspace(1e-4, 1e2, 19)
G_ARMS = RNG.uniform(0.2, 1.0, TAUS.size) * 1e7
G_INF = 2.0e6
#: angular frequencies (rad/s) whose inverse spans exactly the known times
OMEGA = np.geomspace(1e-2, 1e4, 40)
TIMES = np.geomspace(1e-4, 1e2, 50)


def dynamic(omega, G_inf, arms, eta0=0.0):
    """G'(w), G''(w) in Pa of a generalized Maxwell solid (closed forms above)."""
    g = np.array([a[0] for a in arms])
    tau = np.array([a[1] for a in arms])
    wt = np.asarray(omega)[:, None] * tau[None, :]
    storage = G_inf + (g * wt**2 / (1.0 + wt**2)).sum(axis=1)
    loss = (g * wt / (1.0 + wt**2)).sum(axis=1) + eta0 * np.asarray(omega)
    return storage, loss


def relaxation(t, G_inf, arms):
    """G(t) in Pa (closed form above)."""
    return G_inf + sum(g * np.exp(-np.asarray(t) / tau) for g, tau in arms)


KNOWN = list(zip(G_ARMS, TAUS))


def rms_relative(model, data):
    return math.sqrt(np.mean(np.concatenate([(m / d - 1.0) for m, d in zip(model, data)])**2))


def test_relaxation_times_are_log_spaced_with_both_ends():
    taus = relaxation_times(1e-4, 1e2, 3)
    assert taus.size == 19 and taus[0] == pytest.approx(1e-4) and taus[-1] == pytest.approx(1e2)
    assert np.allclose(np.diff(np.log10(taus)), 1.0 / 3.0)


def test_dma_fit_recovers_a_series_on_its_time_grid():
    """Data from a series whose times are the fit's grid (3 per decade over 1/w_max ..
    1/w_min): the NNLS fit finds it back, residual at rounding."""
    storage, loss = dynamic(OMEGA, G_INF, KNOWN)
    mat, residual = Material.from_dma(OMEGA / (2 * np.pi), storage, loss, 0.5, per_decade=3)
    assert residual < 1e-10
    assert mat.model == "prony" and mat.G_inf == pytest.approx(G_INF, rel=1e-8)
    assert len(mat.arms) == TAUS.size
    for (G, tau), (G0, tau0) in zip(mat.arms, KNOWN):
        assert tau == pytest.approx(tau0, rel=1e-12) and G == pytest.approx(G0, rel=1e-8)


def test_dma_fit_of_a_finer_spectrum_reproduces_the_data():
    """Fewer times than the data's series (2 per decade against 3, and not on its
    times): the fit reproduces G' and G'' to within 1 % at every point, and its
    stated residual is the RMS relative misfit of both, recomputed here."""
    storage, loss = dynamic(OMEGA, G_INF, KNOWN)
    mat, residual = Material.from_dma(OMEGA / (2 * np.pi), storage, loss, 0.5, per_decade=2)
    fitted = dynamic(OMEGA, mat.G_inf, mat.arms)
    assert residual == pytest.approx(rms_relative(fitted, (storage, loss)), rel=1e-9)
    assert residual < 5e-3
    assert np.abs(fitted[0] / storage - 1).max() < 0.01
    assert np.abs(fitted[1] / loss - 1).max() < 0.01
    assert mat.G_inf > 0 and all(G > 0 and tau > 0 for G, tau in mat.arms)


def test_dma_fit_with_a_dashpot():
    storage, loss = dynamic(OMEGA, G_INF, KNOWN, eta0=30.0)
    mat, residual = Material.from_dma(OMEGA / (2 * np.pi), storage, loss, 0.5, per_decade=3,
                                      dashpot=True)
    assert residual < 1e-10 and mat.eta0 == pytest.approx(30.0, rel=1e-6)
    without, res2 = Material.from_dma(OMEGA / (2 * np.pi), storage, loss, 0.5, per_decade=3)
    assert without.eta0 == 0.0 and res2 > 1e3 * residual


def test_noisy_data_give_non_negative_moduli_and_a_residual_at_the_noise():
    """1 % multiplicative scatter: every modulus stays > 0 (NNLS), the residual is
    of the order of the scatter (between 0.5 and 2 times its RMS)."""
    rng = np.random.default_rng(1)
    storage, loss = dynamic(OMEGA, G_INF, KNOWN)
    noisy = [x * np.exp(0.01 * rng.standard_normal(x.size)) for x in (storage, loss)]
    mat, residual = Material.from_dma(OMEGA / (2 * np.pi), *noisy, 0.5, per_decade=2)
    assert mat.G_inf > 0 and all(G > 0 for G, _ in mat.arms)
    assert 0.005 < residual < 0.02


def test_relaxation_fit_recovers_a_series_on_its_time_grid():
    G = relaxation(TIMES, G_INF, KNOWN)
    mat, residual = Material.from_relaxation(TIMES, G, 0.45, per_decade=3)
    assert residual < 1e-9 and mat.nu == 0.45
    assert mat.G_inf == pytest.approx(G_INF, rel=1e-6)
    recovered = dict((round(math.log10(tau) * 3), G) for G, tau in mat.arms)
    for G0, tau0 in KNOWN:
        assert recovered[round(math.log10(tau0) * 3)] == pytest.approx(G0, rel=1e-5)


def test_relaxation_fit_of_a_finer_spectrum_reproduces_the_data():
    """2 per decade over a wider span (1e-5 .. 1e3 s) than the data's 3 per decade:
    G(t) within 2 % at every time, residual as stated."""
    t = np.geomspace(1e-5, 1e3, 50)
    G = relaxation(t, G_INF, KNOWN)
    mat, residual = Material.from_relaxation(t, G, 0.45, per_decade=2)
    fitted = relaxation(t, mat.G_inf, mat.arms)
    assert residual == pytest.approx(math.sqrt(np.mean((fitted / G - 1) ** 2)), rel=1e-9)
    assert residual < 5e-3 and np.abs(fitted / G - 1).max() < 0.02
    assert mat.G_inf > 0 and all(g > 0 for g, _ in mat.arms)


def test_the_fit_carries_the_shift_law():
    storage, loss = dynamic(OMEGA, G_INF, KNOWN)
    law = ShiftLaw.wlf(250.0)
    mat, _ = Material.from_dma(OMEGA / (2 * np.pi), storage, loss, 0.5, shift=law)
    assert mat.shift == law


def test_unordered_data_are_fitted_like_ordered_data():
    storage, loss = dynamic(OMEGA, G_INF, KNOWN)
    order = RNG.permutation(OMEGA.size)
    a = Material.from_dma(OMEGA / (2 * np.pi), storage, loss, 0.5)
    b = Material.from_dma((OMEGA / (2 * np.pi))[order], storage[order], loss[order], 0.5)
    assert a.material == b.material


@pytest.mark.parametrize("change, name", [
    (lambda f, s, l: (np.r_[-1.0, f[1:]], s, l), "frequency_Hz[0]"),
    (lambda f, s, l: (f, s[:-1], l), "lengths"),
    (lambda f, s, l: (f, np.r_[s[:3], np.nan, s[4:]], l), "storage_Pa[3]"),
    (lambda f, s, l: (f, s, np.r_[l[:5], np.inf, l[6:]]), "loss_Pa[5]"),
    (lambda f, s, l: (f, s, -l), "loss_Pa[0]"),
    (lambda f, s, l: (f[:2], s[:2], l[:2]), "frequency_Hz (number of distinct values)"),
    (lambda f, s, l: (np.full_like(f, 3.0), s, l), "frequency_Hz (number of distinct values)"),
    (lambda f, s, l: (f[::8], s[::8], l[::8]), "frequency_Hz (number of points)"),
    (lambda f, s, l: (f[None, :], s, l), "frequency_Hz"),
    (lambda f, s, l: ("abc", s, l), "frequency_Hz"),
])
def test_bad_dma_data_are_refused_naming_the_argument(change, name):
    storage, loss = dynamic(OMEGA, G_INF, KNOWN)
    f, s, l = change(OMEGA / (2 * np.pi), storage, loss)
    with pytest.raises(InputError) as exc:
        Material.from_dma(f, s, l, 0.5)
    assert str(exc.value).startswith(f"{name} = ")


def test_bad_fit_options_are_refused():
    storage, loss = dynamic(OMEGA, G_INF, KNOWN)
    with pytest.raises(InputError, match=r"^per_decade = 0 is not allowed"):
        Material.from_dma(OMEGA, storage, loss, 0.5, per_decade=0)
    with pytest.raises(InputError, match=r"^nu = 0.7 is not allowed"):
        Material.from_dma(OMEGA, storage, loss, 0.7)
    with pytest.raises(InputError, match=r"^time_s\[0\] = 0.0 is not allowed"):
        Material.from_relaxation(np.r_[0.0, TIMES[1:]], relaxation(TIMES, G_INF, KNOWN), 0.5)


def test_data_without_a_relaxed_plateau_are_refused():
    """A Maxwell fluid (G_inf = 0) has no relaxed modulus: the fit says so instead of
    returning a material that cannot exist (G_inf > 0 is required)."""
    storage, loss = dynamic(OMEGA, 0.0, KNOWN[:5])
    with pytest.raises(InputError, match="no relaxed plateau; add data at the lowest"):
        Material.from_dma(OMEGA / (2 * np.pi), storage, loss, 0.5, per_decade=3)
