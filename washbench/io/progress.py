"""Progress of long work with its expected end, on standard error: a bar on a terminal, plain lines in a log.

``suite: [########------------]  40% (4 of 10 manoeuvres), expected end 04:12:30 (in 1 min 20 s)``

The expected end is a straight line through the work done so far: with ``done`` of ``total`` units
finished ``elapsed`` seconds after the start, the rest takes ``elapsed * (total - done) / done``. The
units are what the command knows in advance: rows for ``cue``, steps (samples x candidates) for
``sweep``, evaluations for ``tune``, manoeuvres for ``suite``. What a command pays once before or with its
first units (starting its worker processes and, after an install, compiling the kernels: a minute on a loaded
machine) must not stretch every estimate (a suite at 5 % once printed an end 28 minutes away, and ended 2
minutes later; a ``cue`` of 216,000 rows at 4 % an end 3 minutes away, and ended 26 s later). So the line goes
through the first update instead of the start once there is a later one: the rows or steps done since then, in
the time since then. Where the units time themselves (the suite's runs, each timed in its worker:
:meth:`Progress.timed`), the time counts from when the first of them started.

Nothing is shown for work finished within :data:`QUIET_FOR_S` seconds (a short command stays silent).
After that, on a terminal the bar overwrites itself (at most five times a second) and :meth:`Progress.close`
ends its line; in a log (standard error not a terminal) a plain line is written each time another tenth of the
work is done, and at least every :data:`LOG_EVERY_S` seconds while it is slow.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable
from typing import TextIO

QUIET_FOR_S = 2.0
"""Work done within this many seconds shows no progress at all."""
LOG_EVERY_S = 60.0
"""In a log, a line at least this often [s] (besides one per tenth of the work)."""
TTY_EVERY_S = 0.2
BAR_WIDTH = 20


def duration_text(seconds: float) -> str:
    """``45 s``, ``3 min 20 s``, ``2 h 05 min`` (rounded to the second)."""
    s = max(0, round(seconds))
    if s < 60:
        return f"{s} s"
    if s < 3600:
        return f"{s // 60} min {s % 60:02d} s"
    return f"{s // 3600} h {s % 3600 // 60:02d} min"


class Progress:
    """Progress of ``total`` units of work labelled ``label`` (``unit``: their plural name).

    :meth:`update` takes the units done so far (counted from :attr:`offset`, for work done in parts) and an
    optional short text (the item just finished); :meth:`close` ends the bar's line on a terminal. ``stream``,
    ``clock`` (monotonic seconds) and ``wall`` (epoch seconds) are for tests; ``tty`` defaults to whether
    ``stream`` is a terminal.
    """

    def __init__(
        self,
        label: str,
        total: int,
        unit: str = "rows",
        *,
        stream: TextIO | None = None,
        tty: bool | None = None,
        clock: Callable[[], float] = time.monotonic,
        wall: Callable[[], float] = time.time,
    ) -> None:
        self.label, self.total, self.unit = label, max(int(total), 0), unit
        self.offset = 0
        self.stream = stream if stream is not None else sys.stderr
        self.tty = self.stream.isatty() if tty is None else tty
        self.clock, self.wall = clock, wall
        self.start = clock()
        self.work_start: float | None = None
        self._first: tuple[float, int] | None = None  # (clock, units) at the first update, shown or not
        self._last = -1e9
        self._tenth = 0
        self._shown = False

    def timed(self, seconds: float) -> None:
        """A unit just finished that took ``seconds`` where it ran (a suite run's wall time in its worker): the work
        started at the latest ``seconds`` ago (:attr:`work_start`, the earliest such start)."""
        began = self.clock() - max(float(seconds), 0.0)
        self.work_start = began if self.work_start is None else min(self.work_start, began)

    def expected_end(self, done: int) -> tuple[float, float] | None:
        """(seconds still to go, expected end as epoch seconds) after ``done`` units, None before the first: the
        straight line through the time elapsed since the work started (:meth:`timed`), else through the units
        done since the first update (when more are), else since the start."""
        if done <= 0:
            return None
        now = self.clock()
        if self.work_start is not None:
            rate = (now - max(self.work_start, self.start)) / done
        elif self._first is not None and done > self._first[1] and now > self._first[0]:
            rate = (now - self._first[0]) / (done - self._first[1])
        else:
            rate = (now - self.start) / done
        left = rate * max(self.total - done, 0)
        return left, self.wall() + left

    def line(self, done: int, note: str = "") -> str:
        """The progress text after ``done`` units (``note`` appended)."""
        pct = 100.0 * done / max(self.total, 1)
        count = f"{pct:3.0f}% ({done:,} of {self.total:,} {self.unit})"
        if self.tty:
            filled = min(BAR_WIDTH, int(BAR_WIDTH * done / max(self.total, 1)))
            count = f"[{'#' * filled}{'-' * (BAR_WIDTH - filled)}] {count}"
        end = ""
        if done >= self.total:
            end = f", done in {duration_text(self.clock() - self.start)}"
        elif (eta := self.expected_end(done)) is not None:
            left, at = eta
            end = f", expected end {time.strftime('%H:%M:%S', time.localtime(at))} (in {duration_text(left)})"
        return f"{self.label}: {count}{end}{f'  {note}' if note else ''}"

    def update(self, done: int, note: str = "") -> None:
        """Show the progress after ``done`` units (plus :attr:`offset`) when it is due."""
        done += self.offset
        now = self.clock()
        if self._first is None:
            self._first = (now, done)
        if now - self.start < QUIET_FOR_S and not self._shown:
            return
        tenth = int(10 * done / max(self.total, 1))
        if self.tty:
            if now - self._last < TTY_EVERY_S and done < self.total:
                return
            self.stream.write(f"\r\033[K{self.line(done, note)}")
        else:
            if tenth <= self._tenth and now - self._last < LOG_EVERY_S:
                return
            self.stream.write(self.line(done, note) + "\n")
        self._tenth = max(self._tenth, tenth)
        self._last = now
        self._shown = True
        self.stream.flush()

    def message(self, text: str) -> None:
        """Print ``text`` as its own line (a finished item's report), keeping the bar below it on a terminal."""
        if self.tty and self._shown:
            self.stream.write("\r\033[K")
            self._last = -1e9  # the bar is drawn again at the next update
        self.stream.write(text + "\n")
        self.stream.flush()

    def close(self) -> None:
        """End the bar's line on a terminal (nothing in a log)."""
        if self.tty and self._shown:
            self.stream.write("\n")
            self.stream.flush()
            self._shown = False
