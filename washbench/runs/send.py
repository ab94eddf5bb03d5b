"""``washbench send``: a flight simulator's UDP output from a recorded file or a JSBSim flight, at real time.

``washbench send FILE --to HOST:PORT --format FORMAT [--speed N]`` sends any ``washbench cue`` input (read and
converted as ``washbench cue`` reads it) as that simulator would (:mod:`washbench.live.packets`), each sample when
its time comes (``--speed N``: N times faster); a file whose time jumps back is sent as it is (the receiver sees a
simulator restart). ``washbench send --fly MANOEUVRE --to ...`` flies a bundled or user manoeuvre with JSBSim and
the scripted pilot, each step paced to real time, and sends it as it flies.

``--format xplane-rref`` plays X-Plane's side of RREF: it listens on ``--listen HOST:PORT`` (X-Plane's 49000 by
default) for subscriptions and sends the subscribed datarefs (:data:`RREF_DATAREFS`) to whoever subscribed, one
datagram per sample (X-Plane sends at the requested frequency; washbench send at the file's rate), and stops when
every subscription is cancelled.
"""

from __future__ import annotations

import socket
import sys
import time
from collections.abc import Callable, Iterator
from pathlib import Path

import numpy as np

from washbench.errors import WashbenchError
from washbench.flight.fly import fly
from washbench.flight.manoeuvre import load_manoeuvre
from washbench.io.paths import resolve_manoeuvre
from washbench.io.readers import read_samples
from washbench.live.endpoints import bind_udp
from washbench.live.packets import (
    ENCODERS,
    FORMATS,
    RREF_DATAREFS,
    Sample,
    encode_jsbsim_labels,
    encode_rref,
    parse_rref_request,
    rref_values,
)

SPIN_S = 0.0015
"""The last this-many seconds before a sample is due are waited by spinning (sleep is coarser)."""
RREF_WAIT_S = 60.0
"""How long ``--format xplane-rref`` waits for a first subscription."""
SPEED_RANGE = (1e-3, 1e6)
"""``--speed``: from a thousandth of real time to a million times faster."""


class Pacer:
    """Waits until each sample's due time: the start plus the source time elapsed, divided by ``speed``."""

    def __init__(self, speed: float) -> None:
        self.speed = speed
        self.start = time.perf_counter()
        self.elapsed = 0.0
        self.last_t: float | None = None
        self.step = 0.0

    def wait(self, t: float) -> None:
        if self.last_t is not None:
            d = t - self.last_t
            if d > 0.0:
                self.step = d
            self.elapsed += d if d > 0.0 else self.step  # a jump back (a restart) takes one step
        self.last_t = t
        due = self.start + self.elapsed / self.speed
        while True:
            left = due - time.perf_counter()
            if left <= 0.0:
                return
            if left > SPIN_S:
                time.sleep(left - SPIN_S)


def file_samples(path: Path) -> Iterator[Sample]:
    """The samples of a ``washbench cue`` input, in washbench units and axes, as the file orders them (the file is
    read and checked now; the rows are made tuples a block at a time)."""
    s = read_samples(path)
    table = np.column_stack([s.t_s, s.f_mps2, s.omega_degps])

    def rows() -> Iterator[Sample]:
        for a in range(0, table.shape[0], 4096):
            for r in table[a : a + 4096].tolist():
                yield tuple(r)  # type: ignore[misc]

    return rows()


