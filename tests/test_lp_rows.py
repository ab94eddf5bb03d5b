"""The one way the bound's, the replay's and the ceiling's programmes are solved (``washbench.analysis.lp_rows``):
the rows split into equalities, inequalities and bounds without changing the feasible set, and PIQP's solution
against scipy's HiGHS (an independent LP solver) and against a closed-form QP."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import sparse
from scipy.optimize import linprog

from washbench.analysis.lp_rows import SOLVER_STATUS, Rows, solve_qp, split_bounds


def random_rows(rng: np.random.Generator, n: int) -> Rows:
    """Equalities, inequalities of several variables and of one (some repeated, one with a zero coefficient)."""
    rows = Rows()
    idx = np.arange(n)
    rows.add([(idx[:2], rng.normal(size=2)), (idx[2:4], 1.0)], np.zeros(2), equal=True)  # x = 0 is feasible
    rows.add([(idx, rng.normal(size=n)), (np.roll(idx, 1), rng.normal(size=n))], rng.uniform(0.5, 2.0, n), equal=False)
    rows.box(idx, -rng.uniform(0.5, 2.0, n), rng.uniform(0.5, 2.0, n))
    rows.box(idx[: n // 2], -rng.uniform(0.5, 2.0, n // 2), rng.uniform(0.5, 2.0, n // 2))  # tighter or not
    rows.add([(idx[:1], 0.0)], np.array([1.0]), equal=False)  # 0 <= 1: a row, not a bound
    return rows


@settings(max_examples=40, deadline=None, derandomize=True)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(4, 9))
def test_split_keeps_the_feasible_set(seed: int, n: int) -> None:
    """A point satisfies every original row iff it satisfies the equalities, G x <= h and x_l <= x <= x_u."""
    rng = np.random.default_rng(seed)
    rows = random_rows(rng, n)
    a, b, n_eq, _ = rows.matrices(n)
    a_eq, b_eq, g, h, x_l, x_u = split_bounds(a, b, n_eq)
    dense = a.toarray()
    assert np.array_equal(a_eq.toarray(), dense[:n_eq]) and np.array_equal(b_eq, b[:n_eq])
    assert g.shape[0] == n + 1  # the two-variable rows and the zero-coefficient one
    for x in rng.uniform(-2.5, 2.5, (400, n)):
        original = bool(np.all(dense[n_eq:] @ x <= b[n_eq:]))
        split = bool(np.all(g @ x <= h) and np.all(x_l <= x) and np.all(x <= x_u))
        assert original == split


def test_an_lp_has_highs_optimum_and_a_dual_bound_below_it() -> None:
    """The ceiling's use: an LP's primal objective equals HiGHS's optimum, its dual objective lies at most the
    tolerance above it."""
    rng = np.random.default_rng(7)
    n = 30
    rows = random_rows(rng, n)
    a, b, n_eq, _ = rows.matrices(n)
    c = rng.normal(size=n)
    ref = linprog(c, A_ub=a[n_eq:].toarray(), b_ub=b[n_eq:], A_eq=a[:n_eq].toarray(), b_eq=b[:n_eq],
                  bounds=(None, None), method="highs")  # fmt: skip
    assert ref.status == 0
    sol = solve_qp(sparse.csc_matrix((n, n)), c, rows, 1e-9, 200)
    assert sol.status == "Solved"
    assert sol.obj_val == pytest.approx(ref.fun, rel=1e-6, abs=1e-8)
    assert sol.obj_val_dual <= ref.fun + 1e-6 * max(1.0, abs(ref.fun))
    assert np.all(a[n_eq:] @ sol.x <= b[n_eq:] + 1e-7)


def test_a_projection_onto_a_box_and_a_plane_is_the_closed_form() -> None:
    """min 1/2 |x - c|^2 subject to sum(x) = s and lo <= x <= hi: x = clip(c - nu, lo, hi) with nu found by
    bisection (the projection's KKT conditions)."""
    rng = np.random.default_rng(3)
    n = 12
    c = rng.normal(size=n) * 2.0
    lo, hi, s = -np.ones(n), np.ones(n), 1.5
    rows = Rows()
    rows.add([(np.array([k]), 1.0) for k in range(n)], np.array([s]), equal=True)
    rows.box(np.arange(n), lo, hi)
    sol = solve_qp(sparse.identity(n, format="csc"), -c, rows, 1e-10, 200)
    a, b = -10.0, 10.0
    for _ in range(200):
        nu = 0.5 * (a + b)
        a, b = (nu, b) if np.clip(c - nu, lo, hi).sum() > s else (a, nu)
    assert sol.status == "Solved"
    np.testing.assert_allclose(sol.x, np.clip(c - nu, lo, hi), atol=1e-7)


def test_an_infeasible_programme_is_not_solved() -> None:
    """x <= -1 and x >= 1: no solution is reported as one (the status is what the files record)."""
    rows = Rows()
    rows.box(np.array([0]), -np.inf, -1.0)
    rows.add([(np.array([0]), 1.0), (np.array([1]), 1.0)], np.array([5.0]), equal=False)
    rows.add([(np.array([0]), -1.0), (np.array([1]), 0.5)], np.array([-1.0]), equal=False)
    rows.box(np.array([1]), 0.0, 0.0)
    sol = solve_qp(sparse.csc_matrix((2, 2)), np.array([1.0, 0.0]), rows, 1e-8, 100)
    assert sol.status in set(SOLVER_STATUS.values()) - {"Solved"}
