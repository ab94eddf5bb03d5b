"""The ceiling's relaxation of each platform kind: per body axis, bounds that every head motion the platform model
can make satisfies (:mod:`washbench.analysis.ceiling` builds its linear programmes from them; docs/yardstick.md
derives each line).

Body axes x forward, y right, z down; inertial north-east-down; ``gamma = R^T g_I`` gravity in body axes
(``g_I = [0, 0, g]``), ``b = R^T a``, ``V = R^T v``, ``P = R^T p`` the MRP's acceleration, velocity and position from
neutral in body axes (the bench's difference quotients: ``v_k = (p_k - p_{k-1}) / dt``, ``a_k = (v_k - v_{k-1}) /
dt``), ``omega`` the body rate of the quaternion difference (``|omega_k| = 2 sin(theta_k / 2) / dt <= theta_k / dt``
for a turn ``theta_k`` over the step).

* **Atlas**: the limits themselves (a box per inertial axis, norms for the sphere), as before.
* **rig**: closed forms from its limits (ZYX Euler gimbals about the MRP, heave along the inertial down axis):
  ``R^T e_z = [-sin theta, sin phi cos theta, cos phi cos theta]`` bounds gravity per axis by the roll and pitch
  stops, heave's ``b, V, P`` are along the same vector, and the turn per step is at most the sum of the axes' rate
  limits times dt (the triangle inequality of the rotation angle, which every rotation leaves invariant).
* **hexapod**: its workspace's extremes (largest gravity components, farthest MRP from neutral) and its rate bounds
  (leg speed through the inverse leg Jacobian) **found numerically** (boundary points along 6-D rays from neutral,
  then local maximisation with SLSQP; the Jacobian's gain at interior and boundary poses), then widened by stated
  margins. Not proved: a global bound over a 6-D workspace is beyond a sampling. Every run widens them further to
  what each washout's motion on the platform actually did (:func:`widened`), so the ceiling is below every washout
  it is compared with by construction of the rows, and records what had to be widened (a miss of the search).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from functools import lru_cache
from typing import Any

import numpy as np

Vec3 = tuple[float, float, float]

ROTATION_SLACK = 1.0 + 1e-9
"""The platform's rounding on its limits (the Atlas's rotational rows, as before; every bound of a rig)."""
HEXAPOD_RAYS = 4096
"""Rays from neutral along which the hexapod's workspace boundary is found (CHOSEN; seeded, so deterministic)."""
HEXAPOD_SEED = 36
GRAVITY_MARGIN = 0.01
"""Hexapod: added to each |gamma_i| / g bound found (and taken from gamma_z / g's lower bound) (CHOSEN)."""
POSITION_MARGIN = 1.02
RATE_MARGIN = 1.25
ACCELERATION_MARGIN = 1.5
"""Hexapod: factors on the farthest MRP, on the speed and rate bounds, and on the acceleration bounds found (CHOSEN:
the sampled Jacobian gains are a maximum over samples, not a supremum)."""


