"""One progress display over rows, for every runner.

On a terminal (stderr is a TTY and ``CI`` is not set): a tqdm bar with rate and
time left. Otherwise one line on stderr every ~10 s (``VIMPACT_PROGRESS_SECONDS``
overrides the interval) and one at the end::

    vimpact sweep kv_table: 1200/6426 rows (18.7 %), 35.2 rows/s, ~2 min 28 s left

A callable given instead is called as ``callback(rows_done, rows_total)`` after
every finished chunk; ``False`` shows nothing.
"""

from __future__ import annotations

import os
import sys
import time
from collections.abc import Callable

#: Seconds between two progress lines off a terminal.
DEFAULT_INTERVAL_S = 10.0


def _duration(seconds: float) -> str:
    seconds = max(0.0, seconds)
    if seconds < 60:
        return f"{seconds:.0f} s"
    minutes, s = divmod(int(round(seconds)), 60)
    if minutes < 60:
        return f"{minutes} min {s} s"
    hours, minutes = divmod(minutes, 60)
    return f"{hours} h {minutes} min"


class Progress:
    """Rows done of ``total`` (``initial`` were done before this run started).

    Parameters
    ----------
    total : rows of the sweep
    initial : rows already done (resumed parts)
    name : shown in front of the bar or line
    mode : ``None`` (a bar on a terminal, lines otherwise), a callable, or ``False``
    interval_s : seconds between lines (default ``VIMPACT_PROGRESS_SECONDS`` or 10)
    stream : where bar and lines go (default ``sys.stderr``)
    """

    def __init__(self, total: int, initial: int = 0, name: str = "",
                 mode: Callable[[int, int], None] | bool | None = None,
                 interval_s: float | None = None, stream=None):
        self.total, self.done, self.name = total, initial, name
        self.initial = initial
        self.stream = stream or sys.stderr
        self.callback = mode if callable(mode) else None
        self.bar = None
        self.lines = False
        if mode is None:
            tty = hasattr(self.stream, "isatty") and self.stream.isatty()
            if tty and not os.environ.get("CI"):
                self.bar = self._bar()
            else:
                self.lines = True
        if interval_s is None:
            interval_s = float(os.environ.get("VIMPACT_PROGRESS_SECONDS", DEFAULT_INTERVAL_S))
        self.interval_s = interval_s
        self.t0 = self.last = time.monotonic()

    def _bar(self):
        from tqdm import tqdm
        try:
            sized = os.get_terminal_size(self.stream.fileno()).columns > 0
        except (OSError, ValueError, AttributeError):
            sized = False
        # a terminal that reports no size (0 x 0) would get no bar at all
        return tqdm(total=self.total, initial=self.initial, unit="row", desc=self.name,
                    file=self.stream, dynamic_ncols=sized, ncols=None if sized else 100,
                    nrows=None if sized else 24, smoothing=0.1)

    def line(self) -> str:
        """Return the progress line: rows done/total, rows/s of this run, time left."""
        elapsed = time.monotonic() - self.t0
        new = self.done - self.initial
        rate = new / elapsed if elapsed > 0 else 0.0
        left = (self.total - self.done) / rate if rate > 0 else float("nan")
        share = 100.0 * self.done / self.total if self.total else 100.0
        tail = (f"~{_duration(left)} left" if self.done < self.total and rate > 0
                else f"in {_duration(elapsed)}" if self.done >= self.total else "starting")
        return (f"vimpact sweep {self.name}: {self.done}/{self.total} rows ({share:.1f} %), "
                f"{rate:.3g} rows/s, {tail}")

    def update(self, rows: int) -> None:
        """``rows`` more rows are done (a chunk was written)."""
        self.done += rows
        if self.bar is not None:
            self.bar.update(rows)
        elif self.callback is not None:
            self.callback(self.done, self.total)
        elif self.lines:
            now = time.monotonic()
            if now - self.last >= self.interval_s:
                self.last = now
                print(self.line(), file=self.stream, flush=True)

    def close(self, finished: bool = True) -> None:
        """Close the bar (or print the last line when ``finished``)."""
        if self.bar is not None:
            self.bar.close()
            self.bar = None
        elif self.lines and finished and self.done > self.initial:
            print(self.line(), file=self.stream, flush=True)
            self.lines = False


__all__ = ["DEFAULT_INTERVAL_S", "Progress"]
