"""Viscoelastic half-space materials (docs/physics.md#rheologies).

Every material is a generalized Maxwell solid with an optional parallel
dashpot, ``G(t) = G_inf + sum_i G_i exp(-t/tau_i) (+ eta0 delta(t))``, and a
constant Poisson ratio ``nu``. The named rheologies are constructors that
fill in this one form. A material may carry a temperature shift law
(:class:`~vimpact.model.temperature.ShiftLaw`, docs/physics.md#temperature):
:meth:`Material.at_temperature` gives the material at another temperature.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import TYPE_CHECKING, TypeVar, cast

import numpy as np

from vimpact.model.temperature import ShiftLaw
from vimpact.model.validation import non_negative, poisson_ratio, positive, require

if TYPE_CHECKING:  # the fit loads scipy: only when asked
    from vimpact.model.fit import PronyFit

MODELS = ("elastic", "kelvin_voigt", "standard_solid", "prony")


#: A modulus or Poisson ratio: one number, or one per row (elementwise)
_Value = TypeVar("_Value", float, np.ndarray)


def shear_modulus(E: _Value, nu: _Value | float) -> _Value:
    """Shear modulus ``G = E / (2 (1 + nu))`` in Pa from Young's modulus ``E`` in Pa.

    Elementwise for arrays of ``E`` (Pa) and ``nu`` (dimensionless).
    """
    return E / (2.0 * (1.0 + nu))


def _modulus(G, E, nu, name="G"):
    require(f"{name} and E", (G, E), (G is None) != (E is None), "exactly one of them given")
    return positive(name, G) if G is not None else shear_modulus(positive("E", E), nu)


@dataclass(frozen=True)
class Material:
    """A viscoelastic half-space.

    Attributes
    ----------
    model : one of ``MODELS``
    nu : Poisson ratio, dimensionless, in [0, 0.5]
    G_inf : relaxed (long-time) shear modulus, Pa
    arms : Maxwell arms ``((G_i [Pa], tau_i [s]), ...)``
    eta0 : parallel dashpot viscosity, Pa s
    shift : how its times shift with temperature (its reference temperature ``T_ref``
        in K, WLF or Arrhenius), or ``None`` (no temperature dependence given)
    """

    model: str
    nu: float
    G_inf: float
    arms: tuple[tuple[float, float], ...] = ()
    eta0: float = 0.0
    shift: ShiftLaw | None = None

    def __post_init__(self):
        require("model", self.model, self.model in MODELS, "one of " + ", ".join(MODELS))
        poisson_ratio("nu", self.nu)
        positive("G_inf", self.G_inf)
        non_negative("eta0", self.eta0)
        require("arms", self.arms, isinstance(self.arms, (tuple, list)),
                "a sequence of pairs (G_i [Pa], tau_i [s])")
        for i, arm in enumerate(self.arms):
            require(f"arm {i + 1}", arm, isinstance(arm, (tuple, list)) and len(arm) == 2,
                    "a pair (G_i [Pa], tau_i [s])")
            positive(f"G_{i + 1} (arm {i + 1} modulus, Pa)", arm[0])
            positive(f"tau_{i + 1} (arm {i + 1} relaxation time, s)", arm[1])
        # the model names the rheology (and how Q1, Q2 are reported): it must fit it
        fits = {"elastic": (not self.arms and self.eta0 == 0.0, "no arms and eta0 = 0"),
                "kelvin_voigt": (not self.arms, "no Maxwell arms"),
                "standard_solid": (len(self.arms) <= 1 and self.eta0 == 0.0,
                                   "at most one Maxwell arm and eta0 = 0"),
                "prony": (True, "")}
        ok, what = fits[self.model]
        require("model", self.model, ok, f"a rheology with {what} (given {len(self.arms)} "
                f"arms, eta0 = {self.eta0:g} Pa s)")
        require("shift", self.shift, self.shift is None or isinstance(self.shift, ShiftLaw),
                "None or a ShiftLaw (vimpact.model.temperature)")

    # ---- constructors -------------------------------------------------
    @classmethod
    def elastic(cls, nu: float, G: float | None = None, E: float | None = None) -> Material:
        """Elastic half-space with shear modulus ``G`` or Young's modulus ``E`` (Pa)."""
        nu = poisson_ratio("nu", nu)
        return cls("elastic", nu, _modulus(G, E, nu))

    @classmethod
    def kelvin_voigt(cls, nu: float, eta: float, G: float | None = None,
                     E: float | None = None) -> Material:
        """Kelvin-Voigt body: spring ``G`` (or ``E``, Pa) parallel to a dashpot ``eta`` (Pa s)."""
        nu = poisson_ratio("nu", nu)
        return cls("kelvin_voigt", nu, _modulus(G, E, nu), (), non_negative("eta", eta))

    @classmethod
    def standard_solid(cls, nu: float, G1: float, G2: float, eta: float) -> Material:
        """Return a standard linear solid.

        Spring ``G1`` parallel to a Maxwell arm (spring ``G2``, dashpot ``eta``). Moduli
        in Pa, ``eta`` in Pa s; arm time ``tau = eta / G2``.
        """
        nu = poisson_ratio("nu", nu)
        G1, G2 = positive("G1", G1), positive("G2", G2)
        eta = non_negative("eta", eta)
        if eta == 0.0:  # an arm with no dashpot carries no force
            return cls("standard_solid", nu, G1)
        return cls("standard_solid", nu, G1, ((G2, eta / G2),))

    @classmethod
    def prony(cls, nu: float, G_inf: float, arms, eta0: float = 0.0) -> Material:
        """Return a Prony series material.

        Prony series: relaxed modulus ``G_inf`` (Pa), arms ``[(G_i [Pa], tau_i [s]), ...]``,
        optional parallel dashpot ``eta0`` (Pa s).
        """
        nu = poisson_ratio("nu", nu)
        require("arms", arms, isinstance(arms, (tuple, list)),
                "a list of pairs (G_i [Pa], tau_i [s])")
        checked = []
        for i, arm in enumerate(arms, start=1):
            require(f"arm {i}", arm, isinstance(arm, (tuple, list)) and len(arm) == 2,
                    "a pair (G_i [Pa], tau_i [s])")
            checked.append((positive(f"G_{i} (arm {i} modulus, Pa)", arm[0]),
                            positive(f"tau_{i} (arm {i} relaxation time, s)", arm[1])))
        return cls("prony", nu, positive("G_inf", G_inf), tuple(checked), non_negative("eta0", eta0))

    @classmethod
    def from_dma(cls, frequency_Hz, storage_Pa, loss_Pa, nu: float, *,
                 per_decade: float = 2.0, dashpot: bool = False,
                 shift: ShiftLaw | None = None) -> PronyFit:
        """Return a Prony material fitted to a dynamic (DMA) master curve of the shear moduli.

        Non-negative least squares on log-spaced relaxation times
        (:func:`vimpact.model.fit.fit_dma`); returns ``(material, residual)``, the
        residual being the RMS relative misfit of ``G'`` and ``G''`` (dimensionless).

        Parameters
        ----------
        frequency_Hz : frequencies ``f`` (Hz, > 0; ``omega = 2 pi f``)
        storage_Pa, loss_Pa : shear storage and loss moduli ``G'``, ``G''`` at ``f``, Pa
        nu : Poisson ratio, dimensionless, in [0, 0.5]
        per_decade : relaxation times per decade of the data's span (default 2,
            :data:`vimpact.model.fit.DEFAULT_PER_DECADE`)
        dashpot : fit a parallel dashpot ``eta0`` (a loss ``G'' ~ eta0 omega``) too
        shift : the material's temperature shift law (``T_ref``: the master curve's)
        """
        from vimpact.model.fit import fit_dma
        return fit_dma(frequency_Hz, storage_Pa, loss_Pa, nu, per_decade=per_decade,
                       dashpot=dashpot, shift=shift)

    @classmethod
    def from_relaxation(cls, time_s, modulus_Pa, nu: float, *, per_decade: float = 2.0,
                        shift: ShiftLaw | None = None) -> PronyFit:
        """Return a Prony material fitted to a shear relaxation modulus ``G(t)`` (Pa at ``t`` in s).

        Non-negative least squares on log-spaced relaxation times
        (:func:`vimpact.model.fit.fit_relaxation`); returns ``(material, residual)``,
        the residual being the RMS relative misfit of ``G(t)`` (dimensionless).
        Other parameters as :meth:`from_dma`.
        """
        from vimpact.model.fit import fit_relaxation
        return fit_relaxation(time_s, modulus_Pa, nu, per_decade=per_decade, shift=shift)

    # ---- temperature --------------------------------------------------
    def with_shift(self, shift: ShiftLaw | None) -> Material:
        """Return this material with the temperature shift law ``shift``.

        This material with the temperature shift law ``shift`` (its ``T_ref`` is the
        temperature of this material's times).
        """
        return dataclasses.replace(self, shift=shift)

    def at_temperature(self, T: float) -> Material:
        """Return this material at the temperature ``T`` (K).

        Every relaxation time and the dashpot viscosity times the shift factor ``a_T`` of
        :attr:`shift`, moduli unchanged; the result's shift law is referenced to ``T``.

        Raises :class:`~vimpact.model.validation.InputError` for ``T <= 0 K``, a
        ``T`` outside the law's range, or a material without a shift law.
        """
        require("temperature (K)", T, self.shift is not None,
                "used only with a material that has a temperature shift law (T_ref and "
                "WLF or Arrhenius constants)")
        shift = cast(ShiftLaw, self.shift)  # checked above
        a_T = shift.shift_factor(T)
        arms = tuple((G, a_T * tau) for G, tau in self.arms)
        for i, (_, tau) in enumerate(arms, start=1):
            positive(f"tau_{i} at temperature {T!r} K (arm {i} relaxation time a_T tau_i, s; "
                     f"a_T = {a_T:.4g})", tau)
        return dataclasses.replace(self, arms=arms, eta0=a_T * self.eta0,
                                   shift=shift.referenced_to(T))

    # ---- derived ------------------------------------------------------
    @property
    def glassy_modulus(self) -> float:
        """Instantaneous shear modulus ``G_inf + sum G_i``, Pa."""
        return self.G_inf + sum(G for G, _ in self.arms)

    @property
    def kappa(self) -> float:
        """Tangential over normal element stiffness ``c_t / c_n``, dimensionless.

        Tangential over normal element stiffness ``c_t / c_n = 2 (1 - nu) / (2 - nu)``
        (docs/physics.md#method-of-dimensionality-reduction), dimensionless.
        """
        return 2.0 * (1.0 - self.nu) / (2.0 - self.nu)

    @property
    def dashpot_time(self) -> float:
        """``eta0 / G_inf``, s."""
        return self.eta0 / self.G_inf

    @property
    def q2(self) -> float:
        """``Q2 = G1 / G2`` for a standard solid, NaN otherwise (inf without arm)."""
        if self.model != "standard_solid":
            return float("nan")
        return self.G_inf / self.arms[0][0] if self.arms else float("inf")

    def viscous_time(self) -> float:
        """Return the time ``eta / G_inf`` that defines ``Q1`` (s).

        The dashpot of a Kelvin-Voigt body, the arm dashpot of a standard solid over
        ``G1``; 0 for an elastic body, NaN for a general Prony series.
        """
        if self.model in ("elastic", "kelvin_voigt"):
            return self.dashpot_time
        if self.model == "standard_solid":
            if not self.arms:
                return 0.0
            G2, tau = self.arms[0]
            return G2 * tau / self.G_inf
        return float("nan")
