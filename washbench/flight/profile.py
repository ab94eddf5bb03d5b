"""Per-aircraft scripted-pilot profile: speeds, limits, geometry and control gains.

The pilot's control laws are the same for every aircraft; what differs (V-speeds, load
limits, the height of the centre of gravity at rest, the sign of nosewheel steering, the
loop gains) is read from the aircraft's ``pilot.yaml`` (found as :mod:`washbench.io.paths` says). Gains are given at
``reference_airspeed_kts`` and scaled with (V_ref / V)^2 so the loops keep their bandwidth
as dynamic pressure changes.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Literal

from pydantic import Field

from washbench.io.yamlio import StrictModel, load_yaml_model

Positive = Annotated[float, Field(gt=0)]
NonNegative = Annotated[float, Field(ge=0)]


class Speeds(StrictModel):
    """Calibrated airspeeds, kt."""

    stall_kts: Positive
    vr_kts: Positive
    vy_kts: Positive
    vno_kts: Positive
    vne_kts: Positive


class Limits(StrictModel):
    nz_max: Positive  # structural limit load factor, g
    nz_min: Annotated[float, Field(lt=0)]
    touchdown_sink_max_fps: Positive  # beyond it the landing is a crash
    alpha_stall_deg: Positive  # the "stall" event
    flaps_max_deg: Positive
    flaps_full_cmd_deg: Positive  # flap angle that fcs/flap-cmd-norm = 1 commands
    ceiling_ft: Positive | None = None  # highest air start accepted, ft MSL (service ceiling)


class Geometry(StrictModel):
    cg_height_on_ground_ft: Positive  # position/h-agl-ft at rest on level ground
    gear_contacts: list[Annotated[int, Field(ge=0)]]  # gear/unit[i]
    structure_contacts: list[Annotated[int, Field(ge=0)]]  # contact/unit[i] that must never touch


class Engine(StrictModel):
    steer_sign: Annotated[float, Field(ge=-1, le=1)]  # fcs/steer-cmd-norm = steer_sign * rudder-like command
    mixture_schedule: Annotated[list[tuple[float, float]], Field(min_length=1)]  # (altitude_ft, mixture 0..1)
    magneto_cmd: Annotated[int, Field(ge=0, le=3)] | None = None  # propulsion/magneto_cmd at engine start
    propeller_advance_norm: Annotated[float, Field(ge=0, le=1)] | None = None  # fcs/advance-cmd-norm[0] (lever)


class StartOptions(StrictModel):
    """How an air start reaches steady flight.

    ``trim``: JSBSim's ``do_trim(1)``. ``flying``: a flying start, for models JSBSim's trim cannot
    handle (it evaluates the engine alone, without the flight control system): the scripted pilot
    flies the start condition in still air for ``settle_s`` seconds, then the aircraft is put back
    at the start point with the settled attitude, velocities and controls, and the clock at zero.
    """

    air: Literal["trim", "flying"] = "trim"
    settle_s: Positive = 30.0  # flying start: settling time, s


class Surface(StrictModel):
    """Travel of one control surface, as the model's flight-control system maps the command onto it.

    JSBSim's ``aerosurface_scale`` maps the command plus trim (``trim_property``), -1..1, zero-centred
    onto the travel: +1 gives ``max_deg``, -1 ``min_deg``. ``property`` reads the deflection back.
    """

    property: str
    """JSBSim property of the surface deflection, deg (e.g. fcs/elevator-pos-deg)."""
    trim_property: str | None = None
    """JSBSim property of the trim command added to the pilot's command before the scale."""
    min_deg: Annotated[float, Field(le=0)]
    """Deflection at command -1, deg."""
    max_deg: Annotated[float, Field(ge=0)]
    """Deflection at command +1, deg."""


class Surfaces(StrictModel):
    """Surface travel of the three primary controls (from the model XML), for inputs given in degrees."""

    elevator: Surface
    aileron: Surface
    rudder: Surface


class RollGains(StrictModel):
    bank_to_rate: Positive  # roll-rate command per bank error, 1/s
    rate_max_degps: Positive
    kp: Positive  # aileron per rad/s of roll-rate error
    ki: NonNegative  # aileron per rad of integrated roll-rate error
    rate_feedforward: NonNegative  # aileron a steady roll needs, per rad/s at a true airspeed of the reference
    bank_max_deg: Positive  # bank used by heading and track modes


