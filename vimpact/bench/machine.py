"""What every benchmark shares.

The machine it ran on, the median timer, the figures ``vimpact bench compare`` reads, JSON
+ figure output and progress.

Every result file is a JSON object with

- ``benchmark`` (its registry name), ``schema`` (:data:`SCHEMA`), ``quick``;
- ``machine`` (:func:`machine_info`) and ``load_average`` where measured;
- the benchmark's own data;
- ``figures``: the headline numbers, name -> :func:`figure` record (value,
  unit, which direction is better, ``time`` or ``accuracy``, the relative
  spread over the repeats and their number). ``vimpact bench compare``
  judges a change against that spread.
"""

from __future__ import annotations

import importlib.util
import json
import math
import os
import platform
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from types import ModuleType

import numpy as np

#: version of the result-file layout (``benchmark``, ``figures``, ...)
SCHEMA = 1


# ------------------------------------------------------------------ machine
def machine_info() -> dict:
    """Return the machine a result was measured on.

    CPU model, cores, numba threads and the versions of Python, NumPy, numba
    and vimpact (and the platform string).
    """
    import numba

    import vimpact

    cpu = platform.processor() or ""
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return {
        "cpu": cpu,
        "cores": os.cpu_count(),
        "numba_threads": max_threads(),
        "python": platform.python_version(),
        "numpy": np.__version__,
        "numba": numba.__version__,
        "vimpact": vimpact.__version__,
        "platform": platform.platform(),
    }


def machine_line(info: dict) -> str:
    """One line naming the machine of a result (:func:`machine_info`)."""
    return (f"machine: {info.get('cpu') or 'unknown CPU'}, {info.get('cores')} cores, "
            f"{info.get('numba_threads')} numba threads; python {info.get('python')}, "
            f"numpy {info.get('numpy')}, numba {info.get('numba')}, "
            f"vimpact {info.get('vimpact')}")


def max_threads() -> int:
    """Return the most threads numba may use.

    Threads numba may use at most (``NUMBA_NUM_THREADS``, read from the
    environment when numba is imported; :func:`numba.set_num_threads` takes up to it).
    """
    import numba

    return int(vars(numba.config)["NUMBA_NUM_THREADS"])  # set at run time: no stub has it


def element_spec(scene, numerics):
    """Return the element kernel that runs ``scene`` with ``numerics``.

    The element kernel (:class:`vimpact.kernels.elements.KernelSpec`) that runs
    ``scene`` with ``numerics``; ``ValueError`` if a continuum kernel runs it (a
    benchmark of the element kernels passes ``Numerics(continuum=False)``).
    """
    from vimpact.engine.routing import choose_path

    path = choose_path(scene, numerics)
    if path.spec is None:
        raise ValueError(f"numerics = {numerics!r} is not allowed here: the scene runs on "
                         f"{path.name}, must be an element kernel (continuum=False)")
    return path.spec


def load_average() -> list[float]:
    """1, 5 and 15 minute load averages (runnable processes).

    Stored with the times, since the machine may be shared.
    """
    try:
        return [round(x, 2) for x in os.getloadavg()]
    except (AttributeError, OSError):  # not on every platform
        return []


# ------------------------------------------------------------------ timing
def time_samples(fn: Callable[[], object], repeats: int) -> list[float]:
    """Wall times of ``repeats`` calls of ``fn()``, s."""
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return times


def median_time(fn: Callable[[], object], repeats: int) -> float:
    """Median wall time of ``fn()`` over ``repeats`` calls, s."""
    return float(np.median(time_samples(fn, repeats)))


def spread(samples: Sequence[float]) -> float | None:
    """Relative spread of repeated measurements.

    Half their range over their median (``None`` for fewer than two samples or a zero
    median).
    """
    x = np.asarray([s for s in samples if s is not None], dtype=float)
    x = x[np.isfinite(x)]
    if len(x) < 2:
        return None
    med = float(np.median(x))
    if med == 0.0:
        return None
    return float((x.max() - x.min()) / 2.0 / abs(med))


def figure(value, unit: str, better: str = "lower", kind: str = "time",
           samples: Sequence[float] | None = None, rel_spread: float | None = None,
           note: str | None = None) -> dict:
    """Return a headline number of a benchmark, as ``vimpact bench compare`` reads it.

    Parameters
    ----------
    value : the median over the repeats (``None`` if not measured)
    unit : its unit, e.g. ``"s"``, ``"us/row"``, ``"1/s"``, ``"-"``
    better : ``"lower"`` or ``"higher"``
    kind : ``"time"`` (speed: noisy, judged against the spread) or
        ``"accuracy"`` (an error: deterministic up to rounding)
    samples : the repeats the value is the median of (their spread is stored)
    rel_spread : the relative spread, if known otherwise (overrides ``samples``)
    """
    if better not in ("lower", "higher") or kind not in ("time", "accuracy"):
        raise ValueError(f"figure: better={better!r}, kind={kind!r} not allowed")
    v = None if value is None else float(value)
    if v is not None and not math.isfinite(v):
        v = None
    s = rel_spread if rel_spread is not None else (spread(samples) if samples else None)
    rec = {"value": v, "unit": unit, "better": better, "kind": kind,
           "spread": s, "repeats": len(samples) if samples else None}
    if note:
        rec["note"] = note
    return rec


