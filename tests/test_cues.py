"""Cue classification on constructed signals with known correct, scaled, false and missing intervals."""

from __future__ import annotations

import numpy as np
import pytest

from washbench.analysis import cues
from washbench.io.metrics_csv import MetricRow, read_metrics_csv, write_metrics_csv

DT = 0.01


def _signals():
    """10 s at 100 Hz: aircraft 1.0 (threshold 0.2) from 1-3 s and 5-7 s and -1.0 from 8-9 s.

    simulator: 0.8 in 1-3 s (correct), 0.1 in 5-7 s (missing: below threshold), 1.0 in 8-9 s (opposite: false),
    0.5 in 3.5-4.5 s while the aircraft is still (false), 0.3 in... none elsewhere.
    """
    t = np.arange(1000) * DT
    a = np.zeros_like(t)
    b = np.zeros_like(t)
    a[(t >= 1) & (t < 3)] = 1.0
    b[(t >= 1) & (t < 2)] = 0.8  # correct for 1 s
    b[(t >= 2) & (t < 3)] = 0.3  # scaled (ratio 0.3 < 0.5) for 1 s
    a[(t >= 5) & (t < 7)] = 1.0
    b[(t >= 5) & (t < 7)] = 0.1  # missing for 2 s
    a[(t >= 8) & (t < 9)] = -1.0
    b[(t >= 8) & (t < 9)] = 1.0  # opposite direction: false for 1 s
    b[(t >= 3.5) & (t < 4.5)] = -0.5  # spurious: false for 1 s
    return t, a, b


def test_fractions_and_events_of_constructed_signals():
    _, a, b = _signals()
    s = cues.summarise(a, b, 0.2, DT, "surge")
    assert s.fraction("correct") == pytest.approx(0.1)
    assert s.fraction("scaled") == pytest.approx(0.1)
    assert s.fraction("missing") == pytest.approx(0.2)
    assert s.fraction("false") == pytest.approx(0.2)
    assert s.fraction("none") == pytest.approx(0.4)
    assert sum(s.fractions) == pytest.approx(1.0)
    assert [(e.start_s, e.end_s, e.peak) for e in s.events] == [
        pytest.approx((3.5, 4.49, 0.5)), pytest.approx((8.0, 8.99, 1.0))
    ]
    assert all(e.dof == "surge" for e in s.events)


def test_rest_reference_threshold_and_band_edges():
    # heave around -g: 0.25 below the 0.28 threshold is not felt; the ratio band is inclusive
    g = -9.80665
    assert cues.classify(np.array([g + 0.25]), np.array([g]), 0.28, g)[0] == cues.NONE
    assert cues.classify(np.array([1.0]), np.array([2.0]), 0.1)[0] == cues.CORRECT
    assert cues.classify(np.array([1.0]), np.array([2.01]), 0.1)[0] == cues.SCALED
    assert cues.classify(np.array([1.0]), np.array([0.5]), 0.1)[0] == cues.CORRECT
    assert cues.classify(np.array([0.05]), np.array([-0.5]), 0.1)[0] == cues.FALSE


def test_short_runs_merge_and_tiny_events_are_not_listed():
    n = 400
    cls = np.zeros(n, dtype=np.int8)
    cls[10:30] = cues.FALSE  # 0.2 s
    cls[40:60] = cues.FALSE  # gap 0.1 s < MERGE_GAP_S: same event
    cls[200:205] = cues.FALSE  # 0.04 s < MIN_EVENT_S: not listed
    b = np.linspace(0.0, 1.0, n)
    ev = cues.false_events(cls, b, DT, "yaw")
    assert len(ev) == 1
    assert (ev[0].start_s, ev[0].end_s) == pytest.approx((0.10, 0.59))
    assert ev[0].peak == pytest.approx(b[59])


def test_metrics_csv_round_trip_with_cue_columns(tmp_path):
    _, a, b = _signals()
    s = cues.summarise(a, b, 0.2, DT, "surge")
    row = MetricRow("w", "surge", 1.2, 3.4, 5.6, *s.fractions[1:], false_cue_events=cues.events_text(s.events))
    path = tmp_path / "metrics.csv"
    write_metrics_csv(path, [row])
    (back,) = read_metrics_csv(path)
    assert back.cue_false_frac == pytest.approx(0.2)
    assert back.cue_scaled_frac == pytest.approx(0.1)
    parsed = cues.parse_events(back.false_cue_events, "surge")
    expected = [("surge", 3.5, 4.49, 0.5), ("surge", 8.0, 8.99, 1.0)]
    assert [(e.dof, e.start_s, e.end_s, e.peak) for e in parsed] == expected
    old = tmp_path / "old.csv"
    old.write_text("washout,dof,npc,integral_error,max_error\nw,surge,1.0,2.0,3.0\n")
    (r,) = read_metrics_csv(old)
    assert np.isnan(r.cue_false_frac) and r.false_cue_events == ""
