"""What an expensive computation will cost, estimated before it starts, and the one check of it.

Every computation whose memory or time grows with the input's length or with its parameters asks here first:

- the bound (:mod:`washbench.analysis.bound_replay`: its replay's two convex programmes over the whole recording and
  its search's linear programmes, :mod:`washbench.analysis.best_motion`) and the ceiling
  (:mod:`washbench.analysis.ceiling`: six linear programmes over it), whose memory grows with the samples;
- the MPC washouts (:mod:`washbench.cueing.mpc`, :mod:`washbench.cueing.mpc_unrestricted`), whose dense QP grows with
  the square of the horizon (``horizon_steps``, or what ``preview_s`` over ``prediction_step_s`` makes of it) and whose
  building grows with its cube;
- ``omct`` of a washout that costs that much per run (the sum of its runs).

Each model (:func:`bound`, :func:`ceiling`, :func:`mpc` with :func:`mpc_step_s`; ``omct`` and ``tune`` add up
theirs) gives an :class:`Estimate`: the peak memory the computation adds to what the process holds when it starts,
and its CPU time, from the input's length and the parameters alone. The constants are measured
(``bench/cost_calibration.py``, its figures in ``bench/cost_calibration.md``): each memory model is the largest peak
measured per unit of size, times :data:`MEMORY_MARGIN`; each time model the measured CPU time, so it is an estimate,
not a promise (on a shared machine the wall time is longer).

:func:`check` then refuses, in one line, what would not fit (:func:`memory_room`: the least of washbench's cap,
:data:`DEFAULT_CAP_GB` of resident memory for the whole process unless ``WASHBENCH_MAX_MEMORY_GB`` says otherwise,
what the machine has available, a control group's limit and the process's address-space limit), with the figure,
what sets the limit, and the option that changes the size; and announces on stderr what will take longer than
:data:`LONG_S`. The cap is per process: each worker of ``suite --jobs N`` has its own.
"""

from __future__ import annotations

import contextlib
import math
import os
import sys
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

from washbench.errors import WashbenchError, printable
from washbench.io.progress import duration_text

try:
    import resource  # (POSIX: the limits of ulimit; on Windows only the cap and the machine count)
except ImportError:  # pragma: no cover - Windows
    resource = None  # type: ignore[assignment]

CAP_ENV = "WASHBENCH_MAX_MEMORY_GB"
"""The environment variable that sets washbench's memory cap (GB of resident memory per process)."""
DEFAULT_CAP_GB = 4.0
"""washbench's memory cap without ``WASHBENCH_MAX_MEMORY_GB``: the resident memory (GB, 10^9 bytes) one washbench
process may reach, whatever the machine has."""
MAX_CAP_GB = 1e6
LONG_S = 30.0
"""A computation estimated to take longer than this (s) is announced on stderr before it starts."""
MEMORY_MARGIN = 1.15
"""Every memory model is the largest peak measured per unit of size, times this (the peaks vary by a few per cent
with the allocator's state; ``bench/cost_calibration.md``)."""
GB = 1e9


# ---------------------------------------------------------------------------------------------- the machine


def _status() -> dict[str, int]:
    """``/proc/self/status``'s ``Vm*`` fields in bytes (empty where there is no /proc)."""
    out: dict[str, int] = {}
    try:
        text = Path("/proc/self/status").read_text()
    except OSError:
        return out
    for line in text.splitlines():
        key, _, rest = line.partition(":")
        parts = rest.split()
        if key.startswith("Vm") and len(parts) == 2 and parts[1] == "kB" and parts[0].isdigit():
            out[key] = int(parts[0]) * 1024
    return out


def resident_bytes() -> int:
    """The resident memory of this process now (bytes): ``VmRSS``; without /proc its peak so far
    (``ru_maxrss``, an over-estimate)."""
    rss = _status().get("VmRSS")
    if rss is not None or resource is None:
        return rss or 0
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return int(peak if sys.platform == "darwin" else peak * 1024)


def available_bytes() -> int | None:
    """What the machine can give without swapping (``MemAvailable`` of /proc/meminfo, bytes), or None."""
    try:
        text = Path("/proc/meminfo").read_text()
    except OSError:
        return None
    for line in text.splitlines():
        if line.startswith("MemAvailable:"):
            parts = line.split()
            return int(parts[1]) * 1024 if len(parts) >= 2 and parts[1].isdigit() else None
    return None


