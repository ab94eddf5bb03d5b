"""The rerun viewer during ``washbench live``: the recording's layout, filled as the samples come.

The viewer is the rerun executable :func:`washbench.review.replay.find_rerun` finds, started as a child process
(it ends with washbench) and fed over gRPC on a free local port. Shown, on the recording's timeline ``time``
(:data:`washbench.review.rerun_log.TIMELINE`) and entity paths: ``/raw/<dof>`` and ``/perceived/<dof>`` (the
aircraft pilot's and each simulator pilot's specific force and angular velocity, and what each perceives, one
scalar per source) and ``/platform/<washout>/position/axes``, at most :data:`RATE_HZ` rows a second (the viewer
is for the eye; every sample is in the result folder), the plots scrolling over the last :data:`WINDOW_S` s.

Without a display (no ``DISPLAY`` / ``WAYLAND_DISPLAY`` on Linux, a remote shell) the viewer is off with one line;
a viewer closed while running is noticed (its process ended) and logging stops, the session goes on.
"""

from __future__ import annotations

import contextlib
import socket
import subprocess
import sys
import time
from collections.abc import Sequence
from typing import Any

import numpy as np

from washbench.cueing.kernel import O_HEAD_F, O_HEAD_OMEGA, O_POS
from washbench.perception.vestibular import PerceptionStream, VestibularModel
from washbench.review.replay import _die_with_parent, _has_display, find_rerun

RATE_HZ = 30.0
_HEAD = np.r_[O_HEAD_F : O_HEAD_F + 3, O_HEAD_OMEGA : O_HEAD_OMEGA + 3]


def _free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


WINDOW_S = 20.0
"""The plots scroll: they show the last this-many seconds before the time cursor."""


def live_blueprint(names: Sequence[str]) -> Any:
    """The live layout: the recording's perceived and raw motion panels (aircraft pilot and each simulator pilot,
    the recording's colours and names) and each platform's position, all scrolling with the time cursor."""
    import rerun.blueprint as rrb

    from washbench.review.rerun_log import DOFS, TIMELINE, perceived_path, platform_path, raw_path  # deferred: rerun

    window = rrb.VisibleTimeRange(TIMELINE, start=rrb.TimeRangeBoundary.cursor_relative(seconds=-WINDOW_S),
                                  end=rrb.TimeRangeBoundary.cursor_relative())  # fmt: skip
    kinds = ((perceived_path, "perceived"), (raw_path, "raw"))
    motion = [rrb.TimeSeriesView(origin=path(dof), name=f"{what} {dof} ({unit})", time_ranges=[window])
              for path, what in kinds for dof, _, _, unit in DOFS]  # fmt: skip
    platforms = [rrb.TimeSeriesView(origin=platform_path(w, "position"), name=f"{w}: stage position (m)",
                                    time_ranges=[window]) for w in names]  # fmt: skip
    tabs = rrb.Tabs(rrb.Grid(*motion[:6], name="perceived"), rrb.Grid(*motion[6:], name="raw"))
    return rrb.Blueprint(rrb.Horizontal(tabs, rrb.Vertical(*platforms), column_shares=[3, 1]),
                         collapse_panels=True)  # fmt: skip


def send_styles(rec: Any, names: Sequence[str]) -> None:
    """The series' names, colours and widths, as in a recording (static)."""
    import rerun as rr

    from washbench.review.blueprint import AIRCRAFT_WIDTH, AXIS_COLORS, WASHOUT_WIDTH, source_colors  # deferred: rerun
    from washbench.review.rerun_log import AIRCRAFT, DOFS, perceived_path, platform_path, raw_path  # deferred: rerun

    colors = source_colors(list(names))  # the aircraft's first: its line is drawn last, on top, as in a recording
    style = rr.SeriesLines(colors=[*colors[1:], colors[0]], names=[*names, AIRCRAFT],
                           widths=[WASHOUT_WIDTH] * len(names) + [AIRCRAFT_WIDTH])  # fmt: skip
    for dof, *_ in DOFS:
        rec.log(raw_path(dof), style, static=True)
        rec.log(perceived_path(dof), style, static=True)
    for w in names:
        rec.log(platform_path(w, "position"), rr.SeriesLines(colors=list(AXIS_COLORS), names=["x", "y", "z"]),
                static=True)  # fmt: skip


