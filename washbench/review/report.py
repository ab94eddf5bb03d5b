"""report.md and its figures, for one result folder and for a suite, from the files alone.

- :func:`write_result_report` (``washbench run`` writes it into every result folder; ``washbench report DIR`` writes
  it again): ``report.md`` and ``figures/`` (perceived motion, platform envelope; PNG embedded, PDF beside it).
- :func:`write_suite_report` (``washbench suite``; ``washbench report SUITE_DIR``): the suite's ``report.md`` with
  the failures first, the summary, the score heatmap and the Table-4 figure (``figures/``), then each manoeuvre's
  section built by the same code as the single result's report.

Nothing is flown or cued again: everything comes from ``metrics.csv``, ``traces.parquet``, ``run.json`` and
``flight.json`` (see :mod:`washbench.review.result_data`) and, for a suite, ``suite.json``. Numbers have 3
significant digits (:mod:`washbench.review.numbers`; full precision is in the CSV files); the best value of each
DOF is bold; a score above 1 is flagged; saturation is in seconds and percent of the manoeuvre.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from washbench.analysis.metrics import DOFS
from washbench.analysis.ranking import METRICS, RankRow, compare, rank, reference_washout
from washbench.errors import WashbenchError, located
from washbench.io.atomic import write_text_atomic
from washbench.review.numbers import pct, sig
from washbench.review.result_data import ResultData, is_result_folder, load_result

REPORT_FILE = "report.md"
FIGURES_DIR = "figures"
SUITE_FILE = "suite.json"

FLAG = "⚠"
SCORE_NOTE = (
    f"{FLAG} a score above 1: the washout's perceived error is larger than that of a simulator that stands still, "
    "i.e. it gives more false cues than it gives true ones on this manoeuvre."
)
_UNITS = {
    "npc": ("-", "-"),
    "integral_error": ("m/s²·s", "deg"),
    "max_error": ("m/s²", "deg/s"),
}
_METRIC_TITLES = {
    "npc": "Normalized Pearson correlation (NPC: 1 is perfect, 1.5 uncorrelated, lower is better; - where flat)",
    "integral_error": "Integral of |perceived error| (lower is better)",
    "max_error": "Maximum |perceived error| (lower is better)",
}


def _unit(metric: str, dof: str) -> str:
    return _UNITS[metric][0 if dof in DOFS[:3] else 1]


def _rel(path: Path, start: Path) -> str:
    return Path(os.path.relpath(path, start)).as_posix()


# --------------------------------------------------------------------------------------------- pieces of a report


def provenance_lines(prov: dict[str, Any] | None, created_utc: str | None) -> list[str]:
    """The provenance as a two-column Markdown table (what produced the result)."""
    if not prov:
        return ["_No provenance recorded with this result (written by an older washbench)._", ""]
    rows: list[tuple[str, str]] = []

    def file_row(label: str, rec: dict[str, Any] | None) -> None:
        if rec:
            name = f"**{rec['name']}**, " if rec.get("name") else ""
            rows.append((label, f"{name}`{rec.get('path', '?')}` (SHA-256 `{rec.get('sha256', '?')}`)"))

    file_row("manoeuvre file", prov.get("manoeuvre"))
    file_row("aircraft model", prov.get("aircraft"))
    file_row("pilot profile", prov.get("pilot_profile"))
    inp = prov.get("input")
    file_row("input trace", inp)
    if inp and (inp.get("provenance") or {}).get("manoeuvre"):
        file_row("input's manoeuvre file", inp["provenance"]["manoeuvre"])
    file_row("washout parameters", prov.get("params"))
    if prov.get("washouts"):
        runs = [
            f"{w['name']}" + ("" if w["name"] == w["kind"] else f" ({w['kind']})") + (" with its own values" if "values"
            in w else "") for w in prov["washouts"]
        ]  # fmt: skip
        rows.append(("washouts", ", ".join(runs)))
    file_row("platform", prov.get("platform"))
    if "turbulence" in prov or (inp and "turbulence" in (inp.get("provenance") or {})):
        turb = prov.get("turbulence", (inp.get("provenance") or {}).get("turbulence") if inp else None)
        rows.append(("turbulence", f"{turb['severity']}, seed {turb['seed']}" if turb else "none"))
    sw = prov.get("software") or {}
    parts = [
        f"washbench {sw.get('washbench', '?')}"
        + (f" (git `{_short_commit(sw['washbench_git'])}`)" if sw.get("washbench_git") else "")
    ]
    parts += [f"{label} {sw[key]}" for key, label in (("jsbsim", "JSBSim"), ("rerun", "rerun-sdk"), ("numpy", "numpy"),
                                                      ("scipy", "scipy"), ("pyarrow", "pyarrow"), ("python", "Python"))
              if key in sw]  # fmt: skip
    rows.append(("software", ", ".join(parts)))
    if created_utc:
        rows.append(("created", created_utc))
    return ["| provenance | |", "|---|---|", *(f"| {k} | {v} |" for k, v in rows), ""]


def _short_commit(commit: str) -> str:
    """``1cc4a4c2678f3a99...-dirty`` -> ``1cc4a4c2678f-dirty``."""
    head, dash, rest = commit.partition("-")
    return head[:12] + dash + rest


def _score_cell(score: float, best: bool) -> str:
    text = sig(score)
    if best:
        text = f"**{text}**"
    return f"{text} {FLAG}" if score > 1.0 else text


def ranking_lines(data: ResultData, ranking: list[RankRow]) -> list[str]:
    """Ranking table (rank, washout, score) and the DOF weights used."""
    if not ranking:
        return []
    lines = ["| rank | washout | score (-) |", "|---|---|---|"]
    lines += [f"| {r.rank} | {r.washout} | {_score_cell(r.score, r.rank == 1)} |" for r in ranking]
    weights = ranking[0].weights
    lines += [
        "",
        "Score: sum over DOFs of weight x integral error / the aircraft pilot's own perceived motion in that DOF (0 "
        "perfect, 1 no better than standing still). Weights: "
        + ", ".join(f"{d} {sig(weights[d], 2)}" for d in DOFS)
        + ".",
    ]
    if any(r.score > 1.0 for r in ranking):
        lines += ["", SCORE_NOTE]
    return [*lines, ""]


def metric_tables(data: ResultData) -> list[str]:
    """Per metric a DOF-by-washout table: values, the best per DOF bold, each washout against the reference (%).

    The reference is small-angle when it ran, otherwise the first washout listed (:func:`reference_washout`).
    """
    reference = reference_washout(data.washouts)
    comparison = {(c.dof, c.metric): c for c in compare(data.metrics, reference)}
    dofs = [d for d in DOFS if any((d, m) in comparison for m in METRICS)]
    others = [w for w in data.washouts if w != reference]
    lines: list[str] = []
    for metric in METRICS:
        lines += [f"**{_METRIC_TITLES[metric]}**", ""]
        lines.append("| washout | " + " | ".join(f"{d} ({_unit(metric, d)})" for d in dofs) + " |")
        lines.append("|---|" + "---|" * len(dofs))
        for w in data.washouts:
            cells = []
            for d in dofs:
                values = comparison[(d, metric)].values
                v = values.get(w, math.nan)
                finite = [x for x in values.values() if math.isfinite(x)]
                best = bool(finite) and math.isfinite(v) and v == min(finite) and len(finite) > 1
                cells.append(f"**{sig(v)}**" if best else sig(v))
            lines.append(f"| {w} | " + " | ".join(cells) + " |")
        for w in others:
            cells = []
            for d in dofs:
                c = comparison[(d, metric)]
                ref = c.values.get(reference, math.nan)
                diff = c.better_than_reference.get(w, math.nan)
                cells.append(pct(100.0 * diff / ref) if math.isfinite(diff) and ref != 0 else "-")
            lines.append(f"| {w} vs {reference} (% better) | " + " | ".join(cells) + " |")
        if metric == "integral_error":
            lines.append(
                "| _standing still (aircraft pilot's perceived motion)_ | "
                + " | ".join(sig(data.motion.get(d, math.nan)) for d in dofs)
                + " |"
            )
        if metric == "max_error":
            above = time_above_threshold(data)
            lines.append(
                "| _aircraft pilot beyond the perception threshold (s)_ | "
                + " | ".join(sig(above[d]) for d in dofs)
                + " |"
            )
        lines.append("")
    return lines


def saturation_lines(data: ResultData) -> list[str]:
    """Time at each limit per washout, in seconds and percent of the manoeuvre."""
    from washbench.review.figures import SATURATION_LABELS

    kinds = list(dict.fromkeys(k for w in data.washouts for k, f in data.saturated.get(w, {}).items() if f.any()))
    if not kinds:
        return ["No platform or washout limit was reached.", ""]
    head = "| limit | " + " | ".join(f"{w} (s, % of manoeuvre)" for w in data.washouts) + " |"
    lines = [head, "|---|" + "---|" * len(data.washouts)]
    for k in kinds:
        cells = []
        for w in data.washouts:
            flags = data.saturated.get(w, {}).get(k)
            steps = int(np.count_nonzero(flags)) if flags is not None else 0
            cells.append("-" if not steps else f"{sig(steps * data.dt_s)} s ({pct(100.0 * steps / data.n, False)})")
        lines.append(f"| {SATURATION_LABELS.get(k, k)} (`{k}`) | " + " | ".join(cells) + " |")
    return [*lines, ""]


def check_lines(data: ResultData) -> list[str]:
    """The manoeuvre's checks (flight.json): measured value, limits, passed."""
    if not data.checks:
        return []
    lines = ["| check | measured | limits | result |", "|---|---|---|---|"]
    for c in data.checks:
        measured = c.get("measured")
        m = "-" if measured is None else sig(float(measured), 4)
        result = "ok" if c.get("passed") else "**FAILED**"
        lines.append(f"| {c.get('name', '')} | {m} | {c.get('limit', '')} | {result} |")
    return [*lines, ""]


