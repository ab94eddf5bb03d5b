"""Manoeuvre files: the YAML schema, loading with one-line errors, semantic checks, JSON Schema export.

A manoeuvre names the aircraft, the start (in the air or at rest on a runway), the
environment, a sequence of phases (what the pilot holds, and when the phase ends) and the
checks that prove it was flown. Keys carry their units (``altitude_ft``, ``bank_deg``).
The format is documented in docs/reference/manoeuvre-format.md.

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

from pydantic import Field, PrivateAttr, ValidationInfo, field_validator, model_validator

from washbench.errors import WashbenchError, located
from washbench.flight.columns import COLUMN_NAMES, RUNWAY_COLUMNS
from washbench.flight.profile import PilotProfile, load_profile
from washbench.io.atomic import write_text_atomic
from washbench.io.names import Identifier
from washbench.io.paths import AircraftFiles, find_aircraft, find_aircraft_files, find_profile, jsbsim_root
from washbench.io.publish import prepare_output_file
from washbench.io.yamlio import Loc, StrictModel, format_field_path, line_of, read_yaml, validate_data

Positive = Annotated[float, Field(gt=0)]
NonNegative = Annotated[float, Field(ge=0)]
Fraction = Annotated[float, Field(ge=0, le=1)]
Heading = Annotated[float, Field(ge=0, le=360)]  # true, deg; 360 is north, as a pilot says it
Latitude = Annotated[float, Field(ge=-89, le=89)]
Longitude = Annotated[float, Field(ge=-180, le=180)]
FiniteFloat = Annotated[float, Field(allow_inf_nan=False)]
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
    """Free text naming the runway (e.g. '07')."""
    latitude_deg: Latitude
    """Geodetic latitude of the threshold centre, deg."""
    longitude_deg: Longitude
    """Longitude of the threshold centre, deg."""
    heading_deg: Heading
    """True heading of the landing / takeoff direction, deg."""
    elevation_ft: Annotated[float, Field(ge=-1500, le=15000)] = 0.0
    """Elevation of the runway above mean sea level, ft."""
    length_ft: Annotated[float, Field(gt=0, le=50000)]
    """Length of the runway, ft."""
    width_ft: Annotated[float, Field(gt=0, le=1000)]
    """Width of the runway, ft."""
    aim_point_ft: Annotated[float, Field(ge=0, le=50000)] = 1000.0
    """Where the glide path meets the runway, ft past the threshold."""


class AirStart(StrictModel):
    """Start trimmed in straight flight (level unless ``flight_path_deg``).

    Position: lat/lon, or ``before_threshold_ft`` on the runway's extended centreline (then
    the heading defaults to the runway's and the aircraft starts crabbed into the wind).
    """

    altitude_ft: Altitude
    """Altitude above mean sea level at the start, ft."""
    airspeed_kts: Annotated[float, Field(gt=0, le=1000)]
    """Calibrated airspeed at the start, kt."""
    heading_deg: Heading | None = None
    """True heading at the start, deg (default: the runway heading)."""
    latitude_deg: Latitude | None = None
    """Geodetic latitude of the start, deg (with longitude_deg)."""
    longitude_deg: Longitude | None = None
    """Longitude of the start, deg (with latitude_deg)."""
    before_threshold_ft: Annotated[float, Field(ge=-50000, le=200000)] | None = None
    """Start on the runway's extended centreline, this far before the threshold, ft."""
    flight_path_deg: Annotated[float, Field(ge=-10, le=10)] = 0.0
    """Trimmed flight-path angle, deg: climb (+) or descent (-)."""
    flaps_deg: Annotated[float, Field(ge=0, le=90)] = 0.0
    """Flap angle at the start, deg."""


class RunwayStart(StrictModel):
    """Start at rest on the runway centreline, engine running, brakes set."""

    past_threshold_ft: Annotated[float, Field(ge=0, le=50000)] = 0.0
    """Where on the centreline the aircraft stands, ft past the threshold."""


class Start(StrictModel):
    """Where and how the flight starts: exactly one of air or runway."""

    air: AirStart | None = None
    """Start in the air, trimmed."""
    runway: RunwayStart | None = None
    """Start at rest on the runway (needs a top-level runway)."""


