"""The model-predictive washout (``mpc``): a quadratic program per step, the platform's limits as hard constraints.

At every sample the washout solves, by DAQP (a dual active-set solver for small dense QPs, warm-started from the
previous step's active set; the states eliminated, :mod:`washbench.cueing.condensed`),

    minimise    sum_{k=1..N} x_k' Q x_k dt_p  +  sum_{k=0..N-1} u_k' R u_k dt_p
    subject to  x_{k+1} = Phi x_k + Gamma u_k + Gamma_r r_k           (the linear model, held controls)
                |position|, |velocity| <= margin * limit, per axis     (nodes 1..N)
                |acceleration| <= margin * limit, per axis             (moves 0..N-1)
                |tilt rate| <= tilt-rate limit (pitch and roll)        (moves 0..N-1)
                |p| + |q| + |r| <= margin * rate limit                 (the 1-norm ball: inside the 2-norm one)
                |Delta omega|_1 <= margin * alpha_max * interval       (the first: over dt, from the current rate)
                velocity_N = 0                                         (optional: the plan ends at rest)

On a hexapod (``WashoutContext.platform`` a :class:`washbench.platform.hexapod.HexapodModel`) the position rows give
way to the legs: their lengths at nodes 1..N and their speeds on the first moves, linearised about the current pose
at every sample (:mod:`washbench.cueing.mpc_legs`), the QP then solved in whitened variables
(:class:`washbench.cueing.condensed.WhitenedQp`) so that its changing rows stay cheap.

with the state x of :mod:`washbench.cueing.motion_model` (perceived-error states of the otolith and canal models,
cockpit angles, platform position and velocity; the pitch and roll angles split into a tilt part, whose rate is
limited, and a rotational part), x_0 the washout's current state and r_k the aircraft input of this sample
returning over the horizon to its recent mean as e^{-gamma t} (``reference_decay_per_s``, ``reference_mean_s``), or,
with ``preview_s`` > 0 and the recording known, the aircraft's own future (:meth:`MpcWashout.trace`). The
horizon's intervals are ``prediction_step_s`` (coarser than the sample: see docs/optimal-mpc.md). The first move
u_0 is applied for one sample (exact discretisation at dt) and the set points are the resulting position and
attitude. Every solve's status is checked: a failed solve, or a first move that would leave the platform unable to stop
within its travel, is replaced by the last accepted plan continued (feasible: the platform's constraints do not
depend on the aircraft input) or, without one, by braking (counted: :meth:`MpcWashout.report`).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import Field, model_validator
from scipy import linalg

from washbench.cueing.algorithm import SetPoint, WashoutContext
from washbench.cueing.condensed import (
    DenseQp,
    WhitenedQp,
    horizon_problem,
    horizon_reference,
    preview_needs_recording,
    stage_limits,
)
from washbench.cueing.motion_model import CHANNELS, ChannelModel, channel_inputs, channel_model, discretise_zoh
from washbench.cueing.mpc_legs import LEG_RATE_MOVES, LegRows
from washbench.cueing.optimal import merge_channel_defaults
from washbench.errors import WashbenchError
from washbench.io import cost
from washbench.io.progress import duration_text
from washbench.io.yamlio import StrictModel
from washbench.numerics.rotations import quat_from_euler
from washbench.perception.vestibular import CanalParams, OtolithParams
from washbench.platform.hexapod import HexapodModel
from washbench.platform.kinematics import brake_speed

MAX_WORK = 10_000_000
"""The horizon's intervals (preview included) x solver.iter_limit at most this (the defaults: 20,000; a 500-step
horizon with 20,000 iterations)."""
MAX_HORIZON = 500
"""The horizon's intervals at most, ``preview_s`` included (``horizon_steps``' own limit): its QP takes about 2 GB
and five minutes of CPU to build and set up there (:func:`washbench.io.cost.mpc`, ``bench/cost_calibration.md``)."""
REMEDY = "fewer mpc.horizon_steps, a longer mpc.prediction_step_s or a shorter mpc.preview_s"
"""What makes the MPC's QP smaller (the messages of :mod:`washbench.io.cost`)."""
ESTIMATE_AFTER_STEPS = 20
"""The MPC times its first this-many steps and says how long a minute of flight will take when it is slow."""
SLOW_FACTOR = 10.0
"""... when it runs more than this many times slower than real time."""

Weight = Annotated[float, Field(ge=0.0, le=1e9, allow_inf_nan=False)]
PositiveWeight = Annotated[float, Field(gt=0.0, le=1e9, allow_inf_nan=False)]


class MpcWeights(StrictModel):
    """Weights of one channel's stage cost (SI units squared; fields a channel lacks are ignored)."""

    force: Weight = 1.0
    """perceived specific-force error (otolith), per (m/s^2)^2"""
    direct_force: Weight = 1.0
    """specific-force error at the head itself (before the otolith model), per (m/s^2)^2 (see docs/optimal-mpc.md)"""
    rate: Weight = 10.0
    """perceived angular-velocity error (canals), per (rad/s)^2"""
    tilt_angle: Weight = 0.1
    """tilt part of the pitch/roll angle (or the yaw angle), per rad^2"""
    rotation_angle: Weight = 5.0
    """rotational part of the pitch/roll angle, per rad^2 (washes the rotational cue out)"""
    position: Weight = 0.4
    """platform position, per m^2"""
    velocity: Weight = 0.4
    """platform velocity, per (m/s)^2"""
    acceleration: PositiveWeight = 0.05
    """platform acceleration (control), per (m/s^2)^2"""
    angular_rate: PositiveWeight = 0.5
    """cockpit angular rates (controls), per (rad/s)^2"""


