"""The felt error (washbench.analysis.felt) against hand-worked values and its stated properties.

Every expected value here is worked out by hand from the definition in docs/metrics.md (dead band of the error,
false part, jolt, threshold units), not by calling the module's helpers; the convexity test checks the property the
ceiling relies on, on random signals.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from washbench.analysis.felt import (
    DEFAULT_MEASURE,
    FeltMeasure,
    dof_terms,
    felt_errors,
    felt_motion,
    felt_score,
    felt_weights,
    jolt,
)
from washbench.analysis.ranking import RankRule, perceived_motion, rank
from washbench.io.metrics_csv import MetricRow
from washbench.perception.thresholds import ZACHARIAS

DT = 0.01
G = 9.80665
N = 1001  # 10 s


def _rest(n: int = N) -> tuple[np.ndarray, np.ndarray]:
    f = np.zeros((n, 3))
    f[:, 2] = -G
    return f, np.zeros((n, 3))


def _box(n: int, start: int, stop: int, value: float) -> np.ndarray:
    x = np.zeros(n)
    x[start:stop] = value
    return x


def test_a_still_platform_scores_one_and_the_aircraft_itself_zero() -> None:
    f, w = _rest()
    f[:, 1] = _box(N, 100, 600, 1.0)  # 1 m/s^2 of sway for 5 s
    w[:, 0] = np.radians(_box(N, 200, 400, 10.0))  # 10 deg/s of roll for 2 s
    still_f, still_w = _rest()
    m = felt_motion(f, w, DT)
    e, fa = felt_errors(f, w, still_f, still_w, DT)
    assert felt_score(e, fa, np.zeros(3), m) == pytest.approx(1.0, rel=1e-12)
    e0, f0 = felt_errors(f, w, f, w, DT)
    assert felt_score(e0, f0, np.zeros(3), m) == 0.0


def test_the_dead_band_by_hand() -> None:
    # an error of 0.5 m/s^2 in sway on 401 samples (4 s between the first and the last)
    f, w = _rest()
    g, v = _rest()
    g[:, 1] = _box(N, 300, 701, 0.5)
    e, fa = felt_errors(f, w, g, v, DT)
    # the trapezoid rule of the pointwise values: every sample of the box is inside the grid, weight dt each: 4.01 s
    assert e[1] == pytest.approx((0.5 - ZACHARIAS.f_y_mps2) * 4.01, rel=1e-9)
    assert np.all(e[[0, 2, 3, 4, 5]] == 0.0)
    # the aircraft felt nothing there: all of it is a false cue too
    assert fa[1] == pytest.approx(e[1], rel=1e-12)
    # without the dead band the whole error counts
    e_none, _ = felt_errors(f, w, g, v, DT, FeltMeasure(deadband=False))
    assert e_none[1] == pytest.approx(0.5 * 4.01, rel=1e-9)


def test_a_sub_threshold_tilt_costs_nothing() -> None:
    # tilt coordination below the canal threshold: the simulator pilot rolls at 2.5 deg/s (threshold 3.0) while the
    # aircraft pilot feels no roll at all
    f, w = _rest()
    g, v = _rest()
    v[:, 0] = np.radians(_box(N, 100, 900, 2.5))
    e, fa = felt_errors(f, w, g, v, DT)
    assert e[3] == 0.0 and fa[3] == 0.0
    # at 4 deg/s it is felt, and false, by 1 deg/s beyond the threshold
    v[:, 0] = np.radians(_box(N, 100, 900, 4.0))
    e, fa = felt_errors(f, w, g, v, DT)
    assert e[3] == pytest.approx(1.0 * 8.0, rel=1e-9)
    assert fa[3] == pytest.approx(e[3], rel=1e-12)


def test_false_cues_by_size_and_direction() -> None:
    f, w = _rest()
    f[:, 0] = _box(N, 100, 600, 2.0)  # the aircraft pilot feels 2 m/s^2 of surge for 5 s
    weaker = f.copy()
    weaker[:, 0] = _box(N, 100, 600, 1.0)  # a scaled cue: same direction, half the size
    reverse = f.copy()
    reverse[:, 0] = _box(N, 100, 600, -1.0)  # the wrong direction
    _, fa_weak = felt_errors(f, w, weaker, w, DT)
    _, fa_rev = felt_errors(f, w, reverse, w, DT)
    assert fa_weak[0] == 0.0  # too weak is missing, not false
    assert fa_rev[0] == pytest.approx((1.0 - ZACHARIAS.f_x_mps2) * 5.0, rel=1e-9)
    # the wrong-way cue's error (3) is three times the weak one's (1); its false part (1 beyond the threshold)
    # counts once more
    e_w, _ = felt_errors(f, w, weaker, w, DT)
    e_r, _ = felt_errors(f, w, reverse, w, DT)
    m = felt_motion(f, w, DT)
    s_w = felt_score(e_w, fa_weak, np.zeros(3), m)
    s_r = felt_score(e_r, fa_rev, np.zeros(3), m)
    assert s_w == pytest.approx((1.0 - 0.17) / (2.0 - 0.17), rel=1e-9)
    assert s_r == pytest.approx(((3.0 - 0.17) + (1.0 - 0.17)) / (2.0 - 0.17), rel=1e-9)


def test_a_jolt_by_hand() -> None:
    f, _ = _rest()
    g, _ = _rest()
    g[500:520, 0] = -G  # a 1 g surge deceleration for 0.2 s, on and off in one sample each: two steps of g
    j = jolt(g, f, DT)
    allow = DEFAULT_MEASURE.jerk_deadband_mps3 * DT
    assert j[0] == pytest.approx(2 * (G - allow), rel=1e-12)
    assert j[1] == 0.0 and j[2] == 0.0
    # the same deceleration reached over 0.5 s (jerk 19.6 m/s^3, below the dead band) is no jolt
    ramp, _ = _rest()
    ramp[:, 0] = -np.clip(np.concatenate([np.zeros(400), np.arange(601) * DT / 0.5]), 0.0, 1.0) * G
    assert jolt(ramp, f, DT)[0] == 0.0
    # and the aircraft's own jolt, reproduced, is not the platform's
    assert jolt(g, g, DT)[0] == 0.0


def test_weights_follow_what_was_felt_above_threshold() -> None:
    f, w = _rest()
    f[:, 0] = _box(N, 0, N, 1.17)  # 1 m/s^2 above the surge threshold, all the way
    w[:, 1] = np.radians(_box(N, 0, N, 1.0))  # pitch at 1 deg/s: below the canals' threshold, felt as nothing
    f[0, 0] = 0.0  # (the first sample is the still level)
    w[0, 1] = 0.0
    weights = felt_weights(felt_motion(f, w, DT))
    assert weights["pitch"] == 0.0
    assert weights["surge"] == pytest.approx(1.0, rel=1e-12)


def test_a_flight_felt_less_than_the_floor_divides_by_the_floor() -> None:
    f, w = _rest()
    g, v = _rest()
    v[:, 2] = np.radians(_box(N, 0, 200, 3.6))  # 1 deg/s beyond the yaw threshold for 2 s: a false cue only
    e, fa = felt_errors(f, w, g, v, DT)
    score = felt_score(e, fa, np.zeros(3), felt_motion(f, w, DT))
    # numerator: (E + F) / T_yaw with E = F = 1 deg/s x 1.995 s (trapezoid: the first sample is inside, its end not)
    assert score == pytest.approx(2 * 1.0 * 1.995 / ZACHARIAS.omega_z_degps / DEFAULT_MEASURE.felt_floor_s, rel=1e-9)


@given(st.integers(0, 2**32 - 1), st.floats(0.0, 1.0))
def test_the_numerator_is_convex_in_the_simulator_s_motion(seed: int, theta: float) -> None:
    """What the ceiling relies on: the score's numerator is convex in the simulator pilot's perceived signals and
    head specific force (the aircraft's fixed)."""
    rng = np.random.default_rng(seed)
    n = 200
    x_f, x_w = rng.normal(0, 1, (n, 3)), rng.normal(0, 0.1, (n, 3))
    head = rng.normal(0, 1, (n, 3))

    def numerator(y_f: np.ndarray, y_w: np.ndarray, h: np.ndarray) -> float:
        e, fa = felt_errors(x_f, x_w, y_f, y_w, DT)
        return float(np.sum(dof_terms(e, fa, jolt(h, head, DT))))

    a = [rng.normal(0, 1, (n, 3)), rng.normal(0, 0.1, (n, 3)), rng.normal(0, 2, (n, 3))]
    b = [rng.normal(0, 1, (n, 3)), rng.normal(0, 0.1, (n, 3)), rng.normal(0, 2, (n, 3))]
    mid = [theta * p + (1 - theta) * q for p, q in zip(a, b, strict=True)]
    lhs = numerator(*mid)
    rhs = theta * numerator(*a) + (1 - theta) * numerator(*b)
    assert lhs <= rhs + 1e-9 * max(1.0, abs(rhs))


def _rows(name: str, e: np.ndarray, fa: np.ndarray, j: np.ndarray) -> list[MetricRow]:
    dofs = ("surge", "sway", "heave", "roll", "pitch", "yaw")
    return [MetricRow(washout=name, dof=d, npc=math.nan, integral_error=1.0, max_error=1.0, felt_error=float(e[i]),
                      felt_false=float(fa[i]), jolt=float(j[i]) if i < 3 else math.nan)
            for i, d in enumerate(dofs)]  # fmt: skip


def test_the_ranking_ranks_by_the_felt_error_by_default() -> None:
    f, w = _rest()
    f[:, 1] = _box(N, 100, 600, 1.0)
    m = perceived_motion(f, w, DT)
    still_f, still_w = _rest()
    e, fa = felt_errors(f, w, still_f, still_w, DT)
    jolting = f.copy()
    e2, fa2 = felt_errors(f, w, jolting, w, DT)  # exact, but with a jolt
    rows = _rows("still", e, fa, np.zeros(3)) + _rows("jolty", e2, fa2, np.array([0.0, 30.0, 0.0]))
    ranking = rank(rows, m)
    assert RankRule().by == "felt"
    assert [r.washout for r in ranking] == ["still", "jolty"]
    assert ranking[0].score == pytest.approx(1.0)
    # the jolt of 30 m/s^2 counts tau_j x 30 / T_sway threshold-seconds over the felt motion
    felt = (1.0 - 0.17) * 5.0 / 0.17
    assert ranking[1].score == pytest.approx(30.0 / 0.17 / felt, rel=1e-9)