class Wind(StrictModel):
    """Steady wind; ``from_deg`` is the true direction the wind blows FROM."""

    from_deg: Heading
    """True direction the wind blows FROM, deg (270: a westerly)."""
    speed_kts: Annotated[float, Field(ge=0, le=150)]
    """Wind speed, kt."""


class Turbulence(StrictModel):
    """JSBSim MIL-F-8785C turbulence; the seed makes it repeatable."""

    severity: Literal["none", "light", "moderate", "severe"]
    """Turbulence severity (MIL-F-8785C): none, light, moderate or severe."""
    seed: Annotated[int, Field(ge=0, lt=2**31)]
    """Seed of JSBSim's random generator: the same seed gives the same gusts."""


class Environment(StrictModel):
    """The weather: steady wind and turbulence."""

    wind: Wind | None = None
    """Steady wind."""
    turbulence: Turbulence | None = None
    """Turbulence (JSBSim's milspec model)."""


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
    """Lateral target: hold the wings level (the default)."""
    bank_deg: Annotated[float, Field(ge=-80, le=80)] | None = None
    """Lateral target: hold this bank angle, deg (+ right wing down)."""
    heading_deg: Heading | None = None
    """Lateral target: turn to and hold this true heading, deg."""
    roll_rate_degps: Annotated[float, Field(ge=-90, le=90)] | None = None
    """Lateral target: roll at this body roll rate, deg/s (0: keep the roll attitude)."""
    centreline: bool | None = None
    """Lateral target: track the runway centreline (in the air and on the ground)."""
    wing_low: bool | None = None
    """With centreline: align the nose with the runway and bank into the wind (crosswind landing)."""
    pitch_deg: Annotated[float, Field(ge=-45, le=45)] | None = None
    """Pitch target: hold this pitch attitude, deg."""
    altitude_ft: Altitude | None = None
    """Pitch target: climb or descend to and hold this altitude above mean sea level, ft."""
    vertical_speed_fpm: Annotated[float, Field(ge=-10000, le=10000)] | None = None
    """Pitch target: hold this rate of climb, ft/min (negative: descent)."""
    glide_path_deg: Annotated[float, Field(gt=0, le=10)] | None = None
    """Pitch target: follow a glide path of this angle to the runway aim point, deg."""
    pitch_rate_degps: Annotated[float, Field(ge=-30, le=30)] | None = None
    """Pitch target: pitch at this body pitch rate, deg/s."""
    load_factor: Annotated[float, Field(ge=-3, le=6)] | None = None
    """Pitch target: pull this load factor, g (+1 in level flight)."""
    flare: bool | None = None
    """Pitch target: flare, a sink rate proportional to the height of the wheels, to touchdown."""
    airspeed_kts: Annotated[float, Field(gt=0, le=1000)] | None = None
    """Calibrated airspeed to hold, kt: with the throttle, or with the elevator when throttle is fixed."""
    throttle: Fraction | None = None
    """Fixed throttle, 0..1."""
    flaps_deg: Annotated[float, Field(ge=0, le=90)] | None = None
    """Flap angle, deg."""
    brakes: Fraction | None = None
    """Wheel brakes, 0..1."""


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
    """End after this time in the phase, s."""
    event: Event | None = None
    """End at an event: liftoff, touchdown, stopped or stall (angle of attack past the profile's stall angle)."""
    turned_deg: Rotation | None = None
    """End when the heading has changed this much since the phase began, deg."""
    rolled_deg: Rotation | None = None
    """End when the integral of the body roll rate p since the phase began reaches this magnitude, deg."""
    pitched_deg: Rotation | None = None
    """End when the integral of the body pitch rate q since the phase began reaches this magnitude, deg."""
    airspeed_above_kts: Airspeed | None = None
    """End when the calibrated airspeed reaches this value or more, kt."""
    airspeed_below_kts: Airspeed | None = None
    """End when the calibrated airspeed falls to this value or less, kt."""
    altitude_above_ft: Altitude | None = None
    """End when the altitude above mean sea level reaches this value or more, ft."""
    altitude_below_ft: Altitude | None = None
    """End when the altitude above mean sea level falls to this value or less, ft."""
    agl_above_ft: Height | None = None
    """End when the height of the centre of gravity above the ground reaches this value or more, ft."""
    agl_below_ft: Height | None = None
    """End when the height of the centre of gravity above the ground falls to this value or less, ft."""
    bank_above_deg: Annotated[float, Field(ge=0, lt=90)] | None = None
    """End when the magnitude of the bank angle reaches this value, deg."""
    pitch_above_deg: Angle | None = None
    """End when the pitch angle reaches this value or more, deg."""
    pitch_below_deg: Angle | None = None
    """End when the pitch angle falls to this value or less, deg."""
    alpha_above_deg: Angle | None = None
    """End when the angle of attack reaches this value or more, deg."""
    timeout_s: PhaseTime = 120.0
    """Not an end condition: a phase still running after this time fails the flight, s."""


