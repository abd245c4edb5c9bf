"""Time-temperature superposition: shift factors of a thermorheologically simple material.

A thermorheologically simple material has at temperature ``T`` the relaxation
function of its reference temperature ``T_ref`` on a stretched time axis:
every relaxation time (and the dashpot time ``eta0 / G_inf``) is multiplied by
the shift factor ``a_T``, the moduli are unchanged,

    tau_i(T) = a_T tau_i(T_ref),    eta0(T) = a_T eta0(T_ref).

``a_T > 1`` below ``T_ref`` (slower relaxation, a stiffer, glassier material
on a given time scale), ``a_T < 1`` above it, ``a_T(T_ref) = 1``. Two laws
(docs/physics.md#temperature):

- WLF (Williams-Landel-Ferry): ``log10 a_T = -C1 (T - T_ref) / (C2 + T - T_ref)``,
  valid above about the glass transition; refused where ``C2 + T - T_ref <= 0``
  (the law diverges there). The "universal" constants are ``C1 = 17.44``,
  ``C2 = 51.6 K`` with ``T_ref = T_g``.
- Arrhenius: ``ln a_T = (E_a / R) (1/T - 1/T_ref)`` with the activation
  energy ``E_a`` in J/mol and the gas constant ``R`` (:data:`GAS_CONSTANT`).

Temperatures are absolute, in kelvin, everywhere (> 0 K).
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass

from vimpact.model.validation import non_negative, positive, require

#: Molar gas constant R, J/(mol K) (exact since the 2019 SI redefinition).
GAS_CONSTANT = 8.314462618
#: The shift laws, by name.
LAWS = ("wlf", "arrhenius")
#: The "universal" WLF constants with T_ref = T_g (Williams, Landel and Ferry, 1955):
#: C1 (dimensionless) and C2 (K).
UNIVERSAL_WLF = (17.44, 51.6)


def temperature(name: str, value) -> float:
    """Return an absolute temperature in kelvin as a float: a finite number > 0 K."""
    ok = isinstance(value, numbers.Real) and not isinstance(value, bool) \
        and math.isfinite(float(value)) and float(value) > 0.0
    require(name, value, ok, "an absolute temperature in kelvin, a finite number > 0")
    return float(value)


@dataclass(frozen=True)
class ShiftLaw:
    """How the relaxation times of a material shift with temperature.

    Attributes
    ----------
    law : ``"wlf"`` or ``"arrhenius"``
    T_ref : reference temperature of the material's Prony series, K
    C1 : WLF constant, dimensionless (``law == "wlf"``; else 0)
    C2 : WLF constant, K (``law == "wlf"``; else 0)
    E_a : activation energy, J/mol (``law == "arrhenius"``; else 0)
    """

    law: str
    T_ref: float
    C1: float = 0.0
    C2: float = 0.0
    E_a: float = 0.0

    def __post_init__(self):
        require("shift law", self.law, self.law in LAWS, "one of " + ", ".join(map(repr, LAWS)))
        temperature("T_ref (reference temperature, K)", self.T_ref)
        if self.law == "wlf":
            positive("C1 (WLF constant)", self.C1)
            positive("C2 (WLF constant, K)", self.C2)
            require("E_a (activation energy, J/mol)", self.E_a, self.E_a == 0.0,
                    "0 for the WLF law (it is an Arrhenius constant)")
        else:
            non_negative("E_a (activation energy, J/mol)", self.E_a)
            require("C1, C2 (WLF constants)", (self.C1, self.C2), self.C1 == self.C2 == 0.0,
                    "0 for the Arrhenius law (they are WLF constants)")

    @classmethod
    def wlf(cls, T_ref: float, C1: float = UNIVERSAL_WLF[0],
            C2: float = UNIVERSAL_WLF[1]) -> ShiftLaw:
        """WLF law at ``T_ref`` (K) with ``C1`` (dimensionless) and ``C2`` (K).

        The defaults are the universal constants, meant for ``T_ref = T_g``.
        """
        return cls("wlf", float(T_ref), C1=float(C1), C2=float(C2))

    @classmethod
    def arrhenius(cls, T_ref: float, E_a: float) -> ShiftLaw:
        """Arrhenius law at ``T_ref`` (K) with activation energy ``E_a`` (J/mol)."""
        return cls("arrhenius", float(T_ref), E_a=float(E_a))

    def log10_shift(self, T: float) -> float:
        """``log10 a_T`` at the temperature ``T`` (K); dimensionless.

        Raises :class:`~vimpact.model.validation.InputError` for ``T <= 0 K`` and, for
        WLF, where ``C2 + T - T_ref <= 0`` (below ``T_ref - C2`` the law diverges).
        """
        T = temperature("temperature (K)", T)
        if self.law == "wlf":
            dT = T - self.T_ref
            require("temperature (K)", T, self.C2 + dT > 0.0,
                    f"above T_ref - C2 = {self.T_ref - self.C2:g} K, where the WLF law "
                    f"(T_ref = {self.T_ref:g} K, C2 = {self.C2:g} K) is defined")
            return -self.C1 * dT / (self.C2 + dT)
        return self.E_a / GAS_CONSTANT * (1.0 / T - 1.0 / self.T_ref) / math.log(10.0)

    def shift_factor(self, T: float) -> float:
        """Return the shift factor ``a_T`` at ``T`` (K): ``tau(T) = a_T tau(T_ref)``; dimensionless.

        Refuses (``InputError``) a temperature where ``a_T`` leaves the float range.
        """
        log10_a = self.log10_shift(T)
        require("temperature (K)", T, abs(log10_a) < 300.0,
                f"a temperature whose shift factor fits a float (log10 a_T = {log10_a:.4g})")
        if self.law == "wlf":
            return 10.0 ** log10_a
        return math.exp(self.E_a / GAS_CONSTANT * (1.0 / T - 1.0 / self.T_ref))

    def referenced_to(self, T: float) -> ShiftLaw:
        """Return the same law with ``T`` (K) as its reference temperature.

        For a material already shifted to ``T``. For WLF ``C1' = C1 C2 / (C2 + T -
        T_ref)`` and ``C2' = C2 + T - T_ref``, which give the same shift between any two
        temperatures.
        """
        self.log10_shift(T)  # refuses T outside the law's range
        if self.law == "wlf":
            c2 = self.C2 + (T - self.T_ref)
            return ShiftLaw.wlf(T, self.C1 * self.C2 / c2, c2)
        return ShiftLaw.arrhenius(T, self.E_a)

    def describe(self) -> str:
        """One line: the law, its constants and units."""
        if self.law == "wlf":
            return (f"WLF, T_ref = {self.T_ref:g} K, C1 = {self.C1:g}, C2 = {self.C2:g} K")
        return f"Arrhenius, T_ref = {self.T_ref:g} K, E_a = {self.E_a:g} J/mol"


__all__ = ["GAS_CONSTANT", "LAWS", "ShiftLaw", "UNIVERSAL_WLF", "temperature"]
