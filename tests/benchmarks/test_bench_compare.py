"""``vimpact bench compare``: the flag logic on synthetic results (no benchmark
is run) and the command line's errors."""

import json

import pytest

from vimpact.bench.compare import compare, format_table, judge, load_result
from vimpact.bench.machine import figure, spread
from vimpact.cli.main import main
from vimpact.model.validation import InputError

MACHINE = {"cpu": "test CPU", "cores": 2, "numba_threads": 2, "vimpact": "0.1.0"}


def result(figures: dict, quick: bool = True) -> dict:
    return {"benchmark": "overhead", "schema": 1, "quick": quick, "machine": MACHINE,
            "figures": figures}


def timing(samples, better="lower"):
    import numpy as np

    return figure(float(np.median(samples)), "us/row", better=better, samples=samples)


OLD = result({
    "overhead_us_per_row": timing([1.00, 1.01, 0.99]),
    "kernel_us_per_row": timing([3.0, 3.03, 2.97]),
    "rows_per_second": timing([2.0e5, 2.02e5, 1.98e5], better="higher"),
    "noisy_us_per_row": timing([1.0, 1.4, 0.6]),
    "e_z_error": figure(1e-6, "-", kind="accuracy"),
    "gone": timing([1.0, 1.0]),
})


def slowed(factor_overhead=1.5):
    new = json.loads(json.dumps(OLD))
    f = new["figures"]
    f["overhead_us_per_row"]["value"] *= factor_overhead  # deliberately slowed
    f["kernel_us_per_row"]["value"] *= 0.7  # faster
    f["rows_per_second"]["value"] *= 0.6  # fewer rows per second: slower
    f["noisy_us_per_row"]["value"] *= 1.3  # within its +-40 % noise
    f["e_z_error"]["value"] *= 3.0  # less accurate
    del f["gone"]
    f["added"] = timing([1.0, 1.0])
    return new


def test_spread_is_half_the_range_over_the_median():
    assert spread([1.0, 1.2, 0.8]) == pytest.approx(0.2)
    assert spread([1.0]) is None


def test_compare_flags_what_got_worse_beyond_the_noise():
    r = compare(OLD, slowed())
    v = {k: x["verdict"] for k, x in r["figures"].items()}
    assert v == {"overhead_us_per_row": "slower", "kernel_us_per_row": "faster",
                 "rows_per_second": "slower", "noisy_us_per_row": "same",
                 "e_z_error": "less accurate"}
    assert sorted(r["flagged"]) == ["e_z_error", "overhead_us_per_row", "rows_per_second"]
    assert r["figures"]["overhead_us_per_row"]["ratio"] == pytest.approx(1.5)
    assert r["only_old"] == ["gone"] and r["only_new"] == ["added"]
    assert r["warnings"] == []
    table = format_table(r)
    assert "!! overhead_us_per_row" in table and "3 figures worse" in table


def test_same_result_flags_nothing_and_a_small_change_is_noise():
    assert compare(OLD, OLD)["flagged"] == []
    # 3 % slower on a timing whose repeats agree to 1 %: below the 5 % floor
    assert compare(OLD, slowed(1.03))["figures"]["overhead_us_per_row"]["verdict"] == "same"


def test_judge_threshold_follows_the_spread():
    old = figure(1.0, "s", samples=[0.9, 1.0, 1.1])  # spread 0.1
    assert judge(old, figure(1.25, "s", samples=[1.1, 1.25, 1.4]))["verdict"] == "same"
    assert judge(old, figure(1.5, "s", samples=[1.35, 1.5, 1.65]))["verdict"] == "slower"
    lost = judge(figure(1e-6, "-", kind="accuracy"), figure(None, "-", kind="accuracy"))
    assert lost["verdict"].startswith("less accurate")


def test_quick_against_full_and_other_machine_warn():
    other = result(OLD["figures"], quick=False)
    other["machine"] = {**MACHINE, "cores": 64}
    w = compare(OLD, other)["warnings"]
    assert any("quick" in x for x in w) and any("cores" in x for x in w)


def _write(tmp_path, name, data):
    p = tmp_path / name
    p.write_text(data if isinstance(data, str) else json.dumps(data))
    return str(p)


def test_cli_compare_table_and_json(tmp_path, capsys):
    old, new = _write(tmp_path, "old.json", OLD), _write(tmp_path, "new.json", slowed())
    assert main(["bench", "compare", old, new]) == 0  # exit code 0 even when flagged
    assert "!! overhead_us_per_row" in capsys.readouterr().out
    assert main(["bench", "compare", old, new, "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert "overhead_us_per_row" in out["flagged"]


@pytest.mark.parametrize("content, words", [
    ("{not json", "is not JSON"),
    (json.dumps({"rows": [1, 2]}), "not a vimpact benchmark result"),
    (json.dumps({"benchmark": "x", "figures": {"a": {"value": 1}}}), "malformed"),
])
def test_cli_compare_foreign_files(tmp_path, capsys, content, words):
    bad = _write(tmp_path, "bad.json", content)
    good = _write(tmp_path, "good.json", OLD)
    assert main(["bench", "compare", good, bad]) == 2
    err = capsys.readouterr().err
    assert words in err and len(err.strip().splitlines()) == 1


def test_cli_errors_are_one_line_exit_2(tmp_path, capsys):
    good = _write(tmp_path, "good.json", OLD)
    cases = [(["bench", "nosuch"], "accuracy, throughput"),
             (["bench", "compare", good], "two result files"),
             (["bench", "compare", good, str(tmp_path / "missing.json")], "missing.json"),
             (["bench", "list", "extra.json"], "only 'vimpact bench compare' takes files")]
    for argv, words in cases:
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert words in err and len(err.strip().splitlines()) == 1, err


def test_load_result_rejects_foreign_json(tmp_path):
    with pytest.raises(InputError, match="not a vimpact benchmark result"):
        load_result(_write(tmp_path, "a.json", [1, 2, 3]))


def test_cli_list(capsys):
    assert main(["bench", "list"]) == 0
    out = capsys.readouterr().out
    for name in ("accuracy", "throughput", "scaling", "paths", "overhead", "imports"):
        assert name in out