def ratio_spread(*spreads: float | None) -> float | None:
    """Relative spread of a product or ratio of measured numbers (in quadrature)."""
    known = [s for s in spreads if s is not None]
    return math.sqrt(sum(s * s for s in known)) if known else None


# ------------------------------------------------------------------ output
def progress(msg: str, start: float | None = None) -> None:
    """Print a progress line on stderr.

    A progress line on stderr (silenced by ``VIMPACT_BENCH_QUIET``), with
    the seconds since ``start`` (a ``time.perf_counter()`` value) if given.
    """
    if os.environ.get("VIMPACT_BENCH_QUIET") is not None:
        return
    if start is not None:
        msg = f"[{time.perf_counter() - start:6.1f} s] {msg}"
    print(msg, file=sys.stderr, flush=True)


def save_figure(fig, path) -> None:
    """Write ``fig`` to ``path`` (120 dpi) and close it.

    The layout is computed at the dpi the file is written at: matplotlib caches a parsed
    ``$...$`` text (a log axis's tick labels are such texts) per dpi, so a layout at the
    figure's own dpi (100) would parse every one of them a second time for the file.
    """
    import matplotlib.pyplot as plt

    fig.set_dpi(120)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def use_agg() -> None:
    """Draw without a display (call before importing ``matplotlib.pyplot``)."""
    import matplotlib

    matplotlib.use("Agg")


