"""Two recordings of one manoeuvre in one viewer: ``washbench replay A.rrd B.rrd``.

E.g. two parameter sets, or two platform files, on the same manoeuvre. Both recordings are read back and written into
one comparison recording: the six stacked perceived-motion panels (and the raw motion) with the aircraft pilot once
(twice if the two flights differ) and each washout of A and of B, A's in the washout's own colour, B's in the same hue
washed towards grey, labelled ``A: <washout>`` and ``B: <washout>`` with A and B the recordings' labels; the envelope
usage of both; the phase lanes; both metric tables side by side. The two recordings must cover the same time span.
Recordings on two platforms (an Atlas and a hexapod) are compared on what both hold: an envelope panel only one
has (the Atlas's wheels) is left out, and the command says so.

Each recorded series keeps only the samples it needs (:mod:`washbench.review.thinning`): A's and B's lines of a
panel are put on the union of their recorded times, each line interpolated linearly from its own samples (the line
drawn is the same), and the aircraft is drawn once when A's and B's agree within their stored tolerances.
"""

from __future__ import annotations

import uuid
from pathlib import Path

import numpy as np
import rerun as rr
import rerun.blueprint as rrb

from washbench.errors import WashbenchError, located
from washbench.io.atomic import atomic_path
from washbench.review.blueprint import AIRCRAFT_WIDTH, WASHOUT_WIDTH, series_color
from washbench.review.rerun_log import AIRCRAFT, DOFS, ENVELOPE_QUANTITIES, TIMELINE, RrdFile, phase_lane_path
from washbench.review.rrd_read import (
    read_component,
    read_properties,
    read_scalar_series,
    read_static,
    read_text_documents,
)

__all__ = ["comparison_labels", "shared_panels", "write_comparison"]


def _time(t_s: np.ndarray) -> rr.TimeColumn:
    return rr.TimeColumn(TIMELINE, duration=np.round(t_s * 1e9).astype(np.int64).astype("timedelta64[ns]"))


def _washed(rgb: tuple[int, int, int]) -> tuple[int, int, int]:
    """The same hue, halfway to mid grey: B's traces beside A's."""
    r, g, b = (round(0.5 * c + 0.5 * 150) for c in rgb)
    return (r, g, b)


def comparison_labels(a: Path, b: Path) -> tuple[str, str]:
    """Short labels: the recordings' parameter-set names if they differ, else the first differing folder names."""
    pa, pb = read_properties(a).get("params_name", ""), read_properties(b).get("params_name", "")
    if pa and pb and pa != pb:
        return pa, pb
    parts_a, parts_b = Path(a).resolve().parts, Path(b).resolve().parts
    for x, y in zip(parts_a, parts_b, strict=False):
        if x != y:
            return x, y
    return "A", "B"


def _columns(
    path: Path, entity: str, series: dict[str, tuple[np.ndarray, np.ndarray]]
) -> tuple[list[str], np.ndarray, np.ndarray, np.ndarray]:
    """Line names, recorded times (ns), values (M, lines) and per-line tolerance (0 where none is stored)."""
    names = read_static(path, "SeriesLines:names").get(entity)
    t_s, values = series[entity]
    values = values.reshape(values.shape[0], -1)
    if names is None or len(names) != values.shape[1]:
        raise WashbenchError(located(path, f"{entity}: not a washbench recording layout (no line names)"))
    tol = read_static(path, "interpolation_tolerance").get(entity)
    tolerance = np.asarray(tol, dtype=np.float64) if tol and len(tol) == len(names) else np.zeros(len(names))
    return [str(n) for n in names], np.round(t_s * 1e9).astype(np.int64), values, tolerance


def _platform(path: Path) -> str:
    """The recording's platform as its provenance names it (``platform.name``), or "its platform"."""
    return str(read_properties(path).get("platform.name") or "its platform")


def shared_panels(
    a: Path, b: Path, sa: dict[str, tuple[np.ndarray, np.ndarray]], sb: dict[str, tuple[np.ndarray, np.ndarray]]
) -> tuple[list[str], list[str]]:
    """The envelope quantities both recordings hold (compared), and one line for each recording that lacks some the
    other holds (the Atlas's wheels, say, beside a hexapod's recording, which has none): what is left out, and why."""
    have = {p: [q for q, _, _ in ENVELOPE_QUANTITIES if f"/envelope/{q}" in s] for p, s in ((a, sa), (b, sb))}
    shared = [q for q in have[a] if q in have[b]]
    notes = []
    for this, other in ((a, b), (b, a)):
        lacks = [q for q in have[other] if q not in have[this]]
        if lacks:
            notes.append(f"{this} ({_platform(this)}) has no {' or '.join(lacks)} envelope panel, which {other} "
                         f"({_platform(other)}) has: compared without it")  # fmt: skip
    return shared, notes


