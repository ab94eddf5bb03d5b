"""The bound's replay: a physical Atlas motion planned with the whole flight known (the ``bound`` washout).

Two stages, each a convex programme:

1. **Attitude.** The linearised bound (:func:`washbench.analysis.bound.oracle_bound`, started level, centred and
   still) plans the body rates of roll, pitch **and yaw** (tilt coordination in roll and pitch, the canals in all
   three). The rates are integrated as the sphere integrates them (:func:`washbench.platform.kinematics.
   track_rotation`, every rate and angular-acceleration limit kept), so the attitude ``R_k`` used below is the one
   the platform will fly.
2. **Translation, in the right frame.** With the attitude known, the simulator pilot's specific force
   ``f_k = R_k^T (a_k - g_I)`` is linear in the stage's inertial acceleration ``a_k``: the stage's plan minimises
   the ranking's own measure for specific force (the integral of |perceived error| over the felt DOFs, which the
   score weighs equally within its group, :mod:`washbench.analysis.ranking`) plus a small jerk penalty
   ``w_j dt sum |(a_k - a_{k-1}) / dt|^2`` (``BoundParams.jerk_weight``: no chatter), under the stage's exact
   limits (0.1 % inside, position, velocity and acceleration per inertial axis, the discrete integrator
   ``v_k = v_{k-1} + a_k dt``, ``p_k = p_{k-1} + v_k dt``), from rest at the centre, with a small centring penalty
   ``w_p dt sum |p_k|^2`` (``BoundParams.position_weight``) where the measure gains little.

The replay is an achieved motion, not a bound: its score is an upper estimate of the best a washout with the whole
flight known could do, the ceiling (:mod:`washbench.analysis.ceiling`) a certified lower one.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import sparse

from washbench.analysis.bound import BoundParams, oracle_bound
from washbench.analysis.lp_rows import Rows, solve_qp, trapezoid
from washbench.analysis.ranking import MOTION_FLOOR, perceived_motion
from washbench.io import cost
from washbench.io.units import G0_MPS2
from washbench.perception.vestibular import VestibularModel, VestibularParams, otolith_model
from washbench.platform.limits import PlatformLimits

REPLAY_TOL = 1e-6
"""The replay's translation solve: gap and feasibility tolerances (an achieved motion, not a bound: the platform
model keeps every limit whatever the plan)."""

UNFELT_WEIGHT = 0.01
"""The weight of a specific-force DOF the aircraft pilot did not feel (the score gives it none; a little keeps the
replay from moving freely there). CHOSEN."""


def track_attitudes(q_sp: np.ndarray, dt_s: float, limits: PlatformLimits) -> np.ndarray:
    """The attitudes (N, 4) the sphere flies for the attitude set points ``q_sp`` (N, 4), scalar first: the platform's
    own rotation tracking (:func:`washbench.platform.kinematics.track_rotation`, every limit kept), started still at
    the first set point, as the platform starts a washout whose start is that attitude."""
    from washbench.platform.kinematics import track_rotation  # deferred: numba

    rot = limits.rotation
    w_max = math.radians(rot.rate_limit_degps)
    alpha = math.radians(rot.acceleration_limit_degps2)
    n = q_sp.shape[0]
    out = np.empty((n, 4))
    q = tuple(float(x) for x in q_sp[0])
    w_prev = (0.0, 0.0, 0.0)
    prev_sp = q
    for k in range(n):
        sp = (float(q_sp[k, 0]), float(q_sp[k, 1]), float(q_sp[k, 2]), float(q_sp[k, 3]))
        q, w_prev, _, _ = track_rotation(q, w_prev, prev_sp, sp, w_max, alpha, rot.catch_up_fraction, dt_s)
        prev_sp = sp
        out[k] = q
    return out


def attitudes(angles: np.ndarray, yaw_rate: np.ndarray, dt_s: float, limits: PlatformLimits) -> tuple[np.ndarray, ...]:
    """The attitude set points (N, 4) of the planned roll and pitch angles with the heading the planned yaw rate
    (N,) rad/s turns (ZYX Euler angles), and the attitudes the sphere flies for them (:func:`track_attitudes`)."""
    from washbench.numerics.rotations import quat_from_euler  # deferred: numba

    yaw = np.cumsum(yaw_rate) * dt_s
    q_sp = np.array([quat_from_euler(float(a), float(b), float(y))
                     for (a, b), y in zip(angles[:, :2], yaw, strict=True)])  # fmt: skip
    return q_sp, track_attitudes(q_sp, dt_s, limits)


def _rotation_matrices(q: np.ndarray) -> np.ndarray:
    """R (N, 3, 3) body to inertial of quaternions (N, 4), scalar first."""
    w, x, y, z = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], axis=-1),
            np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], axis=-1),
            np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], axis=-1),
        ],
        axis=1,
    )


def translation_plan(
    f_air: np.ndarray,
    q: np.ndarray,
    dt_s: float,
    limits: PlatformLimits,
    gravity_mps2: float,
    jerk_weight: float,
    vestibular: VestibularParams | None = None,
    filter_start: str = "steady",
    position_weight: float = 0.0,
    tolerance: float = REPLAY_TOL,
) -> tuple[np.ndarray, str]:
    """Stage 2 (module docstring): the stage's positions (N, 3) m, NED, for the attitudes ``q`` (N, 4), and the
    solver's status. ``f_air`` (N, 3) m/s^2 the aircraft pilot's specific force; ``jerk_weight`` per (m/s^3)^2,
    ``position_weight`` per m^2 s (``w_p dt sum |p_k|^2``: centring)."""
    vest = vestibular if vestibular is not None else VestibularParams()
    n = f_air.shape[0]
    dt = float(dt_s)
    g = float(gravity_mps2)
    model = VestibularModel(dt, vest)
    ref = model.perceive(f_air, np.zeros_like(f_air), filter_start).f_mps2
    felt = perceived_motion(ref, np.zeros_like(ref), dt)
    oto = otolith_model(vest.otolith, dt)
    b, phi, steady = oto.arrays()
    ns = len(phi)
    rmat = _rotation_matrices(q)  # (N, 3, 3): body -> inertial
    gam = g * rmat[:, 2, :]  # R^T g_I: gravity in body axes (N, 3)
    names = ("a", "v", "p", "t")
    off = {nm: 3 * i * n for i, nm in enumerate(names)}
    x0 = 3 * len(names) * n
    nvar = x0 + 3 * ns * n

    def idx(nm: str, ax: int) -> np.ndarray:
        return off[nm] + ax * n + np.arange(n)

    rows = Rows()
    lim = limits.translation
    relax = 0.999
    k = np.arange(1, n)
    for ax in range(3):
        a, v, p = idx("a", ax), idx("v", ax), idx("p", ax)
        rows.box(a, -lim.acceleration_limit_mps2.xyz[ax] * relax, lim.acceleration_limit_mps2.xyz[ax] * relax)
        rows.box(v, -lim.velocity_limit_mps.xyz[ax] * relax, lim.velocity_limit_mps.xyz[ax] * relax)
        rows.box(p, -lim.position_limit_m.xyz[ax] * relax, lim.position_limit_m.xyz[ax] * relax)
        rows.add([(v[k], 1.0), (v[k - 1], -1.0), (a[k], -dt)], np.zeros(n - 1), equal=True)
        rows.add([(p[k], 1.0), (p[k - 1], -1.0), (v[k], -dt)], np.zeros(n - 1), equal=True)
        # always able to stop within the travel (the tracker's braking bound, brake_speed): braking from v covers
        # v^2 / (2 a_max) <= c |v| with c = v_max / (2 a_max) (+ one step for the discrete integrator), so
        # |p + c v| <= p_max keeps every plan inside what the platform tracks without clipping
        c_brake = lim.velocity_limit_mps.xyz[ax] / (2.0 * lim.acceleration_limit_mps2.xyz[ax]) + dt
        p_lim = lim.position_limit_m.xyz[ax] * relax
        rows.add([(p, 1.0), (v, c_brake)], np.full(n, p_lim), equal=False)
        rows.add([(p, -1.0), (v, -c_brake)], np.full(n, p_lim), equal=False)
        rows.add([(v[:1], 1.0), (a[:1], -dt)], np.zeros(1), equal=True)  # from rest, centred
        rows.add([(p[:1], 1.0), (v[:1], -dt)], np.zeros(1), equal=True)
    rest = filter_start == "rest"
    cost = np.zeros(nvar)
    trap = trapezoid(n, dt)
    for bx in range(3):  # body axis: h_k = sum_j R_k[j, bx] a_k,j - gamma_k,bx
        h_terms = [(idx("a", j), rmat[:, j, bx]) for j in range(3)]
        h_const = -gam[:, bx]
        for s in range(ns):
            xs = x0 + (bx * ns + s) * n + np.arange(n)
            if rest:
                u_r = (0.0, 0.0, -G0_MPS2)[bx]
                rhs0 = phi[s] * steady[s] * u_r + b[s, 1] * u_r + b[s, 0] * h_const[0]
                rows.add([(xs[:1], 1.0), *[(i[:1], -b[s, 0] * c[:1]) for i, c in h_terms]], np.array([rhs0]), True)
            else:
                rows.add([(xs[:1], 1.0), *[(i[:1], -steady[s] * c[:1]) for i, c in h_terms]],
                         np.array([steady[s] * h_const[0]]), True)  # fmt: skip
            terms = [(xs[k], 1.0), (xs[k - 1], -phi[s])]
            terms += [(i[k], -b[s, 0] * c[k]) for i, c in h_terms]
            terms += [(i[k - 1], -b[s, 1] * c[k - 1]) for i, c in h_terms]
            rows.add(terms, b[s, 0] * h_const[k] + b[s, 1] * h_const[k - 1], True)
        y_terms = [(x0 + (bx * ns + s) * n + np.arange(n), 1.0) for s in range(ns)]
        t = idx("t", bx)
        rows.add([*y_terms, (t, -1.0)], ref[:, bx].copy(), equal=False)
        rows.add([*[(i, -c) for i, c in y_terms], (t, -1.0)], -ref[:, bx], equal=False)
        dof = ("surge", "sway", "heave")[bx]
        weight = 1.0 if felt[dof] >= MOTION_FLOOR[dof] else UNFELT_WEIGHT
        cost[t] = weight * trap
    pr, pc, pv = [], [], []
    if jerk_weight > 0.0 and n > 1:
        cj = 2.0 * jerk_weight / dt
        for ax in range(3):
            a = idx("a", ax)
            pr += [a[:-1], a[1:], a[:-1]]
            pc += [a[:-1], a[1:], a[1:]]
            pv += [np.full(n - 1, cj)] * 2 + [np.full(n - 1, -cj)]
    if position_weight > 0.0:
        for ax in range(3):
            p_i = idx("p", ax)
            pr.append(p_i)
            pc.append(p_i)
            pv.append(np.full(n, 2.0 * position_weight * dt))
    pmat = (sparse.csc_matrix((np.concatenate(pv), (np.concatenate(pr), np.concatenate(pc))), shape=(nvar, nvar))
            if pr else sparse.csc_matrix((nvar, nvar)))  # fmt: skip
    sol = solve_qp(sparse.triu(pmat, format="csc"), cost, rows, tolerance, 200)
    z = np.asarray(sol.x, dtype=np.float64)
    pos = np.column_stack([z[idx("p", ax)] for ax in range(3)])
    return pos, str(sol.status)


def replay(
    f_mps2: np.ndarray,
    omega_radps: np.ndarray,
    dt_s: float,
    limits: PlatformLimits,
    gravity_mps2: float,
    params: BoundParams,
    filter_start: str = "steady",
) -> tuple[np.ndarray, np.ndarray, dict[str, float]]:
    """The replay's set points for a flight's aircraft head motion (N, 3) each: positions (N, 3) m, NED; attitudes
    (N, 4), scalar first; and the solves (1 per stage solved). ``params``: :class:`washbench.analysis.bound.
    BoundParams`. Both stages on the flight's own grid (a plan on a coarser grid, interpolated back, was tried:
    planned at 60 Hz for a 120 Hz flight, the short rudder doublet's replay scored 0.129 instead of 0.054)."""
    f = np.asarray(f_mps2, dtype=np.float64)
    w = np.asarray(omega_radps, dtype=np.float64)
    res = oracle_bound(f, w, dt_s, limits, gravity_mps2, params, start_at_rest=True,
                       channels=("pitch", "roll", "yaw"))  # fmt: skip
    traj = res.trajectory
    q_sp, q = attitudes(traj.angles, traj.omega[:, 2], dt_s, limits)
    pos, status = translation_plan(f, q, dt_s, limits, gravity_mps2, params.jerk_weight, filter_start=filter_start,
                                   position_weight=params.position_weight, tolerance=params.eps)  # fmt: skip
    solved = {f"{k}_solved": float(v == "Solved") for k, v in res.statuses.items()}
    solved["translation_solved"] = float(status == "Solved")
    return pos, q_sp, solved


