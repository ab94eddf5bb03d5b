"""``washbench live``: the washouts in real time on a flight simulator's UDP output, platform commands out, and at
the end exactly the result folder ``washbench cue`` writes for the same samples.

One loop, one thread: a datagram arrives (:mod:`washbench.live.packets` decodes it), the link sorts out loss,
reordering, duplicates and restarts (:mod:`washbench.live.link`), each sample to cue is appended to
``OUT/live_input.csv`` (a ``washbench cue`` input in washbench's own columns, written as it arrives, so memory does
not grow and a killed session leaves a readable file), run through :class:`washbench.cueing.CueingBank` (washouts,
Atlas model, head motion) and its command sent (:mod:`washbench.live.commands`); the viewer gets it last.

On stop (Ctrl-C, SIGTERM, ``--duration``, ``--idle-timeout``) the saved input is cued by :func:`run_cue`, the code
of ``washbench cue`` itself: traces.parquet, metrics.csv and the rest are those of ``washbench cue
OUT/live_input.csv`` bit for bit (with ``--resample`` when the source's clock is not on a uniform grid, chosen
and printed as ``washbench cue`` advises it). The session's figures (counts, latency, jitter) go into run.json
under ``live``.
"""

from __future__ import annotations

import contextlib
import gc
import json
import math
import os
import signal
import socket
import struct
import sys
import threading
import time
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from washbench.cueing import CueingBank
from washbench.errors import Terminated, WashbenchError, printable
from washbench.io import interrupts
from washbench.io.atomic import write_text_atomic
from washbench.io.lock import output_lock
from washbench.io.outfolder import owned_entries
from washbench.io.resample import suggest_rate, uniform_step
from washbench.io.result_files import RUN_FILE
from washbench.live import commands
from washbench.live import viewer as live_viewer
from washbench.live.endpoints import Sink, bind_udp
from washbench.live.link import DT_RANGE_S, LatencyStats, Link, Out, UnusableStepError
from washbench.live.packets import RREF_DATAREFS, RREF_ID0, Decoder, PacketError, decoder, rref_request
from washbench.live.saved_input import INPUT_FILE, PART_SUFFIX, InputWriter, own_leftover
from washbench.runs.cue import CueOptions, run_cue
from washbench.runs.options import RunOptions, load_options

POLL_S = 0.05
"""The loop wakes up at least this often to check the stop conditions."""
SO_TIMESTAMPNS = 35
"""Linux's socket option for a datagram's arrival time stamped by the kernel (``SCM_TIMESTAMPNS``: a timespec)."""
MAX_SENDER_NOTES = 8
"""Other senders named on stdout (each once); more are only counted."""
FLIGHTGEAR_NATIVE = b"\x00\x00\x00\x18"
"""The first 4 bytes of FlightGear's native FDM packet (FGNetFDM, version 24, network order): what JSBSim's
``<output type="FLIGHTGEAR">`` sends."""


def receiver(sock: socket.socket) -> tuple[Any, Any]:
    """``(recv, clock)``: ``recv()`` gives ``(data, address, arrival_ns)`` and ``clock()`` the time now on the same
    clock. On Linux the arrival is the kernel's time stamp of the datagram (``SO_TIMESTAMPNS``, wall clock): the
    time it waited in the receive queue is in the latency; elsewhere the time ``recvfrom`` returned."""
    if sys.platform.startswith("linux"):
        try:
            sock.setsockopt(socket.SOL_SOCKET, SO_TIMESTAMPNS, 1)
        except OSError:
            pass
        else:
            space = socket.CMSG_SPACE(16)
            unpack = struct.Struct("@qq").unpack_from
            wall = time.time_ns

            def recv_stamped() -> tuple[bytes, Any, int]:
                data, ancillary, _flags, address = sock.recvmsg(65536, space)
                for level, kind, cdata in ancillary:
                    if level == socket.SOL_SOCKET and kind == SO_TIMESTAMPNS and len(cdata) >= 16:
                        sec, nsec = unpack(cdata)
                        return data, address, sec * 1_000_000_000 + nsec
                return data, address, wall()

            return recv_stamped, wall
    clock = time.perf_counter_ns

    def recv_plain() -> tuple[bytes, Any, int]:
        data, address = sock.recvfrom(65536)
        return data, address, clock()

    return recv_plain, clock


