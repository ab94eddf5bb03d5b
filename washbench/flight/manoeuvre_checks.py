"""The checks of a manoeuvre that its schema cannot express, each problem one line naming the file, line and field.

A known aircraft with a pilot profile (read here), exactly one start, a start inside the aircraft's envelope, one
target per control axis, open-loop inputs that fit their shape and the surface travel, JSBSim properties that exist
in the model (the model is loaded with JSBSim, only when an input names a property), phases that can end, at most
an hour of flight, checks on known signals. Run by :class:`washbench.flight.manoeuvre.Manoeuvre` however it is built.
"""

from __future__ import annotations

import difflib
import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from washbench.errors import WashbenchError, located
from washbench.flight.columns import COLUMN_NAMES, RUNWAY_COLUMNS
from washbench.flight.console import quiet_stdout
from washbench.flight.inputs import shape_extent
from washbench.flight.jsbsim_xml import aircraft_for_jsbsim, scratch_output_dir
from washbench.flight.manoeuvre_schema import (
    EVENT_STATS,
    HEADING_SIGNALS,
    HEADING_VALUE_STATS,
    LATERAL_TARGETS,
    MAX_MANOEUVRE_S,
    MAX_MANOEUVRE_STEPS,
    PITCH_TARGETS,
    RATE_SIGNALS,
    ControlInput,
    Hold,
    ManoeuvreFields,
    Phase,
    Signal,
    Until,
)
from washbench.flight.profile import PilotProfile, load_profile
from washbench.io.paths import AircraftFiles, find_aircraft_files, jsbsim_root
from washbench.io.yamlio import Loc, StrictModel, format_field_path, line_of

#: Lowest air start above the ground (ft): lower, there is no room to trim or recover.
AIR_START_MIN_AGL_FT = 100.0
#: Highest air start when the pilot profile gives no ``limits.ceiling_ft``.
DEFAULT_CEILING_FT = 50000.0


class Where:
    """Collects one-line problems for a file (``FILE:LINE: FIELD: PROBLEM``; ``FIELD: PROBLEM`` without a file)."""

    def __init__(self, path: Path | None, lines: dict[Loc, int]) -> None:
        self.path = path
        self.lines = lines
        self.problems: list[str] = []

    def add(self, loc: Loc, problem: str) -> None:
        field = format_field_path(loc)
        if self.path is None:
            self.problems.append(f"{field}: {problem}")
        else:
            self.problems.append(located(self.path, problem, line=line_of(self.lines, loc), field=field))

    def error(self, loc: Loc, problem: str) -> Exception:
        """Add the problem and return the error to raise now, holding every problem so far (for checks that
        cannot go on after it): WashbenchError for a file, ValueError (pydantic's ValidationError) from Python."""
        self.add(loc, problem)
        if self.path is None:
            return ValueError("; ".join(self.problems))
        return WashbenchError(self.problems[0], self.problems[1:])


def set_fields(model: StrictModel, names: Sequence[str]) -> list[str]:
    """The names among ``names`` that ``model`` sets (neither None nor False)."""
    return [n for n in names if getattr(model, n) is not None and getattr(model, n) is not False]