def write_comparison(a: Path, b: Path, out: Path) -> list[str]:
    """Write the comparison recording of ``a`` and ``b`` to ``out`` (see the module docstring). Returns what was
    left out, one line each: the envelope panels one recording lacks (two platforms: :func:`shared_panels`)."""
    la, lb = comparison_labels(a, b)
    sa, sb = read_scalar_series(a), read_scalar_series(b)
    for key in (f"/{prefix}/{dof}" for prefix in ("perceived", "raw") for dof, _, _, _ in DOFS):
        for path, s in ((a, sa), (b, sb)):
            if key not in s:
                raise WashbenchError(located(path, f"not a washbench recording (no {key})"))
    envelope, notes = shared_panels(a, b, sa, sb)
    key = "/perceived/surge"
    ta, tb = sa[key][0], sb[key][0]
    if abs(ta[0] - tb[0]) > 1e-9 or abs(ta[-1] - tb[-1]) > 1e-9:
        raise WashbenchError(
            located(b, f"its time axis ({tb[0]:.3f}-{tb[-1]:.3f} s) differs from {a}'s ({ta[0]:.3f}-{ta[-1]:.3f} s): "
                    "compare recordings of the same manoeuvre")
        )  # fmt: skip
    rec = rr.RecordingStream("washbench-compare", recording_id=uuid.uuid4(), send_properties=False)
    if not rec.is_enabled():
        raise WashbenchError("rerun logging is disabled by the environment (RERUN=off): unset RERUN to compare")
    t_end_ns = round(float(ta[-1]) * 1e9)
    whole = rrb.TimeRange(
        start=rrb.TimeRangeBoundary.absolute(nanos=0), end=rrb.TimeRangeBoundary.absolute(nanos=t_end_ns)
    )
    axis = rrb.TimeAxis(link="Independent", view_range=whole)

    def panel(origin: str, name: str, legend: bool = False) -> rrb.TimeSeriesView:
        return rrb.TimeSeriesView(origin=origin, name=name, axis_x=axis, plot_legend=rrb.PlotLegend(visible=legend))

    perceived = [panel(f"/perceived/{d}", f"perceived {d} [{u}]") for d, _, _, u in DOFS]
    raw = [panel(f"/raw/{d}", f"{d} [{u}]") for d, _, _, u in DOFS]
    usage = [panel(f"/envelope/{q}", f"{q}: max |axis| / limit") for q in envelope]
    legend = rrb.TimeSeriesView(
        origin="/legend", name="Legend", axis_x=axis, axis_y=rrb.ScalarAxis(range=(1.0, 2.0)),
        plot_legend=rrb.PlotLegend(corner="LeftTop", visible=True),
    )  # fmt: skip
    lanes = rrb.StateTimelineView(origin="/lanes", name="Phases", time_view=axis)
    blueprint = rrb.Blueprint(
        rrb.Horizontal(
            rrb.Tabs(
                rrb.Vertical(lanes, *perceived, row_shares=[1.8] + [2.0] * 6, name=f"Perceived: {la} vs {lb}"),
                rrb.Vertical(*raw, name="Raw motion"),
                rrb.Vertical(*usage, name="Platform envelope"),
            ),
            rrb.Vertical(
                legend,
                rrb.Tabs(
                    rrb.TextDocumentView(origin="/metrics/a", name=f"Metrics {la}"),
                    rrb.TextDocumentView(origin="/metrics/b", name=f"Metrics {lb}"),
                ),
                row_shares=[1, 2],
            ),
            column_shares=[3, 1.4],
        ),
        rrb.BlueprintPanel(state="collapsed"),
        rrb.SelectionPanel(state="collapsed"),
        rrb.TimePanel(state="collapsed", timeline=TIMELINE),
    )
    with atomic_path(out) as tmp:
        rrd = RrdFile(rec, tmp, blueprint)
        try:
            rec.send_recording_name(f"{la} vs {lb}")
            rec.send_property("compared", rr.AnyValues(a=str(a), b=str(b), label_a=la, label_b=lb))
            for prefix in ("perceived", "raw"):
                for dof, _, _, _ in DOFS:
                    lines = _send_pair(rec, f"/{prefix}/{dof}", (a, sa, la), (b, sb, lb))
                    if prefix == "perceived" and dof == "surge":
                        _send_legend(rec, ta, *lines)
                    threshold = f"/perceived/{dof}/threshold"
                    if prefix == "perceived" and threshold in sa:
                        t_th, v_th = sa[threshold]
                        grey = rr.SeriesLines(colors=[(128, 128, 128)] * 2, names=["perception threshold"] * 2)
                        rec.log(threshold, grey, static=True)
                        rec.send_columns(threshold, indexes=[_time(t_th)], columns=rr.Scalars.columns(scalars=v_th))
            for q in envelope:
                _send_pair(rec, f"/envelope/{q}", (a, sa, la), (b, sb, lb), aircraft=False, aggregation="Max")
            phases = read_component(a, "StateChange:state").get(phase_lane_path())
            if phases is not None:
                t_ph, states = phases
                lane = rr.StateChange.columns(state=[str(x) for x in states])
                rec.send_columns("/lanes/phase", indexes=[_time(t_ph)], columns=lane)
            for sub, path in (("a", a), ("b", b)):
                doc = read_text_documents(path).get("/metrics", "")
                rec.log(f"/metrics/{sub}", rr.TextDocument(doc, media_type=rr.MediaType.MARKDOWN), static=True)
            rrd.close()
        except BaseException:
            rrd.abandon()
            raise
    return notes


