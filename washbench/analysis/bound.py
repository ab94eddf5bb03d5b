"""The oracle bound: the least perceived error that any washout could reach on a recorded flight on this platform.

The cost (:func:`perceived_cost`) compares what the simulator pilot and the aircraft pilot perceive, through the
bench's vestibular models (:class:`washbench.perception.vestibular.VestibularModel`, both started in the steady
state of their first sample), over the **linearised head motion** of the platform (small angles, the translational
acceleration taken in the cockpit's axes):

    f_sim = [a_x + g theta, a_y - g phi, a_z - g],      omega_sim = omega_platform (body rates),
    J = dt sum_k  w_f |f_hat_sim,k - f_hat_air,k|^2  +  w_w |omega_hat_sim,k - omega_hat_air,k|^2

with a the platform's acceleration (the bench's ``acc`` columns: (v_k - v_{k-1}) / dt), omega its body rate and
(phi, theta) the integrals of its roll and pitch rates from the start attitude. It is a function of a washout's
platform trajectory alone, so every washout, and the bound, get a value of the same cost
(:func:`washout_cost`).

The bound (:func:`oracle_bound`) minimises J over every platform trajectory on the flight's own time grid that keeps
|p| <= p_max, |v| <= v_max, |v_k - v_{k-1}| <= a_max dt per axis (the Atlas stage, exactly), and each body-rate
component within the rate limit and each component's change within alpha_max dt (a relaxation of the sphere's norm
limits: every trajectory the platform can make satisfies them), with the future known, starting from any position,
attitude and rate within the limits and at rest in translation (as the Atlas stage always starts: a relaxation of
every start). The channels (surge + pitch, sway +
roll, heave, yaw) separate, so it is four sparse QPs (Clarabel's interior-point method: accurate in a few dozen
factorisations of the banded KKT system, where a first-order method needs many thousand iterations here). Since
every washout's trajectory is feasible for the same problem, the bound's cost is at most every washout's; the bound
is optimal for this cost only, not for every metric.

``recovered = (J_still - J_washout) / (J_still - J_bound)``: the fraction of what is recoverable on this platform
that the washout recovers, against a platform that does not move at all (``J_still``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Annotated

import numpy as np
from pydantic import Field
from scipy import sparse

from washbench.cueing.motion_model import discretise_foh
from washbench.errors import WashbenchError
from washbench.io.yamlio import StrictModel
from washbench.numerics.rotations import quat_from_euler
from washbench.perception.vestibular import VestibularModel, VestibularParams, canal_tf, otolith_tf
from washbench.platform.limits import PlatformLimits

MAX_BOUND_SAMPLES = 500_000
"""The longest recording the bound replays as a washout (69 min at 120 Hz; about 20 min of solving)."""
BOUND_S_PER_SAMPLE = 2e-3
"""What the bound's solve costs per sample, s (measured: 1,200 samples 2.3 s, 19,200 samples 37 s on the 2-core
development machine): the order of magnitude of the estimates printed before long work."""


class BoundParams(StrictModel):
    """The bound's cost weights and its solver's tolerances."""

    force_weight: Annotated[float, Field(ge=0.0, le=1e9)] = 1.0
    """w_f, per (m/s^2)^2 of perceived specific-force error"""
    rate_weight: Annotated[float, Field(ge=0.0, le=1e9)] = 10.0
    """w_w, per (rad/s)^2 of perceived angular-velocity error"""
    eps: Annotated[float, Field(gt=0.0, le=1e-2)] = 1e-8
    """the interior-point solver's (Clarabel) gap and feasibility tolerances"""
    max_iter: Annotated[int, Field(ge=10, le=10_000)] = 200


@dataclass(frozen=True)
class Trajectory:
    """A platform trajectory on the flight's grid: acc (N, 3) m/s^2 (NED), omega (N, 3) rad/s (body), angles (N, 3)
    rad (roll, pitch, yaw: integrals of omega from the start attitude), pos (N, 3) m, vel (N, 3) m/s."""

    acc: np.ndarray
    omega: np.ndarray
    angles: np.ndarray
    pos: np.ndarray
    vel: np.ndarray