Shape = Literal["step", "pulse", "doublet", "3211", "sine", "chirp"]


class Signal(StrictModel):
    """The shape keys shared by control and property inputs (times from the start of the phase)."""

    shape: Shape | None = None
    """Excitation signal added to the base: step, pulse, doublet, 3211, sine or chirp (frequency sweep)."""
    start_s: NonNegative = 0.0
    """When the signal starts, s after the start of the phase."""
    duration_s: Positive | None = None
    """Length of the signal, s: pulse width, whole doublet (two halves), whole 3211 (7 units), sweep; sine: optional."""
    period_s: Positive | None = None
    """Period of a sine, s."""
    start_hz: Positive | None = None
    """Chirp: frequency at the start of the sweep, Hz."""
    end_hz: Positive | None = None
    """Chirp: frequency at the end of the sweep, Hz."""
    sweep: Literal["linear", "logarithmic"] = "linear"
    """Chirp: how the frequency moves from start_hz to end_hz: linearly or logarithmically in time."""

    @field_validator("shape", mode="before")
    @classmethod
    def _shape_3211_unquoted(cls, value: object) -> object:
        """YAML reads ``shape: 3211`` as a number: take it as the name it means."""
        return "3211" if value == 3211 and type(value) is int else value


class ControlInput(Signal):
    """An open-loop input on one control axis.

    The base is the pilot's command (the pilot keeps the axis closed-loop and the signal is added
    on top), or, when the axis is free, a fixed value: ``fixed_norm`` / ``fixed_deg``, else the
    command at the start of the phase (``free: true``, controls fixed at trim), or the base of the
    previous phase if that had the axis free too (a signal ends with its phase, the base stays). Degrees are the
    deflection of the surface the pilot profile names (its ``surfaces`` travel, from the model's
    flight-control system), with the sign of that JSBSim property.
    """

    free: bool = False
    """Release the axis: the pilot lets go and the base is fixed (fixed_norm / fixed_deg, else the command
    at the start of the phase, or the base of the previous phase if that had the axis free too)."""
    fixed_norm: FiniteFloat | None = None
    """Release the axis to this normalised command (-1..1; throttle 0..1)."""
    fixed_deg: FiniteFloat | None = None
    """Release the axis to this surface deflection, deg."""
    amplitude_norm: FiniteFloat | None = None
    """Amplitude of the signal in normalised command (full travel = 1)."""
    amplitude_deg: FiniteFloat | None = None
    """Amplitude of the signal in surface deflection, deg."""


class PropertyInput(Signal):
    """An open-loop input on any JSBSim property, in that property's own unit (named in the property)."""

    property: Annotated[str, Field(min_length=1)]
    """JSBSim property name, e.g. fcs/speedbrake-cmd-norm (must exist in the model)."""
    fixed: FiniteFloat | None = None
    """Value written during the phase (default: the value at the start of the phase); the signal is added."""
    amplitude: FiniteFloat | None = None
    """Amplitude of the signal, in the property's unit."""


class Inputs(StrictModel):
    """Open-loop inputs of a phase, per control; the axes not named stay with the closed-loop pilot."""

    elevator: ControlInput | None = None
    """Elevator (+ nose down, as fcs/elevator-cmd-norm)."""
    aileron: ControlInput | None = None
    """Ailerons (+ rolls right, as fcs/aileron-cmd-norm)."""
    rudder: ControlInput | None = None
    """Rudder (sign of fcs/rudder-cmd-norm; on the c172p + yaws the nose left)."""
    throttle: ControlInput | None = None
    """Throttle, 0..1 (fcs/throttle-cmd-norm)."""
    properties: list[PropertyInput] = Field(default_factory=list)
    """Inputs on other JSBSim properties, by name."""


