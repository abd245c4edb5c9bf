"""Throughput and scaling benchmarks: the pure-Python baseline does the NumPy
reference's work and converges with it, and both benchmarks run end to end on
a tiny configuration (no timing is asserted)."""

import functools
import json
import math

import pytest

import vimpact as v
from tests.oracles.naive import naive_impact
from vimpact.bench import scaling
from vimpact.bench.pure_python import pure_python_impact

SCENES = {
    "kelvin_voigt": v.Scene.from_dimensionless(0.1, 0.5),
    "standard_solid": v.Scene.from_dimensionless(0.03, 0.2, Q2=0.5),
    "stiff_arm": v.Scene.from_dimensionless(1.0, 0.0, Q2=10.0),
    "physical_spin": v.Scene(v.Material.standard_solid(nu=0.3, G1=1e6, G2=2e6, eta=10.0),
                             R=0.01, m=0.004, v_z0=1.0, v_x0=0.3, omega0=20.0),
    "normal_only": v.Scene(v.Material.kelvin_voigt(nu=0.4, E=5e8, eta=300.0),
                           R=0.01, m=0.004, v_z0=2.0),
}


@functools.cache
def pure(name: str, steps: int, elements: int) -> dict:
    """:func:`pure_python_impact` of ``SCENES[name]`` (deterministic: run once per session,
    the tests below share the runs at 60/12 and 240/48)."""
    return pure_python_impact(SCENES[name], steps, elements)


@functools.cache
def naive(name: str, steps: int, elements: int) -> dict:
    """:func:`naive_impact` of ``SCENES[name]``, run once per session as :func:`pure`."""
    return naive_impact(SCENES[name], steps, elements)


@pytest.mark.parametrize("name", SCENES)
def test_pure_python_does_the_work_of_naive(name):
    """Same discretization and end of the impact: the same time steps and row
    elements as the NumPy reference (the work the throughput compares)."""
    scene = SCENES[name]
    ref = naive(name, 60, 12)
    got = pure(name, 60, 12)
    assert got["status"] == "ok" and ref["status"] in ("ok", "vc0_zero", "half_space")
    assert got["steps"] == ref["steps"] and got["n_elements"] >= 13  # refined: 13 or more
    if scene.v_c0 == 0.0:
        assert math.isnan(got["e_x"]) and math.isnan(ref["e_x"])
    else:
        assert math.isfinite(got["e_x"]) and got["e_x"] > 0.0


def test_pure_python_converges_to_the_continuum_solution():
    """Kelvin-Voigt e_z against the closed-form continuum value: the error falls
    under refinement and is below the default preset's 1e-4 already at 60/12."""
    from vimpact.reference.closed_forms import kelvin_voigt_continuum

    exact = kelvin_voigt_continuum(0.1).e_z
    errors = [abs(pure("kelvin_voigt", s, e)["e_z"] - exact) for s, e in ((60, 12), (240, 48))]
    assert errors[0] < 1e-4 and errors[1] < errors[0]


@pytest.mark.parametrize("name", SCENES)
def test_pure_python_and_naive_converge_together(name):
    """Two discretizations of one model: their difference shrinks under
    refinement, at least first order (4x finer steps and elements: at least
    2x smaller on e_z; smaller on e_x)."""
    scene = SCENES[name]
    d = []
    for s, e in ((60, 12), (240, 48)):
        a, b = pure(name, s, e), naive(name, s, e)
        assert a["steps"] == b["steps"]
        d.append((abs(a["e_z"] - b["e_z"]), abs(a["e_x"] - b["e_x"])))
    assert d[1][0] <= d[0][0] / 2.0
    if scene.v_c0 != 0.0:
        assert d[1][1] < d[0][1]


