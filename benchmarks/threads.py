"""Full-size run of the ``threads`` benchmark: writes ``benchmarks/results/threads.json``
and ``threads.png`` (``python -m benchmarks.threads [--quick] [--out DIR]``).

The code is :mod:`vimpact.bench.threads` (also ``vimpact bench threads``); its names are
re-exported here.
"""

from vimpact.bench.threads import *  # noqa: F401,F403

from .machine import repository_main


def main(argv: list[str] | None = None) -> dict:
    return repository_main("threads", argv)


if __name__ == "__main__":
    main()