def _cgroup_room() -> tuple[int, int] | None:
    """(limit, room) of this process's control group (cgroup v2 ``memory.max`` less ``memory.current``), or None."""
    try:
        lines = Path("/proc/self/cgroup").read_text().splitlines()
    except OSError:
        return None
    for line in lines:
        if line.startswith("0::"):
            folder = Path("/sys/fs/cgroup") / line[3:].lstrip("/")
            try:
                limit = (folder / "memory.max").read_text().strip()
                current = int((folder / "memory.current").read_text().strip())
            except (OSError, ValueError):
                return None
            if not limit.isdigit():
                return None  # "max": no limit
            return int(limit), int(limit) - current
    return None


def cap_bytes() -> float:
    """washbench's memory cap (bytes): ``WASHBENCH_MAX_MEMORY_GB`` if set, else :data:`DEFAULT_CAP_GB`;
    WashbenchError (one line) for a value that is not a positive number of GB."""
    text = os.environ.get(CAP_ENV, "").strip()
    if not text:
        return DEFAULT_CAP_GB * GB
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and 0.0 < value <= MAX_CAP_GB):
        raise WashbenchError(f"{CAP_ENV}={printable(text)}: expected a number of gigabytes, more than 0 and at most "
                             f"{MAX_CAP_GB:g}")  # fmt: skip
    return value * GB


@dataclass(frozen=True)
class Room:
    """What this process may still allocate (bytes) and what sets that (a phrase for the message)."""

    bytes: float
    why: str


def memory_room() -> Room:
    """The least of: washbench's cap (:func:`cap_bytes`) less the resident memory now; what the machine has
    available; the room under this process's control group's limit; the room under its address-space limit
    (``ulimit -v``) and its data limit."""
    cap = cap_bytes()
    rss = resident_bytes()
    if os.environ.get(CAP_ENV, "").strip():
        rooms = [Room(cap - rss, f"the cap {CAP_ENV}={cap / GB:g} sets ({gb_text(cap)} per process)")]
    else:
        rooms = [Room(cap - rss, f"washbench's cap of {gb_text(cap)} per process ({CAP_ENV} changes it)")]
    avail = available_bytes()
    if avail is not None:
        rooms.append(Room(avail, f"what this machine has available ({gb_text(avail)})"))
    group = _cgroup_room()
    if group is not None:
        rooms.append(Room(group[1], f"this process's control group's memory limit ({gb_text(group[0])})"))
    status = _status()
    limits = () if resource is None else (
        (resource.RLIMIT_AS, status.get("VmSize"), "address-space limit, ulimit -v"),
        (resource.RLIMIT_DATA, status.get("VmData"), "data-size limit, ulimit -d"))  # fmt: skip
    for which, used, name in limits:
        soft = resource.getrlimit(which)[0]
        if soft != resource.RLIM_INFINITY and used is not None:
            rooms.append(Room(soft - used, f"this process's {name} ({gb_text(soft)})"))
    return min(rooms, key=lambda r: r.bytes)


def gb_text(n: float) -> str:
    """Bytes as ``3.2 GB``, ``1010 GB`` or ``450 MB`` (10^9, 10^6; never an exponent)."""
    if abs(n) >= 999.5 * GB:
        return f"{n / GB:.0f} GB"
    if abs(n) >= 0.995 * GB:
        return f"{n / GB:.3g} GB"
    return f"{max(n, 0.0) / 1e6:.3g} MB"


# ---------------------------------------------------------------------------------------------- estimates


@dataclass(frozen=True)
class Estimate:
    """What a computation will cost: ``memory_bytes`` at its peak above what the process holds when it starts (its
    largest part: ``peak``), ``seconds`` of CPU; ``what`` (``washout bound``), ``size`` (``216,000 samples``),
    ``remedy`` (what makes it smaller: the options), ``fits`` (given the room in bytes, a phrase saying how large an
    input would fit, or None)."""

    what: str
    size: str
    memory_bytes: float
    seconds: float
    peak: str
    remedy: str
    fits: Callable[[float], str | None] | None = None

    def text(self) -> str:
        """``about 2 min 30 s and 3.1 GB at the peak (its translation plan)``."""
        return f"about {duration_text(self.seconds)} and {gb_text(self.memory_bytes)} at the peak ({self.peak})"


