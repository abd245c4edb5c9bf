"""Numerics of the element kernel as a value object with named presets."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from vimpact.model.validation import one_of, positive, require

#: Integrators by name (see :mod:`vimpact.kernels.elements`) and their nominal order.
#: The numbers are the kernels' integrator codes (``EULER``, ``SYMPLECTIC_EULER``,
#: ``VERLET`` of :mod:`vimpact.kernels.layout`), written out because the model
#: imports no other folder; ``tests/model/test_numerics_codes.py`` checks they agree.
INTEGRATORS = {"euler": 0, "symplectic_euler": 1, "verlet": 2}
ORDER = {"euler": 1, "symplectic_euler": 1, "verlet": 2}


@dataclass(frozen=True)
class Numerics:
    """How an impact is discretized.

    Attributes
    ----------
    integrator : ``"verlet"`` (default: second order, dashpot implicit),
        ``"symplectic_euler"`` (first order, dashpot implicit) or ``"euler"``
        (the thesis's explicit Euler, first order)
    steps : time steps per Hertz contact time ``t_H`` (of the relaxed
        modulus); the step is shortened further for a stiffer tangential
        mode and for explicit Euler's stability (``vimpact.engine.routing.refinement``)
    elements : elements per Hertz contact radius ``a_H`` on the half row
    row_width : length of the half row, in units of ``a_H`` (>= 1; the
        contact of a passive material never exceeds ``a_H``, and reaching
        the end of the row stops the run with status ``row_exceeded``)
    max_time : time limit in units of ``t_H (1 + 10 t_v / T)`` with the
        viscous time ``t_v = (eta0 + sum G_i tau_i) / G_inf`` (capped at 1e4);
        an impact still running then ends with status ``time_limit``
    continuum : take the continuum 1-DOF path for Kelvin-Voigt and elastic
        normal-only scenes (default ``True``; ``False`` forces elements)
    rtol : relative tolerance of the adaptive continuum paths
    tolerance : the accuracy on e_z and beta_x these numerics were chosen for
        (:meth:`for_tolerance`), or ``None``; a scene on the element path whose
        tolerance is below what that path reaches (:data:`ELEMENT_TOLERANCE_FLOOR`),
        or whose error the model does not bound (the seed memory,
        :data:`SEED_MEMORY_UNVERIFIED`), is refused (status
        ``tolerance_unreachable``), never reported as ``ok``
    """

    integrator: str = "verlet"
    steps: int = 1400
    elements: int = 200
    row_width: float = 1.05
    max_time: float = 100.0
    continuum: bool = True
    rtol: float = 1e-8
    tolerance: float | None = None

    def __post_init__(self):
        one_of("integrator", self.integrator, tuple(INTEGRATORS))
        for name in ("steps", "elements"):
            value = getattr(self, name)
            require(name, value, isinstance(value, int) and not isinstance(value, bool)
                    and 4 <= value <= MAX_SETTING[name],
                    f"an integer from 4 to {MAX_SETTING[name]:.0e}")
        require("row_width", self.row_width, positive("row_width", self.row_width) >= 1.0, ">= 1")
        positive("max_time", self.max_time)
        require("continuum", self.continuum, isinstance(self.continuum, bool), "True or False")
        require("rtol", self.rtol, 1e-14 <= positive("rtol", self.rtol) <= 1e-2,
                "between 1e-14 and 1e-2")
        if self.tolerance is not None:
            require("tolerance", self.tolerance,
                    1e-9 <= positive("tolerance", self.tolerance) <= 1e-2,
                    "between 1e-9 and 1e-2")

    @classmethod
    def for_tolerance(cls, tolerance: float, integrator: str = "verlet") -> Numerics:
        """Numerics that reach ``tolerance`` on e_z and beta_x on the path that runs.

        The continuum paths (every full-stick scene with incremental memory;
        the Kelvin-Voigt normal impact) get ``rtol = tolerance / 1000``: rtol
        bounds the local error of each step, and the measured global error is
        about 0.6 rtol on e_z and typically 3-30 rtol on beta_x, but up to 125
        rtol on beta_x for a standard solid with a stiff arm (Q2 = 0.01; random
        scenes against rtol 1e-13, tests/engine/test_tolerance.py); they cost
        microseconds to a fraction of a millisecond. The element path (friction,
        stiff arms, hand-overs) gets steps and elements from the
        error model measured against the continuum kernel by ``python -m
        benchmarks.element_orders`` (:data:`ERROR_MODEL`: an envelope ``a /
        steps^p + b / elements^q``), aimed at the tolerance divided by
        :data:`ERROR_MODEL_SAFETY`, half of that to the steps and what they leave
        to the elements, no coarser
        than the model's measured grid (:data:`MIN_MODEL_STEPS`,
        :data:`MIN_MODEL_ELEMENTS`) and capped at :data:`MAX_STEPS` and
        :data:`MAX_ELEMENTS`; a tolerance below what the capped element path
        reaches (:data:`ELEMENT_TOLERANCE_FLOOR`) is kept in ``tolerance`` and
        refused for the scenes that need elements (status
        ``tolerance_unreachable``, with the floor in the error column). The
        thesis's seed memory is refused at every tolerance: the model does not
        bound its error (:data:`SEED_MEMORY_UNVERIFIED`).

        Parameters
        ----------
        tolerance : target absolute error on e_z and beta_x, in [1e-9, 1e-2]
            (below 1e-9 the continuum paths cannot be verified in double precision)
        integrator : ``"verlet"`` (the model is measured for it)
        """
        tol = positive("tolerance", tolerance)
        require("tolerance", tolerance, 1e-9 <= tol <= 1e-2, "between 1e-9 and 1e-2")
        one_of("integrator", integrator, ("verlet",))
        m = ERROR_MODEL
        budget = tol / ERROR_MODEL_SAFETY
        steps = math.ceil((m["a"] / (budget / 2.0)) ** (1.0 / m["p"]))
        steps = int(min(max(steps, MIN_MODEL_STEPS), MAX_STEPS))
        # the elements take what the (capped or floored) steps leave of the budget
        rest = budget - m["a"] / steps ** m["p"]
        elements = math.ceil((m["b"] / rest) ** (1.0 / m["q"])) if rest > 0.0 else MAX_ELEMENTS
        return cls(integrator=integrator, steps=steps,
                   elements=int(min(max(elements, MIN_MODEL_ELEMENTS), MAX_ELEMENTS)),
                   rtol=min(max(tol * 1e-3, 1e-13), 1e-8), tolerance=tol)

    @property
    def element_tolerance_reachable(self) -> bool:
        """The element path reaches ``tolerance`` (always, without one)."""
        return self.tolerance is None or self.tolerance >= ELEMENT_TOLERANCE_FLOOR

    def element_refusal(self, path_name: str, seed_memory: bool) -> str | None:
        """Return why the element path must refuse these numerics' tolerance, or None.

        Why the element path ``path_name`` must refuse these numerics' tolerance
        (one line, for the error column), or ``None`` (no tolerance, or one the error
        model bounds there). ``seed_memory``: the path runs the tangential problem
        with the thesis's seed memory, which the model does not bound.
        """
        if not self.element_tolerance_reachable:
            return (f"tolerance = {self.tolerance:g} is not reachable on the element path "
                    f"this scene needs ({path_name}): the smallest it reaches is "
                    f"{ELEMENT_TOLERANCE_FLOOR:.2g}")
        if self.tolerance is not None and seed_memory:
            return SEED_MEMORY_UNVERIFIED.format(tolerance=self.tolerance)
        return None

    @classmethod
    def preset(cls, name: str) -> Numerics:
        """Named settings (:data:`PRESETS`).

        ``fast`` (2.3e-4 on e_z, e_x on the element path), ``default`` (3.1e-5 there),
        ``precise`` (1e-9 and better on the continuum paths; 4.9e-7 on the element path at
        its caps, the best it reaches; :meth:`for_tolerance` refuses less than twice that
        there, :data:`ELEMENT_TOLERANCE_FLOOR`) and ``thesis`` (explicit Euler, 5000 steps
        per t_H, 1000 elements across the contact diameter, as in the thesis). The element
        path figures are :data:`ERROR_MODEL` at the preset; measured largest errors
        against the continuum kernel on its eleven oblique scenes: 2.1e-4, 2.8e-5, 2.0e-7
        (``python -m benchmarks.element_orders``). They hold for the incremental memory,
        with or without friction; the seed memory converges more slowly
        (:data:`SEED_MEMORY_UNVERIFIED`).
        """
        one_of("numerics preset", name, tuple(PRESETS))
        return PRESETS[name]

    def with_(self, **changes) -> Numerics:
        """Return a copy with some fields changed (validated)."""
        return replace(self, **changes)

    @property
    def integrator_code(self) -> int:
        """The kernels' code of :attr:`integrator` (:data:`INTEGRATORS`)."""
        return INTEGRATORS[self.integrator]


