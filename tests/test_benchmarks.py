"""The benchmark scripts run end to end on a tiny configuration (no timing is asserted)."""

import json

from benchmarks import default_accuracy


def test_default_accuracy_quick(tmp_path):
    data = default_accuracy.run(quick=True)
    default_accuracy.plot(data, tmp_path / "acc.png")
    assert (tmp_path / "acc.png").stat().st_size > 0
    json.dumps(data)  # serializable
    assert set(data["presets"]) == {"fast", "default"}
    assert max(data["presets"]["default"]["e_z_error"]) < 1e-4
