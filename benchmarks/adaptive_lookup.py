"""Full-size run of the ``adaptive_lookup`` benchmark: writes
``benchmarks/results/adaptive_lookup.json`` and ``adaptive_lookup.png``
(``python -m benchmarks.adaptive_lookup [--quick] [--out DIR]``).

The code is :mod:`vimpact.bench.adaptive_lookup` (also ``vimpact bench adaptive_lookup``).
"""

from vimpact.bench.adaptive_lookup import *  # noqa: F401,F403

from .machine import repository_main


def main(argv: list[str] | None = None) -> dict:
    return repository_main("adaptive_lookup", argv)


if __name__ == "__main__":
    main()
