"""The NumPy reference at the kernel's own discretization of each scene.

:func:`vimpact.reference.numpy_elements.naive_impact` takes the refinement
factors from its caller (the reference sits below the engine); the tests that
compare it with the kernel to rounding pass the engine's factors for the
scene, as the kernel uses them.
"""

from __future__ import annotations

from vimpact.engine.routing import choose_path, refinement
from vimpact.model.numerics import Numerics
from vimpact.reference import numpy_elements


def kernel_refinement(scene, steps: int, elements: int, row_width: float = 1.05
                      ) -> tuple[float, float]:
    """``(time_factor, element_factor)`` of the element kernel for ``scene``."""
    numerics = Numerics(steps=steps, elements=elements, row_width=row_width, continuum=False)
    return refinement(scene, numerics, choose_path(scene, numerics).spec)


def naive_impact(scene, steps: int, elements: int, row_width: float = 1.05, *args, **kwargs
                 ) -> dict:
    """:func:`~vimpact.reference.numpy_elements.naive_impact` refined as the kernel refines."""
    factors = kernel_refinement(scene, steps, elements, row_width)
    return numpy_elements.naive_impact(scene, steps, elements, row_width, *args,
                                       refinement=factors, **kwargs)