@dataclass(frozen=True)
class LiveOptions:
    """Everything ``washbench live`` is told besides what a run is told (:class:`~washbench.runs.options.RunOptions`:
    the washouts, the parameter and platform files, the outputs, the filters' start, the ranking)."""

    listen: tuple[str, int]
    fmt: str
    out: Path
    sink: tuple[str, int] | None = None
    sink_format: str = "binary"
    duration_s: float | None = None
    idle_timeout_s: float | None = None
    rate_hz: float | None = None
    resample_hz: float | None = None
    xplane: tuple[str, int] = ("127.0.0.1", 49000)
    rref_hz: int = 60
    viewer: bool = True
    realtime: bool = False


@contextlib.contextmanager
def stop_on_signals(busy: list[bool] | None = None) -> Iterator[list[int]]:
    """While inside, SIGINT and SIGTERM only record themselves (the loop stops at its next turn and the result is
    written); yields the list they are recorded in. While ``busy[0]`` (the washouts are computing: a plugin's
    ``step`` may never return) the signal is raised at once, as in ``washbench cue`` (KeyboardInterrupt or
    Terminated). Outside the main thread (tests), nothing is installed."""
    got: list[int] = []
    if threading.current_thread() is not threading.main_thread():
        yield got
        return

    def note(signum: int, frame: object) -> None:
        got.append(signum)
        interrupts.note_received()  # a real signal: the plugin guard lets it through
        if busy is not None and busy[0]:
            raise KeyboardInterrupt if signum == signal.SIGINT else Terminated()

    old = {s: signal.signal(s, note) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield got
    finally:
        for s, h in old.items():
            signal.signal(s, h)


class Session:
    """One live session: the socket, the link, the saved input, the bank, the sink and the figures."""

    def __init__(self, opts: LiveOptions, dec: Decoder, specs: Sequence[Any], limits: Any, filter_start: str,
                 sock: socket.socket, writer: InputWriter, sink: Sink, viewer: Any) -> None:  # fmt: skip
        self.opts, self.dec, self.specs, self.limits, self.filter_start = opts, dec, specs, limits, filter_start
        self.sock, self.writer, self.sink, self.viewer = sock, writer, sink, viewer
        dt = 1.0 / opts.rate_hz if opts.rate_hz else None
        self.link = Link(dt, dec.lag_shift)
        self.latency = LatencyStats()
        self.bank: Any = None
        self.rows: np.ndarray | None = None
        self.foreign = 0
        self.malformed = 0
        self.socket_errors = 0
        self.first_arrival: float | None = None
        self.last_arrival: float | None = None
        self.stop = ""
        self.cpu0 = self.cpu1 = 0.0
        self.last_done: float | None = None
        self._f = np.empty(3)
        self._w = np.empty(3)
        self.busy = [False]  # the washouts are computing (a signal then acts at once: stop_on_signals)
        self.recv, self.clock = receiver(sock)
        self.sender: Any = None  # the address the session locked onto (the first that sent a datagram of the format)
        self.other_senders = 0  # datagrams from any other address (ignored)
        self._others: set[Any] = set()
        self.unusable: str | None = None  # why the source's time cannot be cued (the session stops, saves, refuses)
        self.hints: list[str] = []
        self.save_only = False  # the washouts were cut short by a signal: what is still received is saved, not cued
        self.cued = 0  # samples cued (stepped through the washouts)

    # ------------------------------------------------------------------ the hot path

    def cue(self, o: Out) -> None:
        """Save, cue and command one sample (only save it once the washouts were cut short: :attr:`save_only`)."""
        s = o.sample
        if self.save_only:
            self.writer.row(s, o.held, o.new_segment)
            return
        self.busy[0] = True  # a plugin may block in here: a signal acts at once
        try:
            if o.new_segment or self.bank is None:
                self.bank = CueingBank(self.specs, None, self.limits, self.link.dt_s, self.filter_start)
            f, w = self._f, self._w
            f[0], f[1], f[2] = s[1], s[2], s[3]
            w[0], w[1], w[2] = s[4], s[5], s[6]
            rows = self.rows = self.bank.step(f, np.radians(w))
        except (KeyboardInterrupt, Terminated):  # a signal while a washout computed: the sample was received, kept
            self.writer.row(s, o.held, o.new_segment)
            raise
        finally:
            self.busy[0] = False
        self.cued += 1
        flags = (commands.FLAG_HELD if o.held else 0) | (commands.FLAG_NEW_SEGMENT if o.new_segment else 0)
        self.sink.send(s[0], flags, rows)
        self.writer.row(s, o.held, o.new_segment)  # after the command: not on the latency path
        if self.viewer is not None:
            self.viewer.add(s, rows, self.link.dt_s, o.new_segment)

    def receive(self, data: bytes, arrival_ns: int, address: Any = None) -> None:
        if self.sender is not None and address != self.sender:
            self._other_sender(address)
            return
        try:
            sample = self.dec.decode(data)
        except PacketError as exc:
            if exc.kind == "foreign":
                self.foreign += 1
                if data[:4] == FLIGHTGEAR_NATIVE and len(data) >= 100 and not self.hints:
                    self.hints.append(
                        "datagrams in FlightGear's native FDM format (JSBSim's <output type=\"FLIGHTGEAR\">) arrive: "
                        "washbench reads FlightGear's generic protocol (--format flightgear with washbench's protocol "
                        "file, or JSBSim's type=\"SOCKET\" output with --format jsbsim; docs/live.md)"
                    )
                    print(f"live: {self.hints[-1]}", flush=True)
            else:
                self.malformed += 1
            return
        if self.sender is None and address is not None:
            self.sender = address  # locked onto the first sender of this format
        if sample is None:
            return
        try:
            # the link's arrival clock is monotonic (the kernel's stamp is wall-clock time, which NTP may step)
            outs = self.link.push(sample, time.monotonic())
        except UnusableStepError as exc:
            self._unusable(exc)
            return
        for i, o in enumerate(outs):
            try:
                self.cue(o)
            except (KeyboardInterrupt, Terminated):  # cut short: the rest of what arrived is saved, not lost
                for rest in outs[i + 1 :]:
                    self.writer.row(rest.sample, rest.held, rest.new_segment)
                raise
        if outs:
            done = self.clock()
            last = outs[-1]
            if not last.held:
                self.latency.add(done - arrival_ns, self.link.dt_s)
            self.latency.arrival(arrival_ns * 1e-9, last.new_segment)

    def _other_sender(self, address: Any) -> None:
        """A datagram from another address than the one the session locked onto: counted, ignored; named once."""
        self.other_senders += 1
        if address not in self._others and len(self._others) < MAX_SENDER_NOTES:
            self._others.add(address)
            print(f"live: datagrams from {_address(address)} ignored: locked onto {_address(self.sender)}, the first "
                  "sender", flush=True)  # fmt: skip

    def _unusable(self, exc: UnusableStepError) -> None:
        """The source's step is outside what live accepts: save what was received as it came, and stop."""
        for i, s in enumerate(self.link.pending):
            self.writer.row(s, False, i == 0)
        lo, hi = DT_RANGE_S
        shown = "none" if exc.dt_s is None else f"{exc.dt_s:.3g} s"
        self.unusable = (f"the source's time step, measured on its first samples, is {shown}, outside {lo:g}..{hi:g} s "
                         "(a stream in another byte order or --format, or a corrupt clock?)")  # fmt: skip
        self.stop = "the source's time cannot be cued"

    def run(self, got_signal: list[int]) -> None:
        """Receive until a stop condition; ``stop`` says which."""
        opts, sock = self.opts, self.sock
        sock.settimeout(POLL_S)
        recv = self.recv
        start = time.monotonic()
        deadline = start + opts.duration_s if opts.duration_s is not None else math.inf
        idle = opts.idle_timeout_s
        subscribe = self.dec.name == "xplane-rref"
        next_subscribe = 0.0
        while True:
            now = time.monotonic()
            if got_signal:
                self.stop = "interrupted (Ctrl-C)" if got_signal[0] == signal.SIGINT else "terminated (SIGTERM)"
                self.drain()
                return
            if now >= deadline:
                self.stop = f"--duration {opts.duration_s:g} s"
                return
            if subscribe and self.link.counts.received == 0 and now >= next_subscribe:
                self.rref(self.opts.rref_hz)  # again every 2 s until X-Plane answers (it may start later)
                next_subscribe = now + 2.0
            if self.unusable:
                return
            self.writer.tick()
            try:
                data, address, arrival = recv()
            except TimeoutError:  # nothing waiting: the source may have gone quiet (or never sent anything)
                quiet_since = self.last_arrival if self.last_arrival is not None else start
                if idle is not None and time.monotonic() - quiet_since > idle:
                    never = " (nothing arrived)" if self.last_arrival is None else ""
                    self.stop = f"the source was quiet for --idle-timeout {idle:g} s{never}"
                    return
                continue
            except InterruptedError:
                continue
            except OSError:  # an ICMP error of our own RREF requests, reported on this socket
                self.socket_errors += 1
                continue
            if self.sender is None or address == self.sender:
                self.last_arrival = time.monotonic()  # another sender does not keep the session awake
                if self.first_arrival is None:
                    self.first_arrival = self.last_arrival
                    self.cpu0 = time.process_time()
            self.receive(data, arrival, address)
            self.cpu1, self.last_done = time.process_time(), time.monotonic()
            if self.viewer is not None and self.viewer.closed_now():
                self.viewer = None

    def drain(self) -> None:
        """Take the datagrams already waiting in the socket (received by the system before the stop)."""
        self.sock.setblocking(False)
        while not self.unusable:
            try:
                data, address, arrival = self.recv()
            except (BlockingIOError, InterruptedError):
                return
            except OSError:
                self.socket_errors += 1
                continue
            self.receive(data, arrival, address)

    def finish(self) -> None:
        """The samples still held back, cued; the RREF subscription cancelled."""
        try:
            outs = [] if self.unusable else self.link.flush()
        except UnusableStepError as exc:
            self._unusable(exc)
            outs = []
        for o in outs:
            self.cue(o)
        if self.dec.name == "xplane-rref":
            self.rref(0)

    def rref(self, freq_hz: int) -> None:
        """Subscribe to (or with 0 cancel) the datarefs of :data:`RREF_DATAREFS` at ``opts.xplane``."""
        for i, (path, _unit) in enumerate(RREF_DATAREFS):
            with contextlib.suppress(OSError):
                self.sock.sendto(rref_request(freq_hz, RREF_ID0 + i, path), self.opts.xplane)

    def figures(self) -> dict[str, Any]:
        c = self.link.counts
        return {
            "format": self.dec.name,
            "listen": f"{self.opts.listen[0]}:{self.opts.listen[1]}",
            "sender": None if self.sender is None else _address(self.sender),
            "hints": list(self.hints),
            "stop": self.stop,
            "dt_s": self.link.dt_s,
            "counts": {
                "received": c.received,
                "cued": self.writer.rows,
                "lost_held": c.lost,
                "duplicate": c.duplicate,
                "reordered": c.reordered,
                "restarts": c.restarts,
                "segments": self.writer.segments,
                "short_segments_dropped": self.writer.short_segments,
                "time_jumps": c.time_jumps,
                "lag_unshifted": c.unshifted,
                "foreign": self.foreign,
                "other_senders": self.other_senders,
                "malformed": self.malformed,
                "socket_errors": self.socket_errors,
                "commands": self.sink.seq,
                "sink_sent": self.sink.sent,
                "sink_errors": self.sink.errors,
            },
            "latency": self.latency.summary(),
            "active_wall_s": round(self.last_done - self.first_arrival, 3)
            if self.last_done is not None and self.first_arrival is not None
            else 0.0,  # from the first datagram to the last one handled
            "active_cpu_s": round(self.cpu1 - self.cpu0, 3),  # CPU time of this process over that span
            "sink": None if self.opts.sink is None else f"udp://{self.opts.sink[0]}:{self.opts.sink[1]}",
            "sink_format": self.opts.sink_format,
            "washouts": [w.name for w in self.specs],
            "viewer": "closed" if self.viewer is None and self.opts.viewer else ("on" if self.viewer else "off"),
        }


REALTIME_PRIORITY = 50
"""``--realtime``: SCHED_FIFO at this priority (of 1..99; the kernel's own threads run at 50 too)."""


def realtime_priority() -> tuple[int, os.sched_param] | None:
    """Put this process at the real-time priority :data:`REALTIME_PRIORITY` (Linux SCHED_FIFO; needs root or
    CAP_SYS_NICE); returns the policy and parameter to restore, or None with one line if it cannot."""
    try:
        before = (os.sched_getscheduler(0), os.sched_getparam(0))
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(REALTIME_PRIORITY))
    except (AttributeError, OSError) as exc:
        why = getattr(exc, "strerror", None) or "not supported here"
        print(f"live: --realtime: cannot take a real-time priority ({why}); running at the ordinary one",
              file=sys.stderr)  # fmt: skip
        return None
    print(f"  real-time priority: SCHED_FIFO {REALTIME_PRIORITY} while receiving")
    return before