def perception_thresholds() -> tuple[tuple[float, ...], tuple[float, ...]]:
    """Zacharias thresholds and the resting values they are taken around, per DOF (m/s^2, deg/s)."""
    from washbench.perception.thresholds import STANDARD_GRAVITY_MPS2, ZACHARIAS

    th = ZACHARIAS
    thresholds = (th.f_x_mps2, th.f_y_mps2, th.f_z_mps2, th.omega_x_degps, th.omega_y_degps, th.omega_z_degps)
    return thresholds, (0.0, 0.0, -STANDARD_GRAVITY_MPS2, 0.0, 0.0, 0.0)


def time_above_threshold(data: ResultData) -> dict[str, float]:
    """Per DOF, how long the aircraft pilot's perceived motion lies beyond the perception threshold [s]."""
    thresholds, rest = perception_thresholds()
    p = data.perceived["aircraft"]
    return {
        d: float(np.count_nonzero(np.abs(p[:, i] - rest[i]) > thresholds[i])) * data.dt_s for i, d in enumerate(DOFS)
    }


def result_figures(data: ResultData, pdf: bool = False, into: Path | None = None) -> dict[str, Path]:
    """Draw the result's figures into ``into/figures/`` (a new folder; ``into`` is the result folder by default;
    PNG, and PDF with ``pdf``); figure name -> PNG path."""
    from washbench.review.figures import envelope_figure, perceived_figure

    fig_dir = (into or data.folder) / FIGURES_DIR
    fig_dir.mkdir(exist_ok=True)
    formats = ("png", "pdf") if pdf else ("png",)
    thresholds, rest = perception_thresholds()
    out = {}
    out["perceived"] = perceived_figure(
        fig_dir / "perceived",
        data.title,
        data.t_s,
        data.perceived,
        phases=data.phases,
        thresholds=thresholds,
        rest=rest,
        formats=formats,
    )[0]
    if data.usage:
        out["envelope"] = envelope_figure(
            fig_dir / "envelope", data.title, data.t_s, data.usage, data.saturated, phases=data.phases, formats=formats
        )[0]
    return out


