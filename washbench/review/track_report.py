"""``report.md`` of ``washbench track``, from the summary ``track.json`` holds (:func:`track_report`).

The verdict first (which washout leaves the pilot's control closest to flight, by the distance of
:mod:`washbench.pilot.compare`, and whether the washouts lie between no motion and the aircraft's own motion), then
the conditions side by side with each measure's difference from the aircraft's own motion, the pilot model in each
condition, the figures, how it was measured, and what made it.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from washbench.errors import WashbenchError, located
from washbench.io.atomic import write_text_atomic
from washbench.io.result_files import FIGURES_DIR, REPORT_FILE, TRACK_FILE, TRACK_FRF_FILE
from washbench.pilot.compare import DISTANCE_MEASURES
from washbench.review.numbers import pct, sig
from washbench.review.track_figures import read_curves, track_figures

MEASURE_LABELS: dict[str, str] = {
    "error_var_deg2": "error variance (deg²)",
    "control_var": "control variance (control²)",
    "target_crossover_radps": "target crossover (rad/s)",
    "target_phase_margin_deg": "target phase margin (deg)",
    "disturbance_crossover_radps": "disturbance crossover (rad/s)",
    "disturbance_phase_margin_deg": "disturbance phase margin (deg)",
}
PARAM_LABELS: dict[str, str] = {
    "visual_gain": "K_v, visual gain (control/rad)",
    "lead_s": "T_L, visual lead (s)",
    "vestibular_gain": "K_m, vestibular gain (control/(rad/s))",
    "vestibular_to_visual_s": "K_m / K_v (s)",
    "control_visual_var": "visual part of the control, variance",
    "control_vestibular_var": "vestibular part of the control, variance",
    "motion_gain_1radps": "motion filter gain at 1 rad/s",
    "motion_phase_1radps_deg": "motion filter phase at 1 rad/s (deg)",
    "saturated_s": "time the control was at its stop (s)",
}


def _row(cells: Sequence[str]) -> str:
    return "| " + " | ".join(cells) + " |"


def _table(header: Sequence[str], rows: Sequence[Sequence[str]]) -> list[str]:
    return [_row(header), _row(["---"] * len(header)), *(_row(r) for r in rows)]


def _with_sd(m: Mapping[str, float], key: str) -> str:
    sd = m.get(f"{key}_sd", math.nan)
    return sig(m.get(key, math.nan)) + (f" ± {sig(sd, 2)}" if isinstance(sd, float) and math.isfinite(sd) else "")


def verdict_lines(summary: Mapping[str, Any]) -> list[str]:
    """The verdict paragraph."""
    v = summary.get("verdict") or {}
    conditions = {c["name"]: c for c in summary["conditions"]}
    washouts = [c["name"] for c in summary["conditions"] if c["kind"] == "washout"]
    failed = [c for c in summary["conditions"] if not c["ok"]]
    lines = []
    closest = v.get("closest")
    if closest is not None and math.isfinite(v["distance_pct"].get(closest, math.nan)):
        d = v["distance_pct"]
        others = ", ".join(f"{w} {sig(d[w])} %" for w in v["order"][1:] if math.isfinite(d.get(w, math.nan)))
        none = v.get("no_motion_distance_pct", math.nan)
        lines.append(
            f"**Verdict: {closest} leaves the simulator pilot's control closest to flight**: its measures differ "
            f"from those in the aircraft's own motion by {sig(d[closest])} % (root mean square of the log ratios of "
            f"the error and control variances and the two open loops' crossover frequencies and phase margins)"
            + (f"; the others: {others}" if others else "")
            + (f"; no motion: {sig(none)} %." if math.isfinite(none) else ".")
        )
        bracket = v.get("bracketed") or {}
        outside = {w: [k for k, ok in b.items() if not ok] for w, b in bracket.items()}
        outside = {w: ks for w, ks in outside.items() if ks}
        if bracket and not outside:
            lines.append("Every washout lies between no motion and the aircraft's own motion on every measure (within "
                         "what the runs resolve).")  # fmt: skip
        elif outside:
            lines.append(
                "Outside the bracket of no motion and the aircraft's own motion, beyond what the runs resolve: "
                + "; ".join(f"{w} ({', '.join(MEASURE_LABELS.get(k, k) for k in ks)})" for w, ks in outside.items())
                + "."
            )
    elif washouts:
        lines.append("**No verdict**: no washout condition was measured to its end.")
    else:
        lines.append("**No washout was compared** (only the aircraft's own motion and no motion).")
    for c in failed:
        lines.append(f"**{c['name']} failed**: {c['reason']}")
    ac = conditions.get("aircraft")
    if ac is not None and ac["ok"]:
        m = ac["measures"]
        lines.append(
            f"In the aircraft's own motion the pilot model flies with K_v = {sig(m.get('visual_gain', math.nan))}, "
            f"T_L = {sig(m.get('lead_s', math.nan))} s and K_m / K_v = {sig(m.get('vestibular_to_visual_s', math.nan))}"
            f" s; its disturbance loop crosses over at {sig(m['disturbance_crossover_radps'])} rad/s with "
            f"{sig(m['disturbance_phase_margin_deg'])} deg of phase margin."
        )
    return lines


def track_report(summary: Mapping[str, Any], figures: Mapping[str, str] | None = None) -> str:
    """The report's Markdown (``figures``: name -> path relative to the report, as written)."""
    summary = _numbers(summary)
    task = summary["task"]
    title = f"{task['aircraft']} / {task['name']} ({task['axis']})"
    out = [f"# Pilot in the loop: {title}", ""]
    out += [line for text in verdict_lines(summary) for line in (text, "")]
    ok = [c for c in summary["conditions"] if c["ok"]]
    names = [c["name"] for c in ok]

    out += ["## The conditions side by side", ""]
    out.append("Each measure in each condition (± the standard deviation over single runs where measured per run) "
               "and its difference from the aircraft's own motion.")  # fmt: skip
    out.append("")
    rows = []
    for key in DISTANCE_MEASURES:
        cells = [MEASURE_LABELS[key]]
        for c in ok:
            cell = _with_sd(c["measures"], key)
            diff = c.get("differences_pct", {}).get(key, math.nan)
            if c["name"] != "aircraft" and math.isfinite(diff):
                cell += f" ({pct(diff)})"
            cells.append(cell)
        rows.append(cells)
    rows.append(["distance from flight (%)"] + [sig(c.get("distance_pct", math.nan)) for c in ok])
    out += _table(["measure", *names], rows)
    out.append("")

    out += ["## The pilot model in each condition", ""]
    rows = []
    for key, label in PARAM_LABELS.items():
        values = [c["measures"].get(key, math.nan) for c in ok]
        if all(isinstance(v, float) and math.isnan(v) for v in values):
            continue
        rows.append([label] + [sig(v) for v in values])
    parts = ("error_var_target_deg2", "error_var_disturbance_deg2", "error_var_remnant_deg2")
    for key, label in zip(parts, ("error variance at the target's frequencies (deg²)",
                                  "error variance at the disturbance's frequencies (deg²)",
                                  "error variance, remnant (deg²)"), strict=True):  # fmt: skip
        rows.append([label] + [sig(c["measures"].get(key, math.nan)) for c in ok])
    out += _table(["", *names], rows)
    out.append("")
    pilot = summary.get("pilot", {})
    rule = pilot.get("adaptation", {}).get("rule", "optimal")
    if rule == "optimal" and pilot.get("model") == "multimodal":
        out.append(
            "The pilot adapts K_v, T_L and K_m to each condition: they minimise var(e) + w_u var(u_eq) predicted in "
            "the frequency domain for the measured controlled element and the condition's motion filter "
            f"(w_u = {sig(pilot['adaptation'].get('control_weight_s2', math.nan))} s², perception noises "
            'calibrated once; docs/pilot-model.md, "Adaptation"). The predictions against the measurements:'
        )
        out.append("")
        rows = []
        for c in ok:
            p = c.get("prediction") or {}
            m = c["measures"]
            rows.append(
                [
                    c["name"],
                    f"{sig(p.get('error_var_deg2', math.nan))} / {sig(m['error_var_deg2'])}",
                    f"{sig(p.get('disturbance_crossover_radps', math.nan))} / {sig(m['disturbance_crossover_radps'])}",
                    f"{sig(p.get('target_crossover_radps', math.nan))} / {sig(m['target_crossover_radps'])}",
                ]
            )
        out += _table(["condition", "error variance (deg²), predicted / measured",
                       "disturbance crossover (rad/s)", "target crossover (rad/s)"], rows)  # fmt: skip
        out.append("")
    elif pilot.get("model") == "plugin":
        out.append(f"The pilot model is a plugin ({pilot.get('plugin', {}).get('source', '?')}), flown as it is made "
                   "in every condition (the bench adapts only the built-in model).")  # fmt: skip
        out.append("")

    if figures:
        out += ["## Figures", ""]
        captions = {
            "bode": "The open loops at the forcing frequencies",
            "variance": "Variance decomposition of the error and the control; the control's visual and vestibular "
            "parts",
            "motion": "The motion filter of each condition on the task's axis, as measured in its runs",
        }
        for name, rel in figures.items():
            out += [f"![{captions.get(name, name)}]({rel})", ""]

    out += ["## How it was measured", ""]
    out.append(
        f"JSBSim flew the {task['aircraft']} in closed loop with the pilot model for {task['runs']} run(s) of "
        f"{sig(task['run_in_s'] + task['measurement_s'])} s per condition at {task['rate_hz']} Hz; each run's last "
        f"{sig(task['measurement_s'])} s (the forcing functions' period) were Fourier transformed and the runs' "
        "coefficients averaged. The target and the disturbance are multisines at integer multiples of the window's "
        "base frequency; the disturbance acts on the control, its amplitudes scaled by the controlled element "
        "measured first (the calibration). Each washout condition ran the washout and its platform in lockstep "
        "with the flight, the simulator pilot's head motion through the vestibular models "
        f"({summary.get('vestibular', {}).get('model', '?')}) to the pilot model. The runs' remnant seeds are the "
        "same in every condition. Files: track.json (everything here), measures.csv, frf.csv, signals.parquet, "
        "recording.rrd."
    )
    out.append("")
    cal = summary.get("calibration", {})
    if cal.get("frequencies_radps"):
        out.append("The controlled element measured in the calibration (attitude per unit control):")
        out.append("")
        rows = [[sig(w), sig(g), sig(p)] for w, g, p in zip(cal["frequencies_radps"], cal["gain"], cal["phase_deg"],
                                                                strict=True)]  # fmt: skip
        out += _table(["frequency (rad/s)", "gain", "phase (deg)"], rows)
        out.append("")
    prov = summary.get("provenance", {})
    if prov:
        out += ["## Provenance", ""]
        software = prov.get("software", {})
        out.append("Software: " + ", ".join(f"{k} {v}" for k, v in software.items()) + ".")
        for key in ("task", "aircraft", "pilot_profile", "params", "platform"):
            rec = prov.get(key)
            if isinstance(rec, Mapping) and rec.get("path"):
                out.append(f"{key}: `{rec['path']}` (sha256 {str(rec.get('sha256', ''))[:12]}).")
        out.append("")
    return "\n".join(out).rstrip() + "\n"


