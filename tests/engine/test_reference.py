"""The kernel against the slow physical-units reference and docs/physics.md properties.

Oracles, none of them produced by the kernel:
- ``tests/naive.py``: the same element model and time stepping written in SI
  units, with ``v_x`` and ``omega`` tracked separately (so the kernel's
  nondimensionalization, its ``v_c = v_x + R omega`` reduction and the
  normalization of the tangential problem by ``v_c0`` are tested);
- docs/physics.md#dimensionless-parameters (restitution depends only on ``Q1``, ``Q2``, ``nu``,
  ``Theta / (m R^2)``), with ``eta`` computed here from the docs/physics.md#hertz-scales formulas;
- docs/physics.md#energy-and-passivity (the tangential problem is linear in ``v_c0`` and
  sees ``v_x0``, ``omega0`` only through ``v_c0``).

Coarse numerics keep the file fast; the agreement asked for is about rounding,
not discretization, so it does not depend on the resolution.

The NumPy reference's results for the fixed scenes of the default run are stored in
tests/oracles/data/naive_reference.json, computed by that reference (never by the
kernel) with ``python -m tests.oracles.naive_data``, which looks them up by the whole
scene, resolution and refinement (tests/oracles/naive_data.py); the ``slow`` test
:func:`test_stored_naive_results_are_the_references` computes every one again.
Comparisons with stored results take :data:`~tests.oracles.naive_data.STORED_RTOL`
(1e-11, what a recomputation may differ by) off their tolerance per stored value
involved, so they are as strict as with the reference computed on the spot.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from tests.oracles.naive import naive_impact
from tests.oracles.naive_data import (
    FLOAT_KEYS,
    STORED_RTOL,
    compute,
    naive_reference,
    scene_of,
    stored_cases,
)
from vimpact import Material, Numerics, Scene, hertz_scales, simulate, simulate_batch

STEPS, ELEMENTS = 150, 30
NUM = Numerics(steps=STEPS, elements=ELEMENTS, continuum=False)  # the element kernel itself

RTOL_NAIVE = 1e-8  # kernel vs naive: same algorithm, different units
RTOL_COLLAPSE = 1e-9  # docs/physics.md#dimensionless-parameters: equal dimensionless parameters
#: the same with one or two stored reference results in the comparison
RTOL_NAIVE_STORED = RTOL_NAIVE - STORED_RTOL
RTOL_COLLAPSE_STORED = RTOL_COLLAPSE - STORED_RTOL
RTOL_COLLAPSE_STORED2 = RTOL_COLLAPSE - 2.0 * STORED_RTOL

HERTZ_TIME = 2.9432751843  # docs/physics.md#hertz-scales, t_H / T
Q1_PER_TAU = math.sqrt(15.0 / 32.0)  # docs/physics.md#dimensionless-parameters, Q1 per (eta / G_inf) / T
RHEOLOGIES = ("elastic", "kelvin_voigt", "standard_solid", "prony")
OUTPUTS = ("e_z", "e_x", "beta_x", "v_z_end", "v_x_end", "omega_end", "t_contact", "u_max",
           "a_max")

#: largest relative difference seen per comparison (printed with ``pytest -s``)
MAX_REL: dict[str, float] = {}


@pytest.fixture(scope="module", autouse=True)
def _report_agreement():
    yield
    for key, value in sorted(MAX_REL.items()):
        print(f"max relative difference {key:32s} {value:.2e}")


def assert_close(label, a, b, rtol, scale=0.0):
    """``|a - b| <= rtol * max(|a|, |b|, scale)``; records the relative difference."""
    a, b = float(a), float(b)
    assert math.isfinite(a) and math.isfinite(b), (label, a, b)
    ref = max(abs(a), abs(b), scale)
    rel = abs(a - b) / ref if ref > 0.0 else 0.0
    MAX_REL[label] = max(MAX_REL.get(label, 0.0), rel)
    assert rel <= rtol, f"{label}: {a!r} vs {b!r} (relative {rel:.2e} > {rtol:.0e})"


# ---------------------------------------------------------------- scenes

def hertz_physics(G, nu, R, m, v_z0):
    """``(d, a_H, T)`` in m, m, s from the docs/physics.md#hertz-scales formulas."""
    E_star = 2.0 * G / (1.0 - nu)
    d = (15.0 * m * v_z0**2 / (16.0 * E_star * math.sqrt(R))) ** 0.4
    return d, math.sqrt(R * d), d / v_z0