class BoundWashout:
    """The bound as a washout (kind ``bound``, ``whole_only``: it needs the whole recording; ``run`` cues it after
    the flight on the flight read back, ``cue`` and the whole-trace paths give it the input at once,
    :class:`washbench.cueing.CueingBank` ``future``): its ``trace`` solves the bound for the whole recording,
    started centred, level and still, and returns its positions and attitudes (ZYX Euler from the integrated roll,
    pitch and yaw) as set points, so the platform, head motion, perception, metrics, ranking, report and figures
    treat it like any washout. It knows the future; ``step`` (a live stream) cannot and raises."""

    Params = BoundParams
    name = "bound"
    whole_only = True

    def __init__(self, params: BoundParams | None, context) -> None:
        self.params = params if params is not None else BoundParams()
        self.context = context
        self.solved: dict[str, float] = {}

    def report(self) -> dict[str, float]:
        """The replay's solves: 1 per stage solved (the attitude's four channels, the translation), 0 otherwise."""
        return dict(self.solved)

    def start(self, f_mps2: np.ndarray, omega_radps: np.ndarray):
        return np.zeros(3), np.array([1.0, 0.0, 0.0, 0.0])  # the plan starts level (oracle_bound start_at_rest)

    def step(self, f_mps2: np.ndarray, omega_radps: np.ndarray):
        raise RuntimeError("the oracle bound needs the whole recording in advance (run, cue, suite, omct, sweep, "
                           "tune), not a live stream")  # fmt: skip

    def trace(self, f_mps2: np.ndarray, omega_radps: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The replay's set points (:func:`replay`): positions (N, 3) m, attitudes
        (N, 4), scalar first."""
        c = self.context
        # planned over the whole recording at once, and the ceiling after it: refused before it starts if it would
        # not fit (washbench.io.cost), announced if it takes long
        cost.check(cost.bound(len(f_mps2), c.dt_s))
        pos, q_sp, self.solved = replay(f_mps2, omega_radps, c.dt_s, c.limits, c.gravity_mps2, self.params,
                                        c.filter_start)  # fmt: skip
        return pos, q_sp


__all__ = ["REPLAY_TOL", "UNFELT_WEIGHT", "BoundWashout", "attitudes", "replay", "track_attitudes", "translation_plan"]