def refusal(est: Estimate, room: Room) -> str | None:
    """The one line refusing ``est`` in ``room``, or None when it fits."""
    if est.memory_bytes <= room.bytes:
        return None
    hint = est.fits(room.bytes) if est.fits is not None else None
    return (f"{est.what}: {est.size}: about {gb_text(est.memory_bytes)} at the peak ({est.peak}), more than the "
            f"{gb_text(room.bytes)} this process may still take under {room.why}; {est.remedy}"
            + (f" ({hint})" if hint else ""))  # fmt: skip


_ANNOUNCED = [0]


@contextlib.contextmanager
def announced() -> Iterator[None]:
    """Inside, :func:`check` and the MPC's notes say nothing (they still refuse): the caller has announced the whole
    (``omct``: all its runs at once, not each run)."""
    _ANNOUNCED[0] += 1
    try:
        yield
    finally:
        _ANNOUNCED[0] -= 1


def check(est: Estimate, announce: bool = True) -> None:
    """Refuse ``est`` (WashbenchError, one line) when it does not fit :func:`memory_room`; else, with ``announce``,
    say on stderr what it will cost when that is more than :data:`LONG_S`."""
    why = refusal(est, memory_room())
    if why is not None:
        raise WashbenchError(why)
    if announce and est.seconds > LONG_S:
        note(f"{est.what}: {est.size}: {est.text()} (estimated)")


def note(text: str) -> None:
    """One ``washbench: note:`` line on stderr (none inside :func:`announced`)."""
    if not _ANNOUNCED[0]:
        print(f"washbench: note: {text}", file=sys.stderr, flush=True)


def _samples(n: int, dt_s: float | None) -> str:
    length = f" ({duration_text(n * dt_s)} at {1.0 / dt_s:.4g} Hz)" if dt_s else ""
    return f"{n:,} samples{length}"


def _linear_fit(a: float, b: float) -> Callable[[float], str | None]:
    """For a model ``a + b n`` bytes: how many samples fit in a room (a phrase)."""

    def fits(room: float) -> str | None:
        n = math.floor((room - a) / b)
        return f"{n:,} samples would fit" if n >= 2 else None

    return fits


# --- the bound (bench/cost_calibration.md): peak bytes a + b n and CPU seconds c n of each part, n the samples
BOUND_ATTITUDE = (45e6, 14_700.0, 0.23e-3)
"""The replay's attitude plan (:func:`washbench.analysis.bound.oracle_bound`, pitch, roll, yaw): bytes a, bytes per
sample b, seconds per sample c."""
BOUND_TRANSLATION = (110e6, 30_500.0, 0.45e-3)
"""The replay's translation plan (:func:`washbench.analysis.bound_replay.translation_plan`): the bound's peak."""
CEILING_LP = (5e6, 14_000.0, 0.20e-3)
"""The ceiling (:func:`washbench.analysis.ceiling.ceiling`): its largest linear programme (b), all six (c)."""
BOUND_SEARCH = (20e6, 100_000.0, 1.8e-3)
"""One programme of the best achieved's search (:mod:`washbench.analysis.best_motion`: PIQP's KKT system and its
factor over about 48 variables and 54 rows a sample): bytes a, bytes per sample b (the peak, the same for every
programme), seconds per sample c (for each programme). Measured on the Columbia 400 aerobatics
(``bench/best_bench.py --calibrate``): +106, +312 and +694 MB on 2,000, 4,000 and 8,000 samples (a slope of 103 kB
a sample), 1.06, 1.49 and 1.61 ms a sample (14 to 24 PIQP iterations); on the multi-axis signal
(``bench/cost_calibration.py --only search``): +232, +460 and +904 MB on 2,400, 4,800 and 9,600 samples (0.78 to
0.80 of this model with its margin), 1.66, 1.88 and 1.91 ms a sample; on the two-core development machine under
load (bench/cost_calibration.md)."""
SEARCH_STEPS = 3
"""The search's programmes when the caller does not say (``BoundParams.search_steps``'s default)."""
BOUND_REMEDY = "cut the recording or lower its rate (cue: --start-s, --end-s, --resample HZ)"
SEARCH_REMEDY = ("cut the recording or lower its rate (cue: --start-s, --end-s, --resample HZ), or set the parameter "
                 "file's bound: search_steps: 0 (the best of the motions known, no search)")