def _print_figures(fig: dict[str, Any]) -> None:
    c, lat = fig["counts"], fig["latency"]

    def ms(v: float | None) -> str:
        return "-" if v is None else f"{v:.3f}"

    print(f"live: stopped: {fig['stop']}")
    print(f"  received {c['received']}, cued {c['cued']} in {c['segments']} segment(s); lost (held) {c['lost_held']}, "
          f"duplicate {c['duplicate']}, reordered {c['reordered']}, restarts {c['restarts']}, foreign "
          f"{c['foreign']}, malformed {c['malformed']}")  # fmt: skip
    print(f"  time jumps {c['time_jumps']}, short segments dropped {c['short_segments_dropped']}, last frame dropped "
          f"by the lag shift {c['lag_unshifted']}, datagrams from other senders {c['other_senders']}"
          f"{'' if fig.get('sender') is None else ' (locked onto ' + fig['sender'] + ')'}")  # fmt: skip
    print(f"  commands {c['commands']} (sink sent {c['sink_sent']}, errors {c['sink_errors']}); latency median "
          f"{ms(lat['latency_median_ms'])} ms, p99 {ms(lat['latency_p99_ms'])} ms, max "
          f"{ms(lat['latency_max_ms'])} ms, late {lat['late']}; jitter mean {ms(lat['jitter_mean_ms'])} ms, "
          f"max {ms(lat['jitter_max_ms'])} ms")  # fmt: skip


