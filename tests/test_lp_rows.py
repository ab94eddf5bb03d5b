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


def random_rows(rng: np.random.Generator, n: int) -> tuple[Rows, np.ndarray]:
    """Equalities ``c_k x_k + x_(k+2) = 0`` (k = 0, 1; the ``c`` returned), inequalities of several variables and of
    one (some repeated, one with a zero coefficient)."""
    rows = Rows()
    idx = np.arange(n)
    c = rng.normal(size=2)
    rows.add([(idx[:2], c), (idx[2:4], 1.0)], np.zeros(2), equal=True)  # x = 0 is feasible
    rows.add([(idx, rng.normal(size=n)), (np.roll(idx, 1), rng.normal(size=n))], rng.uniform(0.5, 2.0, n), equal=False)
    rows.box(idx, -rng.uniform(0.5, 2.0, n), rng.uniform(0.5, 2.0, n))
    rows.box(idx[: n // 2], -rng.uniform(0.5, 2.0, n // 2), rng.uniform(0.5, 2.0, n // 2))  # tighter or not
    rows.add([(idx[:1], 0.0)], np.array([1.0]), equal=False)  # 0 <= 1: a row, not a bound
    return rows, c


@settings(max_examples=40, deadline=None, derandomize=True)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(4, 9))
def test_split_keeps_the_feasible_set(seed: int, n: int) -> None:
    """A point satisfies every original row iff it satisfies the equalities, G x <= h and x_l <= x <= x_u."""
    rng = np.random.default_rng(seed)
    rows, c = random_rows(rng, n)
    a_eq, b_eq, a_le, b_le = rows.matrices(n)
    g, h, x_l, x_u = split_bounds(a_le, b_le)
    expected_eq = np.zeros((2, n))
    expected_eq[[0, 1], [0, 1]], expected_eq[[0, 1], [2, 3]] = c, 1.0
    assert np.array_equal(a_eq.toarray(), expected_eq) and np.array_equal(b_eq, np.zeros(2))
    assert g.shape[0] == n + 1  # the two-variable rows and the zero-coefficient one
    dense = a_le.toarray()
    for x in rng.uniform(-2.5, 2.5, (400, n)):
        original = bool(np.all(dense @ x <= b_le))
        split = bool(np.all(g @ x <= h) and np.all(x_l <= x) and np.all(x <= x_u))
        assert original == split


def test_an_lp_has_highs_optimum_and_a_dual_bound_below_it() -> None:
    """The ceiling's use: an LP's primal objective equals HiGHS's optimum, its dual objective lies at most the
    tolerance above it."""
    rng = np.random.default_rng(7)
    n = 30
    rows, _ = random_rows(rng, n)
    a_eq, b_eq, a_le, b_le = rows.matrices(n)
    c = rng.normal(size=n)
    ref = linprog(c, A_ub=a_le.toarray(), b_ub=b_le, A_eq=a_eq.toarray(), b_eq=b_eq, bounds=(None, None),
                  method="highs")  # fmt: skip
    assert ref.status == 0
    sol = solve_qp(sparse.csc_matrix((n, n)), c, rows, 1e-9, 200)
    assert sol.status == "Solved"
    assert sol.obj_val == pytest.approx(ref.fun, rel=1e-6, abs=1e-8)
    assert sol.obj_val_dual <= ref.fun + 1e-6 * max(1.0, abs(ref.fun))
    assert np.all(a_le @ sol.x <= b_le + 1e-7)


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