def check_semantics(m: ManoeuvreFields, where: Where, aircraft_dirs: Sequence[Path] = ()) -> AircraftFiles | None:
    """Checks a schema cannot express; every problem is added to ``where`` (in file order).

    Returns where the aircraft and its pilot profile were found (``aircraft_dirs``: the ``--aircraft-dir``
    folders; ``where.path``, the manoeuvre file, starts the search), None if they were not.
    """
    try:
        files = find_aircraft_files(m.aircraft, where.path, aircraft_dirs, m.pilot_profile)
    except WashbenchError as exc:
        field = "pilot_profile" if str(exc).startswith("pilot_profile:") else "aircraft"
        where.add((field,), str(exc).removeprefix("pilot_profile: "))
        return None
    profile = load_profile(files.profile)

    starts = set_fields(m.start, ("air", "runway"))
    if len(starts) != 1:
        where.add(("start",), "give exactly one of 'air' or 'runway'")
    if m.start.runway is not None and m.runway is None:
        where.add(("start", "runway"), "a runway start needs a top-level 'runway'")
    air = m.start.air
    if air is not None:
        if air.before_threshold_ft is not None and m.runway is None:
            where.add(("start", "air", "before_threshold_ft"), "needs a top-level 'runway'")
        if air.heading_deg is None and m.runway is None:
            where.add(("start", "air", "heading_deg"), "missing required field (no runway to take it from)")
        if (air.latitude_deg is None) != (air.longitude_deg is None):
            where.add(("start", "air", "latitude_deg"), "give both latitude_deg and longitude_deg, or neither")
        if air.before_threshold_ft is not None and air.latitude_deg is not None:
            where.add(("start", "air", "before_threshold_ft"), "give either lat/lon or before_threshold_ft")
        if not profile.speeds.stall_kts <= air.airspeed_kts <= profile.speeds.vne_kts:
            where.add(
                ("start", "air", "airspeed_kts"),
                f"{air.airspeed_kts:g} kt is outside {m.aircraft}'s flight envelope "
                f"({profile.speeds.stall_kts:g}..{profile.speeds.vne_kts:g} kt)",
            )
        if air.flaps_deg > profile.limits.flaps_max_deg:
            where.add(("start", "air", "flaps_deg"), f"more than the {profile.limits.flaps_max_deg:g} deg max")
        ground_ft = m.runway.elevation_ft if m.runway is not None else 0.0
        ceiling_ft = profile.limits.ceiling_ft if profile.limits.ceiling_ft is not None else DEFAULT_CEILING_FT
        if not ground_ft + AIR_START_MIN_AGL_FT <= air.altitude_ft <= ceiling_ft:
            where.add(
                ("start", "air", "altitude_ft"),
                f"{air.altitude_ft:g} ft is outside {m.aircraft}'s air-start range "
                f"({ground_ft + AIR_START_MIN_AGL_FT:g}..{ceiling_ft:g} ft: at least {AIR_START_MIN_AGL_FT:g} ft "
                f"above the {'runway' if m.runway is not None else 'ground'} at {ground_ft:g} ft, at most the ceiling)",
            )

    turbulence = m.environment.turbulence
    if turbulence is not None and turbulence.severity != "none" and turbulence.seed is None:
        where.add(("environment", "turbulence", "seed"), f"missing required field (severity {turbulence.severity} "
                  "needs a seed: the same seed gives the same gusts; severity none needs none)")  # fmt: skip

    on_ground = m.start.runway is not None
    names = [p.name for p in m.phases]
    for i, phase in enumerate(m.phases):
        base: Loc = ("phases", i)
        if names.index(phase.name) != i:
            where.add((*base, "name"), f"duplicate phase name '{phase.name}'")
        hold, until = phase.hold, phase.until
        phase_problems = len(where.problems)
        lateral = set_fields(hold, LATERAL_TARGETS)
        pitch = set_fields(hold, PITCH_TARGETS)
        if len(lateral) > 1:
            where.add((*base, "hold", lateral[1]), f"contradicts '{lateral[0]}' (one lateral target at a time)")
        if len(pitch) > 1:
            where.add((*base, "hold", pitch[1]), f"contradicts '{pitch[0]}' (one pitch target at a time)")
        if hold.airspeed_kts is not None and hold.throttle is not None and pitch:
            where.add(
                (*base, "hold", "airspeed_kts"),
                f"contradicts 'throttle' and '{pitch[0]}': airspeed needs the throttle or the elevator free",
            )
        if hold.load_factor is not None and not profile.limits.nz_min <= hold.load_factor <= profile.limits.nz_max:
            where.add(
                (*base, "hold", "load_factor"),
                f"{hold.load_factor:g} g is outside {m.aircraft}'s load-factor limits "
                f"({profile.limits.nz_min:g}..{profile.limits.nz_max:g} g)",
            )
        if hold.airspeed_kts is not None and hold.airspeed_kts > profile.speeds.vne_kts:
            where.add((*base, "hold", "airspeed_kts"), f"above {m.aircraft}'s VNE")
        if hold.flaps_deg is not None and hold.flaps_deg > profile.limits.flaps_max_deg:
            where.add((*base, "hold", "flaps_deg"), f"more than the {profile.limits.flaps_max_deg:g} deg max")
        if hold.wing_low and not hold.centreline:
            where.add((*base, "hold", "wing_low"), "needs 'centreline: true' (the track it holds)")
        if (hold.centreline or hold.glide_path_deg is not None or hold.flare) and m.runway is None:
            key = "centreline" if hold.centreline else ("flare" if hold.flare else "glide_path_deg")
            where.add((*base, "hold", key), "needs a top-level 'runway'")
        if phase.inputs is not None:
            _check_inputs(phase, (*base, "inputs"), profile, where)
        conditions = set_fields(until, [f for f in Until.model_fields if f != "timeout_s"])
        reasons = [_never_reason(c, until, hold, on_ground, profile, m) for c in conditions]
        if len(where.problems) > phase_problems:
            pass  # whether the phase can end depends on a hold already in error: no consequential error
        elif not conditions:
            where.add((*base, "until"), "the phase can never end: give at least one end condition")
        elif all(r is not None for r in reasons):
            where.add((*base, "until", conditions[0]), f"the phase can never end: {reasons[0]}")
        if until.event == "liftoff":
            on_ground = False
        elif until.event in ("touchdown",):
            on_ground = True
        elif until.agl_below_ft is not None and until.agl_below_ft <= 0 and not on_ground:
            on_ground = True

    longest_s = sum(p.until.duration_s if p.until.duration_s is not None else p.until.timeout_s for p in m.phases)
    if longest_s > MAX_MANOEUVRE_S or longest_s * m.rate_hz > MAX_MANOEUVRE_STEPS:
        where.add(
            ("phases",),
            f"the manoeuvre may last {longest_s:g} s (each phase's duration_s, else its timeout_s), "
            f"{longest_s * m.rate_hz:.0f} steps at {m.rate_hz} Hz: the longest accepted is {MAX_MANOEUVRE_S:g} s "
            f"and {MAX_MANOEUVRE_STEPS} steps (split it into several manoeuvres, or give shorter timeouts)",
        )

    for j, check in enumerate(m.checks):
        base = ("checks", j)
        if check.signal not in COLUMN_NAMES and check.signal != "sink_fps":
            close = difflib.get_close_matches(check.signal, [*COLUMN_NAMES, "sink_fps"], n=1, cutoff=0.7)
            hint = f"did you mean '{close[0]}'?" if close else "a signal is a flight.parquet column, e.g. phi_deg"
            where.add((*base, "signal"), f"unknown signal '{check.signal}' ({hint})")
        if check.signal == "sink_fps" and check.stat not in EVENT_STATS:
            where.add((*base, "stat"), "sink_fps is measured at an event: use at_touchdown or at_liftoff")
        if check.signal in RUNWAY_COLUMNS and m.runway is None:
            where.add((*base, "signal"), f"'{check.signal}' needs a top-level 'runway'")
        if check.stat == "turned" and check.signal != "psi_deg":
            where.add((*base, "stat"), "'turned' applies to the heading signal psi_deg")
        if check.stat == "rotated" and check.signal not in RATE_SIGNALS:
            where.add((*base, "stat"), f"'rotated' integrates a body rate: {', '.join(RATE_SIGNALS)}")
        if check.min is None and check.max is None:
            where.add(base, "give a 'min', a 'max' or both")
        arc = check.signal in HEADING_SIGNALS and check.stat in HEADING_VALUE_STATS  # min > max: through north
        if check.min is not None and check.max is not None and check.min > check.max and not arc:
            where.add((*base, "min"), f"greater than max ({check.min:g} > {check.max:g})")
        if arc:
            for key in ("min", "max"):
                v = getattr(check, key)
                if v is not None and not 0 <= v <= 360:
                    where.add((*base, key), f"a heading limit is 0..360 deg, got {v:g}")
        for k, name in enumerate(check.phases or ()):
            if name not in names:
                where.add((*base, "phases", k), f"no phase named '{name}'")
    _check_properties(m, files, where)
    return files