def _address(address: Any) -> str:
    """``HOST:PORT`` of a socket address (printable)."""
    if isinstance(address, tuple) and len(address) >= 2:
        return printable(f"{address[0]}:{address[1]}")
    return printable(str(address))


def _auto_resample(path: Path) -> float | None:
    """A rate to resample the saved input at when a segment's times are not on a uniform grid (else None)."""
    import pyarrow.csv as pacsv

    t = pacsv.read_csv(path, convert_options=pacsv.ConvertOptions(include_columns=["t_s"])).column(0).to_numpy()
    back = np.flatnonzero(np.diff(t) < 0.0) + 1
    for part in np.split(t, back):
        if part.size >= 2 and uniform_step(part)[0] is None:
            return suggest_rate(part)
    return None


def _add_live_figures(out: Path, input_path: Path, fig: dict[str, Any]) -> None:
    """Put the session's figures into run.json (``live``) of every result folder cued from ``input_path``."""
    for folder in (out, *sorted(out.glob("segment_*"))):
        path = folder / RUN_FILE
        try:
            doc = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            continue
        if doc.get("input") != str(input_path):
            continue
        doc["live"] = fig
        write_text_atomic(path, json.dumps(doc, indent=2) + "\n")


def run_live(opts: LiveOptions, run: RunOptions | None = None) -> int:
    """The ``washbench live`` command; returns the exit status (that of ``washbench cue`` on the saved input, or
    130 / 143 after a Ctrl-C / SIGTERM once the result folder is written).

    ``run``: the options of the final cue (:func:`~washbench.runs.options.load_options`, each file read once), used
    live as well; None: the defaults (the bundled files and washouts, recording and figures).
    """
    for flag, value in (("--duration", opts.duration_s), ("--idle-timeout", opts.idle_timeout_s),
                        ("--rate-hz", opts.rate_hz), ("--resample", opts.resample_hz)):  # fmt: skip
        if value is not None and not (math.isfinite(value) and value > 0.0):
            raise WashbenchError(f"{flag}: expected a positive number, got {value:g}")
    lo, hi = DT_RANGE_S
    if opts.rate_hz is not None and not 1.0 / hi <= opts.rate_hz <= 1.0 / lo:
        raise WashbenchError(f"--rate-hz: expected {1.0 / hi:g}..{1.0 / lo:g} Hz, got {opts.rate_hz:g}")
    if not 0 < opts.rref_hz <= 10000:
        raise WashbenchError(f"--rref-hz: expected 1..10000 Hz, got {opts.rref_hz}")
    if run is None:
        run = load_options()
    specs, limits, names, filter_start = run.washouts, run.limits, list(run.washout_order), run.filter_start
    dec = decoder(opts.fmt)
    CueingBank(specs, None, limits, 0.01, filter_start).step(np.zeros(3), np.zeros(3))  # compiled before listening
    sink = Sink(opts.sink, opts.sink_format, names)
    t_wall = time.perf_counter()
    # a Ctrl-C or SIGTERM from the moment the port is bound only stops the loop: the result is written first
    busy = [False]
    with stop_on_signals(busy) as got, contextlib.closing(sink), contextlib.closing(bind_udp(opts.listen)) as sock, \
            output_lock(opts.out) as out:  # fmt: skip
        # a folder holding someone else's files is refused before listening; a killed session's own .part is taken
        leftover = own_leftover(out / (INPUT_FILE + PART_SUFFIX))
        owned_entries(out, "cue", (INPUT_FILE, *([leftover.name] if leftover else [])))
        if leftover is not None:
            print(f"live: {leftover}: left by a session that was killed; replaced by this one's")
        earlier = (out / INPUT_FILE).is_file()
        writer = InputWriter(out / INPUT_FILE)
        viewer = live_viewer.open_viewer(names, limits, filter_start) if opts.viewer else None
        to = f"udp://{opts.sink[0]}:{opts.sink[1]} ({opts.sink_format})" if opts.sink else "nowhere (no --sink)"
        print(f"live: listening on udp://{opts.listen[0]}:{opts.listen[1]} for {opts.fmt} packets; washouts "
              f"{', '.join(names)}; commands to {to}")  # fmt: skip
        rcvbuf = sock.getsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF)
        print(f"  receive buffer {rcvbuf // 1024} KiB (raise net.core.rmem_max for more)")
        for note in dec.notes:
            print(f"  {note}")
        sys.stdout.flush()
        session = Session(opts, dec, specs, limits, filter_start, sock, writer, sink, viewer)
        session.busy = busy
        cut = False  # a signal stopped the washouts in the middle of a step (a plugin that blocks)
        gc.collect()
        gc.freeze()  # what exists now is never scanned again: shorter collector pauses in the loop
        before = realtime_priority() if opts.realtime else None
        try:
            session.run(got)
        except (KeyboardInterrupt, Terminated) as exc:  # raised inside a step (stop_on_signals): not cued again
            cut = True
            session.stop = ("interrupted (Ctrl-C)" if isinstance(exc, KeyboardInterrupt) else "terminated (SIGTERM)") \
                + " while the washouts were computing"  # fmt: skip
        finally:
            if before is not None:
                os.sched_setscheduler(0, *before)  # the final cue runs at the ordinary priority again
            gc.unfreeze()
            if cut:  # what was received and not yet saved (the link's held samples, the socket's queue): saved only
                session.save_only = True
                session.drain()
            session.finish()
            saved = writer.close()
            if session.viewer is not None:
                session.viewer.close()
    fig = session.figures()
    fig["wall_s"] = round(time.perf_counter() - t_wall, 3)
    _print_figures(fig)
    status = {signal.SIGINT: 130, signal.SIGTERM: 143}.get(got[0], 0) if got else 0
    if session.unusable:
        kept = f"the {writer.rows} sample(s) received are in {saved}" if saved else "nothing was saved"
        raise WashbenchError(f"--listen {opts.listen[0]}:{opts.listen[1]}: {session.unusable}; {kept}")
    if cut:
        kept = (f"the {writer.rows} sample(s) received are in {saved} ({session.cued} cued before it)" if saved
                else "fewer than 2 samples received")  # fmt: skip
        print(f"washbench: {session.stop}: {kept} (not cued again: a washout may not return; `washbench cue` "
              "that file)", file=sys.stderr)  # fmt: skip
        return status or 130
    if saved is None:  # an earlier session's files in --out are left as they were
        with contextlib.suppress(OSError):
            out.rmdir()
        if status:
            print(f"washbench: {session.stop}: fewer than 2 samples received, nothing to cue", file=sys.stderr)
            return status
        raise WashbenchError(f"--listen {opts.listen[0]}:{opts.listen[1]}: {session.link.counts.received} sample(s) "
                             f"received ({session.stop}): nothing to cue")  # fmt: skip
    if earlier:
        print(f"live: {out}: the earlier session's results there are replaced by this one's")
    resample = opts.resample_hz or _auto_resample(saved)
    if resample and not opts.resample_hz:
        print(f"  the source's clock is not on a uniform grid: cued with --resample {resample:g} "
              f"(washbench cue {saved} --resample {resample:g} gives the same)")  # fmt: skip
    cue_opts = CueOptions(resample_hz=resample)
    fig["resample_hz"] = resample
    result = run_cue(saved, out, cue_opts, run, adopt=(INPUT_FILE,))
    _add_live_figures(out, saved, fig)
    if status:
        print(f"washbench: {session.stop}: the result folder holds every sample received", file=sys.stderr)
        return status
    return result