@dataclass(frozen=True)
class BoundResult:
    """The bound's platform motion, its cost (total and per channel: surge/pitch, sway/roll, heave, yaw), the cost of
    a still platform, and the solver statuses."""

    trajectory: Trajectory
    cost: float
    cost_still: float
    channel_costs: dict[str, float]
    statuses: dict[str, str]

    def recovered(self, cost: float) -> float:
        """The fraction of the recoverable cost a washout of cost ``cost`` recovers (1 = as good as the bound)."""
        span = self.cost_still - self.cost
        return float("nan") if span <= 0.0 else (self.cost_still - cost) / span


def linear_head_motion(acc: np.ndarray, angles: np.ndarray, omega: np.ndarray, g: float) -> tuple[np.ndarray, ...]:
    """Linearised simulator head motion (f (N, 3) m/s^2, omega (N, 3) rad/s) of a platform trajectory."""
    f = np.column_stack([acc[:, 0] + g * angles[:, 1], acc[:, 1] - g * angles[:, 0], acc[:, 2] - g])
    return f, np.asarray(omega, dtype=np.float64)


def perceived_cost(
    f_sim: np.ndarray,
    w_sim: np.ndarray,
    f_air: np.ndarray,
    w_air: np.ndarray,
    dt_s: float,
    params: BoundParams,
    vestibular: VestibularParams | None = None,
) -> np.ndarray:
    """Per-axis cost contributions (2, 3): rows force, rate; columns x, y, z (see the module docstring)."""
    model = VestibularModel(dt_s, vestibular)
    ps = model.perceive(f_sim, w_sim)
    pa = model.perceive(f_air, w_air)
    ef = ps.f_mps2 - pa.f_mps2
    ew = ps.omega_radps - pa.omega_radps
    return dt_s * np.vstack([params.force_weight * np.sum(ef**2, axis=0), params.rate_weight * np.sum(ew**2, axis=0)])


def trajectory_from_trace(
    acc: np.ndarray, omega: np.ndarray, q: np.ndarray, dt_s: float, pos: np.ndarray | None = None
) -> Trajectory:
    """A washout's platform trajectory from its trace columns: acc (N, 3) m/s^2, omega (N, 3) rad/s (the platform's
    body rate over each step), q (N, 4) its attitude (scalar first): the roll and pitch of q[0] anchor the
    integrated angles, angle_k = angle_0 + dt sum_{j=1..k} omega_j. pos (N, 3) m is kept if given."""
    w0, x, y, z = (float(c) for c in q[0])
    roll0 = math.atan2(2.0 * (w0 * x + y * z), 1.0 - 2.0 * (x * x + y * y))
    pitch0 = math.asin(max(-1.0, min(1.0, 2.0 * (w0 * y - z * x))))
    omega = np.asarray(omega, dtype=np.float64)
    acc = np.asarray(acc, dtype=np.float64)
    angles = (np.cumsum(omega, axis=0) - omega[0]) * dt_s + np.array([roll0, pitch0, 0.0])
    vel = np.cumsum(acc, axis=0) * dt_s
    p = np.cumsum(vel, axis=0) * dt_s if pos is None else np.asarray(pos, dtype=np.float64)
    return Trajectory(acc=acc, omega=omega, angles=angles, pos=p, vel=vel)


def washout_cost(
    traj: Trajectory,
    f_air: np.ndarray,
    w_air: np.ndarray,
    dt_s: float,
    gravity_mps2: float,
    params: BoundParams | None = None,
    vestibular: VestibularParams | None = None,
) -> float:
    """J of a platform trajectory (a washout's, or the bound's) against the aircraft head motion (N, 3) each."""
    p = params if params is not None else BoundParams()
    f_sim, w_sim = linear_head_motion(traj.acc, traj.angles, traj.omega, gravity_mps2)
    return float(np.sum(perceived_cost(f_sim, w_sim, f_air, w_air, dt_s, p, vestibular)))


def _vest_discrete(num: np.ndarray, den: np.ndarray, dt: float):
    from scipy import signal

    a, b, c, _ = signal.tf2ss(num, den)
    phi, g0, g1 = discretise_foh(a, b, dt)
    steady = -np.linalg.solve(a, b)  # state per unit constant input
    return phi, g0, g1, c, steady


