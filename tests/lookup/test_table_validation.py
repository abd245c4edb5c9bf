"""Tables are validated before use (RestitutionTable.open, hence `vimpact table`, plots).

Each test writes a small broken table with pyarrow (a grid made by ``simulate_batch``,
then one defect) and checks that opening it is an ``InputError`` naming the file, the
column and the offending value and row; and that a sound table with failed rows and
round-off at the physical bounds still opens.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from tests.lookup.test_table import make_table, write_table
from vimpact import cli
from vimpact.lookup.table import RestitutionTable, validate_table
from vimpact.model.validation import InputError


@pytest.fixture(scope="module")
def rows(tmp_path_factory) -> pd.DataFrame:
    """A sound 3 Q1 x 2 nu Kelvin-Voigt grid (one failed row, NaN outputs)."""
    path = tmp_path_factory.mktemp("valid") / "kv.parquet"
    make_table(path, Q1=np.array([0.01, 0.1, 1.0]), nu=(0.3, 0.5), fail=(5,))
    return pq.read_table(path).to_pandas()


def open_broken(tmp_path, frame: pd.DataFrame, model: str = "kelvin_voigt"):
    path = tmp_path / "broken.parquet"
    write_table(path, frame, model)
    return path, lambda: RestitutionTable.open(path)


def test_a_sound_table_with_failed_rows_and_round_off_opens(tmp_path, rows):
    frame = rows.copy()
    frame.loc[0, "e_z"] = 1.0 + 5e-7  # within 1e-6 of an elastic bound
    frame.loc[1, "beta_x"] = -1.0 - 5e-7
    _, opened = open_broken(tmp_path, frame)
    table = opened()
    assert table.info()["statuses"] == {"ok": 5, "time_limit": 1}


@pytest.mark.parametrize("column, row, value, words", [
    ("status", 2, "exploded", r"column status = 'exploded' at row 2 is not a vimpact status"),
    ("e_z", 1, np.nan, r"column e_z = nan at row 1 with status ok"),
    ("beta_x", 3, np.inf, r"column beta_x = inf at row 3 with status ok"),
    ("e_z", 4, 1.01, r"column e_z = 1.01 at row 4 is outside its physical range \(in \[0, 1"),
    ("e_z", 0, -0.2, r"column e_z = -0.2 at row 0 is outside its physical range"),
    ("e_x", 2, 1.5, r"column e_x = 1.5 at row 2 is outside its physical range"),
    ("beta_x", 1, -1.2, r"column beta_x = -1.2 at row 1 .*\|beta_x\| <= 1 \+ 1e-6"),
    ("Q1", 3, -0.1, r"column Q1 = -0.1 at row 3 is outside its domain \(Q1 >= 0\)"),
    ("nu", 0, np.nan, r"column nu = nan at row 0 with status ok"),
    ("nu", 5, 0.7, r"column nu = 0.7 at row 5 is outside its domain \(nu in \[0, 0.5\]\)"),
    ("theta_ratio", 2, 0.0, r"column theta_ratio = 0 at row 2 is outside its domain"),
])
def test_a_bad_value_is_refused_naming_file_column_value_and_row(tmp_path, rows, column, row,
                                                                  value, words):
    frame = rows.copy()
    frame[column] = frame[column].astype(object if column == "status" else float)
    frame.loc[row, column] = value
    path, opened = open_broken(tmp_path, frame)
    with pytest.raises(InputError, match=words) as info:
        opened()
    assert str(path) in str(info.value)


def test_a_failed_row_may_have_nan_outputs_but_not_a_negative_axis(tmp_path, rows):
    frame = rows.copy()
    assert frame.loc[5, "status"] == "time_limit" and np.isnan(frame.loc[5, "e_z"])
    frame.loc[5, "Q1"] = -1.0
    _, opened = open_broken(tmp_path, frame)
    with pytest.raises(InputError, match=r"column Q1 = -1 at row 5"):
        opened()


def test_standard_solid_rows_need_q2_kelvin_voigt_rows_do_not(tmp_path, rows):
    frame = rows.assign(Q2=1.0, model="standard_solid")
    frame.loc[2, "Q2"] = np.nan
    _, opened = open_broken(tmp_path, frame, "standard_solid")
    with pytest.raises(InputError, match=r"column Q2 = nan at row 2 with status ok"):
        opened()
    frame.loc[2, "model"] = "kelvin_voigt"  # the Kelvin-Voigt limit: Q2 = NaN is its mark
    _, opened = open_broken(tmp_path, frame, "standard_solid")
    assert opened().model == "standard_solid"


def test_duplicated_nodes_are_refused(tmp_path, rows):
    frame = pd.concat([rows, rows.iloc[[3]]], ignore_index=True)
    _, opened = open_broken(tmp_path, frame)
    with pytest.raises(InputError, match=r"duplicated node .*rows 3, 6 are all at Q1 = "):
        opened()


def test_a_foreign_parquet_file_is_refused(tmp_path, rows):
    path = tmp_path / "foreign.parquet"
    pq.write_table(pa.Table.from_pandas(rows, preserve_index=False), path)  # no vimpact.* keys
    with pytest.raises(InputError, match="foreign.parquet.*vimpact") as info:
        RestitutionTable.open(path)
    assert "not allowed" in str(info.value)
    assert len(RestitutionTable.open(path, validate=False)) == len(rows)  # to inspect it
    with pytest.raises(InputError, match="no vimpact metadata"):
        validate_table(rows, {}, path)


def test_a_truncated_file_is_refused(tmp_path, rows):
    path, _ = open_broken(tmp_path, rows)
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2])
    with pytest.raises(InputError, match="broken.parquet"):
        RestitutionTable.open(path)


def test_cli_refuses_a_broken_table_in_one_line_exit_2(tmp_path, rows, capsys):
    frame = rows.copy()
    frame.loc[4, "e_z"] = 1.5
    path, _ = open_broken(tmp_path, frame)
    for args in (["table", "info", str(path)],
                 ["table", "lookup", str(path), "--Q1", "0.1", "--nu", "0.4"]):
        assert cli.main(args) == 2
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1 and "column e_z = 1.5 at row 4" in err
