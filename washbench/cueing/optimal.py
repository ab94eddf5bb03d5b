"""The optimal washout (``optimal``): a linear-quadratic design with the vestibular models in the loop.

After Sivan, Ish-Shalom and Huang (1982) and Telban and Cardullo (NASA CR-2005-213747, 2005): per channel
(:mod:`washbench.cueing.motion_model`: pitch = surge + pitch, roll = sway + roll, heave, yaw) the aircraft input r
is modelled as white noise through a first-order low-pass, ``dr/dt = -gamma r + w``; the simulator's controls u
(platform acceleration, cockpit rate) minimise

    J = E{ integral of  e^T W_e e + x^T W_x x + u^T W_u u  dt }

with e the perceived error (otolith and canal models of the simulator minus the aircraft pilot's), x the platform
states (tilt or yaw angle, position, velocity) and u the controls. The algebraic Riccati equation of the augmented
system [x; r] (``scipy.linalg.solve_continuous_are``) gives u = -K_x x - K_r r, i.e. the linear washout filter

    dx/dt = (A - B K_x) x + (E - B K_r) r,     set points: position and angle states of x.

Designed once when the washout is made, discretised exactly for an input linear between samples (first-order
hold: the same input assumption as ``scipy.signal.lsim``) and run per step as one block-diagonal state-space
update (two matrix-vector products). Equations, weights and interpretations: ``docs/optimal-mpc.md``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Annotated, Any

import numpy as np
from pydantic import Field, model_validator
from scipy import linalg

from washbench.cueing.algorithm import SetPoint, WashoutContext
from washbench.cueing.motion_model import (
    CHANNELS,
    ChannelModel,
    channel_inputs,
    channel_model,
    discretise_foh,
    with_position_integral,
)
from washbench.io.yamlio import StrictModel
from washbench.numerics.rotations import quat_from_euler
from washbench.perception.vestibular import CanalParams, OtolithParams

Weight = Annotated[float, Field(ge=0.0, le=1e9, allow_inf_nan=False)]
PositiveWeight = Annotated[float, Field(gt=0.0, le=1e9, allow_inf_nan=False)]


class ChannelWeights(StrictModel):
    """Weights of one channel's quadratic cost (SI: per (m/s^2)^2, (rad/s)^2, rad^2, m^2, (m/s)^2).

    Fields a channel does not have are ignored (heave has no rate or angle, yaw no force, position or velocity).
    """

    force: Weight = 1.0
    """on the perceived specific-force error (otolith model output), per (m/s^2)^2"""
    direct_force: Weight = 0.0
    """on the specific-force error itself at the head (simulator minus aircraft, before the otolith model), per
    (m/s^2)^2: without it the design may start a translational cue with a sharp opposite move (see the docs)"""
    rate: Weight = 1.0
    """on the perceived angular-velocity error (canal model output), per (rad/s)^2"""
    angle: Weight = 0.0
    """on the cockpit's tilt (pitch, roll) or yaw angle, per rad^2"""
    position: Weight = 0.0
    """on the platform's position, per m^2"""
    velocity: Weight = 0.0
    """on the platform's velocity, per (m/s)^2"""
    position_integral: Weight = 0.0
    """on the time integral of the platform's position, per (m s)^2 (optimal washout only: > 0 brings the
    platform back to the centre under a sustained input)"""
    acceleration: PositiveWeight = 1.0
    """on the platform's acceleration (a control), per (m/s^2)^2"""
    angular_rate: PositiveWeight = 1.0
    """on the cockpit's angular rate (a control), per (rad/s)^2"""


class VestibularChoice(StrictModel):
    """The vestibular models inside the design (default: the paper's Eqs. 11-12, as the bench's perception)."""

    otolith: OtolithParams = OtolithParams()
    canals: CanalParams = CanalParams()


