"""Motion-sickness dose: MSDV (ISO 2631-1, weighting Wf) of the vertical motion at a pilot's head.

**Wf** (ISO 2631-1:1997, motion sickness, z axis) is the product of four analogue filters (s = j 2 pi f,
w_i = 2 pi f_i):

- band-limiting high-pass  ``s^2 / (s^2 + w1 s / Q1 + w1^2)``, f1 = 0.08 Hz, Q1 = 1/sqrt(2);
- band-limiting low-pass   ``w2^2 / (s^2 + w2 s / Q2 + w2^2)``, f2 = 0.63 Hz, Q2 = 1/sqrt(2);
- acceleration-velocity transition ``(1 + s / w3) / (1 + s / (Q4 w4) + s^2 / w4^2)``, f3 = infinity (numerator 1),
  f4 = 0.25 Hz, Q4 = 0.86;
- upward step ``(s^2 + w5 s / Q5 + w5^2) / (s^2 + w6 s / Q6 + w6^2)``, f5 = 0.0625 Hz, Q5 = 0.80,
  f6 = 0.1 Hz, Q6 = 0.80;

with gain K = 1. Its magnitude peaks at about 1.0 near 0.16 Hz.

**MSDV** = ``sqrt(integral a_w(t)^2 dt)`` [m/s^1.5] over the manoeuvre, ``a_w`` the Wf-weighted vertical
acceleration. The vertical acceleration at the head is taken from the specific force along the body z axis (down)
as its deviation from rest, ``a_z = -(f_z + g0)`` (up positive; the sign does not change the MSDV, and Wf removes
any constant). For a pilot sitting upright this is the seat-to-head z axis of ISO 2631-1.

Discretisation: the bilinear transform of the analogue Wf at the trace's step, as second-order sections (at 60 Hz
and above the magnitude is within 1e-5 of the analogue's up to 0.16 Hz, 0.15 % at 0.63 Hz and 0.4 % at 1 Hz,
where Wf is 0.06); the filter starts at rest and the input is the
deviation from rest, so a trace that starts in steady 1 g flight starts without a transient.

The parameter values are those of ISO 2631-1:1997 as commonly reproduced; the standard itself was not available
to this project. The tests check the filter against the weighting values tabulated for Wf (0.1-0.63 Hz) and a
sinusoid's MSDV against its closed form ``|Wf(f)| A sqrt(T / 2)``.
"""

from __future__ import annotations

import math

import numpy as np

from washbench.io.units import G0_MPS2
from washbench.numerics.lazyjit import lazy_njit  # numba imported at the first compiled call, not here

WF_PARAMS = {
    "f1_hz": 0.08, "q1": 1.0 / math.sqrt(2.0),
    "f2_hz": 0.63, "q2": 1.0 / math.sqrt(2.0),
    "f4_hz": 0.25, "q4": 0.86,
    "f5_hz": 0.0625, "q5": 0.80,
    "f6_hz": 0.1, "q6": 0.80,
}  # fmt: skip
"""ISO 2631-1 Wf (module docstring); f3 is infinite."""


def wf_tf() -> tuple[np.ndarray, np.ndarray]:
    """The analogue Wf as (numerator, denominator) polynomial coefficients in s (highest power first)."""
    p = WF_PARAMS
    w1, w2, w4, w5, w6 = (2.0 * math.pi * p[k] for k in ("f1_hz", "f2_hz", "f4_hz", "f5_hz", "f6_hz"))
    num = np.polymul(np.polymul([1.0, 0.0, 0.0], [w2 * w2]), [1.0, w5 / p["q5"], w5 * w5])
    num = np.polymul(num, [w4 * w4])  # transition: w4^2 / (s^2 + w4 s / Q4 + w4^2)
    den = np.polymul([1.0, w1 / p["q1"], w1 * w1], [1.0, w2 / p["q2"], w2 * w2])
    den = np.polymul(den, [1.0, w4 / p["q4"], w4 * w4])
    den = np.polymul(den, [1.0, w6 / p["q6"], w6 * w6])
    return num, den