class Phase(StrictModel):
    """One phase of the manoeuvre: what the pilot holds, the open-loop inputs, and when it ends."""

    name: Annotated[str, Field(min_length=1)]
    """Name of the phase, unique in the file (checks select phases by name)."""
    hold: Hold = Hold()
    """What the closed-loop pilot holds or tracks."""
    inputs: Inputs | None = None
    """Open-loop control inputs: fixed controls and excitation signals (doublet, 3211, chirp, ...)."""
    until: Until
    """When the phase ends."""


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
    "oscillation_period",
    "damping_ratio",
    "oscillation_amplitude",
]
EventStat = Literal["at_touchdown", "at_liftoff"]
STATS: tuple[str, ...] = get_args(SampleStat)
EVENT_STATS: tuple[str, ...] = get_args(EventStat)
#: Signals the ``rotated`` statistic integrates (body angular velocity, deg/s).
RATE_SIGNALS = ("omega_x_degps", "omega_y_degps", "omega_z_degps")
#: Headings (deg in [0, 360)): their statistics and limits wrap at north.
HEADING_SIGNALS = ("psi_deg",)
#: The statistics of a heading that are headings themselves (limits are an arc from min to max).
HEADING_VALUE_STATS = ("min", "max", "mean", "initial", "final", "at_touchdown", "at_liftoff")
#: Statistics of an oscillation (a free response after an excitation).
OSCILLATION_STATS = ("oscillation_period", "damping_ratio", "oscillation_amplitude")


class Check(StrictModel):
    """A measured value that must lie within limits.

    ``stat`` of ``signal`` (a flight.parquet column, or ``sink_fps`` at an event) over
    ``phases`` (default: the whole flight). ``max_rise``/``max_drop``/``max_deviation``
    are relative to the value at the start of the first phase listed; ``turned`` is the
    total heading change (deg) of a heading signal; ``rotated`` is the magnitude of the time
    integral (deg) of a body-rate signal over the selected phases (trapezoidal rule).
    """

    name: Annotated[str, Field(min_length=1)]
    """What the check proves, in words (shown in flight.json and reports)."""
    signal: str
    """A flight.parquet column (e.g. phi_deg), or sink_fps at an event."""
    stat: Literal[SampleStat, EventStat]  # one literal type (nested literals flatten): one error message
    """The statistic measured over the selected samples, or at_touchdown / at_liftoff."""
    phases: list[str] | None = None
    """Phases whose samples are measured (default: the whole flight)."""
    min: FiniteFloat | None = None
    """Lowest value that passes (a heading's min may exceed its max: the arc through north)."""
    max: FiniteFloat | None = None
    """Highest value that passes."""


class Manoeuvre(StrictModel):
    """One manoeuvre file, checked in full however it is built.

    The name and the aircraft become result folders (OUT/aircraft/name/), so both are plain identifiers:
    letters, digits, '_' and '-'. After the schema the semantic checks run (a known aircraft with a pilot
    profile, one start, phases that can end, at most an hour of flight): from Python a ValidationError lists
    every problem, from a file every problem is one line naming the file, the line and the field.
    """

    name: Identifier
    """Identifier of the manoeuvre (names the result folders)."""
    description: str = ""
    """Free text: what is flown and why."""
    aircraft: Identifier
    """JSBSim model name (the project's aircraft folder first, then JSBSim's); needs a pilot profile."""
    pilot_profile: str | None = None
    """Path of the pilot profile YAML, relative to this file (default: searched for the aircraft)."""
    rate_hz: Annotated[int, Field(ge=30, le=1000)] = 120
    """Flight-model rate, Hz (t = k / rate_hz)."""
    runway: Runway | None = None
    """The runway of a takeoff, approach or landing."""
    start: Start
    """Where and how the flight starts."""
    environment: Environment = Environment()
    """Wind and turbulence."""
    phases: Annotated[list[Phase], Field(min_length=1)]
    """The phases, flown in order."""
    checks: list[Check] = Field(default_factory=list)
    """Measured values that must lie within limits."""

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

    def error(self, loc: Loc, problem: str) -> Exception:
        """Add the problem and return the error to raise now, holding every problem so far (for checks that
        cannot go on after it): WashbenchError for a file, ValueError (pydantic's ValidationError) from Python."""
        self.add(loc, problem)
        if self.path is None:
            return ValueError("; ".join(self.problems))
        return WashbenchError(self.problems[0], self.problems[1:])


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
        if phase.inputs is not None:
            _check_inputs(phase, (*base, "inputs"), profile, where)
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
    _check_properties(m, where)


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