class LiveViewer:
    """A running viewer and the recording stream that feeds it.

    :meth:`add` takes every cued sample (the aircraft pilot's motion and each washout's simulator head motion) and
    runs the vestibular models on them in blocks, :data:`RATE_HZ` times a second (chunk by chunk they give the bits
    of a whole trace: what the result's traces.parquet holds); the last sample of each block is logged.
    """

    def __init__(self, names: Sequence[str], proc: subprocess.Popen[bytes], rec: Any,
                 filter_start: str = "steady") -> None:  # fmt: skip
        self.names, self.proc, self.rec = tuple(names), proc, rec
        self.filter_start = filter_start
        self.closed = False
        self._next = 0.0
        self._every = 1.0 / RATE_HZ
        self._streams: list[Any] = []
        self._dt: float | None = None
        self._buf: list[tuple[tuple[float, ...], np.ndarray]] = []
        send_styles(rec, self.names)

    def add(self, sample: tuple[float, ...], rows: np.ndarray, dt_s: float, new_segment: bool) -> None:
        """One cued sample and its bank rows (n_washouts, N_FIELDS); logged at most :data:`RATE_HZ` times a second."""
        if self.closed:
            return
        if new_segment or not self._streams or dt_s != self._dt:
            self._flush()

            model = VestibularModel(dt_s)
            self._streams = [PerceptionStream(model, self.filter_start) for _ in range(1 + len(self.names))]
            self._dt = dt_s
        self._buf.append((sample, rows[:, _HEAD].copy()))
        now = time.monotonic()
        if now >= self._next:
            self._next = now + self._every
            self._flush(rows)

    def _flush(self, rows: np.ndarray | None = None) -> None:
        if not self._buf or not self._streams:
            self._buf.clear()
            return
        import rerun as rr

        from washbench.review.rerun_log import (  # deferred: rerun
            DOFS,
            TIMELINE,
            perceived_path,
            platform_path,
            raw_path,
        )

        buf, self._buf = self._buf, []
        motion = np.array([s for s, _ in buf])
        head = np.stack([h for _, h in buf])  # (M, n_washouts, 6)
        f = [motion[:, 1:4], *(head[:, i, 0:3] for i in range(len(self.names)))]
        w = [np.radians(motion[:, 4:7]), *(head[:, i, 3:6] for i in range(len(self.names)))]
        felt = [st.perceive(fi, wi) for st, fi, wi in zip(self._streams, f, w, strict=True)]
        if rows is None:
            return
        try:
            self.rec.set_time(TIMELINE, duration=float(motion[-1, 0]))
            for dof, sig, axis, _unit in DOFS:
                if sig == "f":
                    raw = [fi[-1, axis] for fi in f]
                    seen = [p.f_mps2[-1, axis] for p in felt]
                else:
                    raw = [np.degrees(wi[-1, axis]) for wi in w]
                    seen = [np.degrees(p.omega_radps[-1, axis]) for p in felt]
                # the washouts first, the aircraft last (drawn on top), the order of send_styles
                self.rec.log(raw_path(dof), rr.Scalars(np.asarray([*raw[1:], raw[0]], dtype=np.float64)))
                self.rec.log(perceived_path(dof), rr.Scalars(np.asarray([*seen[1:], seen[0]], dtype=np.float64)))
            for i, name in enumerate(self.names):
                self.rec.log(platform_path(name, "position"), rr.Scalars(rows[i, O_POS : O_POS + 3]))
        except Exception:  # a viewer problem must never stop the session
            self.closed = True

    def closed_now(self) -> bool:
        """True once, when the viewer's process has ended (the user closed it)."""
        if not self.closed and self.proc.poll() is not None:
            self.closed = True
            print("live: the viewer was closed; the session goes on (the result folder has the recording)",
                  file=sys.stderr)  # fmt: skip
            with contextlib.suppress(Exception):
                self.rec.disconnect()
            return True
        return False

    def close(self) -> None:
        with contextlib.suppress(Exception):
            self.rec.flush()
            self.rec.disconnect()


def open_viewer(names: Sequence[str], limits: Any, filter_start: str = "steady") -> LiveViewer | None:
    """Start the viewer, or print one line and return None where it cannot open a window."""

    if not _has_display():
        print("live: no display (DISPLAY / WAYLAND_DISPLAY unset): the live viewer is off; the result folder's "
              "recording.rrd opens with `washbench replay` (--no-viewer silences this)", file=sys.stderr)  # fmt: skip
        return None
    try:
        import rerun as rr

        port = _free_port()
        proc = subprocess.Popen(
            [str(find_rerun()), "--port", str(port)],
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            start_new_session=True,
            preexec_fn=_die_with_parent if sys.platform.startswith("linux") else None,
        )
        rec = rr.RecordingStream("washbench-live")
        time.sleep(0.5)
        rec.connect_grpc(f"rerun+http://127.0.0.1:{port}/proxy")
        rec.send_blueprint(live_blueprint(names))
    except Exception as exc:
        print(f"live: the viewer could not start ({exc}); the session goes on without it", file=sys.stderr)
        return None
    return LiveViewer(names, proc, rec, filter_start)
