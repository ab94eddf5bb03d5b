"""report.md of ``washbench omct``: settings, amplitudes, linearity, boundaries, gain and phase tables per test."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

from washbench.analysis import omct
from washbench.analysis.omct import MAX_DISTORTION, MIN_WINDOW_S, SETTLE_TIME_CONSTANTS, TESTS
from washbench.analysis.omct_boundaries import BoundaryFile
from washbench.cueing.variants import Washout


def report_text(
    points: Sequence[Any],
    settings: Any,
    washouts: Sequence[Washout],
    boundary: BoundaryFile | None,
    plots: dict[str, str],
) -> str:
    """report.md: how the test was run, non-linear and out-of-bounds points, gain and phase per test.

    ``points``: :class:`washbench.runs.omct.OmctPoint`; ``settings``: :class:`washbench.runs.omct.OmctSettings`;
    ``plots``: test name -> Bode plot file name (linked).
    """

    names = [e.name for e in washouts]
    lines = [
        "# Objective Motion Cueing Test",
        "",
        f"Washouts: {', '.join(f'{e.name} ({e.kind})' for e in washouts)}. Sample rate {settings.rate_hz:g} Hz.",
        "",
        "Output: the simulator's actual motion at the pilot's head, from the platform's own state (its "
        "position, attitude and body rates, centred at each sample: `washbench/analysis/omct.py`, "
        "`platform_head_motion`), not the head-rate estimate of `washbench cue` (the paper's Eq. 8 derivative "
        "estimator for the small-angle washout) and not the vestibular models. That estimate is in `omct.csv` "
        "(`estimator_gain`, `estimator_phase_deg`) and drawn as a separate dotted curve, for comparison only. "
        "Gains are dimensionless; for `f_x_to_pitch` and "
        "`f_y_to_roll` the output is the attitude as the specific force it tilts into the pilot (g theta, "
        "-g phi), so a perfect static tilt coordination has gain 1.",
        "",
        f"Each run waits {settings.settle_s:.3g} s ({SETTLE_TIME_CONSTANTS:g} time constants of the slowest "
        f"linearised decay, {settings.slowest_decay_radps:.3g} 1/s: a transient falls to "
        f"{math.exp(-SETTLE_TIME_CONSTANTS):.1e} of its start), then takes the Fourier coefficient at the input "
        f"frequency over whole periods lasting at least {MIN_WINDOW_S:g} s. A point is linear when no platform, "
        f"tilt-rate or rotational-saturation limit bound during its run and the output's residual after the "
        f"fundamental is at most {MAX_DISTORTION:.0%} of the input.",
        "",
        "Amplitudes are chosen here (not ICAO 9625's): 0.5 m/s^2 for the translational tests; for the "
        "rotational tests an attitude of min(2 deg, 50 deg/s^2 / w^2), given as its angular-velocity amplitude "
        "(column `amplitude`, deg/s)."
        + (
            f" Here scaled by {settings.amplitude_scale:g} (`--amplitude-scale`)."
            if settings.amplitude_scale != 1
            else ""
        ),
        "",
    ]
    lines += [
        "Perceived (right-hand plots, `perceived_*` columns): the same responses through the vestibular models "
        "(otolith for specific force, canals for rotation), for each simulator pilot and for the aircraft pilot "
        "given the same input; in `f_x_to_pitch` and `f_y_to_roll` the aircraft does not rotate (gain 0).",
        "",
    ]
    freqs = sorted({p.frequency_radps for p in points})
    scale = settings.amplitude_scale
    lines += [
        "| w (rad/s) | translational (m/s^2) | rotational rate (deg/s) | rotational attitude (deg) |",
        "|---|---|---|---|",
    ]
    for w in freqs:
        f_amp = omct.amplitude("f_x", w)[0] * scale
        r_amp = omct.amplitude("pitch", w)[0] * scale
        lines.append(f"| {w:.4g} | {f_amp:.3g} | {r_amp:.4g} | {r_amp / w:.4g} |")
    lines.append("")
    if boundary is not None:
        lines += [f"Boundaries: {boundary.name} (source: {boundary.source}).", ""]
    else:
        lines += ["Boundaries: none given (`--boundaries FILE`).", ""]
    bad = [p for p in points if not p.linear]
    lines += ["## Linearity", ""]
    if bad:
        lines += [f"{len(bad)} of {len(points)} points are NOT linear:", ""]
        lines += [
            "| washout | test | frequency (rad/s) | amplitude | limits bound | distortion |",
            "|---|---|---|---|---|---|",
        ]
        for p in bad:
            lines.append(
                f"| {p.washout} | {p.test} | {p.frequency_radps:.3g} | {p.amplitude:.3g} {p.amplitude_unit} | "
                f"{', '.join(p.saturated) or '-'} | {p.distortion:.2e} |"
            )
        lines.append("")
    else:
        worst = max(points, key=lambda p: p.distortion)
        lines += [
            f"All {len(points)} points are linear (largest distortion {worst.distortion:.1e}, "
            f"{worst.washout} {worst.test} at {worst.frequency_radps:.3g} rad/s).",
            "",
        ]
    if boundary is not None:
        out = [p for p in points if p.gain_inside is False or p.phase_inside is False]
        checked = [p for p in points if p.gain_inside is not None or p.phase_inside is not None]
        lines += ["## Boundaries", "", f"{len(checked)} points checked, {len(out)} outside.", ""]
        for name in names:
            n_out = sum(1 for p in out if p.washout == name)
            n_chk = sum(1 for p in checked if p.washout == name)
            lines.append(f"- {name}: {n_chk - n_out} of {n_chk} inside")
        lines.append("")
    lines += ["## Gain and phase per test", ""]
    by: dict[tuple[str, str], list[Any]] = {(p.washout, p.test): [] for p in points}
    for p in points:
        by[(p.washout, p.test)].append(p)
    for test in TESTS:
        if not any((n, test.name) in by for n in names):
            continue
        lines += [f"### {test.name} ({test.input_axis} -> {test.output_axis})", ""]
        if test.name in plots:
            lines += [f"![{test.name}]({plots[test.name]})", ""]
        head = "| w (rad/s) | " + " | ".join(f"{n} gain | {n} phase (deg)" for n in names) + " |"
        lines += [head, "|---|" + "---|---|" * len(names)]
        for w in freqs:
            cells = []
            for n in names:
                pts = [p for p in by.get((n, test.name), []) if p.frequency_radps == w]
                if pts:
                    p = pts[0]
                    mark = "" if p.linear else " (non-linear)"
                    if p.gain_inside is False or p.phase_inside is False:
                        mark += " (outside)"
                    cells.append(f"{p.gain:.4g}{mark} | {p.phase_deg:.1f}")
                else:
                    cells.append(" | ")
            lines.append(f"| {w:.4g} | " + " | ".join(cells) + " |")
        lines.append("")
    return "\n".join(lines) + "\n"
