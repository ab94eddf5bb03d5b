"""Manoeuvre files: the YAML schema, loading with one-line errors, semantic checks, JSON Schema export.

A manoeuvre names the aircraft, the start (in the air or at rest on a runway), the
environment, a sequence of phases (what the pilot holds, and when the phase ends) and the
checks that prove it was flown. Keys carry their units (``altitude_ft``, ``bank_deg``).
The format is documented in README.md, section "Manoeuvre files".

Conventions: headings and wind directions are true, in degrees; the wind is given by the
direction it blows FROM (aviation convention: ``from_deg: 270`` is a westerly wind,
blowing towards the east). Airspeeds are calibrated (KCAS ~ KIAS).
"""

from __future__ import annotations

import difflib
import json
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Annotated, Any, Literal, get_args

from pydantic import Field, PrivateAttr, ValidationInfo, model_validator

from washbench.errors import WashbenchError, located
from washbench.flight.columns import COLUMN_NAMES, RUNWAY_COLUMNS
from washbench.flight.profile import PilotProfile, load_profile
from washbench.io.atomic import write_text_atomic
from washbench.io.names import Identifier
from washbench.io.paths import AircraftFiles, find_aircraft, find_aircraft_files, find_profile
from washbench.io.publish import prepare_output_file
from washbench.io.yamlio import Loc, StrictModel, format_field_path, line_of, read_yaml, validate_data

Positive = Annotated[float, Field(gt=0)]
NonNegative = Annotated[float, Field(ge=0)]
Fraction = Annotated[float, Field(ge=0, le=1)]
Heading = Annotated[float, Field(ge=0, le=360)]  # true, deg; 360 is north, as a pilot says it
Latitude = Annotated[float, Field(ge=-89, le=89)]
Longitude = Annotated[float, Field(ge=-180, le=180)]
# Ranges that keep every number physical (a finite but absurd number must not reach the flight model).
Altitude = Annotated[float, Field(ge=-1500, le=60000)]  # ft MSL: the Dead Sea shore to above any piston aircraft
Height = Annotated[float, Field(ge=-1000, le=60000)]  # ft above the ground
Angle = Annotated[float, Field(ge=-90, le=90)]  # pitch or angle of attack, deg
Airspeed = Annotated[float, Field(ge=0, le=1000)]  # kt
Rotation = Annotated[float, Field(gt=0, le=36000)]  # deg turned or rotated in one phase (100 turns)

#: The longest manoeuvre accepted: the sum over its phases of ``duration_s`` (or ``timeout_s`` where a phase
#: has no duration) may not exceed it, and neither may that time in flight-model steps.
MAX_MANOEUVRE_S = 3600.0
MAX_MANOEUVRE_STEPS = 432_000  # one hour at the default 120 Hz
PhaseTime = Annotated[float, Field(gt=0, le=MAX_MANOEUVRE_S)]
#: Lowest air start above the ground (ft): lower, there is no room to trim or recover.
AIR_START_MIN_AGL_FT = 100.0
#: Highest air start when the pilot profile gives no ``limits.ceiling_ft``.
DEFAULT_CEILING_FT = 50000.0


class Runway(StrictModel):
    """A runway: threshold centre, true heading of the landing/takeoff direction, size."""

    name: str = ""
    latitude_deg: Latitude
    longitude_deg: Longitude
    heading_deg: Heading
    elevation_ft: Annotated[float, Field(ge=-1500, le=15000)] = 0.0
    length_ft: Annotated[float, Field(gt=0, le=50000)]
    width_ft: Annotated[float, Field(gt=0, le=1000)]
    aim_point_ft: Annotated[float, Field(ge=0, le=50000)] = 1000.0  # glide path meets the runway, past threshold


class AirStart(StrictModel):
    """Start trimmed in straight flight (level unless ``flight_path_deg``).

    Position: lat/lon, or ``before_threshold_ft`` on the runway's extended centreline (then
    the heading defaults to the runway's and the aircraft starts crabbed into the wind).
    """

    altitude_ft: Altitude
    airspeed_kts: Annotated[float, Field(gt=0, le=1000)]
    heading_deg: Heading | None = None  # default: the runway heading
    latitude_deg: Latitude | None = None
    longitude_deg: Longitude | None = None
    # on the extended centreline, this far before the threshold
    before_threshold_ft: Annotated[float, Field(ge=-50000, le=200000)] | None = None
    flight_path_deg: Annotated[float, Field(ge=-10, le=10)] = 0.0  # trimmed climb (+) or descent (-)
    flaps_deg: Annotated[float, Field(ge=0, le=90)] = 0.0