@dataclass(frozen=True)
class Relaxation:
    """Bounds every head motion of one platform satisfies (SI; per body axis x, y, z where a tuple).

    gravity_lo, gravity_hi: ``gamma_i`` in [lo_i, hi_i], m/s^2. turn_step_rad: the largest turn over one sample.
    acc, vel, pos: ``|b_i|``, ``|V_i|``, ``|P_i|`` bounds; vel_norm, pos_norm: ``|v|``, ``|p|`` bounds (the turning
    frame's terms). start_pos: ``|P_{-1,i}|`` (0: the platform starts at neutral). rate: ``|omega_i|``, rad/s;
    rate_step: ``|omega_k - omega_{k-1}|`` per sample, rad/s (inf: no row); ang_acc: the angular acceleration's norm
    for a head away from the MRP, rad/s^2. source: what each value came from (run.json)."""

    kind: str
    gravity_lo: Vec3
    gravity_hi: Vec3
    turn_step_rad: float
    acc: Vec3
    vel: Vec3
    pos: Vec3
    vel_norm: float
    pos_norm: float
    start_pos: Vec3
    rate: Vec3
    rate_step: float
    ang_acc: float
    source: str

    @property
    def chord(self) -> float:
        """``2 sin(theta / 2)`` of the largest turn per sample: how far a unit vector fixed in one frame moves in
        the other over a sample."""
        return 2.0 * math.sin(min(self.turn_step_rad, math.pi) / 2.0)

    def record(self) -> dict[str, Any]:
        """The values for run.json (SI); a bound that is not finite (no row: a rig's rate step, a hexapod whose leg
        Jacobian is singular somewhere inside its stroke) is null, as JSON has no infinity."""

        def num(x: float) -> float | None:
            return float(x) if math.isfinite(x) else None

        def nums(xs: Vec3) -> list[float | None]:
            return [num(x) for x in xs]

        return {
            "kind": self.kind, "gravity_lo_mps2": nums(self.gravity_lo), "gravity_hi_mps2": nums(self.gravity_hi),
            "turn_step_rad": num(self.turn_step_rad), "acc_mps2": nums(self.acc), "vel_mps": nums(self.vel),
            "pos_m": nums(self.pos), "vel_norm_mps": num(self.vel_norm), "pos_norm_m": num(self.pos_norm),
            "start_pos_m": nums(self.start_pos), "rate_radps": nums(self.rate), "rate_step_radps": num(self.rate_step),
            "ang_acc_radps2": num(self.ang_acc), "source": self.source,
        }  # fmt: skip

    @property
    def unbounded(self) -> tuple[str, ...]:
        """The bounds that are not finite (of rate, acc, vel, ang_acc: a singular leg Jacobian inside the stroke)."""
        values = {"rate": self.rate, "acceleration": self.acc, "velocity": self.vel, "angular acceleration":
                  (self.ang_acc,)}  # fmt: skip
        return tuple(k for k, v in values.items() if not all(math.isfinite(x) for x in v))


def atlas_relaxation(limits: Any, dt_s: float, gravity_mps2: float) -> Relaxation:
    """The Atlas (:class:`washbench.platform.limits.PlatformLimits`): the corners of its boxes, its sphere's norm
    limits, gravity of norm g."""
    g = float(gravity_mps2)
    t = limits.translation
    w_max = math.radians(limits.rotation.rate_limit_degps)
    alpha = math.radians(limits.rotation.acceleration_limit_degps2)
    a_bar = math.hypot(*t.acceleration_limit_mps2.xyz)
    v_bar = math.hypot(*t.velocity_limit_mps.xyz)
    p_bar = math.hypot(*t.position_limit_m.xyz)
    return Relaxation(
        kind="atlas", gravity_lo=(-g, -g, -g), gravity_hi=(g, g, g), turn_step_rad=w_max * float(dt_s),
        acc=(a_bar,) * 3, vel=(v_bar,) * 3, pos=(p_bar,) * 3, vel_norm=v_bar, pos_norm=p_bar, start_pos=(0.0,) * 3,
        rate=(w_max,) * 3, rate_step=alpha * float(dt_s), ang_acc=alpha,
        source="the Atlas's limits (box corners, the sphere's norms)",
    )  # fmt: skip


def _gravity_factors(roll_max: float, pitch_max: float) -> tuple[Vec3, float]:
    """Per body axis the largest |(R^T e_z)_i| for |roll| <= roll_max, |pitch| <= pitch_max (rad, ZYX Euler; yaw
    does not enter), and the least (R^T e_z)_z = cos(roll) cos(pitch)."""
    sx = math.sin(min(pitch_max, math.pi / 2))
    sy = math.sin(min(roll_max, math.pi / 2))
    cr, cp = math.cos(min(roll_max, math.pi)), math.cos(min(pitch_max, math.pi))
    low_z = min(cr, cp, cr * cp)
    return (sx, sy, 1.0), low_z


