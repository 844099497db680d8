"""A dependency-free progress bar for long runs, drawn on stderr only when it is a terminal."""

from __future__ import annotations

import sys
import time

__all__ = ["ProgressBar"]


class ProgressBar:
    """Callable ``bar(fraction)`` drawing ``label [#####.....]  50%  1.2 s, ETA 1 s`` (the time left at the
    rate so far); ``bar.close()`` ends the line."""

    def __init__(self, label: str, stream=None, width: int = 30):
        self.label, self.stream, self.width = label, stream or sys.stderr, width
        self.enabled = hasattr(self.stream, "isatty") and self.stream.isatty()
        self.started = time.perf_counter()

    def __call__(self, fraction: float) -> None:
        if not self.enabled:
            return
        filled = int(round(self.width * min(max(fraction, 0.0), 1.0)))
        elapsed = time.perf_counter() - self.started
        eta = f", ETA {elapsed * (1 - fraction) / fraction:.0f} s " if 0 < fraction < 1 else " " * 12
        self.stream.write(f"\r{self.label} [{'#' * filled}{'.' * (self.width - filled)}] "
                          f"{100 * fraction:5.1f}%  {elapsed:.1f} s{eta}")
        self.stream.flush()

    def close(self) -> None:
        if self.enabled:
            self.stream.write("\n")
            self.stream.flush()
