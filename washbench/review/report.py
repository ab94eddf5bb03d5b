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

from washbench.analysis.cues import SCALE_BAND, dof_thresholds, parse_events
from washbench.analysis.metrics import DOFS
from washbench.analysis.ranking import (
    DEFAULT_RULE,
    METRICS,
    RankRow,
    RankRule,
    compare,
    rank,
    reference_washout,
    rule_from_record,
    undecided,
)
from washbench.io.atomic import write_text_atomic
from washbench.io.outfolder import discard_stage, make_stage, replace_entries
from washbench.io.result_files import FIGURES_DIR, RECORDING_FILE, REPORT_FILE
from washbench.review.bound_section import algorithm_lines, bound_lines
from washbench.review.cue_figures import cue_classes, cue_lane_figure
from washbench.review.felt_breakdown import felt_breakdown_lines
from washbench.review.figures import envelope_figure, perceived_figure, saturation_labels
from washbench.review.input_figure import input_section
from washbench.review.numbers import SCORE_FLAG, pct, sig
from washbench.review.result_data import ResultData, load_result

FLAG = SCORE_FLAG
SCORE_NOTE = (
    f"{FLAG} a value above 1: the washout's perceived error is larger than that of a simulator that stands still, "
    "i.e. it gives more false cues than it gives true ones on this manoeuvre."
)
_UNITS = {
    "npc": ("-", "-"),
    "integral_error": ("m/s²·s", "deg"),
    "max_error": ("m/s²", "deg/s"),
}
_METRIC_TITLES = {
    "npc": "Normalized Pearson correlation (NPC, lower is better: 1 perfect, 1.5 uncorrelated, above 1.5 "
    "anti-correlated, i.e. the cue moves against the aircraft's: 2.5 at a correlation of -0.5, infinite at -1; "
    "- where flat)",
    "integral_error": "Integral of |perceived error| (lower is better)",
    "max_error": "Maximum |perceived error| (lower is better)",
}


def _unit(metric: str, dof: str) -> str:
    return _UNITS[metric][0 if dof in DOFS[:3] else 1]


def _rel(path: Path, start: Path) -> str:
    return Path(os.path.relpath(path, start)).as_posix()


# --------------------------------------------------------------------------------------------- pieces of a report


def plugin_text(rec: dict[str, Any]) -> str:
    """What a plugin washout ran, for the report's provenance table (:func:`washbench.cueing.registry.identity`)."""
    where = rec.get("path") if rec.get("from") == "file" else rec.get("module")
    text = f"`{rec.get('object', '?')}` from {rec.get('from', '?')} `{where or '?'}`"
    if rec.get("distribution"):
        text += f" ({rec['distribution']} {rec.get('version', '?')})"
    if rec.get("sha256"):
        text += f" (SHA-256 `{rec['sha256']}`)"
    if rec.get("shadows"):
        text += f"; replaces the installed {rec['shadows']}"
    values = rec.get("values") or {}
    text += "; values " + (", ".join(f"`{k}={v}`" for k, v in values.items()) if values else "none")
    return text


