"""Full-size run of the ``overhead`` benchmark: writes ``benchmarks/results/overhead.json``
and ``overhead.png`` (``python -m benchmarks.overhead [--quick] [--out DIR]``).

The code is :mod:`vimpact.bench.overhead` (also ``vimpact bench overhead``); its names are
re-exported here.
"""

from vimpact.bench.overhead import *  # noqa: F401,F403

from .machine import repository_main


def main(argv: list[str] | None = None) -> dict:
    return repository_main("overhead", argv)


if __name__ == "__main__":
    main()
