"""Condensed (dense) prediction matrices for the MPC washouts, and the dense QP solver they share (DAQP).

A prediction over ``N`` intervals of ``tp`` seconds, inputs held over each interval (zero-order hold), of a
single-input single-output model ``dx/dt = A x + B u``, ``y = C x`` (strictly proper) is

    y_{k+1} = C Phi^{k+1} x_0 + sum_{j<=k} C Phi^{k-j} Gamma u_j,         k = 0 .. N-1,

i.e. ``y = F x_0 + T u`` with ``T`` lower-triangular Toeplitz (:func:`siso_prediction`). The washouts' axes share one
vestibular model per organ (the paper's Eqs. 11-12 have the same constants on every axis), so a three-axis
prediction is a Kronecker product ``T (x) I_3`` and the per-step cost matrices of the MPC washouts are sums of
Kronecker products of these ``N x N`` matrices with 3 x 3 matrices that depend on the cockpit's attitude
(docs/optimal-mpc.md, "mpc-unrestricted"). Move blocking (one decision held over several intervals,
:func:`blocking_matrix`) multiplies every prediction matrix on the right.

:class:`DenseQp` wraps DAQP (Arnström, Bemporad and Axehill, "A dual active-set solver for embedded quadratic
programming using recursive LDL^T updates", IEEE TAC 67(8), 2022): a dual active-set method for small dense QPs,
warm-started from the previous step's active set, exact (no iteration tolerance on optimality beyond rounding).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import linalg

from washbench.cueing.motion_model import discretise_zoh
from washbench.errors import WashbenchError
from washbench.io.cost import horizon_intervals
from washbench.numerics.statespace import tf2ss


@dataclass(frozen=True)
class SisoPrediction:
    """``y_{1..N} = F x_0 + T u_{0..N-1}`` of one SISO model (see the module docstring); ``Phi``, ``Gamma``, ``C``:
    its exact discretisation at ``tp`` (for propagating the state)."""

    free: np.ndarray  # F (N, n)
    T: np.ndarray  # (N, N)
    A: np.ndarray  # continuous (n, n)
    B: np.ndarray  # continuous (n,)
    C: np.ndarray  # (n,)


def siso_state_space(num: np.ndarray, den: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(A (n, n), B (n,), C (n,)) of a strictly proper transfer function ``num/den`` (coefficients in s)."""
    a, b, c, d = tf2ss(num, den)
    if np.any(np.abs(d) > 0.0):
        raise ValueError("the model must be strictly proper")
    return a, b[:, 0], c[0]


def siso_prediction(num: np.ndarray, den: np.ndarray, tp_s: float, n_steps: int) -> SisoPrediction:
    """The prediction matrices of ``num/den`` over ``n_steps`` intervals of ``tp_s`` seconds (ZOH)."""
    a, b, c = siso_state_space(num, den)
    phi, gam = discretise_zoh(a, b[:, None], tp_s)
    n = a.shape[0]
    o = np.empty((n_steps, n))
    h = np.empty(n_steps)  # Markov parameters C Phi^i Gamma
    p = np.eye(n)
    for i in range(n_steps):
        h[i] = c @ p @ gam[:, 0]
        p = phi @ p
        o[i] = c @ p
    t = np.zeros((n_steps, n_steps))
    for i in range(n_steps):
        t[i:, i] = h[: n_steps - i]
    return SisoPrediction(free=o, T=t, A=a, B=b, C=c)


def default_blocks(n_steps: int) -> tuple[int, ...]:
    """Move-blocking lengths (intervals per decision) covering ``n_steps``: 1, 1, 1, 2, 2, 2, 3, 3, 4, 4, 5, 5, ...

    Fine moves first (the first is the one applied), coarser ones later; a remainder of at most half a move joins
    the last one. 20 intervals take 9 moves (1, 1, 1, 2, 2, 2, 3, 3, 5).
    """
    out: list[int] = []
    total = 0
    while total < n_steps:
        i = len(out)
        length = 1 + i // 3 if i < 6 else 3 + (i - 6) // 2
        take = min(length, n_steps - total)
        if take <= length // 2:  # a short remainder joins the last move
            out[-1] += take
        else:
            out.append(take)
        total += take
    return tuple(out)


