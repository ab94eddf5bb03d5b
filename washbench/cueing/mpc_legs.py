"""The MPC washout's hexapod constraints: the legs' lengths and speeds, linearised about the current pose.

On a hexapod (:class:`washbench.platform.hexapod.HexapodModel`) the ``mpc`` washout plans against the legs instead of
the box about neutral's positions (docs/optimal-mpc.md, "On a hexapod"). Its pose at node k is

    y_k = [p_k; eta_k]

with p_k the platform position (the motion reference point from neutral, inertial NED, m) and eta_k the cockpit's
ZYX Euler angles (roll phi, pitch theta, yaw psi, rad; the set point's attitude is q_z(psi) q_y(theta) q_x(phi),
body -> inertial, each of roll and pitch the sum of its tilt and rotational parts). With l(y) the six leg lengths
(:func:`washbench.platform.hexapod.leg_lengths`) and y_0 the current pose, every node k = 1..N of the plan keeps

    l_mid - margin h  <=  l(y_0) + G(y_0) (y_k - y_0)  <=  l_mid + margin h                         (lengths)

(l_mid the mid-stroke length, h the half stroke, margin ``limit_margin``), and the first :data:`LEG_RATE_MOVES`
moves keep the legs' speed

    | G(y_0) [v; eta_dot] |  <=  margin v_leg        at both ends of the move (v at its nodes k and k+1)  (speeds)

where G = J(y_0) blockdiag(I_3, E(eta_0)): J the legs' Jacobian (:func:`washbench.platform.hexapod.leg_jacobian`,
rows [u_i, (R a_i) x u_i] for a displacement and a small rotation about inertial axes) and E the map from ZYX Euler
angle rates to the inertial angular velocity (:func:`euler_rate_matrix`). The linearisation is the first-order
Taylor expansion of l about the current pose, made again at every sample (the successive linearisation of
nonlinear MPC).
"""

from __future__ import annotations

import math

import numpy as np

from washbench.platform.hexapod import HexapodModel

LEG_RATE_MOVES = 3
"""The legs' speed is constrained on the plan's first this-many moves (both ends of each; the first is applied)."""


def euler_rate_matrix(phi_rad: float, theta_rad: float, psi_rad: float) -> np.ndarray:
    """E (3, 3): the inertial angular velocity (rad/s, NED axes) per ZYX Euler-angle rate [phi', theta', psi'] (rad/s)
    at the attitude q_z(psi) q_y(theta) q_x(phi): columns R_z(psi) R_y(theta) e_x, R_z(psi) e_y, e_z. (A change
    d eta of the angles is the small inertial rotation E d eta: q <- exp(E d eta) q, to first order.)"""
    cp, sp = math.cos(psi_rad), math.sin(psi_rad)
    ct, st = math.cos(theta_rad), math.sin(theta_rad)
    return np.array([[cp * ct, -sp, 0.0], [sp * ct, cp, 0.0], [-st, 0.0, 1.0]])


def rotation_of_euler(eta_rad: np.ndarray) -> np.ndarray:
    """R (3, 3), body -> inertial, of ZYX Euler angles eta = [phi, theta, psi] (rad): R_z(psi) R_y(theta) R_x(phi)."""
    cf, sf = math.cos(eta_rad[0]), math.sin(eta_rad[0])
    ct, st = math.cos(eta_rad[1]), math.sin(eta_rad[1])
    cp, sp = math.cos(eta_rad[2]), math.sin(eta_rad[2])
    return np.array([
        [cp * ct, cp * st * sf - sp * cf, cp * st * cf + sp * sf],
        [sp * ct, sp * st * sf + cp * cf, sp * st * cf - cp * sf],
        [-st, ct * sf, ct * cf],
    ])  # fmt: skip


