"""Predicted motion-sickness incidence (MSI, %) by the subjective vertical conflict (SVC) model, 6-DOF "In1" form.

The SVC theory (Bos and Bles 1998) says sickness grows with the conflict between the vertical the senses give
(``v_s``) and the vertical an internal model of the body's own dynamics expects (``hv_s``). Bos and Bles wrote it
for vertical motion; Kamiji et al. (2007) and Wada et al. (2018) extended it to 6 DOF with the semicircular canals,
and Inoue, Liu and Wada (2023, "In1") revised the internal model and its parameters. This module is that In1 model
as published by its author (T. Wada, public MATLAB reference ``sixdofSVC_IN1_public.m`` and parameter file
``setSVCIN1Param.m``, MIT licence; equations in docs/fidelity.md). Inputs at the head, body axes: the specific
force ``f`` [m/s^2] (the gravito-inertial acceleration, ``[0, 0, -g0]`` at rest in washbench's z-down axes; the
model is unchanged by flipping the sign of every vector) and the angular velocity ``omega`` [rad/s].

State (23): canal ``x_scc, dx_scc``, sensed vertical ``v_s``, internal-model vertical ``hv_s``, internal canal
``x_hscc``, conflict integral ``x_vc``, gravity in head axes ``g``, and ``dMSI, MSI``::

    omega_s  = s^2 tau_d tau_a / ((tau_d s + 1)(tau_a s + 1)) omega        (canals, with adaptation)
    v_s'     = (f - v_s) / tau - omega_s x v_s                             (sensed vertical, low-pass)
    a        = f - g,   a_s = f - v_s
    hf       = (K_a a + K_vc x_vc + K_ac (a_s + hv_s)) / (1 + K_ac)
    homega_s = (x_hscc + K_w omega + K_wc omega_s) / (1 + K_wc)
    hv_s'    = (hf - hv_s) / tau - homega_s x hv_s                         (internal-model vertical)
    x_hscc'  = -(x_hscc + K_w omega + K_wc (omega_s - homega_s)) / tau_d
    x_vc'    = v_s - hv_s
    g'       = -omega x g,  |g| = g0
    h        = (|v_s - hv_s| / b)^n / (1 + (|v_s - hv_s| / b)^n)          (Hill function)
    tau_I^2 MSI'' + 2 tau_I MSI' + MSI = P h                               (second-order lag)

For vertical motion only (omega = 0, f = [0, 0, -(g0 + a)]) it is linear up to the Hill function, with the
conflict ``|v_s - hv_s| = |G(s) a|``::

    G(s) = (1 - K_a) s / ((1 + K_ac) tau s^2 + s + K_vc)

(:func:`vertical_conflict_tf`), a band-pass peaking at ``sqrt(K_vc / ((1 + K_ac) tau))`` = 1.29 rad/s (0.205 Hz)
with the In1 values; and after a long sinusoidal exposure of amplitude ``A`` the incidence settles at
``P (1 - 1 / sqrt(1 + (|G| A / b)^2))`` (n = 2; :func:`steady_msi_vertical`).

Discretisation: classic Runge-Kutta (RK4) per sample step with the input linear between samples, ``g``
renormalised to ``g0`` after each step (as the reference does after its Euler step). The model starts in the
steady state of its first input sample held still (zero conflict, MSI = 0), the state the reference reaches by
iterating a held input (from rest, upright, where that sample is zero: free fall fixes no vertical); a stream
fed in chunks gives the same bits as the whole trace.
"""

from __future__ import annotations

import math
from dataclasses import astuple, dataclass

import numpy as np

from washbench.io.units import G0_MPS2
from washbench.numerics.lazyjit import lazy_njit  # numba imported at the first compiled call, not here


@dataclass(frozen=True)
class SvcParams:
    """Parameters of the 6-DOF SVC model (gains dimensionless, times in s, ``b_mps2`` in m/s^2, ``p_pct`` in %).

    Defaults: In1 of Inoue, Liu and Wada (2023), as in the author's ``setSVCIN1Param.m``.
    """

    k_a: float = 0.1
    k_w: float = 0.1
    k_wc: float = 10.0
    k_vc: float = 5.0
    k_ac: float = 0.5
    tau_d_s: float = 7.0
    tau_a_s: float = 190.0
    tau_s: float = 2.0
    b_mps2: float = 0.5
    tau_i_s: float = 720.0
    p_pct: float = 85.0
    n: float = 2.0

    def __post_init__(self) -> None:
        for name, v in zip(self.__dataclass_fields__, astuple(self), strict=True):
            if not (math.isfinite(v) and v >= 0.0):
                raise ValueError(f"SVC parameter {name} must be a finite number >= 0, got {v!r}")
        for name in ("k_vc", "tau_d_s", "tau_a_s", "tau_s", "b_mps2", "tau_i_s", "n"):
            if getattr(self, name) <= 0.0:
                raise ValueError(f"SVC parameter {name} must be positive, got {getattr(self, name)!r}")