def _json_safe(x):
    """``x`` with non-finite floats as ``None`` (strict JSON) and NumPy scalars as Python ones."""
    if isinstance(x, dict):
        return {str(k): _json_safe(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_json_safe(v) for v in x]
    if isinstance(x, np.ndarray):
        return _json_safe(x.tolist())
    if isinstance(x, (np.floating, float)):
        x = float(x)
        return x if math.isfinite(x) else None
    if isinstance(x, np.integer):
        return int(x)
    if isinstance(x, np.bool_):
        return bool(x)
    return x


def annotate(name: str, module, data: dict, quick: bool) -> dict:
    """Return a result with its benchmark, schema, quick flag and figures.

    ``data`` with ``benchmark``, ``schema``, ``quick`` and ``figures`` (from
    ``module.figures(data)``, or the ``figures`` the data carry for a module
    without that function) added, strict-JSON safe.
    """
    figs = module.figures(data) if hasattr(module, "figures") else data.get("figures", {})
    head = {"benchmark": name, "schema": SCHEMA, "quick": bool(quick)}
    body = {k: x for k, x in data.items() if k not in ("benchmark", "schema", "quick", "figures")}
    return _json_safe({**head, **body, "figures": figs})


def figures_table(figs: dict) -> str:
    """Return the figures of a result as a short text table."""
    if not figs:
        return "(no figures)"
    w = max(len(k) for k in figs)
    lines = [f"{'figure':<{w}}  {'value':>11}  {'unit':<8} {'spread':>7}  better"]
    for k, f in figs.items():
        val = "n/a" if f["value"] is None else f"{f['value']:.4g}"
        sp = "" if f.get("spread") is None else f"{100 * f['spread']:.1f}%"
        lines.append(f"{k:<{w}}  {val:>11}  {f['unit']:<8} {sp:>7}  {f['better']}")
    return "\n".join(lines)


def run_and_write(name: str, module, quick: bool, out: Path, json_name: str | None = None,
                  png_name: str | None = None, details: bool = False) -> tuple[dict, Path, Path]:
    """Run a benchmark and write its JSON and chart.

    Run benchmark ``module`` (``run(quick)``, ``plot(data, path)``,
    ``figures(data)``), write ``out/json_name`` and ``out/png_name`` (default
    ``NAME.json`` and ``NAME.png``), print the machine line and the figures
    table (and ``module.report(data)`` with ``details``); returns the data and
    both paths.
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    progress(f"{name}: {'quick' if quick else 'full'} run", start)
    data = annotate(name, module, module.run(quick), quick)
    json_path = out / (json_name or f"{name}.json")
    png_path = out / (png_name or f"{name}.png")
    json_path.write_text(json.dumps(data, indent=1, allow_nan=False))
    module.plot(data, png_path)
    print(machine_line(data.get("machine", {})))
    if details and hasattr(module, "report"):
        print(module.report(data))
    print(figures_table(data["figures"]))
    print(f"wrote {json_path} and {png_path} ({time.perf_counter() - start:.0f} s)")
    return data, json_path, png_path


def module_at_commit(commit: str, path: str) -> ModuleType | None:
    """Return a module of the repository as of ``commit``.

    The repository's module ``path`` (e.g. ``vimpact/kernels/elements.py``) as of
    ``commit``, for a benchmark that times a kernel before and after a change; ``None``
    without git or outside a source checkout (an installed package). The source is
    written under the temporary folder with a stable name, so that numba's cache
    beside it survives the run.
    """
    checkout = Path(__file__).resolve().parents[2]
    if not (checkout / "pyproject.toml").exists():  # installed: no repository at hand
        return None
    try:
        src = subprocess.run(["git", "show", f"{commit}:{path}"], cwd=checkout,
                             capture_output=True, text=True, check=True).stdout
    except (OSError, subprocess.CalledProcessError):
        return None
    folder = Path(tempfile.gettempdir()) / "vimpact_bench_before"
    folder.mkdir(exist_ok=True)
    name = f"{Path(path).stem}_{commit[:10]}"
    file = folder / f"{name}.py"
    if not file.exists() or file.read_text() != src:
        file.write_text(src)
    spec = importlib.util.spec_from_file_location(name, file)
    if spec is None or spec.loader is None:
        return None
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # numba's cache finds the module again by name
    lent = _lend_moved_names()
    try:
        spec.loader.exec_module(module)
    finally:
        for home, attr in lent:
            delattr(home, attr)
    return module


def package_at_commit(commit: str, package: str) -> ModuleType | None:
    """Return a package of the repository as of ``commit``.

    The repository's package ``package`` (e.g. ``vimpact.engine``) as of ``commit``,
    imported under its own name beside the current one, for a benchmark that times
    Python code before and after a change in one run.

    Its modules import each other from the old copy and everything else (kernels,
    model) from the current package, so the compiled kernels are shared. ``None``
    without git, outside a source checkout, or if the old code does not import any
    more (a name it needs has moved).

    Parameters
    ----------
    commit : str
        A commit of the repository (``git show`` names it).
    package : str
        Dotted name of a folder of the repository, e.g. ``"vimpact.engine"``.

    Returns
    -------
    types.ModuleType or None
        The old package (its modules are imported as its attributes' modules).
    """
    checkout = Path(__file__).resolve().parents[2]
    folder = package.replace(".", "/")
    if not (checkout / "pyproject.toml").exists():
        return None
    try:
        names = subprocess.run(["git", "ls-tree", "--name-only", f"{commit}:{folder}"],
                               cwd=checkout, capture_output=True, text=True,
                               check=True).stdout.split()
        sources = {name: subprocess.run(["git", "show", f"{commit}:{folder}/{name}"],
                                        cwd=checkout, capture_output=True, text=True,
                                        check=True).stdout
                   for name in names if name.endswith(".py")}
    except (OSError, subprocess.CalledProcessError):
        return None
    alias = f"{package.replace('.', '_')}_{commit[:10]}"
    root = Path(tempfile.gettempdir()) / "vimpact_bench_before"
    target = root / alias
    target.mkdir(parents=True, exist_ok=True)
    for name, src in sources.items():
        src = src.replace(f"{package}.", f"{alias}.").replace(f"from {package} import",
                                                               f"from {alias} import")
        file = target / name
        if not file.exists() or file.read_text() != src:
            file.write_text(src)
    if str(root) not in sys.path:
        sys.path.append(str(root))
    try:
        module = importlib.import_module(alias)
        for name in sources:
            if name != "__init__.py":
                importlib.import_module(f"{alias}.{name[:-3]}")
    except (ImportError, AttributeError):
        return None
    return module


#: Names an earlier commit's kernel imports from a module they have since left:
#: ``{old module: {name: module that defines it now}}``.
MOVED_NAMES = {"vimpact.kernels.layout": {"_record": "vimpact.kernels.record"}}


def _lend_moved_names() -> list[tuple[ModuleType, str]]:
    """Lend moved names back to their old modules.

    Put each moved name back on its old module while an old kernel is imported
    (the modules themselves keep no alias); return what was lent.
    """
    lent = []
    for old, names in MOVED_NAMES.items():
        home = importlib.import_module(old)
        for attr, new in names.items():
            if not hasattr(home, attr):
                setattr(home, attr, getattr(importlib.import_module(new), attr))
                lent.append((home, attr))
    return lent
