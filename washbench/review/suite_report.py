"""The suite's report.md and figures, from the files of a suite folder (``washbench suite``, ``washbench report``).

A suite folder holds ``suite.json`` (every manoeuvre file with its status and reason, failures included, and the
suite's provenance) and one result folder per manoeuvre that ran (``<aircraft>/<manoeuvre>/``). Without
``suite.json`` (a folder of results put together by hand) the result folders found below it are reported.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Sequence
from concurrent.futures import Executor, Future
from pathlib import Path
from typing import Any

import numpy as np

from washbench.analysis.metrics import DOFS
from washbench.analysis.ranking import (
    METRICS,
    RankRow,
    compare,
    rank,
    reference_washout,
    rule_from_record,
    undecided,
)
from washbench.errors import WashbenchError, located
from washbench.io.atomic import write_text_atomic
from washbench.io.outfolder import discard_stage, make_stage, refuse_links, replace_entries
from washbench.io.readback import SuiteDoc, read_doc, suite_member
from washbench.io.result_files import FIGURES_DIR, METRICS_FILE, RECORDING_FILE, REPORT_FILE, SUITE_FILE
from washbench.review.bound_section import CEILING_NOTE, VACUOUS, read_ceiling
from washbench.review.figures import score_heatmap, table4_figure
from washbench.review.numbers import sig
from washbench.review.report import (
    CUE_NOTE,
    FLAG,
    MSDV_NOTE,
    MSI_NOTE,
    NO_PDF_NOTE,
    PERCEIVED_NOTE,
    SCORE_NOTE,
    _image,
    _rel,
    provenance_lines,
    result_sections,
    write_result_report,
)
from washbench.review.result_data import ResultData, is_result_folder, load_result
from washbench.review.verdict import Entry, verdict_lines

_HOW_TO_READ = [
    "Metrics compare the aircraft pilot's perceived motion with each simulator pilot's, per degree of freedom: NPC",
    "(normalized Pearson correlation, 1 perfect, larger worse), the integral and the maximum of |error|; surge, sway,",
    "heave in m/s² (integral m/s²·s), roll, pitch, yaw in deg/s (integral deg). The ranking's value (lower is",
    "better) is by default the felt error of `washbench/analysis/felt.py` (docs/metrics.md): the perceived error",
    "beyond the perception thresholds, its false part counted again and the jolts the platform adds at the head, in",
    "threshold units, over what the aircraft pilot felt above threshold (1: a platform standing still; each DOF weighs",
    "what was felt there). `--rank-by score` ranks by the rule before it. Numbers have 3 significant digits; full",
    "precision is in `metrics.csv`, `comparison.csv` and `ranking.csv`. Best values are bold.",
    "",
]


def write_suite_json(
    path: Path,
    entries: list[dict[str, Any]],
    provenance: dict[str, Any],
    created_utc: str,
    top_level: list[str] | None = None,
) -> None:
    """``suite.json``: one entry per manoeuvre file (file, ok, reason, aircraft, manoeuvre, result folder, checks),
    the provenance and, once the suite is complete, ``entries``: every top-level name it wrote (the marker by which
    the next suite recognises what it may replace, :func:`washbench.runs.suite_place.previous_results`)."""
    doc: dict[str, Any] = {"washbench": "suite", "created_utc": created_utc, "provenance": provenance}
    doc["manoeuvres"] = entries
    if top_level is not None:
        doc["entries"] = top_level
    write_text_atomic(path, json.dumps(doc, indent=2) + "\n")


def _entries(suite_dir: Path) -> tuple[list[dict[str, Any]], dict[str, Any]]:
    """The manoeuvre entries and the suite document (suite.json, or found result folders without it)."""

    path = suite_dir / SUITE_FILE
    doc = read_doc(path, SuiteDoc)  # checked as strictly as a user's file
    if doc is not None:
        entries = list(doc["manoeuvres"])
        for e in entries:  # every result inside the suite folder, through no link
            if e.get("result"):
                suite_member(suite_dir, e["result"], path)
        return entries, doc
    folders = sorted({p.parent for p in suite_dir.rglob(METRICS_FILE) if is_result_folder(p.parent)
                      and not any(q.is_symlink() for q in (p.parent, *p.parent.parents) if q != suite_dir
                                  and q.is_relative_to(suite_dir))})  # fmt: skip
    if not folders:
        raise WashbenchError(located(suite_dir, "neither a result folder nor a suite folder (no results found)"))
    return [{"file": "", "result": _rel(f, suite_dir)} for f in folders], {}


def write_suite_report(
    suite_dir: Path, *, regenerate_results: bool = False, figures: bool = True, pool: Executor | None = None
) -> Path:
    """Write the suite's ``report.md`` and ``figures/`` from the suite folder's files; return the report's path.

    ``regenerate_results`` (``washbench report``): first write every result folder's own report and figures again,
    and every figure as PNG and PDF; otherwise the PNG figures the runs wrote are linked and the suite's are PNG.
    ``pool``: the suite's worker processes, idle once the runs are done: they draw the score and Table 4 figures
    side by side while this process writes the text (it then never imports matplotlib); None: drawn here.
    """

    suite_dir = Path(suite_dir)
    entries, doc = _entries(suite_dir)
    # a link in the place of what is rewritten is refused before anything is (the runs' reports were rewritten first)
    refuse_links(suite_dir, [REPORT_FILE, FIGURES_DIR])
    if regenerate_results:
        for e in entries:
            folder = suite_dir / e["result"] if e.get("result") else None
            if folder is not None and is_result_folder(folder):
                refuse_links(folder, [REPORT_FILE, FIGURES_DIR])
    stage = make_stage(suite_dir)  # report.md and figures/ replace the previous ones together (links never followed)
    try:
        _write_suite_report(suite_dir, stage, entries, doc, regenerate_results, figures, pool)
        replace_entries(suite_dir, stage, [REPORT_FILE, FIGURES_DIR])
    finally:
        discard_stage(stage)
    return suite_dir / REPORT_FILE


def _draw(pool: Executor | None, draw: Callable[..., list[Path]], *args: Any, **kwargs: Any) -> Future[list[Path]]:
    """``draw(*args, **kwargs)`` in ``pool``, or here and now (its result or error in a done future)."""
    if pool is not None:
        return pool.submit(draw, *args, **kwargs)
    done: Future[list[Path]] = Future()
    done.set_result(draw(*args, **kwargs))
    return done


def tie_counts(n_tied: int, n_rankings: int, n_any: int) -> str:
    """The suite report's sentence on ties: how many of ``n_rankings`` manoeuvres have first place shared (decided by
    less than the rule's margin) and how many a tie at any rank (counts, no verb to agree with them)."""
    return (f"First place shared (decided by less than that margin): {n_tied} of {n_rankings} manoeuvres; a tie at "
            f"some rank: {n_any} of {n_rankings}.")


