"""Compare two results of one benchmark figure by figure (``vimpact bench compare``).

For every figure in both files: the ratio new / old and the noise of the
comparison, ``sqrt(spread_old^2 + spread_new^2)`` (relative spreads over the
repeats, stored with each figure). A change counts only beyond the
threshold ``max(2 * noise, floor)``, where the floor is
:data:`NOISE_FLOOR` of the figure's kind: timings on a shared machine move
by some percent even when their repeats agree, and errors are reproducible
only up to rounding. Beyond it, a change in the bad direction is flagged
``slower`` (kind ``time``) or ``less accurate`` (kind ``accuracy``); one in
the good direction ``faster`` or ``more accurate``; otherwise ``same``.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

from vimpact.model.validation import InputError

#: smallest relative change that counts, per kind of figure
NOISE_FLOOR = {"time": 0.05, "accuracy": 0.02}
#: noise (relative) assumed for a figure measured once (no spread stored)
UNKNOWN_SPREAD = {"time": 0.10, "accuracy": 0.0}

WORSE = {"time": "slower", "accuracy": "less accurate"}
BETTER = {"time": "faster", "accuracy": "more accurate"}


def load_result(path: str | Path) -> dict:
    """Return a benchmark result file (JSON written by ``vimpact bench``).

    Raises
    ------
    ValueError
        naming the file if it is missing, unreadable or not UTF-8 text.
    vimpact.InputError
        if it is not JSON or not a vimpact benchmark result (no ``benchmark``
        name or no ``figures``).
    """
    from vimpact.model.toml_input import read_text  # the one reading rule for input files

    path = Path(path)
    text = read_text(path, "benchmark result")
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise InputError(f"{path} is not JSON ({exc.msg} at line {exc.lineno}): must be a "
                         "result file written by vimpact bench") from None
    if (not isinstance(data, dict) or not isinstance(data.get("benchmark"), str)
            or not isinstance(data.get("figures"), dict)):
        raise InputError(f"{path} is not a vimpact benchmark result: must be a JSON object "
                         "with 'benchmark' and 'figures' (written by vimpact bench)")
    for name, f in data["figures"].items():
        if not isinstance(f, dict) or "value" not in f or f.get("kind") not in NOISE_FLOOR \
                or f.get("better") not in ("lower", "higher"):
            raise InputError(f"{path}: figure {name!r} is malformed: must have value, "
                             "kind ('time' or 'accuracy') and better ('lower' or 'higher')")
    return data


def judge(old: dict, new: dict) -> dict:
    """One figure's comparison.

    ``ratio`` (new / old), ``noise`` (relative), ``threshold`` and the ``verdict``.
    """
    kind = new["kind"]
    spreads = [float(f["spread"]) if f.get("spread") is not None else UNKNOWN_SPREAD[kind]
               for f in (old, new)]
    noise = math.sqrt(spreads[0] ** 2 + spreads[1] ** 2)
    threshold = max(2.0 * noise, NOISE_FLOOR[kind])
    rec = {"old": old["value"], "new": new["value"], "unit": new.get("unit", ""),
           "kind": kind, "better": new["better"], "noise": noise, "threshold": threshold,
           "ratio": None}
    a, b = old["value"], new["value"]
    if a is None or b is None:  # not measured, or not finite (e.g. an error that failed)
        rec["verdict"] = ("not comparable" if a is None and b is None
                          else "new value" if a is None else WORSE[kind] + " (no value now)")
        return rec
    if a == 0.0 or b == 0.0:
        ratio = 1.0 if a == b else (math.inf if a == 0.0 else 0.0)
    else:
        ratio = b / a
    rec["ratio"] = ratio if math.isfinite(ratio) else None
    # worse: up for lower-is-better, down for higher-is-better (judged on the log scale)
    up = ratio > 1.0 + threshold
    down = ratio < 1.0 / (1.0 + threshold)
    if (up and new["better"] == "lower") or (down and new["better"] == "higher"):
        rec["verdict"] = WORSE[kind]
    elif up or down:
        rec["verdict"] = BETTER[kind]
    else:
        rec["verdict"] = "same"
    return rec


def compare(old: dict, new: dict) -> dict:
    """Compare two results (:func:`load_result`).

    Returns ``benchmark``, ``warnings`` (different benchmarks, quick vs full, machines),
    ``figures`` (name -> :func:`judge`), ``only_old``/``only_new`` and ``flagged`` (the
    figures that got worse beyond the noise).
    """
    warnings = []
    if old["benchmark"] != new["benchmark"]:
        warnings.append(f"different benchmarks: {old['benchmark']} vs {new['benchmark']}")
    if bool(old.get("quick")) != bool(new.get("quick")):
        warnings.append("one result is a --quick run, the other a full run: sizes differ")
    mo, mn = old.get("machine", {}), new.get("machine", {})
    for key in ("cpu", "cores", "numba_threads"):
        if mo.get(key) != mn.get(key):
            warnings.append(f"machines differ in {key}: {mo.get(key)} vs {mn.get(key)}")
    figs = {name: judge(old["figures"][name], f) for name, f in new["figures"].items()
            if name in old["figures"]}
    return {
        "benchmark": new["benchmark"],
        "versions": {"old": mo.get("vimpact"), "new": mn.get("vimpact")},
        "warnings": warnings,
        "figures": figs,
        "only_old": sorted(set(old["figures"]) - set(new["figures"])),
        "only_new": sorted(set(new["figures"]) - set(old["figures"])),
        "flagged": [k for k, r in figs.items() if r["verdict"].startswith(tuple(WORSE.values()))],
    }


def format_table(result: dict) -> str:
    """Return the comparison as a text table (flagged rows marked ``!!``)."""
    lines = [f"benchmark {result['benchmark']}: vimpact {result['versions']['old']} -> "
             f"{result['versions']['new']}"]
    lines += [f"warning: {w}" for w in result["warnings"]]
    figs = result["figures"]
    if figs:
        w = max(len(k) for k in figs)
        lines.append(f"   {'figure':<{w}}  {'old':>10}  {'new':>10}  {'new/old':>8}  "
                     f"{'noise':>6}  verdict")
        for name, r in figs.items():
            mark = "!!" if name in result["flagged"] else "  "
            old = "n/a" if r["old"] is None else f"{r['old']:.4g}"
            new = "n/a" if r["new"] is None else f"{r['new']:.4g}"
            ratio = "n/a" if r["ratio"] is None else f"{r['ratio']:.3f}"
            lines.append(f"{mark} {name:<{w}}  {old:>10}  {new:>10}  {ratio:>8}  "
                         f"{100 * r['noise']:>5.1f}%  {r['verdict']}")
    else:
        lines.append("no figure in common")
    if result["only_old"]:
        lines.append("only in the old result: " + ", ".join(result["only_old"]))
    if result["only_new"]:
        lines.append("only in the new result: " + ", ".join(result["only_new"]))
    n = len(result["flagged"])
    lines.append(f"{n} figure{'s' if n != 1 else ''} worse beyond the noise"
                 + (": " + ", ".join(result["flagged"]) if n else ""))
    return "\n".join(lines)
