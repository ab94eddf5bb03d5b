"""A real link's faults, sorted out sample by sample, and the real-time figures of a live session.

:class:`Link` takes the decoded samples in their order of arrival and gives back the samples to cue, in time order
on the source's grid:

- a sample whose time equals the last one's, or one already taken, is a **duplicate** (dropped, counted);
- a sample earlier than the last one by at most :func:`reset_threshold_s` arrived after a later one: **reordered**
  (dropped, counted: its place was already passed, and held if it was a gap);
- a sample earlier by more is the source **restarting** (a reset, or the simulator's "restart flight"): a new
  segment, as ``washbench cue`` splits a file where time jumps back;
- a time step longer than 1.5 steps is a gap of **lost** samples: each missing step is filled by holding the last
  sample (its values, at the missing time on the grid) and flagged (``live_held`` = 1 in the saved input);
- a jump forward by more than :data:`MAX_JUMP_S` is a malformed time (dropped, counted);
- a jump forward that the **arrival clock** does not show (the source's time advanced by more than
  :data:`JUMP_FACTOR` times the time between the two arrivals plus :data:`JUMP_SLACK_S`: a corrupt or foreign time
  stamp, a source restarted at a later time) is a **time jump**: a new segment, counted, never a gap to fill. So a
  gap is filled only with what real time allows: at most ``(JUMP_FACTOR * arrival interval + JUMP_SLACK_S) / dt``
  held samples (eleven datagrams, ten 2 us apart and one at t = 3000 s, made 1.5e9 of them before).

The source's step ``dt`` is given (``--rate-hz``) or measured: the median step of the first :data:`STARTUP_SAMPLES`
samples, which are held back until then; a step outside :data:`DT_RANGE_S` (a stream in the wrong byte order, a
corrupt clock) is :class:`UnusableStepError`: the session stops and saves what it received. Sources whose pilot
accelerations lag one frame (JSBSim) are shifted back here, per segment, as
:func:`washbench.io.readers.shift_jsbsim_lag` does for a JSBSim CSV file.

:class:`LatencyStats`: the time from a datagram's arrival (on Linux the kernel's time stamp of it, so the time it
waited in the receive queue counts; elsewhere when ``recvfrom`` returned) to its platform command's send,
kept in a fixed histogram of 1 us bins up to :data:`HIST_MAX_US` (memory does not grow with the session), and the
jitter of the arrivals against the source's own clock.
"""

from __future__ import annotations

import itertools
import math
from array import array
from collections import deque
from dataclasses import dataclass, field

import numpy as np

from washbench.live.packets import Sample

STARTUP_SAMPLES = 8
"""Samples held back at the start to measure the source's step (when ``--rate-hz`` is not given)."""
RESET_S = 0.5
"""A time jump back by more than this (or 10 steps, whichever is longer) is a restart, not a reordered packet."""
MAX_JUMP_S = 3600.0
"""A time jump forward by more than this is a corrupt time stamp, not a gap."""
GAP_STEPS = 1.5
"""A step longer than this many steps is a gap: the missing samples are held."""
JUMP_FACTOR = 4.0
"""The source's clock may run this many times faster than the arrival clock over a gap (``washbench send
--speed``, a burst after a stall) before a step forward is a time jump rather than a gap."""
JUMP_SLACK_S = 0.5
"""... plus this much (s): datagrams queued by the network or the receiving system arrive together."""
DT_RANGE_S = (1e-4, 10.0)
"""The source steps ``live`` accepts, s (10 kHz to 0.1 Hz; ``--rate-hz`` 0.1..10,000)."""


class UnusableStepError(Exception):
    """The source's step, measured from its first samples, is outside :data:`DT_RANGE_S` (``dt_s``: that step)."""

    def __init__(self, dt_s: float | None) -> None:
        super().__init__(dt_s)
        self.dt_s = dt_s


def reset_threshold_s(dt_s: float | None) -> float:
    """How far back time must jump to be a restart rather than a reordered packet [s]."""
    return max(RESET_S, 10.0 * dt_s) if dt_s else RESET_S


