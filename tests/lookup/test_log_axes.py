"""One list of log axes: the table interpolates theta_ratio in log, so its held-out
mid-points are geometric means too (the verification checks the cell's worst point)."""

import numpy as np

from vimpact.lookup.interpolate import LOG_AXES
from vimpact.tablebuild.verify import held_out_points


def test_theta_ratio_mid_points_are_geometric():
    assert {"Q1", "Q2", "theta_ratio"} <= set(LOG_AXES) and "nu" not in LOG_AXES
    pts = held_out_points(["Q1", "nu", "theta_ratio"],
                          [np.array([0.01, 1.0]), np.array([0.0, 0.5]), np.array([0.1, 0.4])],
                          n_random=0, kinds=("axis",))
    by_axis = {a: sorted(set(pts.loc[pts["axis"] == a, a])) for a in ("Q1", "nu", "theta_ratio")}
    assert np.isclose(by_axis["Q1"][0], 0.1)  # sqrt(0.01 * 1)
    assert by_axis["nu"] == [0.25]  # a linear axis: the arithmetic mean
    assert np.isclose(by_axis["theta_ratio"][0], 0.2)  # sqrt(0.1 * 0.4)
