"""Full-size run of the ``accuracy`` benchmark: writes ``benchmarks/results/accuracy.json``
and ``accuracy_pareto.png`` (``python -m benchmarks.accuracy [--quick] [--out DIR]``).

The code is :mod:`vimpact.bench.accuracy` (also ``vimpact bench accuracy``); its names are
re-exported here.
"""

from vimpact.bench.accuracy import *  # noqa: F401,F403

from .machine import repository_main


def main(argv: list[str] | None = None) -> dict:
    return repository_main("accuracy", argv, png_stem="accuracy_pareto")


if __name__ == "__main__":
    main()
