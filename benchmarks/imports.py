"""Full-size run of the ``imports`` benchmark: writes ``benchmarks/results/imports.json``
and ``imports.png`` (``python -m benchmarks.imports [--quick] [--out DIR]``).

The code is :mod:`vimpact.bench.imports` (also ``vimpact bench imports``); its names are
re-exported here.
"""

from vimpact.bench.imports import *  # noqa: F401,F403

from .machine import repository_main


def main(argv: list[str] | None = None) -> dict:
    return repository_main("imports", argv)


if __name__ == "__main__":
    main()
