"""The model-predictive washout over the whole Atlas (``mpc-unrestricted``): the stage and the sphere's unlimited
rotation in one prediction, re-linearised about the cockpit's attitude at every sample.

At every sample, with the cockpit at attitude ``R0`` (body to inertial) and ``g_B0 = R0' [0, 0, g]`` gravity in its
body axes, the simulator pilot's specific force for a stage acceleration ``a`` (inertial, m/s^2) and a small further
rotation ``dtheta`` (body axes, rad) is, to first order,

    f_B  =  R0' a  -  g_B0  +  G dtheta,        G = -[g_B0]x                  (f = R' (a - g_I), R = R0 (I + [dtheta]x))

and ``d(dtheta)/dt = omega`` (the sphere's body rate, rad/s). The washout solves, by DAQP (a dual active-set solver
for small dense QPs, warm-started: :class:`washbench.cueing.condensed.DenseQp`), over N intervals of ``tp``

    minimise  kappa F(z)  +  sum_k tp ( |e_oto,k|^2_Wo + |e_f,k|^2_Wd + |e_can,k|^2_Wc + |p_k|^2_Wp + |v_k|^2_Wv
                                         + r_a |a_k|^2 + r_w |omega_k|^2 )
    subject to  |a| <= margin a_max per inertial axis, |p|, |v| likewise (nodes 1..N), v_N = 0 (optional),
                |omega|_1 <= margin rate limit (inside the Atlas's 2-norm ball), and its change per move
                (from the current rate over one sample for the first move) within margin alpha_max,

where ``e_oto`` and ``e_can`` are the perceived errors (the paper's otolith and canal models, Eqs. 11-12, driven by
simulator minus aircraft head signals in body axes), ``e_f`` the specific-force error at the head itself, and
``F(z)`` the ranking's felt error predicted over the horizon (:mod:`washbench.cueing.felt_qp`: at the end of each
move, the perceived error beyond the perception thresholds and its false part against the aircraft pilot's own
perceived motion, in threshold-seconds, and the jolt of the first move; slack variables represent it exactly). The
quadratic terms are small (0.1 per threshold squared): they make the plan unique and bring the cockpit back to
level and the stage to its centre where the felt error is indifferent (below the thresholds). The aircraft's
specific force over the horizon returns from its last value to its recent mean as ``e^{-gamma t}``, its angular
velocity likewise with ``gamma_w``, or, with ``preview_s`` > 0 and the recording known (``run``, ``suite``, ``cue``:
:meth:`MpcUnrestrictedWashout.trace`), the aircraft's own future is used. Decisions are held over blocks of
intervals (move blocking). There is no attitude cost and no tilt-rate limit: the sphere may turn without limit, a
rotation is paid for by what the canals perceive of it beyond their threshold and by the force its tilt adds. The
first move is applied for one sample: the stage integrates ``a`` as the platform does (semi-implicit Euler, so the
head feels ``a`` in the same sample), the attitude ``q <- q exp(omega dt / 2)``, and the error models are driven by
the head signals of that motion. See docs/optimal-mpc.md ("mpc-unrestricted") for the derivation, the references
and the choices.
"""

from __future__ import annotations

import math
from typing import Annotated, Any

import numpy as np
from pydantic import Field, model_validator

from washbench.cueing.algorithm import SetPoint, WashoutContext
from washbench.cueing.condensed import (
    DenseQp,
    blocking_matrix,
    default_blocks,
    horizon_problem,
    horizon_reference,
    preview_needs_recording,
    siso_prediction,
    siso_state_space,
    stage_limits,
)
from washbench.cueing.felt_qp import INF, FeltSlacks
from washbench.cueing.motion_model import discretise_zoh
from washbench.cueing.mpc import MAX_WORK, SLOW_FACTOR, VestibularChoice
from washbench.errors import WashbenchError
from washbench.io import cost
from washbench.io.yamlio import StrictModel
from washbench.numerics.rotations import quat_from_euler
from washbench.perception.thresholds import ZACHARIAS, Thresholds
from washbench.perception.vestibular import canal_tf, otolith_tf
from washbench.platform.kinematics import brake_speed

MAX_HORIZON = 200
"""The horizon's intervals at most, ``preview_s`` included (``horizon_steps``' own limit)."""
REMEDY = ("fewer mpc-unrestricted.horizon_steps, a longer mpc-unrestricted.prediction_step_s or a shorter "
          "mpc-unrestricted.preview_s")  # fmt: skip

Weight = Annotated[float, Field(ge=0.0, le=1e9, allow_inf_nan=False)]
PositiveWeight = Annotated[float, Field(gt=0.0, le=1e9, allow_inf_nan=False)]


class AxisWeights(StrictModel):
    """One weight per axis (x, y, z: body axes for perceived errors and rates, inertial for the stage)."""

    x: Weight
    y: Weight
    z: Weight

    @property
    def xyz(self) -> tuple[float, float, float]:
        """The three values in axis order."""
        return (self.x, self.y, self.z)


