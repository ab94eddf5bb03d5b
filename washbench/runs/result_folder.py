"""A result folder of one flight or recorded trace (``run``, ``cue``, a suite's runs): what it says and how its
files besides the traces are written.

* :class:`RunSummary`: what one result gave (status, metrics, motion per DOF, saturations): ``run.json``
  (:func:`write_run_json`) and what a suite compares;
* :func:`run_dir`: where a run's folder goes (``OUT/<aircraft>/<manoeuvre>``), marked by ``run.json``
  (:data:`RUN_MARKER`);
* :func:`write_run_recording`: ``recording.rrd`` (the one call of the recording writer);
* :func:`write_run_review`: ``ranking.csv`` (:func:`ranking_table`) and ``report.md`` with its figures.

The file names are :mod:`washbench.io.result_files`'s; traces.parquet and metrics.csv are written by the chain
(:mod:`washbench.runs.chain`).
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from washbench.analysis.felt import FELT_PREFIX
from washbench.analysis.ranking import (
    DEFAULT_RULE,
    DOFS,
    RankRow,
    RankRule,
    perceived_motion,
    rank,
    rule_from_record,
)
from washbench.io.atomic import write_text_atomic
from washbench.io.csv_numbers import csv_number
from washbench.io.metrics_csv import MetricRow
from washbench.io.publish import read_marker, result_path
from washbench.io.readback import json_text
from washbench.io.result_files import RANKING_FILE, RUN_FILE
from washbench.platform.limits import wheel_jacobian
from washbench.review.metrics_table import metrics_table_markdown
from washbench.review.report import write_result_report

if TYPE_CHECKING:
    from washbench.io.motion import Motion
    from washbench.platform import PlatformLimits
    from washbench.review.rerun_log import PlatformEnvelope
    from washbench.runs.chain import CueResult


@dataclass(frozen=True)
class RunSummary:
    """What one ``washbench run`` gave: status, where, and what the suite needs to compare.

    A run that could not start (bad file) or broke has only ``ok`` False and the ``reason``.
    """

    ok: bool
    reason: str = ""
    aircraft: str = ""
    manoeuvre: str = ""
    run_dir: Path | None = None
    steps: int = 0
    dt_s: float = 0.0
    checks_passed: int = 0
    checks_total: int = 0
    metrics: list[MetricRow] = field(default_factory=list)
    motion: dict[str, float] = field(default_factory=dict)  # DOF -> aircraft pilot's perceived motion
    saturations: dict[str, dict[str, int]] = field(default_factory=dict)


def metrics_markdown(
    title: str,
    rows: list[MetricRow],
    motion: Mapping[str, float] | None = None,
    rule: RankRule = DEFAULT_RULE,
    ceiling: Mapping[str, Any] | None = None,
) -> str:
    """The ranking (when ``motion``, the aircraft pilot's perceived motion per DOF, is given; with the ceiling when
    ``ceiling``, run.json's ``bound`` record, is) and the metric tables of one run as Markdown, washout by DOF (for
    the recording's Metrics panel)."""
    ranking = rank(rows, motion, rule) if motion is not None else []
    return metrics_table_markdown(title, rows, ranking, rule.label(), ceiling)


#: The file that marks a folder as a ``washbench run`` result (only such a folder is ever replaced).
RUN_MARKER = RUN_FILE


def run_dir(out_root: Path, aircraft: str, manoeuvre: str) -> Path:
    """``OUT/<aircraft>/<manoeuvre>``, proven inside ``out_root`` (both names are identifiers)."""
    return result_path(out_root, aircraft, manoeuvre)


def run_marker(aircraft: str, manoeuvre: str) -> dict[str, object]:
    """What a manoeuvre's run.json must say for its folder to be replaced by a new run of it."""
    return {"aircraft": aircraft, "manoeuvre": manoeuvre}


def write_run_json(path: Path, s: RunSummary, wall_s: float, extra: dict[str, object] | None = None) -> None:
    """``run.json``: the summary of one result folder (``extra``: more keys, e.g. what ``cue`` read)."""
    doc: dict[str, object] = {
        "aircraft": s.aircraft,
        "manoeuvre": s.manoeuvre,
        "ok": s.ok,
        "reason": s.reason,
        "steps": s.steps,
        "dt_s": s.dt_s,
        "wall_s": round(wall_s, 3),
        "checks_passed": s.checks_passed,
        "checks_total": s.checks_total,
        "perceived_motion": {
            d: {"value": v, "unit": "m/s^2*s" if d.removeprefix(FELT_PREFIX) in DOFS[:3] else "deg"}
            for d, v in s.motion.items()
        },
        "saturations": s.saturations,
    }
    doc |= extra or {}
    write_text_atomic(path, json_text(doc))  # (a value that is not finite: null, as the reader reads it)


def write_run_recording(
    path: Path,
    title: str,
    motion: Motion,
    result: CueResult,
    limits: PlatformLimits,
    aircraft_q: np.ndarray,
    phases: list[tuple[str, float, float]],
    properties: dict[str, str] | None = None,
    rule: RankRule = DEFAULT_RULE,
    ceiling: Mapping[str, Any] | None = None,
    tilt_limits: Mapping[str, float | None] | None = None,
) -> None:
    """The recording of one result folder (``run`` and ``cue`` alike): the one call of the recording writer.

    ``aircraft_q`` (N, 4) the aircraft's attitude, body -> NED, scalar first; ``phases`` (name, start, end) [s];
    ``properties``: the provenance as flat strings (:func:`washbench.io.provenance.flat_strings`); ``ceiling``:
    run.json's ``bound`` record (:func:`washbench.runs.bound_stage.bound_outputs`), when the bound ran;
    ``tilt_limits``: washout -> its tilt-rate limit, rad/s, or None (:func:`washbench.cueing.variants.
    tilt_rate_limit_radps`), drawn under the tilt rates the traces hold (``tilt_rate_radps``).
    """
    from washbench.review.rerun_log import (  # deferred: rerun
        HexapodDrawing,
        MotionSeries,
        PlatformSeries,
        RecordingData,
        write_recording,
    )

    ac = result.perceived["aircraft"]
    washouts: dict[str, MotionSeries] = {}
    platforms: dict[str, PlatformSeries] = {}
    for name, tr in result.traces.items():
        p = result.perceived[name]
        washouts[name] = MotionSeries(
            f_mps2=tr.head_f_mps2,
            omega_radps=tr.head_omega_radps,
            perceived_f_mps2=p.f_mps2,
            perceived_omega_radps=p.omega_radps,
            q=tr.q,
        )
        wheels = tr.wheel_radps if np.shape(tr.wheel_radps)[1:] == (3,) else np.zeros((len(tr.pos_m), 3))  # (unused)
        platforms[name] = PlatformSeries(
            pos_m=tr.pos_m, vel_mps=tr.vel_mps, acc_mps2=tr.acc_mps2, wheel_radps=wheels, saturated=tr.saturated,
            tilt_rate_radps=getattr(tr, "tilt_rate_radps", None),
            tilt_rate_limit_radps=(tilt_limits or {}).get(name),
        )
    hexapod = None
    kind = getattr(limits, "kind", "atlas")
    if kind == "hexapod":
        hexapod = HexapodDrawing(np.asarray(limits.base_joints_m), np.asarray(limits.platform_joints_m),
                                 np.asarray(limits.neutral_m))  # fmt: skip
    data = RecordingData(
        title=title,
        t_s=motion.t_s,
        aircraft=MotionSeries(
            f_mps2=motion.f_mps2,
            omega_radps=motion.omega_radps,
            perceived_f_mps2=ac.f_mps2,
            perceived_omega_radps=ac.omega_radps,
            q=aircraft_q,
        ),
        washouts=washouts,
        platforms=platforms,
        envelope=platform_envelope(limits),
        phases=[(p[0], float(p[1]), float(p[2])) for p in phases],
        metrics_markdown=metrics_markdown(title, list(result.metrics),
                                          perceived_motion(ac.f_mps2, ac.omega_radps, float(motion.dt_s),
                                                           rule.measure), rule,
                                          ceiling),
        hexapod=hexapod,
        platform=kind,
        platform_name=platform_title(limits),
    )
    write_recording(path, data, properties)


def platform_title(limits: Any) -> str:
    """The word the recording's tab and view titles use for the platform: Atlas, Hexapod, Rig, or a plugin's kind."""
    kind = str(getattr(limits, "kind", "atlas"))
    return {"atlas": "Atlas", "hexapod": "Hexapod", "rig": "Rig"}.get(kind, kind)


def platform_envelope(limits: Any) -> PlatformEnvelope:
    """The recording's envelope lines from the platform limits: the Atlas's stage, wheels (the wheel limit from the
    rate limit) and sphere rate; a hexapod's box about neutral
    (:meth:`washbench.platform.hexapod.HexapodModel.envelope`), no wheels, the base's diameter; a rig's angle stops
    and its heave's limits (none without heave); a plugin's platform its ``envelope`` box when it has one (nothing
    otherwise: its motion is drawn without limit lines)."""
    from washbench.review.rerun_log import PlatformEnvelope  # deferred: rerun

    kind = getattr(limits, "kind", "atlas")
    if kind == "hexapod":
        box = limits.envelope().translation
        radius = float(np.max(np.linalg.norm(np.asarray(limits.base_joints_m)[:, :2], axis=1)))
        return PlatformEnvelope(pos_m=box.position_limit_m.xyz, vel_mps=box.velocity_limit_mps.xyz,
                                acc_mps2=box.acceleration_limit_mps2.xyz, wheel_radps=None,
                                sphere_diameter_m=2.0 * radius)  # fmt: skip
    if kind == "rig":
        h = limits.heave
        angles = tuple(math.radians(a.angle_limit_deg) if a is not None else math.inf
                       for a in (limits.roll, limits.pitch, limits.yaw))  # fmt: skip
        tiny = 1e-3  # the rig's horizontal axes do not move (as its envelope() for planning)
        return PlatformEnvelope(
            pos_m=(tiny, tiny, h.position_limit_m) if h else None,
            vel_mps=(tiny, tiny, h.velocity_limit_mps) if h else None,
            acc_mps2=(tiny, tiny, h.acceleration_limit_mps2) if h else None,
            wheel_radps=None,
            sphere_diameter_m=2.0,
            angle_rad=angles,  # type: ignore[arg-type]
        )
    if kind != "atlas":  # a plugin's platform
        env = limits.envelope()
        if env is None:
            return PlatformEnvelope(pos_m=None, vel_mps=None, acc_mps2=None, wheel_radps=None, sphere_diameter_m=2.0)
        t = env.translation
        return PlatformEnvelope(pos_m=t.position_limit_m.xyz, vel_mps=t.velocity_limit_mps.xyz,
                                acc_mps2=t.acceleration_limit_mps2.xyz, wheel_radps=None,
                                sphere_diameter_m=2.0)  # fmt: skip

    t = limits.translation
    jac = wheel_jacobian(limits)
    # the fastest any wheel can turn with the sphere at its angular-rate limit
    wheel_max = float(np.max(np.linalg.norm(jac, axis=1)) * math.radians(limits.rotation.rate_limit_degps))
    return PlatformEnvelope(
        pos_m=t.position_limit_m.xyz,
        vel_mps=t.velocity_limit_mps.xyz,
        acc_mps2=t.acceleration_limit_mps2.xyz,
        wheel_radps=wheel_max,
        sphere_diameter_m=limits.sphere_diameter_m,
        rate_radps=math.radians(limits.rotation.rate_limit_degps),
    )


def csv_text(rows: list[list[str]]) -> str:
    buf = io.StringIO()
    csv.writer(buf, lineterminator="\n").writerows(rows)
    return buf.getvalue()


def ranking_table(rankings: dict[tuple[str, str], list[RankRow]], rule: RankRule = DEFAULT_RULE) -> str:
    """``ranking.csv``: rank, washout and the rule's value (``score``, lower is better) per manoeuvre; ``tied``
    (true when the rank is shared: values within the tie margin) and ``rule`` (``--rank-by``)."""
    rows = [["aircraft", "manoeuvre", "rank", "washout", "score", "tied", "rule"]]
    for (aircraft, manoeuvre), ranking in rankings.items():
        for r in ranking:
            tied = "true" if r.tied else "false"
            place = str(r.rank) if r.rank else ""  # empty: the oracle bound, scored but not ranked
            rows.append([aircraft, manoeuvre, place, r.washout, csv_number(r.score), tied, rule.by])
    return csv_text(rows)


def write_run_review(
    run_dir: Path,
    summary: RunSummary,
    source: str = "",
    table: Mapping[str, Any] | None = None,
    figures: bool = True,
    recording: bool | None = None,
) -> None:
    """``ranking.csv`` and ``report.md`` of one result folder (the same tables as a suite's, for one run).

    The one call site for a result folder's report (``washbench run`` and ``washbench cue``); the report and its
    figures are built from the folder's files (:func:`washbench.review.report.write_result_report`), with the
    traces.parquet columns taken from ``table`` when the caller still holds them; ``figures=False``: none drawn;
    ``recording``: whether the report links recording.rrd (None: whether the folder holds one now).
    """
    prov = (read_marker(run_dir, RUN_MARKER) or {}).get("provenance")
    rule = rule_from_record(prov.get("ranking") if isinstance(prov, dict) else None)
    rankings = (
        {(summary.aircraft, summary.manoeuvre): rank(summary.metrics, summary.motion, rule)} if summary.metrics else {}
    )
    write_text_atomic(run_dir / RANKING_FILE, ranking_table(rankings, rule))
    write_result_report(run_dir, table, figures=figures, recording=recording)


