"""The benchmark scripts run end to end on a tiny configuration (no timing is asserted)."""

import json

import pytest


def test_sweep_speedup_quick(tmp_path):
    from benchmarks import sweep_speedup

    spec = tmp_path / "tiny.toml"
    spec.write_text('model = "kelvin_voigt"\nchunk_size = 4\n[numerics]\nsteps = 60\n'
                    'elements = 12\n[grid]\nQ1 = [0.01, 0.1, 1.0]\nnu = [0.5]\n')
    data = sweep_speedup.run(spec, repeats=1)
    assert data["rows"] == 3 and data["speedup"] > 0
    json.dumps(data)


@pytest.mark.slow
def test_paths_quick(tmp_path):
    """Each path runs; the specialized kernels give the general kernel's normal
    results exactly (same arithmetic, branches folded); the continuum path is
    the more accurate one at its setting.

    Slow: on a cold cache it compiles four element kernels (110 s of CPU,
    ``-p tests.compile_profile``), among them the general kernel with arms and
    a dashpot (full stick, incremental), which no other default test runs."""
    from vimpact.bench import paths

    data = paths.run(quick=True)
    paths.plot(data, tmp_path / "paths.png")
    assert (tmp_path / "paths.png").stat().st_size > 0
    json.dumps(data)
    for case in data["specialization_equal_numerics"].values():
        assert case["max_e_z_difference"] == 0.0 and case["speedup"] > 0
    kv = data["kelvin_voigt_normal_equal_accuracy"]["settings"]
    assert kv["continuum rtol=1e-7"]["max_e_z_error"] < 1e-6
