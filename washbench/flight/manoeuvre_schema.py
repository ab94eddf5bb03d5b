"""Manoeuvre files: the YAML schema, every key with its unit and range.

A manoeuvre names the aircraft, the start (in the air or at rest on a runway), the
environment, a sequence of phases (what the pilot holds, and when the phase ends) and the
checks that prove it was flown. Keys carry their units (``altitude_ft``, ``bank_deg``).
The format is documented in docs/reference/manoeuvre-format.md.

Conventions: headings and wind directions are true, in degrees; the wind is given by the
direction it blows FROM (aviation convention: ``from_deg: 270`` is a westerly wind,
blowing towards the east). Airspeeds are calibrated (KCAS ~ KIAS).

What a schema cannot say (a known aircraft, one start, phases that can end, ...) is checked by
:mod:`washbench.flight.manoeuvre_checks`; :class:`washbench.flight.manoeuvre.Manoeuvre` is these fields with those
checks, and :func:`washbench.flight.manoeuvre.load_manoeuvre` reads a file.
"""

from __future__ import annotations

from typing import Annotated, Literal, get_args

from pydantic import Field, field_validator

from washbench.io.names import Identifier
from washbench.io.yamlio import StrictModel

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
    seed: Annotated[int, Field(ge=0, lt=2**31)] | None = None
    """Seed of JSBSim's random generator: the same seed gives the same gusts (needed unless severity is none)."""


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


class ManoeuvreFields(StrictModel):
    """The fields of a manoeuvre file, as the schema states them (:class:`washbench.flight.manoeuvre.Manoeuvre` adds
    the checks between them)."""

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
