"""One same-node rule: the interpolation kernel's numbers are the lookup's."""

import numpy as np

from vimpact.kernels import hermite
from vimpact.lookup import interpolate


def test_kernel_node_tolerance_is_the_lookup_one():
    assert (hermite.NODE_RTOL, hermite.NODE_ATOL) == (interpolate.NODE_RTOL,
                                                      interpolate.NODE_ATOL)


def test_same_node_and_clusters():
    # closer than 1e-9 relative: one node; 1e-6 apart: two (values chosen by hand)
    assert interpolate.same_node(1.0, 1.0 + 1e-10) and not interpolate.same_node(1.0, 1.0 + 1e-6)
    nodes, index = interpolate.cluster_nodes(np.array([0.3, 0.1, 0.1 * (1 + 1e-11), 0.3]))
    assert len(nodes) == 2 and list(index) == [1, 0, 0, 1]


def _clusters_one_by_one(values):
    """The clustering rule written out: each sorted value joins the cluster whose first
    member it is the same node as, else begins a new one; the node is the median member."""
    order = np.argsort(values, kind="stable")
    s = values[order]
    starts = [0]
    for i in range(1, len(s)):
        if not interpolate.same_node(s[starts[-1]], s[i]):
            starts.append(i)
    bounds = starts + [len(s)]
    nodes = np.array([s[(bounds[k] + bounds[k + 1] - 1) // 2] for k in range(len(starts))])
    labels = np.repeat(np.arange(len(starts)), np.diff(bounds))
    index = np.empty(len(values), dtype=np.int64)
    index[order] = labels
    return nodes, index


def test_clusters_follow_the_rule_one_value_at_a_time():
    """The vectorized clustering gives what comparing value by value gives, on values
    with exact repeats, near-repeats around the tolerance (chains longer than it) and
    mixed signs."""
    rng = np.random.default_rng(1)
    for trial in range(300):
        n = int(rng.integers(1, 60))
        base = (rng.choice([0.0, 1e-12, 0.1, 0.3, 1.0, 2.0, -1.0, -0.5], n) if trial % 3
                else rng.uniform(-1.0, 1.0, n))
        if trial % 2:
            base = np.abs(base)
        v = (base * (1 + rng.choice([0.0, 1e-11, 4e-10, 8e-10, 1.2e-9, 1e-6], n))
             + rng.choice([0.0, 5e-13, 2e-12], n))
        got, want = interpolate.cluster_nodes(v), _clusters_one_by_one(v)
        np.testing.assert_array_equal(got[0], want[0])
        np.testing.assert_array_equal(got[1], want[1])
