"""Cueing metrics: how closely a simulator pilot's perception follows the aircraft pilot's.

Per degree of freedom (DOF), comparing the aircraft pilot's perceived signal ``x`` with a
simulator pilot's perceived signal ``y`` sampled on the same uniform grid:

* ``npc``: normalized Pearson correlation, Eqs. 20-21 with K = 1:
  ``NPC = K / (1 + PC) + 1 - K / 2``. 1.0 for perfect correlation, 1.5 for none, larger is worse.

  - PC = -1 (perfectly anti-correlated, to within 1e-12): NPC is reported as ``inf`` (the limit of
    Eq. 21; written as ``inf`` in CSV, read back as ``float('inf')``).
  - a flat signal (standard deviation at most 1e-9 of its own peak magnitude, or exactly zero)
    leaves PC undefined: NPC is ``nan`` (an empty field in CSV), never a made-up number; so do fewer than 3
    samples (two points always correlate by exactly +1 or -1: a 2-sample input gave NPC = ``inf``).

* ``integral_error``: Eq. 22, ``integral |x - y| dt`` by the trapezoid rule on the uniform grid,
  from the first to the last sample.
* ``max_error``: ``max |x - y|``.

Units in reports: surge, sway, heave come from perceived specific force x, y, z in m/s^2
(integral in m/s^2*s); roll, pitch, yaw from perceived angular velocity x, y, z in deg/s
(integral in deg). NPC has no unit.

All three come from one compiled pass over the samples (:mod:`washbench.analysis.metric_sums`), the same code
the studies' evaluation kernel runs per sample.
"""

from __future__ import annotations

import math

import numpy as np

from washbench.io.metrics_csv import MetricRow
from washbench.numerics.jitcache import announce_compile

FLAT_RTOL = 1e-9
"""A signal whose standard deviation is at most this fraction of its peak |value| is flat (the same value as
:data:`washbench.analysis.metric_sums.FLAT_RTOL`, which the compiled sums use; not imported from there so that
importing this module (DOFS, npc_from_pc: a sweep parsing its grid, a refused input) does not import numba)."""


def signal_metrics(x: np.ndarray, y: np.ndarray, dt_s: float) -> tuple[float, float, float]:
    """:func:`washbench.analysis.metric_sums.signal_metrics` (PC, integral and max of ``|x - y|``), imported at the
    first call: numba (about 0.3 s of start-up) is paid only by a command that computes a metric."""
    from washbench.analysis.metric_sums import signal_metrics as compiled  # deferred: numba

    announce_compile(compiled)
    return compiled(x, y, dt_s)

NPC_K = 1.0
"""The K of Eq. 21 used in the paper."""

ANTI_CORRELATED_TOL = 1e-12
"""PC within this of -1 counts as -1 (NPC reported as inf)."""

DOFS = ("surge", "sway", "heave", "roll", "pitch", "yaw")
"""Degrees of freedom, in the order rows are written."""


def _as_pair(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    # contiguous and writable, the one array type the compiled sums are compiled for (a column of a table would
    # otherwise compile them again for strided arrays after an install); the values are the same
    x = np.require(x, np.float64, ("C", "W"))
    y = np.require(y, np.float64, ("C", "W"))
    if x.ndim != 1 or x.shape != y.shape or x.size < 2:
        raise ValueError(f"expected two 1-D signals of equal length >= 2, got shapes {x.shape} and {y.shape}")
    return x, y


def is_flat(x: np.ndarray, rtol: float = FLAT_RTOL) -> bool:
    """True if ``x`` has (numerically) zero variance: ``std(x) <= rtol * max|x|`` (always for all zeros)."""
    x = np.asarray(x, dtype=np.float64)
    std = float(np.std(x))
    return std == 0.0 or std <= rtol * float(np.max(np.abs(x)))


def pearson(x: np.ndarray, y: np.ndarray) -> float:
    """Pearson correlation PC (Eq. 20) in [-1, 1]; ``nan`` if either signal is flat (see :func:`is_flat`)."""
    x, y = _as_pair(x, y)
    return float(signal_metrics(x, y, 1.0)[0])


def npc_from_pc(pc: float, k: float = NPC_K) -> float:
    """Eq. 21: ``k / (1 + pc) + 1 - k / 2``; ``inf`` at pc = -1 (within 1e-12), ``nan`` for nan."""
    if math.isnan(pc):
        return math.nan
    if 1.0 + pc <= ANTI_CORRELATED_TOL:
        return math.inf
    return k / (1.0 + pc) + 1.0 - k / 2.0


def npc(x: np.ndarray, y: np.ndarray, k: float = NPC_K) -> float:
    """Normalized Pearson correlation of two signals (Eqs. 20-21); 1 is perfect, larger is worse."""
    return npc_from_pc(pearson(x, y), k)


def integral_abs_error(x: np.ndarray, y: np.ndarray, dt_s: float) -> float:
    """Eq. 22: ``integral |x - y| dt`` over the trace, trapezoid rule on a uniform grid of step ``dt_s`` [s]."""
    x, y = _as_pair(x, y)
    return float(signal_metrics(x, y, float(dt_s))[1])


def max_abs_error(x: np.ndarray, y: np.ndarray) -> float:
    """``max |x - y|`` over the trace."""
    x, y = _as_pair(x, y)
    return float(signal_metrics(x, y, 1.0)[2])


def dof_metrics(
    washout: str,
    aircraft_f_mps2: np.ndarray,
    aircraft_omega_radps: np.ndarray,
    sim_f_mps2: np.ndarray,
    sim_omega_radps: np.ndarray,
    dt_s: float,
) -> list[MetricRow]:
    """The six DOF rows for one washout from perceived (N, 3) signals of aircraft and simulator pilot.

    Specific force in m/s^2 (body x, y, z -> surge, sway, heave); angular velocity in rad/s (body
    x, y, z -> roll, pitch, yaw), converted to deg/s before the metrics so the errors are in deg/s and deg.
    """
    rows = []
    pairs = [(aircraft_f_mps2, sim_f_mps2, 1.0), (aircraft_omega_radps, sim_omega_radps, 180.0 / math.pi)]
    dofs = iter(DOFS)
    for a, s, scale in pairs:
        a = np.ascontiguousarray(np.asarray(a, dtype=np.float64).T) * scale  # (3, N): contiguous per axis
        s = np.ascontiguousarray(np.asarray(s, dtype=np.float64).T) * scale
        for axis in range(3):
            pc, integral, max_error = signal_metrics(*_as_pair(a[axis], s[axis]), float(dt_s))
            rows.append(
                MetricRow(
                    washout=washout,
                    dof=next(dofs),
                    npc=npc_from_pc(float(pc)),
                    integral_error=float(integral),
                    max_error=float(max_error),
                )
            )
    return rows