def _part(model: tuple[float, float, float], n: int) -> tuple[float, float]:
    a, b, c = model
    return MEMORY_MARGIN * (a + b * n), c * n


def ceiling(n: int, dt_s: float | None = None) -> Estimate:
    """The ceiling of a recording of ``n`` samples (``dt_s`` apart, for the message)."""
    mem, sec = _part(CEILING_LP, n)
    a, b, _ = CEILING_LP
    return Estimate("the ceiling", _samples(n, dt_s), mem, sec, "its largest linear programme", BOUND_REMEDY,
                    _linear_fit(MEMORY_MARGIN * a, MEMORY_MARGIN * b))  # fmt: skip


def bound(n: int, dt_s: float | None = None, with_ceiling: bool = True, search_steps: int = SEARCH_STEPS) -> Estimate:
    """The bound (the best achieved) on ``n`` samples: its replay's two plans, its search's ``search_steps``
    programmes (one at a time: their peak is one's, their time all of theirs) and (``with_ceiling``) the ceiling
    computed after it: the peak of the largest part, the time of all."""
    parts = [("its attitude plan", BOUND_ATTITUDE), ("its translation plan", BOUND_TRANSLATION)]
    if search_steps > 0:
        a, b, c = BOUND_SEARCH
        parts.append(("its search's programmes", (a, b, c * search_steps)))
    if with_ceiling:
        parts.append(("the ceiling's largest programme", CEILING_LP))
    costs = [(_part(model, n), name, model) for name, model in parts]
    (mem, _), name, model = max(costs, key=lambda c: c[0][0])
    seconds = sum(c[0][1] for c in costs)
    a, b, _ = model
    remedy = SEARCH_REMEDY if name == "its search's programmes" else BOUND_REMEDY
    return Estimate("washout bound", _samples(n, dt_s), mem, seconds, name, remedy,
                    _linear_fit(MEMORY_MARGIN * a, MEMORY_MARGIN * b))  # fmt: skip


# --- the MPC washouts (bench/cost_calibration.md): N the horizon's intervals. Memory a + b N^2 bytes (the dense
# condensed QP: N^2 by its construction); times as measured, (N, CPU seconds), interpolated in log-log (the cost per
# sample leaps where the QP's matrices leave the processor's caches: no single power fits)
MPC_MEMORY = (32e6, 7_400.0)
"""mpc on the Atlas, a rig or a plugin's platform."""
MPC_HEXAPOD_MEMORY = (42e6, 11_200.0)
"""mpc on a hexapod (the whitened QP and the legs' rows besides)."""
MPC_UNRESTRICTED_MEMORY = (40e6, 400.0)
"""mpc-unrestricted (its moves are blocked: a QP of a few dozen variables and the felt error's slacks, which grow with
N; N x N prediction matrices)."""
MPC_BUILD_S = ((20, 0.025), (50, 0.68), (100, 1.79), (200, 14.3), (300, 59.5), (500, 305.0))
MPC_HEXAPOD_BUILD_S = ((50, 1.11), (100, 3.45), (200, 19.1), (300, 44.7), (500, 174.0))
MPC_UNRESTRICTED_BUILD_S = ((50, 0.12), (100, 0.22), (200, 0.49))
"""Seconds to build the QP and set its solver up (mpc: the condensed Hessian's accumulation, then DAQP's
factorisation at the first solve; on a hexapod the whitening, its first solve cheap)."""
MPC_STEP_S = ((20, 0.00019), (50, 0.00047), (100, 0.0070), (200, 0.030), (300, 0.049), (500, 0.121))
MPC_HEXAPOD_STEP_S = ((50, 0.00206), (100, 0.0327), (200, 0.0861), (300, 0.146), (500, 0.418))
MPC_UNRESTRICTED_STEP_S = ((50, 0.0011), (100, 0.0011), (200, 0.0023))
"""Seconds per sample: this sample's QP data and a warm-started solve of a few iterations (a hard flight needs
more; the washout times its first samples and says so, :mod:`washbench.cueing.mpc`)."""


