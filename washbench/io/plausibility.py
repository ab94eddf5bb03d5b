"""Plausibility of a recorded motion: the checks that catch wrong units, wrong axes and crashes.

Each check gives one line saying what looks wrong, what to check and which option fixes it. None of
them changes the data: ``washbench cue`` prints them as warnings (``--strict``: errors), and a crash in
the data (specific force above 10 g or angular velocity above 1000 deg/s) is reported in the results
as a failure, not scored silently.

- sample rate outside 10 Hz .. 10 kHz (time in ms or ns?);
- |f| far from g in the quiet parts (|omega| < 5 deg/s; the whole trace if it has none): median
  outside 0.6 g .. 1.6 g (specific force in g or ft/s^2?);
- mean f_z above zero (a z-up sensor? washbench's z points down, f_z = -g at rest);
- |f| above 10 g or |omega| above 1000 deg/s (a crash, a spike, or rad/s read as deg/s?);
- angular velocity never above 1.5 deg/s while the specific force varies by more than 2 m/s^2
  (rates in rad/s read as deg/s?);
- an all-zero or constant input (a missing signal?).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from washbench.io.results import Motion
from washbench.io.units import G0_MPS2

RATE_MIN_HZ, RATE_MAX_HZ = 10.0, 10_000.0
QUIET_OMEGA_DEGPS = 5.0
G_RATIO_RANGE = (0.6, 1.6)
CRASH_F_MPS2 = 10.0 * G0_MPS2
CRASH_OMEGA_DEGPS = 1000.0
SMALL_RATES_DEGPS = 1.5
VARYING_F_MPS2 = 2.0


@dataclass(frozen=True)
class Finding:
    """One plausibility warning: ``text`` (one line), ``crash`` True for a crash or spike in the data."""

    text: str
    crash: bool = False


def check_motion(m: Motion) -> list[Finding]:
    """Every plausibility finding on ``m`` (an empty list when it all looks right)."""
    out: list[Finding] = []
    hz = 1.0 / m.dt_s
    if not RATE_MIN_HZ <= hz <= RATE_MAX_HZ:
        out.append(
            Finding(
                f"sample rate {hz:.4g} Hz is outside {RATE_MIN_HZ:g} Hz .. {RATE_MAX_HZ:g} Hz: is the time in ms "
                "or ns? (give its unit with --columns t=COLUMN:ms)"
            )
        )
    f, w = m.f_mps2, m.omega_degps_out()
    fn = np.linalg.norm(f, axis=1)
    wn = np.linalg.norm(w, axis=1)
    if np.ptp(f, axis=0).max() == 0.0 and np.ptp(w, axis=0).max() == 0.0:
        what = "all zero" if not f.any() and not w.any() else "constant"
        out.append(Finding(f"the motion is {what} throughout: a missing or wrongly mapped signal? (check --columns)"))
        return out
    quiet = wn < QUIET_OMEGA_DEGPS
    ratio = float(np.median(fn[quiet] if quiet.any() else fn)) / G0_MPS2
    if not G_RATIO_RANGE[0] <= ratio <= G_RATIO_RANGE[1]:
        out.append(
            Finding(
                f"|f| is {ratio * G0_MPS2:.4g} m/s^2 ({ratio:.3g} g) in the quiet parts, far from g: is the specific "
                "force in g or ft/s^2? (give its unit with --columns f_x=COLUMN:g,...)"
            )
        )
    mean_fz = float(f[:, 2].mean())
    if mean_fz > 0.0:
        out.append(
            Finding(
                f"mean f_z is {mean_fz:+.4g} m/s^2, above zero: is the sensor's z axis up? washbench's z points down "
                "(f_z = -g at rest); use --axes flu for a z-up, y-left sensor"
            )
        )
    i_f, i_w = int(np.argmax(fn)), int(np.argmax(wn))
    if fn[i_f] > CRASH_F_MPS2:
        out.append(
            Finding(
                f"|f| reaches {fn[i_f]:.4g} m/s^2 ({fn[i_f] / G0_MPS2:.3g} g) at t = {m.t_s[i_f]:.6g} s, above 10 g: "
                "a crash or a spike? (cut it with --end-s)",
                crash=True,
            )
        )
    if wn[i_w] > CRASH_OMEGA_DEGPS:
        out.append(
            Finding(
                f"|omega| reaches {wn[i_w]:.4g} deg/s at t = {m.t_s[i_w]:.6g} s, above {CRASH_OMEGA_DEGPS:g} deg/s: a "
                "crash, a spike, or rates in rad/s read as deg/s? (--columns omega_x=COLUMN:radps,...)",
                crash=True,
            )
        )
    if wn.max() < SMALL_RATES_DEGPS and float(np.ptp(f, axis=0).max()) > VARYING_F_MPS2:
        out.append(
            Finding(
                f"|omega| never exceeds {wn.max():.3g} deg/s while the specific force varies by "
                f"{float(np.ptp(f, axis=0).max()):.3g} m/s^2: are the rates in rad/s? "
                "(give their unit with --columns omega_x=COLUMN:radps,...)"
            )
        )
    return out