def wf_factors() -> list[tuple[tuple[float, float, float], tuple[float, float, float]]]:
    """The four analogue factors of Wf as ((b2, b1, b0), (a2, a1, a0)): ``(b2 s^2 + b1 s + b0) / (a2 s^2 + ...)``."""
    p = WF_PARAMS
    w1, w2, w4, w5, w6 = (2.0 * math.pi * p[k] for k in ("f1_hz", "f2_hz", "f4_hz", "f5_hz", "f6_hz"))
    return [
        ((1.0, 0.0, 0.0), (1.0, w1 / p["q1"], w1 * w1)),
        ((0.0, 0.0, w2 * w2), (1.0, w2 / p["q2"], w2 * w2)),
        ((0.0, 0.0, w4 * w4), (1.0, w4 / p["q4"], w4 * w4)),
        ((1.0, w5 / p["q5"], w5 * w5), (1.0, w6 / p["q6"], w6 * w6)),
    ]


def wf_sos(dt_s: float) -> np.ndarray:
    """Wf discretised by the bilinear transform at step ``dt_s`` [s]: second-order sections (4, 6) in scipy's
    layout ``[b0, b1, b2, 1, a1, a2]`` (coefficients of z^0, z^-1, z^-2), one per analogue factor.

    ``s = K (1 - z^-1) / (1 + z^-1)``, ``K = 2 / dt``, applied to each factor by hand (no scipy import at run time).
    """
    if not (math.isfinite(dt_s) and dt_s > 0.0):
        raise ValueError(f"dt must be a positive number of seconds, got {dt_s!r}")
    k = 2.0 / dt_s
    rows = []
    for (b2, b1, b0), (a2, a1, a0) in wf_factors():
        nb = (b2 * k * k + b1 * k + b0, 2.0 * (b0 - b2 * k * k), b2 * k * k - b1 * k + b0)
        na = (a2 * k * k + a1 * k + a0, 2.0 * (a0 - a2 * k * k), a2 * k * k - a1 * k + a0)
        rows.append([nb[0] / na[0], nb[1] / na[0], nb[2] / na[0], 1.0, na[1] / na[0], na[2] / na[0]])
    return np.array(rows)


def sos_filter(sos: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Filter ``x`` (N,) through second-order sections (S, 6) from rest (direct form II transposed), as
    ``scipy.signal.sosfilt`` does, without importing scipy."""
    y = np.asarray(x, dtype=np.float64).copy()
    for b0, b1, b2, _, a1, a2 in np.asarray(sos, dtype=np.float64):
        y = _biquad(float(b0), float(b1), float(b2), float(a1), float(a2), y)
    return y


@lazy_njit(cache=True)
def _biquad(b0: float, b1: float, b2: float, a1: float, a2: float, x: np.ndarray) -> np.ndarray:
    y = np.empty_like(x)
    z1 = 0.0
    z2 = 0.0
    for i in range(x.shape[0]):
        xi = x[i]
        yi = b0 * xi + z1
        z1 = b1 * xi - a1 * yi + z2
        z2 = b2 * xi - a2 * yi
        y[i] = yi
    return y


def vertical_acceleration(f_z_mps2: np.ndarray) -> np.ndarray:
    """Vertical acceleration at the head (up positive) [m/s^2] from the body-z specific force (N,): -(f_z + g0)."""
    return -(np.asarray(f_z_mps2, dtype=np.float64) + G0_MPS2)


def wf_weighted(a_mps2: np.ndarray, dt_s: float) -> np.ndarray:
    """The Wf-weighted acceleration (N,) of ``a_mps2`` (N,), filter starting at rest."""
    return sos_filter(wf_sos(dt_s), a_mps2)


def msdv(a_mps2: np.ndarray, dt_s: float) -> float:
    """MSDV [m/s^1.5] of a vertical acceleration (N,) sampled every ``dt_s``: sqrt(sum a_w^2 dt) (rectangle rule).

    The sum is a plain loop in sample order (:func:`_sum_squares`), not ``np.dot``: BLAS splits a dot product by
    its thread count (a Dask worker runs BLAS on one thread, this process on as many as there are cores), and the
    last bit of the MSDV differed between a run on a cluster and a local one."""
    aw = wf_weighted(a_mps2, dt_s)
    return float(math.sqrt(_sum_squares(aw) * dt_s))


@lazy_njit(cache=True)
def _sum_squares(x: np.ndarray) -> float:
    """sum x_i^2 in index order (no reassociation: the same bits in every process, whatever its BLAS threads)."""
    acc = 0.0
    for i in range(x.shape[0]):
        acc += x[i] * x[i]
    return acc


def head_msdv(f_z_mps2: np.ndarray, dt_s: float) -> float:
    """MSDV [m/s^1.5] of the vertical motion at a pilot's head, from its body-z specific force (N,) [m/s^2]."""
    return msdv(vertical_acceleration(f_z_mps2), dt_s)
