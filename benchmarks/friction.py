"""Full-size run of the ``friction`` benchmark: writes ``benchmarks/results/friction.json``
and ``friction.png`` (``python -m benchmarks.friction [--quick] [--out DIR]``).

The code is :mod:`vimpact.bench.friction` (also ``vimpact bench friction``); its names are
re-exported here.
"""

from vimpact.bench.friction import *  # noqa: F401,F403

from .machine import repository_main


def main(argv: list[str] | None = None) -> dict:
    return repository_main("friction", argv)


if __name__ == "__main__":
    main()