def test_pure_python_rejects_what_it_does_not_model():
    prony = v.Material.prony(nu=0.5, G_inf=1e6, arms=[(1e6, 1e-3), (2e6, 1e-5)])
    with pytest.raises(ValueError, match="one Maxwell arm"):
        pure_python_impact(v.Scene(prony, R=0.01, m=0.004, v_z0=1.0), 60, 12)
    seed = v.Scene.from_dimensionless(0.1, 0.5, tangential_memory="seed")
    with pytest.raises(ValueError, match="incremental"):
        pure_python_impact(seed, 60, 12)


def _finite_positive(x):
    return isinstance(x, float) and math.isfinite(x) and x > 0.0


def test_throughput_quick(tmp_path):
    """Through the repository script (the same code as ``vimpact bench throughput``)."""
    from benchmarks import throughput as script

    script.main(["--quick", "--out", str(tmp_path)])
    assert (tmp_path / "throughput_quick.png").stat().st_size > 0
    data = json.loads((tmp_path / "throughput_quick.json").read_text())
    cfg, impls = data["config"], data["implementations"]
    assert data["machine"]["cores"] >= 1 and cfg["quick"]
    assert all(p.startswith("elements") for p in data["kernel_paths"])
    numerics = v.Numerics(**cfg["numerics"])
    unrefined = math.ceil(numerics.row_width * numerics.elements)
    assert {"kernel_1_thread", "numpy", "pure_python"} <= set(impls)
    n_scenes = {"kernel_1_thread": cfg["n_scenes"], "kernel_2_threads": cfg["n_scenes"],
                "numpy": cfg["n_numpy"], "pure_python": cfg["n_python"]}
    for name, x in impls.items():
        assert x["n_scenes"] == len(x["steps"]) == len(x["elements"]) == n_scenes[name]
        assert all(k > 0 for k in x["steps"]) and all(n >= unrefined for n in x["elements"])
        assert x["element_updates"] == sum(k * n for k, n in zip(x["steps"], x["elements"]))
        assert len(x["seconds"]) == (cfg["repeats"] if name.startswith("kernel")
                                     else cfg["baseline_repeats"])
        assert _finite_positive(x["element_updates_per_second"])
        if name.startswith("kernel"):
            assert len(x["cpu_seconds"]) == len(x["seconds"])
    # same scenes, same algorithm and discretization: the same steps and rows
    for name in ("numpy", "pure_python"):
        n = impls[name]["n_scenes"]
        assert impls[name]["steps"] == impls["kernel_1_thread"]["steps"][:n]
        assert impls[name]["elements"] == impls["kernel_1_thread"]["elements"][:n]
    ratios = data["ratios"]
    for key in ("kernel_over_numpy", "kernel_over_pure_python", "numpy_over_pure_python"):
        assert _finite_positive(ratios[key])
    if "kernel_2_threads" in impls:
        assert _finite_positive(ratios["two_threads_over_one"])


def test_scaling_quick(tmp_path):
    from vimpact.bench.machine import run_and_write

    run_and_write("scaling", scaling, True, tmp_path)
    assert (tmp_path / "scaling.png").stat().st_size > 0
    data = json.loads((tmp_path / "scaling.json").read_text())
    assert set(data["sweeps"]) == {"scenes", "elements", "steps"}
    for name, sweep in data["sweeps"].items():
        assert sweep["x"] == data["config"][name]
        assert len(sweep["seconds"]) == len(sweep["median_seconds"]) == len(sweep["x"])
        assert all(len(ts) == data["config"]["repeats"] for ts in sweep["seconds"])
        assert all(t > 0.0 for t in sweep["median_seconds"])
        assert math.isfinite(sweep["fit"]["exponent"]) and sweep["fit"]["prefactor"] > 0.0
        assert len(sweep["local_exponents"]) == len(sweep["x"]) - 1
        assert all(math.isfinite(p) for p in sweep["local_exponents"])


def test_fit_power_law_recovers_exponent():
    x = [8.0, 16.0, 32.0, 64.0]
    fit = scaling.fit_power_law(x, [3e-3 * xi**1.5 for xi in x])
    assert fit["exponent"] == pytest.approx(1.5) and fit["prefactor"] == pytest.approx(3e-3)