class PitchGains(StrictModel):
    pitch_to_rate: Positive  # pitch-rate command per pitch error, 1/s
    rate_max_degps: Positive
    kp: Positive  # elevator per rad/s of pitch-rate error
    ki: NonNegative
    pitch_min_deg: float
    pitch_max_deg: float
    nz_kp: NonNegative = 0.05  # load-factor loop: pitch rate per g of load-factor error, rad/s/g
    nz_ki: NonNegative = 0.1  # its integral gain, rad/s/g/s
    alpha_max_deg: Positive = 14.0  # load-factor loop: the largest angle of attack it pulls to, deg
    alpha_to_rate: Positive = 2.0  # pitch rate per angle-of-attack excess, 1/s
    nz_pull_max: Positive | None = None  # load-factor protection: largest load factor the pilot pulls, g
    nz_push_min: Annotated[float, Field(lt=0)] | None = None  # and the most negative one pushed, g


class PathGains(StrictModel):
    climb_to_pitch: Positive  # pitch command per flight-path-angle error (climb-rate error / V), rad/rad
    climb_to_pitch_i: NonNegative  # integral gain of the same, 1/s
    altitude_to_vs: Positive  # climb-rate command per ft of altitude error, 1/s
    vs_max_fps: Positive
    glide_path_to_vs: Positive  # climb-rate correction per ft below the glide path, 1/s
    speed_tau_s: Positive  # airspeed held (elevator or throttle): an error closes at error / tau kt/s ...
    accel_max_ktps: Positive  # ... up to this rate
    speed_rate_filter_s: Positive  # time constant of the filter on the airspeed rate, s
    energy_to_throttle: Positive  # throttle per rad of specific energy-rate error (gamma + vdot / g)
    energy_to_throttle_i: NonNegative  # its integral gain, 1/s
    throttle_rate_per_s: Positive  # throttle slew-rate limit


class YawGains(StrictModel):
    beta_kp: NonNegative  # rudder per rad of sideslip
    beta_ki: NonNegative  # rudder per rad s
    yaw_damper: NonNegative  # rudder per rad/s of yaw-rate beyond the coordinated rate
    aileron_to_rudder: NonNegative  # rudder per aileron of the roll-rate feed-forward (against adverse yaw)


class TrackGains(StrictModel):
    heading_to_bank: Positive  # bank per heading error (deg/deg)
    track_to_bank: Positive  # bank per ground-track error (deg/deg)
    offset_to_track_deg_per_ft: Positive  # intercept angle per ft off the centreline
    intercept_max_deg: Positive
    offset_ki: NonNegative  # integral of the centreline offset: 1/s (added to the offset the intercept uses)
    offset_integral_max_deg: NonNegative  # the largest intercept angle the integral may ask for


class GroundGains(StrictModel):
    heading_kp: Positive  # rudder/steer per rad of heading error
    heading_ki: NonNegative  # per rad s
    yaw_rate_kd: NonNegative  # per rad/s
    offset_to_heading_deg_per_ft: Positive
    offset_heading_max_deg: Positive
    offset_ki: NonNegative  # on the ground: the same integral of the offset
    offset_integral_max_deg: NonNegative


class FlareGains(StrictModel):
    tau_s: Positive  # commanded sink = height of the wheels / tau
    sink_min_fps: Positive  # at the wheels' touchdown


class Gains(StrictModel):
    reference_airspeed_kts: Positive
    surface_rate_per_s: Positive  # largest rate of aileron, elevator and rudder commands (full travel = 1)
    roll: RollGains
    pitch: PitchGains
    path: PathGains
    yaw: YawGains
    track: TrackGains
    ground: GroundGains
    flare: FlareGains


class PilotProfile(StrictModel):
    aircraft: str
    speeds: Speeds
    limits: Limits
    geometry: Geometry
    engine: Engine
    gains: Gains
    start: StartOptions = StartOptions()
    surfaces: Surfaces | None = None


def load_profile(path: str | Path) -> PilotProfile:
    """Load a pilot profile YAML (one-line WashbenchError on any problem)."""
    return load_yaml_model(path, PilotProfile)
