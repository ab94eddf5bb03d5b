"""The conditions side by side: each condition's measures, their differences from the aircraft's own motion, the
distance that ranks the washouts and the verdict (functions over :class:`washbench.pilot.measure.
ConditionResult`).

Measures (docs/pilot-model.md, "Measures"), each the mean over the runs where it is measured per run:

- ``error_var_deg2``, ``control_var``: variances of the displayed error (deg^2) and the control (control
  units^2) over the measurement window;
- ``target_crossover_radps``, ``target_phase_margin_deg``, ``disturbance_crossover_radps``,
  ``disturbance_phase_margin_deg``: the two open loops at the forcing frequencies (the runs' averaged Fourier
  coefficients, as the cited papers), with ``*_sd`` the standard deviation of the same measure over single runs;
- the pilot model's parameters as flown, the visual and vestibular contributions to the control (variances), the
  motion filter's gain and phase at 1 rad/s (Pool et al. 2011's "motion filter gain at 1 rad/s").

Distance from flight: ``D = 100 sqrt(mean_m ln(x_m / x_m,aircraft)^2)`` over the six measures of
:data:`DISTANCE_MEASURES` (the issue's performance and control-behaviour measures), in percent for small
differences; 0 for the aircraft's own motion. The verdict names the washout of least D, and checks the bracket:
a washout is expected between the aircraft's own motion and no motion on every measure, within what the runs
resolve (:func:`bracketed`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from washbench.pilot.forcing import base_frequency
from washbench.pilot.identify import identify
from washbench.pilot.loop import AIRCRAFT, NO_MOTION
from washbench.pilot.measure import ConditionResult, signals_of
from washbench.pilot.task import Task

DISTANCE_MEASURES = (
    "error_var_deg2",
    "control_var",
    "target_crossover_radps",
    "target_phase_margin_deg",
    "disturbance_crossover_radps",
    "disturbance_phase_margin_deg",
)
"""The measures the distance from flight is taken over."""

_DEG2 = (180.0 / math.pi) ** 2


def measures(result: ConditionResult, task: Task) -> dict[str, float]:
    """The measures of one condition (module docstring), floats (NaN where not measured)."""
    idf = result.identified
    t, d = idf.target_crossover, idf.disturbance_crossover
    out: dict[str, float] = {
        "error_var_deg2": result.error.total * _DEG2,
        "error_var_target_deg2": result.error.target * _DEG2,
        "error_var_disturbance_deg2": result.error.disturbance * _DEG2,
        "error_var_remnant_deg2": result.error.remnant * _DEG2,
        "control_var": result.control.total,
        "control_var_target": result.control.target,
        "control_var_disturbance": result.control.disturbance,
        "control_var_remnant": result.control.remnant,
        "target_crossover_radps": t.frequency_radps,
        "target_phase_margin_deg": t.phase_margin_deg,
        "disturbance_crossover_radps": d.frequency_radps,
        "disturbance_phase_margin_deg": d.phase_margin_deg,
    }
    per_run = [identify([signals_of(r)], task.window_steps, base_frequency(task.measurement_s),
                        np.asarray(task.target.multiples), np.asarray(task.disturbance.multiples))
               for r in result.runs]  # fmt: skip
    window = task.window_steps
    per_run_var = {
        "error_var_deg2": [float(np.var(r.error_rad[-window:])) * _DEG2 for r in result.runs],
        "control_var": [float(np.var(r.control[-window:])) for r in result.runs],
    }
    for key, values in per_run_var.items():
        out[f"{key}_sd"] = float(np.std(values, ddof=1)) if len(values) > 1 else math.nan
    for key, get in (
        ("target_crossover_radps", lambda i: i.target_crossover.frequency_radps),
        ("target_phase_margin_deg", lambda i: i.target_crossover.phase_margin_deg),
        ("disturbance_crossover_radps", lambda i: i.disturbance_crossover.frequency_radps),
        ("disturbance_phase_margin_deg", lambda i: i.disturbance_crossover.phase_margin_deg),
    ):
        values = np.array([get(i) for i in per_run])
        out[f"{key}_sd"] = float(np.std(values, ddof=1)) if len(values) > 1 else math.nan
    if result.control_visual is not None and result.control_vestibular is not None:
        out["control_visual_var"] = result.control_visual.total
        out["control_vestibular_var"] = result.control_vestibular.total
    h1 = complex(result.motion(np.array([1.0]))[0])
    out["motion_gain_1radps"] = abs(h1)
    out["motion_phase_1radps_deg"] = math.degrees(math.atan2(h1.imag, h1.real)) if h1 != 0 else 0.0
    for key in ("visual_gain", "lead_s", "vestibular_gain", "visual_delay_s", "vestibular_delay_s"):
        value = result.params.get(key)
        if isinstance(value, (int, float)):
            out[key] = float(value)
    if out.get("visual_gain"):
        out["vestibular_to_visual_s"] = out.get("vestibular_gain", math.nan) / out["visual_gain"]
    out["saturated_s"] = sum(r.saturated_steps for r in result.runs) * task.dt_s
    return out


def differences(m: Mapping[str, float], reference: Mapping[str, float]) -> dict[str, float]:
    """Each measure's relative difference from the reference's, percent (NaN where either is missing or 0)."""
    out = {}
    for key, ref in reference.items():
        value = m.get(key, math.nan)
        ok = math.isfinite(value) and math.isfinite(ref) and ref != 0.0
        out[key] = 100.0 * (value / ref - 1.0) if ok else math.nan
    return out


def distance(m: Mapping[str, float], reference: Mapping[str, float]) -> float:
    """D of the module docstring (percent); NaN when a measure is missing or not positive."""
    terms = []
    for key in DISTANCE_MEASURES:
        a, b = m.get(key, math.nan), reference.get(key, math.nan)
        if not (a > 0.0 and b > 0.0):
            return math.nan
        terms.append(math.log(a / b) ** 2)
    return 100.0 * math.sqrt(sum(terms) / len(terms))


def bracketed(m: Mapping[str, float], aircraft: Mapping[str, float], none: Mapping[str, float], runs: int,
              slack: float = 0.05) -> dict[str, bool]:  # fmt: skip
    """Per distance measure: whether ``m`` lies between the aircraft's own motion and no motion, beyond what the
    runs resolve: with ``slack`` (a fraction of their gap) or two standard errors of the measure over ``runs``
    single runs (``<measure>_sd``), whichever is larger, on either side."""
    out = {}
    for key in DISTANCE_MEASURES:
        a, n, v = aircraft.get(key, math.nan), none.get(key, math.nan), m.get(key, math.nan)
        lo, hi = min(a, n), max(a, n)
        sd = m.get(f"{key}_sd", math.nan)
        noise = 2.0 * sd / math.sqrt(runs) if math.isfinite(sd) and runs > 0 else 0.0
        pad = max(slack * (hi - lo), noise)
        out[key] = bool(lo - pad <= v <= hi + pad)
    return out


def verdict(table: Mapping[str, Mapping[str, float]], washouts: Sequence[str], runs: int = 1) -> dict[str, Any]:
    """The verdict over a table ``condition -> measures`` (with :data:`AIRCRAFT` and, if flown, :data:`NO_MOTION`):
    the washouts ordered by their distance from flight, the closest, no motion's distance."""
    ref = table[AIRCRAFT]
    dist = {w: distance(table[w], ref) for w in washouts}
    order = sorted(washouts, key=lambda w: (math.isnan(dist[w]), dist[w]))
    out: dict[str, Any] = {"order": order, "distance_pct": dist, "closest": order[0] if order else None}
    if NO_MOTION in table:
        out["no_motion_distance_pct"] = distance(table[NO_MOTION], ref)
        out["bracketed"] = {w: bracketed(table[w], ref, table[NO_MOTION], runs) for w in washouts}
    return out
