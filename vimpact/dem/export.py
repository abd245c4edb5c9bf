"""One call from a DEM set-up to a code's input lines and report."""

from __future__ import annotations

import dataclasses
import importlib
import math
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
    problem: DemProblem | None = None


def code_module(code: str):
    """Return the module of a DEM code (one of :data:`CODES`)."""
    return importlib.import_module(f"vimpact.dem.{one_of('--for', code, CODES)}")


def export(problem: DemProblem, code: str, out_dir=None, numerics=None,
           targets: dict[str, Targets] | None = None, steps_per_contact: int | None = None,
           progress=None, tangential: bool | None = None, figure: bool = True) -> Export:
    """Fit ``code``'s constants for every contact of ``problem``; write the files.

    With ``out_dir``, the code's input file(s), ``report_<code>.md`` and
    ``report_<code>.png`` are written there (``figure=False``: no PNG, and the
    report says that no figure was drawn). ``targets`` (from an earlier call, by
    contact key) skips the vimpact runs of the contacts it holds (those without
    ``beta_x`` are run again when the code has a tangential restitution).
    ``steps_per_contact`` sets the exported time step of the codes that get one (LAMMPS,
    LIGGGHTS, Yade; default: the module's ``STEPS_PER_CONTACT``). ``progress(text)`` is
    called before each contact's vimpact runs and before the fit. ``tangential=False``
    skips ``beta_x`` (and the tangential fits) for a code that has it.
    """
    mod = code_module(code)
    say = progress or (lambda _text: None)
    sticky = [c.key for c in problem.contacts if c.adhesion > 0.0]
    if sticky and not getattr(mod, "ADHESION", False):
        from vimpact.model.validation import InputError

        raise InputError(f"[adhesion] of {', '.join(sticky)} is not allowed with --for {code}: "
                         "only --for lammps has an adhesive law (granular jkr)")
    steps = getattr(mod, "STEPS_PER_CONTACT", None)
    if steps_per_contact is not None:
        if steps is None:
            from vimpact.model.validation import InputError, message

            raise InputError(message("--steps-per-contact", steps_per_contact,
                                     "only with --for lammps, liggghts or yade "
                                     f"({code} takes no time step)"))
        steps = steps_per_contact
    tan = mod.TANGENTIAL if tangential is None else (mod.TANGENTIAL and tangential)
    targets = {k: t for k, t in (targets or {}).items() if not (tan and t.beta_x is None)}
    if not tan:
        targets = {k: dataclasses.replace(t, beta_x=None) for k, t in targets.items()}
    missing = [c for c in problem.contacts if c.key not in targets]
    for k, c in enumerate(missing, start=1):
        say(f"vimpact curves {k}/{len(missing)}: {c.key}"
            + (" (normal and tangential)" if tan else ""))
        targets[c.key] = compute_targets(problem, c, tangential=tan, numerics=numerics)
    targets = {c.key: targets[c.key] for c in problem.contacts}
    say(f"fitting {code}'s constants")
    fits = mod.fit(problem, targets)
    render_kw = {} if steps is None else {"steps_per_contact": steps}
    files: list[Path] = []
    if out_dir is not None:
        from vimpact.dem import report

        out = Path(out_dir)
        out.mkdir(parents=True, exist_ok=True)
        for name, text in mod.render(problem, fits, **render_kw).items():
            (out / name).write_text(text, encoding="utf-8")
            files.append(out / name)
        png = (report.figure(code, problem, targets, fits, out / f"report_{code}.png")
               if figure else None)
        md = out / f"report_{code}.md"
        md.write_text(report.markdown(code, problem, targets, fits, [p.name for p in files],
                                      None if png is None else png.name, steps,
                                      getattr(mod, "TIME_STEP_ERROR", None),
                                      getattr(mod, "BETA_TIME_STEP_ERROR", None)),
                      encoding="utf-8")
        files += [md] if png is None else [md, png]
    return Export(code, fits, targets, files, problem)


#: most size classes :func:`export_to_residual` tries per size-range type
MAX_SIZE_CLASSES = 8


def export_to_residual(problem: DemProblem, code: str, residual: float, out_dir=None,
                       numerics=None, steps_per_contact: int | None = None,
                       progress=None, tangential: bool | None = None, figure: bool = True
                       ) -> tuple[Export, bool, int]:
    """Split the size-range types into size classes until ``e_z`` meets ``residual``.

    Size classes as in :meth:`DemProblem.with_size_classes`, until the largest ``e_z``
    residual (dimensionless) of every contact is at most ``residual``: 1 class, then
    (the size range's error falling about as 1/k) the number that scaling says, checked
    again, up to :data:`MAX_SIZE_CLASSES`; it stops early when a split no longer lowers
    the residual (what is left is not the size range's, e.g. the speed dependence a
    constant-``e`` code cannot follow). Writes the files of the best problem (with
    ``beta_x`` and the tangential fits, unless ``tangential=False``; the search itself
    uses ``e_z`` only; ``figure`` as in :func:`export`).

    Returns
    -------
    (export, met, needed) : the export (``export.problem.size_classes`` is the
    number of classes used, its types the split ones), whether the target was
    met and the number of classes the 1/k scaling says it takes (0 when splitting
    does not lower the residual).
    """
    from vimpact.model.validation import positive

    positive("--residual", residual)
    say = progress or (lambda _text: None)
    cache: dict = {}

    def ident(c):
        return (c.key, c.first.radii, getattr(c.second, "radii", None))

    last = None
    stalled = not problem.has_size_range
    k = 1
    while True:
        prob = problem.with_size_classes(k) if k > 1 else problem
        say(f"size classes per size-range type: {k}")
        known = {c.key: cache[ident(c)] for c in prob.contacts if ident(c) in cache}
        ex = export(prob, code, None, numerics, known, steps_per_contact, progress,
                    tangential=False)  # the search needs e_z only
        for c in prob.contacts:
            cache[ident(c)] = ex.targets[c.key]
        worst = max(f.res_e_z.max_abs for f in ex.fits)
        if last is not None and worst >= 0.95 * last[2]:
            stalled = True
            break  # splitting no longer helps: the residual left is not the size range's
        last = (prob, ex, worst)
        if worst <= residual or not problem.has_size_range or k >= MAX_SIZE_CLASSES:
            break
        # the size range's error falls about as 1/k: aim there, at least one class more
        k = min(MAX_SIZE_CLASSES, max(k + 1, math.ceil(1.1 * k * worst / residual)))
    prob, ex, worst = last
    met = worst <= residual
    k = prob.size_classes
    needed = k if met else (0 if stalled else math.ceil(k * worst / residual))
    if out_dir is not None:
        ex = export(prob, code, out_dir, numerics, ex.targets, steps_per_contact, progress,
                    tangential, figure)
    return ex, met, needed
