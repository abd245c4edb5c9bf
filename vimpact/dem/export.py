"""One call from a DEM set-up to a code's input lines and report."""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from pathlib import Path

from vimpact.dem import CODES  # noqa: F401 - the one list of the codes (module vimpact.dem.<code>)
from vimpact.dem.fit import ContactFit, Targets, compute_targets
from vimpact.dem.problem import DemProblem
from vimpact.model.validation import one_of


@dataclass
class Export:
    """What :func:`export` produced: the fits, the targets and the files written."""

    code: str
    fits: list[ContactFit]
    targets: dict[str, Targets]
    files: list[Path]


def code_module(code: str):
    """The module of a DEM code (one of :data:`CODES`)."""
    return importlib.import_module(f"vimpact.dem.{one_of('--for', code, CODES)}")


def export(problem: DemProblem, code: str, out_dir=None, numerics=None,
           targets: dict[str, Targets] | None = None) -> Export:
    """Fit ``code``'s constants for every contact of ``problem``; with ``out_dir``
    write its input file(s), ``report_<code>.md`` and ``report_<code>.png`` there.

    ``targets`` (from an earlier call) skips the vimpact runs; they must hold
    ``beta_x`` if the code has a tangential restitution.
    """
    mod = code_module(code)
    if targets is None or (mod.TANGENTIAL and any(t.beta_x is None for t in targets.values())):
        targets = {c.key: compute_targets(problem, c, tangential=mod.TANGENTIAL, numerics=numerics)
                   for c in problem.contacts}
    fits = mod.fit(problem, targets)
    files: list[Path] = []
    if out_dir is not None:
        from vimpact.dem import report

        out = Path(out_dir)
        out.mkdir(parents=True, exist_ok=True)
        for name, text in mod.render(problem, fits).items():
            (out / name).write_text(text, encoding="utf-8")
            files.append(out / name)
        png = report.figure(code, problem, targets, fits, out / f"report_{code}.png")
        md = out / f"report_{code}.md"
        md.write_text(report.markdown(code, problem, targets, fits, [p.name for p in files],
                                      png.name), encoding="utf-8")
        files += [md, png]
    return Export(code, fits, targets, files)
