"""One step of the best achieved's search: the felt error of a whole platform motion as a linear programme, with the
attitude's kinematics linearised about a flown motion (:mod:`washbench.analysis.best_motion` repeats it).

Frames and units as everywhere (docs/architecture.md): body axes x forward, y right, z down; inertial NED with
``g_I = [0, 0, g]``; quaternions scalar first, body to inertial; SI inside (the rotational DOFs' thresholds in rad/s
here, in deg/s at the edges). The platform's motion on the flight's own grid k = 0..N-1, from its start (``k = -1``:
the stage centred at rest, the sphere at the start attitude ``q_s``):

* the stage, exactly as the platform model integrates it (:mod:`washbench.platform.kinematics`): the inertial
  acceleration ``a_k``, ``v_k = v_{k-1} + a_k dt``, ``p_k = p_{k-1} + v_k dt``, ``v_{-1} = p_{-1} = 0``, within its
  limits per inertial axis (0.1 % inside) and always able to stop within its travel, ``|p + c v| <= p_max`` with
  ``c = v_max / (2 a_max) + dt`` (the bound's replay's rows, :func:`washbench.analysis.bound_replay.translation_plan`);
* the sphere's attitude as a small turn ``d_k`` (body axes, rad) of a reference motion's ``R_k``:
  ``R_k = Rbar_k exp([d_k]x)``, ``d_{-1} = 0``. Linearised about ``d = 0`` (the reference itself):

  - the body rate over a step, ``w_k = wbar_k + (d_k - Dbar_k^T d_{k-1}) / dt`` with ``Dbar_k = Rbar_{k-1}^T Rbar_k``
    (exact to first order in ``d``; the neglected terms are of the order of the step's own turn, ``wbar dt``, times
    ``d``'s change);
  - the head's specific force, ``f_k = Rbar_k^T (a_k - g_I) + fbar_k x d_k`` with ``fbar_k = Rbar_k^T (abar_k - g_I)``
    the reference's (the first-order term of ``exp(-[d]x) Rbar^T (a - g_I)``: gravity's direction turned by ``d``,
    the stage's acceleration as the reference turned it; a head away from the sphere's centre is not modelled here:
    the motion flown decides, :mod:`washbench.analysis.best_motion`);
  - the sphere's limits as polytopes inside its norm limits, in a frame per sample whose first axis is the
    reference's rate (or the aircraft's where the reference barely turns): ``|w_k|_1 <= w_max`` and
    ``|w_k - w_{k-1}|_1 <= alpha_max dt`` in that frame (a 1-norm is at least the 2-norm, so every point is within
    the platform's limits; along the frame's first axis the whole limit is kept);
  - a trust region, ``|d_k| <= rho`` per component (the stage's acceleration enters linearly: no trust region);

* perception exactly as the metrics apply it (the vestibular model's first-order-hold sections,
  :class:`washbench.perception.vestibular.DiscreteModel`, started in the steady state of the first sample or from
  rest), and the felt error's terms exactly (:mod:`washbench.analysis.felt`; their rows as the ceiling writes them,
  :mod:`washbench.analysis.ceiling`): per DOF ``t_k >= |y_k - x_k| - T_d``, the false part ``v_k`` by the aircraft's
  cue's sign, per force axis the jolt ``j_k >= |f_k - f_{k-1}| - |F_k - F_{k-1}| - J_T dt`` (k >= 1), the objective
  their weighted sum (:class:`Weights`: the ranking rule's, so at ``d = 0``, ``a = abar`` the objective is the
  rule's value of the reference motion itself, to the head offset and the sphere's rounding).

Solved by PIQP (:func:`washbench.analysis.lp_rows.solve_qp`) to a loose tolerance and a few dozen iterations: a step
is a proposal, flown through the platform model and judged by the exact measure before it is taken. With PIQP's
default least regularisation (1e-10) the programme's steps stalled after about 25 iterations at a duality gap of
1 % (the C172 steep turn: 5,795 samples, 278,160 variables); with 1e-8 (:data:`REG_LOWER_LIMIT`) the gap fell below
1e-4 in 40.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import sparse

from washbench.analysis.lp_rows import Rows, solve_qp, trapezoid
from washbench.perception.vestibular import DiscreteModel

REG_LOWER_LIMIT = 1e-8
"""PIQP's least proximal regularisation for this programme (module docstring)."""

