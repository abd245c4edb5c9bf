"""Benchmarks of vimpact, runnable on the user's machine (``vimpact bench``).

Each benchmark is a module with

- ``TITLE``: one line, shown by ``vimpact bench list``;
- ``run(quick: bool) -> dict``: measures; ``quick`` finishes in under a
  minute on 2 cores (kernels already compiled);
- ``plot(data, path)``: writes the chart;
- ``figures(data) -> dict``: the headline numbers
  (:func:`vimpact.bench.machine.figure` records) that ``vimpact bench
  compare`` judges;
- optionally ``report(data) -> str``: a longer text summary.

:data:`BENCHMARKS` maps the name to the module; a new benchmark is one line
there, e.g. ``"friction": "benchmarks.friction",`` for a module that lives in
the repository's ``benchmarks/`` folder (available from a source checkout) or
``"friction": "vimpact.bench.friction",`` once it ships with the package.
The repository's ``benchmarks/<name>.py`` scripts run the same code at full
size and write ``benchmarks/results/``.
"""

from __future__ import annotations

import importlib
import importlib.util
from types import ModuleType

#: benchmark name -> module (in the order ``vimpact bench list`` shows them)
BENCHMARKS: dict[str, str] = {
    "accuracy": "vimpact.bench.accuracy",
    "throughput": "vimpact.bench.throughput",
    "scaling": "vimpact.bench.scaling",
    "paths": "vimpact.bench.paths",
    "overhead": "vimpact.bench.overhead",
    "imports": "vimpact.bench.imports",
    "threads": "vimpact.bench.threads",
    "cold_start": "vimpact.bench.cold_start",
    "specialization": "vimpact.bench.specialization",
    "friction": "vimpact.bench.friction",
    "sweep_backends": "vimpact.bench.sweep_backends",
    "lookup": "vimpact.bench.lookup",
    "adaptive_lookup": "vimpact.bench.adaptive_lookup",
    "continuum_maxwell": "vimpact.bench.continuum_maxwell",
    "element_orders": "vimpact.bench.element_orders",
}


def available(name: str) -> bool:
    """Return whether the module of benchmark ``name`` can be imported here.

    Whether the module of benchmark ``name`` can be imported here (a
    benchmark in the repository's ``benchmarks/`` needs a source checkout).
    """
    try:
        return importlib.util.find_spec(BENCHMARKS[name]) is not None
    except (ImportError, ValueError):
        return False


def title(name: str) -> str:
    """Return the ``TITLE`` of benchmark ``name``, read from its source.

    ``TITLE`` of benchmark ``name``, read from its source without importing
    it (``vimpact bench list`` stays fast): the first top-level statement that
    assigns a string constant to ``TITLE`` (only that statement is parsed, not
    the module); empty if it has none.
    """
    import ast

    spec = importlib.util.find_spec(BENCHMARKS[name])
    if spec is None or not spec.origin or not spec.origin.endswith(".py"):
        return ""
    with open(spec.origin, encoding="utf-8") as f:
        lines = f.read().splitlines()
    for k, line in enumerate(lines):
        if not line.startswith("TITLE"):
            continue
        for end in range(k + 1, len(lines) + 1):  # the statement may span lines
            try:
                tree = ast.parse("\n".join(lines[k:end]))
            except SyntaxError:
                continue
            node = tree.body[0] if tree.body else None
            if (isinstance(node, ast.Assign) and any(isinstance(t, ast.Name) and t.id == "TITLE"
                                                     for t in node.targets)
                    and isinstance(node.value, ast.Constant)):
                return str(node.value.value)
            break
    return ""


def load(name: str) -> ModuleType:
    """Return the module of benchmark ``name``.

    Raises
    ------
    vimpact.InputError
        if ``name`` is not a registered benchmark (the message names the
        choices) or its module cannot be imported here.
    """
    from vimpact.model.validation import InputError, message

    if name not in BENCHMARKS:
        raise InputError(message("benchmark", name, "one of " + ", ".join(BENCHMARKS)
                                 + " (or list, compare)"))
    if not available(name):
        raise InputError(f"benchmark {name!r} needs module {BENCHMARKS[name]}, which is not "
                         "importable here (run it from a source checkout)")
    return importlib.import_module(BENCHMARKS[name])