class DaqpSettings(StrictModel):
    """DAQP's settings for the per-step QP (see DAQP's documentation)."""

    iter_limit: Annotated[int, Field(ge=1, le=100_000)] = 1000
    """active-set iterations per solve, at most 100,000 (and horizon_steps x iter_limit at most :data:`MAX_WORK`);
    a solve that reaches it falls back (counted)"""


class VestibularChoice(StrictModel):
    """The vestibular models in the cost (default: the paper's Eqs. 11-12, as the bench's perception)."""

    otolith: OtolithParams = OtolithParams()
    canals: CanalParams = CanalParams()


class MpcParams(StrictModel):
    """The ``mpc:`` section of the parameter file."""

    horizon_steps: Annotated[int, Field(ge=1, le=500)] = 20
    """N, the number of prediction intervals (with ``preview_s``, N = max(horizon_steps, preview_s /
    prediction_step_s), at most 500 intervals in all)"""
    prediction_step_s: Annotated[float, Field(gt=0.0, le=5.0, allow_inf_nan=False)] = 0.1
    """the prediction interval (s); at least the sample step"""
    reference_decay_per_s: Annotated[float, Field(ge=0.0, le=100.0, allow_inf_nan=False)] = 0.5
    """gamma: the aircraft input predicted to return from its last value to its recent mean as e^{-gamma t} over the
    horizon (0: held; the default 0.5 1/s: with the input held the plan must undo within the horizon any cue it
    gives, and heave cues came out with the wrong sign, see docs/optimal-mpc.md)"""
    reference_mean_s: Annotated[float, Field(gt=0.0, le=600.0, allow_inf_nan=False)] = 5.0
    """the time constant of that recent mean (s): a first-order low-pass of the aircraft's input, started at the first
    sample (a steady flight is predicted to stay as it is)"""
    preview_s: Annotated[float, Field(ge=0.0, le=20.0, allow_inf_nan=False)] = 0.0
    """how far ahead the aircraft's motion is known (s; the horizon is extended to cover it, at most 500 intervals:
    20 s needs prediction_step_s of at least 0.04 s): 0 none; > 0 needs the recording in advance (run, suite, cue),
    not a live stream"""
    limit_margin: Annotated[float, Field(gt=0.0, le=1.0)] = 0.95
    """the QP's limits are this fraction of the platform's"""
    tilt_rate_limit_degps: Annotated[float, Field(gt=0.0, le=1000.0)] | None = 3.0
    """hard limit on the tilt part's rate (deg/s, per axis); null: none"""
    terminal_rest: bool = True
    """the plan ends with the platform at rest (velocity 0 at node N)"""
    vestibular: VestibularChoice = VestibularChoice()
    pitch: MpcWeights = MpcWeights()
    roll: MpcWeights = MpcWeights()
    heave: MpcWeights = MpcWeights(position=4.0, velocity=1.0)
    yaw: MpcWeights = MpcWeights(tilt_angle=0.5)
    solver: DaqpSettings = DaqpSettings()
    fallback: Literal["brake"] = "brake"
    """what a failed solve does (brake: decelerate translation and rotation at the limits)"""

    @model_validator(mode="after")
    def _bounded_work(self) -> MpcParams:
        """The horizon's intervals, preview included, within :data:`MAX_HORIZON`, and the worst case of one step's
        solve, those intervals x iter_limit, within :data:`MAX_WORK`."""
        problem = horizon_problem(self.horizon_steps, self.preview_s, self.prediction_step_s,
                                  self.solver.iter_limit, MAX_HORIZON, MAX_WORK)  # fmt: skip
        if problem is not None:
            raise ValueError(problem)
        return self

    @model_validator(mode="before")
    @classmethod
    def _channel_defaults(cls, data: Any) -> Any:
        """A channel section given in part keeps that channel's defaults for the keys it does not give."""
        defaults = {ch: f.default.model_dump() for ch, f in cls.model_fields.items() if ch in CHANNELS}
        return merge_channel_defaults(data, defaults)


