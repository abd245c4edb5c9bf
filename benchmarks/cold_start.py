"""Full-size run of the ``cold_start`` benchmark: writes ``benchmarks/results/cold_start.json``
and ``cold_start.png`` (``python -m benchmarks.cold_start [--quick] [--out DIR]``).

The code is :mod:`vimpact.bench.cold_start` (also ``vimpact bench cold_start``); its names are
re-exported here.
"""

from vimpact.bench.cold_start import *  # noqa: F401,F403

from .machine import repository_main


def main(argv: list[str] | None = None) -> dict:
    return repository_main("cold_start", argv)


if __name__ == "__main__":
    main()