@dataclass
class LinkCounts:
    """What the link did, counted."""

    received: int = 0  # samples decoded (every datagram that carried one)
    duplicate: int = 0
    reordered: int = 0
    lost: int = 0  # missing steps, filled by holding
    time_jumps: int = 0  # jumps forward beyond MAX_JUMP_S (dropped), or beyond what the arrival clock allows
    restarts: int = 0
    unshifted: int = 0  # last sample of a segment dropped by the lag shift (no next frame)


@dataclass(frozen=True)
class Out:
    """One sample to cue: ``held`` it fills a gap; ``new_segment`` it starts a segment (the first, or a restart)."""

    sample: Sample
    held: bool
    new_segment: bool


class Link:
    """Arrival order in, time order on the grid out (see the module notes)."""

    def __init__(self, dt_s: float | None = None, lag_shift: bool = False) -> None:
        self.dt_s = dt_s
        self.lag_shift = lag_shift
        self.counts = LinkCounts()
        self._last_t: float | None = None
        self._recent: deque[float] = deque(maxlen=256)
        self._seen: set[float] = set()
        self._lagged: Sample | None = None  # the lag shift's previous frame
        self._lag_new = False
        self._pending: list[tuple[Sample, bool]] = []
        self._prev: Sample | None = None  # the last sample given out in this segment
        self._last_arrival: float | None = None  # arrival clock of the last sample taken, s

    def push(self, s: Sample, arrival_s: float | None = None) -> list[Out]:
        """The samples to cue now that ``s`` arrived (none, or held ones and ``s``); ``arrival_s``: when it arrived
        (a monotonic clock, s; None: not known, the source's clock alone is trusted)."""
        c = self.counts
        c.received += 1
        t = s[0]
        new_segment = False
        last = self._last_t
        if last is None:
            new_segment = True
        elif t > last:
            if t - last > MAX_JUMP_S:
                c.time_jumps += 1
                return []
            real = None if arrival_s is None or self._last_arrival is None else arrival_s - self._last_arrival
            if real is not None and t - last > JUMP_FACTOR * real + JUMP_SLACK_S:
                c.time_jumps += 1  # the source's time jumped, real time did not pass: a new segment, not a gap
                new_segment = True
                self._recent.clear()
                self._seen.clear()
        elif last - t > reset_threshold_s(self.dt_s):
            c.restarts += 1
            new_segment = True
            self._recent.clear()
            self._seen.clear()
        elif t == last or t in self._seen:
            c.duplicate += 1
            return []
        else:
            c.reordered += 1
            return []
        self._last_t = t
        self._last_arrival = arrival_s
        if len(self._recent) == self._recent.maxlen:
            self._seen.discard(self._recent[0])
        self._recent.append(t)
        self._seen.add(t)
        if self.lag_shift:
            prev, prev_new = self._lagged, self._lag_new
            self._lagged, self._lag_new = s, new_segment
            if prev is None or new_segment:
                if prev is not None:
                    c.unshifted += 1
                return []
            s, new_segment = (prev[0], s[1], s[2], s[3], prev[4], prev[5], prev[6]), prev_new
        return self._timed(s, new_segment)

    def flush(self) -> list[Out]:
        """At the end: the samples still held back (all of them, if the step was never measured)."""
        if self.dt_s is None and self._pending:
            measured = _median_step(self._pending)
            if measured is None:
                return []  # no step to measure: nothing can be cued (the samples are in ``pending``)
            self.dt_s = _checked(measured)
        return self._drain()

    @property
    def pending(self) -> list[Sample]:
        """The samples held back until the step is known (still there after :class:`UnusableStepError`)."""
        return [s for s, _ in self._pending]

    def _timed(self, s: Sample, new_segment: bool) -> list[Out]:
        if self.dt_s is None:
            self._pending.append((s, new_segment))
            if len(self._pending) < STARTUP_SAMPLES:
                return []
            self.dt_s = _checked(_median_step(self._pending))
            return self._drain()
        return self._gap_filled(s, new_segment)

    def _drain(self) -> list[Out]:
        out: list[Out] = []
        pending, self._pending = self._pending, []
        for s, new in pending:
            out += self._gap_filled(s, new)
        return out

    def _gap_filled(self, s: Sample, new_segment: bool) -> list[Out]:
        out: list[Out] = []
        prev = None if new_segment else self._prev
        dt = self.dt_s
        if prev is not None and dt:
            step = s[0] - prev[0]
            if step > GAP_STEPS * dt:
                missing = round(step / dt) - 1
                self.counts.lost += missing
                t0 = prev[0]
                for j in range(1, missing + 1):
                    out.append(Out((t0 + j * dt, *prev[1:]), True, False))  # type: ignore[arg-type]
        out.append(Out(s, False, new_segment))
        self._prev = s
        return out