def log_uniform(rng, lo, hi):
    return float(10.0 ** rng.uniform(math.log10(lo), math.log10(hi)))


def random_scene(rng, rheology, memory):
    """A random physical scene of the given rheology.

    E, R, v_z0 span decades; the mass follows from a drawn ``a_H / R`` in
    [1e-3, 0.05] (well inside the half-space limit); relaxation times are
    drawn relative to the Hertz time unit ``T`` so that the viscoelasticity
    matters; ``v_c0`` has either sign and spans decades relative to ``v_z0``.
    """
    nu = float(rng.uniform(0.0, 0.5))
    G = log_uniform(rng, 1e5, 1e11) / (2.0 * (1.0 + nu))  # from Young's modulus, Pa
    R = log_uniform(rng, 1e-3, 1.0)
    v_z0 = log_uniform(rng, 0.01, 100.0)
    d = log_uniform(rng, 1e-3, 0.05) ** 2 * R  # a_H = sqrt(R d)
    E_star = 2.0 * G / (1.0 - nu)
    m = 16.0 * E_star * math.sqrt(R) * d**2.5 / (15.0 * v_z0**2)
    T = d / v_z0
    if rheology == "elastic":
        material = Material.elastic(nu=nu, G=G)
    elif rheology == "kelvin_voigt":
        material = Material.kelvin_voigt(nu=nu, G=G, eta=log_uniform(rng, 0.01, 1.0) * T * G)
    elif rheology == "standard_solid":
        G2 = log_uniform(rng, 0.1, 10.0) * G
        material = Material.standard_solid(nu=nu, G1=G, G2=G2,
                                           eta=log_uniform(rng, 0.05, 5.0) * T * G2)
    else:
        arms = [(log_uniform(rng, 0.1, 5.0) * G, log_uniform(rng, 0.02, 20.0) * T)
                for _ in range(2)]
        eta0 = log_uniform(rng, 0.01, 0.3) * T * G if rng.uniform() < 0.5 else 0.0
        material = Material.prony(nu=nu, G_inf=G, arms=arms, eta0=eta0)
    v_c0 = float(rng.choice([-1.0, 1.0])) * log_uniform(rng, 0.01, 100.0) * v_z0
    v_x0 = v_c0 * float(rng.uniform(-1.0, 2.0))
    omega0 = (v_c0 - v_x0) / R
    Theta = float(rng.uniform(0.1, 1.0)) * m * R**2
    return Scene(material, R=R, m=m, v_z0=v_z0, v_x0=v_x0, omega0=omega0, Theta=Theta,
                 tangential_memory=memory)


def compare_with_naive(scene, res, ref, tag, rtol=RTOL_NAIVE_STORED):
    """Every output of a kernel result ``res`` against the naive dict ``ref`` (stored:
    ``rtol = RTOL_NAIVE_STORED``; computed now: ``RTOL_NAIVE``); where the
    naive solution itself leaves the elastic bound (``e_z > 1 + 1e-6``: this
    discretization is too coarse for the scene) the kernel must say so (``unstable``
    for the passive incremental memory) instead of a number."""
    if scene.tangential_memory == "incremental" and ref["e_z"] > 1.0 + 1e-6:
        assert (res.status, ref["status"]) == ("unstable", "ok") and math.isnan(res.e_z)
        return
    assert res.status == ref["status"] == "ok", (res.status, ref["status"])
    scales = output_scales(scene)
    for key in OUTPUTS:
        assert_close(f"{tag} {key}", getattr(res, key), ref[key], rtol, scales.get(key, 0.0))


def output_scales(scene):
    """The scale of each output below which its difference is measured absolutely."""
    velocity = max(abs(scene.v_x0), abs(scene.v_c0))  # tangential velocity scale, m/s
    return dict(v_x_end=velocity, omega_end=velocity / scene.R,
                e_x=1.0, beta_x=1.0)  # e_x may pass through 0


# -------------------------------------------------- kernel vs naive, random

