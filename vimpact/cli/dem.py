"""``vimpact dem``: a DEM set-up (TOML) to the input lines of one DEM code, with a report."""

from __future__ import annotations

import argparse
import os


def add_parser(sub) -> None:
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
    p.add_argument("--preset", default="fast", choices=("fast", "default", "precise"),
                   help="vimpact numerics for the restitution curves (default: fast)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from vimpact.dem.export import export
    from vimpact.dem.problem import load_problem
    from vimpact.model.numerics import Numerics

    out = args.out or f"vimpact-dem-{args.code}"
    if args.out is not None and (os.path.lexists(out) and not os.path.isdir(out)
                                 or os.path.islink(out)):
        raise ValueError(f"--out = {out!r} is not allowed: it is "
                         + ("a symbolic link" if os.path.islink(out) else "a file")
                         + "; give a directory (created if missing)")
    problem = load_problem(args.file)
    result = export(problem, args.code, out, Numerics.preset(args.preset))
    for f in result.fits:
        rb = f"; beta_x {f.res_beta_x}" if f.res_beta_x is not None else ""
        print(f"{f.contact.key}: e_z residual {f.res_e_z}{rb}")
    for path in result.files:
        print(f"wrote {path}")
    return 0