def _checked(dt_s: float | None) -> float | None:
    """``dt_s`` if it is within :data:`DT_RANGE_S` (or None), else :class:`UnusableStepError`."""
    if dt_s is not None and not DT_RANGE_S[0] <= dt_s <= DT_RANGE_S[1]:
        raise UnusableStepError(dt_s)
    return dt_s


def _median_step(pending: list[tuple[Sample, bool]]) -> float | None:
    """The median positive step between consecutive samples of one segment, or None if there is none."""
    steps = [b[0][0] - a[0][0] for a, b in itertools.pairwise(pending) if not b[1] and b[0][0] > a[0][0]]
    return float(np.median(steps)) if steps else None


HIST_MAX_US = 200_000
"""Latencies are binned by the microsecond up to this (200 ms); longer ones are counted and their maximum kept."""


@dataclass
class LatencyStats:
    """Arrival-to-command latency (a fixed histogram) and arrival jitter, for a live session."""

    hist: array = field(default_factory=lambda: array("q", bytes(8 * HIST_MAX_US)))  # fast to count into
    n: int = 0
    over: int = 0
    max_ns: int = 0
    late: int = 0  # commands sent more than one source step after their datagram arrived
    jitter_sum_s: float = 0.0
    jitter_n: int = 0
    jitter_max_s: float = 0.0
    _arrival: float | None = None
    _interval: float | None = None

    def add(self, latency_ns: int, dt_s: float | None) -> None:
        """One command sent ``latency_ns`` after its datagram arrived."""
        self.n += 1
        us = latency_ns // 1000
        if us < HIST_MAX_US:
            self.hist[us] += 1
        else:
            self.over += 1
        self.max_ns = max(self.max_ns, latency_ns)
        if dt_s and latency_ns > dt_s * 1e9:
            self.late += 1

    def arrival(self, arrival_s: float, new_segment: bool) -> None:
        """A sample's arrival time (local clock, s): jitter is the change between consecutive arrival intervals,
        |(a_k - a_k-1) - (a_k-1 - a_k-2)| (the inter-packet delay variation of RFC 5481), whatever the rate."""
        if new_segment:
            self._arrival = self._interval = None
        elif self._arrival is not None:
            interval = arrival_s - self._arrival
            if self._interval is not None:
                j = abs(interval - self._interval)
                self.jitter_sum_s += j
                self.jitter_n += 1
                self.jitter_max_s = max(self.jitter_max_s, j)
            self._interval = interval
        self._arrival = arrival_s

    def percentile_ms(self, q: float) -> float | None:
        """The ``q``-th percentile (0..100) of the latency [ms], to the microsecond; None with no commands."""
        if self.n == 0:
            return None
        rank = max(1, math.ceil(q / 100.0 * self.n))
        cum = np.cumsum(np.frombuffer(self.hist, dtype=np.int64))
        i = int(np.searchsorted(cum, rank))
        if i >= HIST_MAX_US:
            return self.max_ns / 1e6
        return (i + 0.5) / 1000.0

    def summary(self) -> dict[str, float | int | None]:
        return {
            "commands": self.n,
            "latency_median_ms": self.percentile_ms(50.0),
            "latency_p99_ms": self.percentile_ms(99.0),
            "latency_max_ms": self.max_ns / 1e6 if self.n else None,
            "late": self.late,
            "jitter_mean_ms": 1e3 * self.jitter_sum_s / self.jitter_n if self.jitter_n else None,
            "jitter_max_ms": 1e3 * self.jitter_max_s if self.jitter_n else None,
        }
