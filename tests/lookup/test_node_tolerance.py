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
