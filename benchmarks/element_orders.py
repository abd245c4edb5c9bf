"""Full-size run of the ``element_orders`` benchmark: writes ``benchmarks/results/element_orders.json``
and ``element_orders.png`` (``python -m benchmarks.element_orders [--quick] [--out DIR]``).

The code is :mod:`vimpact.bench.element_orders` (also ``vimpact bench element_orders``); its names are
re-exported here.
"""

from vimpact.bench.element_orders import *  # noqa: F401,F403

from .machine import repository_main


def main(argv: list[str] | None = None) -> dict:
    return repository_main("element_orders", argv)


if __name__ == "__main__":
    main()