def provenance_lines(prov: dict[str, Any] | None, created_utc: str | None) -> list[str]:
    """The provenance as a two-column Markdown table (what produced the result)."""
    if not prov:
        return ["_No provenance recorded with this result (written by an older washbench)._", ""]
    rows: list[tuple[str, str]] = []

    def file_row(label: str, rec: dict[str, Any] | None) -> None:
        if rec:
            name = f"**{rec['name']}**, " if rec.get("name") else ""
            shipped = f"bundled with {rec['bundled']}, " if rec.get("bundled") else ""
            rows.append((label, f"{name}`{rec.get('path', '?')}` ({shipped}SHA-256 `{rec.get('sha256', '?')}`)"))

    file_row("manoeuvre file", prov.get("manoeuvre"))
    file_row("aircraft model", prov.get("aircraft"))
    file_row("pilot profile", prov.get("pilot_profile"))
    inp = prov.get("input")
    file_row("input trace", inp)
    if inp and (inp.get("provenance") or {}).get("manoeuvre"):
        file_row("input's manoeuvre file", inp["provenance"]["manoeuvre"])
    file_row("washout parameters", prov.get("params"))
    defaults = (prov.get("params") or {}).get("defaults")
    if isinstance(defaults, dict) and defaults.get("sections"):
        rows.append(("parameters not in that file", ", ".join(f"`{k}`" for k in defaults["sections"])
                     + f" from `{defaults.get('path', '?')}` (SHA-256 `{defaults.get('sha256', '?')}`)"))  # fmt: skip
    if prov.get("washouts"):
        runs = [
            f"{w['name']}" + ("" if w["name"] == w["kind"] else f" ({w['kind']})") + (" with its own values" if "values"
            in w else "") for w in prov["washouts"]
        ]  # fmt: skip
        rows.append(("washouts", ", ".join(runs)))
        for w in prov["washouts"]:
            if isinstance(w.get("plugin"), dict):
                rows.append((f"plugin {w['name']}", plugin_text(w["plugin"])))
    file_row("platform", prov.get("platform"))
    file_row("configuration file", prov.get("config"))
    vest = prov.get("vestibular")
    if isinstance(vest, dict) and vest.get("model"):
        names = {"young-meiry": "Meiry-Young otolith, Young-Oman canals (the paper's)",
                 "telban-cardullo": "Telban-Cardullo otolith and canals (NASA CR-2005-213747)"}  # fmt: skip
        rows.append(("vestibular models", names.get(vest["model"], str(vest["model"]))))
        msi = (vest.get("sickness") or {}).get("msi") or {}
        if msi.get("model"):
            rows.append(("sickness models", "MSDV: ISO 2631-1 Wf; MSI: "
                         + ("6-DOF subjective vertical conflict, In1 (Inoue, Liu and Wada 2023)"
                            if msi["model"] == "6dof-svc-in1" else str(msi["model"]))))  # fmt: skip
    ranking = prov.get("ranking")
    if isinstance(ranking, dict) and ranking.get("by"):
        rows.append(("ranking rule", f"`--rank-by {ranking['by']}`"))
    if "turbulence" in prov or (inp and "turbulence" in (inp.get("provenance") or {})):
        turb = prov.get("turbulence", (inp.get("provenance") or {}).get("turbulence") if inp else None)
        seed = f", seed {turb['seed']}" if turb and turb.get("seed") is not None else ""
        rows.append(("turbulence", f"{turb['severity']}{seed}" if turb else "none"))
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


BOUND_NOTE = ("the bound (the best achieved: a motion searched for with the whole flight known), not ranked: an "
              "achieved motion, above the ceiling")  # fmt: skip


def result_rule(data: ResultData) -> RankRule:
    """The ranking rule a result was written with (its provenance's ``ranking``; the default before rules)."""
    prov = data.provenance
    return rule_from_record(prov.get("ranking") if isinstance(prov, dict) else None)


def rank_cell(r: RankRow) -> str:
    """A rank as shown: ``1`` or, when shared (a tie within the margin), ``1 (tie)``; ``-`` for the oracle bound
    (scored, not ranked)."""
    if r.rank < 1:
        return "-"
    return f"{r.rank} (tie)" if r.tied else str(r.rank)


END_STOP_SHARE = 0.05
"""Share of the manoeuvre at a stage position limit (an end stop) from which the report says, next to the score,
that the score reflects the end stop: the stage then stops hard, and the steps it makes in the simulator pilot's
specific force (up to the 1 g acceleration limit) are perceived errors the washout's filters did not make."""


def end_stop_note(data: ResultData, washout: str) -> str:
    """``end stop: stage at its position limit for 32.8 s (54 %)`` when that share reaches :data:`END_STOP_SHARE`,
    else empty."""
    flags = data.saturated.get(washout, {}).get("pos")
    steps = int(np.count_nonzero(flags)) if flags is not None else 0
    if not steps or steps < END_STOP_SHARE * data.n:
        return ""
    kind = platform_of(data)
    what = "stage at its position limit" if kind == "atlas" else f"at its {saturation_labels(kind)['pos']} limit"
    return (f"end stop: {what} for {sig(steps * data.dt_s)} s "
            f"({pct(100.0 * steps / data.n, False)}), the score reflects its hard stops")  # fmt: skip


