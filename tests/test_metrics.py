"""Metrics against identities, numpy/scipy and closed forms."""

import math

import numpy as np
import pytest
import scipy.stats
from hypothesis import given, settings
from hypothesis import strategies as st

from washbench.analysis.metrics import (
    DOFS,
    dof_metrics,
    integral_abs_error,
    is_flat,
    max_abs_error,
    npc,
    npc_from_pc,
    pearson,
)

T = np.arange(2001) * 0.01  # 20 s at 100 Hz
X = np.sin(0.7 * T) + 0.3 * np.cos(2.3 * T) + 0.05 * T


def test_npc_identities() -> None:
    assert npc(X, X) == pytest.approx(1.0, abs=1e-15)
    assert npc(X, 3.5 * X - 2.0) == pytest.approx(1.0, abs=1e-15)
    assert npc(X, -X) == math.inf  # PC = -1 is reported as +inf (documented)
    assert npc(X, -0.2 * X + 7.0) == math.inf
    # uncorrelated (orthogonal, zero-mean over whole periods): PC = 0 -> NPC = 1 / 1 + 1 - 1/2 = 1.5
    t = np.arange(1000) * (2 * np.pi / 1000)
    assert npc(np.sin(t), np.cos(t)) == pytest.approx(1.5, abs=1e-12)


def test_npc_formula_by_hand() -> None:
    # K = 1: NPC = 1 / (1 + PC) + 1/2
    assert npc_from_pc(0.5) == pytest.approx(1 / 1.5 + 0.5)
    assert npc_from_pc(-0.5) == pytest.approx(1 / 0.5 + 0.5)
    assert npc_from_pc(1.0) == 1.0
    assert npc_from_pc(-1.0) == math.inf
    assert math.isnan(npc_from_pc(math.nan))


@settings(max_examples=50, deadline=None)
@given(st.integers(min_value=0, max_value=2**32 - 1), st.integers(min_value=3, max_value=400))
def test_pc_equals_numpy_and_scipy(seed: int, n: int) -> None:
    rng = np.random.default_rng(seed)
    x = rng.normal(size=n) * 10.0 ** rng.uniform(-3, 3)
    y = 0.3 * x + rng.normal(size=n)
    pc = pearson(x, y)
    assert pc == pytest.approx(np.corrcoef(x, y)[0, 1], abs=1e-12)
    assert pc == pytest.approx(scipy.stats.pearsonr(x, y).statistic, abs=1e-12)


def test_flat_signal_gives_nan() -> None:
    flat = np.full_like(X, -9.80665)
    assert is_flat(flat) and is_flat(np.zeros(10))
    assert is_flat(flat + 1e-13 * np.sin(T))  # rounding-level wiggle on a large constant is flat
    assert not is_flat(1e-13 * np.sin(T))  # a small signal around zero is a signal
    assert math.isnan(npc(X, flat))
    assert math.isnan(npc(flat, X))
    assert math.isnan(pearson(np.zeros(5), np.zeros(5)))


def test_integral_error_of_constants_and_max_error() -> None:
    n, dt = 1201, 1 / 120  # 10 s
    a, b = np.full(n, 2.5), np.full(n, -1.0)
    assert integral_abs_error(a, b, dt) == pytest.approx(3.5 * 10.0, rel=1e-12)
    # trapezoid of |t - 5| over [0, 10] is exact for a kink on a grid point: 25
    t = np.arange(n) * dt
    assert integral_abs_error(t, np.full(n, 5.0), dt) == pytest.approx(25.0, rel=1e-12)
    x = np.array([0.0, 1.0, -2.0, 0.5])
    y = np.array([0.1, 1.0, 1.5, 0.0])
    assert max_abs_error(x, y) == 3.5


def test_dof_metrics_units_and_order() -> None:
    n, dt = 501, 0.02
    t = np.arange(n) * dt
    f_ac = np.column_stack([np.sin(t), np.cos(t), -9.80665 + 0.1 * np.sin(3 * t)])
    w_ac = np.column_stack([0.1 * np.sin(t), np.zeros(n), 0.2 * np.cos(t)])
    f_sim = f_ac.copy()
    f_sim[:, 0] = 0.0  # surge cue missing entirely
    w_sim = w_ac + np.radians([1.0, 0.0, 0.0])  # constant 1 deg/s roll offset
    rows = dof_metrics("small-angle", f_ac, w_ac, f_sim, w_sim, dt)
    assert [r.dof for r in rows] == list(DOFS)
    by = {r.dof: r for r in rows}
    assert math.isnan(by["surge"].npc)  # simulator surge flat
    assert by["surge"].max_error == pytest.approx(np.abs(np.sin(t)).max())
    assert by["sway"].npc == pytest.approx(1.0) and by["sway"].integral_error == 0.0
    assert by["roll"].npc == pytest.approx(1.0)  # offset does not change correlation
    assert by["roll"].max_error == pytest.approx(1.0, rel=1e-12)  # deg/s
    assert by["roll"].integral_error == pytest.approx(1.0 * (n - 1) * dt, rel=1e-12)  # deg
    assert math.isnan(by["pitch"].npc)  # both pitch signals are zero
    assert by["pitch"].max_error == 0.0


def test_bad_shapes_raise() -> None:
    with pytest.raises(ValueError):
        npc(np.zeros(3), np.zeros(4))
    with pytest.raises(ValueError):
        integral_abs_error(np.zeros(1), np.zeros(1), 0.1)


def test_the_flatness_tolerance_is_one_value_in_both_modules() -> None:
    """``analysis.metrics`` keeps its own copy of the compiled sums' flatness tolerance (importing those imports
    numba); the copy must not drift from the value the compiled pass uses."""
    from washbench.analysis import metric_sums, metrics

    assert metrics.FLAT_RTOL == metric_sums.FLAT_RTOL
