"""Full-size run of the ``throughput`` benchmark: writes ``benchmarks/results/throughput.json``
and ``throughput.png`` (``python -m benchmarks.throughput [--quick] [--out DIR]``).

The code is :mod:`vimpact.bench.throughput` (also ``vimpact bench throughput``); its names are
re-exported here.
"""

from vimpact.bench.throughput import *  # noqa: F401,F403

from .machine import repository_main


def main(argv: list[str] | None = None) -> dict:
    return repository_main("throughput", argv)


if __name__ == "__main__":
    main()
