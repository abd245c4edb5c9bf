"""Import time: ``import vimpact`` and the kernel modules, each in a fresh interpreter.

Run: ``vimpact bench imports [--quick] [--out DIR]``; the full-size run of
the repository is ``python -m benchmarks.imports`` (``benchmarks/results/``).

For each target a fresh ``python -c`` subprocess (the same interpreter as
this one) imports it; measured are the wall time of the whole process (as a
user sees ``python -c "import vimpact"``), the time of the import statement
alone inside it, and which heavy modules (``pandas``, ``pyarrow``, ``numba``,
``scipy``, ``matplotlib``; ``numpy`` for reference) the import pulled in.
An empty ``python -c pass`` gives the interpreter's own start-up. The
targets are run in turn, repeat by repeat (the machine is shared); the
median is reported. Nothing here asserts a time.
"""

from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from .machine import figure, load_average, machine_info, progress, save_figure, use_agg

TITLE = "import time of vimpact and of its kernel modules (fresh interpreter) and what they pull in"

#: modules whose import is heavy (seconds or tens of MB)
HEAVY = ("pandas", "pyarrow", "numba", "scipy", "matplotlib", "numpy")

#: label -> statement run in the fresh interpreter
TARGETS = {
    "python": "pass",
    "vimpact": "import vimpact",
    "vimpact.kernels.elements": "import vimpact.kernels.elements",
    "vimpact.kernels.continuum_kv": "import vimpact.kernels.continuum_kv",
}

CONFIGS = {"full": dict(repeats=9), "quick": dict(repeats=3)}

_PROBE = """
import sys, time, json
t0 = time.perf_counter()
{statement}
t1 = time.perf_counter()
print(json.dumps({{"import_s": t1 - t0,
                   "heavy": [m for m in {heavy!r} if m in sys.modules],
                   "modules": len(sys.modules)}}))
"""


def probe(statement: str) -> dict:
    """Run ``statement`` in a fresh interpreter.

    ``wall_s`` (the process), ``import_s`` (the statement), ``heavy`` (heavy modules
    loaded) and ``modules`` (entries in ``sys.modules``).
    """
    code = _PROBE.format(statement=statement, heavy=HEAVY)
    t0 = time.perf_counter()
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          check=False)
    wall = time.perf_counter() - t0
    if done.returncode != 0:
        last = (done.stderr.strip().splitlines() or ["no output"])[-1]
        raise RuntimeError(f"python -c {statement!r} failed: {last}")
    rec = json.loads(done.stdout.strip().splitlines()[-1])
    rec["wall_s"] = wall
    return rec


def run(quick: bool = False) -> dict:
    """Time every target import.

    Time every target; returns the JSON-ready record (``targets``: per label
    the statement, the samples and medians of ``wall_s`` and ``import_s``,
    the heavy modules and the module count).
    """
    cfg = CONFIGS["quick" if quick else "full"]
    load_before = load_average()
    start = time.perf_counter()
    samples: dict[str, list[dict]] = {k: [] for k in TARGETS}
    for r in range(cfg["repeats"]):
        progress(f"imports: repeat {r + 1} of {cfg['repeats']}", start)
        for label, statement in TARGETS.items():
            samples[label].append(probe(statement))
    out = {}
    for label, recs in samples.items():
        wall = [x["wall_s"] for x in recs]
        imp = [x["import_s"] for x in recs]
        out[label] = {"statement": TARGETS[label], "wall_s": wall, "import_s": imp,
                      "median_wall_s": float(np.median(wall)),
                      "median_import_s": float(np.median(imp)),
                      "heavy": recs[-1]["heavy"], "modules": recs[-1]["modules"]}
    base = out["python"]["median_wall_s"]
    for rec in out.values():
        rec["median_wall_over_python_s"] = rec["median_wall_s"] - base
    return {"machine": machine_info(), "executable": sys.executable,
            "load_average": {"before": load_before, "after": load_average()},
            "config": {**cfg, "quick": quick}, "heavy_modules": list(HEAVY), "targets": out}


def figures(data: dict) -> dict:
    """Return the headline numbers of an imports run.

    Time of each import statement (inside the fresh interpreter) and the
    wall time of ``python -c "import vimpact"``.
    """
    out = {}
    for label, rec in data["targets"].items():
        if label == "python":
            continue
        out[f"import_{label}_s"] = figure(rec["median_import_s"], "s", samples=rec["import_s"])
    v = data["targets"]["vimpact"]
    out["python_c_import_vimpact_wall_s"] = figure(v["median_wall_s"], "s", samples=v["wall_s"])
    return out


def report(data: dict) -> str:
    """Per target: process wall time, import time and the heavy modules."""
    lines = [f"{'target':<30}{'process s':>10}{'import s':>10}  heavy modules loaded"]
    for label, rec in data["targets"].items():
        lines.append(f"{label:<30}{rec['median_wall_s']:>10.3f}{rec['median_import_s']:>10.3f}  "
                     + (", ".join(rec["heavy"]) or "-"))
    return "\n".join(lines)


def plot(data: dict, path: Path) -> None:
    """Draw the import time per target to ``path``.

    Horizontal bars: import time per target (interpreter start-up stacked
    below), labelled with the heavy modules each pulls in.
    """
    use_agg()
    import matplotlib.pyplot as plt

    targets = data["targets"]
    labels = list(targets)
    base = targets["python"]["median_wall_s"]
    imp = [targets[k]["median_import_s"] for k in labels]
    rest = [max(targets[k]["median_wall_s"] - base - targets[k]["median_import_s"], 0.0)
            for k in labels]
    y = np.arange(len(labels))[::-1]
    fig, ax = plt.subplots(figsize=(9.0, 3.6))
    ax.barh(y, [base] * len(labels), color="lightgrey", label="interpreter start-up and exit")
    ax.barh(y, imp, left=base, color="tab:blue", label="the import statement")
    ax.barh(y, rest, left=[base + i for i in imp], color="tab:cyan",
            label="rest of the process (interpreter exit, atexit)")
    for yi, k in zip(y, labels):
        heavy = [m for m in targets[k]["heavy"] if m != "numpy"]
        ax.annotate(f"{targets[k]['median_wall_s']:.2f} s; " + (", ".join(heavy) or "no heavy "
                                                                "modules"),
                    (targets[k]["median_wall_s"], yi), xytext=(4, 0), textcoords="offset points",
                    va="center", fontsize=8)
    ax.set_yticks(y, [targets[k]["statement"] for k in labels], fontsize=8)
    ax.set_xlim(0, max(t["median_wall_s"] for t in targets.values()) * 1.7)
    ax.set_xlabel(f"wall time of a fresh `python -c ...`, s (median of "
                  f"{data['config']['repeats']})")
    ax.set_title(f"Import time; {data['machine']['cpu']}", fontsize=9)
    ax.legend(fontsize=7, loc="upper right")
    save_figure(fig, path)