_RULE_FORMULA = {
    "felt": "Felt error: per DOF, the perceived error beyond the perception thresholds, its false part once more and "
    "(surge, sway, heave) the jolts the platform adds, in threshold units, over the motion the aircraft pilot felt "
    "above threshold; summed with each DOF weighted by what the pilot felt there (0 perfect, 1 no better than "
    "standing still; docs/metrics.md).",
    "score": "Score: sum over DOFs of weight x integral error / the aircraft pilot's own perceived motion in that DOF "
    "(0 perfect, 1 no better than standing still).",
    "weighted": "Weighted: sum over DOFs of the parameter file's weight x integral error / the aircraft pilot's own "
    "perceived motion in that DOF (0 perfect, 1 no better than standing still).",
}
"""How each ranking rule's value is made, one sentence for the run report (its weights follow)."""


def ranking_lines(
    data: ResultData, ranking: list[RankRow], rule: RankRule = DEFAULT_RULE, explain: bool = True
) -> list[str]:
    """Ranking table (rank, washout, the rule's value, and a note where end stops dominate), the rule with its tie
    margin and the DOF weights used. ``explain=False`` (the suite report, which explains once): the weights only."""
    if not ranking:
        return []
    unit = {"false-cue": "false-cue time (DOF lengths)", "felt": "felt error (-)"}.get(rule.by, "score (-)")
    flag = rule.by != "false-cue"
    notes = {r.washout: end_stop_note(data, r.washout) for r in ranking}
    for r in ranking:
        if r.rank < 1:  # the oracle bound
            notes[r.washout] = "; ".join(x for x in (BOUND_NOTE, notes[r.washout]) if x)

    def value(r: RankRow) -> str:
        return _score_cell(r.score, r.rank == 1) if flag else sig(r.score)

    if any(notes.values()):
        lines = [f"| rank | washout | {unit} | note |", "|---|---|---|---|"]
        lines += [f"| {rank_cell(r)} | {r.washout} | {value(r)} | {notes[r.washout]} |" for r in ranking]
    else:
        lines = [f"| rank | washout | {unit} |", "|---|---|---|"]
        lines += [f"| {rank_cell(r)} | {r.washout} | {value(r)} |" for r in ranking]
    weights = ranking[0].weights
    if not explain:
        if undecided(ranking):
            lines += ["", "**The first place is a tie**."]
        if rule.by != "false-cue":
            lines += ["", "Weights: " + ", ".join(f"{d} {sig(weights[d], 2)}" for d in DOFS) + "."]
        return [*lines, ""]
    lines += ["", f"Ranked by {rule.label()}."]
    if undecided(ranking):
        lines += ["", "**The first place is a tie**: the best values differ by less than the tie margin."]
    if rule.by != "false-cue":
        lines += ["", _RULE_FORMULA.get(rule.by, _RULE_FORMULA["score"]) + " Weights: "
                  + ", ".join(f"{d} {sig(weights[d], 2)}" for d in DOFS) + "."]  # fmt: skip
    if flag and any(r.score > 1.0 for r in ranking):
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


CUE_NOTE = (
    "Percent of the manoeuvre's time (docs/fidelity.md): a cue is correct when both pilots feel the DOF (above "
    f"the Zacharias threshold) in the same direction with a magnitude ratio within {SCALE_BAND[0]:g}-"
    f"{SCALE_BAND[1]:g}, scaled outside that ratio, false when the simulator pilot feels motion the aircraft "
    "pilot does not or in the opposite direction, missing when the aircraft pilot feels motion the simulator "
    "pilot does not."
)

MSDV_NOTE = (
    "Motion sickness dose value MSDV = sqrt(integral a_w^2 dt) of the vertical acceleration at the head, "
    "weighted by ISO 2631-1 Wf (peak near 0.16 Hz), over the manoeuvre (docs/fidelity.md). Lower is better; "
    "a simulator pilot above the aircraft pilot gets more vertical low-frequency motion than the flight had."
)

MSI_NOTE = (
    "MSI: motion-sickness incidence (% who would vomit) the 6-DOF subjective vertical conflict model "
    "(Inoue, Liu and Wada 2023, after Bos and Bles 1998) predicts at the end of the manoeuvre, from all six "
    "DOFs of the head motion. It builds up with a 12-min second-order lag, so a manoeuvre of minutes gives "
    "small numbers: compare the pilots, not the value with an exposure of hours (docs/fidelity.md)."
)

PERCEIVED_NOTE = (
    "Aircraft pilot (wide solid line) against each washout's simulator pilot (each its own colour and dash); "
    "grey band: the perception thresholds (Zacharias 1978) around the pilot's resting value (what was perceived "
    "at the start), what lies inside it is not felt; shaded: the phases."
)