NO_FIGURES = "_No figures were drawn (`--no-figures`): `washbench report` on this folder draws them from its files._"


def _image(png: Path, start: Path, alt: str, vector: bool | None = None) -> list[str]:
    """The figure embedded, and its PDF linked when there is one (``vector``: whether there is, when the figure is
    still in a stage; else how to get it)."""
    rel = _rel(png, start)
    pdf = Path(rel).with_suffix(".pdf")
    if png.with_suffix(".pdf").is_file() if vector is None else vector:
        return [f"![{alt}]({rel})", "", f"Vector version for papers: [{pdf.name}]({pdf.as_posix()})", ""]
    return [f"![{alt}]({rel})", "", "Vector versions for papers (PDF): `washbench report` on this folder.", ""]


def result_sections(
    data: ResultData, figures: dict[str, Path], start: Path, level: int, brief: bool = False, vector: bool | None = None
) -> list[str]:
    """The body of one result's report; links relative to ``start`` (the folder report.md is in).

    ``brief`` (the suite report): without the envelope figure, checks and phases (they are in the result's own
    report, which the suite report links).
    """
    h = "#" * level
    lines: list[str] = []
    ranking = rank(data.metrics, data.motion) if data.metrics else []
    lines += [f"{h} Ranking", "", *ranking_lines(data, ranking)]
    lines += [f"{h} Perceived motion", ""]
    lines += [
        "Aircraft pilot (magenta, wide) against each washout's simulator pilot; dashed: perception thresholds "
        "(Zacharias 1978) around the resting value, what lies between them is not felt; shaded: the phases.",
        "",
    ]
    lines += (
        _image(figures["perceived"], start, "perceived motion", vector) if "perceived" in figures else [NO_FIGURES, ""]
    )
    lines += [f"{h} Metrics", "", *metric_tables(data)]
    lines += [f"{h} Platform", ""]
    if brief:
        pass
    elif "envelope" in figures:
        lines += _image(figures["envelope"], start, "platform envelope", vector)
    elif not figures:
        pass
    else:
        lines += ["_No platform limits are recorded with this result: no envelope figure._", ""]
    lines += [f"Time at a limit ({sig(data.duration_s)} s manoeuvre):", "", *saturation_lines(data)]
    if data.checks and not brief:
        lines += [f"{h} Checks", "", *check_lines(data)]
    if data.phases and not brief:
        lines += [f"{h} Phases", "", "| phase | start (s) | end (s) |", "|---|---|---|"]
        lines += [f"| {n} | {t0:.2f} | {t1:.2f} |" for n, t0, t1 in data.phases]
        lines.append("")
    recording = data.folder / "recording.rrd"
    if recording.exists():
        rel = _rel(recording, start)
        lines += [f"Recording: [{rel}]({rel}) (`washbench replay {rel}`).", ""]
    return lines