def _nan(x: Any) -> Any:
    """JSON's null (a NaN or infinity when written) back to NaN, through dicts and lists."""
    if x is None:
        return math.nan
    if isinstance(x, dict):
        return {k: _nan(v) for k, v in x.items()}
    if isinstance(x, list):
        return [_nan(v) for v in x]
    return x


def _numbers(summary: Mapping[str, Any]) -> dict[str, Any]:
    """``summary`` with the nulls of its numbers (measures, differences, distances, predictions) as NaN."""
    out = dict(summary)
    out["conditions"] = [
        {**c, **{k: _nan(c[k]) for k in ("measures", "differences_pct", "distance_pct", "prediction") if k in c}}
        for c in summary["conditions"]
    ]
    v = dict(summary.get("verdict") or {})
    for k in ("distance_pct", "no_motion_distance_pct"):
        if k in v:
            v[k] = _nan(v[k])
    out["verdict"] = v
    return out


def write_track_report(folder: Path, figures: bool = True, palette: str = "default") -> Path:
    """Write ``report.md`` (and, with ``figures``, the figures) of a track result folder from its ``track.json``
    and ``frf.csv``: what ``washbench track`` writes and ``washbench report DIR`` writes again."""
    try:
        summary = json.loads((folder / TRACK_FILE).read_text(encoding="utf-8"))
        frf = (folder / TRACK_FRF_FILE).read_text(encoding="utf-8")
    except (OSError, ValueError) as exc:
        raise WashbenchError(located(folder, f"not a readable washbench track result ({exc})")) from None
    summary = _numbers(summary)
    drawn: dict[str, str] = {}
    if figures:
        task = summary["task"]
        title = f"{task['aircraft']} / {task['name']} ({task['axis']})"
        paths = track_figures(folder / FIGURES_DIR, read_curves(summary, frf), title, palette)
        drawn = {k: f"{FIGURES_DIR}/{p.name}" for k, p in paths.items()}
    path = folder / REPORT_FILE
    write_text_atomic(path, track_report(summary, drawn))
    return path