IN1 = SvcParams()
"""Inoue, Liu and Wada (2023), model In1: the default."""
WADA2018 = SvcParams(k_a=0.1, k_w=0.8, k_wc=5.0, k_vc=5.0, k_ac=1.0, tau_s=5.0)
"""Wada, Fujisawa and Doi (2018), as quoted (commented out) in the same parameter file."""

MODEL_NAME = "6dof-svc-in1"
"""The model's name in the provenance (:func:`sickness_record`)."""


def sickness_record(params: SvcParams = IN1) -> dict[str, object]:
    """Provenance of the sickness numbers: the MSDV weighting and the MSI model with its parameter values."""
    name = MODEL_NAME if params == IN1 else "6dof-svc"
    return {
        "msdv": "ISO 2631-1 Wf",
        "msi": {"model": name, "values": dict(zip(params.__dataclass_fields__, astuple(params), strict=True))},
    }


N_STATE = 23
_V_S, _HV_S, _X_VC, _G, _MSI = 6, 9, 15, 18, 22


def vertical_conflict_tf(p: SvcParams = IN1) -> tuple[np.ndarray, np.ndarray]:
    """Closed form of the conflict for vertical motion only: ``(1 - K_a) s / ((1 + K_ac) tau s^2 + s + K_vc)``
    from the vertical acceleration [m/s^2] to ``v_s - hv_s`` [m/s^2], as (numerator, denominator) in s."""
    return np.array([1.0 - p.k_a, 0.0]), np.array([(1.0 + p.k_ac) * p.tau_s, 1.0, p.k_vc])


def steady_msi_vertical(amplitude_mps2: float, f_hz: float, p: SvcParams = IN1) -> float:
    """MSI [%] a vertical sinusoid of ``amplitude_mps2`` at ``f_hz`` settles at (long exposure, n = 2 only):
    ``P (1 - 1 / sqrt(1 + k^2))``, ``k = |G(j 2 pi f)| A / b`` (the mean of the Hill function over a period)."""
    if p.n != 2.0:
        raise ValueError("the closed form holds for the Hill exponent n = 2 only")
    num, den = vertical_conflict_tf(p)
    s = 2j * math.pi * f_hz
    k = abs(np.polyval(num, s) / np.polyval(den, s)) * amplitude_mps2 / p.b_mps2
    return p.p_pct * (1.0 - 1.0 / math.sqrt(1.0 + k * k))


def steady_state(f_mps2: np.ndarray, p: SvcParams = IN1) -> np.ndarray:
    """The state (23,) in which a head holding the specific force ``f_mps2`` (3,) still stays: no rotation, sensed
    and internal verticals equal to ``f``, gravity ``g0 f / |f|``, MSI 0 (``x_vc`` from ``hf = f``)."""
    f = np.asarray(f_mps2, dtype=np.float64)
    norm = float(np.linalg.norm(f))
    if not (f.shape == (3,) and math.isfinite(norm) and norm > 0.0):
        raise ValueError(f"the first specific force must be a finite, non-zero 3-vector, got {f_mps2!r}")
    x = np.zeros(N_STATE)
    g = f * (G0_MPS2 / norm)
    x[_V_S : _V_S + 3] = f
    x[_HV_S : _HV_S + 3] = f
    x[_X_VC : _X_VC + 3] = (f - p.k_a * (f - g)) / p.k_vc
    x[_G : _G + 3] = g
    return x


@lazy_njit(cache=True)
def _cross(a: np.ndarray, ia: int, b: np.ndarray, ib: int, out: np.ndarray, io: int, sign: float) -> None:
    out[io] += sign * (a[ia + 1] * b[ib + 2] - a[ia + 2] * b[ib + 1])
    out[io + 1] += sign * (a[ia + 2] * b[ib] - a[ia] * b[ib + 2])
    out[io + 2] += sign * (a[ia] * b[ib + 1] - a[ia + 1] * b[ib])