class Sender:
    """One datagram per sample to ``to`` (or, for RREF, to the subscribers); refused sends are counted."""

    def __init__(self, fmt: str, to: tuple[str, int] | None, listen: tuple[str, int] | None) -> None:
        if fmt not in FORMATS:
            raise WashbenchError(f"--format: expected one of {', '.join(FORMATS)}, got {fmt!r}")
        self.fmt = fmt
        self.sent = 0
        self.errors = 0
        self.seq = 0
        self.subscribers: dict[tuple[str, int], dict[int, int]] = {}  # address -> {id: dataref index}
        self.had_subscriber = False
        if fmt == "xplane-rref":
            self.sock = bind_udp(listen or ("127.0.0.1", 49000), "--listen")
            self.sock.setblocking(False)
            self.to = None
        else:
            if to is None:
                raise WashbenchError("--to HOST:PORT is required")
            self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
            self.sock.connect(to)
            self.to = to
        self.encode: Callable[[int, Sample], bytes] | None = ENCODERS.get(fmt)
        # JSBSim's pilot accelerations lag one frame, and the receiver (washbench live, as washbench cue of a JSBSim
        # CSV file) shifts them back: the samples sent (already in step) get that lag again, so they arrive as sent
        self._lagged: Sample | None = None
        self._step = 0.0
        if fmt == "jsbsim":
            self._send(encode_jsbsim_labels())

    def _send(self, data: bytes, address: tuple[str, int] | None = None) -> None:
        try:
            if address is None:
                self.sock.send(data)
            else:
                self.sock.sendto(data, address)
            self.sent += 1
        except OSError:
            self.errors += 1

    def _subscriptions(self) -> None:
        """Take the RREF requests waiting on the socket."""
        paths = [p for p, _ in RREF_DATAREFS]
        while True:
            try:
                data, addr = self.sock.recvfrom(2048)
            except (BlockingIOError, InterruptedError):
                return
            except OSError:
                continue
            req = parse_rref_request(data)
            if req is None:
                continue
            freq, rid, path = req
            subs = self.subscribers.setdefault(addr, {})
            if freq <= 0:
                subs.pop(rid, None)
                if not subs:
                    del self.subscribers[addr]
            elif path in paths:
                subs[rid] = paths.index(path)
                self.had_subscriber = True

    def wait_for_subscriber(self, timeout_s: float) -> None:
        end = time.monotonic() + timeout_s
        while not self.subscribers:
            self._subscriptions()
            if time.monotonic() > end:
                raise WashbenchError(f"--format xplane-rref: no RREF subscription within {timeout_s:g} s")
            time.sleep(0.005)
        time.sleep(0.05)  # the rest of the subscription burst
        self._subscriptions()

    def _jsbsim_frame(self, s: Sample) -> Sample:
        """The frame JSBSim would send for sample ``s``: its pilot accelerations those of the frame before (the first
        of a segment: its own); a jump back in time (a restart) first closes the segment (:meth:`close_segment`)."""
        prev = self._lagged
        if prev is not None and s[0] < prev[0]:
            self.close_segment()
            prev = None
        if prev is not None:
            self._step = s[0] - prev[0]
        self._lagged = s
        if prev is None:
            return s
        return (s[0], prev[1], prev[2], prev[3], s[4], s[5], s[6])

    def close_segment(self) -> None:
        """JSBSim format: one more frame after a segment's last sample, carrying its accelerations (the receiver's
        lag shift takes them from there; the frame itself is dropped as JSBSim's last one is)."""
        last, self._lagged = self._lagged, None
        if self.fmt != "jsbsim" or last is None or self.encode is None:
            return
        t = last[0] + (self._step or 1e-3)
        self._send(self.encode(self.seq, (t, last[1], last[2], last[3], last[4], last[5], last[6])))
        self.seq += 1

    def send(self, s: Sample) -> bool:
        """Send sample ``s``; False when nobody is subscribed any more (RREF)."""
        if self.encode is not None:
            self._send(self.encode(self.seq, self._jsbsim_frame(s) if self.fmt == "jsbsim" else s))
        else:
            self._subscriptions()
            if not self.subscribers:
                return False
            values = rref_values(s)
            for addr, subs in self.subscribers.items():
                self._send(encode_rref([(rid, values[j]) for rid, j in subs.items()]), addr)
        self.seq += 1
        return True

    def close(self) -> None:
        self.sock.close()


def run_send(
    fmt: str,
    to: tuple[str, int] | None,
    path: Path | None = None,
    fly_path: Path | None = None,
    speed: float = 1.0,
    listen: tuple[str, int] | None = None,
    aircraft_dirs: tuple[Path, ...] = (),
) -> int:
    """The ``washbench send`` command."""
    lo, hi = SPEED_RANGE
    if not lo <= speed <= hi:  # NaN too
        raise WashbenchError(f"--speed: expected {lo:g}..{hi:g} (times real time), got {speed:g}")
    if (path is None) == (fly_path is None):
        raise WashbenchError("give either a FILE or --fly MANOEUVRE")
    samples: Iterator[Sample] | None = None
    if path is not None:
        samples = file_samples(path)
    sender = Sender(fmt, to, listen)
    where = f"udp://{to[0]}:{to[1]}" if to else "the RREF subscribers"
    try:
        if fmt == "xplane-rref":
            print(f"send: waiting for RREF subscriptions on udp://{(listen or ('127.0.0.1', 49000))[0]}:"
                  f"{(listen or ('127.0.0.1', 49000))[1]}", flush=True)  # fmt: skip
            sender.wait_for_subscriber(RREF_WAIT_S)
        print(f"send: {fmt} packets to {where} at {speed:g} x real time", flush=True)
        pacer = Pacer(speed)
        if samples is not None:
            for s in samples:
                pacer.wait(s[0])
                if not sender.send(s):
                    break
        else:
            _fly_and_send(fly_path, sender, pacer, aircraft_dirs)  # type: ignore[arg-type]
        sender.close_segment()
    finally:
        sender.close()
    print(f"send: sent {sender.sent} datagrams in {time.perf_counter() - pacer.start:.3f} s"
          f"{f' ({sender.errors} refused: nobody listening?)' if sender.errors else ''}")  # fmt: skip
    return 0


def _fly_and_send(path: Path, sender: Sender, pacer: Pacer, aircraft_dirs: tuple[Path, ...]) -> None:
    """Fly the manoeuvre with JSBSim, each step paced to (``--speed`` times) real time and sent as it is final."""
    m = load_manoeuvre(resolve_manoeuvre(path), aircraft_dirs)
    dt = m.dt_s
    r2d = 180.0 / np.pi
    stopped = False

    def hook(k: int, f: np.ndarray, w: np.ndarray) -> None:
        nonlocal stopped
        if stopped:
            return
        t = k * dt
        pacer.wait(t)
        s = (t, float(f[0]), float(f[1]), float(f[2]), float(w[0]) * r2d, float(w[1]) * r2d, float(w[2]) * r2d)
        stopped = not sender.send(s)

    result = fly(m, step_hook=hook)
    if not result.ok:
        print(f"send: the flight stopped early: {result.reason}", file=sys.stderr)