def _default_weights() -> dict[str, ChannelWeights]:
    # chosen (not published for this platform): see docs/optimal-mpc.md for the effect of each
    tilt = ChannelWeights(
        force=1.0,
        direct_force=1.0,
        rate=10.0,
        angle=1.0,
        position=0.4,
        velocity=0.4,
        position_integral=0.1,
        acceleration=0.05,
        angular_rate=0.5,
    )
    return {
        "pitch": tilt,
        "roll": tilt,
        "heave": ChannelWeights(
            force=1.0, direct_force=1.0, position=4.0, velocity=1.0, position_integral=0.5, acceleration=0.05
        ),
        "yaw": ChannelWeights(rate=10.0, angle=0.5, angular_rate=0.5),
    }


class OptimalParams(StrictModel):
    """The ``optimal:`` section of the parameter file."""

    input_break_radps: Annotated[float, Field(gt=0.0, le=1e3, allow_inf_nan=False)] = 1.0
    """gamma: break frequency of the first-order low-pass that models the aircraft input (rad/s)"""
    vestibular: VestibularChoice = VestibularChoice()
    pitch: ChannelWeights = Field(default_factory=lambda: _default_weights()["pitch"])
    roll: ChannelWeights = Field(default_factory=lambda: _default_weights()["roll"])
    heave: ChannelWeights = Field(default_factory=lambda: _default_weights()["heave"])
    yaw: ChannelWeights = Field(default_factory=lambda: _default_weights()["yaw"])

    @model_validator(mode="before")
    @classmethod
    def _channel_defaults(cls, data: Any) -> Any:
        """A channel section given in part keeps that channel's defaults for the keys it does not give."""
        return merge_channel_defaults(data, {ch: w.model_dump() for ch, w in _default_weights().items()})


def merge_channel_defaults(data: Any, defaults: dict[str, dict[str, Any]]) -> Any:
    """``data`` with each channel mapping laid over that channel's default mapping (other values unchanged)."""
    if not isinstance(data, dict):
        return data
    out = dict(data)
    for ch, base in defaults.items():
        if isinstance(out.get(ch), dict):
            out[ch] = {**base, **out[ch]}
    return out


def cost_matrices(model: ChannelModel, w: ChannelWeights) -> tuple[np.ndarray, np.ndarray]:
    """(Q (n, n), R (m, m)) of the channel's running cost e^T W_e e + x^T W_x x + u^T W_u u, e = C_err x."""
    n = model.A.shape[0]
    k = model.C_err.shape[0]
    we = np.array([w.force if i < model.force_inputs else w.rate for i in range(k)])
    Q = model.C_err.T @ np.diag(we) @ model.C_err
    if model.i_angle >= 0:
        Q[model.i_angle, model.i_angle] += w.angle
    if model.i_pos >= 0:
        Q[model.i_pos, model.i_pos] += w.position
        Q[model.i_vel, model.i_vel] += w.velocity
    if model.i_int >= 0:
        Q[model.i_int, model.i_int] += w.position_integral
    ru = []
    for name in model.controls:
        ru.append(w.acceleration if name.startswith("a_") else w.angular_rate)
    Q = 0.5 * (Q + Q.T)
    return Q + np.zeros((n, n)), np.diag(ru)