def test_naive_uses_physics_hertz_scales():
    """The naive reference takes t_H and a_H from vimpact.model.hertz: check them
    against docs/physics.md#hertz-scales so that the reference stays independent."""
    rng = np.random.default_rng(7)
    for _ in range(20):
        G, nu = log_uniform(rng, 1e4, 1e11), float(rng.uniform(0.0, 0.5))
        R, m, v = log_uniform(rng, 1e-3, 1.0), log_uniform(rng, 1e-6, 1e3), log_uniform(rng, 1e-2, 1e2)
        d, a_H, T = hertz_physics(G, nu, R, m, v)
        hz = hertz_scales(G, nu, R, m, v)
        assert_close("hertz d", hz.d, d, 1e-12)
        assert_close("hertz a_H", hz.a_H, a_H, 1e-12)
        assert_close("hertz t_H", hz.t_H, HERTZ_TIME * T, 1e-10)


#: (rheology, memory) pairs whose kernel no other test of the default run compiles:
#: the seed memory with a dashpot (Kelvin-Voigt; Prony draws one in half its scenes),
#: about 80 s of compiling on a fresh clone. The seed memory stays checked against the
#: reference in the default run on the elastic and standard-solid (arms) kernels.
SLOW_PAIRS = {("kelvin_voigt", "seed"), ("prony", "seed")}


@pytest.mark.parametrize("rheology, memory", [
    pytest.param(r, m, id=f"{r}-{m}", marks=[pytest.mark.slow] if (r, m) in SLOW_PAIRS else [])
    for m in ("incremental", "seed") for r in RHEOLOGIES])
def test_kernel_matches_naive(rheology, memory):
    rng = np.random.default_rng([11, RHEOLOGIES.index(rheology), memory == "seed"])
    for _ in range(4):
        scene = random_scene(rng, rheology, memory)
        if (rheology, memory) in SLOW_PAIRS:  # not stored: computed now
            compare_with_naive(scene, simulate(scene, NUM), naive_impact(scene, STEPS, ELEMENTS),
                               "naive", RTOL_NAIVE)
        else:
            compare_with_naive(scene, simulate(scene, NUM),
                               naive_reference(scene, STEPS, ELEMENTS), "naive")


@pytest.mark.slow
def test_stored_naive_results_are_the_references():
    """The NumPy reference computed now gives every stored result: status and steps
    equal, every float within STORED_RTOL (relative, with the comparisons' scales; on
    the machine that wrote them, bit for bit)."""
    cases = stored_cases()
    assert len(cases) > 40
    for case in cases:
        got, want = compute(case), case["result"]
        assert (got["status"], got["steps"]) == (want["status"], want["steps"])
        scales = output_scales(scene_of(case["scene"]))
        for key in FLOAT_KEYS:
            if math.isnan(want[key]):
                assert math.isnan(got[key]), key
            else:
                assert_close(f"stored {key}", got[key], want[key], STORED_RTOL,
                             scales.get(key, 0.0))


def test_batch_with_mixed_arm_counts_matches_naive():
    """``simulate_batch`` pads the arm arrays of a mixed batch (0, 1, 2 arms) and
    groups its rows by kernel (both memories; the seed memory without a dashpot,
    see :data:`SLOW_PAIRS`)."""
    rng = np.random.default_rng(23)
    scenes = [random_scene(rng, RHEOLOGIES[i % 4], "seed" if i in (4, 6) else "incremental")
              for i in range(8)]
    table = simulate_batch(scenes, NUM)
    for scene, (_, row) in zip(scenes, table.iterrows()):
        compare_with_naive(scene, row, naive_reference(scene, STEPS, ELEMENTS), "naive batch")


# ------------------------------ collapse (docs/physics.md#dimensionless-parameters)

def collapse_scenes(rng, n, Q1, nu, Q2=None, theta_ratio=0.4):
    """``n`` physical scenes spanning decades with the given ``Q1`` (and ``Q2``).

    ``eta`` is computed from the docs/physics.md formulas here, not by vimpact.
    Draws whose Hertz radius exceeds 0.1 R are rejected (``a_max <= a_H``
    for these passive materials, so the half-space limit 0.2 R is safe).
    """
    scenes = []
    while len(scenes) < n:
        E = log_uniform(rng, 1e5, 1e11)
        R = log_uniform(rng, 1e-3, 1.0)
        m = log_uniform(rng, 1e-7, 1e3)
        v_z0 = log_uniform(rng, 0.01, 100.0)
        G = E / (2.0 * (1.0 + nu))
        d, a_H, T = hertz_physics(G, nu, R, m, v_z0)
        if a_H > 0.1 * R:
            continue
        eta = Q1 / Q1_PER_TAU * T * G  # Q1 = sqrt(15/32) (eta / G_inf) / T
        if Q2 is None:
            material = Material.kelvin_voigt(nu=nu, G=G, eta=eta)
        else:
            material = Material.standard_solid(nu=nu, G1=G, G2=G / Q2, eta=eta)
        v_c0 = float(rng.choice([-1.0, 1.0])) * log_uniform(rng, 1e-2, 1e2) * v_z0
        v_x0 = v_c0 * float(rng.uniform(-1.0, 2.0))
        scenes.append(Scene(material, R=R, m=m, v_z0=v_z0, v_x0=v_x0,
                            omega0=(v_c0 - v_x0) / R, Theta=theta_ratio * m * R**2))
    return scenes


