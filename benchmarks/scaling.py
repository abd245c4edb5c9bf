"""Full-size run of the ``scaling`` benchmark: writes ``benchmarks/results/scaling.json``
and ``scaling.png`` (``python -m benchmarks.scaling [--quick] [--out DIR]``).

The code is :mod:`vimpact.bench.scaling` (also ``vimpact bench scaling``); its names are
re-exported here.
"""

from vimpact.bench.scaling import *  # noqa: F401,F403

from .machine import repository_main


def main(argv: list[str] | None = None) -> dict:
    return repository_main("scaling", argv)


if __name__ == "__main__":
    main()