#: Error model of the Verlet element path: ``max(|e_z err|, |e_x err|) <= a /
#: steps^p + b / elements^q``, the smallest envelope of this form over the errors
#: against the continuum kernel (rtol 1e-12) of eleven oblique scenes (Kelvin-Voigt
#: Q1 0.01..10, standard solids with Q1 0.03..30 and Q2 1e-3..10, nu 0..0.5) on the
#: grid steps 250..4000 x elements 50..3200 (``python -m benchmarks.element_orders``:
#: ``error_model``; it bounds every point, at most 9.8 times the largest error
#: measured at each: the time error floors the finest elements). The element
#: spacing dominates; the step error is second order but its largest values over
#: the scenes fall like ``1 / steps`` on the grid.
#: (Fitted on eight scenes with Q1 <= 5 it was a = 0.0021, b = 1.72, and
#: ``for_tolerance(1e-5)`` gave 2.5e-5 on random scenes with Q1 up to 30: the step
#: error of a glassy standard solid at Q1 = 10 is about 6e-3 / steps.)
ERROR_MODEL = {"a": 0.0062, "p": 1.0, "b": 1.08, "q": 2.0}
#: :meth:`Numerics.for_tolerance` aims the envelope at ``tolerance / ERROR_MODEL_SAFETY``.
#: The envelope bounds its own grid, but between grid points the error jumps with
#: the element count (the contact edge crossing element centres) and above 800
#: elements this jitter outgrows the smooth 1/elements^2 trend: on 40 random scenes
#: (Q1 1e-3..30, two seeds, tests/engine/test_tolerance.py's calibration) the error
#: reached 1.5 times the tolerance at 1e-6 (12000 steps, 1470 elements; aimed with
#: no safety) and 1.03 times at 3e-6, while at 1e-5..1e-4 it stayed at 0.5-0.84 of
#: it. A factor 2 covers what was measured; the validation scenes of that test are
#: drawn from a third seed.
ERROR_MODEL_SAFETY = 2.0


