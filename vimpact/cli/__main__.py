"""``python -m vimpact.cli``: the same as the ``vimpact`` command."""

import sys

from vimpact.cli.main import run

sys.exit(run())
