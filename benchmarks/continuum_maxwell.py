"""Full-size run of the ``continuum_maxwell`` benchmark: writes
``benchmarks/results/continuum_maxwell.json`` and ``continuum_maxwell.png``
(``python -m benchmarks.continuum_maxwell [--quick] [--out DIR]``).

The code is :mod:`vimpact.bench.continuum_maxwell` (also ``vimpact bench continuum_maxwell``);
its names are re-exported here.
"""

from vimpact.bench.continuum_maxwell import *  # noqa: F401,F403

from .machine import repository_main


def main(argv: list[str] | None = None) -> dict:
    return repository_main("continuum_maxwell", argv)


if __name__ == "__main__":
    main()
