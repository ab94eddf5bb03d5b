"""How resampling and real-time logging change washbench's metrics: measured on JSBSim's own scripts.

For each script (flown in place from the jsbsim package, first ``--start-s`` seconds cut: untrimmed
start), the clean 120 Hz trace is cued once as the reference, then again after each of these input
degradations, each brought back with ``--resample`` where needed:

- ``down N Hz``: resampled to N Hz (anti-alias low-pass then interpolation);
- ``xplane 20 Hz``: logged at 20 Hz with +-1 ms timing jitter, time written with 3 decimals, back to 120 Hz;
- ``3 decimals``: 120 Hz with time rounded to 3 decimals, back to 120 Hz;
- ``drop 1``: one sample in 50 dropped, back to 120 Hz.

Printed per case: the largest change of any washout's ranking score (absolute; scores are relative errors,
0 perfect, 1 no better than standing still), the largest change of an integral error relative to the
aircraft pilot's own perceived motion in that DOF (the ranking's denominator; at least the ranking's motion
floor, 0.05 m/s^2*s or 0.5 deg, so a DOF the pilot did not feel does not divide by ~0), and whether the ranking
order stayed the same::

    .venv/bin/python tools/resample_effect.py
"""

from __future__ import annotations

import argparse

import numpy as np

from washbench.analysis.ranking import MOTION_FLOOR, perceived_motion, rank
from washbench.cueing import WASHOUT_NAMES, load_washout_params
from washbench.flight.scripts import bundled_script, fly_script
from washbench.io.readers import Samples
from washbench.io.resample import resample, to_motion
from washbench.platform import load_platform_limits
from washbench.runs.chain import cue_motion


def samples_of(t: np.ndarray, f: np.ndarray, w: np.ndarray) -> Samples:
    from pathlib import Path

    return Samples(Path("mem"), "csv", t, f, w, {}, None)


def scores(motion, params, limits):  # type: ignore[no-untyped-def]
    r = cue_motion(motion, WASHOUT_NAMES, params, limits)
    ac = r.perceived["aircraft"]
    felt = perceived_motion(ac.f_mps2, ac.omega_radps, motion.dt_s)
    ranking = rank(r.metrics, felt)
    return {x.washout: x.score for x in ranking}, {(m.washout, m.dof): m.integral_error for m in r.metrics}, felt


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scripts", nargs="+", default=["c172_cruise_8K", "737_cruise_steady_turn", "ah1s_flight_test"])
    ap.add_argument("--seconds", type=float, default=60.0)
    ap.add_argument("--start-s", type=float, default=6.0)
    args = ap.parse_args()
    params, limits = load_washout_params(None), load_platform_limits(None)
    rng = np.random.default_rng(1)
    print(f"{'script':<24} {'case':<14} {'max |d score|':>13} {'max |dE|/M':>11} {'same order':>10}")
    for name in args.scripts:
        seg = fly_script(bundled_script(name), max_time_s=args.seconds).segments[0]
        c = seg.columns
        keep = c["t_s"] >= args.start_s
        t = c["t_s"][keep]
        f = np.column_stack([c[f"f_{a}_mps2"] for a in "xyz"])[keep]
        w = np.column_stack([c[f"omega_{a}_degps"] for a in "xyz"])[keep]
        hz = round(1.0 / (t[1] - t[0]))
        ref_s, ref_e, felt = scores(to_motion(samples_of(t, f, w)), params, limits)

        cases = {}
        for down in (60, 50, 30, 20):
            cases[f"down {down} Hz"] = (samples_of(t, f, w), down)
        tj = np.arange(t[0], t[-1], 1 / 20) + rng.uniform(-1e-3, 1e-3, size=len(np.arange(t[0], t[-1], 1 / 20)))
        tj = np.clip(tj, t[0], t[-1])
        cols = [np.interp(tj, t, x) for x in (*f.T, *w.T)]
        fj, wj = np.column_stack(cols[:3]), np.column_stack(cols[3:])
        cases["xplane 20 Hz"] = (samples_of(np.round(tj, 3), fj, wj), hz)
        cases["3 decimals"] = (samples_of(np.round(t, 3), f, w), hz)
        keep1 = np.ones(len(t), bool)
        keep1[25::50] = False
        cases["drop 1 in 50"] = (samples_of(t[keep1], f[keep1], w[keep1]), hz)
        for label, (s, rate) in cases.items():
            motion, _ = resample(s, rate)
            sc, e, _ = scores(motion, params, limits)
            d_score = max(abs(sc[k] - ref_s[k]) for k in ref_s)
            d_e = max(abs(e[k] - ref_e[k]) / max(felt[k[1]], MOTION_FLOOR[k[1]]) for k in ref_e)
            same = sorted(sc, key=sc.get) == sorted(ref_s, key=ref_s.get)
            print(f"{name:<24} {label:<14} {d_score:13.4f} {d_e:11.4f} {'yes' if same else 'NO':>10}")


if __name__ == "__main__":
    main()