def rig_relaxation(rig: Any, dt_s: float, gravity_mps2: float) -> Relaxation:
    """A rig (:class:`washbench.platform.rig.RigModel`), in closed form from its limits (module docstring)."""
    g = float(gravity_mps2)
    axes = [a for a in (rig.roll, rig.pitch, rig.yaw) if a is not None]
    (sx, sy, sz), low_z = _gravity_factors(math.radians(rig.roll.angle_limit_deg),
                                           math.radians(rig.pitch.angle_limit_deg))  # fmt: skip
    turn_rate = sum(math.radians(a.rate_limit_degps) for a in axes) * ROTATION_SLACK
    rates = [math.radians(a.rate_limit_degps) for a in axes]
    # continuous time: omega = E(angles) rates, d omega / dt = E accelerations + (dE/dt) rates
    alpha = (sum(math.radians(a.acceleration_limit_degps2) for a in axes) + sum(rates) ** 2) * ACCELERATION_MARGIN
    h = rig.heave
    pa, pv, pp = (h.acceleration_limit_mps2, h.velocity_limit_mps, h.position_limit_m) if h else (0.0, 0.0, 0.0)
    # the platform's rounding (its difference quotients, the angles' sines): a relative 1e-9 on every bound
    sx, sy, low_z = min(1.0, sx * ROTATION_SLACK), min(1.0, sy * ROTATION_SLACK), low_z - (ROTATION_SLACK - 1.0)
    pa, pv, pp = pa * ROTATION_SLACK, pv * ROTATION_SLACK, pp * ROTATION_SLACK
    factors = (sx, sy, sz)
    return Relaxation(
        kind="rig", gravity_lo=(-g * sx, -g * sy, g * low_z), gravity_hi=(g * sx, g * sy, g),
        turn_step_rad=turn_rate * float(dt_s), acc=tuple(pa * f for f in factors),
        vel=tuple(pv * f for f in factors), pos=tuple(pp * f for f in factors), vel_norm=pv, pos_norm=pp,
        start_pos=tuple(pp * f for f in factors), rate=(turn_rate,) * 3, rate_step=math.inf, ang_acc=alpha,
        source=("the rig's limits in closed form (roll and pitch stops bound gravity per axis, heave along R^T e_z, "
                "the turn per sample within the sum of the axes' rate limits); the angular acceleration for a head "
                "offset from its continuous-time derivative with a margin"),
    )  # fmt: skip


def _rotations(rv: np.ndarray) -> np.ndarray:
    """Rotation matrices (N, 3, 3) of rotation vectors (N, 3) (Rodrigues)."""
    th = np.linalg.norm(rv, axis=1)
    safe = np.where(th > 0.0, th, 1.0)
    k = rv / safe[:, None]
    kx = np.zeros((len(rv), 3, 3))
    kx[:, 0, 1], kx[:, 0, 2], kx[:, 1, 2] = -k[:, 2], k[:, 1], -k[:, 0]
    kx[:, 1, 0], kx[:, 2, 0], kx[:, 2, 1] = k[:, 2], -k[:, 1], k[:, 0]
    s, c = np.sin(th)[:, None, None], np.cos(th)[:, None, None]
    return np.eye(3)[None] + s * kx + (1.0 - c) * (kx @ kx)


