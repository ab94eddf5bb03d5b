"""Linear per-channel model of simulator motion and perception, for the optimal and MPC washouts and the bound.

Linearised about a level cockpit at heading 0 (small angles; body axes = inertial NED axes), SI units. The
aircraft pilot-head input of one channel is ``r`` (deviation of the specific force from level flight,
``f - [0, 0, -g]``, m/s^2, and/or the body rate, rad/s); the simulator's controls ``u`` are the platform's
inertial acceleration (m/s^2) and the cockpit's angular rate (rad/s). Four channels, independent in this model:

==========  ===================  ==================  =================================================
channel     aircraft input r     controls u          simulator head signals (small angle)
==========  ===================  ==================  =================================================
``pitch``   f_x, omega_y         a_x, q              f_x = a_x + g theta,  omega_y = q
``roll``    f_y, omega_x         a_y, p              f_y = a_y - g phi,    omega_x = p
``heave``   f_z + g              a_z                 f_z + g = a_z
``yaw``     omega_z              r                   omega_z = r
==========  ===================  ==================  =================================================

(signs: a cockpit pitched nose up by theta at rest feels f_x = +g sin(theta); rolled right by phi it feels
f_y = -g sin(phi); see docs/cueing.md.)

State of a channel (continuous, ``dx/dt = A x + B u + E r``)::

    x = [x_oto (2 per force axis) | x_can (3 per rate axis) | angle | position, velocity]

with ``x_oto``, ``x_can`` the states of the **error** vestibular models, driven by (simulator - aircraft) head
signals, so their outputs ``e = C x`` are the perceived errors (perceived simulator minus perceived aircraft
motion, Eqs. 11-12 of the paper: both models are linear, so the difference of the perceptions is the
perception of the difference when both start from the same state). Both models are strictly proper, so the
errors have no direct feed-through.

Functions here are pure (matrices in, matrices out); :func:`channel_model` builds one channel.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy import linalg

from washbench.numerics.statespace import tf2ss
from washbench.perception.vestibular import CanalParams, OtolithParams, canal_tf, otolith_tf

CHANNELS: tuple[str, ...] = ("pitch", "roll", "heave", "yaw")


@dataclass(frozen=True)
class ChannelModel:
    """One channel's continuous linear model (see the module docstring).

    A (n, n), B (n, m) controls, E (n, k) aircraft input; C_err (k, n): perceived errors [otolith (m/s^2) then
    canal (rad/s), in the order of the aircraft inputs]; C_head (k, n) + D_head (k, m): the simulator head signals
    (the same order) as functions of state and control. Index fields give state positions (-1 if absent):
    ``i_angle`` (rad), ``i_pos`` (m), ``i_vel`` (m/s). ``controls``: the names of u.
    """

    name: str
    A: np.ndarray
    B: np.ndarray
    E: np.ndarray
    C_err: np.ndarray
    C_head: np.ndarray
    D_head: np.ndarray
    i_angle: int
    i_pos: int
    i_vel: int
    n_vest: int
    controls: tuple[str, ...]
    inputs: tuple[str, ...]
    force_inputs: int  # the first ``force_inputs`` of r (and rows of C_err) are specific forces, the rest rates
    i_int: int = -1  # the integral of position (m s), if the model was built with it


def with_position_integral(model: ChannelModel) -> ChannelModel:
    """The model with one more state, the time integral of the platform position (m s), ``d(int p)/dt = p``.

    Weighting it (Telban and Cardullo's ``int x_s`` state) makes the position's steady state zero under a constant
    input. A channel without position is returned unchanged.
    """
    if model.i_pos < 0:
        return model
    n, m = model.B.shape
    A = np.zeros((n + 1, n + 1))
    A[:n, :n] = model.A
    A[n, model.i_pos] = 1.0
    pad = np.zeros((1, n + 1))

    def grow(M: np.ndarray) -> np.ndarray:
        return np.hstack([M, np.zeros((M.shape[0], 1))])

    return replace(
        model,
        A=A,
        B=np.vstack([model.B, np.zeros((1, m))]),
        E=np.vstack([model.E, pad[:, : model.E.shape[1]]]),
        C_err=grow(model.C_err),
        C_head=grow(model.C_head),
        i_int=n,
    )


def _ss(num: np.ndarray, den: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    a, b, c, d = tf2ss(num, den)
    if np.any(np.abs(d) > 0.0):
        raise ValueError("vestibular model must be strictly proper")
    return a, b, c


def channel_model(name: str, otolith: OtolithParams, canals: CanalParams, gravity_mps2: float) -> ChannelModel:
    """The continuous model of channel ``name`` (:data:`CHANNELS`)."""
    if name not in CHANNELS:
        raise ValueError(f"unknown channel {name!r} (valid: {', '.join(CHANNELS)})")
    ao, bo, co = _ss(*otolith_tf(otolith))
    ac, bc, cc = _ss(*canal_tf(canals))
    g = float(gravity_mps2)
    if name in ("pitch", "roll"):
        sign = 1.0 if name == "pitch" else -1.0  # f_x = a_x + g theta; f_y = a_y - g phi
        # x = [oto(2), can(3), angle, pos, vel]; u = [a, rate]; r = [f, omega]
        n = 8
        A = np.zeros((n, n))
        B = np.zeros((n, 2))
        E = np.zeros((n, 2))
        A[0:2, 0:2] = ao
        A[0:2, 5:6] = bo * sign * g  # otolith error driven by (a + sign g angle - f)
        B[0:2, 0:1] = bo
        E[0:2, 0:1] = -bo
        A[2:5, 2:5] = ac
        B[2:5, 1:2] = bc
        E[2:5, 1:2] = -bc
        B[5, 1] = 1.0  # d angle / dt = rate
        A[6, 7] = 1.0  # d pos / dt = vel
        B[7, 0] = 1.0  # d vel / dt = a
        C_err = np.zeros((2, n))
        C_err[0, 0:2] = co[0]
        C_err[1, 2:5] = cc[0]
        C_head = np.zeros((2, n))
        C_head[0, 5] = sign * g
        D_head = np.array([[1.0, 0.0], [0.0, 1.0]])
        axis = "x" if name == "pitch" else "y"
        rate = "omega_y" if name == "pitch" else "omega_x"
        return ChannelModel(
            name, A, B, E, C_err, C_head, D_head, 5, 6, 7, 5, (f"a_{axis}", rate), (f"f_{axis}", rate), 1
        )
    if name == "heave":
        # x = [oto(2), pos, vel]; u = [a_z]; r = [f_z + g]
        n = 4
        A = np.zeros((n, n))
        B = np.zeros((n, 1))
        E = np.zeros((n, 1))
        A[0:2, 0:2] = ao
        B[0:2, 0:1] = bo
        E[0:2, 0:1] = -bo
        A[2, 3] = 1.0
        B[3, 0] = 1.0
        C_err = np.zeros((1, n))
        C_err[0, 0:2] = co[0]
        return ChannelModel(name, A, B, E, C_err, np.zeros((1, n)), np.ones((1, 1)), -1, 2, 3, 2, ("a_z",), ("f_z",), 1)
    # yaw: x = [can(3), angle]; u = [r]; r = [omega_z]
    n = 4
    A = np.zeros((n, n))
    B = np.zeros((n, 1))
    E = np.zeros((n, 1))
    A[0:3, 0:3] = ac
    B[0:3, 0:1] = bc
    E[0:3, 0:1] = -bc
    B[3, 0] = 1.0
    C_err = np.zeros((1, n))
    C_err[0, 0:3] = cc[0]
    return ChannelModel(
        name, A, B, E, C_err, np.zeros((1, n)), np.ones((1, 1)), 3, -1, -1, 3, ("omega_z",), ("omega_z",), 0
    )


def channel_inputs(name: str, f_mps2: np.ndarray, omega_radps: np.ndarray, gravity_mps2: float) -> np.ndarray:
    """The aircraft input r of channel ``name`` from head specific force and body rate, (N, 3) each -> (N, k)."""
    f = np.asarray(f_mps2, dtype=np.float64)
    w = np.asarray(omega_radps, dtype=np.float64)
    if name == "pitch":
        return np.stack([f[..., 0], w[..., 1]], axis=-1)
    if name == "roll":
        return np.stack([f[..., 1], w[..., 0]], axis=-1)
    if name == "heave":
        return (f[..., 2] + gravity_mps2)[..., None]
    if name == "yaw":
        return w[..., 2][..., None]
    raise ValueError(f"unknown channel {name!r}")


def discretise_zoh(A: np.ndarray, B: np.ndarray, dt_s: float) -> tuple[np.ndarray, np.ndarray]:
    """Exact discretisation for an input held over the step: (Phi, Gamma) with x+ = Phi x + Gamma u."""
    n, m = B.shape
    M = np.zeros((n + m, n + m))
    M[:n, :n] = A
    M[:n, n:] = B
    eM = linalg.expm(M * dt_s)
    return eM[:n, :n], eM[:n, n:]


def discretise_foh(A: np.ndarray, B: np.ndarray, dt_s: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Exact discretisation for an input linear between samples (first-order hold, as ``scipy.signal.lsim``).

    Returns (Phi, G0, G1) with ``x[k+1] = Phi x[k] + G0 u[k] + G1 u[k+1]``; states keep their meaning. From
    expm of [[A, B, 0], [0, 0, I/dt], [0, 0, 0]] dt = [[Phi, F0, F1], ...]: G0 = F0 - F1, G1 = F1.
    """
    n, m = B.shape
    M = np.zeros((n + 2 * m, n + 2 * m))
    M[:n, :n] = A * dt_s
    M[:n, n : n + m] = B * dt_s
    M[n : n + m, n + m :] = np.eye(m)
    eM = linalg.expm(M)
    phi = eM[:n, :n]
    f0 = eM[:n, n : n + m]
    f1 = eM[:n, n + m :]
    return phi, f0 - f1, f1


__all__ = [
    "CHANNELS",
    "ChannelModel",
    "channel_inputs",
    "channel_model",
    "discretise_foh",
    "discretise_zoh",
    "with_position_integral",
]
