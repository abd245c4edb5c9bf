"""The ``overhead`` and ``imports`` benchmarks and the ``vimpact bench NAME``
command run end to end on a small configuration: files written, JSON keys
(no time is asserted)."""

import json
import math
import re

import pytest

from vimpact.bench import BENCHMARKS, imports, load, overhead
from vimpact.cli.main import main

FIGURE_KEYS = {"value", "unit", "better", "kind", "spread", "repeats"}


def _check_common(data: dict, name: str) -> None:
    assert data["benchmark"] == name and data["schema"] == 1 and data["quick"] is True
    for key in ("cpu", "cores", "numba_threads", "python", "numpy", "numba", "vimpact"):
        assert key in data["machine"]
    assert data["figures"]
    for f in data["figures"].values():
        assert FIGURE_KEYS <= set(f) and f["kind"] in ("time", "accuracy")


def test_registry_loads_every_benchmark():
    for name in BENCHMARKS:
        m = load(name)
        assert callable(m.run) and callable(m.plot) and callable(m.figures) and m.TITLE


def test_overhead_through_the_command(tmp_path, monkeypatch, capsys):
    monkeypatch.setitem(overhead.CONFIGS, "quick", dict(kv_rows=2000, kv_repeats=2,
                                                        element_rows=40, element_repeats=2,
                                                        one_impact_calls=20,
                                                        one_impact_repeats=3))
    assert main(["bench", "overhead", "--quick", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert out.startswith("machine: ") and "continuum_overhead_us_per_row" in out
    assert (tmp_path / "overhead.png").stat().st_size > 0
    data = json.loads((tmp_path / "overhead.json").read_text())
    _check_common(data, "overhead")
    for key, rows, status in (("continuum", 2000, "normal_only"), ("elements", 40, "ok")):
        d = data[key]
        assert d["rows"] == rows and len(d["total_s"]) == len(d["kernel_s"]) == 2
        assert all(t >= k > 0.0 for t, k in zip(d["total_s"], d["kernel_s"]))
        assert d["statuses"] == {status: rows}
    assert list(data["continuum"]["paths"]) == ["continuum[kelvin_voigt,normal]"]
    assert all(p.startswith("elements[") and "tangential" in p and "friction" in p
               for p in data["elements"]["paths"])
    assert {"continuum_overhead_met", "element_overhead_met",
            "kv_rows_per_second_met"} <= set(data["targets"])
    one = data["one_impact"]
    assert len(one["scenes"]) == 3
    for rec in one["scenes"].values():
        # the Python outside the kernel, measured with the kernel replaced by its row
        assert 0.0 < rec["outside_kernel_us"] and len(rec["outside_kernel_us_samples"]) == 3
        if one["before_commit"] is not None:  # a checkout with the history at hand
            assert rec["same_result_as_before"] is True
            assert rec["before_outside_kernel_us"] > 0.0


def test_overhead_columns_are_valid_kelvin_voigt_rows():
    """The random rows are what the module says: ``a_H / R`` and ``Q1`` in
    their ranges (checked through the package's own Hertz scales)."""
    import numpy as np

    from vimpact.model.hertz import Q1_PER_TAU, hertz_scales

    c = overhead.scene_columns(500, seed=3)
    oblique = overhead.scene_columns(500, seed=3, oblique=True)
    assert np.all((oblique["mu"] >= 0.1) & (oblique["mu"] <= 0.5))
    assert np.array_equal(oblique["v_x0_m_s"], oblique["v_z0_m_s"])
    hz = hertz_scales(c["G_inf_Pa"], c["nu"], c["R_m"], c["m_kg"], c["v_z0_m_s"])
    a_over_R = hz.a_H / c["R_m"]
    assert np.all((a_over_R > 0.003 * (1 - 1e-9)) & (a_over_R < 0.03 * (1 + 1e-9)))
    Q1 = c["eta0_Pa_s"] / c["G_inf_Pa"] / hz.T * Q1_PER_TAU
    assert np.all((Q1 >= 1e-3 * (1 - 1e-9)) & (Q1 <= 1.0 * (1 + 1e-9)))


def test_imports(tmp_path, monkeypatch):
    """The probe on three small targets: the heavy module a statement pulls in is found
    (numpy, of :data:`imports.HEAVY` the cheapest to import in a fresh interpreter; a
    kernel module's numba would cost that process about 0.3 s of CPU)."""
    monkeypatch.setitem(imports.CONFIGS, "quick", dict(repeats=1))
    monkeypatch.setattr(imports, "TARGETS", {"python": "pass", "vimpact": "import vimpact",
                                             "numpy": "import numpy"})
    from vimpact.bench.machine import run_and_write

    data, js, png = run_and_write("imports", imports, True, tmp_path)
    assert png.stat().st_size > 0 and json.loads(js.read_text()) == data
    _check_common(data, "imports")
    t = data["targets"]
    assert t["python"]["heavy"] == []
    assert t["numpy"]["heavy"] == ["numpy"]
    for rec in t.values():
        assert len(rec["wall_s"]) == 1 and math.isfinite(rec["median_wall_s"])
    assert set(data["figures"]) == {"import_vimpact_s", "import_numpy_s",
                                    "python_c_import_vimpact_wall_s"}


def test_imports_probe_reports_a_failed_import():
    with pytest.raises(RuntimeError, match="no_such_module"):
        imports.probe("import no_such_module")


def test_a_benchmark_is_registered_by_one_line(tmp_path, monkeypatch, capsys):
    """A module with ``run``/``plot`` (and figures in its data) outside the
    package runs as ``vimpact bench NAME`` once it has its line in BENCHMARKS."""
    from vimpact import bench

    (tmp_path / "tiny_bench.py").write_text(
        'TITLE = "tiny"\n'
        "from vimpact.bench.machine import figure, machine_info, save_figure, use_agg\n"
        "def run(quick):\n"
        "    return {'machine': machine_info(), 'x': [1, 2],\n"
        "            'figures': {'t_s': figure(0.5, 's', samples=[0.4, 0.5, 0.6])}}\n"
        "def plot(data, path):\n"
        "    use_agg()\n"
        "    import matplotlib.pyplot as plt\n"
        "    fig, ax = plt.subplots()\n"
        "    ax.plot(data['x'])\n"
        "    save_figure(fig, path)\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setitem(bench.BENCHMARKS, "tiny", "tiny_bench")  # the one line
    out = tmp_path / "out"
    assert main(["bench", "list"]) == 0
    assert re.search(r"^tiny +tiny$", capsys.readouterr().out, re.M)
    assert main(["bench", "tiny", "--quick", "--out", str(out)]) == 0
    data = json.loads((out / "tiny.json").read_text())
    assert (out / "tiny.png").stat().st_size > 0
    _check_common(data, "tiny")
    assert data["figures"]["t_s"]["spread"] == pytest.approx(0.2)
    monkeypatch.setitem(bench.BENCHMARKS, "gone", "no_such_module_here")
    assert main(["bench", "gone"]) == 2
    assert "not importable here" in capsys.readouterr().err


def test_replaced_kernels_cover_every_single_impact_path():
    """The one-impact overhead is measured with the kernel replaced by a recorded
    row: a scene of each path (continuum stick, continuum normal, elements) must
    then give the recorded scene's result, not its own (the kernel never ran)."""
    import vimpact as v
    from vimpact.engine import pack

    mat = v.Material.kelvin_voigt(nu=0.5, E=5e10, eta=1e5)
    other = v.Material.kelvin_voigt(nu=0.5, E=5e10, eta=1e6)
    fast = v.Numerics.preset("fast")
    for kw, num in ((dict(v_x0=5.0), None), (dict(tangential="none"), None),
                    (dict(v_x0=5.0, mu=0.3), fast)):
        with overhead._KernelsReplaced([pack]) as recorder:
            recorded = v.simulate(v.Scene(mat, R=0.2, m=10.0, v_z0=10.0, **kw), num)
        own = v.simulate(v.Scene(other, R=0.2, m=10.0, v_z0=10.0, **kw), num)
        assert own.e_z != recorded.e_z  # the two scenes differ
        with overhead._KernelsReplaced([pack], recorder.row, recorder.returned):
            replaced = v.simulate(v.Scene(other, R=0.2, m=10.0, v_z0=10.0, **kw), num)
        assert replaced.e_z == recorded.e_z, kw
