"""Full-size run of the ``specialization`` benchmark: writes ``benchmarks/results/specialization.json``
and ``specialization.png`` (``python -m benchmarks.specialization [--quick] [--out DIR]``).

The code is :mod:`vimpact.bench.specialization` (also ``vimpact bench specialization``); its names are
re-exported here.
"""

from vimpact.bench.specialization import *  # noqa: F401,F403

from .machine import repository_main


def main(argv: list[str] | None = None) -> dict:
    return repository_main("specialization", argv)


if __name__ == "__main__":
    main()