def blocking_matrix(blocks: tuple[int, ...]) -> np.ndarray:
    """(N, M) 0/1 matrix mapping M held moves to N = sum(blocks) intervals."""
    n = int(sum(blocks))
    out = np.zeros((n, len(blocks)))
    row = 0
    for j, b in enumerate(blocks):
        out[row : row + b, j] = 1.0
        row += b
    return out


def rows_kron3(m: np.ndarray) -> np.ndarray:
    """``m (x) I_3``: the three-axis form of a per-axis matrix, for node-major vectors (index 3 k + axis)."""
    return np.kron(m, np.eye(3))


def horizon_reference(
    current: np.ndarray,
    mean: np.ndarray,
    decay: np.ndarray,
    future: np.ndarray | None,
    index: int,
    preview_s: float,
    tp_s: float,
    dt_s: float,
) -> np.ndarray:
    """The aircraft input over a horizon's intervals (N, k), for the MPC washouts: the ``current`` input (k,)
    returning to its recent ``mean`` as ``decay`` (N,: e^{-gamma tp j}); with a recording ``future`` (n, k) of which
    ``index`` is the current sample and ``preview_s`` > 0, the samples at the intervals' midpoints (at ``tp_s``,
    samples ``dt_s`` apart, the last one held past the end) as far as the preview reaches, and beyond it the last
    previewed value returning to the mean the same way. ``decay`` may be (N, k): one per input."""
    n_int = decay.shape[0]
    d = decay if decay.ndim == 2 else decay[:, None]
    out = mean + d * (current - mean)
    if future is None or preview_s <= 0.0:
        return out
    mid = tp_s * (np.arange(n_int) + 0.5)
    seen = mid <= preview_s + 1e-9
    idx = np.minimum(index + np.rint(mid / dt_s).astype(np.int64), len(future) - 1)
    out[seen] = future[idx[seen]]
    j = int(np.count_nonzero(seen))
    if 0 < j < n_int:
        out[j:] = mean + d[: n_int - j] * (out[j - 1] - mean)
    return out


def stage_limits(limits: object) -> tuple[np.ndarray, np.ndarray, np.ndarray, float, float]:
    """The limits an MPC plans against, in SI: the stage's position, velocity and acceleration limits per inertial
    axis (3,) each (m, m/s, m/s^2) and the rotation's rate and angular-acceleration limits (rad/s, rad/s^2), from
    Atlas-shaped ``limits`` (:class:`washbench.platform.limits.PlatformLimits`, or the box about neutral that stands
    for another platform); WashbenchError (one line) without them (a platform plugin without ``envelope``)."""
    if not (hasattr(limits, "translation") and hasattr(limits, "rotation")):
        raise WashbenchError("an MPC washout plans against the platform's envelope (Atlas-shaped limits), which this "
                             "platform does not give (a platform plugin needs envelope(params))")  # fmt: skip
    t, r = limits.translation, limits.rotation
    return (np.array(t.position_limit_m.xyz), np.array(t.velocity_limit_mps.xyz),
            np.array(t.acceleration_limit_mps2.xyz), math.radians(r.rate_limit_degps),
            math.radians(r.acceleration_limit_degps2))  # fmt: skip


