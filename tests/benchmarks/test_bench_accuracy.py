"""The accuracy-versus-cost benchmark runs end to end on a tiny configuration
and its derived numbers are consistent (no time is asserted).

The default run checks the quick configuration as ``vimpact bench accuracy --quick``
runs it: the Verlet ladder, whose element kernels the rest of the suite compiles
anyway. The explicit and semi-implicit Euler ladders run the oblique scenes through
parallel batch kernels nothing else compiles, so the same checks on every integrator
are marked slow."""

import json
import math

import pytest

import vimpact as v
from vimpact.bench import accuracy
from vimpact.reference.closed_forms import kelvin_voigt_continuum


@pytest.fixture(scope="module", params=[
    pytest.param(None, id="quick"),
    pytest.param(accuracy.INTEGRATORS, id="every-integrator", marks=pytest.mark.slow)])
def integrators(request):
    """The ladders a run measures: the quick configuration's, or every integrator."""
    return request.param


@pytest.fixture(scope="module")
def data(integrators):
    return accuracy.run(quick=True, integrators=integrators)


def test_structure_and_plot(data, integrators, tmp_path):
    json.dumps(data, allow_nan=False)  # strict JSON
    accuracy.plot(data, tmp_path / "pareto.png")
    assert (tmp_path / "pareto.png").stat().st_size > 0
    names = integrators or accuracy.CONFIGS["quick"]["integrators"]
    assert tuple(data["integrators"]) == tuple(names)
    # presets on the element path: those of the run's integrators; as routed: all
    assert set(data["presets"]) == {p for p, n in v.PRESETS.items() if n.integrator in names}
    assert set(data["presets"]) | set(data["presets_not_on_elements"]) == set(v.PRESETS)
    assert not set(data["presets"]) & set(data["presets_not_on_elements"])
    assert set(data["presets_as_routed"]) == set(v.PRESETS)
    # the text summary and the headline figures (a failed setting has error None: the
    # quick run's envelope model check at 4/26 is one)
    text = accuracy.report(data)
    assert all(f"{n} front:" in text for n in names)
    assert all(f"preset {p}: not run on the element path" in text
               for p in data["presets_not_on_elements"])
    assert set(accuracy.figures(data)) >= {f"preset_{p}_error" for p in data["presets"]}
    for key in ("cheapest", "cheapest_by_time_model", "cheapest_e_z_only",
                "euler_over_verlet_time", "orders", "error_models", "suggested_presets"):
        assert key in data["derived"]
    grids = {r["grid"] for r in data["integrators"]["verlet"]["settings"]}
    assert grids == {"base", "refined"}
    assert set(data["derived"]["cheapest"]) == {f"{t:g}" for t in accuracy.TOLERANCES}


def test_scenes_oblique_and_reference_from_the_continuum_kernel(data):
    ref = data["reference"]
    assert ref["rtol"] == accuracy.REFERENCE_RTOL == 1e-12
    assert "continuum" in ref["e_z_source"] and "continuum" in ref["e_x_source"]
    for s in data["scenes"]:
        assert math.isfinite(s["e_x_ref"]) and s["e_x_ref"] > 0  # e_x is defined
        assert 0 < s["e_z_ref"] < 1
    # the floors are the rtol 1e-12 / 1e-10 distance; the kernel's error is up to
    # about 125 rtol, so the rtol 1e-10 run is within ~1e-8 of the exact value
    assert 0 <= ref["e_z_uncertainty_max"] == ref["e_z_floor"] < 2e-8
    assert 0 <= ref["e_x_uncertainty_max"] == ref["e_x_floor"] < 2e-8
    # so every tolerance the benchmark reports (down to 1e-7) can be verified
    for table in ("cheapest", "cheapest_e_z_only", "cheapest_e_x_only"):
        assert all(row["verifiable"] for row in data["derived"][table].values())


def test_reference_matches_the_kelvin_voigt_closed_form(data):
    """The closed form is independent of the continuum_maxwell kernel."""
    kv = [s for s in data["scenes"] if s["model"] == "kelvin_voigt"]
    assert kv
    diff = [abs(s["e_z_ref"] - kelvin_voigt_continuum(s["Q1"]).e_z) for s in kv]
    assert max(diff) < 1e-8
    assert data["reference"]["kelvin_voigt_closed_form_e_z_difference_max"] == pytest.approx(
        max(diff), rel=1e-6, abs=1e-15)
    # over the whole Q1 range of the full run, both nu of it
    specs = [dict(Q1=q, nu=nu, Q2=None) for q in (1e-3, 0.03, 1.0, 10.0) for nu in (0.0, 0.5)]
    e_z, e_x = accuracy.continuum_restitution(
        [v.Scene.from_dimensionless(s["Q1"], s["nu"]) for s in specs], accuracy.REFERENCE_RTOL)
    for s, ez, ex in zip(specs, e_z, e_x):
        assert ez == pytest.approx(kelvin_voigt_continuum(s["Q1"]).e_z, abs=1e-8)
        assert 0 < ex < 1