class RunwayStart(StrictModel):
    """Start at rest on the runway centreline, engine running, brakes set."""

    past_threshold_ft: Annotated[float, Field(ge=0, le=50000)] = 0.0


class Start(StrictModel):
    air: AirStart | None = None
    runway: RunwayStart | None = None


class Wind(StrictModel):
    """Steady wind; ``from_deg`` is the true direction the wind blows FROM."""

    from_deg: Heading
    speed_kts: Annotated[float, Field(ge=0, le=150)]


class Turbulence(StrictModel):
    """JSBSim MIL-F-8785C turbulence; the seed makes it repeatable."""

    severity: Literal["none", "light", "moderate", "severe"]
    seed: Annotated[int, Field(ge=0, lt=2**31)]


class Environment(StrictModel):
    wind: Wind | None = None
    turbulence: Turbulence | None = None


LATERAL_TARGETS = ("wings_level", "bank_deg", "heading_deg", "roll_rate_degps", "centreline")
PITCH_TARGETS = (
    "pitch_deg",
    "altitude_ft",
    "vertical_speed_fpm",
    "glide_path_deg",
    "pitch_rate_degps",
    "load_factor",
    "flare",
)


class Hold(StrictModel):
    """What the pilot holds or tracks during a phase.

    At most one lateral target (ailerons): ``wings_level``, ``bank_deg``, ``heading_deg``,
    ``roll_rate_degps``, ``centreline`` (default: wings level). At most one pitch target
    (elevator): ``pitch_deg``, ``altitude_ft``, ``vertical_speed_fpm``, ``glide_path_deg``,
    ``pitch_rate_degps``, ``load_factor``, ``flare``. The body-rate targets (``roll_rate_degps``,
    ``pitch_rate_degps``, ``load_factor``) use no Euler angle, so they work through the vertical
    and inverted (aerobatics); ``roll_rate_degps: 0`` keeps the roll attitude about the body x
    axis. ``airspeed_kts`` is held with the throttle when a pitch target is given, and with
    the elevator when ``throttle`` is fixed instead. The rudder
    coordinates (zero sideslip) in the air and tracks the runway on the ground; with
    ``wing_low`` (needs ``centreline``) it aligns the nose with the runway in the air while
    the ailerons bank into the wind to hold the centreline (crosswind landing technique).
    """

    wings_level: bool | None = None
    bank_deg: Annotated[float, Field(ge=-80, le=80)] | None = None
    heading_deg: Heading | None = None
    roll_rate_degps: Annotated[float, Field(ge=-90, le=90)] | None = None
    centreline: bool | None = None
    wing_low: bool | None = None
    pitch_deg: Annotated[float, Field(ge=-45, le=45)] | None = None
    altitude_ft: Altitude | None = None
    vertical_speed_fpm: Annotated[float, Field(ge=-10000, le=10000)] | None = None
    glide_path_deg: Annotated[float, Field(gt=0, le=10)] | None = None
    pitch_rate_degps: Annotated[float, Field(ge=-30, le=30)] | None = None
    load_factor: Annotated[float, Field(ge=-3, le=6)] | None = None  # g, +1 in level flight
    flare: bool | None = None
    airspeed_kts: Annotated[float, Field(gt=0, le=1000)] | None = None
    throttle: Fraction | None = None
    flaps_deg: Annotated[float, Field(ge=0, le=90)] | None = None
    brakes: Fraction | None = None


Event = Literal["liftoff", "touchdown", "stopped", "stall"]
EVENTS: tuple[str, ...] = get_args(Event)


class Until(StrictModel):
    """When a phase ends: the first of the given conditions that holds.

    ``rolled_deg`` and ``pitched_deg`` are the magnitudes of the integrals of the body rates p
    and q since the phase began (rotation about the body x and y axes, not Euler angles).
    ``timeout_s`` is not an end condition: if none of the conditions is met by then, the
    flight fails (a phase that cannot end must not run forever).
    """

    duration_s: PhaseTime | None = None
    event: Event | None = None
    turned_deg: Rotation | None = None
    rolled_deg: Rotation | None = None
    pitched_deg: Rotation | None = None
    airspeed_above_kts: Airspeed | None = None
    airspeed_below_kts: Airspeed | None = None
    altitude_above_ft: Altitude | None = None
    altitude_below_ft: Altitude | None = None
    agl_above_ft: Height | None = None
    agl_below_ft: Height | None = None
    bank_above_deg: Annotated[float, Field(ge=0, lt=90)] | None = None
    pitch_above_deg: Angle | None = None
    pitch_below_deg: Angle | None = None
    alpha_above_deg: Angle | None = None
    timeout_s: PhaseTime = 120.0


