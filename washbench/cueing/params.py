"""Washout parameters: the typed, frozen model of ``washbench/data/cw1.yaml`` and its loader.

Units are in the key names (rad/s for break frequencies, deg/s for rate limits at this edge; the
numbers are converted to SI when the compiled bank is built). Unknown keys, wrong types and
non-positive values are rejected with one line naming file, line and field.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import BeforeValidator, Field

from washbench.errors import WashbenchError
from washbench.io.paths import DATA_DIR
from washbench.io.yamlio import StrictModel, validate_data

WASHOUT_KINDS: tuple[str, ...] = ("small-angle", "large-angle", "unrestricted")
"""The three washout algorithms (kinds). A run's washouts are a list of (name, kind, parameters): the
built-in washouts are named after their kind, variants (:mod:`washbench.cueing.variants`) have their own names."""

WASHOUT_NAMES = WASHOUT_KINDS
"""The built-in washouts run by default (one per kind, named after it)."""

DEFAULT_PARAMS_PATH = DATA_DIR / "cw1.yaml"


def check_washouts(washouts: Sequence[str]) -> tuple[str, ...]:
    """Built-in washout names as a tuple; WashbenchError if none, one is unknown or one is listed twice."""
    names = tuple(washouts)
    if not names:
        raise WashbenchError("no washout selected")
    for name in names:
        if name not in WASHOUT_KINDS:
            raise WashbenchError(f"unknown washout {name!r} (valid: {', '.join(WASHOUT_KINDS)})")
    if len(set(names)) != len(names):
        raise WashbenchError(f"washout listed twice: {', '.join(names)}")
    return names


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


def load_base_params(path: Path, data: Any, lines: dict[Any, int]) -> WashoutParams:
    """Validate parsed YAML ``data`` (without its ``variants:`` section) into a WashoutParams."""
    return validate_data(path, data, lines, WashoutParams)