def split_angle(model: ChannelModel) -> ChannelModel:
    """Pitch/roll model with the angle split into tilt (``i_angle``) and rotational parts (a new last state).

    Controls become [a, tilt rate, rotational rate]; both angles act on the otolith alike and both rates on the
    canals. Channels without a tilt (heave, yaw) are returned unchanged.
    """
    if model.name not in ("pitch", "roll"):
        return model
    n, m = model.B.shape
    A = np.zeros((n + 1, n + 1))
    A[:n, :n] = model.A
    A[:n, n] = model.A[:n, model.i_angle]  # the rotational angle tilts the otolith input like the tilt angle
    B = np.zeros((n + 1, m + 1))
    B[:n, :m] = model.B
    B[:n, m] = model.B[:n, 1]  # canal input: the total rate
    B[model.i_angle, m] = 0.0
    B[n, m] = 1.0
    E = np.vstack([model.E, np.zeros((1, model.E.shape[1]))])
    grow = np.zeros((model.C_err.shape[0], 1))
    c_head = np.hstack([model.C_head, model.C_head[:, model.i_angle : model.i_angle + 1]])  # g (theta_t + theta_r)
    d_head = np.hstack([model.D_head, model.D_head[:, 1:2]])  # rate row: tilt + rotational rate
    return replace(model, A=A, B=B, E=E, C_err=np.hstack([model.C_err, grow]), C_head=c_head, D_head=d_head,
                   controls=(*model.controls, "rotation"))  # fmt: skip


@dataclass(frozen=True)
class StackedModel:
    """The four channels side by side (block-diagonal), with index maps into the stacked state and control."""

    A: np.ndarray
    B: np.ndarray
    E: np.ndarray
    Q: np.ndarray
    R: np.ndarray
    i_pos: np.ndarray  # (3,) x, y, z
    i_vel: np.ndarray  # (3,)
    i_tilt: np.ndarray  # (3,) roll, pitch, yaw angle states (the tilt part; yaw: its angle)
    i_rot: np.ndarray  # (2,) roll, pitch rotational angle states
    j_acc: np.ndarray  # (3,) controls a_x, a_y, a_z
    j_tilt: np.ndarray  # (2,) roll, pitch tilt rates
    j_rot: np.ndarray  # (3,) roll, pitch rotational rates, yaw rate
    C_dir: np.ndarray  # (3, n) head specific force (x, y, z rows, deviation from level) from the state ...
    D_dir: np.ndarray  # (3, m) ... and the controls
    W_dir: np.ndarray  # (3,) direct_force weights of the pitch, roll and heave channels


def stacked_model(params: MpcParams, gravity_mps2: float) -> StackedModel:
    """Build the stacked continuous model and its stage-cost matrices (per second)."""
    v = params.vestibular
    models = {ch: split_angle(channel_model(ch, v.otolith, v.canals, gravity_mps2)) for ch in CHANNELS}
    offs_x, offs_u, qs, rs = {}, {}, [], []
    ix = iu = 0
    for ch in CHANNELS:
        m = models[ch]
        w: MpcWeights = getattr(params, ch)
        offs_x[ch], offs_u[ch] = ix, iu
        n, k = m.A.shape[0], m.C_err.shape[0]
        we = np.array([w.force if i < m.force_inputs else w.rate for i in range(k)])
        q = m.C_err.T @ np.diag(we) @ m.C_err
        if m.i_angle >= 0:
            q[m.i_angle, m.i_angle] += w.tilt_angle
        if ch in ("pitch", "roll"):
            q[n - 1, n - 1] += w.rotation_angle
        if m.i_pos >= 0:
            q[m.i_pos, m.i_pos] += w.position
            q[m.i_vel, m.i_vel] += w.velocity
        qs.append(0.5 * (q + q.T))
        rs.append(np.diag([w.acceleration if c.startswith("a_") else w.angular_rate for c in m.controls]))
        ix += n
        iu += m.B.shape[1]
    A = linalg.block_diag(*[models[c].A for c in CHANNELS])
    B = linalg.block_diag(*[models[c].B for c in CHANNELS])
    E = linalg.block_diag(*[models[c].E for c in CHANNELS])
    mp, mr, mh, my = (models[c] for c in CHANNELS)
    ox, ou = offs_x, offs_u
    n_all, m_all = ix, iu
    c_dir = np.zeros((3, n_all))
    d_dir = np.zeros((3, m_all))
    for row, ch in enumerate(("pitch", "roll", "heave")):
        mm = models[ch]
        c_dir[row, ox[ch] : ox[ch] + mm.A.shape[0]] = mm.C_head[0]
        d_dir[row, ou[ch] : ou[ch] + mm.B.shape[1]] = mm.D_head[0]
    return StackedModel(
        A=A,
        B=B,
        E=E,
        Q=linalg.block_diag(*qs),
        R=linalg.block_diag(*rs),
        i_pos=np.array([ox["pitch"] + mp.i_pos, ox["roll"] + mr.i_pos, ox["heave"] + mh.i_pos]),
        i_vel=np.array([ox["pitch"] + mp.i_vel, ox["roll"] + mr.i_vel, ox["heave"] + mh.i_vel]),
        i_tilt=np.array([ox["roll"] + mr.i_angle, ox["pitch"] + mp.i_angle, ox["yaw"] + my.i_angle]),
        i_rot=np.array([ox["roll"] + mr.A.shape[0] - 1, ox["pitch"] + mp.A.shape[0] - 1]),
        j_acc=np.array([ou["pitch"], ou["roll"], ou["heave"]]),
        j_tilt=np.array([ou["roll"] + 1, ou["pitch"] + 1]),
        j_rot=np.array([ou["roll"] + 2, ou["pitch"] + 2, ou["yaw"]]),
        C_dir=c_dir,
        D_dir=d_dir,
        W_dir=np.array([params.pitch.direct_force, params.roll.direct_force, params.heave.direct_force]),
    )


