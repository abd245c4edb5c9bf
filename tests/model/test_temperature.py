"""Shift factors (WLF, Arrhenius) against hand-computed values; a material at a
temperature is the same material with its times scaled by a_T."""

from __future__ import annotations

import dataclasses
import math

import pytest

import vimpact as v
from vimpact import InputError, Material, ShiftLaw
from vimpact.model.temperature import GAS_CONSTANT


def test_wlf_against_hand_computed_values():
    """Universal constants at T_ref = 220 K, T = 270 K: log10 a_T = -17.44 * 50 / 101.6
    = -8.58267716535... (by hand: 872 / 101.6)."""
    law = ShiftLaw.wlf(220.0, 17.44, 51.6)
    assert law.log10_shift(270.0) == pytest.approx(-8.582677165354331, rel=1e-13)
    assert law.shift_factor(270.0) == pytest.approx(2.6142e-9, rel=1e-4)
    # 10 K below T_ref: log10 a_T = 174.4 / 41.6 = 4.1923...: slower relaxation
    assert law.log10_shift(210.0) == pytest.approx(4.192307692307692, rel=1e-13)
    assert law.shift_factor(210.0) > 1.0


def test_arrhenius_against_hand_computed_values():
    """E_a = 100 kJ/mol, T_ref = 300 K, T = 330 K: ln a_T = -E_a (T - T_ref) / (R T T_ref)
    = -1e5 * 30 / (8.314462618 * 330 * 300) = -3.6446..."""
    law = ShiftLaw.arrhenius(300.0, 1.0e5)
    expected = -1.0e5 * 30.0 / (8.314462618 * 330.0 * 300.0)
    assert expected == pytest.approx(-3.64461, abs=1e-5)
    assert math.log(law.shift_factor(330.0)) == pytest.approx(expected, rel=1e-12)
    assert law.log10_shift(330.0) == pytest.approx(expected / math.log(10.0), rel=1e-12)
    assert GAS_CONSTANT == 8.314462618


@pytest.mark.parametrize("law", [ShiftLaw.wlf(220.0), ShiftLaw.arrhenius(300.0, 8e4)])
def test_the_shift_factor_is_one_at_the_reference_temperature(law):
    assert law.shift_factor(law.T_ref) == 1.0
    assert law.log10_shift(law.T_ref) == 0.0


@pytest.mark.parametrize("law", [ShiftLaw.wlf(220.0), ShiftLaw.arrhenius(300.0, 8e4)])
def test_shifting_twice_is_shifting_once(law):
    """A material shifted to T1 carries its law referenced to T1; shifting it on to T2
    gives the material shifted to T2 directly (the WLF re-referencing
    C1' = C1 C2 / (C2 + T1 - T_ref), C2' = C2 + T1 - T_ref is exact)."""
    mat = Material.prony(nu=0.5, G_inf=1e6, arms=[(1e7, 1e-3), (1e8, 1e-6)]).with_shift(law)
    T1, T2 = law.T_ref + 15.0, law.T_ref + 40.0
    a = mat.at_temperature(T1).at_temperature(T2)
    b = mat.at_temperature(T2)
    for (Ga, ta), (Gb, tb) in zip(a.arms, b.arms):
        assert Ga == Gb and ta == pytest.approx(tb, rel=1e-12)
    assert a.shift.T_ref == b.shift.T_ref == T2
    assert a.shift.shift_factor(T1) == pytest.approx(law.shift_factor(T1) / law.shift_factor(T2),
                                                     rel=1e-12)


def test_below_the_reference_temperature_relaxation_is_slower():
    """tau(T) = a_T tau(T_ref), a_T > 1 below T_ref; moduli and nu unchanged, the
    dashpot viscosity scales with the times (eta0 / G_inf is a time)."""
    law = ShiftLaw.wlf(250.0)
    mat = Material.prony(nu=0.45, G_inf=1e6, arms=[(1e7, 1e-3)], eta0=2.0).with_shift(law)
    cold, warm = mat.at_temperature(240.0), mat.at_temperature(260.0)
    assert cold.arms[0][1] > 1e-3 > warm.arms[0][1]
    a_T = law.shift_factor(240.0)
    assert cold.arms[0] == (1e7, a_T * 1e-3) and cold.eta0 == a_T * 2.0
    assert (cold.G_inf, cold.nu, cold.glassy_modulus) == (mat.G_inf, mat.nu, mat.glassy_modulus)


