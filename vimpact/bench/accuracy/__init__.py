"""What accuracy costs in time.

Error versus wall time per impact for every integrator, its Pareto front, the presets, and
an error model to pick numerics.

Run: ``vimpact bench accuracy [--quick] [--out DIR]`` (writes ``DIR/accuracy.json``
and ``accuracy.png``); the full-size run of the repository is
``python -m benchmarks.accuracy`` (``benchmarks/results/accuracy.json`` and
``accuracy_pareto.png``). The full run measures every integrator; the quick one
the Verlet ladder only (``CONFIGS["quick"]["integrators"]``: the Euler ladders
compile element kernels of their own), ``run(quick=True, integrators=INTEGRATORS)``
all three. Presets whose integrator a run leaves out are measured as routed only
(``presets_not_on_elements`` says which).

- Scenes: oblique impacts (``v_c0 != 0``, so ``e_x`` is computed), Kelvin-Voigt
  at ``nu = 0`` and ``0.5`` and the standard solid at ``Q2 = 0.1`` and ``10``
  (``nu = 0.5``), ``Q1`` log-spaced over ``[1e-3, 10]``.
- Reference: ``e_z`` and ``e_x`` of every scene from the exact full-stick
  continuum kernel (:func:`vimpact.kernels.continuum_maxwell.maxwell_stick_batch`,
  every rheology, the limit of the element row as steps and elements grow;
  docs/physics.md, continuum limit) at rtol 1e-12 (:func:`continuum_restitution`);
  its uncertainty per scene is ``|value(rtol 1e-12) - value(rtol 1e-10)|``
  (1e-13 to 3e-9: below it an error is not resolved, see the
  ``verifiable`` flags). Independent check: on the Kelvin-Voigt scenes its
  ``e_z`` against the closed form
  :func:`vimpact.reference.closed_forms.kelvin_voigt_continuum` (largest
  difference recorded in the JSON).
- Settings (element path, ``Numerics(continuum=False)``: the full-stick
  scenes would otherwise take a continuum path): for each integrator a
  coarse 2-D grid of (steps per ``t_H``,
  elements per ``a_H``). For each setting: max and median ``|e_z error|`` and
  ``|e_x error|`` over the scenes and the wall time per impact of
  ``vimpact.simulate_batch`` on all scenes at once (numba threads: 2; the
  kernels are compiled by a warm-up call first; cheap settings run on the
  scenes repeated to a batch of about 0.2 s; median of 3 samples taken in
  separate passes over all settings, see :class:`Timer`).
- Derived: Pareto front per integrator (error ``= max(max |e_z err|, max |e_x
  err|)`` versus time per impact), the cheapest setting per tolerance, the
  explicit-Euler / Verlet time ratio, observed orders, the thesis's table
  4.1 for all integrators, per integrator a fitted error model ``err = a /
  steps^p + b / elements^q`` (least squares in logs, for e_z, e_x and their
  max), an envelope of the same form with ``p = 1``, ``q = 2`` that bounds
  every grid point, and a time model ``t = c0 + cs steps + c1 steps
  elements``; the (steps, elements) the Verlet models pick per tolerance,
  run and measured; ``Numerics.for_tolerance`` and every preset in
  ``vimpact.PRESETS`` measured on the same scenes on the element path
  (``presets``, ``for_tolerance``; and, untimed, ``for_tolerance`` at 19
  tolerances from 1e-3 to 1e-6, ``for_tolerance_scan``), and the presets as routed
  (``presets_as_routed``: most of these full-stick scenes take the continuum
  path, a standard solid with a stiff arm the element path); suggested presets.
- Also: the continuum path (Kelvin-Voigt normal-only, ``tangential="none"``)
  at several ``rtol``, and the thesis's table 4.1 (elastic normal impact,
  element path) for all three integrators.

Explicit Euler gains energy; ``simulate`` flags such a passive impact as
``unstable`` with NaN outputs, so for those rows (table 4.1) the kernel's own
numbers are read (:func:`raw_restitution`).

The machine is shared: times carry the load average at start and end.
Nothing here asserts a time.

The code is split by job: :mod:`.config` (tolerances, integrators, scenes,
ladders), :mod:`.measure` (reference, errors, timing), :mod:`.models` (error and
time models, Pareto fronts), :mod:`.derive` (what a run derives), :mod:`.runner`
(:func:`run`), :mod:`.plot` and :mod:`.report`.
"""

from __future__ import annotations

from .config import CONFIGS, INTEGRATORS, THESIS_TABLE_4_1, THREADS, TOLERANCES, _ladder
from .measure import (
    REFERENCE_CHECK_RTOL,
    REFERENCE_MAX_STEPS,
    REFERENCE_RTOL,
    Timer,
    continuum_ladder,
    continuum_restitution,
    evaluate,
    for_tolerance_scan,
    raw_restitution,
    reference,
    table_4_1,
)
from .models import (
    fit_envelope,
    fit_error_model,
    fit_time_model,
    model_pick,
    pareto,
)
from .plot import COLOURS, plot
from .report import figures, report
from .runner import run

TITLE = "what accuracy costs: error vs time per impact for every integrator, presets, continuum"

__all__ = [
    "COLOURS", "CONFIGS", "INTEGRATORS", "REFERENCE_CHECK_RTOL", "REFERENCE_MAX_STEPS",
    "REFERENCE_RTOL", "THESIS_TABLE_4_1", "THREADS", "TITLE", "TOLERANCES", "Timer",
    "continuum_ladder", "continuum_restitution", "evaluate", "figures", "fit_envelope",
    "fit_error_model", "fit_time_model", "for_tolerance_scan", "model_pick", "pareto", "plot",
    "raw_restitution", "reference", "report", "run", "table_4_1", "_ladder",
]
