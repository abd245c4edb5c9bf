"""The presets meet their stated accuracy on random points never used to tune them.

The points are drawn here (log-uniform Q1 in [1e-3, 10], nu in [0, 0.5],
Q2 log-uniform in [1e-4, 10] for the standard solid: arms from far faster than
the step to slow); the seed only makes CI reproducible. The element path is
forced (``continuum=False``); its stated accuracy is the error model at the
preset's settings (``ERROR_MODEL``, fitted on other scenes by
benchmarks/element_orders.py). Reference: the full-stick continuum kernel at
rtol 1e-12 (tests/kernels/test_continuum_maxwell.py checks it against scipy),
and the Kelvin-Voigt closed form (docs/physics.md#kelvin-voigt-continuum) for
the continuum paths.
"""

import numpy as np
import pytest

import vimpact as v
from tests.engine.test_tolerance import _continuum_kernel
from vimpact.model.numerics import element_error_bound
from vimpact.reference.closed_forms import kelvin_voigt_continuum

RNG = np.random.default_rng(20261121)
Q1 = 10.0 ** RNG.uniform(-3, 1, 3)
NU = RNG.uniform(0.0, 0.5, 3)
Q2 = 10.0 ** RNG.uniform(-4, 1, 3)
SCENES = ([v.Scene.from_dimensionless(q, n) for q, n in zip(Q1, NU)]
          + [v.Scene.from_dimensionless(q, n, q2) for q, n, q2 in zip(Q1, NU, Q2)])


def model_bound(numerics: v.Numerics) -> float:
    return element_error_bound(numerics.steps, numerics.elements)


@pytest.fixture(scope="module")
def exact():
    return _continuum_kernel(SCENES)


@pytest.mark.parametrize("preset", ["fast", "default",
                                    pytest.param("precise", marks=pytest.mark.slow)])
def test_element_path_meets_the_error_model(exact, preset):
    """e_z and e_x of the element path within the error model's bound at the
    preset (fast 2.3e-4, default 3.1e-5, precise 4.9e-7)."""
    numerics = v.Numerics.preset(preset).with_(continuum=False)
    df = v.simulate_batch(SCENES, numerics)
    assert (df.status == "ok").all() and df.path.str.startswith("elements").all()
    err = np.maximum(np.abs(df.e_z.to_numpy() - exact[0]), np.abs(df.e_x.to_numpy() - exact[1]))
    assert err.max() <= model_bound(numerics), (err, model_bound(numerics))
    if preset == "precise":
        assert err.max() <= 1e-6


@pytest.mark.parametrize("preset", ["fast", "default", "precise"])
def test_continuum_path_meets_the_tolerance(preset):
    """Normal-only Kelvin-Voigt scenes take the continuum path; its error
    stays within the preset's rtol band (precise: 1e-7)."""
    scenes = [v.Scene.from_dimensionless(q, n, tangential="none") for q, n in zip(Q1, NU)]
    df = v.simulate_batch(scenes, v.Numerics.preset(preset))
    assert df.path.str.startswith("continuum").all()
    exact = np.array([kelvin_voigt_continuum(q).e_z for q in Q1])
    err = np.abs(df.e_z.to_numpy() - exact)
    assert err.max() < {"fast": 1e-3, "default": 1e-4, "precise": 1e-7}[preset], err
