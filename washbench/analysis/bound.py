"""The linearised bound: the quadratic perceived-error cost J over a small-angle, fixed-heading platform model, and its
minimum with the whole flight known. It plans the attitude of the bound's replay
(:mod:`washbench.analysis.bound_replay`). It is **not** a bound on the ranking (it minimises J, not the score, over a
linearisation that does not contain what the Atlas does with unlimited rotation): the certified lower bound on the
ranking's own measure is the ceiling, :mod:`washbench.analysis.ceiling` (docs/yardstick.md).

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
roll, heave, yaw) separate, so it is four sparse QPs (PIQP's proximal interior-point method: accurate in a few dozen
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

from washbench.analysis.lp_rows import Rows, solve_qp
from washbench.cueing.motion_model import discretise_foh
from washbench.io.yamlio import StrictModel
from washbench.numerics.statespace import tf2ss
from washbench.perception.vestibular import VestibularModel, VestibularParams, canal_tf, otolith_tf
from washbench.platform.limits import PlatformLimits


class BoundParams(StrictModel):
    """The bound's cost weights and its solver's tolerances."""

    force_weight: Annotated[float, Field(ge=0.0, le=1e9)] = 1.0
    """w_f, per (m/s^2)^2 of perceived specific-force error"""
    rate_weight: Annotated[float, Field(ge=0.0, le=1e9)] = 10.0
    """w_w, per (rad/s)^2 of perceived angular-velocity error"""
    jerk_weight: Annotated[float, Field(ge=0.0, le=1e3)] = 1e-3
    """w_j, per (m/s^3)^2 of the stage's jerk ((a_k - a_{k-1}) / dt): keeps the replay from chattering (CHOSEN, its
    effect in docs/optimal-mpc.md)"""
    position_weight: Annotated[float, Field(ge=0.0, le=1e3)] = 0.01
    """w_p, per m^2 s of the stage's distance from its centre: keeps the replay centred where the measure gains
    little (a DOF the pilot does not feel, a steady force of millimetres per second squared) (CHOSEN,
    docs/yardstick.md)"""
    eps: Annotated[float, Field(gt=0.0, le=1e-2)] = 1e-4
    """the interior-point solver's (PIQP) residual and duality-gap tolerances, absolute and relative, both of the
    replay's stages (an achieved motion, not a bound: the platform keeps every limit whatever the plan; on the 22
    bundled manoeuvres 1e-4 and 1e-6 give replay scores within 9e-4 of each other; 1e-6 takes 1.3 times as long)"""
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
    a, b, c, _ = tf2ss(num, den)
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
    """One channel's QP. Per sample k the variables are a, w, ang, p, v, z_o (2), z_c (3), restricted to those the
    channel has (each a block of n), and the start variables ang_-1, p_-1, v_-1, w_-1. Returns the optimal sequences
    and the status. The rows are built a block of samples at a time (:class:`washbench.analysis.lp_rows.Rows`)."""
    has_f = r_f is not None
    has_w = r_w is not None
    tilt = has_f and has_w
    names = (["a"] if has_f else []) + (["w"] if has_w else []) + (["ang"] if tilt else [])
    names += ["p", "v"] if has_f else []
    no = 2 if has_f else 0
    nc = 3 if has_w else 0
    names += [f"zo{i}" for i in range(no)] + [f"zc{i}" for i in range(nc)]
    n = len(r_f) if has_f else len(r_w)
    idx = {name: i * n + np.arange(n) for i, name in enumerate(names)}
    starts = (["ang"] if tilt else []) + (["p", "v"] if has_f else []) + (["w"] if has_w else [])
    s0 = len(names) * n
    scol = {name: s0 + i for i, name in enumerate(starts)}
    nz = s0 + len(starts)
    k1 = np.arange(1, n)

    def prev(name: str) -> np.ndarray:
        """x_{k-1} for k = 0..n-1 (the start variable at k = 0)."""
        return np.concatenate([[scol[name]], idx[name][:-1]])

    rows = Rows()
    zero = np.zeros(n)
    if has_f:
        rows.add([(idx["v"], 1.0), (prev("v"), -1.0), (idx["a"], -dt)], zero.copy(), equal=True)
        rows.add([(idx["p"], 1.0), (prev("p"), -1.0), (idx["v"], -dt)], zero.copy(), equal=True)
    if tilt:
        rows.add([(idx["ang"], 1.0), (prev("ang"), -1.0), (idx["w"], -dt)], zero.copy(), equal=True)
    oto = _vest_discrete(*otolith_tf(vest.otolith), dt) if has_f else None
    can = _vest_discrete(*canal_tf(vest.canals), dt) if has_w else None

    def head(which: str, sel: np.ndarray | slice) -> list[tuple[np.ndarray, float]]:
        """The simulator head signal as terms: force a + sign g ang, or rate w."""
        if which == "f":
            return [(idx["a"][sel], 1.0)] + ([(idx["ang"][sel], sign * g)] if tilt else [])
        return [(idx["w"][sel], 1.0)]

    for which, model, nzv, ref, pre in (("f", oto, no, r_f, "zo"), ("w", can, nc, r_w, "zc")):
        if model is None:
            continue
        phi, g0, g1, _, steady = model
        ref = np.asarray(ref, dtype=np.float64)
        for i in range(nzv):
            z = idx[f"{pre}{i}"]
            # z_0 = steady * (h_0 - r_0)
            rows.add([(z[:1], 1.0), *[(c_, -steady[i, 0] * w_) for c_, w_ in head(which, slice(0, 1))]],
                     np.array([-steady[i, 0] * ref[0]]), equal=True)  # fmt: skip
            terms = [(z[k1], 1.0)]
            terms += [(idx[f"{pre}{j}"][k1 - 1], -phi[i, j]) for j in range(nzv) if phi[i, j] != 0.0]
            terms += [(c_, -g0[i, 0] * w_) for c_, w_ in head(which, slice(0, n - 1))]
            terms += [(c_, -g1[i, 0] * w_) for c_, w_ in head(which, slice(1, n))]
            rows.add(terms, -(g0[i, 0] * ref[:-1] + g1[i, 0] * ref[1:]), equal=True)
    if has_f:
        rows.box(idx["a"], -lim["a"], lim["a"])
        rows.box(idx["p"], -lim["p"], lim["p"])
        rows.box(idx["v"], -lim["v"], lim["v"])
    if has_w:
        rows.box(idx["w"], -lim["w"], lim["w"])
        rows.add([(idx["w"], 1.0), (prev("w"), -1.0)], np.full(n, lim["dw"]), equal=False)
        rows.add([(idx["w"], -1.0), (prev("w"), 1.0)], np.full(n, lim["dw"]), equal=False)
    for name in starts:
        fixed = start_at_rest or name == "v"  # the Atlas stage always starts at rest in translation
        bound = 0.0 if fixed else (math.pi if name == "ang" else lim[name])
        if fixed:
            rows.add([(np.array([scol[name]]), 1.0)], np.zeros(1), equal=True)
        else:
            rows.box(np.array([scol[name]]), -bound, bound)
    if start_at_rest and has_f:  # the replay also ends at rest: the stage can stop within its travel at the end
        rows.add([(idx["v"][-1:], 1.0)], np.zeros(1), equal=True)
    # cost: dt (w_f (C_o z_o)^2 + w_w (C_c z_c)^2) per sample (the solver minimises 1/2 z' P z; P's upper triangle)
    pr, pc, pv = [], [], []
    for model, nzv, pre, wgt in ((oto, no, "zo", params.force_weight), (can, nc, "zc", params.rate_weight)):
        if model is None:
            continue
        c = model[3]
        m = 2.0 * dt * wgt * (c.T @ c)
        for i in range(nzv):
            for j in range(i, nzv):
                if m[i, j] != 0.0:
                    pr.append(idx[f"{pre}{i}"])
                    pc.append(idx[f"{pre}{j}"])
                    pv.append(np.full(n, m[i, j]))
    if has_f and params.jerk_weight > 0.0 and n > 1:  # w_j dt sum ((a_k - a_{k-1}) / dt)^2
        cj = 2.0 * params.jerk_weight / dt
        a_i = idx["a"]
        pr += [a_i[:-1], a_i[1:], a_i[:-1]]
        pc += [a_i[:-1], a_i[1:], a_i[1:]]
        pv += [np.full(n - 1, cj), np.full(n - 1, cj), np.full(n - 1, -cj)]
    P = sparse.csc_matrix((np.concatenate(pv), (np.concatenate(pr), np.concatenate(pc))), shape=(nz, nz))
    sol = solve_qp(sparse.triu(P, format="csc"), np.zeros(nz), rows, params.eps, params.max_iter)
    status = str(sol.status)
    x = np.asarray(sol.x, dtype=np.float64)
    out = {name: x[idx[name]] for name in names if not name.startswith("z")}
    for name in starts:
        out[f"{name}_start"] = np.array([x[scol[name]]])
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
    channels: tuple[str, ...] = ("pitch", "roll", "heave", "yaw"),
) -> BoundResult:
    """The bound on a flight's aircraft head motion f_air (N, 3) m/s^2, w_air (N, 3) rad/s (see the module).

    ``channels``: the channels solved (the others left still and costed as such); the replay's attitude stage
    (:mod:`washbench.analysis.bound_replay`) needs pitch, roll and yaw only.

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
        if name not in channels:
            continue
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


__all__ = [
    "BoundParams",
    "BoundResult",
    "Trajectory",
    "costs_from_columns",
    "linear_head_motion",
    "oracle_bound",
    "perceived_cost",
    "trajectory_from_trace",
    "washout_cost",
]