class _Hexapod:
    """The hexapod's legs, Jacobians and gains, vectorised over poses (p (N, 3), rotation vector (N, 3))."""

    def __init__(self, model: Any) -> None:
        self.b = np.asarray(model.base_joints_m, dtype=np.float64)
        self.a = np.asarray(model.platform_joints_m, dtype=np.float64)
        self.n = np.asarray(model.neutral_m, dtype=np.float64)
        self.lo, self.hi = model.leg_length_m.min, model.leg_length_m.max

    def legs(self, p: np.ndarray, rv: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        r = _rotations(rv)
        ra = np.einsum("nij,kj->nki", r, self.a)  # (N, 6, 3)
        d = self.n + p[:, None, :] + ra - self.b[None]
        return np.linalg.norm(d, axis=2), d, ra

    def inside(self, p: np.ndarray, rv: np.ndarray) -> np.ndarray:
        legs = self.legs(p, rv)[0]
        return np.all((legs >= self.lo) & (legs <= self.hi), axis=1)

    def gains(self, p: np.ndarray, rv: np.ndarray, v_leg: float, a_leg: float) -> dict[str, np.ndarray]:
        """Per pose (N,) bounds on what leg speeds within ``v_leg`` and leg accelerations within ``a_leg`` let the
        platform do, through the inverse leg Jacobian M (inf where it is singular):

        - ``vel``, ``rate``: the largest |dp/dt| and |omega| for leg speeds in [-v_leg, v_leg]^6 (a norm of a linear
          map is convex: its maximum over the box is at one of the 64 corners);
        - ``acc``, ``ang_acc``: the same of M (l'' - c) with |l''_i| <= a_leg and the velocity terms
          ``c_i = |P'_i,perp|^2 / l_i + u_i . (omega x (omega x R a_i))`` (the second derivative of
          l_i = |P_i - b_i|, P_i = n + p + R a_i), bounded by their corners' largest |P'_i,perp|^2 / l_i (convex in
          the leg speeds) plus the largest |omega|^2 |a_i|."""
        legs, d, ra = self.legs(p, rv)
        u = d / legs[:, :, None]
        jac = np.concatenate([u, np.cross(ra, u)], axis=2)  # (N, 6, 6)
        ok = np.linalg.cond(jac) < 1e8
        inv = np.full_like(jac, np.nan)
        inv[ok] = np.linalg.inv(jac[ok])
        signs = np.array(np.meshgrid(*[[-1.0, 1.0]] * 6, indexing="ij")).reshape(6, -1)  # (6, 64)
        tw = (inv @ signs) * v_leg  # (N, 6, 64) twists at the corners
        vel = np.linalg.norm(tw[:, :3], axis=1).max(axis=1)
        w2 = (np.linalg.norm(tw[:, 3:], axis=1) ** 2).max(axis=1)  # (N,)
        # joint velocities P'_i = p' + omega x R a_i at each corner: (N, 6 legs, 3, 64)
        pdot = tw[:, None, :3, :] + np.cross(tw[:, None, 3:, :], ra[:, :, :, None], axisa=2, axisb=2, axisc=2)
        along = np.einsum("nkic,nki->nkc", pdot, u)
        perp2 = (np.sum(pdot**2, axis=2) - along**2).max(axis=2)  # (N, 6)
        c = perp2 / legs + w2[:, None] * np.linalg.norm(ra, axis=2)
        half = a_leg + c  # (N, 6): |l'' - c| within a box of these half-widths
        tw2 = inv @ (signs[None] * half[:, :, None])
        out = {
            "vel": vel,
            "rate": np.sqrt(w2),
            "acc": np.linalg.norm(tw2[:, :3], axis=1).max(axis=1),
            "ang_acc": np.linalg.norm(tw2[:, 3:], axis=1).max(axis=1),
        }
        return {k: np.where(ok, v, np.inf) for k, v in out.items()}


def _boundary(hx: _Hexapod, dirs: np.ndarray) -> np.ndarray:
    """Per 6-D direction (translation m, rotation vector rad) the scale s at which the pose (s t, s r) first leaves
    the workspace going out from neutral: marched in steps of 1/64 of the direction (a leg's stroke is crossed in
    far more), then bisected. (Leg lengths alone also allow poses that no motion from neutral reaches, such as the
    platform mirrored below its base: a bisection between neutral and a far pose could land there.)"""
    last = np.zeros(len(dirs))
    alive = np.ones(len(dirs), dtype=bool)
    step = 1.0 / 64.0
    for i in range(1, 64 * 8 + 1):
        s = i * step
        ok = hx.inside(dirs[alive, :3] * s, dirs[alive, 3:] * s)
        idx = np.flatnonzero(alive)
        last[idx[ok]] = s
        alive[idx[~ok]] = False
        if not alive.any():
            break
    lo, hi = last, last + step
    for _ in range(30):
        mid = 0.5 * (lo + hi)
        ok = hx.inside(dirs[:, :3] * mid[:, None], dirs[:, 3:] * mid[:, None])
        lo, hi = np.where(ok, mid, lo), np.where(ok, hi, mid)
    return lo


def _same_side(hx: _Hexapod, x: np.ndarray) -> bool:
    """Whether the pose ``x`` (6,) keeps the platform on the side of its base it is on at neutral (every leg's
    vertical component of the sign it has at neutral, the cockpit upright): leg lengths alone also allow poses no
    motion from neutral reaches (the platform mirrored below its base, turned over), which the search must not
    count."""
    d = hx.legs(x[None, :3], x[None, 3:])[1][0]
    d0 = hx.legs(np.zeros((1, 3)), np.zeros((1, 3)))[1][0]
    upright = _rotations(x[None, 3:])[0, 2, 2] > 0.0
    return bool(upright and np.all(np.sign(d[:, 2]) == np.sign(d0[:, 2])))


def _maximise(hx: _Hexapod, x0: np.ndarray, objective) -> float:
    """The largest ``objective(p, rv)`` found by SLSQP from ``x0`` (6,) within the legs' stroke, on neutral's side of
    the base (:func:`_same_side`; the start's value when it does not improve on it)."""
    from scipy.optimize import minimize

    def f(x: np.ndarray) -> float:
        return -float(objective(x[None, :3], x[None, 3:])[0])

    def cons(x: np.ndarray) -> np.ndarray:
        legs = hx.legs(x[None, :3], x[None, 3:])[0][0]
        return np.concatenate([legs - hx.lo, hx.hi - legs])

    best = -f(x0)
    res = minimize(f, x0, method="SLSQP", constraints=[{"type": "ineq", "fun": cons}],
                   options={"maxiter": 200, "ftol": 1e-12})  # fmt: skip
    if res.success and np.all(cons(res.x) >= -1e-9) and _same_side(hx, res.x):
        best = max(best, -float(res.fun))
    return best


@lru_cache(maxsize=8)
def _hexapod_bounds(geometry: tuple[float, ...], lengths: tuple[float, float], v_leg: float, a_leg: float
                    ) -> dict[str, float]:
    """The hexapod's workspace extremes and Jacobian gains per unit leg speed (numerical; module docstring)."""
    arr = np.asarray(geometry).reshape(-1)

    class _M:  # the model's numbers only (hashable cache key)
        base_joints_m = arr[:18].reshape(6, 3)
        platform_joints_m = arr[18:36].reshape(6, 3)
        neutral_m = arr[36:39]

        class leg_length_m:  # noqa: N801
            min, max = lengths

    hx = _Hexapod(_M)
    rng = np.random.default_rng(HEXAPOD_SEED)
    dirs = rng.standard_normal((HEXAPOD_RAYS, 6))
    dirs[: HEXAPOD_RAYS // 8, 3:] = 0.0  # pure translations
    dirs[HEXAPOD_RAYS // 8 : HEXAPOD_RAYS // 4, :3] = 0.0  # pure rotations
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)  # unit steps: 1 m of translation, 1 rad of rotation
    s = _boundary(hx, dirs)[:, None]
    edge = np.concatenate([dirs[:, :3] * s, dirs[:, 3:] * s], axis=1)
    inner = edge * rng.uniform(0.0, 1.0, (len(edge), 1))

    def gz(p: np.ndarray, rv: np.ndarray) -> np.ndarray:  # (R^T e_z) = third row of R
        return _rotations(rv)[:, 2, :]

    objectives = {
        "gx": lambda p, rv: np.abs(gz(p, rv)[:, 0]),
        "gy": lambda p, rv: np.abs(gz(p, rv)[:, 1]),
        "gz_low": lambda p, rv: -gz(p, rv)[:, 2],
        "pos": lambda p, rv: np.linalg.norm(p, axis=1),
    }
    out: dict[str, float] = {}
    for name, obj in objectives.items():
        vals = obj(edge[:, :3], edge[:, 3:])
        best = float(vals.max())
        for i in np.argsort(vals)[-4:]:
            best = max(best, _maximise(hx, edge[i], obj))
        out[name] = best
    poses = np.concatenate([edge * 0.999, inner])
    for key, values in hx.gains(poses[:, :3], poses[:, 3:], v_leg, a_leg).items():
        out[key] = float(values.max())
    return out


def hexapod_relaxation(model: Any, dt_s: float, gravity_mps2: float) -> Relaxation:
    """A hexapod (:class:`washbench.platform.hexapod.HexapodModel`): numerical workspace and rate bounds with
    margins (module docstring; docs/yardstick.md)."""
    g = float(gravity_mps2)
    dt = float(dt_s)
    geo = tuple(float(x) for x in np.concatenate([np.ravel(model.base_joints_m), np.ravel(model.platform_joints_m),
                                                  np.ravel(model.neutral_m)]))  # fmt: skip
    v_leg, a_leg = float(model.leg_velocity_limit_mps), float(model.leg_acceleration_limit_mps2)
    hb = _hexapod_bounds(geo, (float(model.leg_length_m.min), float(model.leg_length_m.max)), v_leg, a_leg)
    sx = min(1.0, hb["gx"] + GRAVITY_MARGIN)
    sy = min(1.0, hb["gy"] + GRAVITY_MARGIN)
    low_z = max(-1.0, -hb["gz_low"] - GRAVITY_MARGIN)
    p_bar = hb["pos"] * POSITION_MARGIN
    v_bar = hb["vel"] * RATE_MARGIN
    w_bar = hb["rate"] * RATE_MARGIN
    a_bar = hb["acc"] * ACCELERATION_MARGIN
    alpha = hb["ang_acc"] * ACCELERATION_MARGIN
    return Relaxation(
        kind="hexapod", gravity_lo=(-g * sx, -g * sy, g * low_z), gravity_hi=(g * sx, g * sy, g),
        turn_step_rad=w_bar * dt, acc=(a_bar,) * 3, vel=(v_bar,) * 3, pos=(p_bar,) * 3, vel_norm=v_bar,
        pos_norm=p_bar, start_pos=(p_bar,) * 3, rate=(w_bar,) * 3, rate_step=alpha * dt, ang_acc=alpha,
        source=(f"numerical: {HEXAPOD_RAYS} rays from neutral to the workspace's edge, SLSQP from the 4 best of each "
                f"extreme, the inverse leg Jacobian's gain at {2 * HEXAPOD_RAYS} poses; margins +{GRAVITY_MARGIN} g on "
                f"gravity's components, x{POSITION_MARGIN} on the farthest MRP, x{RATE_MARGIN} on speeds and rates, "
                f"x{ACCELERATION_MARGIN} on accelerations"),
    )  # fmt: skip


def relaxation_of(platform: Any, dt_s: float, gravity_mps2: float) -> Relaxation:
    """The relaxation of a loaded platform file (Atlas limits, hexapod or rig); ValueError for another kind (a
    plugin's platform: its workspace is not known to the bench)."""
    if isinstance(platform, Relaxation):
        return platform
    kind = getattr(platform, "kind", "atlas")
    if kind == "atlas":
        return atlas_relaxation(platform, dt_s, gravity_mps2)
    if kind == "hexapod":
        return hexapod_relaxation(platform, dt_s, gravity_mps2)
    if kind == "rig":
        return rig_relaxation(platform, dt_s, gravity_mps2)
    raise ValueError(f"the ceiling needs the platform's workspace; a {kind} platform does not give one")


def observed(traces: dict[str, Any], dt_s: float, gravity_mps2: float) -> dict[str, float]:
    """What the washouts' motions (``WashoutTrace``-like: ``pos_m``, ``vel_mps``, ``acc_mps2``, ``q``,
    ``omega_radps``, (N, 3|4)) reached, in the relaxation's terms (largest over the washouts)."""
    g = float(gravity_mps2)
    out = {"gx": 0.0, "gy": 0.0, "gz_low": 1.0, "acc": 0.0, "vel": 0.0, "pos": 0.0, "rate": 0.0, "rate_step": 0.0,
           "turn": 0.0}  # fmt: skip
    for tr in traces.values():
        q = np.asarray(tr.q)
        w, x, y, z = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
        gam = np.column_stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)])  # R^T e_z
        # the turn over each sample, 2 atan2(|vec(r)|, |w(r)|) of r = q_prev* q (accurate for small turns, where
        # 2 acos(q_prev . q) loses half its digits)
        a, b = q[:-1], q[1:]
        rw = np.sum(a * b, axis=1)
        rv = a[:, :1] * b[:, 1:] - b[:, :1] * a[:, 1:] - np.cross(a[:, 1:], b[:, 1:])
        turns = 2.0 * np.arctan2(np.linalg.norm(rv, axis=1), np.abs(rw))
        om = np.asarray(tr.omega_radps)
        out["gx"] = max(out["gx"], float(np.abs(gam[:, 0]).max()))
        out["gy"] = max(out["gy"], float(np.abs(gam[:, 1]).max()))
        out["gz_low"] = min(out["gz_low"], float(gam[:, 2].min()))
        out["acc"] = max(out["acc"], float(np.linalg.norm(tr.acc_mps2, axis=1).max()))
        out["vel"] = max(out["vel"], float(np.linalg.norm(tr.vel_mps, axis=1).max()))
        out["pos"] = max(out["pos"], float(np.linalg.norm(tr.pos_m, axis=1).max()))
        out["rate"] = max(out["rate"], float(np.abs(om).max()))
        if len(om) > 1:
            out["rate_step"] = max(out["rate_step"], float(np.linalg.norm(np.diff(om, axis=0), axis=1).max()))
            out["turn"] = max(out["turn"], float(turns.max()))
    out["g"] = g
    out["dt"] = float(dt_s)
    return out