class Phase(StrictModel):
    name: Annotated[str, Field(min_length=1)]
    hold: Hold = Hold()
    until: Until


#: Statistics over the selected samples, and those taken at an event (the first touchdown or lift-off).
SampleStat = Literal[
    "min",
    "max",
    "mean",
    "max_abs",
    "initial",
    "final",
    "max_rise",
    "max_drop",
    "max_deviation",
    "turned",
    "rotated",
]
EventStat = Literal["at_touchdown", "at_liftoff"]
STATS: tuple[str, ...] = get_args(SampleStat)
EVENT_STATS: tuple[str, ...] = get_args(EventStat)
#: Signals the ``rotated`` statistic integrates (body angular velocity, deg/s).
RATE_SIGNALS = ("omega_x_degps", "omega_y_degps", "omega_z_degps")


class Check(StrictModel):
    """A measured value that must lie within limits.

    ``stat`` of ``signal`` (a flight.parquet column, or ``sink_fps`` at an event) over
    ``phases`` (default: the whole flight). ``max_rise``/``max_drop``/``max_deviation``
    are relative to the value at the start of the first phase listed; ``turned`` is the
    total heading change (deg) of a heading signal; ``rotated`` is the magnitude of the time
    integral (deg) of a body-rate signal over the selected phases (trapezoidal rule).
    """

    name: Annotated[str, Field(min_length=1)]
    signal: str
    stat: Literal[SampleStat, EventStat]  # one literal type (nested literals flatten): one error message
    phases: list[str] | None = None
    min: float | None = None
    max: float | None = None


class Manoeuvre(StrictModel):
    """One manoeuvre file, checked in full however it is built.

    ``name`` and ``aircraft`` become result folders (``OUT/<aircraft>/<name>/``), so both are plain
    identifiers (:mod:`washbench.io.names`). After the schema, the semantic checks run (a known aircraft
    with a pilot profile, one start, phases that can end, a manoeuvre no longer than
    :data:`MAX_MANOEUVRE_S`, ...): :meth:`model_validate` from Python raises ``ValidationError`` listing
    every problem; :func:`load_manoeuvre` raises WashbenchError with ``file:line: field: problem`` lines.
    """

    name: Identifier
    description: str = ""
    aircraft: Identifier
    pilot_profile: str | None = None  # path of the pilot profile YAML, relative to this file (default: searched)
    rate_hz: Annotated[int, Field(ge=30, le=1000)] = 120
    runway: Runway | None = None
    start: Start
    environment: Environment = Environment()
    phases: Annotated[list[Phase], Field(min_length=1)]
    checks: list[Check] = Field(default_factory=list)

    _files: AircraftFiles | None = PrivateAttr(default=None)
    _source: Path | None = PrivateAttr(default=None)
    _lines: dict[Loc, int] = PrivateAttr(default_factory=dict)

    @property
    def dt_s(self) -> float:
        """The flight dynamics time step, s."""
        return 1.0 / self.rate_hz

    @property
    def source(self) -> Path | None:
        """The file this manoeuvre was loaded from (None when built in Python)."""
        return self._source

    def located(self, loc: Loc, problem: str) -> str:
        """``FILE:LINE: FIELD: PROBLEM`` for a problem found later (e.g. in flight) with a field of this manoeuvre."""
        field = format_field_path(loc)
        if self._source is None:
            return f"manoeuvre '{self.name}': {field}: {problem}"
        return located(self._source, problem, line=line_of(self._lines, loc), field=field)

    @model_validator(mode="after")
    def _semantic_checks(self, info: ValidationInfo) -> Manoeuvre:
        context = info.context if isinstance(info.context, dict) else {}
        source = context.get("source")
        where = _Where(Path(source) if source is not None else None, context.get("lines", {}))
        _check_semantics(self, where, context.get("aircraft_dirs", ()))
        if where.problems:
            if source is not None:  # from a file: one located line per problem (WashbenchError passes through)
                raise WashbenchError(where.problems[0], where.problems[1:])
            raise ValueError("; ".join(where.problems))
        if source is not None:
            self._source = Path(source)
            self._lines = context.get("lines", {})
        return self

    @property
    def aircraft_files(self) -> AircraftFiles:
        """Where the aircraft model and the pilot profile are (found when the file was loaded).

        For a manoeuvre built in Python, searched now without a manoeuvre file or ``--aircraft-dir``.
        """
        if self._files is None:
            self._files = find_aircraft_files(self.aircraft, self._source, (), self.pilot_profile)
        return self._files


# --- aircraft lookup ---------------------------------------------------------------------------


