"""Numerics of the element kernel as a value object with named presets."""

from __future__ import annotations

from dataclasses import dataclass, replace

from .core.impact import EULER, VERLET
from .validation import one_of, positive, require

INTEGRATORS = {"euler": EULER, "verlet": VERLET}


@dataclass(frozen=True)
class Numerics:
    """How an impact is discretized.

    Attributes
    ----------
    integrator : ``"verlet"`` (default: second order, dashpot implicit) or
        ``"euler"`` (the thesis's explicit Euler, first order)
    steps : time steps per Hertz contact time ``t_H`` (of the relaxed modulus)
    elements : elements per Hertz contact radius ``a_H`` on the half row
    row_width : length of the half row, in units of ``a_H`` (>= 1; the
        contact of a passive material never exceeds ``a_H``, and reaching
        the end of the row stops the run with status ``row_exceeded``)
    max_time : time limit in units of ``t_H (1 + 10 t_v / T)`` with the
        viscous time ``t_v = (eta0 + sum G_i tau_i) / G_inf`` (capped at 1e4);
        an impact still running then ends with status ``time_limit``
    """

    integrator: str = "verlet"
    steps: int = 1000
    elements: int = 200
    row_width: float = 1.05
    max_time: float = 100.0

    def __post_init__(self):
        one_of("integrator", self.integrator, tuple(INTEGRATORS))
        for name in ("steps", "elements"):
            value = getattr(self, name)
            require(name, value, isinstance(value, int) and value >= 4, "an integer >= 4")
        require("row_width", self.row_width, positive("row_width", self.row_width) >= 1.0, ">= 1")
        positive("max_time", self.max_time)

    @classmethod
    def preset(cls, name: str) -> "Numerics":
        """Named settings: ``default`` (about 1e-4 on e_z, e_x), ``fast``
        (about 1e-3) and ``thesis`` (explicit Euler, 5000 steps per t_H,
        1000 elements across the contact diameter, as in the thesis)."""
        one_of("numerics preset", name, tuple(PRESETS))
        return PRESETS[name]

    def with_(self, **changes) -> "Numerics":
        """A copy with some fields changed (validated)."""
        return replace(self, **changes)

    @property
    def integrator_code(self) -> int:
        return INTEGRATORS[self.integrator]


PRESETS = {
    "default": Numerics(),
    "fast": Numerics(steps=400, elements=80),
    "thesis": Numerics(integrator="euler", steps=5000, elements=500),
}