def _write_suite_report(
    suite_dir: Path, stage: Path, entries: list[dict[str, Any]], doc: dict[str, Any], regenerate_results: bool,
    figures: bool, pool: Executor | None = None,
) -> None:  # fmt: skip

    results: list[tuple[dict[str, Any], ResultData | None]] = []
    for e in entries:
        folder = suite_dir / e["result"] if e.get("result") else None
        if folder is not None and is_result_folder(folder):
            if regenerate_results:
                write_result_report(folder, pdf=True)
            results.append((e, load_result(folder, series=False)))
        else:
            results.append((e, None))
    loaded = [d for _, d in results if d is not None]
    washouts = list(dict.fromkeys(w for d in loaded for w in d.washouts))
    reference = reference_washout(washouts)
    prov = doc.get("provenance")
    rule = rule_from_record(prov.get("ranking") if isinstance(prov, dict) else None)
    rankings = {id(d): rank(d.metrics, d.motion, rule) for d in loaded}

    fig_dir = stage / FIGURES_DIR
    if figures:
        fig_dir.mkdir()
    formats = ("png", "pdf") if regenerate_results else ("png",)
    drawing: dict[str, Future[list[Path]]] = {}  # the figures' paths, PNG first, once drawn
    labels = [d.title + (" (FAILED)" if d.ok is False else "") + _tie_label(rankings[id(d)]) for d in loaded]
    if loaded and figures:
        scores = np.full((len(loaded), len(washouts)), math.nan)
        for r, d in enumerate(loaded):
            for row in rankings[id(d)]:
                scores[r, washouts.index(row.washout)] = row.score
        firsts = [[r.washout for r in rankings[id(d)] if r.rank == 1] for d in loaded]
        drawing["scores"] = _draw(pool, score_heatmap, fig_dir / "scores", labels, washouts, scores, formats=formats,
                                  firsts=firsts)  # fmt: skip
        others = [w for w in washouts if w != reference]
        if others:
            better = {w: np.full((len(loaded), len(METRICS) * len(DOFS)), math.nan) for w in others}
            for r, d in enumerate(loaded):
                for c in compare(d.metrics, reference):
                    col = METRICS.index(c.metric) * len(DOFS) + DOFS.index(c.dof)
                    ref = c.values.get(reference, math.nan)
                    for w, diff in c.better_than_reference.items():
                        if math.isfinite(diff) and ref != 0:
                            better[w][r, col] = 100.0 * diff / ref
            drawing["table4"] = _draw(
                pool, table4_figure, fig_dir / "table4", labels, reference, better, DOFS, METRICS, formats=formats
            )
    drawn = {name: fig_dir / f"{name}.png" for name in drawing}  # where each figure's PNG goes

    ok = [e for e, d in results if e.get("ok", d.ok if d else False)]
    lines = ["# washbench suite report", ""]
    lines.append(f"{len(ok)} of {len(results)} manoeuvres ran and passed their checks.")
    lines.append("")
    verdict = [
        Entry(label=d.title, group=d.title.partition(" / ")[2] or d.title, ranking=rankings[id(d)],
              metrics=d.metrics, motion=d.motion, ceiling=read_ceiling(d.folder))
        for d in loaded
    ]  # fmt: skip
    failed = [(e, d) for e, d in results if not e.get("ok", d.ok if d else False)]
    if failed:  # failures first: what did not run comes before any verdict on what did
        lines += ["## Failures", ""]
        for e, d in failed:
            name = e.get("file") or (d.title if d else "?")
            reason = e.get("reason") or (d.reason if d else "") or "failed"
            kept = f" (results kept in `{e['result']}/`)" if d is not None else ""
            lines.append(f"- `{name}`: {reason}{kept}")
        lines.append("")
    lines += verdict_lines(verdict, washouts, reference, rule, failed=len(failed))
    lines += provenance_lines(doc.get("provenance"), doc.get("created_utc"))
    lines += ["## Summary", ""]
    head = ["aircraft", "manoeuvre", "status", "checks", "duration (s)", "best washout"]
    head += [f"{w} score (-)" for w in washouts] + ["report", "recording"]
    lines += ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    any_above = False
    for e, d in results:
        status = "ok" if e.get("ok", d.ok if d else False) else "FAILED"
        if d is None:
            name = Path(e.get("file", "?")).name
            lines.append(f"| {e.get('aircraft') or '-'} | {e.get('manoeuvre') or name} | {status} | - | - | - | "
                         + " | ".join("-" for _ in washouts) + " | - | - |")  # fmt: skip
            continue
        ranking = rankings[id(d)]
        by_name = {r.washout: r.score for r in ranking}
        best = " = ".join(r.washout for r in ranking if r.rank == 1) + (" (tie)" if undecided(ranking) else "")
        firsts = {r.washout for r in ranking if r.rank == 1}
        cells = []
        for w in washouts:
            s = by_name.get(w, math.nan)
            any_above |= s > 1.0
            text = f"**{sig(s)}**" if w in firsts else sig(s)
            cells.append(f"{text} {FLAG}" if s > 1.0 else text)
        checks = f"{sum(bool(c.get('passed')) for c in d.checks)}/{len(d.checks)}" if d.checks else "-"
        rel = _rel(d.folder, suite_dir)
        rec = f"[{RECORDING_FILE}]({rel}/{RECORDING_FILE})" if (d.folder / RECORDING_FILE).exists() else "-"
        aircraft, _, manoeuvre = d.title.partition(" / ")
        lines.append(f"| {aircraft} | {manoeuvre or d.title} | {status} | {checks} | {sig(d.duration_s)} | {best} | "
                     + " | ".join(cells) + f" | [report.md]({rel}/{REPORT_FILE}) | {rec} |")  # fmt: skip
    lines.append("")
    if rankings:
        n_tied = sum(1 for r in rankings.values() if undecided(r))
        n_any = sum(1 for r in rankings.values() if any(x.tied for x in r))
        lines += [f"Ranked by {rule.label()}. {tie_counts(n_tied, len(rankings), n_any)} Shared ranks are "
                  "marked \"(tie)\" in the reports, `tied` in `ranking.csv` and \"tie:\" in the score figure's row "
                  "labels.", ""]  # fmt: skip
    if any_above:
        lines += [SCORE_NOTE, ""]
    if "scores" in drawn:
        lines += _image(suite_dir / drawn["scores"].relative_to(stage), suite_dir, "score per manoeuvre and washout",
                        regenerate_results)  # fmt: skip
    if "table4" in drawn:
        lines += [f"## Against {reference} (Table 4 of the paper)", ""]
        lines += [f"Each cell: how much better than {reference} the washout is, in percent of the "
                  f"{reference} value (positive, green: better). Absolute differences are in "
                  "`comparison.csv`.", ""]  # fmt: skip
        lines += _image(suite_dir / drawn["table4"].relative_to(stage), suite_dir, "Table 4", regenerate_results)
    lines += ["## How to read the numbers", "", *_HOW_TO_READ, f"Ranked by {rule.label()}.", "",
              PERCEIVED_NOTE, "", CUE_NOTE, "", MSDV_NOTE, "", MSI_NOTE, ""]  # fmt: skip
    if any(e.ceiling for e in verdict):
        name = "felt error" if rule.by == "felt" else rule.by
        lines += [CEILING_NOTE.format(measure=name, vacuous=100 * VACUOUS), ""]
    for d in loaded:
        rel = _rel(d.folder, suite_dir)
        lines += [f"## {d.title}", ""]
        lines += [f"Results in `{rel}/`; its [report]({rel}/{REPORT_FILE}) adds the platform envelope figure, "
                  "the checks and the phases.", ""]  # fmt: skip
        if d.ok is False:
            lines += [f"> **FAILED**: {d.reason or 'a check failed'}", ""]
        lines += result_sections(d, _existing_figures(d) if figures else {}, suite_dir, 3, brief=True)
    lines += [NO_PDF_NOTE, ""] if figures and not regenerate_results else []  # once, not under every figure
    for future in drawing.values():  # drawn (or failed: raised here) before the report that shows them
        future.result()
    write_text_atomic(stage / REPORT_FILE, "\n".join(lines).rstrip() + "\n")


def _existing_figures(d: ResultData) -> dict[str, Path]:
    """The result's figures as its report links them (drawn again, with its report, when missing)."""

    def found() -> dict[str, Path]:
        paths = {name: d.folder / FIGURES_DIR / f"{name}.png" for name in ("perceived", "envelope", "cues")}
        return {k: p for k, p in paths.items() if p.is_file() and not p.parent.is_symlink()}

    if "perceived" not in found():
        write_result_report(d.folder)  # staged: a link in the result folder is refused, never written through
    return found()


def _tie_label(ranking: Sequence[RankRow]) -> str:
    """Row-label suffix of the score figure naming a shared first place (a second line ``tie: a = b``), else empty."""
    return "\ntie: " + " = ".join(r.washout for r in ranking if r.rank == 1) if undecided(ranking) else ""
