"""The washout's linear filters: continuous transfer functions, discretised once, stepped in numba.

Each filter is single-input single-output and at most second order. Its continuous transfer function
(numerator, denominator in powers of s, s in rad/s) is discretised ONCE at set-up with the bilinear
(Tustin) transform into a discrete state space (A, B, C, D) (the controllable canonical form and the
formulas of ``scipy.signal.tf2ss`` and ``cont2discrete(method="bilinear")``, written in numpy so that no
command pays the second it takes to import ``scipy.signal``), padded to two states and packed into 9
floats ``[A00, A01, A10, A11, B0, B1, C0, C1, D]``. The compiled step
is then ``y = C x + D u; x <- A x + B u``. A filter starts in the steady state of its first input
sample (:func:`filt_init`), so a constant input gives no transient.

Filters of the paper (all break frequencies wn in rad/s):

- translational high-pass ``s^2 / (s + wn)^2`` (Eq. 2), input acceleration m/s^2;
- tilt low-pass ``4 wn^2 / (s^2 + 4 wn s + 4 wn^2)`` (Eq. 3), critically damped at 2 wn;
- rotational high-pass ``s / (s + wn)`` (Eq. 6); ``wn = 0`` is the identity (unrestricted washout);
- derivative estimator ``s w2 / (s + w2)`` (Eq. 8), w2 = 12.5 rad/s by default.
"""

from __future__ import annotations

import functools

import numpy as np

from washbench.numerics.jit import njit
from washbench.numerics.statespace import tf2ss

NCOEF = 9

TransferFunction = tuple[list[float], list[float]]


def translational_highpass(wn: float) -> TransferFunction:
    """s^2 / (s + wn)^2 (paper Eq. 2)."""
    return [1.0, 0.0, 0.0], [1.0, 2.0 * wn, wn * wn]


def tilt_lowpass(wn: float) -> TransferFunction:
    """4 wn^2 / (s^2 + 4 wn s + 4 wn^2) (paper Eq. 3): unit DC gain, double pole at -2 wn."""
    return [4.0 * wn * wn], [1.0, 4.0 * wn, 4.0 * wn * wn]


def rotational_highpass(wn: float) -> TransferFunction:
    """s / (s + wn) (paper Eq. 6); wn = 0 gives the identity 1/1."""
    if wn == 0.0:
        return [1.0], [1.0]
    return [1.0, 0.0], [1.0, wn]


def derivative_estimator(w2: float) -> TransferFunction:
    """s w2 / (s + w2) (paper Eq. 8): a derivative below w2 rad/s, a gain of w2 above."""
    return [w2, 0.0], [1.0, w2]


def discretise(tf: TransferFunction, dt_s: float) -> np.ndarray:
    """Bilinear discretisation of a continuous transfer function into the packed (9,) float64 form.

    Cached per (transfer function, dt): a study builds thousands of parameter sets that share most filters.
    """
    num, den = tf
    return _discretise(tuple(map(float, num)), tuple(map(float, den)), float(dt_s)).copy()


@functools.lru_cache(maxsize=4096)
def _discretise(num: tuple[float, ...], den: tuple[float, ...], dt_s: float) -> np.ndarray:
    coef = np.zeros(NCOEF)
    if len(den) == 1:  # static gain
        coef[8] = num[-1] / den[0]
        return coef
    n = len(den) - 1
    if n > 2:
        raise ValueError(f"filter order {n} > 2 is not supported")
    a, b, c, d = tf2ss(num, den)
    # bilinear transform (generalised bilinear with alpha = 1/2), as scipy.signal.cont2discrete does it
    ima = np.eye(n) - 0.5 * dt_s * a
    ad = np.linalg.solve(ima, np.eye(n) + 0.5 * dt_s * a)
    bd = np.linalg.solve(ima, dt_s * b)
    cd = np.linalg.solve(ima.T, c.T).T
    dd = d + 0.5 * (c @ bd)
    a2 = np.zeros((2, 2))
    a2[:n, :n] = ad
    coef[0:4] = a2.ravel()
    coef[4 : 4 + n] = bd[:, 0]
    coef[6 : 6 + n] = cd[0, :]
    coef[8] = dd[0, 0]
    return coef


@njit(cache=True)
def filt_init(c: np.ndarray, x: np.ndarray, u: float) -> None:
    """Set state ``x`` (2,) to the steady state of a constant input ``u``: x = (I - A)^-1 B u."""
    a00 = 1.0 - c[0]
    a01 = -c[1]
    a10 = -c[2]
    a11 = 1.0 - c[3]
    det = a00 * a11 - a01 * a10
    if det == 0.0:
        x[0] = 0.0
        x[1] = 0.0
        return
    b0 = c[4] * u
    b1 = c[5] * u
    x[0] = (a11 * b0 - a01 * b1) / det
    x[1] = (a00 * b1 - a10 * b0) / det


@njit(cache=True)
def filt_step(c: np.ndarray, x: np.ndarray, u: float) -> float:
    """One sample: return y = C x + D u and advance x <- A x + B u (in place)."""
    x0 = x[0]
    x1 = x[1]
    y = c[6] * x0 + c[7] * x1 + c[8] * u
    x[0] = c[0] * x0 + c[1] * x1 + c[4] * u
    x[1] = c[2] * x0 + c[3] * x1 + c[5] * u
    return y


@njit(cache=True)
def run_filter(c: np.ndarray, u: np.ndarray, steady_start: bool) -> np.ndarray:
    """Run one packed filter over a whole input array (N,); start at rest or in the first sample's steady state."""
    x = np.zeros(2)
    y = np.empty(u.shape[0])
    if steady_start and u.shape[0] > 0:
        filt_init(c, x, u[0])
    for k in range(u.shape[0]):
        y[k] = filt_step(c, x, u[k])
    return y
