"""Numerics.for_tolerance delivers its tolerance on the path that runs, or refuses.

Scenes are drawn at random (seeded) over rheologies, nu and Theta: none of them
was used to choose the rule. The reference is the same continuum kernel at
rtol = 1e-13, which tests/kernels/test_continuum_maxwell.py checks against an
independent scipy solution of the same equations.
"""

import numpy as np
import pytest

import vimpact as v

REFERENCE = v.Numerics(rtol=1e-13)


def _random_scenes(n, seed):
    rng = np.random.default_rng(seed)
    scenes = []
    for _ in range(n):
        q1 = 10 ** rng.uniform(-3, 0.5)
        nu = rng.uniform(0.0, 0.5)
        theta = rng.uniform(0.1, 0.67)
        q2 = None if rng.random() < 0.4 else 10 ** rng.uniform(-2, 2)
        scenes.append(v.Scene.from_dimensionless(q1, nu, q2, theta_ratio=theta))
    return scenes


@pytest.mark.parametrize("tolerance", [1e-6, 1e-8, 1e-9])
def test_for_tolerance_reaches_its_target_on_the_continuum_path(tolerance):
    scenes = _random_scenes(12, seed=20261123)
    got = v.simulate_batch(scenes, v.Numerics.for_tolerance(tolerance))
    ref = v.simulate_batch(scenes, REFERENCE)
    assert (got.status == "ok").all() and got.path.str.startswith("continuum").all()
    for name in ("e_z", "beta_x"):
        err = np.abs(got[name] - ref[name]).max()
        assert err <= tolerance, (name, err)


def test_presets_claim_on_the_continuum_path():
    """precise: 1e-9 wherever the continuum path applies."""
    scenes = _random_scenes(8, seed=7)
    got = v.simulate_batch(scenes, v.Numerics.preset("precise"))
    ref = v.simulate_batch(scenes, REFERENCE)
    for name in ("e_z", "beta_x"):
        assert np.abs(got[name] - ref[name]).max() <= 1e-9, name
