"""The felt error over a prediction horizon as slack variables of a quadratic programme, for the MPC washouts.

The ranking's measure (``washbench.analysis.felt``; docs/metrics.md, "The felt error") is a sum of convex,
piecewise-linear functions of the simulator pilot's perceived motion and head specific force. Over a prediction
horizon whose perceived errors are affine in the decisions ``z`` (the condensed prediction,
:mod:`washbench.cueing.condensed`), each term is exactly a slack variable with two rows (the epigraph of a dead
band), so the MPC can minimise a prediction of the measure itself. At K nodes of the horizon (times ``t_k``, each
standing for ``w_k`` seconds of it) and for each DOF d with threshold ``T_d`` (Zacharias 1978):

* perceived error ``e = c + P z`` (SI), normalised ``u = e / T_d``: the felt error's slack
  ``t >= u - 1, t >= -u - 1, t >= 0``, costed ``w_k t`` (threshold-seconds: ``integral max(|e| - T, 0) dt / T``);
* the simulator pilot's cue against the aircraft pilot's start ``v = (x - x0 + e) / T_d`` (``x`` the aircraft
  pilot's predicted perceived motion, ``x0`` its value at the first sample): two slacks ``p >= v - 1``,
  ``m >= -v - 1`` (both ``>= 0``), costed ``lambda w_k p`` where the aircraft pilot's cue ``x - x0`` is not above
  ``+T`` (a positive cue is false there) and ``lambda w_k m`` where it is not below ``-T``: the measure's false part
  (``lambda`` counts it again);
* the jolt of the first move, per body axis i: ``j >= |(R' (a_0 - a_prev))_i| - (J_T dt + |F_k - F_{k-1}|_i)``,
  ``j >= 0``, costed ``tau_j j / T_i``: the jerk the stage adds at the head beyond the aircraft's own and the dead
  band (the rotation's part, at most ``alpha_max g`` = 17 m/s^3 on the Atlas, is left out).

Every slack's cost is linear (plus ``eps`` times its square, so the Hessian stays positive definite for the dual
active-set solver); its rows' constants change at every sample (the bounds), their coefficients only with the
attitude the prediction is linearised about. The rows are ``lo <= A z`` with no upper bound (:data:`INF`).
"""

from __future__ import annotations

import numpy as np

INF = 1e30
"""DAQP's infinity: a bound at or beyond it is no bound."""


