"""``vimpact dem``: a DEM set-up (TOML) to the input lines of one DEM code, with a report."""

from __future__ import annotations

import argparse
import math
import os

from vimpact.model.numerics import CONVERGED_PRESETS


def add_parser(sub) -> None:
    """Register ``vimpact dem`` and its options on the subcommand parser ``sub``."""
    from vimpact.dem import CODES  # the light list: the exports load scipy

    p = sub.add_parser(
        "dem", help="fit a DEM code's contact constants to vimpact's restitution",
        description=("Read particle types, walls, friction and the impact-speed range from a "
                     "TOML file (example: sweeps/dem/two_rubbers.toml), fit the chosen DEM "
                     "code's own contact constants to vimpact's e_z(v) (and beta_x(v) where the "
                     "code has a tangential restitution) and write the code's input lines and a "
                     "report (Markdown + PNG) of vimpact beside what the code will produce. "
                     "Guide: docs/dem.md."))
    p.add_argument("file", help="DEM set-up, TOML")
    p.add_argument("--for", dest="code", required=True, choices=CODES, help="the DEM code")
    p.add_argument("--out", default=None,
                   help="output directory (default: vimpact-dem-<code> in the current directory)")
    p.add_argument("--temperature", type=float, default=None, metavar="K",
                   help="temperature of the DEM run, kelvin (> 0): every viscoelastic "
                        "material is shifted to it by its shift law (overrides the set-up's "
                        "temperature_K)")
    p.add_argument("--preset", default="fast", choices=CONVERGED_PRESETS,
                   help="vimpact numerics for the restitution curves (default: fast)")
    p.add_argument("--steps-per-contact", type=int, default=None, metavar="N",
                   help="time steps per shortest contact in the exported time step (lammps: "
                        "100, liggghts: 100, yade: 400 by default); the report gives the "
                        "code's time-step error measured at such steps")
    p.add_argument("--residual", type=float, default=None, metavar="E",
                   help="split every type with a radius range into 1, 2, ... size classes "
                        "(types NAME_1..NAME_k) until the largest e_z residual of every contact "
                        "is at most E (up to 8 classes); the summary says how many it took")
    p.add_argument("--figure", action=argparse.BooleanOptionalAction, default=True,
                   help="draw the report's figure report_<code>.png (default); --no-figure "
                        "skips it (drawing it takes longer than writing the rest of the "
                        "report) and the Markdown report says that no figure was drawn")
    p.add_argument("--json", action="store_true",
                   help="print the fits (constants, residuals, files written) as JSON")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run ``vimpact dem`` and return the exit code."""
    import json
    import sys

    from vimpact.dem.export import export
    from vimpact.dem.problem import load_problem
    from vimpact.model.numerics import Numerics
    from vimpact.model.validation import InputError, message

    if args.steps_per_contact is not None and args.steps_per_contact < 4:
        raise InputError(message("--steps-per-contact", args.steps_per_contact,
                                  "an integer >= 4"))
    if args.out is not None and (os.path.lexists(args.out) and not os.path.isdir(args.out)
                                 or os.path.islink(args.out)):
        raise ValueError(f"--out = {args.out!r} is not allowed: it is "
                         + ("a symbolic link" if os.path.islink(args.out) else "a file")
                         + "; give a directory (created if missing)")
    problem = load_problem(args.file, temperature=args.temperature)
    out = args.out or f"vimpact-dem-{args.code}"

    def progress(text: str) -> None:
        print(f"vimpact dem: {text}", file=sys.stderr, flush=True)

    classes = None
    if args.residual is not None:
        from vimpact.dem.export import export_to_residual

        result, met, needed = export_to_residual(problem, args.code, args.residual, out,
                                         Numerics.preset(args.preset),
                                         steps_per_contact=args.steps_per_contact,
                                         progress=progress, figure=args.figure)
        worst = max((f.res_e_z.max_abs for f in result.fits if f.res_e_z is not None),
                    default=math.nan)
        final = result.problem or problem  # the problem refined to meet the residual
        classes = {"size_classes": final.size_classes,
                   "types": len(final.types), "target": args.residual,
                   "max_residual_e_z": worst, "met": met, "classes_needed": needed}
    else:
        result = export(problem, args.code, out, Numerics.preset(args.preset),
                        steps_per_contact=args.steps_per_contact, progress=progress,
                        figure=args.figure)
    if args.json:
        data = to_json(result)
        if classes is not None:
            data["size_classes"] = classes
        print(json.dumps(data, indent=1))
        return 0
    if classes is not None:
        head = (f"size classes: {classes['size_classes']} per size-range type "
                f"({classes['types']} particle types), largest e_z residual "
                f"{classes['max_residual_e_z']:.2e}")
        if classes["met"]:
            print(f"{head} <= target {args.residual:g}")
        elif classes["classes_needed"]:
            print(f"{head} > target {args.residual:g}: not met; about "
                  f"{classes['classes_needed']} classes would be (the size range's error "
                  "falls as 1/classes)")
        else:
            print(f"{head} > target {args.residual:g}: not met; splitting does not lower it "
                  "(the residual left is not the size range's)")
    for f in result.fits:
        rb = f"; beta_x {f.res_beta_x}" if f.res_beta_x is not None else ""
        print(f"{f.contact.key}: e_z residual {f.res_e_z}{rb}")
    for path in result.files:
        print(f"wrote {path}")
    return 0


def _number(x):
    """JSON-safe: non-finite floats become ``None`` (never NaN or Infinity in the output)."""
    import math

    if isinstance(x, float) and not math.isfinite(x):
        return None
    return x


def to_json(result) -> dict:
    """Return the fits of an export as plain data.

    Per contact the constants (SI), the residuals (code minus vimpact, dimensionless) and
    the notes; the files written.
    """
    def res(r):
        return None if r is None else {"max_abs": r.max_abs, "rms": r.rms}

    def beta_basis(f):
        if f.res_beta_x is None:
            return None
        ob = result.targets[f.contact.key].oblique
        if f.beta_oblique is None or ob is None:
            return {"friction": None, "note": "full stick"}
        return {"friction": ob.mu, "angles_deg": sorted(set(ob.angle_deg.tolist())),
                "speeds_m_s": sorted(set(ob.v.tolist())),
                "note": "oblique impacts with the contact's friction, nominal sizes"}

    return {
        "code": result.code,
        "contacts": [{"contact": f.contact.key, "wall": f.contact.is_wall,
                      "params": {k: _number(v) for k, v in f.params.items()
                                 if isinstance(v, (int, float))},
                      "residual_e_z": res(f.res_e_z), "residual_beta_x": res(f.res_beta_x),
                      "beta_x_fitted_to": beta_basis(f),
                      "notes": f.notes} for f in result.fits],
        "files": [str(p) for p in result.files],
    }