def _axes(x: float, y: float, z: float) -> AxisWeights:
    return AxisWeights(x=x, y=y, z=z)


QUADRATIC_PER_THRESHOLD = 0.1
"""rho: the quadratic terms' weight per threshold squared (chosen; docs/optimal-mpc.md shows its effect)"""
_QUADRATIC = tuple(QUADRATIC_PER_THRESHOLD / u**2 for u in (
    ZACHARIAS.f_x_mps2, ZACHARIAS.f_y_mps2, ZACHARIAS.f_z_mps2, *(math.radians(d) for d in (
        ZACHARIAS.omega_x_degps, ZACHARIAS.omega_y_degps, ZACHARIAS.omega_z_degps))))  # fmt: skip


# sign patterns of the 1-norm ball's facets |p| + |q| + |r| <= w, as |s . omega| <= w
_FACETS = np.array([[1.0, 1.0, 1.0], [1.0, 1.0, -1.0], [1.0, -1.0, 1.0], [1.0, -1.0, -1.0]])


class DaqpSettings(StrictModel):
    """DAQP's settings for the per-step QP."""

    iter_limit: Annotated[int, Field(ge=1, le=100_000)] = 1000
    """active-set iterations per solve at most (a solve that reaches it falls back, counted)"""


class MpcUnrestrictedParams(StrictModel):
    """The ``mpc-unrestricted:`` section of the parameter file (SI; axis triples are x, y, z)."""

    horizon_steps: Annotated[int, Field(ge=1, le=200)] = 20
    """N, prediction intervals (extended to cover ``preview_s``: at most 200 intervals in all)"""
    prediction_step_s: Annotated[float, Field(gt=0.0, le=5.0, allow_inf_nan=False)] = 0.1
    """the prediction interval tp (s); at least the sample step"""
    preview_s: Annotated[float, Field(ge=0.0, le=20.0, allow_inf_nan=False)] = 0.0
    """how far ahead the aircraft's motion is known (s; 20 s needs prediction_step_s of at least 0.1 s, the horizon
    being at most 200 intervals): 0 none; > 0 needs the recording in advance"""
    reference_decay_per_s: Annotated[float, Field(ge=0.0, le=100.0, allow_inf_nan=False)] = 0.5
    """gamma: beyond what is previewed, the aircraft's specific force is predicted to return from the last known value
    to its recent mean as e^{-gamma t} (0: held)"""
    rate_decay_per_s: Annotated[float, Field(ge=0.0, le=100.0, allow_inf_nan=False)] = 4.0
    """gamma_w: the same for the aircraft's angular velocity (chosen faster: a rate is predicted to fade within about
    0.25 s, so a tilt that following it would add is not overrated)"""
    reference_mean_s: Annotated[float, Field(gt=0.0, le=600.0, allow_inf_nan=False)] = 5.0
    """the time constant of those recent means (s): a first-order low-pass of the aircraft's input, started at the
    first sample, so a steady flight is predicted to stay as it is"""
    limit_margin: Annotated[float, Field(gt=0.0, le=1.0)] = 0.95
    """the QP's limits are this fraction of the platform's"""
    terminal_rest: bool = True
    """the plan ends with the stage at rest (velocity 0 at node N)"""
    vestibular: VestibularChoice = VestibularChoice()
    force: AxisWeights = _axes(*_QUADRATIC[:3])
    """quadratic weights of the perceived specific-force error (otolith), body x, y, z, per (m/s^2)^2 (default
    0.1 / T^2 of the Zacharias thresholds: 0.1 per threshold squared)"""
    direct_force: AxisWeights = _axes(*_QUADRATIC[:3])
    """quadratic weights of the specific-force error at the head (before the otolith), per (m/s^2)^2"""
    rate: AxisWeights = _axes(*_QUADRATIC[3:])
    """quadratic weights of the perceived angular-velocity error (canals), body roll, pitch, yaw, per (rad/s)^2
    (default 0.1 / T^2)"""
    position: AxisWeights = _axes(0.1, 0.1, 0.5)
    """quadratic weights of the stage's position, inertial north, east, down, per m^2"""
    velocity: AxisWeights = _axes(0.1, 0.1, 0.125)
    """quadratic weights of the stage's velocity, per (m/s)^2"""
    acceleration: PositiveWeight = 0.05
    """stage acceleration (control), per (m/s^2)^2"""
    angular_rate: PositiveWeight = 0.05
    """sphere body rate (control), per (rad/s)^2"""
    relinearise_deg: Annotated[float, Field(ge=0.0, le=10.0, allow_inf_nan=False)] = 2.0
    """the model is linearised again when the cockpit has turned more than this since the last linearisation (deg;
    0: every sample); in between the turn so far enters the prediction as an offset (first order: an error of at
    most g (1 - cos x) ~ 0.006 m/s^2 at 2 deg)"""
    felt_weight: Weight = 1.0
    """kappa: the weight of the felt error's prediction in the cost, per threshold-second (0: the quadratic terms
    alone, a QP without slacks)"""
    false_weight: Weight = 1.0
    """lambda: the false part counted again (the ranking's: washbench.analysis.felt.FALSE_WEIGHT)"""
    jolt_time_s: Weight = 1.0
    """tau_j (s): a jolt counts as a felt error held this long (the ranking's: JOLT_TIME_S)"""
    jerk_deadband_mps3: Weight = 50.0
    """J_T (m/s^3): jerk the stage may add at the head beyond the aircraft's without cost (the ranking's:
    JERK_DEADBAND_MPS3)"""
    thresholds: Thresholds = ZACHARIAS
    """the DOFs' perception thresholds (Zacharias 1978 by default, as the ranking's): the felt error's units and
    dead bands"""
    slack_regularisation: PositiveWeight = 1e-3
    """eps: the slacks' quadratic cost, per (threshold units)^2 or (m/s^2)^2 for a jolt: keeps the Hessian
    positive definite for the dual active-set solver (chosen small against the slacks' linear costs, 0.1-0.5 per
    threshold unit: 10 thresholds beyond the dead band cost 2-10 % more)"""
    solver: DaqpSettings = DaqpSettings()

    @model_validator(mode="after")
    def _bounded_horizon(self) -> MpcUnrestrictedParams:
        """The horizon's intervals, preview included, within :data:`MAX_HORIZON`; those intervals x iter_limit
        within :data:`washbench.cueing.mpc.MAX_WORK`."""
        problem = horizon_problem(self.horizon_steps, self.preview_s, self.prediction_step_s,
                                  self.solver.iter_limit, MAX_HORIZON, MAX_WORK)  # fmt: skip
        if problem is not None:
            raise ValueError(problem)
        return self

    @model_validator(mode="before")
    @classmethod
    def _axis_defaults(cls, data: Any) -> Any:
        """An axis triple given in part (``rate: {z: 2}``, ``--set mpc-unrestricted.rate.z=2``) keeps the default
        of the axes it does not give."""
        if not isinstance(data, dict):
            return data
        out = dict(data)
        for name, field in cls.model_fields.items():
            if isinstance(field.default, AxisWeights) and isinstance(out.get(name), dict):
                out[name] = {**field.default.model_dump(), **out[name]}
        return out


