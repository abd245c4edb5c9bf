"""pytest plugin: which test pays for which numba compile.

A fresh clone compiles every kernel the default run touches; each element-kernel
specialization (:class:`vimpact.kernels.elements.KernelSpec`) takes 20-55 s on
the CI machine, so the default run must not compile one that only one test
needs. Run on a cold cache::

    NUMBA_CACHE_DIR=$(mktemp -d) python -m pytest -q -p tests.compile_profile

Every top-level compile (a dispatcher compiling a new signature, its callees
included) is attributed to the test that triggered it; the terminal summary
lists them by time, and ``COMPILE_PROFILE_OUT`` (default
``.pytest_cache/numba_compiles.json``) gets the rows. Element kernels are
named after their compiled effects (``..._integrator2_tangential1_memory0_arms0_
dashpot1_frictionR``, ``R``: friction read from the row). Compiles in
subprocesses (command-line tests) are not seen.

Package functions compiled for more than one signature are listed too: a
callee that receives a bare literal (``f(x, 0)``, or a counter that starts at
``0``) is compiled once for ``Literal[int](0)`` and again for ``int64``, each
time with everything it calls (the continuum kernel compiled its right-hand
side eight times that way).
"""

from __future__ import annotations

import json
import os
import time
from pathlib import Path

import pytest
from numba.core import event

_state = {"test": "<collection>", "depth": 0, "start": 0.0, "func": "", "rows": []}
_signatures: dict[tuple[str, int], set] = {}  # (function, dispatcher id) -> signatures


def _label(dispatcher) -> str:
    f = dispatcher.py_func
    name = f"{f.__module__}.{f.__qualname__}"
    consts = []
    for cell in f.__closure__ or ():
        try:
            value = cell.cell_contents
        except ValueError:  # an empty cell
            continue
        if isinstance(value, (bool, int, float, str)):
            consts.append(repr(value))
    return name + (f"[{','.join(consts)}]" if consts else "")


class _Listener(event.Listener):
    def on_start(self, ev):
        f = ev.data["dispatcher"].py_func
        if f.__module__.startswith("vimpact."):
            key = (f"{f.__module__}.{f.__qualname__}", id(ev.data["dispatcher"]))
            _signatures.setdefault(key, set()).add(str(ev.data["args"]))
        if _state["depth"] == 0:
            _state["start"] = time.perf_counter()
            _state["func"] = _label(ev.data["dispatcher"])
        _state["depth"] += 1

    def on_end(self, ev):
        _state["depth"] -= 1
        if _state["depth"] == 0:
            _state["rows"].append({"test": _state["test"], "func": _state["func"],
                                   "seconds": time.perf_counter() - _state["start"]})


event.register("numba:compile", _Listener())


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item, nextitem):
    _state["test"] = item.nodeid
    yield


def pytest_terminal_summary(terminalreporter):
    rows = sorted(_state["rows"], key=lambda r: -r["seconds"])
    total = sum(r["seconds"] for r in rows)
    tr = terminalreporter
    tr.section(f"numba compiles: {len(rows)} top-level, {total:.0f} s")
    for r in rows:
        if r["seconds"] >= 1.0:
            tr.write_line(f"{r['seconds']:7.1f} s  {r['func']}\n           {r['test']}")
    for (name, _), sigs in sorted(_signatures.items()):
        if len(sigs) > 1:
            tr.write_line(f"compiled for {len(sigs)} signatures: {name}")
    out = Path(os.environ.get("COMPILE_PROFILE_OUT", ".pytest_cache/numba_compiles.json"))
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(rows, indent=1))
    tr.write_line(f"rows written to {out}")