def stacked_inputs(f_mps2: np.ndarray, omega_radps: np.ndarray, gravity_mps2: float) -> np.ndarray:
    """The stacked aircraft input r (6,): [f_x, omega_y | f_y, omega_x | f_z + g | omega_z]."""
    return np.concatenate([channel_inputs(c, f_mps2, omega_radps, gravity_mps2) for c in CHANNELS], axis=-1)


# sign patterns of the 1-norm ball's facets |p| + |q| + |r| <= w, as |s . omega| <= w (roll, pitch, yaw)
_FACETS = np.array([[1.0, 1.0, 1.0], [1.0, 1.0, -1.0], [1.0, -1.0, 1.0], [1.0, -1.0, -1.0]])


class MpcWashout:
    """The MPC washout per step (:class:`washbench.cueing.algorithm.WashoutAlgorithm`).

    State: the stacked model state ``x`` (perceived-error states, angles, position, velocity), the last applied
    controls ``u``, the input's recent mean ``r_mean`` and DAQP's workspace (warm start). Counters: :attr:`solves`,
    :attr:`fallbacks` (failed or rejected solves replaced by braking), :attr:`iterations` (DAQP iterations per step).
    """

    Params = MpcParams
    name = "mpc"

    whole_only = staticmethod(preview_needs_recording)  # with preview_s > 0: cued after the flight, by trace()

    def __init__(self, params: MpcParams | None, context: WashoutContext) -> None:
        self.params = p = params if params is not None else MpcParams()
        self.context = context
        self.dt = float(context.dt_s)
        self.g = float(context.gravity_mps2)
        if p.prediction_step_s < self.dt * (1.0 - 1e-9):
            raise ValueError(f"mpc: prediction_step_s {p.prediction_step_s} s is shorter than the sample {self.dt} s")
        self.model = sm = stacked_model(p, self.g)
        self.hexapod = context.platform if isinstance(context.platform, HexapodModel) else None
        lim = context.limits
        self.p_max, self.v_max, self.a_max, self.w_max, self.alpha_max = stage_limits(lim)
        self.n, self.m = sm.B.shape
        self.tp = p.prediction_step_s
        self.N = cost.horizon_intervals(p.horizon_steps, p.preview_s, self.tp)
        self._cost = cost.mpc("mpc", self.N, self.dt, hexapod=self.hexapod is not None, remedy=REMEDY)
        cost.check(self._cost, announce=False)  # its QP must fit before it is built
        self._announce()
        ab = np.hstack([sm.B, sm.E])
        self.phi_p, gam = discretise_zoh(sm.A, ab, self.tp)
        self.gam_p, self.gam_rp = gam[:, : self.m], gam[:, self.m :]
        self.phi_f, gam = discretise_zoh(sm.A, ab, self.dt)
        self.gam_f, self.gam_rf = gam[:, : self.m], gam[:, self.m :]
        self.rho = math.exp(-p.reference_decay_per_s * self.tp)
        self._decay = self.rho ** np.arange(self.N)
        self._mean_gain = -math.expm1(-self.dt / p.reference_mean_s)
        self._build_qp()
        if self.hexapod is None:
            self.qp: DenseQp | WhitenedQp = DenseQp(self.nz, self.A_qp, self._eq, p.solver.iter_limit)
        else:
            self._build_legs(self.hexapod)
        self.x = np.zeros(self.n)
        self.u = np.zeros(self.m)
        self.r_mean = np.zeros(6)
        self.solves = 0
        self.fallbacks = 0
        self.brakes = 0
        self._plan: np.ndarray | None = None
        self._plan_age = 0
        self.iterations: list[int] = []
        self._sat_tilt = False
        self._sat_rot = False
        self._tilt_rate = 0.0
        self._block: tuple[np.ndarray, np.ndarray] = (np.zeros(0), np.zeros(0, dtype=bool))
        self._timed_steps = 0
        self._timed_s = 0.0
        self._first_done = False
        self._future: tuple[np.ndarray, np.ndarray] | None = None
        self._k = 0

    # ---- the QP, condensed: z = [u_0, ..., u_{N-1}], the states eliminated (x_{k+1} = Phi x_k + Gamma u_k +
    # Gamma_r R_k); the parameters of a solve are w = [x_0 (n), R_0 .. R_{N-1} (6 each)]
    def _build_qp(self) -> None:
        sm, n, m, N, tp = self.model, self.n, self.m, self.N, self.tp
        p = self.params
        self.nz = nz = N * m
        nw = n + 6 * N
        # forward recursion of the states' dependence on z and w
        xu = np.zeros((n, nz))
        xw = np.zeros((n, nw))
        xw[:, :n] = np.eye(n)
        mdir = np.hstack([sm.D_dir, sm.C_dir])  # (3, m + n): head force deviation of stage k from [u_k, x_{k+1}]
        wdir = np.diag(sm.W_dir)
        block = linalg.block_diag(sm.R, sm.Q) + mdir.T @ wdir @ mdir
        sel = np.zeros((3, 6))
        sel[0, 0] = sel[1, 2] = sel[2, 4] = 1.0  # r = [f_x, omega_y | f_y, omega_x | f_z + g | omega_z]
        H = np.zeros((nz, nz))
        F = np.zeros((nz, nw))
        Xu, Xw = [], []
        for k in range(N):
            eu = np.zeros((m, nz))
            eu[:, k * m : (k + 1) * m] = np.eye(m)
            rk = np.zeros((6, nw))
            rk[:, n + 6 * k : n + 6 * (k + 1)] = np.eye(6)
            xu = self.phi_p @ xu + self.gam_p @ eu
            xw = self.phi_p @ xw + self.gam_rp @ rk
            Xu.append(xu)
            Xw.append(xw)
            gu = np.vstack([eu, xu])  # y_k = [u_k; x_{k+1}] = gu z + gw w
            gw = np.vstack([np.zeros((m, nw)), xw])
            H += gu.T @ block @ gu
            F += gu.T @ (block @ gw - mdir.T @ wdir @ sel @ rk)
        # the whole cost times 2 dt_p: 1/2 z' H z + (F w)' z
        self.H_qp = 2.0 * tp * 0.5 * (H + H.T)
        self.F_qp = 2.0 * tp * F
        # constraints: simple bounds on z, then rows [position, velocity (nodes 1..N), rate facets, rate changes]
        mg = p.limit_margin
        tilt = math.radians(p.tilt_rate_limit_degps) if p.tilt_rate_limit_degps is not None else np.inf
        hi_z = np.full(nz, np.inf)
        for k in range(N):
            hi_z[k * m + sm.j_acc] = mg * self.a_max
            hi_z[k * m + sm.j_tilt] = tilt
            hi_z[k * m + sm.j_rot] = mg * self.w_max
        pv = np.concatenate([sm.i_pos, sm.i_vel])
        A_state = np.vstack([Xu[k][pv] for k in range(N)])  # (6N, nz)
        self._state_w = np.vstack([Xw[k][pv] for k in range(N)])  # their dependence on w
        p_box = mg * self.p_max if self.hexapod is None else np.full(3, np.inf)  # a hexapod: its legs instead
        hi_state = np.tile(np.concatenate([p_box, mg * self.v_max]), N)
        rate = np.zeros((4 * N, nz))
        dacc = np.zeros((4 * N, nz))
        for k in range(N):
            for f, sgn in enumerate(_FACETS):
                row = 4 * k + f
                for ax in range(3):
                    cols = [k * m + sm.j_rot[ax]] + ([k * m + sm.j_tilt[ax]] if ax < 2 else [])
                    for c in cols:
                        rate[row, c] = sgn[ax]
                        dacc[row, c] = sgn[ax]
                        if k > 0:
                            dacc[row, c - m] = -sgn[ax]
        self.A_qp = np.vstack([A_state, rate, dacc])
        w = mg * self.w_max
        dw = mg * self.alpha_max * tp
        self._hi = np.concatenate([hi_z, hi_state, np.full(4 * N, w), np.full(4 * N, dw)])
        self._lo = -self._hi
        self._eq = np.zeros(self.A_qp.shape[0], dtype=bool)
        n_s = 6 * N
        self._rows_state = slice(nz, nz + n_s)
        if p.terminal_rest:  # v_N = 0
            self._eq[n_s - 3 : n_s] = True
            self._lo[nz + n_s - 3 : nz + n_s] = 0.0
            self._hi[nz + n_s - 3 : nz + n_s] = 0.0
        self._rows_dacc0 = slice(nz + n_s + 4 * N, nz + n_s + 4 * N + 4)
        self._dw0 = mg * self.alpha_max * self.dt
        self._tilt_max = tilt
        self._Xu, self._Xw = Xu, Xw  # (for the hexapod's rows)

    def _build_legs(self, hexapod: HexapodModel) -> None:
        """On a hexapod: the QP in whitened variables (:class:`WhitenedQp`) with the legs' rows (:class:`LegRows`:
        their lengths at nodes 1..N, their speeds on the first moves), rebuilt about the current pose at every
        sample."""
        sm, n, m, N, nz = self.model, self.n, self.m, self.N, self.nz
        nw = n + 6 * N
        sel = np.zeros((6, n))  # the pose [p; eta] of a state: position, and roll and pitch tilt + rotational
        sel[[0, 1, 2], sm.i_pos] = 1.0
        sel[[3, 4, 5], sm.i_tilt] = 1.0
        sel[[3, 4], sm.i_rot] = 1.0
        vel = np.zeros((3, n))
        vel[[0, 1, 2], sm.i_vel] = 1.0
        rates = np.zeros((3, m))  # the angle rates eta_dot of a move: tilt + rotational (roll, pitch), yaw
        rates[[0, 1, 2], sm.j_rot] = 1.0
        rates[[0, 1], sm.j_tilt] = 1.0
        self._pose_sel, self._rate_sel = sel, rates
        x0_w = np.hstack([np.eye(n), np.zeros((n, nw - n))])
        pose_z = np.stack([sel @ self._Xu[k] for k in range(N)])
        pose_w = np.stack([sel @ self._Xw[k] for k in range(N)])
        k_rate = min(LEG_RATE_MOVES, N)
        rate_z = np.zeros((k_rate, 2, 6, nz))
        rate_w = np.zeros((k_rate, 2, 6, nw))
        for k in range(k_rate):
            rate_z[k, :, 3:, k * m : (k + 1) * m] = rates
            rate_z[k, 0, :3] = vel @ self._Xu[k - 1] if k > 0 else 0.0
            rate_w[k, 0, :3] = vel @ (self._Xw[k - 1] if k > 0 else x0_w)
            rate_z[k, 1, :3] = vel @ self._Xu[k]
            rate_w[k, 1, :3] = vel @ self._Xw[k]
        margin = self.params.limit_margin
        bounded = np.isfinite(self._lo) | np.isfinite(self._hi)  # (the box's positions are not: the legs instead)
        self.qp = qp = WhitenedQp(self.H_qp, self.A_qp, self._eq, 6 * N + 12 * k_rate, self.params.solver.iter_limit,
                                  bounded)  # fmt: skip
        self.legs = LegRows(hexapod, margin, qp.whiten(pose_z), pose_w, qp.whiten(rate_z), rate_w)

    def _total_rates(self, u: np.ndarray) -> np.ndarray:
        sm = self.model
        w = u[sm.j_rot].copy()
        w[:2] += u[sm.j_tilt]
        return w

    # ---- the washout
    def _set_point(self) -> SetPoint:
        sm, x = self.model, self.x
        ang = x[sm.i_tilt].copy()
        ang[:2] += x[sm.i_rot]
        return x[sm.i_pos].copy(), np.array(quat_from_euler(float(ang[0]), float(ang[1]), float(ang[2])))

    def start(self, f_mps2: np.ndarray, omega_radps: np.ndarray) -> SetPoint:
        """Start at the steady state of the first sample (of rest with ``filter_start="rest"``): centred and still,
        tilted by the roll and pitch that minimise the stage cost for that input held (:meth:`_steady_state`), the
        error models at their steady state; the recent mean of the input starts at it."""
        if self.context.filter_start == "rest":
            r0 = stacked_inputs(np.array([0.0, 0.0, -self.g]), np.zeros(3), self.g)
        else:
            r0 = stacked_inputs(np.asarray(f_mps2, float), np.asarray(omega_radps, float), self.g)
        self.x = self._steady_state(r0)
        self.u = np.zeros(self.m)
        self.r_mean = r0.copy()
        self._plan, self._plan_age = None, 0
        self._k = 0
        return self._set_point()

    def _steady_state(self, r0: np.ndarray) -> np.ndarray:
        """The still equilibrium for the input ``r0`` held with the least stage cost: the tilt angles tau (roll,
        pitch) minimise (x' Q x + |C_dir x - r_f|^2_Wd) over x(tau) = the error models' steady state with the
        platform centred, still and tilted by tau (a 2 x 2 least-squares problem)."""
        sm = self.model
        xa = self._steady_error(r0)
        cols = []
        for i in sm.i_tilt[:2]:
            unit = np.zeros(self.n)
            unit[i] = 1.0
            cols.append(self._steady_error(np.zeros(6), unit) + unit)
        xt = np.column_stack(cols)
        sel = np.zeros((3, 6))
        sel[0, 0] = sel[1, 2] = sel[2, 4] = 1.0
        wd = np.diag(sm.W_dir)
        m = sm.Q + sm.C_dir.T @ wd @ sm.C_dir
        lhs = xt.T @ m @ xt
        rhs = xt.T @ (sm.Q @ xa + sm.C_dir.T @ wd @ (sm.C_dir @ xa - sel @ r0))
        return xa + xt @ np.linalg.solve(lhs, -rhs)

    def _steady_error(self, r0: np.ndarray, platform: np.ndarray | None = None) -> np.ndarray:
        """The error models' steady state for the input ``r0`` held with the platform still at ``platform`` (its
        angle and position entries of a state; None: level and centred); the platform's entries are left 0."""
        sm = self.model
        x = np.zeros(self.n)
        plat = np.zeros(self.n, dtype=bool)
        plat[np.concatenate([sm.i_pos, sm.i_vel, sm.i_tilt, sm.i_rot])] = True
        vest = ~plat
        a = sm.A[np.ix_(vest, vest)]
        drive = sm.E @ r0 + (sm.A @ platform if platform is not None else 0.0)
        x[vest] = -np.linalg.solve(a, drive[vest])
        return x

    def _safe(self, u0: np.ndarray) -> bool:
        """Whether the first move keeps the platform within its limits at the sample step and able to stop."""
        sm = self.model
        if not np.all(np.isfinite(u0)):
            return False
        x1 = self.phi_f @ self.x + self.gam_f @ u0 + self._r_term
        p1 = x1[sm.i_pos]
        v1 = x1[sm.i_vel]
        if np.any(np.abs(v1) > self.v_max) or np.any(np.abs(u0[sm.j_acc]) > self.a_max * (1 + 1e-9)):
            return False
        if self.hexapod is not None:  # its legs (the hexapod's own tracker brakes each leg at its stroke)
            if not self._legs_safe(x1, u0):
                return False
        else:
            if np.any(np.abs(p1) > self.p_max):
                return False
            for j in range(3):
                room = self.p_max[j] - p1[j] if v1[j] > 0 else self.p_max[j] + p1[j]
                if abs(v1[j]) > brake_speed(room, self.a_max[j], self.dt) + 1e-9:
                    return False
        w = self._total_rates(u0)
        dw = np.linalg.norm(w - self._total_rates(self.u))
        return bool(np.linalg.norm(w) <= self.w_max and dw <= self.alpha_max * self.dt)

    def _legs_safe(self, x1: np.ndarray, u0: np.ndarray) -> bool:
        """On a hexapod: whether every leg of the pose after the first move is within its stroke (its length, not
        linearised) and its speed (to first order: G [v; eta_dot]) within its limit."""
        hx = self.hexapod
        legs, g = self.legs.at(self._pose_sel @ x1)
        speed = g @ np.concatenate([x1[self.model.i_vel], self._rate_sel @ u0])
        lo, hi = hx.leg_length_m.min, hx.leg_length_m.max
        return bool(np.all((legs >= lo) & (legs <= hi)) and np.all(np.abs(speed) <= hx.leg_velocity_limit_mps))

    def _fallback_move(self) -> np.ndarray:
        """The move of a failed step: the last accepted plan, continued (feasible for the platform: its limits do not
        depend on the aircraft input), at rest after its end; braking (counted in :attr:`brakes`) if there is none or
        it is not safe; holding still if even braking is not (it always is, short of rounding)."""
        if self._plan is not None:
            j = int(self._plan_age * self.dt / self.tp + 1e-9)
            move = self._plan[j].copy() if j < self.N else np.zeros(self.m)
            if (self.params.terminal_rest or j < self.N) and self._safe(move):
                return move
        self.brakes += 1
        move = self._brake()
        return move if self._safe(move) else np.zeros(self.m)

    def _brake(self) -> np.ndarray:
        """Braking move: each axis decelerates towards rest at its acceleration limit; the rates likewise."""
        sm = self.model
        u = np.zeros(self.m)
        v = self.x[sm.i_vel]
        u[sm.j_acc] = -np.clip(v / self.dt, -self.a_max, self.a_max)
        rates = self.u.copy()
        for idx in (sm.j_tilt, sm.j_rot):
            w = rates[idx]
            nw = np.linalg.norm(w)
            step = self.alpha_max * self.dt / math.sqrt(5.0)  # the five rate controls share the limit
            u[idx] = 0.0 if nw <= step else w * (1.0 - step / nw)
        return u

    def _references(self, r: np.ndarray) -> np.ndarray:
        """The aircraft input over the horizon's intervals (N, 6) (:func:`washbench.cueing.condensed.horizon_reference`:
        previewed as far as ``preview_s`` reaches, then returning to the recent mean as rho^k)."""
        p = self.params
        return horizon_reference(r, self.r_mean, self._decay, self._future, self._k, p.preview_s, self.tp, self.dt)

    def plan(self, r: np.ndarray) -> tuple[bool, np.ndarray]:
        """Solve the QP from the current state for the stacked aircraft input ``r`` (6,).

        Returns (solved, controls (N, m)); ``solved`` is False unless DAQP reports an optimal solution with a finite
        result (its first move is still checked by :meth:`_safe`).
        """
        w = np.concatenate([self.x, self._references(r).ravel()])
        lo, hi = self._lo.copy(), self._hi.copy()
        off = self._state_w @ w
        lo[self._rows_state] -= off
        hi[self._rows_state] -= off
        s = _FACETS @ self._total_rates(self.u)
        lo[self._rows_dacc0] = s - self._dw0
        hi[self._rows_dacc0] = s + self._dw0
        if isinstance(self.qp, WhitenedQp):  # a hexapod: its legs, linearised about the current pose
            leg_lo, leg_hi = self.legs.rows(self._pose_sel @ self.x, w, self.qp.var_rows)
            ok, z, it = self.qp.solve(self.F_qp @ w, lo, hi, leg_lo, leg_hi)
        else:
            ok, z, it = self.qp.solve(self.H_qp, self.F_qp @ w, lo, hi, h_changed=False)
        self.solves += 1
        self.iterations.append(it)
        if not ok:
            return False, np.zeros((self.N, self.m))
        return True, z.reshape(self.N, self.m)

    def step(self, f_mps2: np.ndarray, omega_radps: np.ndarray) -> SetPoint:
        """Solve the QP for this sample, apply its first move for one sample, return the set point."""
        if self.params.preview_s > 0.0 and self._future is None:
            raise WashbenchError("washout mpc: preview_s > 0 needs the recording in advance (run, suite, cue), not a "
                                 "live stream; set mpc.preview_s: 0")  # fmt: skip
        return self._timed_step(f_mps2, omega_radps)

    def _timed_step(self, f_mps2: np.ndarray, omega_radps: np.ndarray) -> SetPoint:
        """:meth:`_step`, the :data:`ESTIMATE_AFTER_STEPS` after the first timed (:meth:`_estimate`), by :meth:`step`
        and :meth:`trace` alike. The first is not: the solver sets itself up there (DAQP factorises the QP: 200 s of
        a 500-interval horizon's first sample, then 0.12 s a sample), which is the building's, not a minute of
        flight's."""
        if not self._first_done:
            self._first_done = True
            return self._step(f_mps2, omega_radps)
        if self._timed_steps < ESTIMATE_AFTER_STEPS:
            t0 = time.perf_counter()
            out = self._step(f_mps2, omega_radps)
            self._timed_s += time.perf_counter() - t0
            self._timed_steps += 1
            if self._timed_steps == ESTIMATE_AFTER_STEPS:
                self._estimate()
            return out
        return self._step(f_mps2, omega_radps)

    def _announce(self, samples: int | None = None) -> None:
        """Before the work, on stderr when it is long (:func:`washbench.io.cost.announce_mpc`): building the QP and a
        minute of flight (``samples`` None: when it is made), or the ``samples`` of a recording (:meth:`trace`)."""
        cost.announce_mpc(self._cost, "mpc", self.N, self.dt, samples, SLOW_FACTOR, self.hexapod is not None)

    def _estimate(self) -> None:
        """Say on stderr how long a minute of flight takes, when the MPC runs far slower than real time (timed on its
        first steps; only a message: the set points never depend on time)."""
        per_step = self._timed_s / self._timed_steps
        if per_step <= SLOW_FACTOR * self.dt:
            return
        minute = per_step * 60.0 / self.dt
        cost.note(f"washout mpc: {per_step:.3g} s per sample (timed on {self._timed_steps} after the first): a "
                  f"minute of flight takes about {duration_text(minute)}; fewer mpc.horizon_steps or "
                  "mpc.solver.iter_limit make it faster")  # fmt: skip

    def _step(self, f_mps2: np.ndarray, omega_radps: np.ndarray) -> SetPoint:
        r = stacked_inputs(f_mps2, omega_radps, self.g)
        if not np.all(np.isfinite(r)):
            raise ValueError("mpc: non-finite input")
        self.r_mean += self._mean_gain * (r - self.r_mean)
        ok, plan = self.plan(r)
        self._r_term = self.gam_rf @ r
        if ok and self._safe(plan[0]):
            move = plan[0].copy()
            self._plan, self._plan_age = plan, 0
        else:
            self.fallbacks += 1
            move = self._fallback_move()
        self._plan_age += 1
        self._tilt_rate = float(np.max(np.abs(move[self.model.j_tilt])))  # as the limit measures it: per axis
        self._sat_tilt = bool(self._tilt_rate >= 0.999 * self._tilt_max)
        self._sat_rot = bool(np.sum(np.abs(self._total_rates(move))) >= 0.999 * self.params.limit_margin * self.w_max)
        self.u = move
        self.x = self.phi_f @ self.x + self.gam_f @ move + self._r_term
        self._k += 1
        return self._set_point()

    def trace(self, f_mps2: np.ndarray, omega_radps: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The set points of the whole recording (after :meth:`start`); with ``preview_s`` > 0 each sample's plan
        sees the recording ``preview_s`` ahead. Without preview the same numbers as stepping."""
        f = np.asarray(f_mps2, float)
        w = np.asarray(omega_radps, float)
        pos = np.empty((len(f), 3))
        q = np.empty((len(f), 4))
        rate, at = np.full(len(f), math.nan), np.zeros(len(f), dtype=bool)
        self._block = (rate, at)
        self._future = stacked_inputs(f, w, self.g)
        self._announce(len(f))
        try:
            for i in range(len(f)):
                pos[i], q[i] = self._timed_step(f[i], w[i])
                rate[i], at[i] = self._tilt_rate, self._sat_tilt
        finally:
            self._future = None
        return pos, q

    def flags(self) -> tuple[bool, bool]:
        """(tilt-rate limit reached, rotational-rate limit reached) on the last step."""
        return self._sat_tilt, self._sat_rot

    def tilt_rate(self) -> float:
        """The tilt rate commanded on the last step, rad/s: the larger of the roll and pitch tilt parts' rates (the
        QP limits each to ``tilt_rate_limit_degps``); its flag (:meth:`flags`) is set at 0.999 of that limit."""
        return self._tilt_rate

    def block_tilt(self) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`tilt_rate` and the tilt-rate flag after each sample of the last :meth:`trace` (rad/s (M,), bool
        (M,))."""
        return self._block

    def report(self) -> dict[str, float]:
        """Solver statistics so far: solves, fallbacks (failed or unsafe solves), of which brakes (no usable previous
        plan: braking), iterations (DAQP's active-set iterations: median, max)."""
        it = np.array(self.iterations) if self.iterations else np.zeros(1)
        return {
            "solves": float(self.solves),
            "fallbacks": float(self.fallbacks),
            "brakes": float(self.brakes),
            "iterations_median": float(np.median(it)),
            "iterations_max": float(np.max(it)),
        }


__all__ = ["DaqpSettings", "MpcParams", "MpcWashout", "MpcWeights", "StackedModel", "stacked_model"]
