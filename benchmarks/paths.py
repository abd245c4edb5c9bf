"""Full-size run of the ``paths`` benchmark: writes ``benchmarks/results/paths.json``
and ``paths.png`` (``python -m benchmarks.paths [--quick] [--out DIR]``).

The code is :mod:`vimpact.bench.paths` (also ``vimpact bench paths``); its names are
re-exported here.
"""

from vimpact.bench.paths import *  # noqa: F401,F403

from .machine import repository_main


def main(argv: list[str] | None = None) -> dict:
    return repository_main("paths", argv)


if __name__ == "__main__":
    main()
