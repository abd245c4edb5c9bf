"""The start-up and threading benchmarks run end to end on their quick configuration
(no time is asserted). Marked slow: they start processes with an empty numba
cache or compile a kernel that nothing else in the default run needs."""

import json

import pytest

from vimpact.bench import specialization, threads
from vimpact.bench.machine import annotate


@pytest.mark.slow
def test_specialization_quick_outputs_identical(tmp_path):
    """The run-time-flag kernels compute exactly what the specialized ones do."""
    data = annotate("specialization", specialization, specialization.run(quick=True), True)
    json.dumps(data, allow_nan=False)
    assert set(data["candidates"]) == set(specialization.QUICK)
    for cand in data["candidates"].values():
        assert len(cand["families"]) == 2
        for case in cand["families"].values():
            assert case["identical_outputs"] and case["rows"] > 0
    specialization.plot(data, tmp_path / "s.png")
    assert (tmp_path / "s.png").stat().st_size > 0


@pytest.mark.slow
def test_threads_quick_reports_every_configuration(tmp_path, monkeypatch):
    monkeypatch.setitem(threads.REPEATS, "quick", 5)
    data = annotate("threads", threads, threads.run(quick=True), True)
    json.dumps(data, allow_nan=False)
    for load in ("as_is", "busy"):
        assert set(data[load]) == set(threads.CONFIGS)
        default = data[load]["package default"]
        assert default["layer"] in ("tbb", "omp", "workqueue")
    threads.plot(data, tmp_path / "t.png")
    assert (tmp_path / "t.png").stat().st_size > 0