def _status_line(data: ResultData) -> list[str]:
    if data.ok is False:
        return [f"> **FAILED**: {data.reason or 'a check failed'}", ""]
    return []


def write_result_report(
    result_dir: Path, table: Mapping[str, np.ndarray] | None = None, pdf: bool = False, figures: bool = True
) -> Path:
    """Write ``report.md`` and ``figures/`` for one result folder from its files; return the report's path.

    ``table``: the traces.parquet columns already in memory (not read again); ``pdf``: PDF figures besides the PNG;
    ``figures=False``: none drawn (``--no-figures``; figures of an earlier run in the folder are removed).
    """
    from washbench.io.outfolder import discard_stage, make_stage, replace_entries

    data = load_result(Path(result_dir), table, series=figures)
    stage = make_stage(data.folder)  # report.md and figures/ replace the previous ones together (links never followed)
    try:
        _write_result_report(data, stage, pdf, figures)
        replace_entries(data.folder, stage, [REPORT_FILE, FIGURES_DIR])
    finally:
        discard_stage(stage)
    return data.folder / REPORT_FILE


def _write_result_report(data: ResultData, stage: Path, pdf: bool, figures: bool) -> None:
    drawn = result_figures(data, pdf, into=stage) if figures else {}
    lines = [f"# {data.title}", "", *_status_line(data)]
    checks = f", checks {sum(bool(c.get('passed')) for c in data.checks)}/{len(data.checks)}" if data.checks else ""
    status = {True: "ok", False: "FAILED", None: "cued"}[data.ok]
    lines += [
        f"{status}{checks}; {sig(data.duration_s)} s, {data.n} samples at {sig(1.0 / data.dt_s)} Hz; "
        f"washouts: {', '.join(data.washouts)}.",
        "",
    ]
    lines += provenance_lines(data.provenance, data.created_utc)
    final = {k: data.folder / p.relative_to(stage) for k, p in drawn.items()}  # where they will be
    lines += result_sections(data, final, data.folder, 2, vector=pdf)
    write_text_atomic(stage / REPORT_FILE, "\n".join(lines).rstrip() + "\n")


def report_command(results_dir: Path) -> int:
    """``washbench report DIR``: write report.md and the figures (PNG and PDF) again from a result or suite folder's
    files."""
    from washbench.io.lock import output_lock
    from washbench.io.outfolder import recover

    folder = Path(results_dir)
    if not folder.is_dir():
        raise WashbenchError(located(folder, "no such folder"))
    with output_lock(folder):  # no other washbench command writes into it meanwhile
        recover(folder)
        if is_result_folder(folder) and not (folder / SUITE_FILE).exists():
            path = write_result_report(folder, pdf=True)
        else:
            from washbench.review.suite_report import write_suite_report

            path = write_suite_report(folder, regenerate_results=True)
    print(f"report: {path}")
    return 0