def element_error_bound(steps: float, elements: float) -> float:
    """Return the error model's bound on the Verlet element path, dimensionless.

    :data:`ERROR_MODEL`'s bound on ``max(|e_z err|, |e_x err|)`` of the Verlet element
    path at ``steps`` per t_H and ``elements`` per a_H (dimensionless).
    """
    m = ERROR_MODEL
    return m["a"] / steps ** m["p"] + m["b"] / elements ** m["q"]


#: Coarsest settings :meth:`Numerics.for_tolerance` gives (the model's measured grid).
MIN_MODEL_STEPS = 250
MIN_MODEL_ELEMENTS = 50
#: Caps of :meth:`Numerics.for_tolerance` on the element path (about 0.3 s per impact).
MAX_STEPS = 16000
#: Fewest time steps an impact's contact may span on the element path; a
#: shorter contact (heavy damping: the sphere bounces off a stiff dashpot
#: within a few steps) is reported as status ``unresolved``, not as a number.
MIN_CONTACT_STEPS = 20
#: Cost bounds of one impact on the element path (after the automatic refinement
#: for stiff modes): more is refused with status ``too_costly`` instead of running
#: for hours. 1e7 steps per Hertz time is about a minute per impact.
MAX_STEPS_PER_T_H = 1e7
MAX_ELEMENTS_IN_ROW = 1e6
MAX_ELEMENTS = 3200
#: The smallest tolerance the element path verifiably reaches: the error model at the
#: caps times the safety (9.9e-7; the envelope there is 4.9e-7, and the ``precise``
#: preset, these caps, measured 2.0e-7 on the model's scenes).
ELEMENT_TOLERANCE_FLOOR = ERROR_MODEL_SAFETY * element_error_bound(MAX_STEPS, MAX_ELEMENTS)
#: Why a tolerance is refused for the thesis's seed memory (every element carries the
#: total contact-point displacement, so the stress jumps at the contact edge): its
#: beta_x converges at order 1.2-1.5 in the element spacing (worst over the edge's
#: position, ``python -m benchmarks.element_orders``) and, with a stiff fast arm, not
#: measurably below 3e-4 up to the caps, while :data:`ERROR_MODEL` is measured with the
#: incremental memory: ``for_tolerance`` missed 1e-4 and 1e-5 on 4 of 6 seed scenes, by
#: up to 22x and 132x, and 1e-3 on one (2x) (``tolerance_check`` of the benchmark; the
#: same settings with friction stay below 0.09 of the tolerance).
SEED_MEMORY_UNVERIFIED = (
    "tolerance = {tolerance:g} cannot be verified with the seed memory (thesis eq. 4.16): "
    "its beta_x converges more slowly than the error model, which is measured with the "
    "incremental memory; give steps and elements (or a preset) and compare two resolutions")
#: Largest accepted ``steps`` and ``elements`` settings (cost bounds).
MAX_SETTING = {"steps": 10_000_000, "elements": 1_000_000}

PRESETS = {
    # chosen from the accuracy-versus-time front (benchmarks/results/accuracy.json)
    # element path, largest error against the continuum kernel on the eleven scenes of
    # ERROR_MODEL (python -m benchmarks.element_orders):
    "fast": Numerics(steps=500, elements=70),  # 2.1e-4 (model 2.3e-4)
    "default": Numerics(),  # 1400/200: 2.8e-5 (model 3.1e-5)
    # elements: the best the element path verifiably reaches (2.0e-7, model 4.9e-7);
    # continuum paths: rtol 1e-12 gives 1e-10 and better on beta_x (error up to ~125 rtol)
    "precise": Numerics(steps=16000, elements=3200, rtol=1e-12),
    "thesis": Numerics(integrator="euler", steps=5000, elements=500),
}


#: The presets that converge (not the thesis's explicit Euler): for fits and exports.
CONVERGED_PRESETS = tuple(n for n, p in PRESETS.items() if p.integrator != "euler")


def preset_summary(name: str) -> str:
    """One line on preset ``name`` for help texts.

    Its error bound on the element path (:func:`element_error_bound`, dimensionless), or
    what the thesis preset is.
    """
    p = PRESETS[name]
    if p.integrator == "euler":
        return f"{name} (explicit Euler as in the thesis)"
    bound = f"{element_error_bound(p.steps, p.elements):.0e}".replace("e-0", "e-")
    return f"{name} (about {bound} on the element path)"