def _solve_channel(
    kind: str,
    r_f: np.ndarray | None,
    r_w: np.ndarray | None,
    sign: float,
    dt: float,
    g: float,
    lim: dict[str, float],
    params: BoundParams,
    vest: VestibularParams,
    start_at_rest: bool = False,
) -> tuple[dict[str, np.ndarray], str]:
    """One channel's QP. Per sample k the variables are [a, w, ang, p, v, z_o (2), z_c (3)] restricted to those the
    channel has; four more start variables ang_-1, p_-1, v_-1, w_-1. Returns the optimal sequences and the status."""
    import clarabel

    has_f = r_f is not None
    has_w = r_w is not None
    tilt = has_f and has_w
    names = (["a"] if has_f else []) + (["w"] if has_w else []) + (["ang"] if tilt else [])
    names += ["p", "v"] if has_f else []
    no = 2 if has_f else 0
    nc = 3 if has_w else 0
    names += [f"zo{i}" for i in range(no)] + [f"zc{i}" for i in range(nc)]
    nv = len(names)
    col = {n: i for i, n in enumerate(names)}
    n = len(r_f) if has_f else len(r_w)
    starts = (["ang"] if tilt else []) + (["p", "v"] if has_f else []) + (["w"] if has_w else [])
    s0 = n * nv
    scol = {name: s0 + i for i, name in enumerate(starts)}
    nz = s0 + len(starts)

    def v(k: int, name: str) -> int:
        return k * nv + col[name] if k >= 0 else scol[name]

    rows: list[int] = []
    cols: list[int] = []
    vals: list[float] = []
    lo: list[float] = []
    hi: list[float] = []
    r = 0

    def eq(terms: list[tuple[int, float]], rhs: float) -> None:
        nonlocal r
        for c_, v_ in terms:
            rows.append(r)
            cols.append(c_)
            vals.append(v_)
        lo.append(rhs)
        hi.append(rhs)
        r += 1

    def box(c_: int, bound: float) -> None:
        eq([(c_, 1.0)], 0.0)
        lo[-1], hi[-1] = -bound, bound

    oto = _vest_discrete(*otolith_tf(vest.otolith), dt) if has_f else None
    can = _vest_discrete(*canal_tf(vest.canals), dt) if has_w else None

    def head_terms(k: int, which: str) -> list[tuple[int, float]]:
        """The simulator head signal of sample k as terms: force a + sign g ang, or rate w."""
        if which == "f":
            return [(v(k, "a"), 1.0)] + ([(v(k, "ang"), sign * g)] if tilt else [])
        return [(v(k, "w"), 1.0)]

    for k in range(n):
        if has_f:
            eq([(v(k, "v"), 1.0), (v(k - 1, "v"), -1.0), (v(k, "a"), -dt)], 0.0)
            eq([(v(k, "p"), 1.0), (v(k - 1, "p"), -1.0), (v(k, "v"), -dt)], 0.0)
        if tilt:
            eq([(v(k, "ang"), 1.0), (v(k - 1, "ang"), -1.0), (v(k, "w"), -dt)], 0.0)
        for which, model, nzv, ref, pre in (("f", oto, no, r_f, "zo"), ("w", can, nc, r_w, "zc")):
            if model is None:
                continue
            phi, g0, g1, _, steady = model
            for i in range(nzv):
                if k == 0:  # z_0 = steady * (h_0 - r_0)
                    terms = [(v(0, f"{pre}{i}"), 1.0)] + [(c_, -steady[i, 0] * w_) for c_, w_ in head_terms(0, which)]
                    eq(terms, -steady[i, 0] * ref[0])
                else:
                    terms = [(v(k, f"{pre}{i}"), 1.0)]
                    terms += [(v(k - 1, f"{pre}{j}"), -phi[i, j]) for j in range(nzv) if phi[i, j] != 0.0]
                    terms += [(c_, -g0[i, 0] * w_) for c_, w_ in head_terms(k - 1, which)]
                    terms += [(c_, -g1[i, 0] * w_) for c_, w_ in head_terms(k, which)]
                    eq(terms, -(g0[i, 0] * ref[k - 1] + g1[i, 0] * ref[k]))
        if has_f:
            box(v(k, "a"), lim["a"])
            box(v(k, "p"), lim["p"])
            box(v(k, "v"), lim["v"])
        if has_w:
            box(v(k, "w"), lim["w"])
            eq([(v(k, "w"), 1.0), (v(k - 1, "w"), -1.0)], 0.0)
            lo[-1], hi[-1] = -lim["dw"], lim["dw"]
    for name in starts:
        box(scol[name], math.pi if name == "ang" else lim[name])
        if start_at_rest or name == "v":  # the Atlas stage always starts at rest in translation
            lo[-1] = hi[-1] = 0.0
    if start_at_rest and has_f:  # the replay also ends at rest: the stage can stop within its travel at the end
        box(v(n - 1, "v"), 0.0)
    A = sparse.csc_matrix((vals, (rows, cols)), shape=(r, nz))
    # cost: dt (w_f (C_o z_o)^2 + w_w (C_c z_c)^2) per sample
    pr, pc, pv = [], [], []
    for model, nzv, pre, wgt in ((oto, no, "zo", params.force_weight), (can, nc, "zc", params.rate_weight)):
        if model is None:
            continue
        c = model[3]
        m = 2.0 * dt * wgt * (c.T @ c)  # OSQP minimises 1/2 z' P z
        for k in range(n):
            for i in range(nzv):
                for j in range(i, nzv):
                    if m[i, j] != 0.0:
                        pr.append(v(k, f"{pre}{i}"))
                        pc.append(v(k, f"{pre}{j}"))
                        pv.append(m[i, j])
    P = sparse.csc_matrix((pv, (pr, pc)), shape=(nz, nz))
    lo_a, hi_a = np.array(lo), np.array(hi)
    is_eq = lo_a == hi_a
    A_eq, A_in = A[np.flatnonzero(is_eq)], A[np.flatnonzero(~is_eq)]
    # Clarabel: A x + s = b, s in cones: equalities (zero cone), then A x <= hi and -A x <= -lo (non-negative cone)
    A_all = sparse.vstack([A_eq, A_in, -A_in], format="csc")
    b_all = np.concatenate([lo_a[is_eq], hi_a[~is_eq], -lo_a[~is_eq]])
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    settings.max_iter = params.max_iter
    settings.tol_gap_abs = settings.tol_gap_rel = settings.tol_feas = params.eps
    cones = [clarabel.ZeroConeT(A_eq.shape[0]), clarabel.NonnegativeConeT(2 * A_in.shape[0])]
    sol = clarabel.DefaultSolver(sparse.triu(P, format="csc"), np.zeros(nz), A_all, b_all, cones, settings).solve()
    status = str(sol.status)
    z = np.asarray(sol.x, dtype=np.float64)
    out = {name: z[col[name] : n * nv : nv] for name in names if not name.startswith("z")}
    for name in starts:
        out[f"{name}_start"] = np.array([z[scol[name]]])
    return out, status


