"""The presets meet their tolerance on random points never used to tune them.

The points are drawn here (log-uniform Q1 in [1e-3, 10], nu in [0, 0.5],
Q2 log-uniform in [0.1, 10] for the standard solid); the seed only makes CI
reproducible. References: the Kelvin-Voigt continuum solution to 1e-12
(docs/physics.md#kelvin-voigt-continuum) for e_z, and the ``precise`` preset for e_x and the
standard solid (itself checked against the continuum on e_z).
"""

import numpy as np
import pytest

import vimpact as v
from vimpact.reference.closed_forms import kelvin_voigt_continuum

RNG = np.random.default_rng(20261121)
Q1 = 10.0 ** RNG.uniform(-3, 1, 3)
NU = RNG.uniform(0.0, 0.5, 3)
Q2 = 10.0 ** RNG.uniform(-1, 1, 3)
TOLERANCE = {"fast": 1e-3, "default": 1e-4}


@pytest.fixture(scope="module")
def runs():
    scenes = [v.Scene.from_dimensionless(q, n) for q, n in zip(Q1, NU)]
    scenes += [v.Scene.from_dimensionless(q, n, q2) for q, n, q2 in zip(Q1, NU, Q2)]
    return {name: v.simulate_batch(scenes, v.Numerics.preset(name))
            for name in ("fast", "default", "precise")}


@pytest.mark.parametrize("preset", ["fast", "default", "precise"])
def test_kelvin_voigt_e_z_against_the_continuum(runs, preset):
    """e_z of the element path (oblique scenes) against the closed-form continuum."""
    exact = np.array([kelvin_voigt_continuum(q).e_z for q in Q1])
    err = np.abs(runs[preset].e_z.to_numpy()[:3] - exact)
    assert err.max() < TOLERANCE.get(preset, 1e-5), err


@pytest.mark.parametrize("preset", ["fast", "default"])
def test_e_x_and_standard_solid_against_precise(runs, preset):
    ref = runs["precise"]
    for key in ("e_z", "e_x"):
        err = np.abs(runs[preset][key].to_numpy() - ref[key].to_numpy())
        assert err.max() < TOLERANCE[preset], (key, err)


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