#: Shape keys each input shape uses (the others must be left out: a stray key is a mistake).
SHAPE_KEYS: dict[str, tuple[tuple[str, ...], tuple[str, ...]]] = {  # shape: (required, optional)
    "step": ((), ()),
    "pulse": (("duration_s",), ()),
    "doublet": (("duration_s",), ()),
    "3211": (("duration_s",), ()),
    "sine": (("period_s",), ("duration_s",)),
    "chirp": (("duration_s", "start_hz", "end_hz"), ("sweep",)),
}
_SHAPE_PARAMS = ("duration_s", "period_s", "start_hz", "end_hz")
#: What each axis's free / fixed input takes away from the pilot's hold targets.
_AXIS_TARGETS = {
    "aileron": LATERAL_TARGETS,
    "elevator": PITCH_TARGETS,
    "rudder": ("wing_low",),
    "throttle": ("throttle",),
}
#: JSBSim properties the flight loop writes: open-loop inputs reach them through the axis keys.
PILOT_PROPERTIES = (
    "fcs/aileron-cmd-norm",
    "fcs/elevator-cmd-norm",
    "fcs/rudder-cmd-norm",
    "fcs/throttle-cmd-norm",
    "fcs/steer-cmd-norm",
    "fcs/mixture-cmd-norm",
    "fcs/flap-cmd-norm",
    "fcs/left-brake-cmd-norm",
    "fcs/right-brake-cmd-norm",
)