def _norm(v: np.ndarray) -> float:
    """Euclidean norm of a short vector (without numpy.linalg's overhead)."""
    return math.sqrt(float(v @ v))


def _skew(v: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def quat_matrix(q: np.ndarray) -> np.ndarray:
    """Rotation matrix (body to inertial) of a unit quaternion, scalar first."""
    w, x, y, z = q
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])  # fmt: skip


def quat_step(q: np.ndarray, omega_radps: np.ndarray, dt_s: float) -> np.ndarray:
    """``q exp(omega dt / 2)``: the attitude after turning at body rate ``omega`` for ``dt`` (exact), normalised."""
    th = float(_norm(omega_radps)) * dt_s
    if th < 1e-12:
        d = np.array([1.0, *(0.5 * dt_s * omega_radps)])
    else:
        ax = omega_radps / _norm(omega_radps)
        d = np.array([math.cos(0.5 * th), *(math.sin(0.5 * th) * ax)])
    out = quat_mul(q, d)
    return out / _norm(out)


def quat_mul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton product ``a b`` (scalar first)."""
    w0, x0, y0, z0 = a
    w1, x1, y1, z1 = b
    return np.array([
        w0 * w1 - x0 * x1 - y0 * y1 - z0 * z1,
        w0 * x1 + x0 * w1 + y0 * z1 - z0 * y1,
        w0 * y1 - x0 * z1 + y0 * w1 + z0 * x1,
        w0 * z1 + x0 * y1 - y0 * x1 + z0 * w1,
    ])  # fmt: skip


def quat_conj(q: np.ndarray) -> np.ndarray:
    """The conjugate (inverse of a unit quaternion)."""
    return np.array([q[0], -q[1], -q[2], -q[3]])


def rotation_vector(q: np.ndarray) -> np.ndarray:
    """The rotation vector (rad) of a unit quaternion, the shorter way round."""
    w, v = q[0], q[1:]
    if w < 0.0:
        w, v = -w, -v
    n = float(_norm(v))
    if n < 1e-12:
        return 2.0 * v
    return (2.0 * math.atan2(n, w) / n) * v


def tilt_matched(f_mps2: np.ndarray) -> np.ndarray:
    """The level-heading attitude (yaw 0) whose gravity gives the direction of ``f`` (body axes): roll
    ``atan2(-f_y, -f_z)``, pitch ``asin(f_x / |f|)``; level when ``|f|`` is below 1 m/s^2."""
    n = float(_norm(f_mps2))
    if n < 1.0:
        return np.array([1.0, 0.0, 0.0, 0.0])
    phi = math.atan2(-f_mps2[1], -f_mps2[2])
    theta = math.asin(max(-1.0, min(1.0, f_mps2[0] / n)))
    return np.array(quat_from_euler(phi, theta, 0.0))


class MpcUnrestrictedWashout:
    """``mpc-unrestricted`` per step (:class:`washbench.cueing.algorithm.WashoutAlgorithm`), see the module docstring.

    State: attitude ``q`` (body to inertial, scalar first), stage position ``p`` and velocity ``v`` (inertial, from
    the centre), the applied rate ``w`` and acceleration, the otolith (2, 3) and canal (3, 3) error-model states per
    body axis, and the aircraft pilot's own otolith and canal states (for the felt error's false part). Counters
    (:meth:`report`): solves, fallbacks (failed or unsafe solves: braking), iterations, relinearisations.
    """

    Params = MpcUnrestrictedParams
    name = "mpc-unrestricted"

    whole_only = staticmethod(preview_needs_recording)  # with preview_s > 0: cued after the flight, by trace()

    def __init__(self, params: MpcUnrestrictedParams | None, context: WashoutContext) -> None:
        self.params = p = params if params is not None else MpcUnrestrictedParams()
        self.context = context
        self.dt = float(context.dt_s)
        self.g = float(context.gravity_mps2)
        if p.prediction_step_s < self.dt * (1.0 - 1e-9):
            raise ValueError(f"mpc-unrestricted: prediction_step_s {p.prediction_step_s} s is shorter than the "
                             f"sample {self.dt} s")  # fmt: skip
        lim = context.limits
        mg = p.limit_margin
        self.p_max, self.v_max, self.a_max, self.w_max, self.alpha_max = stage_limits(lim)
        self.tp = tp = p.prediction_step_s
        self.N = N = cost.horizon_intervals(p.horizon_steps, p.preview_s, tp)
        self._cost = cost.mpc("mpc-unrestricted", N, self.dt, remedy=REMEDY)
        cost.check(self._cost, announce=False)  # its QP must fit before it is built
        cost.announce_mpc(self._cost, "mpc-unrestricted", N, self.dt, None, SLOW_FACTOR)
        self.blocks = default_blocks(N)
        Bk = blocking_matrix(self.blocks)
        self.M = M = len(self.blocks)
        v = p.vestibular
        oto = siso_prediction(*otolith_tf(v.otolith), tp, N)
        can = siso_prediction(*canal_tf(v.canals), tp, N)
        # per-sample (dt) discretisations of the error models, for applying a move exactly
        ao, bo, self._co = siso_state_space(*otolith_tf(v.otolith))
        ac, bc, self._cc = siso_state_space(*canal_tf(v.canals))
        # per unit constant input, the models' steady states (2,) and (3,): -A^-1 B
        self._oto_gain = -np.linalg.solve(ao, bo)
        self._can_gain = -np.linalg.solve(ac, bc)
        self._phi_o, g = discretise_zoh(ao, bo[:, None], self.dt)
        self._gam_o = g[:, 0]
        self._phi_c, g = discretise_zoh(ac, bc[:, None], self.dt)
        self._gam_c = g[:, 0]
        self._Oo, self._Oc = oto.free, can.free
        self._To, self._Tc = oto.T, can.T
        lower = np.tril(np.ones((N, N)), -1)
        Lm = tp * (lower + 0.5 * np.eye(N))  # dtheta at the intervals' midpoints from the moves' rates
        self._Pp = (
            tp * tp * (np.tril(np.subtract.outer(np.arange(N), np.arange(N)), 0) + 0.5 * np.tril(np.ones((N, N))))
        )
        self._Pv = tp * np.tril(np.ones((N, N)))
        self._t_nodes = tp * np.arange(1, N + 1)
        # blocked prediction matrices (N, M)
        self._ToB = oto.T @ Bk
        self._ToLmB = oto.T @ Lm @ Bk
        self._LmB = Lm @ Bk
        self._TcB = can.T @ Bk
        self._PpB = self._Pp @ Bk
        self._PvB = self._Pv @ Bk
        self._B = Bk
        # The Hessian, z = [a moves (M x 3), omega moves (M x 3)]: sum_k Gram_k (x) S_k with the (2M, 2M) Gram
        # matrices fixed and the 3 x 3 factors S_k set by the attitude each sample (see _plan), plus a fixed part.
        BtB = Bk.T @ Bk
        gram = np.zeros((8, 2 * M, 2 * M))
        a_, w_ = slice(0, M), slice(M, 2 * M)
        gram[0][a_, a_] = self._ToB.T @ self._ToB  # (R Wo R')
        gram[1][a_, a_] = BtB  # (R Wd R')
        gram[2][a_, w_] = self._ToB.T @ self._ToLmB  # (R Wo G)
        gram[3][w_, a_] = gram[2][a_, w_].T  # (G' Wo R')
        gram[4][a_, w_] = Bk.T @ self._LmB  # (R Wd G)
        gram[5][w_, a_] = gram[4][a_, w_].T  # (G' Wd R')
        gram[6][w_, w_] = self._ToLmB.T @ self._ToLmB  # (G' Wo G)
        gram[7][w_, w_] = self._LmB.T @ self._LmB  # (G' Wd G)
        self._gram = gram.reshape(8, -1).T.copy()  # (4 M^2, 8): H's varying part is one product with S (8, 9)
        h_fixed = np.zeros((6 * M, 6 * M))
        h_fixed[: 3 * M, : 3 * M] = (np.kron(self._PpB.T @ self._PpB, np.diag(p.position.xyz))
                                     + np.kron(self._PvB.T @ self._PvB, np.diag(p.velocity.xyz))
                                     + np.kron(BtB, p.acceleration * np.eye(3)))  # fmt: skip
        h_fixed[3 * M :, 3 * M :] = np.kron(BtB, p.angular_rate * np.eye(3))
        h_fixed[3 * M :, 3 * M :] += np.kron(self._TcB.T @ self._TcB, np.diag(p.rate.xyz))  # the canal error's
        self._h_fixed = h_fixed
        self._S = np.empty((8, 3, 3))
        self._relin_rad = math.radians(p.relinearise_deg)
        self._H: np.ndarray | None = None
        self._q_lin = np.array([1.0, 0.0, 0.0, 0.0])
        self._Wo = np.diag(p.force.xyz)
        self._Wd = np.diag(p.direct_force.xyz)
        self._Wc = np.diag(p.rate.xyz)
        self._Wp = np.diag(p.position.xyz)
        self._Wv = np.diag(p.velocity.xyz)
        # constraints: rows [position (3N), velocity (3N), rate facets (4M), rate change facets (4M)] over
        # z = [a_0..a_{M-1} (3 each), omega_0..omega_{M-1} (3 each)], then the felt error's slacks and rows
        nc = 6 * M
        self._slacks: FeltSlacks | None = None
        if p.felt_weight > 0.0:
            th = p.thresholds
            units = np.array([th.f_x_mps2, th.f_y_mps2, th.f_z_mps2,
                              *np.radians([th.omega_x_degps, th.omega_y_degps, th.omega_z_degps])])  # fmt: skip
            self._slacks = FeltSlacks(tp * np.array(self.blocks, dtype=np.float64), units, nc, np.arange(3),
                                    weight=p.felt_weight, false_weight=p.false_weight, jolt_time_s=p.jolt_time_s,
                                    jerk_deadband_mps3=p.jerk_deadband_mps3, dt_s=self.dt,
                                    eps=p.slack_regularisation)  # fmt: skip
        n_slack = self._slacks.n_slack if self._slacks is not None else 0
        self.nz = nz = nc + n_slack
        # the stage's limits at the end of each move (velocity is linear within a move, so its box holds between;
        # position may bulge within a move by at most a_max tb^2 / 8, inside the margin for these moves)
        self._ends = ends = np.cumsum(self.blocks) - 1
        A_pos = np.hstack([np.kron(self._PpB[ends], np.eye(3)), np.zeros((3 * M, 3 * M))])
        A_vel = np.hstack([np.kron(self._PvB[ends], np.eye(3)), np.zeros((3 * M, 3 * M))])
        facets = np.kron(np.eye(M), _FACETS)  # (4M, 3M)
        diff = np.eye(M) - np.eye(M, k=-1)
        A_rate = np.hstack([np.zeros((4 * M, 3 * M)), facets])
        A_dacc = np.hstack([np.zeros((4 * M, 3 * M)), np.kron(diff, _FACETS)])
        A_ctrl = np.vstack([A_pos, A_vel, A_rate, A_dacc])
        n_felt_rows = self._slacks.n_rows if self._slacks is not None else 0
        A = np.zeros((A_ctrl.shape[0] + n_felt_rows, nz))
        A[: A_ctrl.shape[0], :nc] = A_ctrl
        self._A = A
        self._n_felt = slice(nz + A_ctrl.shape[0], nz + A.shape[0])
        eq = np.zeros(A.shape[0], dtype=bool)
        if p.terminal_rest:
            eq[6 * M - 3 : 6 * M] = True
        self.qp = DenseQp(nz, A, eq, p.solver.iter_limit)
        w = mg * self.w_max
        self._hi = np.concatenate([
            np.tile(mg * self.a_max, M), np.full(3 * M, w), np.full(n_slack, INF),  # simple bounds
            np.tile(mg * self.p_max, M), np.tile(mg * self.v_max, M),
            np.full(4 * M, w), np.full(4 * M, mg * self.alpha_max * tp), np.full(n_felt_rows, INF),
        ])  # fmt: skip
        self._lo = -self._hi
        self._lo[nc:nz] = 0.0
        self._H_full = np.zeros((nz, nz))
        if self._slacks is not None:
            self._H_full[nc:, nc:] = np.eye(n_slack) * (2.0 * p.slack_regularisation)
        self._n_pos = slice(nz, nz + 3 * M)
        self._n_vel = slice(nz + 3 * M, nz + 6 * M)
        self._n_dacc0 = slice(nz + 6 * M + 4 * M, nz + 6 * M + 4 * M + 4)
        self._dw0 = mg * self.alpha_max * self.dt
        gam = np.array([p.reference_decay_per_s] * 3 + [p.rate_decay_per_s] * 3)
        self._decay = np.exp(-np.outer(tp * np.arange(N), gam))  # interval j, from its start; (N, 6)
        self._mean_gain = -math.expm1(-self.dt / p.reference_mean_s)  # the recent mean's low-pass, per sample
        self._f_mean = np.array([0.0, 0.0, -self.g])
        self._w_mean = np.zeros(3)
        # the aircraft pilot's own perception (for the felt error's false part): its models' states and start
        self._air_o = np.zeros((ao.shape[0], 3))
        self._air_c = np.zeros((ac.shape[0], 3))
        self._air_0 = (np.zeros(3), np.zeros(3))
        # state
        self.q = np.array([1.0, 0.0, 0.0, 0.0])
        self.p = np.zeros(3)
        self.v = np.zeros(3)
        self.w = np.zeros(3)
        self._a_prev = np.zeros(3)
        self._f_prev = np.array([0.0, 0.0, -self.g])
        self.xo = np.zeros((ao.shape[0], 3))
        self.xc = np.zeros((ac.shape[0], 3))
        self.solves = 0
        self.relinearisations = 0
        self.fallbacks = 0
        self.iterations: list[int] = []
        self._sat_rot = False
        self._future: np.ndarray | None = None  # the recording (n, 6): f, omega, while trace() runs
        self._k = 0

    # ---- perception error models
    def _steady_states(self, e_f: np.ndarray, e_w: np.ndarray) -> None:
        """The error models' steady state for constant head-signal errors ``e_f`` (m/s^2), ``e_w`` (rad/s)."""
        self.xo = np.outer(self._oto_gain, e_f)
        self.xc = np.outer(self._can_gain, e_w)

    def _perceive_aircraft(self, f: np.ndarray, w: np.ndarray) -> None:
        """Advance the aircraft pilot's perception (otolith and canal states) by one sample."""
        self._air_o = self._phi_o @ self._air_o + np.outer(self._gam_o, f)
        self._air_c = self._phi_c @ self._air_c + np.outer(self._gam_c, w)

    def _head_force(self, q: np.ndarray, a: np.ndarray) -> np.ndarray:
        return quat_matrix(q).T @ (a - np.array([0.0, 0.0, self.g]))

    # ---- the washout
    def start(self, f_mps2: np.ndarray, omega_radps: np.ndarray) -> SetPoint:
        """Start at the steady state of the first sample: centred and still, the cockpit tilted so that gravity
        gives the direction of the first specific force (level with ``filter_start="rest"``), the error models
        at the steady state of what is left (the magnitude's difference)."""
        f = np.asarray(f_mps2, float)
        w = np.asarray(omega_radps, float)
        if self.context.filter_start == "rest":
            f, w = np.array([0.0, 0.0, -self.g]), np.zeros(3)
        self.q = tilt_matched(f)
        self.p = np.zeros(3)
        self.v = np.zeros(3)
        self.w = np.zeros(3)
        self._a_prev = np.zeros(3)
        self._f_prev = np.array(f_mps2, dtype=np.float64)
        self._steady_states(self._head_force(self.q, np.zeros(3)) - f, -w)
        self._f_mean, self._w_mean = f.copy(), w.copy()
        self._air_o = np.outer(self._oto_gain, f)
        self._air_c = np.outer(self._can_gain, w)
        self._air_0 = (self._co @ self._air_o, self._cc @ self._air_c)
        self._k = 0
        self._H = None
        return self.p.copy(), self.q.copy()

    def _reference(self, f: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The aircraft's specific force and rate over the horizon's intervals, (N, 3) each
        (:func:`washbench.cueing.condensed.horizon_reference`)."""
        p = self.params
        r = horizon_reference(np.concatenate([f, w]), np.concatenate([self._f_mean, self._w_mean]), self._decay,
                              self._future, self._k, p.preview_s, self.tp, self.dt)  # fmt: skip
        return r[:, :3], r[:, 3:]

    def _plan(self, f: np.ndarray, w: np.ndarray) -> tuple[bool, np.ndarray, np.ndarray]:
        """Solve this sample's QP; (solved, a moves (M, 3) inertial, omega moves (M, 3) body)."""
        M = self.M
        d0 = rotation_vector(quat_mul(quat_conj(self._q_lin), self.q)) if self._H is not None else None
        relinearise = d0 is None or float(_norm(d0)) > self._relin_rad
        if relinearise:  # a new linearisation point: the Hessian and its 3 x 3 factors are rebuilt
            self.relinearisations += 1
            self._q_lin = self.q.copy()
            d0 = np.zeros(3)
            R0 = quat_matrix(self.q)
            gB = R0.T @ np.array([0.0, 0.0, self.g])
            G = -_skew(gB)
            Wo, Wd = self._Wo, self._Wd
            S = self._S
            RWo, RWd = R0 @ Wo, R0 @ Wd
            S[0] = RWo @ R0.T
            S[1] = RWd @ R0.T
            S[2] = RWo @ G
            S[3] = S[2].T
            S[4] = RWd @ G
            S[5] = S[4].T
            S[6] = G.T @ Wo @ G
            S[7] = G.T @ Wd @ G
            H = (self._gram @ S.reshape(8, 9)).reshape(2 * M, 2 * M, 3, 3).transpose(0, 2, 1, 3)
            self._H = 2.0 * self.tp * (H.reshape(6 * M, 6 * M) + self._h_fixed)
            self._H_full[: 6 * M, : 6 * M] = self._H
            self._lin = (R0, gB, G)
            if self._slacks is not None:  # the felt rows' coefficients: the errors at the nodes against the moves
                e = self._ends
                P = np.zeros((6 * len(e), 6 * M))
                P[: 3 * len(e)] = np.hstack([np.kron(self._ToB[e], R0.T), np.kron(self._ToLmB[e], G)])
                P[3 * len(e) :, 3 * M :] = np.kron(self._TcB[e], np.eye(3))
                self._slacks.set_rows(P, R0.T)
                self._A[-self._slacks.n_rows :] = self._slacks.A
        R0, gB, G = self._lin
        Wo, Wd = self._Wo, self._Wd
        F, Wr = self._reference(f, w)
        # the otolith input is R0' a + G (d0 + dtheta) - (f_air + g_B0), d0 the rotation since the linearisation
        Fref = F + (gB - G @ d0)
        c_o = self._Oo @ self.xo - self._To @ Fref  # (N, 3)
        c_d = -Fref
        c_c = self._Oc @ self.xc - self._Tc @ Wr
        c_p = self.p + np.outer(self._t_nodes, self.v)
        c_v = np.broadcast_to(self.v, (self.N, 3))
        fa = (self._ToB.T @ (c_o @ Wo) + self._B.T @ (c_d @ Wd)) @ R0.T + self._PpB.T @ (c_p @ self._Wp) + (
            self._PvB.T @ (c_v @ self._Wv)
        )  # fmt: skip
        fw = (self._ToLmB.T @ (c_o @ Wo) + self._LmB.T @ (c_d @ Wd)) @ G
        fw += self._TcB.T @ (c_c @ self._Wc)
        fz = np.concatenate([fa.ravel(), fw.ravel()])
        lo, hi = self._lo.copy(), self._hi.copy()
        cp_end = c_p[self._ends].ravel()
        lo[self._n_pos] -= cp_end
        hi[self._n_pos] -= cp_end
        v_all = np.broadcast_to(self.v, (self.M, 3)).ravel()
        lo[self._n_vel] -= v_all
        hi[self._n_vel] -= v_all
        if self.params.terminal_rest:  # v_N = 0: (PvB (x) I) z_a = -v_0
            lo[self._n_vel.stop - 3 : self._n_vel.stop] = -c_v[-1]
            hi[self._n_vel.stop - 3 : self._n_vel.stop] = -c_v[-1]
        s = _FACETS @ self.w
        lo[self._n_dacc0] = s - self._dw0
        hi[self._n_dacc0] = s + self._dw0
        fz = 2.0 * self.tp * fz
        if self._slacks is not None:
            e = self._ends
            x_o = self._Oo[e] @ self._air_o + self._To[e] @ F - self._air_0[0]
            x_c = self._Oc[e] @ self._air_c + self._Tc[e] @ Wr - self._air_0[1]
            c = np.concatenate([c_o[e].ravel(), c_c[e].ravel()])
            dx = np.concatenate([x_o.ravel(), x_c.ravel()])
            lo[self._n_felt], f_slack = self._slacks.data(c, dx, R0.T @ self._a_prev, f - self._f_prev)
            fz = np.concatenate([fz, f_slack])
        # the whole cost doubled and times tp is 1/2 z' H z + f' z with H = 2 tp (J' W J), f = 2 tp J' W c
        ok, z, it = self.qp.solve(self._H_full, fz, lo, hi, h_changed=relinearise,
                                  A=self._A if relinearise and self._slacks is not None else None)  # fmt: skip
        self.solves += 1
        self.iterations.append(it)
        return ok, z[: 3 * M].reshape(M, 3), z[3 * M : 6 * M].reshape(M, 3)

    def _safe(self, a: np.ndarray, w: np.ndarray) -> bool:
        """Whether the move keeps the stage within its limits after one sample and able to stop, and the rate
        within the sphere's limits."""
        if not (np.all(np.isfinite(a)) and np.all(np.isfinite(w))):
            return False
        dt = self.dt
        v1 = self.v + a * dt
        p1 = self.p + self.v * dt + a * dt * dt
        if np.any(np.abs(p1) > self.p_max) or np.any(np.abs(v1) > self.v_max) or np.any(np.abs(a) > self.a_max):
            return False
        for j in range(3):
            room = self.p_max[j] - p1[j] if v1[j] > 0 else self.p_max[j] + p1[j]
            if abs(v1[j]) > brake_speed(room, self.a_max[j], dt) + 1e-9:
                return False
        return bool(_norm(w) <= self.w_max and _norm(w - self.w) <= self.alpha_max * dt * (1 + 1e-9))

    def _brake(self) -> tuple[np.ndarray, np.ndarray]:
        """Braking: each stage axis decelerates towards rest at its limit, the rate towards 0 at the sphere's."""
        a = -np.clip(self.v / self.dt, -self.a_max, self.a_max)
        nw = float(_norm(self.w))
        step = self.alpha_max * self.dt
        w = np.zeros(3) if nw <= step else self.w * (1.0 - step / nw)
        return a, w

    def _advance(self, f: np.ndarray, w_air: np.ndarray) -> SetPoint:
        if not (np.all(np.isfinite(f)) and np.all(np.isfinite(w_air))):
            raise ValueError("mpc-unrestricted: non-finite input")
        self._perceive_aircraft(f, w_air)
        self._f_mean += self._mean_gain * (f - self._f_mean)
        self._w_mean += self._mean_gain * (w_air - self._w_mean)
        ok, a_plan, w_plan = self._plan(f, w_air)
        a, w = (a_plan[0], w_plan[0]) if ok else (np.zeros(3), np.zeros(3))
        if not (ok and self._safe(a, w)):
            self.fallbacks += 1
            a, w = self._brake()
        dt = self.dt
        q_mid = quat_step(self.q, w, 0.5 * dt)
        e_f = self._head_force(q_mid, a) - f
        self.xo = self._phi_o @ self.xo + np.outer(self._gam_o, e_f)
        self.xc = self._phi_c @ self.xc + np.outer(self._gam_c, w - w_air)
        self.p = self.p + self.v * dt + a * dt * dt  # semi-implicit Euler, as the platform integrates
        self.v = self.v + a * dt
        self.q = quat_step(self.q, w, dt)
        self._a_prev = a
        self._f_prev = f
        self._sat_rot = bool(np.sum(np.abs(w)) >= 0.999 * self.params.limit_margin * self.w_max)
        self.w = w
        self._k += 1
        return self.p.copy(), self.q.copy()

    def step(self, f_mps2: np.ndarray, omega_radps: np.ndarray) -> SetPoint:
        """Solve this sample's QP, apply its first move for one sample, return the set point."""
        if self.params.preview_s > 0.0 and self._future is None:
            raise WashbenchError("washout mpc-unrestricted: preview_s > 0 needs the recording in advance (run, "
                                 "suite, cue), not a live stream; set mpc-unrestricted.preview_s: 0")  # fmt: skip
        return self._advance(np.asarray(f_mps2, float), np.asarray(omega_radps, float))

    def trace(self, f_mps2: np.ndarray, omega_radps: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The set points of the whole recording (after :meth:`start`); with ``preview_s`` > 0 each sample's plan
        sees the recording ``preview_s`` ahead. Without preview the same numbers as stepping."""
        f = np.asarray(f_mps2, float)
        w = np.asarray(omega_radps, float)
        n = len(f)
        pos = np.empty((n, 3))
        q = np.empty((n, 4))
        self._future = np.hstack([f, w])
        cost.announce_mpc(self._cost, "mpc-unrestricted", self.N, self.dt, n, SLOW_FACTOR)
        try:
            for i in range(n):
                pos[i], q[i] = self._advance(f[i], w[i])
        finally:
            self._future = None
        return pos, q

    def flags(self) -> tuple[bool, bool]:
        """(tilt-rate limit reached: never, it has none; the sphere's rate limit reached) on the last step."""
        return False, self._sat_rot

    def report(self) -> dict[str, float]:
        """Solver statistics: solves, fallbacks (failed or unsafe solves: braking), iterations (median, max),
        relinearisations (new linearisation points: the QP's Hessian and rows rebuilt, DAQP factorised again)."""
        it = np.array(self.iterations) if self.iterations else np.zeros(1)
        return {
            "solves": float(self.solves),
            "fallbacks": float(self.fallbacks),
            "iterations_median": float(np.median(it)),
            "iterations_max": float(np.max(it)),
            "relinearisations": float(self.relinearisations),
        }


__all__ = ["MpcUnrestrictedParams", "MpcUnrestrictedWashout", "quat_matrix", "quat_step", "tilt_matched"]
