"""``python -m vimpact``: the same as the ``vimpact`` command (and ``python -m vimpact.cli``)."""

import sys

from vimpact.cli.main import run

sys.exit(run())
