"""A dependency-free progress report for long runs, on stderr: a bar redrawn in place on a terminal,
otherwise (a log, CI) one line at most every ``interval_s`` seconds."""

from __future__ import annotations

import sys
import time

__all__ = ["ProgressBar"]


class ProgressBar:
    """Callable ``bar(fraction)`` drawing ``label [#####.....]  12/176 runs  50%  1.2 s, ETA 1 s`` (the
    count when ``total`` is set, the time left at the rate so far); the line ends at 100 % or at
    ``bar.close()``.

    total: how many items the fraction counts (runs, claims, ...), ``unit`` their name; a caller that
    learns it later sets ``bar.total``. Off a terminal the first line comes after ``interval_s``, so a
    short step prints nothing, and the last at completion once a line was printed."""

    def __init__(self, label: str, stream=None, width: int = 30, total: int | None = None, unit: str = "",
                 interval_s: float = 10.0):
        self.label, self.stream, self.width = label, stream or sys.stderr, width
        self.total, self.unit, self.interval_s = total, unit, interval_s
        self.terminal = hasattr(self.stream, "isatty") and self.stream.isatty()
        self.started = time.perf_counter()
        self._last_line = self.started if not self.terminal else None  # off a terminal: time of the last line
        self._printed, self._open = False, False

    def __call__(self, fraction: float) -> None:
        fraction = min(max(fraction, 0.0), 1.0)
        now = time.perf_counter()
        elapsed = now - self.started
        count = f"  {round(fraction * self.total)}/{self.total}{' ' + self.unit if self.unit else ''}" \
            if self.total is not None else ""
        eta = f", ETA {elapsed * (1 - fraction) / fraction:.0f} s" if 0 < fraction < 1 else ""
        if self.terminal:
            filled = int(round(self.width * fraction))
            self.stream.write(f"\r{self.label} [{'#' * filled}{'.' * (self.width - filled)}]{count} "
                              f"{100 * fraction:5.1f}%  {elapsed:.1f} s{eta}   ")
            self._open = True
            if fraction >= 1:
                self.close()
                return
        elif now - self._last_line >= self.interval_s or (fraction >= 1 and self._printed):
            self.stream.write(f"{self.label}:{count} ({100 * fraction:.0f}%), {elapsed:.0f} s{eta}\n")
            self._last_line, self._printed = now, True
        else:
            return
        self.stream.flush()

    def close(self) -> None:
        """End the bar's line (on a terminal); the next write starts on a new line."""
        if self._open:
            self.stream.write("\n")
            self.stream.flush()
            self._open = False