MARGIN = 0.999
"""The stage's and the sphere's limits in the programme: this fraction of the platform's (the model keeps them
exactly; the margin keeps a plan off the limits the platform would clip at, by rounding or by the linearisation)."""


@dataclass(frozen=True)
class Reference:
    """A flown platform motion the programme is linearised about, N samples ``dt`` apart: ``q`` (N, 4) attitudes,
    ``acc`` (N, 3) the stage's inertial acceleration (m/s^2), ``q_start`` (4,) the attitude before the first sample."""

    q: np.ndarray
    acc: np.ndarray
    q_start: np.ndarray


@dataclass(frozen=True)
class Aircraft:
    """What the simulator pilot is compared with: the aircraft pilot's perceived specific force (N, 3) m/s^2 and
    angular velocity (N, 3) rad/s, and his head specific force (N, 3) m/s^2 (the jolt's allowance)."""

    perceived_f: np.ndarray
    perceived_omega: np.ndarray
    head_f: np.ndarray


@dataclass(frozen=True)
class Weights:
    """The objective: per DOF (surge, sway, heave, roll, pitch, yaw) the weight of the integral of the error beyond
    the dead band (``error``, per m/s^2*s or per rad), of the false part (``false``, the same units), the dead band
    itself (``band``, m/s^2 or rad/s); per force axis the weight of the jolt (``jolt``, per m/s^2). A ranking rule's
    value is this sum (:func:`washbench.analysis.best_motion.rule_weights`)."""

    error: np.ndarray
    false: np.ndarray
    band: np.ndarray
    jolt: np.ndarray
    jerk_deadband_mps3: float = 0.0


@dataclass(frozen=True)
class Sphere:
    """The limits the programme keeps (SI): per inertial axis the stage's position, velocity and acceleration limits
    (3,) each; the sphere's rate and angular-acceleration norm limits."""

    pos: np.ndarray
    vel: np.ndarray
    acc: np.ndarray
    rate: float
    ang_acc: float


@dataclass(frozen=True)
class Step:
    """A solved step: the stage's positions (N, 3) m, the attitude turns ``d`` (N, 3) rad, the programme's value
    (the predicted felt error), the solver's status and its iterations."""

    pos: np.ndarray
    turn: np.ndarray
    value: float
    status: str
    iterations: int


# ------------------------------------------------------------------------------------------- quaternions, vectorised


