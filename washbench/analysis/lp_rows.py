"""Sparse linear constraints assembled a block of rows at a time, for the bound's, the ceiling's and the replay's
programmes (equalities ``A x = b`` and inequalities ``A x <= b``), and the one way they are solved (:func:`solve_qp`:
PIQP, the inequalities of one variable as its bounds)."""

from __future__ import annotations

from dataclasses import dataclass

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

    def matrices(self, nvar: int) -> tuple[sparse.csc_matrix, np.ndarray, sparse.csr_matrix, np.ndarray]:
        """``(A_eq, b_eq, A_le, b_le)`` over ``nvar`` variables (the inequalities by rows, for :func:`split_bounds`);
        duplicate entries of a row are summed."""

        def stack(blocks: list, nrows: int, fmt: type) -> sparse.spmatrix:
            if not blocks:
                return fmt((0, nvar))
            r = np.concatenate([b[0] for b in blocks])
            c = np.concatenate([b[1] for b in blocks])
            v = np.concatenate([b[2] for b in blocks])
            return fmt((v, (r, c)), shape=(nrows, nvar))

        def rhs(parts: list[np.ndarray]) -> np.ndarray:
            return np.concatenate(parts) if parts else np.zeros(0)

        return (stack(self.eq, self.n_eq, sparse.csc_matrix), rhs(self.eq_rhs),
                stack(self.le, self.n_le, sparse.csr_matrix), rhs(self.le_rhs))  # fmt: skip


def trapezoid(n: int, dt: float) -> np.ndarray:
    """Trapezoid-rule weights (s) of n samples ``dt`` apart (the metrics' integral, Eq. 22)."""
    w = np.full(n, dt)
    if n > 1:
        w[0] = w[-1] = 0.5 * dt
    return w


SOLVER_STATUS = {
    "PIQP_SOLVED": "Solved",
    "PIQP_MAX_ITER_REACHED": "MaxIterations",
    "PIQP_PRIMAL_INFEASIBLE": "PrimalInfeasible",
    "PIQP_DUAL_INFEASIBLE": "DualInfeasible",
    "PIQP_NUMERICS": "NumericalError",
    "PIQP_UNSOLVED": "Unsolved",
}
"""PIQP's statuses as the files name them (``ceiling.csv``, ``run.json``: the names the files had with the interior-
point solver used before, Clarabel; ``Solved`` is the one a result is taken from)."""


INFEASIBILITY_EPS = 1e-12
"""PIQP's primal and dual infeasibility tolerances (its defaults: 1e-8 and 1e-8). Every programme here is feasible
and bounded by construction (a still platform satisfies them all), but with the defaults PIQP declared a ceiling's
LP primal infeasible part-way (the heave of a 2.2 g doublet, ``tests/test_ceiling.py``) that it solves in 37
iterations with this tolerance, to Clarabel's objective within 3e-7: a certificate of infeasibility here would be a
numerical artefact, not a fact about the flight."""


@dataclass(frozen=True)
class QpSolution:
    """A programme's solution: ``x`` the last iterate, ``status`` (:data:`SOLVER_STATUS`), the primal and dual
    objectives and the interior-point iterations."""

    x: np.ndarray
    status: str
    obj_val: float
    obj_val_dual: float
    iterations: int


def split_bounds(le: sparse.csr_matrix, h: np.ndarray) -> tuple[
        sparse.csc_matrix, np.ndarray, np.ndarray, np.ndarray]:  # fmt: skip
    """The inequalities ``le x <= h`` as PIQP takes them: those of more than one variable ``(G, h_G)``, and those of
    one (a non-zero coefficient) as bounds ``x_l <= x <= x_u`` (-inf and +inf where none; the tightest where several
    rows bound one variable)."""
    starts = le.indptr[:-1]
    single = np.diff(le.indptr) == 1
    single[single] = le.data[starts[single]] != 0.0
    col, coef = le.indices[starts[single]], le.data[starts[single]]
    limit = h[single] / coef
    x_u = np.full(le.shape[1], np.inf)
    x_l = np.full(le.shape[1], -np.inf)
    up = coef > 0.0
    np.minimum.at(x_u, col[up], limit[up])
    np.maximum.at(x_l, col[~up], limit[~up])
    return le[~single].tocsc(), h[~single], x_l, x_u


def solve_qp(p_upper: sparse.csc_matrix, q: np.ndarray, rows: Rows, tol: float, max_iter: int,
             reg_lower_limit: float | None = None) -> QpSolution:  # fmt: skip
    """PIQP's solution (a proximal interior-point method) of min 1/2 x' P x + q' x subject to ``rows`` (``len(q)``
    variables); ``p_upper`` is P's upper triangle, ``tol`` the absolute and relative tolerances of the residuals and
    of the duality gap; ``reg_lower_limit``: the least proximal regularisation (PIQP's default, 1e-10, without it;
    the best achieved's search takes 1e-8, :data:`washbench.analysis.felt_programme.REG_LOWER_LIMIT`).

    PIQP, not Clarabel as before: it takes the rows of one variable as bounds of that variable instead of as rows of
    the KKT system (most of these programmes' inequalities), and on the bound's five programmes of a 61 s flight it
    took 4.6 s where Clarabel took 12.5 s, its objectives within the tolerance of Clarabel's (docs/optimal-mpc.md,
    "What it costs")."""
    import piqp  # deferred: only the bound and the ceiling need it

    a_eq, b_eq, a_le, b_le = rows.matrices(len(q))
    g, h, x_l, x_u = split_bounds(a_le, b_le)
    solver = piqp.SparseSolver()
    settings = solver.settings
    settings.verbose = False
    settings.max_iter = max_iter
    settings.eps_abs = settings.eps_rel = tol
    settings.eps_duality_gap_abs = settings.eps_duality_gap_rel = tol
    settings.eps_primal_inf = settings.eps_dual_inf = INFEASIBILITY_EPS
    if reg_lower_limit is not None:
        settings.reg_lower_limit = reg_lower_limit
    solver.setup(sparse.csc_matrix(p_upper), np.asarray(q, dtype=np.float64), a_eq, b_eq, g,
                 np.full(len(h), -np.inf), h, x_l, x_u)  # fmt: skip
    status = solver.solve()
    info = solver.result.info
    name = SOLVER_STATUS.get(status.name)
    if name is None:  # PIQP_INVALID_SETTINGS: a tolerance or a count out of PIQP's range, not the programme
        raise ValueError(f"PIQP refused the settings: {status.name}")
    return QpSolution(np.array(solver.result.x, dtype=np.float64), name, float(info.primal_obj),
                      float(info.dual_obj), int(info.iter))  # fmt: skip


__all__ = ["INFEASIBILITY_EPS", "SOLVER_STATUS", "QpSolution", "Rows", "solve_qp", "split_bounds", "trapezoid"]