def _curve(points: tuple[tuple[float, float], ...], x: float) -> float:
    """``points`` (x, y), x increasing, interpolated in log-log at ``x`` (beyond the ends: the end segment's
    slope)."""
    lx = math.log(max(x, 1e-300))
    xs = [math.log(p[0]) for p in points]
    ys = [math.log(p[1]) for p in points]
    i = 1
    while i < len(xs) - 1 and lx > xs[i]:
        i += 1
    slope = (ys[i] - ys[i - 1]) / (xs[i] - xs[i - 1])
    return math.exp(ys[i - 1] + slope * (lx - xs[i - 1]))


def _mpc_tables(kind: str, hexapod: bool) -> tuple[tuple[float, float], tuple, tuple]:
    if kind != "mpc":
        return MPC_UNRESTRICTED_MEMORY, MPC_UNRESTRICTED_BUILD_S, MPC_UNRESTRICTED_STEP_S
    if hexapod:
        return MPC_HEXAPOD_MEMORY, MPC_HEXAPOD_BUILD_S, MPC_HEXAPOD_STEP_S
    return MPC_MEMORY, MPC_BUILD_S, MPC_STEP_S


def mpc(kind: str, horizon: int, dt_s: float, hexapod: bool = False, remedy: str = "") -> Estimate:
    """An MPC washout of ``kind`` (``mpc`` or ``mpc-unrestricted``) with a horizon of ``horizon`` intervals
    (``hexapod``: planned against a hexapod's legs): the memory of its QP, and in ``seconds`` the time to build it;
    the time per sample is :func:`mpc_step_s`. ``dt_s``: the sample step (for the messages)."""
    (a, b), build, _ = _mpc_tables(kind, hexapod)
    return Estimate(f"washout {kind}", f"a horizon of {horizon:,} intervals", MEMORY_MARGIN * (a + b * horizon**2),
                    _curve(build, horizon), "its QP", remedy)  # fmt: skip


def mpc_step_s(kind: str, horizon: int, hexapod: bool = False) -> float:
    """Seconds per sample of an MPC washout with a horizon of ``horizon`` intervals (typical: a warm-started solve)."""
    return _curve(_mpc_tables(kind, hexapod)[2], horizon)


def horizon_intervals(horizon_steps: int, preview_s: float, prediction_step_s: float) -> int:
    """The intervals an MPC washout predicts over: ``horizon_steps``, extended to cover ``preview_s`` (the
    intervals of ``prediction_step_s`` that reach it; at most 10^18, whatever the ratio)."""
    return max(int(horizon_steps), math.ceil(min(preview_s / prediction_step_s, 1e18) - 1e-9))


def announce_mpc(est: Estimate, kind: str, horizon: int, dt_s: float, samples: int | None, slow: float,
                 hexapod: bool = False) -> None:  # fmt: skip
    """An MPC washout's notes before its work, when it is long: with ``samples`` None (when it is made), building its
    QP (``est``, :func:`mpc`) and a minute of flight, if the building takes more than :data:`LONG_S` or a sample more
    than ``slow`` times ``dt_s``; with ``samples`` (a whole recording), their time if more than :data:`LONG_S`."""
    per = mpc_step_s(kind, horizon, hexapod)
    if samples is None:
        if est.seconds > LONG_S or per > slow * dt_s:
            minute = per * 60.0 / dt_s
            note(f"washout {kind}: {est.size}: its QP takes about {duration_text(est.seconds)} and "
                 f"{gb_text(est.memory_bytes)} to build, then about {per:.2g} s per sample (a minute of flight at "
                 f"{1.0 / dt_s:.4g} Hz: about {duration_text(minute)}) (estimated; {est.remedy} make it faster)")
    elif samples * per > LONG_S:
        note(f"washout {kind}: {samples:,} samples: about {duration_text(samples * per)} (estimated)")


__all__ = [
    "CAP_ENV",
    "DEFAULT_CAP_GB",
    "LONG_S",
    "Estimate",
    "Room",
    "announce_mpc",
    "announced",
    "available_bytes",
    "bound",
    "cap_bytes",
    "ceiling",
    "check",
    "gb_text",
    "horizon_intervals",
    "memory_room",
    "mpc",
    "mpc_step_s",
    "note",
    "refusal",
    "resident_bytes",
]