def oracle_bound(
    f_air: np.ndarray,
    w_air: np.ndarray,
    dt_s: float,
    limits: PlatformLimits,
    gravity_mps2: float,
    params: BoundParams | None = None,
    vestibular: VestibularParams | None = None,
    start_at_rest: bool = False,
) -> BoundResult:
    """The bound on a flight's aircraft head motion f_air (N, 3) m/s^2, w_air (N, 3) rad/s (see the module).

    The platform starts at rest in translation, anywhere within its travel, at any attitude and rate; with
    ``start_at_rest`` centred, level and still, and at rest in translation at the end (what :class:`BoundWashout`
    replays: the Atlas stage must always be able to stop within its travel, which the free bound need not at the
    end of the recording)."""
    p = params if params is not None else BoundParams()
    vest = vestibular if vestibular is not None else VestibularParams()
    f_air = np.asarray(f_air, dtype=np.float64)
    w_air = np.asarray(w_air, dtype=np.float64)
    n = f_air.shape[0]
    t = limits.translation
    # the platform's own rounding; the replay stays 0.1 % inside, where the stage's discrete braking bound is not
    # touched by rounding
    relax = 0.999 if start_at_rest else 1.0 + 1e-9
    w_max = math.radians(limits.rotation.rate_limit_degps) * relax
    dw = math.radians(limits.rotation.acceleration_limit_degps2) * dt_s * relax
    g = float(gravity_mps2)
    acc = np.zeros((n, 3))
    omega = np.zeros((n, 3))
    angles = np.zeros((n, 3))
    pos = np.zeros((n, 3))
    vel = np.zeros((n, 3))
    statuses = {}
    for name, ax, wax, sign in (
        ("pitch", 0, 1, 1.0),
        ("roll", 1, 0, -1.0),
        ("heave", 2, None, 0.0),
        ("yaw", None, 2, 0.0),
    ):
        lim = {"w": w_max, "dw": dw}
        if ax is not None:
            lim.update(p=t.position_limit_m.xyz[ax] * relax, v=t.velocity_limit_mps.xyz[ax] * relax,
                       a=t.acceleration_limit_mps2.xyz[ax] * relax)  # fmt: skip
        r_f = None if ax is None else (f_air[:, 2] + g if ax == 2 else f_air[:, ax])
        r_w = None if wax is None else w_air[:, wax]
        sol, statuses[name] = _solve_channel(name, r_f, r_w, sign, dt_s, g, lim, p, vest, start_at_rest)
        if ax is not None:
            acc[:, ax], pos[:, ax], vel[:, ax] = sol["a"], sol["p"], sol["v"]
        if wax is not None:
            omega[:, wax] = sol["w"]
            if "ang" in sol:
                angles[:, wax] = sol["ang"]
    traj = Trajectory(acc=acc, omega=omega, angles=angles, pos=pos, vel=vel)
    f_sim, w_sim = linear_head_motion(acc, angles, omega, g)
    per = perceived_cost(f_sim, w_sim, f_air, w_air, dt_s, p, vest)
    f_still, w_still = linear_head_motion(np.zeros((n, 3)), np.zeros((n, 3)), np.zeros((n, 3)), g)
    still = float(np.sum(perceived_cost(f_still, w_still, f_air, w_air, dt_s, p, vest)))
    channels = {"pitch": per[0, 0] + per[1, 1], "roll": per[0, 1] + per[1, 0], "heave": per[0, 2], "yaw": per[1, 2]}
    return BoundResult(traj, float(np.sum(per)), still, {k: float(v) for k, v in channels.items()}, statuses)


