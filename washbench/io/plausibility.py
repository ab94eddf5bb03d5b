"""Plausibility of a recorded motion: the checks that catch wrong units, wrong axes and crashes.

Each check gives one line saying what looks wrong, what to check and which option fixes it; a unit hint
names a unit under which the data would look right, given the unit the column was read in (a rate
declared ``:radps`` reaching 5000 deg/s is in deg/s, not the other way round). None of
them changes the data: ``washbench cue`` prints them as warnings (``--strict``: errors), and a crash in
the data (specific force above 10 g or angular velocity above 1000 deg/s) is reported in the results
as a failure, not scored silently.

- sample rate outside 10 Hz .. 10 kHz (time in ms or ns?);
- |f| far from g in the quiet parts (|omega| < 5 deg/s; the whole trace if it has none): median
  outside 0.6 g .. 1.6 g (specific force in g or ft/s^2?);
- mean f_z above zero (a z-up sensor? washbench's z points down, f_z = -g at rest);
- |f| above 10 g or |omega| above 1000 deg/s (a crash, a spike, or deg/s read as rad/s?);
- angular velocity never above 1.5 deg/s while the specific force varies by more than 2 m/s^2
  (rates in rad/s read as deg/s?);
- an all-zero or constant input (a missing signal?).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np

from washbench.io import units
from washbench.io.motion import Motion
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


def check_motion(m: Motion, declared: Mapping[str, str] | None = None) -> list[Finding]:
    """Every plausibility finding on ``m`` (an empty list when it all looks right); see :func:`check_arrays`."""
    return check_arrays(m.t_s, m.dt_s, m.f_mps2, m.omega_degps_out(), declared)


def _other_units(quantity: str, declared: str, scale: float, plausible: Callable[[float], bool]) -> list[str]:
    """The units of ``quantity`` under which the data would look right: a value read as ``declared`` is
    ``scale`` (in canonical units); read as unit u it would be ``scale * factor(u) / factor(declared)``."""
    here = units.unit_factor(quantity, declared)
    out = []
    for u in units.units_of(quantity):
        if u not in (declared, "timestamp") and plausible(scale * units.unit_factor(quantity, u) / here):
            out.append(u)
    return out


def _unit_hint(field: str, unit: str, declared: str) -> str:
    """How to say a unit on the command line, and what the column was read as."""
    return f"read as {declared} now; give the unit with --columns {field}=COLUMN:{unit},..."


def check_arrays(
    t_s: np.ndarray,
    dt_s: float,
    f_mps2: np.ndarray,
    w_degps: np.ndarray,
    declared: Mapping[str, str] | None = None,
) -> list[Finding]:
    """Every plausibility finding on a motion: time ``t_s`` (N,) [s] at the typical step ``dt_s`` [s] (the grid's,
    or the median step before resampling), specific force ``f_mps2`` (N, 3) [m/s^2] and angular velocity
    ``w_degps`` (N, 3) [deg/s] after the unit conversion. ``declared``: the units the input's columns were read
    in (``t``: a time unit, ``f``: a specific-force unit, ``omega``: a rate unit, :mod:`washbench.io.units`;
    default washbench's own), so that a hint names the unit under which the data would look right, never the one
    already given.
    """
    t_unit = units.normalise_unit((declared or {}).get("t", "s"))
    f_unit = units.normalise_unit((declared or {}).get("f", "mps2"))
    w_unit = units.normalise_unit((declared or {}).get("omega", "degps"))
    out: list[Finding] = []
    hz = 1.0 / dt_s
    if not RATE_MIN_HZ <= hz <= RATE_MAX_HZ:
        fits = _other_units(units.TIME, t_unit, dt_s, lambda step: RATE_MIN_HZ <= 1.0 / step <= RATE_MAX_HZ)
        hint = f"is the time in {fits[0]}? ({_unit_hint('t', fits[0], t_unit)})" if fits else ""
        out.append(
            Finding(
                f"sample rate {hz:.4g} Hz is outside {RATE_MIN_HZ:g} Hz .. {RATE_MAX_HZ:g} Hz"
                + (f": {hint}" if hint else f" (time read as {t_unit})")
            )
        )
    f, w = f_mps2, w_degps
    fn = np.linalg.norm(f, axis=1)
    wn = np.linalg.norm(w, axis=1)
    if np.ptp(f, axis=0).max() == 0.0 and np.ptp(w, axis=0).max() == 0.0:
        what = "all zero" if not f.any() and not w.any() else "constant"
        out.append(Finding(f"the motion is {what} throughout: a missing or wrongly mapped signal? (check --columns)"))
        return out
    quiet = wn < QUIET_OMEGA_DEGPS
    ratio = float(np.median(fn[quiet] if quiet.any() else fn)) / G0_MPS2
    if not G_RATIO_RANGE[0] <= ratio <= G_RATIO_RANGE[1]:
        fits = _other_units(units.FORCE, f_unit, ratio, lambda r: G_RATIO_RANGE[0] <= r <= G_RATIO_RANGE[1])
        if fits:
            hint = f"is it in {fits[0]}? ({_unit_hint('f_x', fits[0], f_unit)})"
        else:
            hint = f"in no unit would it be about g (read as {f_unit}): is gravity removed, or a wrong column mapped?"
        out.append(
            Finding(
                f"|f| is {ratio * G0_MPS2:.4g} m/s^2 ({ratio:.3g} g) in the quiet parts, far from g: {hint}"
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
                f"|f| reaches {fn[i_f]:.4g} m/s^2 ({fn[i_f] / G0_MPS2:.3g} g) at t = {t_s[i_f]:.6g} s, above 10 g: "
                "a crash or a spike? (cut it with --end-s)",
                crash=True,
            )
        )
    if wn[i_w] > CRASH_OMEGA_DEGPS:
        fits = _other_units(units.RATE, w_unit, float(wn[i_w]), lambda v: SMALL_RATES_DEGPS <= v <= CRASH_OMEGA_DEGPS)
        unit_hint = (
            f", or rates in {fits[0]}? ({_unit_hint('omega_x', fits[0], w_unit)})" if fits else ""
        )
        out.append(
            Finding(
                f"|omega| reaches {wn[i_w]:.4g} deg/s at t = {t_s[i_w]:.6g} s, above {CRASH_OMEGA_DEGPS:g} deg/s: a "
                f"crash or a spike{unit_hint or '? (cut it with --end-s)'}",
                crash=True,
            )
        )
    if wn.max() < SMALL_RATES_DEGPS and float(np.ptp(f, axis=0).max()) > VARYING_F_MPS2:
        fits = _other_units(units.RATE, w_unit, float(wn.max()), lambda v: v >= SMALL_RATES_DEGPS)
        hint = (
            f"are the rates in {fits[0]}? ({_unit_hint('omega_x', fits[0], w_unit)})"
            if fits
            else f"they are read as {w_unit} already: is a wrong column mapped? (check --columns)"
        )
        out.append(
            Finding(
                f"|omega| never exceeds {wn.max():.3g} deg/s while the specific force varies by "
                f"{float(np.ptp(f, axis=0).max()):.3g} m/s^2: {hint}"
            )
        )
    return out
