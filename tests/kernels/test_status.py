"""One status table: every list of statuses is derived from it, one text per status."""

import vimpact as v
from vimpact.engine.result import FINISHED
from vimpact.engine.unpack import KERNEL_STATUSES
from vimpact.kernels import layout, status
from vimpact.lookup.table import DATA_STATUSES
from vimpact.tableformat.schema import SWEEP_STATUSES


def test_names_and_codes_are_unique():
    names = [s.name for s in status.TABLE]
    codes = [s.code for s in status.TABLE if s.code is not None]
    assert len(set(names)) == len(names) and len(set(codes)) == len(codes)
    # the hand-over signal of the continuum kernels is no status of a result
    assert layout.STATUS_ASSUMPTION not in codes
    assert KERNEL_STATUSES[layout.STATUS_ASSUMPTION] == "non_finite"


def test_every_list_is_the_table():
    assert set(v.STATUSES) | {"failed"} == set(SWEEP_STATUSES) == set(status.BY_NAME)
    for name, message in SWEEP_STATUSES.items():  # one text per status, e.g. "invalid"
        assert message == status.BY_NAME[name].message
        assert v.STATUSES.get(name, message) == message
    assert set(FINISHED) == {s.name for s in status.TABLE if s.finished}
    assert set(DATA_STATUSES) <= set(FINISHED) and DATA_STATUSES == ("ok",)
    assert {layout.STATUS_OK, layout.STATUS_TIME_LIMIT, layout.STATUS_ROW_EXCEEDED,
            layout.STATUS_NON_FINITE} == set(status.BY_CODE)