@pytest.mark.parametrize("Q2", [None, 0.5], ids=["kelvin_voigt", "standard_solid"])
@pytest.mark.parametrize("theta_ratio", [0.4, 2.0 / 3.0])
def test_collapse_on_dimensionless_parameters(Q2, theta_ratio):
    Q1, nu = 0.3, 0.3
    rng = np.random.default_rng([31, Q2 is None, theta_ratio == 0.4])
    scenes = collapse_scenes(rng, 8, Q1, nu, Q2, theta_ratio)
    E = [s.material.G_inf for s in scenes]
    assert max(E) / min(E) > 1e3  # the draws really span decades
    reference = simulate(Scene.from_dimensionless(Q1, nu, Q2, theta_ratio=theta_ratio), NUM)
    table = simulate_batch(scenes, NUM)
    assert (table["status"] == "ok").all(), table["status"].tolist()
    for _, row in table.iterrows():
        for key in ("e_z", "e_x", "beta_x"):
            assert_close(f"collapse {key}", row[key], getattr(reference, key), RTOL_COLLAPSE)
        # the same in units of the Hertz scales (dimensional analysis)
        assert_close("collapse t_contact/t_H", row["t_contact"] / row["t_hertz"],
                     reference.t_contact / reference.t_hertz, RTOL_COLLAPSE)
        assert_close("collapse u_max/d", row["u_max"] / row["d_hertz"],
                     reference.u_max / reference.d_hertz, RTOL_COLLAPSE)

    # the honest check: the naive reference does not nondimensionalize
    extremes = [min(scenes, key=lambda s: s.hertz.T), max(scenes, key=lambda s: s.hertz.T)]
    for scene in extremes:
        ref = naive_reference(scene, STEPS, ELEMENTS)
        for key in ("e_z", "e_x", "beta_x"):
            assert_close(f"collapse naive {key}", ref[key], getattr(reference, key),
                         RTOL_COLLAPSE_STORED)


def test_collapse_tolerance_resolves_q1():
    """A 1e-4 change of Q1 is far above the collapse tolerance: the collapse
    test above can fail."""
    a = simulate(Scene.from_dimensionless(0.3, 0.3), NUM)
    b = simulate(Scene.from_dimensionless(0.3 * (1.0 + 1e-4), 0.3), NUM)
    assert abs(a.e_z - b.e_z) > 1e3 * RTOL_COLLAPSE
    assert abs(a.e_x - b.e_x) > 1e3 * RTOL_COLLAPSE


# ---------------------------------- tangential (docs/physics.md#energy-and-passivity)

R_TAN = 0.5  # a power of two, so v_x0 + R omega0 is exact below


def tangential_scene(v_x0, omega0, memory="incremental"):
    """A fixed standard-solid normal scene (a_H about 0.02 R) with the given spin state."""
    G, nu, m, v_z0 = 2e8, 0.25, 0.25, 2.0
    d, a_H, T = hertz_physics(G, nu, R_TAN, m, v_z0)
    assert a_H < 0.05 * R_TAN
    material = Material.standard_solid(nu=nu, G1=G, G2=2.0 * G, eta=0.4 * T * G)
    return Scene(material, R=R_TAN, m=m, v_z0=v_z0, v_x0=v_x0, omega0=omega0,
                 tangential_memory=memory)


