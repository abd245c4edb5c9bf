"""The ``vimpact table`` subcommand: info, lookup, verify and e(v) export of restitution tables.

``add_parser(subparsers)`` registers it on the subparsers object of
:func:`vimpact.cli.main.build_parser`; each sets
``func`` to its handler, which returns the exit code and raises
``ValueError`` on bad input (``vimpact.cli.main.main`` prints it as one line and
exits with 2).
"""

from __future__ import annotations

import argparse
import json
import math

import numpy as np

from vimpact.cli.material_args import add_material_arguments, as_flags, material_from_args

__all__ = ["add_parser"]

#: The most speeds of `table export --n`: :data:`vimpact.lookup.table.MAX_CURVE_POINTS`
#: (not imported here, so that building the parser does not import pandas).
MAX_CURVE_POINTS = 100_000


def _number_list(text: str) -> list[float]:
    """``"0.1,0.2, 1e-3"`` -> ``[0.1, 0.2, 0.001]`` (argparse type)."""
    try:
        values = [float(x) for x in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"{text!r} is not a number or a comma-separated list of numbers") from None
    if not values:
        raise argparse.ArgumentTypeError("expected a number or a comma-separated list of numbers")
    return values


def _json_value(x):
    if isinstance(x, (float, np.floating)):
        return float(x) if math.isfinite(x) else None
    return x


# --------------------------------------------------------------------------
# vimpact table
# --------------------------------------------------------------------------