def qmul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton products (N, 4) of (N, 4) quaternions, scalar first."""
    aw, ax, ay, az = a[..., 0], a[..., 1], a[..., 2], a[..., 3]
    bw, bx, by, bz = b[..., 0], b[..., 1], b[..., 2], b[..., 3]
    return np.stack([aw * bw - ax * bx - ay * by - az * bz, aw * bx + ax * bw + ay * bz - az * by,
                     aw * by - ax * bz + ay * bw + az * bx, aw * bz + ax * by - ay * bx + az * bw],
                    axis=-1)  # fmt: skip


def qconj(q: np.ndarray) -> np.ndarray:
    return q * np.array([1.0, -1.0, -1.0, -1.0])


def qexp(v: np.ndarray) -> np.ndarray:
    """The quaternions (N, 4) of rotation vectors (N, 3), rad."""
    th = np.linalg.norm(v, axis=-1)
    half = 0.5 * th
    k = np.where(th > 1e-12, np.sin(half) / np.where(th > 1e-12, th, 1.0), 0.5 - th * th / 48.0)
    return np.concatenate([np.cos(half)[..., None], v * k[..., None]], axis=-1)


def qlog(q: np.ndarray) -> np.ndarray:
    """Rotation vectors (N, 3), rad, of the shortest rotations of quaternions (N, 4) (as ``qrotvec``)."""
    q = np.where(q[..., :1] < 0.0, -q, q)
    n = np.linalg.norm(q[..., 1:], axis=-1)
    w = q[..., 0]
    k = np.where(n < 1e-12, 2.0 / np.where(w > 0.0, w, 1.0), 2.0 * np.arctan2(n, w) / np.where(n > 0.0, n, 1.0))
    return q[..., 1:] * k[..., None]


def rotation_matrices(q: np.ndarray) -> np.ndarray:
    """R (N, 3, 3), body to inertial, of quaternions (N, 4), scalar first."""
    w, x, y, z = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], axis=-1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], axis=-1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], axis=-1),
    ], axis=1)  # fmt: skip


def step_rates(q: np.ndarray, q_start: np.ndarray, dt: float) -> np.ndarray:
    """The body rate over each step (N, 3), rad/s, as the sphere tracks it: the rotation vector of
    ``q_{k-1}* q_k`` over dt, from ``q_start``."""
    prev = np.concatenate([np.asarray(q_start, dtype=np.float64)[None], q[:-1]])
    return qlog(qmul(qconj(prev), q)) / dt


# ------------------------------------------------------------------------------------------------------- the rows


def _frames(w_ref: np.ndarray, w_air: np.ndarray, rate: float) -> np.ndarray:
    """Per sample an orthonormal frame (N, 3, 3) whose first row is the reference's rate direction (the aircraft's
    where the reference turns at less than a tenth of the limit; x where neither turns)."""
    n = len(w_ref)
    u = np.array(w_ref, dtype=np.float64)
    weak = np.linalg.norm(u, axis=1) < 0.1 * rate
    u[weak] = w_air[weak]
    norm = np.linalg.norm(u, axis=1)
    u[norm < 1e-9] = (1.0, 0.0, 0.0)
    u /= np.linalg.norm(u, axis=1)[:, None]
    # a second axis orthogonal to u: u x (the unit axis u is least along)
    least = np.zeros((n, 3))
    least[np.arange(n), np.argmin(np.abs(u), axis=1)] = 1.0
    e1 = np.cross(u, least)
    e1 /= np.linalg.norm(e1, axis=1)[:, None]
    e2 = np.cross(u, e1)
    return np.stack([u, e1, e2], axis=1)


SIGNS = np.array([[sx, sy, sz] for sx in (1.0, -1.0) for sy in (1.0, -1.0) for sz in (1.0, -1.0)])
"""The eight facets of a 1-norm ball in three dimensions."""


def _perception(rows: Rows, u_terms: list[tuple[np.ndarray, np.ndarray | float]], u_const: np.ndarray,
                states: np.ndarray, model: DiscreteModel, rest_input: float | None) -> None:  # fmt: skip
    """The model's sections driven by the input ``u_k = sum_j c_j x[idx_j] + u_const_k`` (terms of length N), their
    states at ``states`` (S, N) (as :func:`washbench.analysis.ceiling._perception_rows`)."""
    b, phi, steady = model.arrays()
    n = states.shape[1]
    k = np.arange(1, n)
    for s in range(len(phi)):
        xs = states[s]
        first = [(i[:1], np.broadcast_to(c, (n,))[:1]) for i, c in u_terms]
        if rest_input is None:  # x_0 = steady u_0
            rows.add([(xs[:1], 1.0), *[(i, -steady[s] * c) for i, c in first]], np.array([steady[s] * u_const[0]]),
                     equal=True)  # fmt: skip
        else:
            rhs = phi[s] * steady[s] * rest_input + b[s, 1] * rest_input + b[s, 0] * u_const[0]
            rows.add([(xs[:1], 1.0), *[(i, -b[s, 0] * c) for i, c in first]], np.array([rhs]), equal=True)
        now = [(i[k], -b[s, 0] * np.broadcast_to(c, (n,))[k]) for i, c in u_terms]
        before = [(i[k - 1], -b[s, 1] * np.broadcast_to(c, (n,))[k - 1]) for i, c in u_terms]
        rows.add([(xs[k], 1.0), (xs[k - 1], -phi[s]), *now, *before],
                 b[s, 0] * u_const[k] + b[s, 1] * u_const[k - 1], equal=True)  # fmt: skip


def _false_rows(rows: Rows, y: list[tuple[np.ndarray, float]], x: np.ndarray, band: float, v: np.ndarray) -> None:
    """The false part ``v_k`` (:mod:`washbench.analysis.felt`) by the sign of the aircraft's cue ``x_k - x_0`` beyond
    the band: ``v_k >= -s_k (y_k - x_0) - band`` where it is ``s_k``, ``v_k >= |y_k - x_0| - band`` where there is
    none; ``v >= 0`` (as :func:`washbench.analysis.ceiling._perception_rows` writes them)."""
    rows.box(v, 0.0, np.inf)
    dx = x - x[0]
    s = np.where(np.abs(dx) > band, np.sign(dx), 0.0)
    for sign in (1.0, -1.0):  # where the cue is -sign, or none: sign (y_k - x_0) - v_k <= band
        sel = np.flatnonzero((s == -sign) | (s == 0.0))
        if len(sel):
            rows.add([*[(i[sel], sign * c) for i, c in y], (v[sel], -1.0)], np.full(len(sel), band + sign * x[0]),
                     equal=False)  # fmt: skip


def solve_step(
    ref: Reference,
    aircraft: Aircraft,
    dt_s: float,
    gravity_mps2: float,
    sphere: Sphere,
    otolith: DiscreteModel,
    canals: DiscreteModel,
    weights: Weights,
    rest_start: bool,
    rho: float,
    tolerance: float,
    max_iter: int,
) -> Step:
    """The programme of the module docstring about ``ref``, solved (PIQP): the next motion's stage positions and
    attitude turns, and the programme's value (the rule's value it predicts)."""
    n = len(ref.q)
    dt = float(dt_s)
    g = float(gravity_mps2)
    rmat = rotation_matrices(ref.q)  # (N, 3, 3) body -> inertial
    w_bar = step_rates(ref.q, ref.q_start, dt)
    prev = np.concatenate([np.asarray(ref.q_start, dtype=np.float64)[None], ref.q[:-1]])
    d_bar = rotation_matrices(qmul(qconj(prev), ref.q))  # Dbar_k = Rbar_{k-1}^T Rbar_k
    f_bar = np.einsum("nji,nj->ni", rmat, ref.acc - np.array([0.0, 0.0, g]))  # Rbar^T (abar - g_I)
    gam = g * rmat[:, 2, :]  # Rbar^T g_I
    felt = [bool(weights.error[d] > 0.0 or weights.false[d] > 0.0) for d in range(6)]
    jolts = [bool(weights.jolt[i] > 0.0 and n > 1) for i in range(3)]
    sections = [len(otolith.phi)] * 3 + [len(canals.phi)] * 3
    names = [f"{v}{i}" for v in ("a", "v", "p", "d", "w", "f") for i in range(3)]
    names += [f"t{d}" for d in range(6) if weights.error[d] > 0.0]
    names += [f"u{d}" for d in range(6) if weights.false[d] > 0.0]
    names += [f"j{i}" for i in range(3) if jolts[i]]
    names += [f"x{d}_{s}" for d in range(6) if felt[d] for s in range(sections[d])]
    ix = {nm: i * n + np.arange(n) for i, nm in enumerate(names)}
    nvar = len(names) * n
    rows = Rows()
    k = np.arange(1, n)
    # the stage
    for i in range(3):
        a, v, p = ix[f"a{i}"], ix[f"v{i}"], ix[f"p{i}"]
        rows.add([(v[k], 1.0), (v[k - 1], -1.0), (a[k], -dt)], np.zeros(n - 1), equal=True)
        rows.add([(p[k], 1.0), (p[k - 1], -1.0), (v[k], -dt)], np.zeros(n - 1), equal=True)
        rows.add([(v[:1], 1.0), (a[:1], -dt)], np.zeros(1), equal=True)
        rows.add([(p[:1], 1.0), (v[:1], -dt)], np.zeros(1), equal=True)
        rows.box(a, -float(sphere.acc[i]) * MARGIN, float(sphere.acc[i]) * MARGIN)
        rows.box(v, -float(sphere.vel[i]) * MARGIN, float(sphere.vel[i]) * MARGIN)
        p_lim = float(sphere.pos[i]) * MARGIN
        rows.box(p, -p_lim, p_lim)
        c_brake = float(sphere.vel[i]) / (2.0 * float(sphere.acc[i])) + dt
        rows.add([(p, 1.0), (v, c_brake)], np.full(n, p_lim), equal=False)
        rows.add([(p, -1.0), (v, -c_brake)], np.full(n, p_lim), equal=False)
    # the attitude's turn within the trust region, and the body rate it makes:
    # k = 0: w_0 - d_0 / dt = wbar_0 (d_{-1} = 0); k >= 1: + sum_j Dbar_k[j, i] d_{k-1, j} / dt
    for i in range(3):
        rows.box(ix[f"d{i}"], -rho, rho)
        rows.add([(ix[f"w{i}"][:1], 1.0), (ix[f"d{i}"][:1], -1.0 / dt)], w_bar[:1, i].copy(), equal=True)
        if n > 1:
            later = [(ix[f"w{i}"][k], 1.0), (ix[f"d{i}"][k], -1.0 / dt)]
            later += [(ix[f"d{j}"][k - 1], d_bar[k, j, i] / dt) for j in range(3)]
            rows.add(later, w_bar[k, i].copy(), equal=True)
    # the head's specific force: f - Rbar^T a - [fbar]x d = -gamma
    cross = np.zeros((n, 3, 3))
    cross[:, 0, 1], cross[:, 0, 2] = -f_bar[:, 2], f_bar[:, 1]
    cross[:, 1, 0], cross[:, 1, 2] = f_bar[:, 2], -f_bar[:, 0]
    cross[:, 2, 0], cross[:, 2, 1] = -f_bar[:, 1], f_bar[:, 0]
    for i in range(3):
        terms = [(ix[f"f{i}"], 1.0)]
        terms += [(ix[f"a{j}"], -rmat[:, j, i]) for j in range(3)]
        terms += [(ix[f"d{j}"], -cross[:, i, j]) for j in range(3) if j != i]
        rows.add(terms, -gam[:, i], equal=True)
    # the sphere's limits: 1-norms in a frame along the reference's rate (module docstring)
    frames = _frames(w_bar, aircraft.perceived_omega, sphere.rate)
    w_lim = sphere.rate * MARGIN
    dw_lim = sphere.ang_acc * dt * MARGIN
    for sgn in SIGNS:
        coef = np.einsum("j,njc->nc", sgn, frames)  # (N, 3): sum_j s_j e_j
        rows.add([(ix[f"w{c}"], coef[:, c]) for c in range(3)], np.full(n, w_lim), equal=False)
        if n > 1:
            rows.add([*[(ix[f"w{c}"][k], coef[k, c]) for c in range(3)],
                      *[(ix[f"w{c}"][k - 1], -coef[k, c]) for c in range(3)]], np.full(n - 1, dw_lim), equal=False)
        if rest_start:  # from rest: the first step's rate within one step's angular acceleration
            rows.add([(ix[f"w{c}"][:1], coef[:1, c]) for c in range(3)], np.full(1, dw_lim), equal=False)
    # perception and the rule's terms
    trap = trapezoid(n, dt)
    cost = np.zeros(nvar)
    rest_inputs = (0.0, 0.0, -g, 0.0, 0.0, 0.0)
    inputs = [f"f{i}" for i in range(3)] + [f"w{i}" for i in range(3)]
    reference = np.column_stack([aircraft.perceived_f, aircraft.perceived_omega]).astype(np.float64)
    for d in range(6):
        if not felt[d]:
            continue
        model = otolith if d < 3 else canals
        states = np.stack([ix[f"x{d}_{s}"] for s in range(sections[d])])
        _perception(rows, [(ix[inputs[d]], 1.0)], np.zeros(n), states, model, rest_inputs[d] if rest_start else None)
        y = [(st, 1.0) for st in states]
        x = reference[:, d]
        band = float(weights.band[d])
        if weights.error[d] > 0.0:
            t = ix[f"t{d}"]
            rows.add([*y, (t, -1.0)], x + band, equal=False)
            rows.add([*[(i, -c) for i, c in y], (t, -1.0)], -x + band, equal=False)
            rows.box(t, 0.0, np.inf)
            cost[t] = weights.error[d] * trap
        if weights.false[d] > 0.0:
            v = ix[f"u{d}"]
            _false_rows(rows, y, x, band, v)
            cost[v] = weights.false[d] * trap
    for i in range(3):
        if not jolts[i]:
            continue
        j = ix[f"j{i}"]
        rows.box(j, 0.0, np.inf)
        allow = np.abs(np.diff(np.asarray(aircraft.head_f[:, i], dtype=np.float64))) + weights.jerk_deadband_mps3 * dt
        f = ix[f"f{i}"]
        for sign in (1.0, -1.0):
            rows.add([(f[k], sign), (f[k - 1], -sign), (j[k], -1.0)], allow, equal=False)
        rows.box(j[:1], 0.0, 0.0)  # the first sample's jolt is not counted
        cost[j[1:]] = weights.jolt[i]
    sol = solve_qp(sparse.csc_matrix((nvar, nvar)), cost, rows, tolerance, max_iter, REG_LOWER_LIMIT)
    x = sol.x
    pos = np.column_stack([x[ix[f"p{i}"]] for i in range(3)])
    turn = np.column_stack([x[ix[f"d{i}"]] for i in range(3)])
    return Step(pos=pos, turn=turn, value=float(sol.obj_val), status=sol.status, iterations=sol.iterations)


__all__ = ["MARGIN", "REG_LOWER_LIMIT", "Aircraft", "Reference", "Sphere", "Step", "Weights", "qconj", "qexp", "qlog",
           "qmul", "rotation_matrices", "solve_step", "step_rates"]  # fmt: skip