def horizon_problem(horizon_steps: int, preview_s: float, prediction_step_s: float, iter_limit: int, largest: int,
                    max_work: int) -> str | None:  # fmt: skip
    """Why an MPC section's horizon is too large (one phrase), or None: its intervals (:func:`horizon_intervals`,
    preview included) at most ``largest``, and the intervals times ``iter_limit`` at most ``max_work``."""
    n = horizon_intervals(horizon_steps, preview_s, prediction_step_s)
    if n > largest:
        return (f"preview_s {preview_s:g} / prediction_step_s {prediction_step_s:g} makes {n:,} prediction intervals, "
                f"more than the horizon's limit of {largest} (the QP grows with the square of the intervals and its "
                f"building with their cube); a prediction_step_s of at least {preview_s / largest:.4g} s or a "
                f"preview_s of at most {largest * prediction_step_s:.4g} s")  # fmt: skip
    work = n * iter_limit
    if work > max_work:
        what = f"horizon_steps {horizon_steps}" if n == horizon_steps else f"a horizon of {n} intervals (preview_s)"
        return (f"{what} x solver.iter_limit {iter_limit} = {work:,}: more than {max_work:,} (the QP's size times "
                "its iterations, per sample: hours per minute of flight); lower one of them")  # fmt: skip
    return None


def preview_needs_recording(section: dict) -> bool:
    """An MPC washout's ``whole_only`` (:func:`washbench.cueing.registry.needs_whole`): with ``preview_s`` > 0 in
    its parameter section it needs the recording in advance (cued after the flight, by its ``trace``)."""
    value = section.get("preview_s", 0.0)
    return isinstance(value, int | float) and value > 0.0


class DenseQp:
    """``minimise 1/2 z' H z + f' z`` s.t. ``lo <= z <= hi`` (simple bounds), ``lo_A <= A z <= hi_A`` (rows with
    ``eq`` True: equalities) by DAQP, the workspace kept between solves (warm start from the last active set).

    ``solve`` returns (ok, z, iterations); ``ok`` is False unless DAQP reports an optimal solution (exit flag 1 or
    2, "optimal" and "soft optimal") with a finite result.
    """

    def __init__(self, n: int, A: np.ndarray, eq: np.ndarray, iter_limit: int) -> None:
        import daqp  # deferred: daqp (imported when an MPC washout is made)

        self.n = n
        self.A = np.ascontiguousarray(A, dtype=np.float64)
        m = n + self.A.shape[0]
        self.sense = np.zeros(m, dtype=np.int32)
        self.sense[n:][np.asarray(eq, dtype=bool)] = 5
        self._model = daqp.Model()
        self._ready = False
        self.iter_limit = int(iter_limit)

    def set_iter_limit(self, iter_limit: int) -> None:
        """Change the iteration limit of later solves."""
        self.iter_limit = int(iter_limit)
        if self._ready:
            self._model.settings = {"iter_limit": self.iter_limit}

    def solve(self, H: np.ndarray, f: np.ndarray, lo: np.ndarray, hi: np.ndarray, h_changed: bool = True,
              A: np.ndarray | None = None) -> tuple[bool, np.ndarray, int]:  # fmt: skip
        """Solve with this step's data (``lo``/``hi``: simple bounds then the rows of ``A``; ``A``: new rows' matrix,
        the same shape, or None to keep the last)."""
        if A is not None:
            self.A = np.ascontiguousarray(A, dtype=np.float64)
        if not self._ready:
            flag, _ = self._model.setup(H, f, self.A, hi, lo, self.sense)
            self._model.settings = {"iter_limit": self.iter_limit}
            self._ready = flag >= 0
            if not self._ready:
                return False, np.zeros(self.n), 0
        elif A is not None:
            self._model.update(H=H, f=f, A=self.A, bupper=hi, blower=lo)
        elif h_changed:
            self._model.update(H=H, f=f, bupper=hi, blower=lo)
        else:
            self._model.update(f=f, bupper=hi, blower=lo)
        x, _, flag, info = self._model.solve()
        z = np.asarray(x, dtype=np.float64)
        ok = flag in (1, 2) and z.shape == (self.n,) and bool(np.all(np.isfinite(z)))
        return ok, z, int(info.get("iterations", 0))