def pose_legs(model: HexapodModel, pose: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(l (6,), G (6, 6)) at the pose [p (m, NED from neutral); eta (rad, ZYX)]: the leg lengths (m) and their
    derivative with respect to the pose, m per m and m per rad (G = J blockdiag(I_3, E), the module docstring).
    Vectorised over the legs (the MPC calls it every sample); the same quantities as
    :func:`washbench.platform.hexapod.leg_lengths` and :func:`~washbench.platform.hexapod.leg_jacobian`."""
    return _legs_at(np.asarray(model.base_joints_m, dtype=np.float64),
                    np.asarray(model.platform_joints_m, dtype=np.float64),
                    np.asarray(model.neutral_m, dtype=np.float64), pose)  # fmt: skip


def _legs_at(
    base: np.ndarray, plat: np.ndarray, neutral: np.ndarray, pose: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    ra = plat @ rotation_of_euler(pose[3:]).T  # (6, 3) R a_i
    d = neutral + pose[:3] + ra - base
    legs = np.sqrt(np.einsum("ij,ij->i", d, d))
    u = d / legs[:, None]
    g = np.empty((6, 6))
    g[:, :3] = u
    moment = np.column_stack([ra[:, 1] * u[:, 2] - ra[:, 2] * u[:, 1], ra[:, 2] * u[:, 0] - ra[:, 0] * u[:, 2],
                              ra[:, 0] * u[:, 1] - ra[:, 1] * u[:, 0]])  # fmt: skip
    g[:, 3:] = moment @ euler_rate_matrix(float(pose[3]), float(pose[4]), float(pose[5]))
    return legs, g


class LegRows:
    """The constraint rows of the legs for the condensed QP, rebuilt from the current pose at every sample.

    ``pose_z`` (N, 6, nz) and ``pose_w`` (N, 6, nw): the pose of nodes 1..N as ``pose_z[k] z + pose_w[k] w``;
    ``rate_z`` (K, 2, 6, nz) and ``rate_w`` (K, 2, 6, nw): [v; eta_dot] at the start and the end of moves 0..K-1
    likewise (v at the move's two nodes, eta_dot the move's angle rates). The ``_z`` parts may be given in the QP's
    whitened variables (:class:`washbench.cueing.condensed.WhitenedQp`): the rows are linear in them.
    """

    def __init__(self, model: HexapodModel, margin: float, pose_z: np.ndarray, pose_w: np.ndarray,
                 rate_z: np.ndarray, rate_w: np.ndarray) -> None:  # fmt: skip
        self.model = model
        self._geometry = (np.asarray(model.base_joints_m, dtype=np.float64),
                          np.asarray(model.platform_joints_m, dtype=np.float64),
                          np.asarray(model.neutral_m, dtype=np.float64))  # fmt: skip
        lo, hi = model.leg_length_m.min, model.leg_length_m.max
        mid, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
        self.len_lo = mid - margin * half
        self.len_hi = mid + margin * half
        self.speed = margin * model.leg_velocity_limit_mps
        self.pose_z, self.pose_w = pose_z, pose_w
        self.rate_z, self.rate_w = rate_z, rate_w
        self.n_rows = 6 * pose_z.shape[0] + 12 * rate_z.shape[0]

    def at(self, pose: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:func:`pose_legs` of this hexapod."""
        return _legs_at(*self._geometry, pose)

    def rows(self, pose0: np.ndarray, w: np.ndarray, out: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The rows of ``lo <= rows z <= hi`` for the current pose ``pose0`` (6,) and the solve's parameters ``w``,
        written into ``out`` (n_rows, nz): the lengths at nodes 1..N, then the speeds of the first moves; returns
        (lo, hi)."""
        legs, g = self.at(pose0)
        n_len = 6 * self.pose_z.shape[0]
        np.matmul(g, self.pose_z, out=out[:n_len].reshape(self.pose_z.shape))
        np.matmul(g, self.rate_z, out=out[n_len:].reshape(self.rate_z.shape))
        len_off = ((self.pose_w @ w) @ g.T + (legs - g @ pose0)).ravel()
        rate_off = ((self.rate_w @ w) @ g.T).ravel()
        lo = np.concatenate([self.len_lo - len_off, -self.speed - rate_off])
        hi = np.concatenate([self.len_hi - len_off, self.speed - rate_off])
        return lo, hi


__all__ = ["LEG_RATE_MOVES", "LegRows", "euler_rate_matrix", "pose_legs", "rotation_of_euler"]
