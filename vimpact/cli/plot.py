"""``vimpact plot``: redraw a figure from our own runs or tables."""

from __future__ import annotations

import argparse
import textwrap


def add_parser(subparsers) -> argparse.ArgumentParser:
    """Register ``vimpact plot NAME --out FILE [--table TABLE]`` on ``subparsers``."""
    from vimpact.plots.catalogue import CATALOGUE  # titles only: no drawing code yet

    lines = [f"  {name:<7} {title}" + (f"\n          (needs --table, made by {spec})"
                                       if spec else "")
             for name, (title, spec) in CATALOGUE.items()]
    plot = subparsers.add_parser(
        "plot", help="redraw a thesis figure from our own runs or tables",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description=textwrap.fill(
            "Redraw a figure of the thesis. Figures 3.x and 4.x are computed on the fly; "
            "figures 5.x read a restitution table (--table). The format follows the extension "
            "of --out: .png, .svg or .pdf.", 79) + "\n\nfigures:\n" + "\n".join(lines),
        epilog="Example: vimpact plot fig5_2 --table fig5_2_5_3.parquet --out fig5_2.png")
    plot.add_argument("name", metavar="NAME", help="figure name, e.g. fig3_2 or 5.2 (list above)")
    plot.add_argument("--out", required=True, metavar="FILE", help="output file (.png, .svg, .pdf)")
    plot.add_argument("--table", action="append", metavar="TABLE",
                      help="restitution table for figures 5.x (.parquet); figures 5.4/5.5 take "
                           "a second one, a Kelvin-Voigt table for the black curve")
    plot.set_defaults(func=_cmd_plot)
    return plot


def _cmd_plot(a) -> int:
    from vimpact.plots.catalogue import figure_name

    figure_name(a.name)  # a bad name is refused before the drawing code loads (about 2.5 s)
    from vimpact.plots.figures import plot_figure

    try:
        path = plot_figure(a.name, a.out, table=a.table)
    except ValueError as exc:  # name the options as typed, not the API's arguments
        text = str(exc)
        for api, flag in (("out = ", "--out = "), ("table = ", "--table = ")):
            if text.startswith(api):
                raise ValueError(flag + text[len(api):]) from None
        raise
    print(f"wrote {path}")
    return 0