@pytest.mark.parametrize("memory", ["incremental", "seed"])
def test_tangential_independent_of_vc0_size(memory):
    """e_x and beta_x do not depend on |v_c0| (nor on its sign)."""
    results = []
    for v_c0 in (1e-3, 1.0, 1e3, -1.0):
        scene = tangential_scene(0.5 * v_c0, v_c0, memory)  # v_x0 + R omega0 = v_c0
        assert scene.v_c0 == v_c0
        res, ref = simulate(scene, NUM), naive_reference(scene, STEPS, ELEMENTS)
        compare_with_naive(scene, res, ref, "tangential naive")
        # linear in v_c0: the impulse per unit v_c0 is the same for every size
        results.append((res, ref, scene.m * (scene.v_x0 - ref["v_x_end"]) / v_c0))
    base_res, base_ref, base_impulse = results[1]
    for res, ref, impulse in results:
        for key in ("e_x", "beta_x"):
            assert_close(f"|v_c0| kernel {key}", getattr(res, key), getattr(base_res, key), 1e-12)
            assert_close(f"|v_c0| naive {key}", ref[key], base_ref[key], RTOL_COLLAPSE_STORED2)
        assert_close("|v_c0| naive impulse / v_c0", impulse, base_impulse, RTOL_COLLAPSE_STORED2)
    assert abs(base_res.beta_x) > 0.01  # something happened tangentially


@pytest.mark.parametrize("memory", ["incremental", "seed"])
def test_tangential_depends_on_vc0_only(memory):
    """Different (v_x0, omega0) with v_c0 = 1 m/s: same e_x, beta_x and impulse;
    the angular impulse is R times the linear one (Theta domega = R m dv_x)."""
    states = [(1.0, 0.0), (0.0, 2.0), (3.0, -4.0), (-2.5, 7.0)]
    impulses = []
    base = None
    for v_x0, omega0 in states:
        scene = tangential_scene(v_x0, omega0, memory)
        assert scene.v_c0 == 1.0
        res, ref = simulate(scene, NUM), naive_reference(scene, STEPS, ELEMENTS)
        compare_with_naive(scene, res, ref, "split naive")
        J = scene.m * (v_x0 - ref["v_x_end"])  # N s
        assert_close("split naive angular impulse", scene.Theta * (omega0 - ref["omega_end"]),
                     scene.R * J, RTOL_COLLAPSE_STORED2, scale=scene.Theta * abs(omega0))
        impulses.append((J, scene.m * (v_x0 - res.v_x_end)))
        if base is None:
            base = (res, ref)
        for key in ("e_x", "beta_x"):
            assert_close(f"split kernel {key}", getattr(res, key), getattr(base[0], key),
                         RTOL_COLLAPSE)
            assert_close(f"split naive {key}", ref[key], base[1][key], RTOL_COLLAPSE_STORED2,
                         scale=1.0)
    # the largest centre velocity times the mass sets the rounding scale of J
    scale = max(abs(v_x0) for v_x0, _ in states) * tangential_scene(1.0, 0.0).m
    for J_naive, J_kernel in impulses:
        assert_close("split naive impulse", J_naive, impulses[0][0], RTOL_COLLAPSE_STORED2, scale)
        assert_close("split kernel impulse", J_kernel, impulses[0][1], RTOL_COLLAPSE, scale)
    assert abs(impulses[0][0]) > 1e-3  # the tangential force did something


def test_vc0_zero_gives_no_tangential_force():
    """v_c0 = 0 with v_x0 = -R omega0 != 0: status vc0_zero, NaN e_x and
    beta_x, v_x and omega unchanged, and the normal problem as with v_c0 != 0."""
    scene = tangential_scene(0.75, -1.5)
    assert scene.v_c0 == 0.0
    res, ref = simulate(scene, NUM), naive_impact(scene, STEPS, ELEMENTS)
    assert res.status == ref["status"] == "vc0_zero"
    for out in (res.e_x, res.beta_x, ref["e_x"], ref["beta_x"]):
        assert math.isnan(out)
    assert res.v_x_end == scene.v_x0 and res.omega_end == scene.omega0
    assert_close("vc0=0 naive v_x_end", ref["v_x_end"], scene.v_x0, 1e-12)
    assert_close("vc0=0 naive omega_end", ref["omega_end"], scene.omega0, 1e-12)
    # same normal scene, v_c0 = 1.5 m/s: the normal problem does not see the
    # tangential one, but the tangential scene runs on a finer step (its mode is
    # faster), so the two agree to the discretization error, not to rounding
    spinning = simulate(tangential_scene(0.75, 1.5), NUM)
    for key in ("e_z", "v_z_end", "t_contact", "u_max"):
        assert_close(f"vc0=0 naive {key}", ref[key], getattr(res, key), RTOL_NAIVE)
        assert_close(f"vc0=0 normal independent {key}", getattr(res, key),
                     getattr(spinning, key), 1e-4)
