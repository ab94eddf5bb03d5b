"""Washout parameters: the typed, frozen model of ``washbench/data/cw1.yaml`` and its loader.

Units are in the key names (rad/s for break frequencies, deg/s for rate limits at this edge; the
numbers are converted to SI when the compiled bank is built). Unknown keys, wrong types and
non-positive values are rejected with one line naming file, line and field.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import BeforeValidator, Field

from washbench.errors import WashbenchError
from washbench.io.paths import DATA_DIR
from washbench.io.yamlio import StrictModel, validate_data

CLASSICAL_KINDS: tuple[str, ...] = ("small-angle", "large-angle", "unrestricted")
"""The paper's three classical-family washouts."""

ADAPTIVE_KINDS: tuple[str, ...] = ("adaptive", "adaptive-large-angle", "adaptive-unrestricted")
"""The coordinated adaptive washout on the small-angle, large-angle and unrestricted structures (docs/washouts.md)."""

WASHOUT_KINDS: tuple[str, ...] = CLASSICAL_KINDS + ADAPTIVE_KINDS
"""The compiled built-in washout algorithms (kinds). A run's washouts are a list of (name, kind, parameters): the
built-in washouts are named after their kind, variants (:mod:`washbench.cueing.variants`) have their own names.
Algorithms outside the kernel (Python: built-in ones and plugins) are in :mod:`washbench.cueing.registry`."""

WASHOUT_NAMES = CLASSICAL_KINDS
"""The built-in washouts run by default (one per kind, named after it): the paper's three."""

DEFAULT_PARAMS_PATH = DATA_DIR / "cw1.yaml"


# Accepted ranges (a finite but absurd number, e.g. a scale of 1e300, would make the platform model meaningless
# or slow): break frequencies up to 1000 rad/s, scale factors up to 10, gravity 1..100 m/s^2, rates in deg/s.
Positive = Annotated[float, Field(gt=0.0, le=1e3, allow_inf_nan=False)]
NonNegative = Annotated[float, Field(ge=0.0, le=1e3, allow_inf_nan=False)]
Finite = Annotated[float, Field(ge=-10.0, le=10.0, allow_inf_nan=False)]  # head offset, m
ScaleFactor = Annotated[float, Field(gt=0.0, le=10.0, allow_inf_nan=False)]
Gravity = Annotated[float, Field(ge=1.0, le=100.0, allow_inf_nan=False)]
RATE_LIMIT_MAX_DEGPS = 3600.0


def _positive_or_off(value: Any) -> float | None:
    """A positive finite number, or ``off`` (YAML reads a bare ``off`` as false): None means no limit."""
    if value is False or value is None or value == "off":
        return None
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value) or value <= 0.0:
        raise ValueError(f"expected a positive number or off, got {value!r}")
    if value > RATE_LIMIT_MAX_DEGPS:
        raise ValueError(f"expected at most {RATE_LIMIT_MAX_DEGPS:g} deg/s or off, got {value!r}")
    return float(value)


PositiveOrOff = Annotated[float | None, BeforeValidator(_positive_or_off)]
"""A rate limit (deg/s, at most RATE_LIMIT_MAX_DEGPS) that can be switched off: ``off`` in YAML (None here)."""


class TranslationalAxes(StrictModel):
    """One value per axis x, y, z (surge, sway, heave)."""

    x: Positive
    y: Positive
    z: Positive

    @property
    def xyz(self) -> tuple[float, float, float]:
        """The three values in axis order (x, y, z)."""
        return (self.x, self.y, self.z)


class RotationalAxes(StrictModel):
    """One value per rotational axis."""

    roll: NonNegative
    pitch: NonNegative
    yaw: NonNegative


class Scale(StrictModel):
    """Scale factors applied to the aircraft motion before the washout (dimensionless)."""

    specific_force: ScaleFactor
    angular_velocity: ScaleFactor


class Tilt(StrictModel):
    """Tilt coordination."""

    lowpass_wn_radps: TranslationalAxes
    gain_per_s: Positive
    rate_limit_degps: PositiveOrOff
    rate_limit_mode: Literal["norm", "axis"] = "norm"
    lowpass_position: Literal["auto", "before_cross_product", "after_cross_product"] = "auto"


class Rotational(StrictModel):
    """Rotational channel."""

    highpass_wn_radps: RotationalAxes
    saturation_degps: PositiveOrOff