def aircraft_path(name: str, manoeuvre_file: Path | None = None, aircraft_dirs: Sequence[Path] = ()) -> Path | None:
    """The folder holding ``<name>/<name>.xml`` along the search path (washbench.io.paths), or None."""
    try:
        return find_aircraft(name, manoeuvre_file, aircraft_dirs)
    except WashbenchError:
        return None


def pilot_profile_path(aircraft: str, manoeuvre_file: Path | None = None, aircraft_dirs: Sequence[Path] = ()) -> Path:
    """The scripted pilot's profile for ``aircraft`` along the search path (WashbenchError if there is none)."""
    return find_profile(aircraft, manoeuvre_file, aircraft_dirs)


# --- semantic checks ---------------------------------------------------------------------------


class _Where:
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


def _set_fields(model: StrictModel, names: Sequence[str]) -> list[str]:
    return [n for n in names if getattr(model, n) is not None and getattr(model, n) is not False]


def _check_semantics(m: Manoeuvre, where: _Where, aircraft_dirs: Sequence[Path] = ()) -> None:
    """Checks a schema cannot express; every problem is added to ``where`` (in file order)."""
    try:
        files = find_aircraft_files(m.aircraft, where.path, aircraft_dirs, m.pilot_profile)
    except WashbenchError as exc:
        field = "pilot_profile" if str(exc).startswith("pilot_profile:") else "aircraft"
        where.add((field,), str(exc).removeprefix("pilot_profile: "))
        return
    m._files = files
    m._source = where.path
    profile = load_profile(files.profile)

    starts = _set_fields(m.start, ("air", "runway"))
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

    on_ground = m.start.runway is not None
    names = [p.name for p in m.phases]
    for i, phase in enumerate(m.phases):
        base: Loc = ("phases", i)
        if names.index(phase.name) != i:
            where.add((*base, "name"), f"duplicate phase name '{phase.name}'")
        hold, until = phase.hold, phase.until
        phase_problems = len(where.problems)
        lateral = _set_fields(hold, LATERAL_TARGETS)
        pitch = _set_fields(hold, PITCH_TARGETS)
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
        conditions = _set_fields(until, [f for f in Until.model_fields if f != "timeout_s"])
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
            hint = f"did you mean '{close[0]}'?" if close else "a signal is a flight.parquet column, see README.md"
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
        if check.min is not None and check.max is not None and check.min > check.max:
            where.add((*base, "min"), f"greater than max ({check.min:g} > {check.max:g})")
        for k, name in enumerate(check.phases or ()):
            if name not in names:
                where.add((*base, "phases", k), f"no phase named '{name}'")


def _never_reason(
    cond: str, until: Until, hold: Hold, on_ground: bool, profile: PilotProfile, m: Manoeuvre
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


# --- public API ----------------------------------------------------------------------------------


def load_manoeuvre(path: str | Path, aircraft_dirs: Sequence[Path] = ()) -> Manoeuvre:
    """Read, validate and semantically check a manoeuvre file.

    The aircraft and its pilot profile are found along the search path of :mod:`washbench.io.paths`
    (``aircraft_dirs`` are the ``--aircraft-dir`` folders) and kept in :attr:`Manoeuvre.aircraft_files`.
    Raises WashbenchError holding every problem of the file (``problems``: one located line each).
    """
    path = Path(path)
    data, lines = read_yaml(path)
    context = {"source": path, "lines": lines, "aircraft_dirs": tuple(aircraft_dirs)}
    return validate_data(path, data, lines, Manoeuvre, context=context)


def validate_command(paths: Sequence[Path], aircraft_dirs: Sequence[Path] = ()) -> int:
    """``washbench validate FILE...``: print ``FILE: OK`` or the error line per file; 2 if any is bad."""
    bad = 0
    for path in paths:
        try:
            load_manoeuvre(path, aircraft_dirs)
        except WashbenchError as exc:
            for problem in exc.problems:
                print(f"washbench: error: {problem}", file=sys.stderr)
            bad += 1
        else:
            print(f"{path}: OK")
    return 2 if bad else 0


def manoeuvre_json_schema() -> dict[str, Any]:
    """The JSON Schema of manoeuvre files (for editors: completion and checking)."""
    schema = Manoeuvre.model_json_schema()
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    schema["title"] = "washbench manoeuvre"
    return schema


def schema_command(out: Path | None) -> int:
    """``washbench schema [--out FILE]``: print or write the JSON Schema."""
    text = json.dumps(manoeuvre_json_schema(), indent=2, sort_keys=True) + "\n"
    if out is None:
        sys.stdout.write(text)
    else:
        write_text_atomic(prepare_output_file(out), text)
    return 0
