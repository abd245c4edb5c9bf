"""The shipped standard-solid table (adaptive) over its whole range, and the thesis's
figures 5.4/5.5 drawn from it alone, against direct simulation at off-node points."""

from pathlib import Path

import numpy as np
import pytest

from tests.lookup import shipped

ROOT = Path(__file__).resolve().parents[2]
TABLE = ROOT / "sweeps" / "tables" / "standard_solid_table.parquet"


@pytest.fixture(scope="module")
def table():
    return shipped(TABLE.stem)


def test_covers_the_whole_range_and_states_its_error(table):
    assert table.is_adaptive
    info = table.info()
    assert info["ranges"]["Q1"] == pytest.approx([1e-3, 100.0])
    assert info["ranges"]["Q2"] == pytest.approx([1e-3, 100.0])
    err = table.interpolation_error
    assert err is not None and err["points"] >= 2000
    for k in ("e_z", "beta_x"):
        assert err["outputs"][k]["max"] is not None
    # a lookup at the bottom of the range answers (the tensor table refused Q2 < 4)
    out = table.lookup(15.6, 0.5, Q2=1e-3)
    assert 0.0 < out["e_z"] < 1.0 and out["error_bound"] is not None
    assert TABLE.stat().st_size < 20e6


def test_below_its_range_the_band_answers_or_its_spec_is_named(table):
    """Below Q2 = 1e-3 the band table beside it answers; without it the refusal names
    the spec that builds it (vimpact.lookup.band)."""
    from vimpact.lookup.band import BAND_FILE, BAND_SPEC
    from vimpact.model.validation import InputError

    if (TABLE.parent / BAND_FILE).is_file():
        out = table.lookup(30.0, 0.3, Q2=1e-4)
        assert 0.0 < out["e_z"] < 1.0 and out["error_bound"] is not None
    else:
        with pytest.raises(InputError, match="build it with") as exc:
            table.lookup(30.0, 0.3, Q2=1e-4)
        assert BAND_SPEC in str(exc.value) and (ROOT / BAND_SPEC).is_file()


@pytest.mark.slow
def test_figures_5_4_and_5_5_from_the_table_alone(table):
    """e_z(Q1) and e_x(Q1) for Q2 = 0.01 ... 1 at nu = 0.5 (thesis figs. 5.4/5.5) from the
    lookup, compared with direct simulation at points off the table's nodes; the
    difference stays within the table's stated bound (1.5 x the largest error measured
    at its held-out points) and, where the build met its tolerance, within 1e-5."""
    from vimpact.tablebuild.verify import numerics_of, simulate_dimensionless

    q1 = np.logspace(-3, 1.5, 23) * 1.0371  # off the lattice's nodes
    q2 = np.array([0.01, 0.03, 0.1, 0.3, 1.0]) * 1.013
    Q1, Q2 = (a.ravel() for a in np.meshgrid(q1, q2, indexing="ij"))
    nu = np.full(Q1.size, 0.5)
    look = table.lookup(Q1, nu, Q2=Q2)
    sim = simulate_dimensionless("standard_solid", Q1, nu, Q2, numerics=numerics_of(table))
    bound = table.error_bound()
    for k in ("e_z", "e_x"):
        gap = np.max(np.abs(look[k] - sim[k].to_numpy()))
        assert gap <= bound[k], (k, gap, bound[k])
        if table.meta("grid_refinement")["met"]:
            assert gap <= 1e-5, (k, gap)


def test_the_shipped_band_meets_its_neighbours_within_their_bounds(table):
    """At the seams the two independently built tables agree within the sum of their
    stated bounds: the main table and the band at Q2 = 1e-3, the band and the
    Kelvin-Voigt table (plus the band's measured distance to that limit) at 1e-5."""
    from vimpact.lookup.band import BAND_FILE, KELVIN_VOIGT_FILE

    band_path = TABLE.parent / BAND_FILE
    if not band_path.is_file():
        pytest.skip("no band table beside the main one")
    band = shipped(band_path.stem)
    kv = shipped(Path(KELVIN_VOIGT_FILE).stem)
    rng = np.random.default_rng(7)
    q1, nu = 10 ** rng.uniform(-3, 2, 300), rng.uniform(0, 0.5, 300)
    main_b, band_b, kv_b = table.error_bound(), band.error_bound(), kv.error_bound()
    at_top = band.lookup(q1, nu, Q2=np.full(300, 1e-3))
    main = table.lookup(q1, nu, Q2=np.full(300, 1e-3))
    at_bottom = band.lookup(q1, nu, Q2=np.full(300, 1e-5))
    limit = kv.lookup(q1, nu)
    gap = band.meta("kelvin_voigt_limit")["gap"]
    for k in ("e_z", "beta_x"):
        assert np.max(np.abs(at_top[k] - main[k])) <= main_b[k] + band_b[k]
        assert np.max(np.abs(at_bottom[k] - limit[k])) <= band_b[k] + kv_b[k] + gap[k]


def test_info_names_the_table_that_answers_below(table):
    """`table info` says which neighbour answers below the Q2 range: the band below the
    main table, the Kelvin-Voigt table (with the measured distance) below the band."""
    from vimpact.lookup.band import BAND_FILE, KELVIN_VOIGT_FILE
    from vimpact.lookup.info import format_info

    band_path = TABLE.parent / BAND_FILE
    if not band_path.is_file():
        assert table.info()["below"] is None
        return
    below = table.info()["below"]
    assert below["file"] == BAND_FILE and below["Q2"] == pytest.approx(1e-3)
    assert f"Q2 < 0.001: {BAND_FILE} beside it answers" in format_info(table.info())
    band = shipped(band_path.stem).info()
    assert band["below"]["file"] == KELVIN_VOIGT_FILE and band["below"]["Q2"] == pytest.approx(1e-5)
    assert 0.0 < band["below"]["limit_distance"]["beta_x"] < 1e-5
    kv = shipped(Path(KELVIN_VOIGT_FILE).stem)
    assert kv.info()["below"] is None