def add_parser(subparsers) -> argparse.ArgumentParser:
    """Register ``vimpact table {info,lookup,verify,export}`` on ``subparsers``."""
    table = subparsers.add_parser(
        "table", help="inspect, interpolate and export restitution tables",
        description=(
            "Read a restitution table (Parquet, written by `vimpact sweep`): summarize it, "
            "interpolate e_z, e_x, beta_x at given Q1 [Q2] nu [theta_ratio] [psi] (cubic "
            "Hermite in log Q1, log Q2, nu, log theta_ratio and psi on the table's grid, or "
            "linear), measure the interpolation error against direct simulation, or export "
            "e_z(v), e_x(v) for one material and sphere. A table is validated when opened "
            "(vimpact metadata, known statuses, finite outputs within [0, 1] (|beta_x| <= 1) "
            "in ok rows, axes in their domains, no duplicated node): a table that fails is "
            "refused with the file, column, value and row."))
    sub = table.add_subparsers(dest="table_command", required=True, metavar="ACTION")

    info = sub.add_parser("info", help="model, rows, statuses, covered ranges, grid, numerics",
                          description="Summarize a restitution table.",
                          epilog="Example: vimpact table info kv.parquet --json")
    info.add_argument("table", metavar="TABLE", help="restitution table (.parquet)")
    info.add_argument("--json", action="store_true", help="print one JSON object")
    info.set_defaults(func=_cmd_info)

    look = sub.add_parser(
        "lookup", help="interpolate e_z, e_x, beta_x at Q1 [Q2] nu",
        description=(
            "Interpolate e_z, e_x, beta_x (dimensionless) on a grid table: cubic Hermite in "
            "log Q1 (and log Q2), nu, log theta_ratio (tables with several) and psi (tables "
            "with a psi column), shape-preserving where the data is monotone (or "
            "--method linear). The measured interpolation error of the table (`vimpact table "
            "verify --write`) is printed with the values. Each of --Q1, --Q2, --nu, "
            "--theta-ratio, --psi takes one value or a comma-separated list; lists are paired "
            "element by element (a single value is used for every element). Values outside "
            "the table's range are an error unless --extrapolate is given."),
        epilog="Example: vimpact table lookup kv.parquet --Q1 0.01,0.1,1 --nu 0.5 --json")
    look.add_argument("table", metavar="TABLE", help="restitution table (.parquet)")
    look.add_argument("--Q1", type=_number_list, required=True, metavar="Q1[,Q1...]",
                      help="damping parameter sqrt(15/32) (eta/G_inf)/T, dimensionless")
    look.add_argument("--nu", type=_number_list, metavar="NU[,NU...]",
                      help="Poisson ratio, dimensionless (required, except for an adhesive "
                           "table, whose normal impact does not depend on it)")
    look.add_argument("--lam", type=_number_list, metavar="LAM[,LAM...]",
                      help="adhesion number sqrt(2 pi a_H dgamma / E*) / d, dimensionless: "
                           "for adhesive tables (prints e_z, stuck and the sticking lam_s)")
    look.add_argument("--Q2", type=_number_list, metavar="Q2[,Q2...]",
                      help="G1/G2, dimensionless (standard-solid tables only)")
    look.add_argument("--theta-ratio", type=_number_list, metavar="RATIO[,RATIO...]",
                      help="Theta / (m R^2), dimensionless, > 0: for tables that hold several "
                           "(interpolated in log theta_ratio)")
    look.add_argument("--psi", type=_number_list, metavar="PSI[,PSI...]",
                      help="friction incidence 2 (1 - nu) / (mu (2 - nu)) v_c0 / v_z0, "
                           "dimensionless, >= 0: for tables with a psi column")
    look.add_argument("--extrapolate", action="store_true",
                      help="extrapolate linearly outside the covered range (clipped to "
                           "0 <= e <= 1) instead of failing")
    look.add_argument("--method", choices=("cubic", "linear"), default="cubic",
                      help="interpolation: cubic Hermite (default) or multilinear")
    look.add_argument("--json", action="store_true", help="print one JSON object")
    look.set_defaults(func=_cmd_lookup)

    ver = sub.add_parser(
        "verify", help="measure the interpolation error against direct simulation",
        description=(
            "Simulate held-out points between the table's nodes (the mid-point of every cell "
            "edge along each axis, every cell centre, and --n random interior points) with "
            "the table's own numerics, compare with the lookup, and print the max and RMS "
            "error of e_z, beta_x, e_x (dimensionless). --write stores it in the table as "
            "the metadata entry vimpact.interpolation_error, which lookup and info report."),
        epilog="Example: vimpact table verify kv.parquet --n 500 --write")
    ver.add_argument("table", metavar="TABLE", help="restitution table (.parquet)")
    ver.add_argument("--n", type=int, metavar="N",
                     help="random interior points besides the mid-points (default 200; "
                          "an adhesive table: the number its build used)")
    ver.add_argument("--seed", type=int, help="seed of the random points (default 0; an "
                                              "adhesive table: its build's)")
    ver.add_argument("--method", choices=("cubic", "linear"), default="cubic",
                     help="interpolation measured (default cubic)")
    ver.add_argument("--theta-ratio", type=float, metavar="RATIO",
                     help="Theta / (m R^2), only for tables that hold several")
    ver.add_argument("--write", action="store_true",
                     help="store the result in the table (rewrites the file)")
    ver.add_argument("--json", action="store_true", help="print one JSON object")
    ver.set_defaults(func=_cmd_verify)

    bld = sub.add_parser(
        "build", help="build an adaptive table from a spec with [grid] refine = \"adaptive\"",
        description=(
            "Refine cells in log Q1 (x log Q2) until each cell's cubic lookup meets half of "
            "the spec's [grid] tolerance at its check points (e_z, beta_x; nu is a tensor "
            "axis with the spec's nu values), then measure the error at --n random held-out "
            "points and --n points inside random cells against direct simulation, and write "
            "the table (node rows plus the cells in the metadata vimpact.adaptive) with that "
            "error (vimpact.interpolation_error) and the build's time (vimpact.build). A spec "
            "with a lam axis builds an adhesive table instead (e_z and the stuck flag over lam "
            "x Q1, Kelvin-Voigt: vimpact.tablebuild.adhesion; docs/physics.md#adhesion)."),
        epilog="Example: vimpact table build sweeps/standard_solid_table.toml")
    bld.add_argument("spec", metavar="SPEC", help="sweep spec (.toml)")
    bld.add_argument("--out", metavar="PATH",
                     help="Parquet file to write (default: the spec's output)")
    bld.add_argument("--n", type=int, default=2000, metavar="N",
                     help="random held-out points of the verification (default 2000)")
    bld.add_argument("--seed", type=int, default=0, help="seed of the held-out points")
    bld.add_argument("--max-seconds", type=float, metavar="S",
                     help="time budget of the refinement; later levels stay unrefined and "
                          "are reported")
    bld.set_defaults(func=_cmd_build)

    exp = sub.add_parser(
        "export", help="write e_z(v), e_x(v) for one material and sphere to CSV",
        description=(
            "Restitution against impact speed for one material and sphere, from the table: "
            "each speed gives Q1 (through the Hertz time) and is looked up. The material model "
            "is inferred from the options (--E/--G with --eta -> kelvin_voigt; --G1 --G2 "
            "--eta -> standard_solid) and must be the table's. A table with a friction "
            "incidence axis psi needs --angle-deg and --mu: psi = 2 (1 - nu) / (mu (2 - nu)) "
            "tan(angle) for a non-spinning sphere, the same at every speed. Columns of the "
            "CSV: v_z0_m_s (m/s), Q1, [Q2,] [psi,] e_z, e_x, beta_x (dimensionless)."),
        epilog=("Example: vimpact table export kv.parquet --out curve.csv --E 5e10 --nu 0.5 "
                "--eta 1e5 --R 0.2 --m 10 --vz0-min 0.1 --vz0-max 10 --n 50"))
    exp.add_argument("table", metavar="TABLE", help="restitution table (.parquet)")
    exp.add_argument("--out", required=True, metavar="FILE", help="output CSV file (.csv)")
    g = exp.add_argument_group("material")
    add_material_arguments(g, prony=False)
    g = exp.add_argument_group("sphere and speeds")
    g.add_argument("--R", type=float, required=True, metavar="M", help="sphere radius, m")
    g.add_argument("--m", type=float, required=True, metavar="KG", help="sphere mass, kg")
    g.add_argument("--theta-ratio", type=float, metavar="RATIO",
                   help="Theta / (m R^2) (default: the table's, 0.4 for a solid sphere)")
    g.add_argument("--vz0-min", type=float, required=True, metavar="M_S",
                   help="lowest normal impact speed, m/s (> 0)")
    g.add_argument("--vz0-max", type=float, required=True, metavar="M_S",
                   help="highest normal impact speed, m/s")
    g.add_argument("--n", type=int, default=50, metavar="N",
                   help=f"number of speeds (default 50, at most {MAX_CURVE_POINTS})")
    g.add_argument("--spacing", choices=("log", "linear"), default="log",
                   help="spacing of the speeds (default log)")
    g = exp.add_argument_group("friction (tables with a psi axis)")
    g.add_argument("--angle-deg", type=float, metavar="DEG",
                   help="impact angle from the surface normal, degrees, in [0, 90)")
    g.add_argument("--mu", type=float, metavar="MU",
                   help="Coulomb friction coefficient, > 0 (inf: full stick)")
    g = exp.add_argument_group("options")
    g.add_argument("--extrapolate", action="store_true",
                   help="extrapolate outside the table's range instead of failing")
    g.add_argument("--allow-large-contact", action="store_true",
                   help="accept speeds whose Hertz contact radius exceeds 0.2 R")
    g.add_argument("--json", action="store_true", help="print a JSON summary")
    exp.set_defaults(func=_cmd_export)
    return table


