"""Sample thinning for the recording: checked by interpolating the kept samples back (numpy), not by re-running it."""

from __future__ import annotations

import numpy as np
import pytest

from washbench.review.thinning import keep_changes, keep_samples


def test_kept_samples_interpolate_every_row_within_the_tolerance():
    rng = np.random.default_rng(3)
    k = np.arange(20_000)
    values = np.column_stack([np.cumsum(rng.normal(0, 0.01, k.size)), np.sin(k / 300.0), 0 * k])
    tol = np.array([0.02, 0.001, 0.0])
    idx = keep_samples(k, values, tol, max_gap=500)
    assert idx[0] == 0 and idx[-1] == k.size - 1 and np.all(np.diff(idx) > 0) and np.all(np.diff(idx) <= 500)
    for j in range(3):
        assert np.max(np.abs(np.interp(k, idx, values[idx, j]) - values[:, j])) <= tol[j] * (1 + 1e-12) + 1e-15
    assert idx.size < 0.2 * k.size


def test_straight_lines_keep_their_ends_and_the_gaps():
    idx = keep_samples(np.arange(1001.0), np.linspace(0.0, 1.0, 1001), 1e-12, max_gap=250)
    np.testing.assert_array_equal(idx, [0, 250, 500, 750, 1000])
    kink = np.abs(np.arange(-50.0, 51.0))  # |x|: the corner is kept exactly
    np.testing.assert_array_equal(keep_samples(np.arange(101.0), kink, 1e-9, max_gap=1000), [0, 50, 100])


def test_irregular_times_are_interpolated_in_time_and_long_gaps_pass():
    rng = np.random.default_rng(11)
    t = np.cumsum(rng.uniform(0.5, 1.5, 3000))
    t[1500:] += 100.0  # a hole longer than max_gap
    v = np.sin(t / 40.0) + 0.001 * t
    t.flags.writeable = v.flags.writeable = False  # as Arrow's zero-copy arrays are
    idx = keep_samples(t, v, 0.002, max_gap=50.0)
    assert {1499, 1500} <= set(idx.tolist())
    gaps = np.diff(t[idx])
    assert np.all((gaps <= 50.0) | (np.diff(idx) == 1))
    assert np.max(np.abs(np.interp(t, t[idx], v[idx]) - v)) <= 0.002 * (1 + 1e-12)
    assert idx.size < 0.2 * t.size


def test_non_finite_values_are_kept_with_their_neighbours():
    v = np.linspace(0.0, 1.0, 100)
    v[40] = np.nan
    idx = keep_samples(np.arange(100.0), v, 0.01, max_gap=1000)
    assert {39, 40, 41} <= set(idx.tolist())
    seg = np.arange(41, 100)
    np.testing.assert_allclose(np.interp(seg, idx[idx >= 41], v[idx[idx >= 41]]), v[seg], atol=0.01)


def test_held_rows_stay_within_the_tolerance():
    rng = np.random.default_rng(5)
    v = np.cumsum(rng.normal(0, 0.001, (5000, 2)), axis=0)
    idx = keep_changes(v, 0.01, max_gap=300)
    held = v[idx[np.searchsorted(idx, np.arange(5000), side="right") - 1]]
    assert np.max(np.abs(held - v)) <= 0.01 and idx.size < 0.2 * 5000 and np.all(np.diff(idx) <= 300)
    assert idx[0] == 0 and idx[-1] == 4999


def test_bad_arguments():
    with pytest.raises(ValueError, match="tolerance"):
        keep_samples(np.arange(3.0), np.zeros((3, 2)), -1.0, 5)
    with pytest.raises(ValueError, match="max_gap"):
        keep_changes(np.zeros(3), 0.1, 0)