def _add(where: _Where, loc: Loc, problem: str) -> bool:
    """Add a problem to ``where``; False (for ``return _add(...)``: the check failed)."""
    where.add(loc, problem)
    return False


def _check_signal(sig: Signal, amplitude: float | None, loc: Loc, amp_key: str, phase: Phase, where: _Where) -> bool:
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


def _check_inputs(phase: Phase, loc: Loc, profile: PilotProfile, where: _Where) -> None:
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
            taken = _set_fields(hold, _AXIS_TARGETS[axis])
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


def _check_travel(ci: ControlInput, travel: Any, phase: Phase, at: Loc, where: _Where) -> None:
    """An ``amplitude_deg`` signal fits the surface travel (from the model's flight-control system, copied into the
    pilot profile): from a ``fixed_deg`` base exactly; from any other base (the command at the phase start or the
    pilot's, known only in flight) its swing, highest minus lowest deflection asked, must fit the whole travel.
    Where it fits only from some bases, a flight reports the time clipped at a stop (:mod:`washbench.flight.openloop`).
    """
    from washbench.flight.inputs import shape_extent

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


def _check_properties(m: Manoeuvre, where: _Where) -> None:
    """Every JSBSim property an input names exists in the model (JSBSim itself ignores typos)."""
    wanted = [
        ((("phases", i, "inputs", "properties", j, "property")), pi.property)
        for i, phase in enumerate(m.phases)
        if phase.inputs is not None
        for j, pi in enumerate(phase.inputs.properties)
    ]
    if not wanted:
        return
    import os
    import tempfile

    import jsbsim

    from washbench.flight.console import quiet_stdout
    from washbench.flight.jsbsim_xml import aircraft_for_jsbsim, scratch_output_dir

    os.environ["JSBSIM_DEBUG"] = "0"
    fdm = jsbsim.FGFDMExec(str(jsbsim_root()), None)
    fdm.set_output_path(scratch_output_dir())
    with tempfile.TemporaryDirectory(prefix="washbench-aircraft-") as tmp:  # the model without <output>
        fdm.set_aircraft_path(str(aircraft_for_jsbsim(m.aircraft_files.root, m.aircraft, Path(tmp))))
        with quiet_stdout():
            try:
                loaded = fdm.load_model(m.aircraft)
            except Exception as exc:  # JSBSim raises plain exceptions on broken models
                raise where.error(("aircraft",), f"JSBSim could not load the model ({exc})") from None
    if not loaded:
        raise where.error(("aircraft",), "JSBSim could not load the model")
    pm = fdm.get_property_manager()
    for loc, name in wanted:
        if not pm.hasNode(name):
            where.add(loc, f"unknown JSBSim property '{name}' (not in the {m.aircraft} model)")


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


def manoeuvre_json_schema() -> dict[str, Any]:
    """The JSON Schema of manoeuvre files (for editors: completion and checking)."""
    schema = _plain_descriptions(Manoeuvre.model_json_schema())
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    schema["title"] = "washbench manoeuvre"
    return schema


def _plain_descriptions(node: Any) -> Any:
    """Docstrings as editor hover text: ``code`` as Markdown `code`, lines joined within a paragraph."""
    if isinstance(node, dict):
        out = {k: _plain_descriptions(v) for k, v in node.items()}
        text = node.get("description")
        if isinstance(text, str):
            paragraphs = [" ".join(p.split()) for p in text.replace("``", "`").split("\n\n")]
            out["description"] = "\n\n".join(p for p in paragraphs if p)
        return out
    if isinstance(node, list):
        return [_plain_descriptions(v) for v in node]
    return node


def schema_command(out: Path | None) -> int:
    """``washbench schema [--out FILE]``: print or write the JSON Schema."""
    text = json.dumps(manoeuvre_json_schema(), indent=2, sort_keys=True) + "\n"
    if out is None:
        sys.stdout.write(text)
    else:
        write_text_atomic(prepare_output_file(out), text)
    return 0