def cue_lines(data: ResultData, explain: bool = True) -> list[str]:
    """Time fractions of correct, scaled, false and missing cues per washout and DOF, and the false-cue events
    (``explain=False``: without :data:`CUE_NOTE`)."""

    rows = [m for m in data.metrics if not math.isnan(m.cue_false_frac)]
    if not rows:
        return ["_This result was written before the cue classification: `washbench cue` it again for it._", ""]
    lines = [CUE_NOTE, ""] if explain else []
    lines += [] if not explain else [
        "| washout | DOF | correct (%) | scaled (%) | false (%) | missing (%) | false-cue events |",
        "|---|---|---|---|---|---|---|",
    ]
    for m in rows if explain else []:  # the suite report: the total here, the table in the result's own report
        events = parse_events(m.false_cue_events, m.dof)
        longest = max(events, key=lambda e: e.end_s - e.start_s, default=None)
        ev = f"{len(events)}" + (f" (longest {sig(longest.start_s)}-{sig(longest.end_s)} s, peak "
                                 f"{sig(longest.peak)} {_unit('max_error', m.dof)})" if longest else "")  # fmt: skip
        cells = (m.cue_correct_frac, m.cue_scaled_frac, m.cue_false_frac, m.cue_missing_frac)
        lines.append(f"| {m.washout} | {m.dof} | " + " | ".join(sig(100.0 * c) for c in cells) + f" | {ev} |")
    washouts = dict.fromkeys(r.washout for r in rows)
    false_time = {w: sum(m.cue_false_frac for m in rows if m.washout == w) for w in washouts}
    lines += [""] if explain else ["False-cue time per DOF and events: in the result's own report.", ""]
    total = ", ".join(f"{w} {sig(v * data.duration_s)} s" for w, v in false_time.items())
    lines += [f"Time with a false cue, added up over the six DOFs (a second with false cues in two DOFs counts "
              f"twice): {total}, of a {sig(data.duration_s)} s manoeuvre.", ""]  # fmt: skip
    return lines


def sickness_lines(data: ResultData, explain: bool = True) -> list[str]:
    """MSDV (ISO 2631-1 Wf) of the vertical motion at each pilot's head and the SVC model's MSI (the heave rows of
    metrics.csv; a result written before the MSI shows the MSDV alone); ``explain=False``: without the notes."""
    heave = [m for m in data.metrics if m.dof == "heave" and not math.isnan(m.msdv_mps15)]
    if not heave:
        return ["_This result was written before the motion sickness dose: `washbench cue` it again for it._", ""]
    lines = [MSDV_NOTE, ""] if explain else []
    if any(not math.isnan(m.msi_pct) for m in heave):
        lines += [MSI_NOTE, ""] if explain else []
        lines += [
            "| pilot | MSDV (m/s^1.5) | MSI (%) |",
            "|---|---|---|",
            f"| aircraft | {sig(heave[0].msdv_aircraft_mps15)} | {sig(heave[0].msi_aircraft_pct)} |",
        ]
        lines += [f"| {m.washout} | {sig(m.msdv_mps15)} | {sig(m.msi_pct)} |" for m in heave]
    else:
        lines += ["| pilot | MSDV (m/s^1.5) |", "|---|---|", f"| aircraft | {sig(heave[0].msdv_aircraft_mps15)} |"]
        lines += [f"| {m.washout} | {sig(m.msdv_mps15)} |" for m in heave]
    return [*lines, ""]


def saturation_lines(data: ResultData) -> list[str]:
    """Time at each limit per washout, in seconds and percent of the manoeuvre."""

    kinds = list(dict.fromkeys(k for w in data.washouts for k, f in data.saturated.get(w, {}).items() if f.any()))
    if not kinds:
        return ["No platform or washout limit was reached.", ""]
    labels = saturation_labels(platform_of(data))
    head = "| limit | " + " | ".join(f"{w} (s, % of manoeuvre)" for w in data.washouts) + " |"
    lines = [head, "|---|" + "---|" * len(data.washouts)]
    for k in kinds:
        cells = []
        for w in data.washouts:
            flags = data.saturated.get(w, {}).get(k)
            steps = int(np.count_nonzero(flags)) if flags is not None else 0
            cells.append("-" if not steps else f"{sig(steps * data.dt_s)} s ({pct(100.0 * steps / data.n, False)})")
        lines.append(f"| {labels.get(k, k)} (`{k}`) | " + " | ".join(cells) + " |")
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