#: JSBSim properties whose writing makes JSBSim write a file (``initfile.T.xml``): refused as inputs.
FILE_WRITING_PROPERTIES = ("simulation/write-state-file",)


def _add(where: Where, loc: Loc, problem: str) -> bool:
    """Add a problem to ``where``; False (for ``return _add(...)``: the check failed)."""
    where.add(loc, problem)
    return False


def _check_signal(sig: Signal, amplitude: float | None, loc: Loc, amp_key: str, phase: Phase, where: Where) -> bool:
    """A signal's keys fit its shape, it has an amplitude, and it ends within a fixed-length phase; False (the
    problem added to ``where``) if not."""
    if sig.shape is None:
        stray = [k for k in (*_SHAPE_PARAMS, "start_s") if k in sig.model_fields_set]
        if amplitude is not None:
            keys = ("amplitude_norm", "amplitude_deg", "amplitude")
            given = next(k for k in keys if getattr(sig, k, None) is not None)
            return _add(where, (*loc, given), "an amplitude needs a 'shape'")
        if stray:
            return _add(where, (*loc, stray[0]), "needs a 'shape'")
        return True
    if amplitude is None:
        return _add(where, (*loc, "shape"), f"a {sig.shape} needs an amplitude ({amp_key})")
    required, optional = SHAPE_KEYS[sig.shape]
    for key in required:
        if getattr(sig, key) is None:
            return _add(where, (*loc, "shape"), f"a {sig.shape} needs '{key}'")
    for key in (*_SHAPE_PARAMS, "sweep"):
        if key in sig.model_fields_set and key not in required and key not in optional:
            return _add(where, (*loc, key), f"not used by a {sig.shape}")
    if sig.shape == "chirp" and sig.sweep == "logarithmic" and sig.start_hz == sig.end_hz:
        return _add(where, (*loc, "end_hz"), "a logarithmic sweep needs end_hz different from start_hz")
    end = sig.start_s + (sig.duration_s or 0.0)
    limit = phase.until.duration_s
    if limit is not None and end > limit + 1e-9:
        problem = f"the {sig.shape} runs to {end:g} s, past the phase's duration_s of {limit:g} s"
        return _add(where, (*loc, "start_s"), problem)
    return True