class Head(StrictModel):
    """Simulator pilot-head motion (paper Eqs. 7-10, 18-19)."""

    derivative_wn_radps: Annotated[float, Field(gt=0.0, le=1e4, allow_inf_nan=False)]
    offset_m: tuple[Finite, Finite, Finite]
    rate_method: Literal["auto", "euler_estimator", "quaternion_difference"] = "auto"


class SmallAngle(StrictModel):
    """Guards of the Euler-angle (small-angle) washout."""

    min_cos_pitch: Annotated[float, Field(gt=0.0, lt=1.0)]


class GainBounds(StrictModel):
    """An adapted gain's bounds (and, for the translational gain, its start)."""

    min: NonNegative
    max: Positive


class TranslationalGain(GainBounds):
    """The translational channel's adaptive gain p (dimensionless), per inertial axis."""

    initial: Annotated[float, Field(ge=0.0, le=10.0, allow_inf_nan=False)] = 1.0


class Adaptive(StrictModel):
    """The coordinated adaptive washout (kinds ``adaptive``, ``adaptive-large-angle``, ``adaptive-unrestricted``):
    steepest descent on J = 1/2 [W_f |f_A - f_S|^2 + W_w |w_A - w_S|^2 + W_x |x|^2 + W_v |v|^2 + W_p |p - p0|^2
    + W_k |k - k0|^2] (docs/washouts.md). Rates of 0 give the classical washout of the same structure exactly.
    All values chosen (Reid and Nahon's published set was not available to us); their effect is in the docs."""

    rate_translational: NonNegative = 1.0
    """G_p: adaptation rate of the translational gains p, 1/((m/s^2)^2 s) per unit cost."""
    rate_tilt: NonNegative = 1.0
    """G_k: adaptation rate of the tilt gains k (1/s), per unit cost and second."""
    weight_specific_force: NonNegative = 1.0
    """W_f on the specific-force error, per (m/s^2)^2."""
    weight_angular_velocity: NonNegative = 10.0
    """W_w on the angular-velocity error, per (rad/s)^2."""
    weight_position: NonNegative = 1.0
    """W_x on the translational set point's distance from centre, per m^2."""
    weight_velocity: NonNegative = 1.0
    """W_v on its speed, per (m/s)^2."""
    weight_gain_translational: NonNegative = 0.1
    """W_p pulling p back to its start."""
    weight_gain_tilt: NonNegative = 0.1
    """W_k pulling k back to the tilt gain (tilt.gain_per_s)."""
    translational_gain: TranslationalGain = TranslationalGain(min=0.0, max=1.5)
    """p: start and bounds."""
    tilt_gain_per_s: GainBounds = GainBounds(min=0.05, max=5.0)
    """k bounds, 1/s (it starts at tilt.gain_per_s)."""


class WashoutParams(StrictModel):
    """A complete washout parameter set (e.g. CW1), shared by the three washouts."""

    name: str
    gravity_mps2: Gravity
    scale: Scale
    translational_highpass_wn_radps: TranslationalAxes
    tilt: Tilt
    rotational: Rotational
    head: Head
    small_angle: SmallAngle
    free_fall_threshold_mps2: Annotated[float, Field(gt=0.0, le=100.0, allow_inf_nan=False)]
    adaptive: Adaptive = Adaptive()
    """The adaptive washouts' rates, weights and gain bounds (defaults when the section is absent)."""
    sections: dict[str, dict[str, Any]] = Field(default_factory=dict)
    """The Python algorithms' own sections (:mod:`washbench.cueing.registry`), by kind: in the file each is a
    top-level key named after the algorithm; validated by the algorithm's ``Params`` when a washout is made."""


def load_base_params(path: Path, data: Any, lines: dict[Any, int]) -> WashoutParams:
    """Validate parsed YAML ``data`` (without its ``variants:`` section) into a WashoutParams."""
    return validate_data(path, data, lines, WashoutParams)


FILTER_STARTS = ("steady", "rest")
"""Start states: ``steady`` of the first sample (a recording that begins in steady flight), or ``rest`` (the
simulator level and still, f = [0, 0, -g]: the first sample is a change, as for a recording begun mid-manoeuvre)."""


def check_filter_start(start: str) -> str:
    """``start`` if it is one of :data:`FILTER_STARTS`, else WashbenchError (checked before
    anything is read: the compiled bank, and numba, are imported only once there is work for them)."""
    if start not in FILTER_STARTS:
        raise WashbenchError(f"unknown filter start {start!r} (valid: {', '.join(FILTER_STARTS)})")
    return start