def perception_thresholds(data: ResultData) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """Zacharias thresholds and the resting values they are taken around, per DOF (m/s^2, deg/s): those of the cue
    classification (:func:`washbench.analysis.cues.dof_thresholds`: (0, 0, -g, 0, 0, 0)), so the figure's "not felt"
    band, the report's time beyond the threshold, the cue lanes, ``metrics.csv``'s cue columns and the recording's
    threshold lines say the same. (The first sample, taken before, is a transient where a flight starts untrimmed,
    as JSBSim's scripts do: the band then sat beside the curves.) ``data`` is not used (kept for the callers)."""

    del data
    thresholds, rest = dof_thresholds()
    return tuple(thresholds), tuple(rest)


def time_above_threshold(data: ResultData) -> dict[str, float]:
    """Per DOF, how long the aircraft pilot's perceived motion lies beyond the perception threshold around its
    resting value (:func:`perception_thresholds`) [s]."""
    thresholds, rest = perception_thresholds(data)
    p = data.perceived["aircraft"]
    return {
        d: float(np.count_nonzero(np.abs(p[:, i] - rest[i]) > thresholds[i])) * data.dt_s for i, d in enumerate(DOFS)
    }


def result_figures(
    data: ResultData, pdf: bool = False, palette: str | None = None, into: Path | None = None
) -> dict[str, Path]:
    """Draw the result's figures into ``into/figures/`` (``into``: a stage folder whose ``figures/`` replaces the
    result's; by default the result folder itself) as PNG, and PDF with ``pdf``; figure name -> PNG path.

    ``palette``: :data:`washbench.review.palette.PALETTES` (None: ``$WASHBENCH_PALETTE`` or the default).
    A PDF left from an earlier ``washbench report`` in the result folder is removed when none is drawn.
    """

    fig_dir = (into or data.folder) / FIGURES_DIR
    fig_dir.mkdir(exist_ok=True)
    formats = ("png", "pdf") if pdf else ("png",)
    if not pdf and into is None:
        for stem in ("perceived", "envelope", "cues"):
            (fig_dir / f"{stem}.pdf").unlink(missing_ok=True)
    thresholds, rest = perception_thresholds(data)
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
        palette=palette,
    )[0]
    if data.washouts and all(w in data.perceived for w in data.washouts):
        classes = cue_classes(data.perceived, data.washouts)
        out["cues"] = cue_lane_figure(fig_dir / "cues", data.title, data.t_s, classes, formats=formats)[0]
    if data.usage:
        out["envelope"] = envelope_figure(
            fig_dir / "envelope", data.title, data.t_s, data.usage, data.saturated, phases=data.phases, formats=formats,
            palette=palette, labels=saturation_labels(platform_of(data)),
        )[0]
    return out


def platform_of(data: ResultData) -> str:
    """The platform's kind a result was made on (its provenance; ``atlas`` when it does not say)."""
    record = (data.provenance or {}).get("platform") or {}
    values = record.get("values") if isinstance(record, dict) else None
    kind = values.get("kind", "atlas") if isinstance(values, dict) else "atlas"
    return kind if isinstance(kind, str) else "atlas"


NO_FIGURES = "_No figures were drawn (`--no-figures`): `washbench report` on this folder draws them from its files._"
#: Said once, at the end of a report whose figures have no PDF beside them (once, not under every figure).
NO_PDF_NOTE = "Vector versions of the figures for papers (PDF): `washbench report` on this folder draws them."


def _image(png: Path, start: Path, alt: str, vector: bool | None = None) -> list[str]:
    """The figure embedded, and its PDF linked when there is one (``vector``: whether there is, when the figure is
    still in a stage); without one, the report says once how to get them (:data:`NO_PDF_NOTE`)."""
    rel = _rel(png, start)
    pdf = Path(rel).with_suffix(".pdf")
    if png.with_suffix(".pdf").is_file() if vector is None else vector:
        return [f"![{alt}]({rel})", "", f"Vector version for papers: [{pdf.name}]({pdf.as_posix()})", ""]
    return [f"![{alt}]({rel})", ""]