@lazy_njit(cache=True)
def _deriv(x: np.ndarray, u: np.ndarray, prm: np.ndarray, out: np.ndarray, tmp: np.ndarray) -> None:
    """dx/dt into ``out`` for input ``u = [omega (3), f (3)]`` (``prm``: :func:`_coefficients`)."""
    ka, kw, kwc, kvc, kac = prm[0], prm[1], prm[2], prm[3], prm[4]
    c1, c0, inv_tau, inv_kac1, inv_kwc1, inv_taud = prm[5], prm[6], prm[7], prm[8], prm[9], prm[10]
    inv_b2, taui, inv_taui2, pp, n, square = prm[11], prm[12], prm[13], prm[14], prm[15], prm[16]
    d2 = 0.0
    for i in range(3):
        w = u[i]
        f = u[3 + i]
        oms = c1 * x[3 + i] + c0 * x[i] + w  # tmp[0:3]: omega_s
        hf = (ka * (f - x[18 + i]) + kvc * x[15 + i] + kac * (f - x[6 + i] + x[9 + i])) * inv_kac1
        homs = (x[12 + i] + kw * w + kwc * oms) * inv_kwc1  # tmp[3:6]: internal omega_s
        tmp[i] = oms
        tmp[3 + i] = homs
        out[i] = x[3 + i]
        out[3 + i] = -c1 * x[3 + i] - c0 * x[i] - w
        out[6 + i] = (f - x[6 + i]) * inv_tau
        out[9 + i] = (hf - x[9 + i]) * inv_tau
        out[12 + i] = -(x[12 + i] + kw * w + kwc * (oms - homs)) * inv_taud
        dv = x[6 + i] - x[9 + i]
        out[15 + i] = dv
        out[18 + i] = 0.0
        d2 += dv * dv
    _cross(tmp, 0, x, 6, out, 6, -1.0)
    _cross(tmp, 3, x, 9, out, 9, -1.0)
    _cross(u, 0, x, 18, out, 18, -1.0)
    r = d2 * inv_b2 if square else (d2 * inv_b2) ** (0.5 * n)  # (c / b)^n, c = |v_s - hv_s|
    out[21] = (-2.0 * taui * x[21] - x[22] + pp * r / (1.0 + r)) * inv_taui2
    out[22] = x[21]


def _coefficients(p: SvcParams) -> np.ndarray:
    """The parameters as the compiled loop uses them (reciprocals precomputed)."""
    return np.array([
        p.k_a, p.k_w, p.k_wc, p.k_vc, p.k_ac,
        1.0 / p.tau_d_s + 1.0 / p.tau_a_s, 1.0 / (p.tau_d_s * p.tau_a_s), 1.0 / p.tau_s, 1.0 / (1.0 + p.k_ac),
        1.0 / (1.0 + p.k_wc), 1.0 / p.tau_d_s, 1.0 / (p.b_mps2 * p.b_mps2), p.tau_i_s, 1.0 / (p.tau_i_s * p.tau_i_s),
        p.p_pct, p.n, 1.0 if p.n == 2.0 else 0.0,
    ])  # fmt: skip


@lazy_njit(cache=True)
def _run(
    x: np.ndarray, u_prev: np.ndarray, u: np.ndarray, dt: float, prm: np.ndarray, g0: float,
    msi: np.ndarray, conflict: np.ndarray,
) -> None:  # fmt: skip
    """Advance ``x`` (in place) over the samples ``u`` (N, 6), the previous sample being ``u_prev`` (6,) (updated);
    MSI and conflict at each sample into ``msi``, ``conflict`` (N,)."""
    nx = x.shape[0]
    k1 = np.empty(nx)
    k2 = np.empty(nx)
    k3 = np.empty(nx)
    k4 = np.empty(nx)
    xs = np.empty(nx)
    tmp = np.empty(6)
    um = np.empty(6)
    for j in range(u.shape[0]):
        for i in range(6):
            um[i] = 0.5 * (u_prev[i] + u[j, i])
        _deriv(x, u_prev, prm, k1, tmp)
        for i in range(nx):
            xs[i] = x[i] + 0.5 * dt * k1[i]
        _deriv(xs, um, prm, k2, tmp)
        for i in range(nx):
            xs[i] = x[i] + 0.5 * dt * k2[i]
        _deriv(xs, um, prm, k3, tmp)
        for i in range(nx):
            xs[i] = x[i] + dt * k3[i]
        _deriv(xs, u[j], prm, k4, tmp)
        for i in range(nx):
            x[i] += dt * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]) / 6.0
        gn = math.sqrt(x[18] * x[18] + x[19] * x[19] + x[20] * x[20])
        for i in range(18, 21):
            x[i] *= g0 / gn
        for i in range(6):
            u_prev[i] = u[j, i]
        msi[j] = x[22]
        d2 = 0.0
        for i in range(3):
            d2 += (x[6 + i] - x[9 + i]) ** 2
        conflict[j] = math.sqrt(d2)