def widened(relax: Relaxation, seen: dict[str, float]) -> tuple[Relaxation, list[str]]:
    """``relax`` widened to contain the motions ``seen`` (:func:`observed`), and the names of what had to be widened
    (empty: every washout's motion was within the relaxation as found). The Atlas's bounds are its limits: never
    widened."""
    if relax.kind == "atlas":
        return relax, []
    g = seen["g"]
    up = 1.0 + 1e-9
    changed: list[str] = []
    lo, hi = list(relax.gravity_lo), list(relax.gravity_hi)
    for i, key in ((0, "gx"), (1, "gy")):
        if seen[key] * g > hi[i]:
            hi[i] = min(g, seen[key] * g * up)
            lo[i] = -hi[i]
            changed.append(f"gravity_{'xy'[i]}")
    if seen["gz_low"] * g < lo[2]:
        lo[2] = seen["gz_low"] * g - 1e-9 * g
        changed.append("gravity_z")
    fields: dict[str, Any] = {"gravity_lo": tuple(lo), "gravity_hi": tuple(hi)}
    # each bound as the rows use it, what the motions reached, and the fields it sets when widened
    checks = (
        ("acc", max(relax.acc), seen["acc"], ("acc",)),
        ("vel", relax.vel_norm, seen["vel"], ("vel", "vel_norm")),
        ("pos", relax.pos_norm, seen["pos"], ("pos", "pos_norm", "start_pos")),
        ("rate", max(relax.rate), seen["rate"], ("rate",)),
        ("turn", relax.turn_step_rad, seen["turn"], ("turn_step_rad",)),
        ("rate_step", relax.rate_step, seen["rate_step"], ("rate_step",)),
    )
    for key, bound, value, names in checks:
        if math.isfinite(bound) and value > bound:
            changed.append(key)
            for name in names:
                old = getattr(relax, name)
                fields[name] = tuple(max(x, value * up) for x in old) if isinstance(old, tuple) else value * up
    if "rate_step" in changed:
        fields["ang_acc"] = max(relax.ang_acc, fields["rate_step"] / seen["dt"])
    return replace(relax, **fields), changed


__all__ = ["Relaxation", "atlas_relaxation", "hexapod_relaxation", "observed", "relaxation_of", "rig_relaxation",
           "widened"]  # fmt: skip
