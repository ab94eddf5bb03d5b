"""The pilot model against the literature with JSBSim in the loop, and the bundled tasks side by side: the numbers
and the figure of docs/pilot-model.md.

1. The motion filter gain sweep: the c172p roll task flown through a first-order high-pass of gain K on the roll
   axis (the large-angle washout with ``scale.angular_velocity = K`` and its tilt coordination held at 0.001 deg/s:
   its rotational high-pass s / (s + 0.5) alone turns the cockpit), K = 1, 0.75, 0.5, 0.25 and 0 (no motion),
   beside the aircraft's own motion; the adapted visual gain and lead against the motion filter's gain at
   1 rad/s, with the compiled trend of Pool et al. (2011): -20 % and +30 % from gain 1 to 0.
2. Each bundled task (c172 and columbia400, roll and pitch) with the three default washouts.

    python tools/pilot_literature_check.py OUT_DIR      # about a minute of CPU per task

Writes ``OUT_DIR/<task>/`` (``washbench track`` result sets), ``OUT_DIR/summary.md`` (the tables) and
``docs/img/pilot_gain_sweep.png``.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

from washbench.io.paths import TASKS_DIR
from washbench.runs.options import load_options
from washbench.runs.outputs import Outputs
from washbench.runs.track import TrackOptions, run_track

ROOT = Path(__file__).resolve().parents[1]
GAINS = (1.0, 0.75, 0.5, 0.25)  # and 0: the no-motion condition


def _sweep(out: Path) -> tuple[dict, list[str]]:
    variants = [f"K{int(k * 100):03d}=large-angle,scale.angular_velocity={k},tilt.rate_limit_degps=0.001"
                for k in GAINS]  # fmt: skip
    options = load_options(variants=variants, outputs=Outputs(recording=False, figures=True))
    summary = run_track(TASKS_DIR / "c172" / "roll.yaml", out / "gain_sweep", options, TrackOptions(progress=False))
    lines = ["| condition | motion gain at 1 rad/s | K_v | T_L (s) | K_m / K_v (s) | error variance (deg²) | "
             "disturbance crossover (rad/s) | target crossover (rad/s) | distance (%) |",
             "|---|---|---|---|---|---|---|---|---|"]  # fmt: skip
    for c in summary["conditions"]:
        m = c["measures"]
        lines.append(
            f"| {c['name']} | {m['motion_gain_1radps']:.2f} | {m['visual_gain']:.3f} | {m['lead_s']:.3f} | "
            f"{m.get('vestibular_to_visual_s') or 0:.3f} | {m['error_var_deg2']:.3f} | "
            f"{m['disturbance_crossover_radps']:.2f} | {m['target_crossover_radps']:.2f} | "
            f"{c.get('distance_pct') or 0:.1f} |"
        )
    return summary, lines


def _figure(summary: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = [c for c in summary["conditions"] if c["name"].startswith("K") or c["name"] == "no-motion"]
    rows.sort(key=lambda c: -c["measures"]["motion_gain_1radps"])
    gain = [c["measures"]["motion_gain_1radps"] for c in rows]
    kv = [c["measures"]["visual_gain"] for c in rows]
    tl = [c["measures"]["lead_s"] for c in rows]
    kv1, tl1 = kv[0], tl[0]  # K = 1
    fig, axes = plt.subplots(1, 2, figsize=(10.0, 4.0))
    for ax, values, ref, label, trend in ((axes[0], kv, kv1, "visual gain K_v", -0.20),
                                          (axes[1], tl, tl1, "visual lead T_L", 0.30)):  # fmt: skip
        g1 = gain[0]
        ax.plot(gain, [100.0 * (v / ref - 1.0) for v in values], "o-", label="adapted model, JSBSim in the loop")
        ax.plot([g1, 0.0], [0.0, 100.0 * trend], "k--", label=f"compiled trend, {100 * trend:+.0f} % (Pool 2011)")
        ax.set_xlabel("motion filter gain at 1 rad/s")
        ax.set_ylabel(f"{label}: change from K = 1 (%)")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("c172p roll task, first-order high-pass of gain K on the roll axis, K from 1 to 0")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def main() -> int:
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else Path("pilot-check")
    out.mkdir(parents=True, exist_ok=True)
    text = ["# The pilot model against the literature, JSBSim in the loop", ""]
    summary, lines = _sweep(out)
    _figure(summary, ROOT / "docs" / "img" / "pilot_gain_sweep.png")
    rows = {c["name"]: c["measures"] for c in summary["conditions"]}
    k1, k0 = rows["K100"], rows["no-motion"]
    text += ["## Gain sweep, c172p roll", "", *lines, "",
             f"K_v from K = 1 to 0: {100 * (k0['visual_gain'] / k1['visual_gain'] - 1):+.1f} %; "
             f"T_L: {100 * (k0['lead_s'] / k1['lead_s'] - 1):+.1f} %.", ""]  # fmt: skip
    options = load_options(outputs=Outputs(recording=False, figures=True))
    for task in ("c172/roll", "c172/pitch", "columbia400/roll", "columbia400/pitch"):
        s = run_track(TASKS_DIR / f"{task}.yaml", out / task.replace("/", "_"), options, TrackOptions(progress=False))
        text += [f"## {task}", "", f"closest to flight: {s['verdict'].get('closest')}; no motion: "
                 f"{s['verdict'].get('no_motion_distance_pct', math.nan):.1f} %", "",
                 "| condition | K_v | T_L (s) | K_m (control/(rad/s)) | error variance (deg²) | control variance | "
                 "disturbance crossover (rad/s) | disturbance phase margin (deg) | target crossover (rad/s) | "
                 "target phase margin (deg) | distance (%) |", "|" + "---|" * 11]  # fmt: skip
        for c in s["conditions"]:
            if not c["ok"]:
                text.append(f"| {c['name']} | failed: {c['reason']} |")
                continue
            m = c["measures"]
            text.append(
                f"| {c['name']} | {m['visual_gain']:.3f} | {m['lead_s']:.3f} | {m['vestibular_gain']:.3f} | "
                f"{m['error_var_deg2']:.3f} | {m['control_var']:.3g} | {m['disturbance_crossover_radps']:.2f} | "
                f"{m['disturbance_phase_margin_deg']:.1f} | {m['target_crossover_radps']:.2f} | "
                f"{m['target_phase_margin_deg']:.1f} | {c.get('distance_pct') or 0:.1f} |"
            )
        text.append("")
    (out / "summary.md").write_text("\n".join(text) + "\n")
    print((out / "summary.md").read_text())
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