@dataclass(frozen=True)
class ChannelDesign:
    """One channel's LQ design: the gain, the Riccati solution and the resulting washout filter (continuous).

    Washout filter: dx/dt = A_w x + B_w r; controls u = -K_x x - K_r r. ``P`` solves the CARE of the augmented
    system [x; r] with ``A_aug = [[A, E], [0, -gamma I]]``.
    """

    model: ChannelModel
    gamma: float
    Q: np.ndarray
    R: np.ndarray
    P: np.ndarray
    K_x: np.ndarray
    K_r: np.ndarray
    A_w: np.ndarray
    B_w: np.ndarray
    S: np.ndarray  # cross weight between [x; r] and u (the direct force error term)
    Q_aug: np.ndarray  # the augmented state weight including the direct force error term

    def augmented(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(A_aug, B_aug, Q_aug) of the Riccati problem (its cost: z' Q_aug z + u' R u + 2 z' S u)."""
        a, b, _ = augmented_system(self.model, self.gamma, self.Q)
        return a, b, self.Q_aug

    def outputs(self) -> tuple[np.ndarray, np.ndarray, list[str]]:
        """(C, D, names): set-point outputs y = C x + D r: position (m) and angle (rad) where the channel has them."""
        n = self.A_w.shape[0]
        k = self.B_w.shape[1]
        rows, names = [], []
        if self.model.i_pos >= 0:
            rows.append(np.eye(n)[self.model.i_pos])
            names.append("position_m")
        if self.model.i_angle >= 0:
            rows.append(np.eye(n)[self.model.i_angle])
            names.append("angle_rad")
        return np.array(rows), np.zeros((len(rows), k)), names


def augmented_system(model: ChannelModel, gamma: float, Q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The Riccati problem's system: state [x; r], r modelled as ``dr/dt = -gamma r + white noise``."""
    n, m = model.B.shape
    k = model.E.shape[1]
    A = np.zeros((n + k, n + k))
    A[:n, :n] = model.A
    A[:n, n:] = model.E
    A[n:, n:] = -gamma * np.eye(k)
    B = np.vstack([model.B, np.zeros((k, m))])
    Qa = np.zeros((n + k, n + k))
    Qa[:n, :n] = Q
    return A, B, Qa


def design_channel(model: ChannelModel, weights: ChannelWeights, gamma: float) -> ChannelDesign:
    """Solve the channel's LQ problem (continuous algebraic Riccati equation) and form its washout filter.

    Raises ValueError if the design is not stabilising (weights that leave a platform state unobserved).
    """
    Q, R = cost_matrices(model, weights)
    A, B, Qa = augmented_system(model, gamma, Q)
    n = model.B.shape[0]
    k = model.E.shape[1]
    # direct force error d = C_head x + D_head u - r on the force rows: d = Cz z + D u with Cz = [C_head, -I]
    nf = model.force_inputs
    Cz = np.hstack([model.C_head[:nf], -np.eye(k)[:nf]])
    D = model.D_head[:nf]
    wd = weights.direct_force
    Qa = Qa + wd * Cz.T @ Cz
    R = R + wd * D.T @ D
    S = wd * Cz.T @ D
    try:
        P = linalg.solve_continuous_are(A, B, Qa, R, s=S)
    except (ValueError, np.linalg.LinAlgError) as exc:
        raise ValueError(
            f"optimal washout: the {model.name} design is not stable ({exc}: weights leave a state free)"
        ) from None
    K = np.linalg.solve(R, B.T @ P + S.T)
    K_x, K_r = K[:, :n], K[:, n:]
    A_w = model.A - model.B @ K_x
    B_w = model.E - model.B @ K_r
    if not np.all(np.linalg.eigvals(A_w).real < 0.0):
        raise ValueError(f"optimal washout: the {model.name} design is not stable (weights leave a state free)")
    return ChannelDesign(model, gamma, Q, R, P, K_x, K_r, A_w, B_w, S, Qa)


def design(params: OptimalParams, gravity_mps2: float) -> dict[str, ChannelDesign]:
    """The four channels' designs."""
    v = params.vestibular
    return {
        ch: design_channel(
            with_position_integral(channel_model(ch, v.otolith, v.canals, gravity_mps2)),
            getattr(params, ch),
            params.input_break_radps,
        )
        for ch in CHANNELS
    }


class OptimalWashout:
    """The optimal washout per step (:class:`washbench.cueing.algorithm.WashoutAlgorithm`).

    State: the four channels' filter states stacked (``x``) and the previous input (``r_prev``). Set points:
    position [x, y, z] from the pitch, roll and heave channels' position states (inertial NED = body axes in the
    linear design), attitude from (roll, pitch, yaw) angles, ZYX Euler, scalar-first quaternion.
    """

    Params = OptimalParams
    name = "optimal"

    def __init__(self, params: OptimalParams | None, context: WashoutContext) -> None:
        self.params = params if params is not None else OptimalParams()
        self.context = context
        self.g = float(context.gravity_mps2)
        self.designs = design(self.params, self.g)
        blocks_a, blocks_b = [], []
        self._slices: dict[str, slice] = {}
        i = 0
        for ch in CHANNELS:
            d = self.designs[ch]
            n = d.A_w.shape[0]
            self._slices[ch] = slice(i, i + n)
            i += n
            blocks_a.append(d.A_w)
            blocks_b.append(d.B_w)
        # input r = [f_x, omega_y | f_y, omega_x | f_z + g | omega_z]
        self.A_w = linalg.block_diag(*blocks_a)
        self.B_w = linalg.block_diag(*blocks_b)
        self.phi, self.g0, self.g1 = discretise_foh(self.A_w, self.B_w, float(context.dt_s))
        sl = self._slices
        self._i_pos = np.array([sl[c].start + self.designs[c].model.i_pos for c in ("pitch", "roll", "heave")])
        self._i_ang = np.array([sl[c].start + self.designs[c].model.i_angle for c in ("roll", "pitch", "yaw")])
        self.x = np.zeros(self.A_w.shape[0])
        self.r_prev = np.zeros(self.B_w.shape[1])

    def inputs(self, f_mps2: np.ndarray, omega_radps: np.ndarray) -> np.ndarray:
        """The stacked channel input r (6,) or (N, 6) from head f (m/s^2) and omega (rad/s)."""
        return np.concatenate([channel_inputs(c, f_mps2, omega_radps, self.g) for c in CHANNELS], axis=-1)

    def steady_state(self, r: np.ndarray) -> np.ndarray:
        """The filter state at rest under a constant input r: x = -A_w^-1 B_w r."""
        return -np.linalg.solve(self.A_w, self.B_w @ r)

    def _set_point(self, x: np.ndarray) -> SetPoint:
        phi, theta, psi = x[self._i_ang]
        return x[self._i_pos].copy(), np.array(quat_from_euler(float(phi), float(theta), float(psi)))

    def start(self, f_mps2: np.ndarray, omega_radps: np.ndarray) -> SetPoint:
        """Start in the steady state of the first sample (or of rest); returns that set point."""
        if self.context.filter_start == "rest":
            r0 = self.inputs(np.array([0.0, 0.0, -self.g]), np.zeros(3))
        else:
            r0 = self.inputs(np.asarray(f_mps2, dtype=np.float64), np.asarray(omega_radps, dtype=np.float64))
        self.x = self.steady_state(r0)
        self.r_prev = r0
        return self._set_point(self.x)

    def step(self, f_mps2: np.ndarray, omega_radps: np.ndarray) -> SetPoint:
        """One sample: x <- Phi x + G0 r_prev + G1 r; set points from x."""
        r = self.inputs(f_mps2, omega_radps)
        self.x = self.phi @ self.x + self.g0 @ self.r_prev + self.g1 @ r
        self.r_prev = r
        return self._set_point(self.x)

    def trace(self, f_mps2: np.ndarray, omega_radps: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Whole-trace form: the same numbers as N steps (the same update, in a loop), (N, 3) and (N, 4)."""
        r_all = self.inputs(f_mps2, omega_radps)
        n = r_all.shape[0]
        pos = np.empty((n, 3))
        q = np.empty((n, 4))
        for k in range(n):
            pos[k], q[k] = self.step(f_mps2[k], omega_radps[k])
        return pos, q


__all__ = ["ChannelDesign", "ChannelWeights", "OptimalParams", "OptimalWashout", "design", "design_channel"]
