"""unpack.member takes two routes (a Python pass on short arrays, np.isin on long
ones); both must give NumPy's answer."""

import numpy as np
import pytest

from vimpact.engine.result import FINISHED, STATUSES
from vimpact.engine.unpack import _SHORT, member


@pytest.mark.parametrize("n", [0, 1, _SHORT, _SHORT + 1, 5000])
def test_member_is_numpy_isin(n):
    rng = np.random.default_rng(n)
    names = np.array(list(STATUSES) + ["not a status"], dtype=object)
    values = names[rng.integers(0, len(names), n)]
    got = member(values, FINISHED)
    assert got.dtype == bool and got.shape == (n,)
    assert np.array_equal(got, np.isin(values, list(FINISHED)))