def _check_inputs(phase: Phase, loc: Loc, profile: PilotProfile, where: Where) -> None:
    """The open-loop inputs of a phase are complete, consistent with the hold, and in range: the first problem of
    each input is added to ``where`` (its other checks would only repeat it), and the next input is checked."""
    inputs = phase.inputs
    if inputs is None:
        return
    hold = phase.hold
    for axis in ("elevator", "aileron", "rudder", "throttle"):
        ci: ControlInput | None = getattr(inputs, axis)
        if ci is None:
            continue
        at: Loc = (*loc, axis)
        if ci.fixed_norm is not None and ci.fixed_deg is not None:
            where.add((*at, "fixed_deg"), "give either fixed_norm or fixed_deg")
            continue
        if ci.amplitude_norm is not None and ci.amplitude_deg is not None:
            where.add((*at, "amplitude_deg"), "give either amplitude_norm or amplitude_deg")
            continue
        uses_deg = ci.fixed_deg is not None or ci.amplitude_deg is not None
        key = "fixed_deg" if ci.fixed_deg is not None else "amplitude_deg"
        if uses_deg and axis == "throttle":
            where.add((*at, key), "the throttle has no surface: use the _norm keys")
            continue
        if uses_deg and profile.surfaces is None:
            where.add((*at, key), f"the pilot profile of '{profile.aircraft}' gives no surface travel")
            continue
        if ci.fixed_norm is not None:
            lo = 0.0 if axis == "throttle" else -1.0
            if not lo <= ci.fixed_norm <= 1.0:
                where.add((*at, "fixed_norm"), f"outside the command range {lo:g}..1")
                continue
        if ci.fixed_deg is not None and profile.surfaces is not None:
            travel = getattr(profile.surfaces, axis)
            if not travel.min_deg <= ci.fixed_deg <= travel.max_deg:
                where.add((*at, "fixed_deg"), f"outside the surface travel {travel.min_deg:g}..{travel.max_deg:g} deg")
                continue
        amplitude = ci.amplitude_norm if ci.amplitude_norm is not None else ci.amplitude_deg
        if not _check_signal(ci, amplitude, at, "amplitude_norm or amplitude_deg", phase, where):
            continue
        if ci.amplitude_deg is not None and ci.shape is not None and profile.surfaces is not None:
            _check_travel(ci, getattr(profile.surfaces, axis), phase, at, where)
        released = ci.free or ci.fixed_norm is not None or ci.fixed_deg is not None
        if not released and ci.shape is None:
            where.add(at, "does nothing: give a 'shape', 'free: true' or a fixed value")
            continue
        if released:
            taken = set_fields(hold, _AXIS_TARGETS[axis])
            if taken:
                contradicted = f"'hold.{taken[0]}' (the {axis} is its control)"
                where.add((*at,), f"the {axis} is released, which contradicts {contradicted}")
                continue
            if axis == "throttle" and hold.airspeed_kts is not None:  # without a fixed throttle it holds the speed
                where.add(at, "the throttle is released, which contradicts 'hold.airspeed_kts' (held with it)")
                continue
            if axis == "elevator" and hold.airspeed_kts is not None and hold.throttle is not None:
                where.add(at, "the elevator is released, which contradicts 'hold.airspeed_kts' (held with it)")
                continue
    seen: set[str] = set()
    for j, pi in enumerate(inputs.properties):
        at = (*loc, "properties", j)
        if pi.property in PILOT_PROPERTIES:
            where.add((*at, "property"), f"'{pi.property}' is written by the pilot: use the axis keys")
            continue
        if pi.property.strip("/") in FILE_WRITING_PROPERTIES:
            where.add((*at, "property"), f"'{pi.property}' makes JSBSim write a file on every write (washbench "
                      "records the flight itself)")  # fmt: skip
            continue
        if pi.property in seen:
            where.add((*at, "property"), f"'{pi.property}' is given twice in this phase")
            continue
        seen.add(pi.property)
        if not _check_signal(pi, pi.amplitude, at, "amplitude", phase, where):
            continue
        if pi.shape is None and pi.fixed is None:
            where.add(at, "does nothing: give a 'shape' or a 'fixed' value")
            continue


def _check_travel(ci: ControlInput, travel: Any, phase: Phase, at: Loc, where: Where) -> None:
    """An ``amplitude_deg`` signal fits the surface travel (from the model's flight-control system, copied into the
    pilot profile): from a ``fixed_deg`` base exactly; from any other base (the command at the phase start or the
    pilot's, known only in flight) its swing, highest minus lowest deflection asked, must fit the whole travel.
    Where it fits only from some bases, a flight reports the time clipped at a stop (:mod:`washbench.flight.openloop`).
    """
    lo, hi = shape_extent(ci.shape, ci.start_s, ci.duration_s, ci.period_s, ci.start_hz, ci.end_hz, ci.sweep,
                          phase.until.duration_s)  # fmt: skip
    a = float(ci.amplitude_deg or 0.0)
    low, high = sorted((a * lo, a * hi))
    span = f"{travel.min_deg:g}..{travel.max_deg:g} deg"
    if ci.fixed_deg is not None:
        if ci.fixed_deg + low < travel.min_deg - 1e-9 or ci.fixed_deg + high > travel.max_deg + 1e-9:
            where.add(
                (*at, "amplitude_deg"),
                f"from fixed_deg {ci.fixed_deg:g} the {ci.shape} asks {ci.fixed_deg + low:g}..{ci.fixed_deg + high:g} "
                f"deg, beyond the surface travel {span} (it would stop at the limit)",
            )
    elif high - low > travel.max_deg - travel.min_deg + 1e-9:
        where.add(
            (*at, "amplitude_deg"),
            f"the {ci.shape} swings {high - low:g} deg, more than the whole surface travel {span} (it would stop at "
            "the limits)",
        )


