"""The multimodal pilot model's parameters, with the values chosen and where they come from (docs/pilot-model.md).

The model (:mod:`washbench.pilot.multimodal`), per task axis::

    u = H_nms(s) [ H_v(s) (e + n_v) - H_m(s) (w_hat + n_m) - H_a(s) (f_hat - f_hat_0) ]

    H_v(s)   = K_v (T_L s + 1) / (T_I s + 1) exp(-tau_v s)     visual: to the displayed error e [rad]
    H_m(s)   = K_m exp(-tau_m s)                               vestibular: to the canals' perceived rate [rad/s]
    H_a(s)   = K_a exp(-tau_m s)                               otolith: to the perceived specific force [m/s^2]
    H_nms(s) = w_nms^2 / (s^2 + 2 zeta_nms w_nms s + w_nms^2)   neuromuscular dynamics

``u`` is in the task's control units (normalised aileron, or normalised elevator with the nose-up sign), so
``K_v`` is in control units per rad and ``K_m`` per rad/s; ``K_m / K_v`` (s) is free of those units. ``n_v`` and
``n_m`` are white perception noises (two-sided intensities ``V_v`` in rad^2 s and ``V_m`` in rad^2/s): the
remnant of the time-domain model and the reason the optimal adaptation (:mod:`washbench.pilot.adapt`) keeps the
vestibular gain finite.

Values (docs/pilot-model.md, "The values"): the delays and the neuromuscular frequency and damping are those
identified by Pool et al. (2016) for trained pilots with motion; ``K_v``, ``T_L`` and ``K_m`` are adapted to each
condition; ``V_v`` is chosen (the optimal-control model's -20 dB observation noise for a 0.5 deg RMS error) and
``V_m`` is calibrated once (:data:`CALIBRATED_VESTIBULAR_NOISE`).
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field

from washbench.io.yamlio import StrictModel

Gain = Annotated[float, Field(ge=0.0, le=1.0e3)]
Delay = Annotated[float, Field(ge=0.0, le=1.0)]
TimeConstant = Annotated[float, Field(ge=0.0, le=10.0)]

#: Vestibular (roll- or pitch-rate) perception noise, rad^2/s: calibrated once (tools/calibrate_pilot_noise.py) so
#: that the model adapted to the aircraft's own motion on the bundled c172p roll task has K_m / K_v = 0.10 s, within
#: the 0.05-0.12 s Pool et al. (2016) identified (docs/pilot-model.md, "Calibration"); kept fixed for every
#: condition, task and aircraft.
CALIBRATED_VESTIBULAR_NOISE = 8.1e-5
#: Visual (displayed-error) perception noise, rad^2 s: chosen, the optimal-control model's observation noise of
#: -20 dB (rho = 0.01 pi) for a 0.5 deg RMS error: 0.01 pi (0.5 pi / 180)^2 = 2.4e-6.
VISUAL_NOISE = 2.4e-6


class MultimodalParams(StrictModel):
    """The built-in model's parameters (module docstring: the equation; docs/pilot-model.md: the values)."""

    visual_gain: Gain = 2.0
    """K_v: visual gain, control units per rad of displayed error (adapted per condition)."""
    lead_s: TimeConstant = 0.3
    """T_L: visual lead time constant, s (adapted per condition)."""
    lag_s: TimeConstant = 0.0
    """T_I: visual lag time constant, s (0: none, the roll and pitch tasks' form)."""
    visual_delay_s: Delay = 0.22
    """tau_v: visual time delay, s (Pool et al. 2016)."""
    vestibular_gain: Gain = 0.2
    """K_m: vestibular gain, control units per rad/s of perceived rate (adapted per condition; 0: visual only)."""
    vestibular_delay_s: Delay = 0.19
    """tau_m: vestibular time delay, s (Pool et al. 2016)."""
    otolith_gain: Gain = 0.0
    """K_a: otolith gain, control units per m/s^2 of perceived specific force on the task's axis (0: off)."""
    nms_frequency_radps: Annotated[float, Field(gt=0.5, le=100.0)] = 14.0
    """w_nms: neuromuscular natural frequency, rad/s (Pool et al. 2016)."""
    nms_damping: Annotated[float, Field(gt=0.0, le=2.0)] = 0.30
    """zeta_nms: neuromuscular damping ratio (Pool et al. 2016)."""
    visual_noise_rad2s: Annotated[float, Field(ge=0.0, le=1.0)] = VISUAL_NOISE
    """V_v: intensity of the white noise on the perceived error, rad^2 s (0: none)."""
    vestibular_noise_rad2ps: Annotated[float, Field(ge=0.0, le=1.0)] = CALIBRATED_VESTIBULAR_NOISE
    """V_m: intensity of the white noise on the perceived rate, rad^2/s (0: none)."""


ADAPTABLE = ("visual_gain", "lead_s", "vestibular_gain")
"""The parameters the optimal adaptation may change (the others are the published values, fixed)."""


class AdaptParams(StrictModel):
    """How the model adapts to a condition (:mod:`washbench.pilot.adapt`)."""

    rule: Literal["optimal", "none"] = "optimal"
    """optimal: minimise J = var(e) + control_weight var(u_eq) over the adapted parameters; none: fly as given."""
    control_weight_s2: Annotated[float, Field(ge=0.0, le=100.0)] = 0.01
    """w_u: weight of the control effort, s^2 (u_eq = |j H_c(j 1)| u: the control as the attitude rate it asks at
    1 rad/s, rad/s, so J is in rad^2 whatever the aircraft's control power). Chosen (docs/pilot-model.md shows its
    effect)."""
    adapt: tuple[Literal["visual_gain", "lead_s", "vestibular_gain"], ...] = ADAPTABLE
    """Which parameters adapt (the others keep the values given)."""


#: The published set the stability check uses, with its plant: Pool et al. (2016) (trained motion group, end of
#: training), a pitch target-following disturbance-rejection task on Cessna Citation pitch dynamics
#: theta / delta_e = 10.62 (s + 0.99) / (s (s^2 + 2.58 s + 7.61)) behind a stick gain of 0.2865, with a visual
#: response K_v (T_lead s + 1)^2 / (T_lag s + 1) exp(-tau_v s) and a vestibular one s^2 H_scc K_m exp(-tau_m s),
#: H_scc = (0.11 s + 1) / (5.9 s + 1) (docs/pilot-model.md, "Stability at the published values").
PUBLISHED_PITCH = {
    "visual_gain": 4.75,
    "lead_s": 0.30,
    "lag_s": 0.95,
    "visual_delay_s": 0.22,
    "vestibular_gain": 3.00,
    "vestibular_delay_s": 0.19,
    "nms_frequency_radps": 14.0,
    "nms_damping": 0.30,
    "stick_gain": 0.2865,
}