def _send_legend(
    rec: rr.RecordingStream, t_s: np.ndarray, names: list[str], colors: list[tuple[int, int, int]], widths: list[float]
) -> None:
    """The one legend, in a panel of its own (its lines lie outside the panel's y range)."""
    rec.log("/legend", rr.SeriesLines(colors=colors, names=names, widths=widths), static=True)
    rec.send_columns(
        "/legend", indexes=[_time(t_s[[0, -1]])], columns=rr.Scalars.columns(scalars=np.zeros((2, len(names))))
    )


def _send_pair(
    rec: rr.RecordingStream,
    entity: str,
    a: tuple[Path, dict[str, tuple[np.ndarray, np.ndarray]], str],
    b: tuple[Path, dict[str, tuple[np.ndarray, np.ndarray]], str],
    *,
    aircraft: bool = True,
    aggregation: str | None = None,
) -> tuple[list[str], list[tuple[int, int, int]], list[float]]:
    """One entity holding A's lines and B's: the aircraft once if both flights agree, then A's and B's washouts."""
    (pa, sa, la), (pb, sb, lb) = a, b
    names_a, ta, va, tol_a = _columns(pa, entity, sa)
    names_b, tb, vb, tol_b = _columns(pb, entity, sb)
    t_ns = np.union1d(ta, tb)  # each line interpolated from its own samples: the same line, drawn on both's times

    def line_a(i: int) -> np.ndarray:
        return np.interp(t_ns, ta, va[:, i])

    def line_b(i: int) -> np.ndarray:
        return np.interp(t_ns, tb, vb[:, i])

    washouts_a = [n for n in names_a if n != AIRCRAFT]
    washouts_b = [n for n in names_b if n != AIRCRAFT]
    names, colors, widths, cols, tols = [], [], [], [], []
    for w in washouts_a:
        names.append(f"{la}: {w}")
        colors.append(series_color(w, washouts_a))
        widths.append(WASHOUT_WIDTH)
        cols.append(line_a(names_a.index(w)))
        tols.append(tol_a[names_a.index(w)])
    for w in washouts_b:
        names.append(f"{lb}: {w}")
        colors.append(_washed(series_color(w, washouts_b)))
        widths.append(WASHOUT_WIDTH)
        cols.append(line_b(names_b.index(w)))
        tols.append(tol_b[names_b.index(w)])
    n_washouts = len(names)
    if aircraft and AIRCRAFT in names_a:  # last: the viewer draws it on top of the washouts (as in a recording)
        i_a = names_a.index(AIRCRAFT)
        ac_a = line_a(i_a)
        same = AIRCRAFT not in names_b
        if not same:
            i_b = names_b.index(AIRCRAFT)
            ac_b = line_b(i_b)
            same = bool(np.all(np.abs(ac_a - ac_b) <= tol_a[i_a] + tol_b[i_b] + 1e-12 * np.abs(ac_a)))
        names += ["aircraft"] if same else [f"{la}: aircraft", f"{lb}: aircraft"]
        colors += [series_color(AIRCRAFT)] if same else [series_color(AIRCRAFT), _washed(series_color(AIRCRAFT))]
        widths += [AIRCRAFT_WIDTH] if same else [AIRCRAFT_WIDTH, AIRCRAFT_WIDTH]
        cols += [ac_a] if same else [ac_a, ac_b]
        tols += [tol_a[i_a]] if same else [tol_a[i_a], tol_b[i_b]]
    style = rr.SeriesLines(colors=colors, names=names, widths=widths, aggregation_policy=aggregation)
    rec.log(entity, style, rr.AnyValues(interpolation_tolerance=np.array(tols)), static=True)
    time = rr.TimeColumn(TIMELINE, duration=t_ns.astype("timedelta64[ns]"))
    rec.send_columns(entity, indexes=[time], columns=rr.Scalars.columns(scalars=np.column_stack(cols)))
    legend = list(range(n_washouts, len(names))) + list(range(n_washouts))  # the legend: the aircraft first
    return [names[i] for i in legend], [colors[i] for i in legend], [widths[i] for i in legend]
