"""A progress line every HEARTBEAT_SECONDS when the output is not a terminal (a log, a CI job, a pipe).

In a terminal the rich progress bars show the progress; written to a file they are switched off, and a long run,
sweep or diagnosis would say nothing for minutes. `Heartbeat.beat(done, total, detail)` prints one line at most
every interval: what is done of how much, the elapsed time and, when `total` is known, the time left at the pace
since the first update (not since the start: loading or compiling the kernels comes before it). The interval is $CLEARSIM_HEARTBEAT_SECONDS (default 10 s; 0 prints every update).
"""

from __future__ import annotations

import os
import time
from typing import Callable

DEFAULT_SECONDS = 10.0


def heartbeat_seconds() -> float:
    """The interval between two lines (s): $CLEARSIM_HEARTBEAT_SECONDS, else DEFAULT_SECONDS."""
    text = os.environ.get("CLEARSIM_HEARTBEAT_SECONDS", "")
    try:
        return max(float(text), 0.0) if text else DEFAULT_SECONDS
    except ValueError:
        return DEFAULT_SECONDS


def duration(seconds: float) -> str:
    """'4.2 s', '42 s', '3 min 05 s', '2 h 07 min'."""
    if seconds < 9.95:
        return f"{max(seconds, 0.0):.1f} s"
    seconds = int(round(seconds))
    if seconds < 60:
        return f"{seconds} s"
    if seconds < 3600:
        return f"{seconds // 60} min {seconds % 60:02d} s"
    return f"{seconds // 3600} h {seconds % 3600 // 60:02d} min"


def time_left(elapsed: float, done: float, total: float | None) -> float | None:
    """Seconds still needed at the pace so far; None when it cannot be told yet."""
    if total is None or done <= 0.0 or elapsed <= 0.0:
        return None
    return elapsed * max(total - done, 0.0) / done


class Heartbeat:
    """Prints '<command>: <progress>, <elapsed> elapsed[, about <left> left]' at most every `interval` seconds."""

    def __init__(self, write: Callable[[str], None], command: str, interval: float | None = None,
                 clock: Callable[[], float] = time.monotonic):
        self.write, self.command, self.clock = write, command, clock
        self.interval = heartbeat_seconds() if interval is None else interval
        self.started = clock()
        self.last = self.started
        self.first: tuple[float, float] | None = None  # (time, done) of the first update: the pace is measured from it

    def beat(self, progress: str, done: float = 0.0, total: float | None = None) -> None:
        now = self.clock()
        if self.first is None:
            self.first = (now, done)
        if now - self.last < self.interval:
            return
        self.last = now
        elapsed = now - self.started
        first_time, first_done = self.first
        left = time_left(now - first_time, done - first_done, None if total is None else total - first_done)
        tail = f", about {duration(left)} left" if left is not None else ""
        self.write(f"{self.command}: {progress}, {duration(elapsed)} elapsed{tail}")