class WhitenedQp:
    """``minimise 1/2 z' H z + f' z`` s.t. ``lo <= z <= hi``, ``lo_A <= A z <= hi_A`` (fixed rows; ``eq`` True:
    equalities) and ``lo_V <= V z <= hi_V`` (rows that change at every solve), H fixed, by DAQP in the whitened
    variables y = R z (H = R' R, R upper triangular): 1/2 y' y + (R^-T f)' y, every row times R^-1, the simple
    bounds on z rows R^-1 of their own. Rows (and simple bounds) that ``bounded`` marks False (both bounds
    infinite, for every solve) are left out.

    DAQP keeps M = A R^-1 and rebuilds it (O(rows n^2)) whenever A changes; with H = I here its update is a copy,
    and the changing rows come already whitened (:meth:`whiten` of their fixed factors, once), so a solve with new
    rows costs O(rows n), not O(rows n^2). The workspace is kept between solves (warm start from the last active
    set). ``solve`` returns (ok, z, iterations) as :meth:`DenseQp.solve`.
    """

    def __init__(self, H: np.ndarray, A: np.ndarray, eq: np.ndarray, n_var: int, iter_limit: int,
                 bounded: np.ndarray) -> None:  # fmt: skip
        import daqp  # deferred: daqp (imported when an MPC washout is made)

        self.n = n = H.shape[0]
        r = linalg.cholesky(0.5 * (H + H.T), lower=False)
        self.r_inv = linalg.solve_triangular(r, np.eye(n), lower=False)
        self._keep = np.flatnonzero(bounded)
        fixed = np.vstack([self.r_inv, np.asarray(A, dtype=np.float64) @ self.r_inv])[self._keep]
        self.n_fixed = fixed.shape[0]
        self.A = np.zeros((self.n_fixed + n_var, n))
        self.A[: self.n_fixed] = fixed
        self.sense = np.zeros(self.A.shape[0], dtype=np.int32)
        equality = np.concatenate([np.zeros(n, dtype=bool), np.asarray(eq, dtype=bool)])
        self.sense[: self.n_fixed][equality[self._keep]] = 5
        self._eye = np.eye(n)
        self._model = daqp.Model()
        self._ready = False
        self.iter_limit = int(iter_limit)

    def whiten(self, rows: np.ndarray) -> np.ndarray:
        """Rows acting on z (..., n) as rows acting on y: ``rows R^-1``."""
        return rows @ self.r_inv

    @property
    def var_rows(self) -> np.ndarray:
        """The changing rows, whitened (n_var, n): a view to write this solve's rows into."""
        return self.A[self.n_fixed :]

    def solve(self, f: np.ndarray, lo: np.ndarray, hi: np.ndarray, var_lo: np.ndarray,
              var_hi: np.ndarray) -> tuple[bool, np.ndarray, int]:  # fmt: skip
        """Solve with this step's data: ``lo``/``hi`` for the simple bounds then the fixed rows, the bounds of the
        changing rows (written into :attr:`var_rows` before); ``lo``/``hi`` cover every row, those left out too."""
        fy = self.r_inv.T @ f
        up = np.concatenate([hi[self._keep], var_hi])
        low = np.concatenate([lo[self._keep], var_lo])
        if not self._ready:
            flag, _ = self._model.setup(self._eye, fy, self.A, up, low, self.sense)
            self._model.settings = {"iter_limit": self.iter_limit}
            self._ready = flag >= 0
            if not self._ready:
                return False, np.zeros(self.n), 0
        else:
            self._model.update(f=fy, A=self.A, bupper=up, blower=low)
        y, _, flag, info = self._model.solve()
        y = np.asarray(y, dtype=np.float64)
        ok = flag in (1, 2) and y.shape == (self.n,) and bool(np.all(np.isfinite(y)))
        return ok, (self.r_inv @ y if ok else np.zeros(self.n)), int(info.get("iterations", 0))


__all__ = [
    "DenseQp",
    "SisoPrediction",
    "WhitenedQp",
    "blocking_matrix",
    "default_blocks",
    "horizon_problem",
    "horizon_reference",
    "preview_needs_recording",
    "rows_kron3",
    "siso_prediction",
    "siso_state_space",
    "stage_limits",
]
