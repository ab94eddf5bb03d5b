"""Washout parameters: the typed, frozen model of ``washbench/data/cw1.yaml`` and its loader.

Units are in the key names (rad/s for break frequencies, deg/s for rate limits at this edge; the
numbers are converted to SI when the compiled bank is built). Unknown keys, wrong types and
non-positive values are rejected with one line naming file, line and field.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Annotated

from pydantic import Field

from washbench.errors import WashbenchError
from washbench.io.paths import DATA_DIR
from washbench.io.yamlio import StrictModel, load_yaml_model

WASHOUT_NAMES: tuple[str, ...] = ("small-angle", "large-angle", "unrestricted")
DEFAULT_PARAMS_PATH = DATA_DIR / "cw1.yaml"


def check_washouts(washouts: Sequence[str]) -> tuple[str, ...]:
    """The names as a tuple; WashbenchError if none, one is unknown or one is listed twice."""
    names = tuple(washouts)
    if not names:
        raise WashbenchError("no washout selected")
    for name in names:
        if name not in WASHOUT_NAMES:
            raise WashbenchError(f"unknown washout {name!r} (valid: {', '.join(WASHOUT_NAMES)})")
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
RateLimit = Annotated[float, Field(gt=0.0, le=3600.0, allow_inf_nan=False)]  # deg/s


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
    rate_limit_degps: RateLimit


class Rotational(StrictModel):
    """Rotational channel."""

    highpass_wn_radps: RotationalAxes
    saturation_degps: RateLimit


class Head(StrictModel):
    """Simulator pilot-head motion (paper Eqs. 7-10, 18-19)."""

    derivative_wn_radps: Annotated[float, Field(gt=0.0, le=1e4, allow_inf_nan=False)]
    offset_m: tuple[Finite, Finite, Finite]


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


def load_washout_params(path: Path | None = None) -> WashoutParams:
    """Load a washout parameter YAML file (``None``: the bundled CW1 set, ``washbench/data/cw1.yaml``).

    Raises :class:`washbench.errors.WashbenchError` with ``file:line: field: problem`` on bad input.
    """
    return load_yaml_model(DEFAULT_PARAMS_PATH if path is None else Path(path), WashoutParams)
