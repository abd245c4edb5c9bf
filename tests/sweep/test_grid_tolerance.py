"""``[grid] tolerance``: the sweep refines its grid before chunking, caches the refined
axes for ``--resume``, stores the refinement report and the measured interpolation
error, and refuses a tolerance it cannot reach.

Tiny Kelvin-Voigt grids on the continuum path (errors ~1e-8): seconds each. The
tolerance is checked against direct simulations at points the refinement never
used (a seed it did not draw from).
"""

import json

import numpy as np
import pytest

from vimpact.lookup.table import RestitutionTable
from vimpact.model.validation import InputError
from vimpact.sweep import SweepInterrupted, load_spec, parts_dir, read_metadata
from vimpact.tablebuild import refine
from vimpact.tablebuild import sweep as build
from vimpact.tablebuild.sweep import run_sweep
from vimpact.tablebuild.verify import held_out_errors

TOL = 1e-4
KV = """
model = "kelvin_voigt"
chunk_size = 16
output = "kv.parquet"

[grid]
Q1 = [0.01, 0.1, 1.0]
nu = [0.0, 0.5]
tolerance = {tol}
"""


def write(tmp_path, tol=TOL, name="kv.toml"):
    path = tmp_path / name
    path.write_text(KV.format(tol=tol))
    return path


@pytest.fixture(scope="module")
def swept(tmp_path_factory):
    """A refined sweep interrupted after its first chunk, then resumed: the refinement
    runs once (the resume reads it from the parts directory)."""
    tmp = tmp_path_factory.mktemp("tol")
    spec_path = write(tmp)
    out = tmp / "kv.parquet"
    calls = []
    real = refine.refine_grid

    def counted(*args, **kwargs):
        calls.append(1)
        return real(*args, **kwargs)

    def stop_after_first_chunk(done, total):
        raise KeyboardInterrupt

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(refine, "refine_grid", counted)
        with pytest.raises(SweepInterrupted):
            run_sweep(spec_path, progress=stop_after_first_chunk)
        cache = json.loads((parts_dir(out) / build.GRID_CACHE).read_text())
        run_sweep(spec_path, resume=True, progress=False)
    return spec_path, out, cache, len(calls)


def test_resume_reads_the_cached_refinement(swept):
    spec_path, out, cache, calls = swept
    assert calls == 1
    assert cache["sweep_hash"] == load_spec(spec_path).sweep_hash
    assert not parts_dir(out).exists()  # the cache left with the parts
    table = RestitutionTable.open(out)
    assert table.meta("grid_refinement") == cache["report"]
    np.testing.assert_array_equal(np.unique(table.data["Q1"]), cache["axes"]["Q1"])
    np.testing.assert_array_equal(np.unique(table.data["nu"]), cache["axes"]["nu"])


def test_refined_sweep_meets_its_tolerance_at_points_it_never_saw(swept):
    _, out, _, _ = swept
    table = RestitutionTable.open(out)
    report = table.meta("grid_refinement")
    assert report["met"] and report["tolerance"] == TOL
    # the refinement had to insert nodes, and says where and what error it found there
    inserted = report["rounds"][0]["inserted"]
    assert inserted and all(c["max_error"] > TOL / 2 for v in inserted.values() for c in v)
    grid = table.info()["grid"]
    assert grid["Q1"] > 3 and grid["nu"] > 2
    assert len(table.data) == grid["Q1"] * grid["nu"] == read_metadata(out)["rows"]
    assert set(table.data["Q1"]) >= {0.01, 0.1, 1.0}  # the spec's nodes stay
    # the interpolation error was measured on the finished table and stored
    measured = table.interpolation_error
    assert measured["kinds"]["axis"] > 0 and measured["kinds"]["random"] > 0
    assert max(measured["outputs"][k]["max"] for k in ("e_z", "beta_x")) <= TOL
    # independent check: fresh random points, another seed, direct simulation
    fresh = held_out_errors(table, n=150, seed=2024, kinds=("random",))
    assert fresh["e_z_err"].max() <= TOL and fresh["beta_x_err"].max() <= TOL


def test_unreachable_tolerance_is_refused_and_nothing_is_written(tmp_path, monkeypatch):
    monkeypatch.setattr(refine, "MAX_AXIS_NODES", 4)
    spec_path = write(tmp_path, tol=1e-7)
    with pytest.raises(InputError, match=r"grid\.tolerance = 1e-07 .*smallest error it "
                                         r"reached.*e_z [0-9.e-]+, beta_x [0-9.e-]+"):
        run_sweep(spec_path, progress=False)
    assert not (tmp_path / "kv.parquet").exists()
    assert not (parts_dir(tmp_path / "kv.parquet") / build.GRID_CACHE).exists()


def test_grid_tolerance_on_an_elastic_grid_is_refused(tmp_path):
    path = tmp_path / "el.toml"
    path.write_text('model = "elastic"\n[grid]\nnu = [0.0, 0.5]\ntolerance = 1e-5\n')
    with pytest.raises(InputError, match="grid.tolerance = 1e-05 is not allowed for a "
                                         "elastic grid"):
        run_sweep(path, progress=False)


@pytest.mark.slow
def test_refined_dataset_keeps_only_its_parts(tmp_path):
    """Dataset layout: the cache sits among the parts while the sweep runs and leaves
    before _common_metadata is written (a dataset holds only its parts)."""
    from vimpact.tableformat.integrity import verify_table

    path = tmp_path / "kv.toml"
    path.write_text(KV.format(tol=TOL).replace('output = "kv.parquet"',
                                               'output = "kv.parquet"\nlayout = "dataset"'))

    def stop_after_first_chunk(done, total):
        raise KeyboardInterrupt

    with pytest.raises(SweepInterrupted):
        run_sweep(path, progress=stop_after_first_chunk)
    assert (tmp_path / "kv.parquet" / build.GRID_CACHE).is_file()
    out = run_sweep(path, resume=True, progress=False)
    assert not (out / build.GRID_CACHE).exists()
    assert "content hash verified" in verify_table(out)
    table = RestitutionTable.open(out)
    assert table.meta("grid_refinement")["met"]
    assert table.interpolation_error["outputs"]["beta_x"]["max"] <= TOL
