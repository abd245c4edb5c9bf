"""What machine a benchmark ran on: printed and stored with every result."""

from __future__ import annotations

import os
import platform

import numba
import numpy as np

import vimpact


def machine_info() -> dict:
    cpu = platform.processor() or ""
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return {
        "cpu": cpu,
        "cores": os.cpu_count(),
        "numba_threads": numba.config.NUMBA_NUM_THREADS,
        "python": platform.python_version(),
        "numpy": np.__version__,
        "numba": numba.__version__,
        "vimpact": vimpact.__version__,
        "platform": platform.platform(),
    }