def result_sections(
    data: ResultData,
    figures: dict[str, Path],
    start: Path,
    level: int,
    brief: bool = False,
    vector: bool | None = None,
    recording: bool | None = None,
) -> list[str]:
    """The body of one result's report; links relative to ``start`` (the folder report.md is in).

    ``recording``: whether the result has a recording.rrd to link (None: whether the folder holds one now; a
    report drawn while the recording is still being written, :mod:`washbench.runs.beside`, is told).

    ``brief`` (the suite report): without the envelope figure, checks and phases (they are in the result's own
    report, which the suite report links).
    """
    h = "#" * level
    lines: list[str] = []
    rule = result_rule(data)
    ranking = rank(data.metrics, data.motion, rule) if data.metrics else []
    lines += [f"{h} Ranking", "", *ranking_lines(data, ranking, rule, explain=not brief)]
    if rule.by == "felt" and not brief:
        lines += felt_breakdown_lines(data.metrics, data.motion, rule.measure, ranking)

    if bounded := bound_lines(data.folder, [r.washout for r in ranking], explain=not brief):
        lines += [f"{h} Against the ceiling", "", *bounded]
    if solver := algorithm_lines(data.folder):
        lines += [f"{h} Solver statistics", "", *solver]
    lines += [f"{h} Perceived motion", ""]
    lines += [PERCEIVED_NOTE, ""] if not brief else []
    lines += (
        _image(figures["perceived"], start, "perceived motion", vector) if "perceived" in figures else [NO_FIGURES, ""]
    )
    lines += [f"{h} Cues: correct, scaled, false, missing", "", *cue_lines(data, explain=not brief)]
    if "cues" in figures:
        lines += _image(figures["cues"], start, "false and missing cues", vector)
    lines += [f"{h} Motion sickness dose", "", *sickness_lines(data, explain=not brief)]
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
    rrd = data.folder / RECORDING_FILE
    if rrd.exists() if recording is None else recording:
        rel = _rel(rrd, start)
        lines += [f"Recording: [{rel}]({rel}) (`washbench replay {rel}`).", ""]
    return lines


def _status_line(data: ResultData) -> list[str]:
    if data.ok is False:
        return [f"> **FAILED**: {data.reason or 'a check failed'}", ""]
    return []


def write_result_report(
    result_dir: Path,
    table: Mapping[str, np.ndarray] | None = None,
    pdf: bool = False,
    figures: bool = True,
    recording: bool | None = None,
) -> Path:
    """Write ``report.md`` and ``figures/`` for one result folder from its files; return the report's path.

    ``table``: the traces.parquet columns already in memory (not read again); ``pdf``: PDF figures besides the PNG;
    ``figures=False``: none drawn (``--no-figures``; figures of an earlier run in the folder are removed);
    ``recording``: whether recording.rrd is linked (None: whether the folder holds one now).
    """

    data = load_result(Path(result_dir), table, series=figures)
    stage = make_stage(data.folder)  # report.md and figures/ replace the previous ones together (links never followed)
    try:
        _write_result_report(data, stage, pdf, figures, recording)
        replace_entries(data.folder, stage, [REPORT_FILE, FIGURES_DIR])
    finally:
        discard_stage(stage)
    return data.folder / REPORT_FILE


def _write_result_report(data: ResultData, stage: Path, pdf: bool, figures: bool, recording: bool | None) -> None:
    drawn = result_figures(data, pdf, into=stage) if figures else {}
    lines = [f"# {data.title}", "", *_status_line(data)]
    checks = f", checks {sum(bool(c.get('passed')) for c in data.checks)}/{len(data.checks)}" if data.checks else ""
    status = {True: "ok", False: "FAILED", None: "cued"}[data.ok]
    lines += [
        f"{status}{checks}; {sig(data.duration_s)} s, {data.n} samples at {sig(1.0 / data.dt_s)} Hz; "
        f"washouts: {', '.join(data.washouts)}.",
        "",
    ]

    lines += input_section(data.folder, pdf, _image, stage) if figures else []  # a cue result: the input as read, first
    lines += provenance_lines(data.provenance, data.created_utc)
    final = {k: data.folder / p.relative_to(stage) for k, p in drawn.items()}  # where they will be
    lines += result_sections(data, final, data.folder, 2, vector=pdf, recording=recording)
    lines += [NO_PDF_NOTE, ""] if drawn and not pdf else []
    write_text_atomic(stage / REPORT_FILE, "\n".join(lines).rstrip() + "\n")
