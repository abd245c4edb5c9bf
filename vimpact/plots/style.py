"""The house style of the figures and the one way to draw and save one.

matplotlib is imported only when a figure is drawn.
"""

from __future__ import annotations

import contextlib
from pathlib import Path
from typing import TYPE_CHECKING, Any

from vimpact.tableformat.files import atomic_file, refuse_symlink

if TYPE_CHECKING:  # matplotlib's names of rc keys, for the checker only
    from matplotlib.typing import RcKeyType

__all__ = ["FORMATS", "STYLE", "check_out", "drawing"]

#: Output formats, chosen by the extension of ``out``.
FORMATS = (".png", ".svg", ".pdf")

#: Sizes readable in print at about 8 cm to 16 cm width.
STYLE: dict[RcKeyType, Any] = {
    "font.size": 11,
    "axes.titlesize": 12,
    "axes.labelsize": 12,
    "xtick.labelsize": 10,
    "ytick.labelsize": 10,
    "legend.fontsize": 9.5,
    "legend.framealpha": 0.9,
    "lines.linewidth": 1.6,
    "lines.markersize": 5,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "savefig.dpi": 200,
    "svg.fonttype": "none",
    "pdf.fonttype": 42,
}


def check_out(out) -> Path:
    """``out`` as a Path, if its extension is one of :data:`FORMATS` and its folder exists."""
    path = Path(out)
    if path.suffix.lower() not in FORMATS:
        raise ValueError(f"out = {str(out)!r} is not allowed: must end in "
                         + ", ".join(FORMATS) + " (the format follows the extension)")
    if not path.parent.is_dir():
        raise ValueError(f"out = {str(out)!r} is not allowed: directory "
                         f"{str(path.parent)!r} does not exist")
    refuse_symlink(path, "out")
    return path


@contextlib.contextmanager
def drawing(out, nrows=1, ncols=1, figsize=(6.4, 4.4), **subplots):
    """Yield ``(fig, axes)`` with the house style; save to ``out`` on exit."""
    import matplotlib
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    path = check_out(out)
    with matplotlib.rc_context(STYLE):
        fig = Figure(figsize=figsize, layout="constrained")
        FigureCanvasAgg(fig)
        axes = fig.subplots(nrows, ncols, squeeze=True, **subplots)
        yield fig, axes
        with atomic_file(path, "out") as f:  # never through a symbolic link
            fig.savefig(f, format=path.suffix[1:].lower())
    fig.clear()
