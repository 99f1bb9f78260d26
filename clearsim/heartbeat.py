"""A progress line every ~10 s when the output is not a terminal (a log, a CI job, a pipe).

In a terminal the rich progress bars show the progress; written to a file they are switched off, and a long run,
sweep or diagnosis would say nothing for minutes. A `Heartbeat` keeps the latest progress it was given
(`update(progress, done, total)`) and, while it runs (`with heartbeat:`), writes one line every interval, whether
or not anything changed meanwhile (a sweep's case or a diagnosis's batch can take minutes): what is done of how
much, the elapsed time and, when `total` is known, the time left at the pace since the first update (not since the
start: loading or compiling the kernels comes before it). The interval is $CLEARSIM_HEARTBEAT_SECONDS (default
10 s). A progress given since the last line is written when the heartbeat stops, so a log ends with the final state.
"""

from __future__ import annotations

import os
import threading
import time
from typing import Callable

DEFAULT_SECONDS = 10.0
SHORTEST_SECONDS = 0.01  # the ticker's shortest wait, whatever the interval


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
    """Seconds still needed for `total` at the pace of `done` in `elapsed`; None when it cannot be told yet."""
    if total is None or done <= 0.0 or elapsed <= 0.0:
        return None
    return elapsed * max(total - done, 0.0) / done


class Heartbeat:
    """'<command>: <progress>, <elapsed> elapsed[, about <left> left]' every `interval` seconds while running."""

    def __init__(self, write: Callable[[str], None], command: str, interval: float | None = None,
                 clock: Callable[[], float] = time.monotonic, enabled: bool = True):
        self.write, self.command, self.clock, self.enabled = write, command, clock, enabled
        self.interval = heartbeat_seconds() if interval is None else interval
        self.started = clock()
        self.last = self.started
        self.progress, self.done, self.total = "starting", 0.0, None
        self.first: tuple[float, float] | None = None  # (time, done) of the first update: the pace is measured from it
        self.unwritten = False  # a progress was given since the last line
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._ticker: threading.Thread | None = None

    def update(self, progress: str, done: float = 0.0, total: float | None = None) -> None:
        """The latest progress (written at the next beat)."""
        with self._lock:
            if self.first is None:
                self.first = (self.clock(), done)
            self.progress, self.done, self.total = progress, done, total
            self.unwritten = True
        self.beat()

    def beat(self, final: bool = False) -> None:
        """Write the latest progress if the interval has passed since the last line (final: if it is unwritten)."""
        if not self.enabled:
            return
        with self._lock:
            now = self.clock()
            if (not self.unwritten) if final else (now - self.last < self.interval):
                return
            self.last, self.unwritten = now, False
            line = self.line(now)
        self.write(line)

    def line(self, now: float) -> str:
        left = None
        if self.first is not None and self.total is not None:
            first_time, first_done = self.first
            left = time_left(now - first_time, self.done - first_done, self.total - first_done)
        tail = f", about {duration(left)} left" if left is not None else ""
        return f"{self.command}: {self.progress}, {duration(now - self.started)} elapsed{tail}"

    def __enter__(self) -> "Heartbeat":
        if not self.enabled:
            return self
        self._ticker = threading.Thread(target=self._tick, name="clearsim-heartbeat", daemon=True)
        self._ticker.start()
        return self

    def __exit__(self, *exc) -> None:
        self._stop.set()
        if self._ticker is not None:
            self._ticker.join()
        self.beat(final=True)

    def _tick(self) -> None:
        while not self._stop.wait(max(self.interval, SHORTEST_SECONDS)):
            self.beat()