def _scene(material):
    return v.Scene(material, R=0.01, m=0.004, v_z0=0.5)


def test_a_material_at_a_temperature_simulates_like_its_hand_scaled_times():
    """The same simulate() result, bit for bit, as the material built by hand with
    tau_i -> a_T tau_i and eta0 -> a_T eta0, a_T from the WLF formula written here.
    Arms near the contact time: the full-stick continuum kernel runs."""
    C1, C2, T_ref, T = 17.44, 51.6, 250.0, 262.0
    arms = [(2e7, 3e-3), (1e7, 3e-2)]
    mat = Material.prony(nu=0.49, G_inf=5e6, arms=arms).with_shift(ShiftLaw.wlf(T_ref, C1, C2))
    dT = T - T_ref
    a_T = 10.0 ** (-C1 * dT / (C2 + dT))
    by_hand = Material.prony(nu=0.49, G_inf=5e6, arms=[(G, a_T * tau) for G, tau in arms])
    numerics = v.Numerics.preset("fast")
    got = v.simulate(_scene(mat.at_temperature(T)), numerics)
    want = v.simulate(_scene(by_hand), numerics)
    assert got.path == want.path and got.path.startswith("continuum")
    assert got.e_z == want.e_z and got.t_contact == want.t_contact
    # and the temperature matters: the material at T_ref gives another e_z
    assert v.simulate(_scene(mat), numerics).e_z != pytest.approx(got.e_z, abs=1e-3)


@pytest.mark.parametrize("T, match", [
    (0.0, "must be an absolute temperature in kelvin"),
    (-10.0, "must be an absolute temperature in kelvin"),
    (float("nan"), "must be an absolute temperature in kelvin"),
    (True, "must be an absolute temperature in kelvin"),
    (160.0, r"must be above T_ref - C2 = 168.4 K"),
])
def test_bad_temperatures_are_refused(T, match):
    mat = Material.prony(nu=0.5, G_inf=1e6, arms=[(1e7, 1e-3)]).with_shift(ShiftLaw.wlf(220.0))
    with pytest.raises(InputError, match=match) as exc:
        mat.at_temperature(T)
    assert str(exc.value).startswith("temperature (K) = ")


def test_a_temperature_needs_a_shift_law():
    with pytest.raises(InputError, match="only with a material that has a temperature shift law"):
        Material.prony(nu=0.5, G_inf=1e6, arms=[(1e7, 1e-3)]).at_temperature(300.0)


@pytest.mark.parametrize("make, name", [
    (lambda: ShiftLaw("vogel", 300.0), "shift law"),
    (lambda: ShiftLaw.wlf(-5.0), "T_ref (reference temperature, K)"),
    (lambda: ShiftLaw.wlf(220.0, -17.44, 51.6), "C1 (WLF constant)"),
    (lambda: ShiftLaw.wlf(220.0, 17.44, 0.0), "C2 (WLF constant, K)"),
    (lambda: ShiftLaw.arrhenius(300.0, -1.0), "E_a (activation energy, J/mol)"),
])
def test_bad_shift_laws_are_refused(make, name):
    with pytest.raises(InputError) as exc:
        make()
    assert str(exc.value).startswith(f"{name} = ")


def test_the_shift_law_leaves_equality_of_the_physics_alone():
    """A material with a shift law is a different value (it says how it shifts), but
    replacing the law keeps every physical field."""
    mat = Material.prony(nu=0.5, G_inf=1e6, arms=[(1e7, 1e-3)])
    with_law = mat.with_shift(ShiftLaw.wlf(220.0))
    assert with_law != mat and dataclasses.replace(with_law, shift=None) == mat