def costs_from_columns(
    cols: dict[str, np.ndarray],
    dt_s: float,
    limits: PlatformLimits,
    gravity_mps2: float,
    params: BoundParams | None = None,
    vestibular: VestibularParams | None = None,
) -> tuple[BoundResult, dict[str, float]]:
    """The bound and every washout's cost from the columns of a run's ``traces.parquet`` (``aircraft.f_x_mps2`` ...,
    ``NAME.acc_x_mps2``, ``NAME.omega_platform_x_degps``, ``NAME.q_w`` ...)."""
    f_air = np.column_stack([cols[f"aircraft.f_{a}_mps2"] for a in "xyz"])
    w_air = np.radians(np.column_stack([cols[f"aircraft.omega_{a}_degps"] for a in "xyz"]))
    res = oracle_bound(f_air, w_air, dt_s, limits, gravity_mps2, params, vestibular)
    costs = {}
    for key in cols:
        if not key.endswith(".acc_x_mps2"):
            continue
        name = key[: -len(".acc_x_mps2")]
        acc = np.column_stack([cols[f"{name}.acc_{a}_mps2"] for a in "xyz"])
        om = np.radians(np.column_stack([cols[f"{name}.omega_platform_{a}_degps"] for a in "xyz"]))
        q = np.column_stack([cols[f"{name}.q_{c}"] for c in "wxyz"])
        traj = trajectory_from_trace(acc, om, q, dt_s)
        costs[name] = washout_cost(traj, f_air, w_air, dt_s, gravity_mps2, params, vestibular)
    return res, costs


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

    def start(self, f_mps2: np.ndarray, omega_radps: np.ndarray):
        return np.zeros(3), np.array([1.0, 0.0, 0.0, 0.0])

    def step(self, f_mps2: np.ndarray, omega_radps: np.ndarray):
        raise RuntimeError("the oracle bound needs the whole recording in advance (run, cue, suite, omct, sweep, "
                           "tune), not a live stream")  # fmt: skip

    def trace(self, f_mps2: np.ndarray, omega_radps: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        c = self.context
        if len(f_mps2) > MAX_BOUND_SAMPLES:
            raise WashbenchError(f"washout bound: {len(f_mps2):,} samples in one recording, more than the oracle "
                                 f"bound's limit of {MAX_BOUND_SAMPLES:,} (one optimisation over the whole recording: "
                                 "about 2 ms per sample); cut the recording or lower its rate")  # fmt: skip
        res = oracle_bound(f_mps2, omega_radps, c.dt_s, c.limits, c.gravity_mps2, self.params, start_at_rest=True)
        ang = res.trajectory.angles
        q = np.array([quat_from_euler(float(a), float(b), float(y)) for a, b, y in ang])
        return res.trajectory.pos.copy(), q


__all__ = [
    "BoundParams",
    "BoundResult",
    "BoundWashout",
    "Trajectory",
    "costs_from_columns",
    "linear_head_motion",
    "oracle_bound",
    "perceived_cost",
    "trajectory_from_trace",
    "washout_cost",
]
