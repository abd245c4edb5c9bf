"""Pure-Python baseline of the MDR impact: moved to :mod:`vimpact.bench.pure_python`."""

from vimpact.bench.pure_python import *  # noqa: F401,F403