def _check_properties(m: ManoeuvreFields, files: AircraftFiles, where: Where) -> None:
    """Every JSBSim property an input names exists in the model (JSBSim itself ignores typos)."""
    wanted = [
        ((("phases", i, "inputs", "properties", j, "property")), pi.property)
        for i, phase in enumerate(m.phases)
        if phase.inputs is not None
        for j, pi in enumerate(phase.inputs.properties)
    ]
    if not wanted:
        return
    import tempfile

    import jsbsim  # imported only when an input names a property

    os.environ["JSBSIM_DEBUG"] = "0"
    fdm = jsbsim.FGFDMExec(str(jsbsim_root()), None)
    fdm.set_output_path(scratch_output_dir())  # not JSBSim's root: its own files are thrown away
    with tempfile.TemporaryDirectory(prefix="washbench-aircraft-") as tmp:  # the model without <output>
        fdm.set_aircraft_path(str(aircraft_for_jsbsim(files.root, m.aircraft, Path(tmp))))
        with quiet_stdout():
            try:
                loaded = fdm.load_model(m.aircraft)
                fdm.disable_output()  # the model's <output> directives, neutralised, write nothing (jsbsim_xml)
            except Exception as exc:  # JSBSim raises plain exceptions on broken models
                raise where.error(("aircraft",), f"JSBSim could not load the model ({exc})") from None
    if not loaded:
        raise where.error(("aircraft",), "JSBSim could not load the model")
    pm = fdm.get_property_manager()
    for loc, name in wanted:
        if not pm.hasNode(name):
            where.add(loc, f"unknown JSBSim property '{name}' (not in the {m.aircraft} model)")


def _never_reason(
    cond: str, until: Until, hold: Hold, on_ground: bool, profile: PilotProfile, m: ManoeuvreFields
) -> str | None:
    """Why the end condition ``cond`` can never be met in this phase, or None if it can."""
    value = getattr(until, cond)
    if cond == "event":
        if value == "liftoff" and not on_ground:
            return "waits for lift-off but the aircraft is already flying"
        if value == "touchdown" and on_ground:
            return "waits for touchdown but the aircraft is already on the ground"
        if value == "touchdown" and hold.altitude_ft is not None:
            return "waits for touchdown while holding an altitude"
        if value == "stopped" and not on_ground and hold.altitude_ft is not None:
            return "waits for a stop while holding an altitude"
        if value == "stall" and on_ground:
            return "waits for a stall on the ground"
        return None
    if cond == "airspeed_above_kts" and value > profile.speeds.vne_kts:
        return f"{value:g} kt is above {m.aircraft}'s VNE ({profile.speeds.vne_kts:g} kt)"
    if cond == "airspeed_below_kts" and value <= 0:
        return "an airspeed below zero"
    if cond == "agl_below_ft" and value < 0:
        return "a height below the ground"
    if cond == "bank_above_deg" and (hold.wings_level or (hold.bank_deg is not None and abs(hold.bank_deg) < value)):
        return "the bank held stays below it"
    if cond == "rolled_deg" and not hold.roll_rate_degps:
        return "no roll rate is held, so the aircraft does not keep rolling"
    if cond == "turned_deg" and (hold.wings_level or hold.heading_deg is not None or hold.centreline):
        return "the heading is held, so the aircraft never turns that far"
    if hold.altitude_ft is not None:
        if cond == "altitude_above_ft" and value > hold.altitude_ft:
            return f"the altitude is held at {hold.altitude_ft:g} ft"
        if cond == "altitude_below_ft" and value < hold.altitude_ft:
            return f"the altitude is held at {hold.altitude_ft:g} ft"
    if hold.pitch_deg is not None and not on_ground:
        if cond == "pitch_above_deg" and value > hold.pitch_deg + 5:
            return f"the pitch is held at {hold.pitch_deg:g} deg"
        if cond == "pitch_below_deg" and value < hold.pitch_deg - 5:
            return f"the pitch is held at {hold.pitch_deg:g} deg"
    if cond == "alpha_above_deg" and value > 30:
        return "an angle of attack beyond 30 deg"
    return None