@dataclass(frozen=True)
class SvcOutput:
    """The model's outputs at each sample: ``msi_pct`` (N,) [%] and the conflict ``|v_s - hv_s|`` (N,) [m/s^2]."""

    msi_pct: np.ndarray
    conflict_mps2: np.ndarray


class SvcStream:
    """One pilot's SVC model fed chunk by chunk (the same bits as :func:`svc_msi` on the whole trace).

    It starts in :func:`steady_state` of the first sample of the first chunk, or of rest (``start="rest"``:
    ``f = [0, 0, -g0]``; also where the first sample has no specific force at all, which fixes no vertical).
    """

    def __init__(self, dt_s: float, params: SvcParams = IN1, start: str = "steady") -> None:
        if not (math.isfinite(dt_s) and dt_s > 0.0):
            raise ValueError(f"dt must be a positive number of seconds, got {dt_s!r}")
        if start not in ("steady", "rest"):
            raise ValueError(f"unknown start {start!r} (valid: steady, rest)")
        self.dt_s = float(dt_s)
        self.params = params
        self._prm = _coefficients(params)
        self._x: np.ndarray | None = None
        self._u_prev = np.zeros(6)
        if start == "rest":
            self._x = steady_state(np.array([0.0, 0.0, -G0_MPS2]), params)
            self._u_prev[3:] = (0.0, 0.0, -G0_MPS2)

    def update(self, f_mps2: np.ndarray, omega_radps: np.ndarray) -> SvcOutput:
        """The next samples: head specific force and angular velocity (N, 3) each, body axes."""
        f = np.asarray(f_mps2, dtype=np.float64)
        w = np.asarray(omega_radps, dtype=np.float64)
        if f.ndim != 2 or f.shape[1] != 3 or w.shape != f.shape:
            raise ValueError(f"f and omega must both have shape (N, 3), got {f.shape} and {w.shape}")
        u = np.ascontiguousarray(np.hstack([w, f]))
        n = u.shape[0]
        msi = np.empty(n)
        conflict = np.empty(n)
        if n == 0:
            return SvcOutput(msi, conflict)
        first = 0
        if self._x is None:  # a first sample with no specific force (free fall, an all-zero file): from rest
            held = f[0] if np.all(np.isfinite(f[0])) and np.any(f[0] != 0.0) else np.array([0.0, 0.0, -G0_MPS2])
            self._x = steady_state(held, self.params)
            self._u_prev[:] = u[0]
            msi[0], conflict[0] = 0.0, 0.0
            first = 1
        _run(self._x, self._u_prev, u[first:], self.dt_s, self._prm, G0_MPS2, msi[first:], conflict[first:])
        return SvcOutput(msi, conflict)

    @property
    def msi_pct(self) -> float:
        """MSI [%] at the last sample fed (NaN before any)."""
        return math.nan if self._x is None else float(self._x[_MSI])


def svc_msi(
    f_mps2: np.ndarray, omega_radps: np.ndarray, dt_s: float, params: SvcParams = IN1, start: str = "steady"
) -> SvcOutput:
    """MSI [%] and conflict [m/s^2] at each sample of a head motion: specific force (N, 3) [m/s^2] and angular
    velocity (N, 3) [rad/s], body axes, every ``dt_s`` seconds."""
    return SvcStream(dt_s, params, start).update(f_mps2, omega_radps)


def head_msi(
    f_mps2: np.ndarray, omega_radps: np.ndarray, dt_s: float, params: SvcParams = IN1, start: str = "steady"
) -> float:
    """Predicted motion-sickness incidence [%] at the end of a head motion (see :func:`svc_msi`)."""
    out = svc_msi(f_mps2, omega_radps, dt_s, params, start)
    return float(out.msi_pct[-1]) if out.msi_pct.size else math.nan