class FeltSlacks:
    """The slack variables and rows of the felt error over a horizon (module docstring).

    ``node_s`` (K,): the seconds each node stands for; ``units`` (6,): the DOFs' thresholds in SI (m/s^2 for the
    three specific-force axes, rad/s for the three rates); ``n_ctrl``: the number of control decisions before the
    slacks in ``z``; ``first_acc``: the columns of the first move's stage acceleration (3,) in ``z``.

    Errors are stacked as ``[force at node 0 (x, y, z), force at node 1, ..., rate at node 0, ...]`` (6K), the
    slacks ``[t (6K), p (6K), m (6K), j (3)]``.
    """

    def __init__(self, node_s: np.ndarray, units: np.ndarray, n_ctrl: int, first_acc: np.ndarray, *,
                 weight: float, false_weight: float, jolt_time_s: float, jerk_deadband_mps3: float, dt_s: float,
                 eps: float) -> None:  # fmt: skip
        self.K = K = len(node_s)
        self.node_s = np.asarray(node_s, dtype=np.float64)
        self.units = np.asarray(units, dtype=np.float64)
        self.n_ctrl = n_ctrl
        self.n_err = 6 * K
        self.n_slack = 18 * K + 3
        self.n_rows = 24 * K + 6
        self.first_acc = np.asarray(first_acc)
        self.weight = float(weight)
        self.false_weight = float(false_weight)
        self.jolt_time_s = float(jolt_time_s)
        self.jerk_allow = float(jerk_deadband_mps3) * float(dt_s)
        self.eps = float(eps)
        # per error row: its unit (force rows x, y, z at each node, then rate rows) and its node's seconds
        self.row_unit = np.concatenate([np.tile(self.units[:3], K), np.tile(self.units[3:], K)])
        self.row_s = np.concatenate([np.repeat(self.node_s, 3), np.repeat(self.node_s, 3)])
        n = n_ctrl + self.n_slack
        self.A = np.zeros((self.n_rows, n))
        E, s0 = self.n_err, n_ctrl
        eye = np.eye(E)
        self.A[0:E, s0 : s0 + E] = eye  # t - P z >= c - 1
        self.A[E : 2 * E, s0 : s0 + E] = eye  # t + P z >= -c - 1
        self.A[2 * E : 3 * E, s0 + E : s0 + 2 * E] = eye  # p - P z >= c + dx - 1
        self.A[3 * E : 4 * E, s0 + 2 * E : s0 + 3 * E] = eye  # m + P z >= -c - dx - 1
        self.A[4 * E : 4 * E + 3, s0 + 3 * E :] = np.eye(3)  # j - R' a_0 >= -R' a_prev - allow
        self.A[4 * E + 3 :, s0 + 3 * E :] = np.eye(3)  # j + R' a_0 >= R' a_prev - allow
        self._f = np.zeros(self.n_slack)
        self._f[:E] = self.weight * self.row_s
        self._f[3 * E :] = self.weight * self.jolt_time_s / self.units[:3]
        self._lo = np.empty(self.n_rows)

    def set_rows(self, P: np.ndarray, R0t: np.ndarray) -> None:
        """The rows' coefficients for the error sensitivity ``P`` (6K, n_ctrl), SI, and the cockpit's attitude
        (``R0t``: inertial to body, 3 x 3) at which the prediction is linearised."""
        E, nc = self.n_err, self.n_ctrl
        Pn = P / self.row_unit[:, None]
        self.A[0:E, :nc] = -Pn
        self.A[E : 2 * E, :nc] = Pn
        self.A[2 * E : 3 * E, :nc] = -Pn
        self.A[3 * E : 4 * E, :nc] = Pn
        jr = np.zeros((3, nc))
        jr[:, self.first_acc] = R0t
        self.A[4 * E : 4 * E + 3, :nc] = -jr
        self.A[4 * E + 3 :, :nc] = jr

    def data(self, c: np.ndarray, dx: np.ndarray, jerk_ref: np.ndarray,
             allow: np.ndarray) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
        """(row lower bounds (n_rows,), slack costs (n_slack,)) for this sample: ``c`` the errors' constant part
        (6K), SI; ``dx`` the aircraft pilot's predicted perceived motion less its start (6K), SI; ``jerk_ref``
        ``R0' a_prev`` (3,); ``allow`` the aircraft's own head-force change this sample (3,), m/s^2, |.|."""
        E = self.n_err
        cn = c / self.row_unit
        vn = cn + dx / self.row_unit
        lo = self._lo
        lo[0:E] = cn - 1.0
        lo[E : 2 * E] = -cn - 1.0
        lo[2 * E : 3 * E] = vn - 1.0
        lo[3 * E : 4 * E] = -vn - 1.0
        a = self.jerk_allow + np.abs(allow)
        lo[4 * E : 4 * E + 3] = -jerk_ref - a
        lo[4 * E + 3 :] = jerk_ref - a
        f = self._f.copy()
        cue = dx / self.row_unit  # the aircraft pilot's cue in threshold units
        w = self.weight * self.false_weight * self.row_s
        plus, minus = cue > 1.0, cue < -1.0  # a positive simulator cue is false unless the aircraft's is positive
        f[E : 2 * E] = np.where(plus, 0.0, w)
        f[2 * E : 3 * E] = np.where(minus, 0.0, w)
        lo[2 * E : 3 * E][plus] = -INF  # a slack that costs nothing is not bound either (else its eps would)
        lo[3 * E : 4 * E][minus] = -INF
        return lo, f


__all__ = ["INF", "FeltSlacks"]
