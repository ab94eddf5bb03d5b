"""Sparse linear constraints assembled a block of rows at a time, for the bound's, the ceiling's and the replay's
programmes (Clarabel's form: equalities in a zero cone, inequalities ``A x <= b`` in a non-negative cone), and the
one way they are solved (:func:`solve_qp`)."""

from __future__ import annotations

from typing import Any

import numpy as np
from scipy import sparse


class Rows:
    """Sparse rows ``A x (=|<=) b`` assembled a block of rows at a time (one row per sample)."""

    def __init__(self) -> None:
        self.eq: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
        self.eq_rhs: list[np.ndarray] = []
        self.le: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
        self.le_rhs: list[np.ndarray] = []
        self.n_eq = 0
        self.n_le = 0

    def add(self, terms: list[tuple[np.ndarray, np.ndarray | float]], rhs: np.ndarray, equal: bool) -> None:
        """Rows ``sum_j coef_j * x[idx_j] (= or <=) rhs`` for arrays ``idx_j`` of one length (one row each)."""
        m = len(rhs)
        base = self.n_eq if equal else self.n_le
        r = np.arange(base, base + m)
        rows, cols, vals = [], [], []
        for idx, coef in terms:
            rows.append(r)
            cols.append(np.asarray(idx))
            vals.append(np.broadcast_to(np.asarray(coef, dtype=np.float64), (m,)))
        block = (np.concatenate(rows), np.concatenate(cols), np.concatenate(vals))
        if equal:
            self.eq.append(block)
            self.eq_rhs.append(np.asarray(rhs, dtype=np.float64))
            self.n_eq += m
        else:
            self.le.append(block)
            self.le_rhs.append(np.asarray(rhs, dtype=np.float64))
            self.n_le += m

    def box(self, idx: np.ndarray, lo: float | np.ndarray, hi: float | np.ndarray) -> None:
        """``lo <= x[idx] <= hi``."""
        m = len(idx)
        self.add([(idx, 1.0)], np.broadcast_to(np.asarray(hi, dtype=np.float64), (m,)).copy(), equal=False)
        self.add([(idx, -1.0)], -np.broadcast_to(np.asarray(lo, dtype=np.float64), (m,)), equal=False)

    def matrices(self, nvar: int) -> tuple[sparse.csc_matrix, np.ndarray, int, int]:
        def stack(blocks, nrows):
            if not blocks:
                return sparse.csc_matrix((0, nvar))
            r = np.concatenate([b[0] for b in blocks])
            c = np.concatenate([b[1] for b in blocks])
            v = np.concatenate([b[2] for b in blocks])
            return sparse.csc_matrix((v, (r, c)), shape=(nrows, nvar))

        a = sparse.vstack([stack(self.eq, self.n_eq), stack(self.le, self.n_le)], format="csc")
        b = np.concatenate(self.eq_rhs + self.le_rhs) if (self.eq_rhs or self.le_rhs) else np.zeros(0)
        return a, b, self.n_eq, self.n_le


def trapezoid(n: int, dt: float) -> np.ndarray:
    """Trapezoid-rule weights (s) of n samples ``dt`` apart (the metrics' integral, Eq. 22)."""
    w = np.full(n, dt)
    if n > 1:
        w[0] = w[-1] = 0.5 * dt
    return w


REFINEMENT_TOL = 1e-10
"""Clarabel's iterative refinement of each linear solve stops once its residual is this small, absolute and
relative (Clarabel's defaults: 1e-12 and 1e-13). These programmes have 10^5 variables and factors of tens of
millions of entries; with the defaults the refinement (up to ten solves with the factors, twice an iteration) took
more time than the factorisations. 1e-10 took the five programmes of the bound on a 61 s flight from 16.1 s to
13.0 s; their objectives moved by 2e-7 of themselves at most, well within the tolerances they are solved to (the
bound's ``eps``, 1e-4 by default, for the attitude plan and the replay; 1e-7 for the ceiling). docs/optimal-mpc.md,
"What it costs"."""


def solve_qp(p_upper: sparse.csc_matrix, q: np.ndarray, rows: Rows, tol: float, max_iter: int,
             tol_ktratio: float | None = None) -> Any:  # fmt: skip
    """Clarabel's solution of min 1/2 x' P x + q' x subject to ``rows`` (``len(q)`` variables); ``p_upper`` is P's
    upper triangle, ``tol`` the gap and feasibility tolerances, ``tol_ktratio`` Clarabel's if given."""
    import clarabel  # deferred: only the bound and the ceiling need it

    a, b, n_eq, n_le = rows.matrices(len(q))
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    settings.max_iter = max_iter
    settings.tol_gap_abs = settings.tol_gap_rel = settings.tol_feas = tol
    if tol_ktratio is not None:
        settings.tol_ktratio = tol_ktratio
    settings.iterative_refinement_abstol = settings.iterative_refinement_reltol = REFINEMENT_TOL
    cones = [clarabel.ZeroConeT(n_eq), clarabel.NonnegativeConeT(n_le)]
    return clarabel.DefaultSolver(p_upper, q, a, b, cones, settings).solve()


__all__ = ["REFINEMENT_TOL", "Rows", "solve_qp", "trapezoid"]