def _open(path):
    from vimpact.lookup.table import RestitutionTable

    return RestitutionTable.open(path)


def _plain(x):
    """Return ``x`` with non-finite floats as text.

    ``x`` with non-finite floats as text (``"inf"``: mu of a full-stick row), so the
    JSON is standard.
    """
    if isinstance(x, dict):
        return {k: _plain(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_plain(v) for v in x]
    if isinstance(x, (float, np.floating)) and not math.isfinite(x):
        return str(float(x))
    return x


def _cmd_build(a) -> int:
    import sys

    from vimpact.sweep.spec import ADHESION_AXIS, load_spec
    from vimpact.tablebuild.adaptive import build_adaptive
    from vimpact.tablebuild.verify import MAX_POINTS

    if not 0 <= a.n <= MAX_POINTS:
        raise ValueError(f"--n = {a.n} is not allowed: must be an integer from 0 to "
                         f"{MAX_POINTS} (held-out points, each one direct simulation)")
    if a.seed < 0:
        raise ValueError(f"--seed = {a.seed} is not allowed: must be an integer >= 0")
    if a.max_seconds is not None and not a.max_seconds > 0:
        raise ValueError(f"--max-seconds = {a.max_seconds} is not allowed: must be > 0")
    spec = load_spec(a.spec)
    if ADHESION_AXIS in spec.axes:  # an adhesive table (vimpact.lookup.adhesion)
        from vimpact.tablebuild.adhesion import build_adhesion_table

        build_adhesion_table(spec, a.out, n_verify=a.n, seed=a.seed,
                             log=lambda line: print(line, file=sys.stderr, flush=True))
        return 0
    build_adaptive(spec, a.out, n_verify=a.n, seed=a.seed, max_seconds=a.max_seconds,
                   log=lambda line: print(line, file=sys.stderr, flush=True))
    return 0


def _cmd_info(a) -> int:
    from vimpact.lookup.adhesion import is_adhesion_table

    if is_adhesion_table(a.table):
        from vimpact.lookup.adhesion import AdhesionTable
        from vimpact.lookup.adhesion import format_info as adhesion_info

        info = AdhesionTable.open(a.table).info()
        print(json.dumps(_plain(info), default=_json_value) if a.json else adhesion_info(info))
        return 0
    info = _open(a.table).info()
    if a.json:
        print(json.dumps(_plain(info), default=_json_value, allow_nan=False))
    else:
        from vimpact.lookup.table import format_info

        print(format_info(info))
    return 0


def _lookup_adhesion(a) -> int:
    from vimpact.lookup.adhesion import AdhesionTable

    if a.lam is None:
        raise ValueError("--lam is missing: an adhesive table is looked up at --Q1 and --lam "
                         "(the adhesion number)")
    for flag, value in (("--Q2", a.Q2), ("--theta-ratio", a.theta_ratio), ("--psi", a.psi)):
        if value:
            raise ValueError(f"{flag} is not allowed for an adhesive table (axes Q1, lam)")
    if a.nu is not None and not all(0.0 <= x <= 0.5 for x in a.nu):
        raise ValueError(f"--nu = {a.nu} is not allowed: must be in [0, 0.5]")
    if a.extrapolate or a.method != "cubic":
        raise ValueError("--extrapolate, --method linear are not allowed for an adhesive "
                         "table: its lookup is cubic inside its range")
    if len({len(a.Q1), len(a.lam)} - {1}) > 1:
        raise ValueError(f"--Q1 has {len(a.Q1)} values, --lam has {len(a.lam)}: lists must "
                         "have one length (or be a single value)")
    table = AdhesionTable.open(a.table)
    n = max(len(a.Q1), len(a.lam))
    res = table.lookup(np.broadcast_to(np.array(a.Q1, dtype=float), (n,)),
                       np.broadcast_to(np.array(a.lam, dtype=float), (n,)))
    bound = res.pop("error_bound")
    rows = [{"Q1": float(res["Q1"][i]), "lam": float(res["lam"][i]),
             "e_z": float(res["e_z"][i]), "stuck": bool(res["stuck"][i]),
             "lam_s": float(res["lam_s"][i])} for i in range(n)]
    if a.json:
        print(json.dumps({"table": a.table, "kind": "adhesion", "model": "kelvin_voigt",
                          "error_bound": bound, "rows": rows}))
        return 0
    print(f"adhesive kelvin_voigt table {a.table}, cubic (normal impact; stuck: the sphere "
          "does not separate, e_z = 0)")
    print("  ".join(f"{k:>12}" for k in rows[0]))
    for row in rows:
        print("  ".join(f"{str(v) if isinstance(v, bool) else format(v, '.6g'):>12}"
                        for v in row.values()))
    if bound:
        print("interpolation error (max measured at held-out points): "
              + ", ".join(f"{k} {v:.2g}" for k, v in bound.items() if v is not None))
    return 0


def _cmd_lookup(a) -> int:
    from vimpact.lookup.adhesion import is_adhesion_table

    if is_adhesion_table(a.table):
        return _lookup_adhesion(a)
    if a.lam is not None:
        raise ValueError("--lam is not allowed: this is not an adhesive table")
    if a.nu is None:
        raise ValueError("--nu is missing: the lookup needs the Poisson ratio")
    table = _open(a.table)
    given = {"--Q1": a.Q1, "--nu": a.nu, **({"--Q2": a.Q2} if a.Q2 else {}),
             **({"--theta-ratio": a.theta_ratio} if a.theta_ratio else {}),
             **({"--psi": a.psi} if a.psi else {})}
    if len({len(v) for v in given.values()} - {1}) > 1:
        raise ValueError(", ".join(f"{k} has {len(v)} values" for k, v in given.items())
                         + ": lists must have one length (or be a single value)")
    n = max(len(v) for v in given.values())

    def column(values):
        return None if values is None else np.broadcast_to(np.array(values, dtype=float), (n,))

    try:
        res = table.lookup(column(a.Q1), column(a.nu), column(a.Q2), extrapolate=a.extrapolate,
                           theta_ratio=column(a.theta_ratio), method=a.method,
                           psi=column(a.psi))
    except ValueError as exc:  # name the options as typed, not the API's arguments
        raise as_flags(exc, _LOOKUP_FLAGS) from None
    bound = res.pop("error_bound")
    names = list(res)
    rows = [{k: _json_value(float(res[k][i])) for k in names} for i in range(len(res["Q1"]))]
    if a.json:
        print(json.dumps({"table": a.table, "model": table.model, "extrapolate": a.extrapolate,
                          "method": a.method, "error_bound": bound, "rows": rows}))
    else:
        print(f"{table.model} table {a.table}, {a.method}" + (" (extrapolated where outside)"
                                                              if a.extrapolate else ""))
        print("  ".join(f"{k:>12}" for k in names))
        for row in rows:
            print("  ".join(f"{'nan' if row[k] is None else format(row[k], '.6g'):>12}"
                            for k in names))
        if bound:
            from vimpact.tablebuild.verify import BOUND_FACTOR

            print(f"interpolation error bound ({BOUND_FACTOR:g} x the max measured between "
                  "nodes): " + ", ".join(f"{k} {v:.2g}" for k, v in bound.items()))
        else:
            print(f"interpolation error not measured for {a.method} "
                  f"(`vimpact table verify {a.table} --method {a.method} --write`)")
    return 0


def _verify_adhesion(a) -> int:
    from vimpact.lookup.adhesion import AdhesionTable
    from vimpact.tablebuild.adhesion import verify_adhesion_table
    from vimpact.tablebuild.verify import MAX_POINTS

    if a.seed is not None and a.seed < 0:
        raise ValueError(f"--seed = {a.seed} is not allowed: must be an integer >= 0")
    if a.n is not None and not 1 <= a.n <= MAX_POINTS:
        raise ValueError(f"--n = {a.n} is not allowed: must be an integer from 1 to "
                         f"{MAX_POINTS} (held-out points, twice as many simulations)")
    table = AdhesionTable.open(a.table)
    stored = table.meta("interpolation_error") or {}
    n = stored.get("n", 200) if a.n is None else a.n
    seed = stored.get("seed", 0) if a.seed is None else a.seed
    result = verify_adhesion_table(table, n=n, seed=seed)
    if a.write:
        table.metadata["vimpact.interpolation_error"] = json.dumps(result)
        table.save(a.table)
    if a.json:
        print(json.dumps({"measured": result, "stored": stored or None}, default=_json_value))
        return 0
    print(f"adhesive table {a.table}: lookup against direct simulation at {result['points']} "
          f"held-out points (seed {seed}; half in the band around the sticking boundary)")
    for name, v in result["outputs"].items():
        was = (stored.get("outputs") or {}).get(name, {}).get("max")
        if v["max"] is None:
            print(f"  {name:<9} no points")
            continue
        print(f"  {name:<9} max {v['max']:.6g}, rms {v['rms']:.3g}"
              + (f" (stored max {was:.6g})" if was is not None else ""))
    print(f"  stuck flag misread at {result['stuck_misread']} points"
          + (f" (stored {stored['stuck_misread']})" if "stuck_misread" in stored else ""))
    return 0


def _cmd_verify(a) -> int:
    from vimpact.lookup.adhesion import is_adhesion_table
    from vimpact.tablebuild.verify import MAX_POINTS, interpolation_error, write_interpolation_error

    if is_adhesion_table(a.table):
        return _verify_adhesion(a)
    a.n = 200 if a.n is None else a.n
    a.seed = 0 if a.seed is None else a.seed
    if a.seed < 0:
        raise ValueError(f"--seed = {a.seed} is not allowed: must be an integer >= 0")
    if not 0 <= a.n <= MAX_POINTS:
        raise ValueError(f"--n = {a.n} is not allowed: must be an integer from 0 to "
                         f"{MAX_POINTS} (random held-out points, each one direct simulation)")
    table = _open(a.table)
    result = interpolation_error(table, n=a.n, seed=a.seed, theta_ratio=a.theta_ratio,
                                 method=a.method)
    if a.write:
        write_interpolation_error(table, result)
    if a.json:
        print(json.dumps(result, default=_json_value))
        return 0
    print(f"{table.model} table {a.table}: {a.method} lookup against direct simulation at "
          f"{result['points']} held-out points ({result['failed']} failed, left out)")
    for name, v in result["outputs"].items():
        if v["max"] is None:
            print(f"  {name:<7} no data")
            continue
        at = ", ".join(f"{k} = {x:.4g}" for k, x in v["at"].items())
        print(f"  {name:<7} max {v['max']:.3g} (at {at}), rms {v['rms']:.3g}")
    for axis, errs in result["per_axis"].items():
        print(f"  mid-way along {axis}: " + ", ".join(f"{k} {e:.3g}" for k, e in errs.items()))
    if result["node_error"]:
        print("  at the table's nodes (re-simulated sample): "
              + ", ".join(f"{k} {e:.3g}" for k, e in result["node_error"].items()))
    if a.write:
        print(f"stored as vimpact.interpolation_error in {a.table}")
    return 0


_MATERIAL_OPTIONS = {
    "kelvin_voigt": "--E or --G (Pa), --eta (Pa s) and --nu",
    "standard_solid": "--G1, --G2 (Pa), --eta (Pa s) and --nu",
}


#: ``RestitutionTable.lookup`` parameter -> the ``table lookup`` option.
_LOOKUP_FLAGS = {"Q1": "--Q1", "Q2": "--Q2", "nu": "--nu", "theta_ratio": "--theta-ratio",
                 "psi": "--psi", "extrapolate=True (--extrapolate)": "--extrapolate"}
#: ``RestitutionTable.export_curve`` parameter -> the ``table export`` option.
_EXPORT_FLAGS = {"out": "--out", "mu": "--mu", "angle_deg": "--angle-deg",
                 "theta_ratio": "--theta-ratio", "R": "--R", "m": "--m", "v_z0": "--vz0-min/max",
                 "speeds": "--vz0-min/max"}


def _cmd_export(a) -> int:
    require_n = a.n >= 1 and (a.n >= 2 or a.vz0_min == a.vz0_max)
    if not require_n:
        raise ValueError(f"--n = {a.n} is not allowed: must be an integer >= 2 "
                         "(1 only when --vz0-min equals --vz0-max)")
    if a.n > MAX_CURVE_POINTS:
        raise ValueError(f"--n = {a.n} is not allowed: at most {MAX_CURVE_POINTS} speeds "
                         "per curve")
    if not (math.isfinite(a.vz0_min) and a.vz0_min > 0):
        raise ValueError(f"--vz0-min = {a.vz0_min!r} is not allowed: must be a finite speed > 0 (m/s)")
    if not (math.isfinite(a.vz0_max) and a.vz0_max >= a.vz0_min):
        raise ValueError(f"--vz0-max = {a.vz0_max!r} is not allowed: must be finite and "
                         f">= --vz0-min = {a.vz0_min!r} (m/s)")
    table = _open(a.table)
    material = material_from_args(a)  # model inferred as in `vimpact simulate`
    if material.model != table.model:
        need = _MATERIAL_OPTIONS.get(table.model, f"a {table.model} material")
        raise ValueError(f"the material options give the model {material.model!r}, but the "
                         f"table is {table.model!r}: give {need}")
    if a.spacing == "log":
        speeds = np.geomspace(a.vz0_min, a.vz0_max, a.n)
    else:
        speeds = np.linspace(a.vz0_min, a.vz0_max, a.n)
    try:
        df = table.export_curve(a.out, material, a.R, a.m, speeds, theta_ratio=a.theta_ratio,
                                extrapolate=a.extrapolate,
                                allow_large_contact=a.allow_large_contact,
                                angle_deg=a.angle_deg, mu=a.mu)
    except ValueError as exc:  # name the options as typed, not the API's arguments
        raise as_flags(exc, _EXPORT_FLAGS) from None
    summary = {"out": a.out, "model": material.model, "rows": len(df),
               **({"psi": float(df.psi.iloc[0]), "angle_deg": a.angle_deg, "mu": a.mu}
                  if "psi" in df.columns else {}),
               "v_z0_m_s": [float(speeds[0]), float(speeds[-1])],
               "Q1": [float(df.Q1.min()), float(df.Q1.max())],
               "e_z": [_json_value(df.e_z.min()), _json_value(df.e_z.max())]}
    if a.json:
        print(json.dumps(summary))
    else:
        at = (f", psi {df.psi.iloc[0]:.4g} at {a.angle_deg:g} deg, mu {a.mu:g}"
              if "psi" in df.columns else "")
        print(f"wrote {len(df)} speeds {speeds[0]:.6g} .. {speeds[-1]:.6g} m/s "
              f"(Q1 {df.Q1.min():.4g} .. {df.Q1.max():.4g}, e_z {df.e_z.min():.4g} .. "
              f"{df.e_z.max():.4g}{at}) to {a.out}")
    return 0
