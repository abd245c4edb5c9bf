"""Full-size run of the ``lookup`` benchmark: writes ``benchmarks/results/lookup.json``
and ``lookup.png`` (``python -m benchmarks.lookup [--quick] [--out DIR]``).

The code is :mod:`vimpact.bench.lookup` (also ``vimpact bench lookup``); its names are
re-exported here.
"""

from vimpact.bench.lookup import *  # noqa: F401,F403

from .machine import repository_main


def main(argv: list[str] | None = None) -> dict:
    return repository_main("lookup", argv)


if __name__ == "__main__":
    main()