def test_every_setting_ran_on_the_element_path(data):
    for name, g in data["integrators"].items():
        assert g["failed_settings"] == 0
        assert g["paths"] and all(p.startswith(f"elements[{name},") for p in g["paths"])
        for r in g["settings"]:
            assert r["error"] == max(r["e_z_error_max"], r["e_x_error_max"])
            assert r["e_z_error_median"] <= r["e_z_error_max"]
            assert r["seconds_per_impact"] > 0
    # presets and for_tolerance: on the element path, as the settings
    for r in list(data["presets"].values()) + data["for_tolerance"]:
        assert all(p.startswith("elements[") for p in r["paths"]) and r["failed"] == 0
        assert sum(r["rows_per_path"].values()) == len(data["scenes"])
        assert max(r["error_by_path"].values()) == r["error"]
    assert set(data["presets_as_routed"]) == set(v.PRESETS)
    scan = data["for_tolerance_scan"]
    for r in scan["rows"]:
        assert r["error"] == max(r["e_z_error_max"], r["e_x_error_max"])
        assert r["met"] == (r["error_over_tolerance"] <= 1.0)
    assert scan["missed"] == sum(not r["met"] for r in scan["rows"])
    for c in data["continuum"]:
        assert c["failed"] == 0 and all(p.startswith("continuum") for p in c["paths"])
    # the continuum path is accurate at a tight rtol
    tight = min(data["continuum"], key=lambda c: c["rtol"])
    assert tight["e_z_error_max"] < 1e-6


def test_front_is_a_pareto_front(data):
    for g in data["integrators"].values():
        front = g["front"]
        assert front
        times = [r["seconds_per_impact"] for r in front]
        errors = [r["error"] for r in front]
        assert times == sorted(times)
        assert all(a > b for a, b in zip(errors, errors[1:]))
        # nothing off the front beats a front point in both respects
        for r in g["settings"]:
            assert not any(r["seconds_per_impact"] < f["seconds_per_impact"]
                           and r["error"] < f["error"] for f in front)


def test_cheapest_meets_its_tolerance(data):
    for tol, row in data["derived"]["cheapest"].items():
        for name in data["integrators"]:
            c = row[name]
            if c != "not reached":
                assert c["error"] <= float(tol)


def test_run_rejects_unknown_integrators_and_a_run_without_verlet():
    for bad in (("verlet", "rk4"), ("euler",)):
        with pytest.raises(ValueError, match="integrators="):
            accuracy.run(quick=True, integrators=bad)


def test_pareto_helper():
    assert accuracy.pareto([1, 2, 3, 4], [1e-2, 1e-3, 5e-3, math.inf]) == [0, 1]
    assert accuracy.pareto([2, 1], [1e-3, 1e-3]) == [1]


def test_ladder_base_grid_and_refinement():
    cfg = accuracy.CONFIGS["full"]
    lad = accuracy._ladder(cfg, "verlet")
    base = [(s, e) for s, e, g in lad if g == "base"]
    assert len(base) == 49 and (1000, 200) in base and (8000, 1600) in base
    assert all(2.5 <= s / e <= 40 for s, e, g in lad if g == "refined")
    assert len(set((s, e) for s, e, _ in lad)) == len(lad)
    euler = accuracy._ladder(cfg, "euler")
    assert max(s for s, _, _ in euler) == 128000
    assert all(s * e <= 32000 * 1600 for s, e, _ in euler)


def test_envelope_bounds_every_point():
    S = [s for s in (100, 200, 400, 800) for _ in range(3)]
    E = [e for _ in range(4) for e in (20, 40, 80)]
    err = [0.05 / s * (1.3 if i % 2 else 0.8) + 0.7 / e**2 for i, (s, e) in enumerate(zip(S, E))]
    m = accuracy.fit_envelope(S, E, err, 0.0, 1.0, 2.0)
    assert m["scale"] >= 1.0
    assert all(m["a"] / s + m["b"] / e**2 >= y * (1 - 1e-12) for s, e, y in zip(S, E, err))


def test_error_model_recovers_known_constants():
    S = [s for s in (100, 200, 400, 800, 1600) for _ in range(4)]
    E = [e for _ in range(5) for e in (20, 40, 80, 160)]
    err = [0.3 / s**2 + 0.02 / e**1.5 for s, e in zip(S, E)]
    m = accuracy.fit_error_model(S, E, err, floor=0.0, p0=2.0)
    assert m["fitted"]
    assert m["p"] == pytest.approx(2.0, rel=1e-3) and m["q"] == pytest.approx(1.5, rel=1e-3)
    assert m["a"] == pytest.approx(0.3, rel=1e-2) and m["b"] == pytest.approx(0.02, rel=1e-2)


def test_thesis_table_4_1_explicit_euler(data):
    t = data["table_4_1"]
    for n, pct in t["euler"]["percent"].items():
        # element path (not the continuum one): the thesis's first-order error
        assert pct == pytest.approx(t["thesis_percent"][n], rel=0.05)
    assert all(p.startswith("elements[euler") for p in t["euler"]["paths"])
    # the second-order integrator is far more accurate at the same steps
    assert t["verlet"]["percent"]["1000"] < 0.01 * t["euler"]["percent"]["1000"]
