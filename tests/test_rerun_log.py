"""The rerun recording: write real .rrd files, read them back with rerun's own reader and check every trace.

The data is synthetic but shaped like the pipeline's (N samples at dt = 1/120 s, three washouts). Expected values come
from the inputs and from independent tools (scipy's Rotation for quaternion order, numpy edge detection for saturation
onsets, the rerun CLI for file validity).
"""

from __future__ import annotations

import itertools
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from rerun.chunk import RrdReader
from scipy.spatial.transform import Rotation

from washbench.review import rerun_log
from washbench.review.replay import find_rerun
from washbench.review.rerun_log import (
    AIRCRAFT,
    DOFS,
    ENVELOPE_QUANTITIES,
    PLATFORM_DETAIL_TOLERANCE,
    MotionSeries,
    PlatformEnvelope,
    PlatformSeries,
    RecordingData,
    cue_lane_path,
    envelope_usage_path,
    perceived_path,
    phase_lane_path,
    platform_path,
    quat_wxyz_to_xyzw,
    raw_path,
    read_component,
    read_properties,
    read_scalar_series,
    read_text_documents,
    washout_lane_path,
    write_recording,
)
from washbench.review.rrd_read import read_blueprint_components, read_static

WASHOUTS = ("small-angle", "large-angle", "unrestricted")
G = 9.80665
METRICS = "| dof | NPC small-angle |\n|---|---|\n| surge | 0.91 |\n| roll | 0.42 |\n"


def make_data(n: int = 600, washouts: tuple[str, ...] = WASHOUTS, seed: int = 7) -> RecordingData:
    """Synthetic run: t = k/120 s, pilot-head signals around level flight, random attitudes, saturation bursts."""
    rng = np.random.default_rng(seed)
    k = np.arange(n)
    t = k / 120.0

    def motion() -> MotionSeries:
        f = np.column_stack([np.sin(0.5 * t), 0.3 * np.cos(0.7 * t), -G + 0.2 * np.sin(t)]) + rng.normal(
            0, 0.05, (n, 3)
        )
        w = rng.normal(0, 0.1, (n, 3))
        q = Rotation.from_rotvec(rng.normal(0, 0.4, (n, 3))).as_quat(scalar_first=True)
        return MotionSeries(f, w, 0.8 * f + rng.normal(0, 0.01, (n, 3)), 0.5 * w, q)

    platforms = {}
    for w in washouts:
        burst = (k % 200) >= 180  # 20-sample bursts
        pos = rng.uniform(-1.4, 1.4, (n, 3)) * [1.0, 1.0, 0.7]
        pos[0] = [0.45, -0.45, 0.9]
        platforms[w] = PlatformSeries(
            pos_m=pos,
            vel_mps=rng.normal(0, 0.5, (n, 3)),
            acc_mps2=rng.normal(0, 2.0, (n, 3)),
            wheel_radps=rng.normal(0, 10.0, (n, 3)),
            saturated={"pos": burst, "rate": (k % 300) == 5, "vel": np.zeros(n, dtype=bool),
                       "tilt_rate": (k % 150 >= 100) & (k % 150 < 100 + 10 * min(3, 1 + washouts.index(w)))},
        )
    return RecordingData(
        title="c172p / coordinated_turn",
        t_s=t,
        aircraft=motion(),
        washouts={w: motion() for w in washouts},
        platforms=platforms,
        envelope=PlatformEnvelope(pos_m=(1.5, 1.5, 1.0), vel_mps=2.0, acc_mps2=5.0, wheel_radps=40.0,
                                  rate_radps=np.radians(30.0)),
        phases=[("entry", 0.0, t[n // 5]), ("hold", t[n // 5], t[n // 2]), ("exit", t[n // 2], t[-1])],
        metrics_markdown=METRICS,
    )


@pytest.fixture(scope="module")
def written(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, RecordingData]:
    data = make_data()
    path = tmp_path_factory.mktemp("rec") / "recording.rrd"
    write_recording(path, data, {"washbench_version": "0.1.0", "params_sha256": "ab" * 32})
    return path, data


def assert_recorded(
    t_rec: np.ndarray,
    v_rec: np.ndarray,
    t_s: np.ndarray,
    values: np.ndarray,
    tolerance: float | np.ndarray,
    ulps: int = 0,
) -> None:
    """The stated precision of a recorded series against the values it came from (``values`` (N,) or (N, L) at the
    times ``t_s``): every recorded time is one of ``t_s`` (to 0.5 ns), the first and the last among them, none more
    than MAX_GAP_S after the previous; each recorded value equals float32(value) exactly; linear interpolation between
    the recorded samples is within ``tolerance`` of float32(value) at every step, so within tolerance plus float32's
    half step (2^-24 relative) of the value itself. ``ulps``: recorded values may be this many float32 steps off
    (for values that reached the recording by another float64 path than ``values``)."""
    values = np.asarray(values, dtype=np.float64).reshape(t_s.size, -1)
    v_rec = np.asarray(v_rec).reshape(t_rec.size, -1)
    assert v_rec.dtype == np.float64 and v_rec.shape[1] == values.shape[1]
    k = np.searchsorted(t_s, t_rec - 0.5e-9)
    assert np.all(k < t_s.size) and np.all(np.abs(t_s[np.minimum(k, t_s.size - 1)] - t_rec) <= 0.5e-9 + 1e-15)
    assert k[0] == 0 and k[-1] == t_s.size - 1 and np.all(np.diff(k) > 0)
    assert np.all(np.diff(t_rec) <= rerun_log.MAX_GAP_S + 1e-9)
    f32 = values.astype(np.float32).astype(np.float64)
    if ulps:
        step = np.spacing(np.abs(f32[k]).astype(np.float32)).astype(np.float64)
        assert np.all(np.abs(v_rec - f32[k]) <= ulps * step)
    else:
        np.testing.assert_array_equal(v_rec, f32[k])
    tol = np.broadcast_to(np.asarray(tolerance, dtype=np.float64), (values.shape[1],))
    for j in range(values.shape[1]):
        err = np.abs(np.interp(t_s, t_rec, v_rec[:, j]) - f32[:, j])
        slack = ulps * np.spacing(np.abs(f32[:, j]).astype(np.float32)).astype(np.float64)
        assert np.all(err <= tol[j] * (1 + 1e-9) + 1e-12 + slack), (j, err.max(), tol[j])
        off = np.abs(np.interp(t_s, t_rec, v_rec[:, j]) - values[:, j])
        assert np.all(off <= tol[j] * (1 + 1e-9) + 2.0**-24 * np.abs(values[:, j]) + 1e-12 + slack)


THRESHOLDS = {"surge": 0.17, "sway": 0.17, "heave": 0.28, "roll": 3.0, "pitch": 3.6, "yaw": 2.6}
"""Zacharias (1978), m/s^2 and deg/s, typed here from washbench/perception/thresholds.py."""


def panel_ranges(path: Path) -> dict[str, tuple[float, float]]:
    """The fixed y range of every time-series panel in the stored blueprint: origin -> (lo, hi)."""
    out = {}
    for v in _views(path).values():
        if v.get("ScalarAxis:range"):
            lo, hi = v["ScalarAxis:range"][0]
            out[v["ViewBlueprint:space_origin"][0]] = (lo, hi)
    return out


def motion_tolerances(path: Path, entity: str, lines: int) -> float:
    """The tolerance stored with a perceived or raw entity, after checking it against the stated bound: at most 1 %
    of the DOF's perception threshold and at most 0.2 % of the height of the panel that shows it."""
    stored = np.asarray(read_static(path, "interpolation_tolerance")[entity], dtype=np.float64)
    assert stored.shape == (lines,) and np.all(stored == stored[0]) and stored[0] > 0
    lo, hi = panel_ranges(path)[entity]
    bound = min(0.01 * THRESHOLDS[entity.rsplit("/", 1)[1]], 0.002 * (hi - lo))
    assert stored[0] <= bound * (1 + 1e-12)
    return float(stored[0])


def test_time_axis_is_k_dt_to_the_nanosecond(written):
    path, data = written
    series = read_scalar_series(path)
    t, _ = series[perceived_path("surge")]
    k = np.round(t * 120).astype(int)
    np.testing.assert_allclose(t, data.t_s[k], rtol=0, atol=0.5e-9 + 1e-15)
    assert k[0] == 0 and k[-1] == data.t_s.size - 1


def test_motion_traces_equal_the_inputs_one_line_per_source(written):
    """Stated precision: float32 values at the recorded steps, linear interpolation within 1 % of the perception
    threshold and 0.2 % of the panel's height at every step (angular rates in deg/s); the tolerance is stored with
    each entity."""
    path, data = written
    series = read_scalar_series(path)
    sources = [*data.washouts.values(), data.aircraft]  # the aircraft's line last: drawn on top
    for dof, sig, axis, _unit in DOFS:
        for entity, fields in ((perceived_path(dof), ("perceived_f_mps2", "perceived_omega_radps")),
                               (raw_path(dof), ("f_mps2", "omega_radps"))):  # fmt: skip
            t_rec, v_rec = series[entity]
            assert v_rec.shape[1] == 1 + len(WASHOUTS)
            expected = np.column_stack([getattr(m, fields[0 if sig == "f" else 1])[:, axis] for m in sources])
            if sig == "omega":
                expected = expected * 180 / np.pi
            assert_recorded(t_rec, v_rec, data.t_s, expected, motion_tolerances(path, entity, 1 + len(WASHOUTS)))
    names = read_static(path, "SeriesLines:names")
    assert names[perceived_path("surge")] == [*WASHOUTS, AIRCRAFT]


def test_smooth_motion_is_thinned_and_fast_motion_kept(tmp_path):
    """A slow sine needs a sample about every MAX_GAP_S; a burst of fast motion keeps (nearly) every step there."""
    base = make_data(n=2400)
    t = base.t_s
    slow = np.column_stack([0.5 * np.sin(0.2 * t), 0.0 * t, -G + 0.1 * np.sin(0.3 * t)])
    fast = slow.copy()
    burst = (t > 10.0) & (t < 12.0)
    fast[burst, 0] += 0.4 * np.sin(2 * np.pi * 8.0 * t[burst])  # 8 Hz, 0.4 m/s^2
    w0 = np.zeros_like(slow)
    q = base.aircraft.q

    def m(f: np.ndarray) -> MotionSeries:
        return MotionSeries(f, w0, f, w0, q)

    data = RecordingData(**{**base.__dict__, "aircraft": m(fast), "washouts": {w: m(slow) for w in WASHOUTS}})
    write_recording(tmp_path / "r.rrd", data)
    series = read_scalar_series(tmp_path / "r.rrd")
    t_rec, v_rec = series[perceived_path("surge")]
    expected = np.column_stack([slow[:, 0]] * 3 + [fast[:, 0]])  # the aircraft last
    assert_recorded(t_rec, v_rec, t, expected, motion_tolerances(tmp_path / "r.rrd", perceived_path("surge"), 4))
    in_burst = (t_rec > 10.0) & (t_rec < 12.0)
    assert in_burst.sum() > 0.5 * burst.sum()  # the fast part at (almost) full rate
    assert (~in_burst).sum() < 0.1 * (~burst).sum()  # the slow rest at a few per cent of the steps
    t_sway, _ = series[perceived_path("sway")]
    assert t_sway.size <= t[-1] / rerun_log.MAX_GAP_S + 2  # a flat line: one sample per MAX_GAP_S


def test_perception_thresholds_are_drawn_as_plus_minus_lines(written):
    """Zacharias (1978) values, typed here from the table in washbench/perception/thresholds.py."""
    path, data = written
    series = read_scalar_series(path)
    expected = {"surge": (0, 0.17), "sway": (0, 0.17), "heave": (-9.80665, 0.28),
                "roll": (0, 3.0), "pitch": (0, 3.6), "yaw": (0, 2.6)}  # fmt: skip
    for dof, (centre, th) in expected.items():
        t, v = series[f"/perceived/{dof}/threshold"]
        np.testing.assert_allclose(t, data.t_s[[0, -1]], atol=1e-9)
        np.testing.assert_allclose(v, [[centre + th, centre - th]] * 2, rtol=1e-12)


def test_platform_traces_and_envelope_usage(written):
    """Envelope usage within 0.002 (limit at 1), the per-axis traces within 0.2 % of each axis's limit."""
    path, data = written
    series = read_scalar_series(path)
    for q, fname, _unit in ENVELOPE_QUANTITIES:
        limit = np.asarray(getattr(data.envelope, fname), dtype=float)  # scalar, or per axis (position)
        t_lim, v_lim = series[f"/envelope/{q}/limit"]
        np.testing.assert_array_equal(v_lim, [1.0, 1.0])
        np.testing.assert_allclose(t_lim, data.t_s[[0, -1]], atol=1e-9)
        t_u, usage = series[envelope_usage_path(q)]
        assert usage.shape[1] == len(WASHOUTS)
        expected = [np.linalg.norm(getattr(data.platforms[w], fname) / limit, ord=np.inf, axis=1) for w in WASHOUTS]
        assert_recorded(t_u, usage, data.t_s, np.column_stack(expected), 0.002)
        for i, w in enumerate(WASHOUTS):
            values = getattr(data.platforms[w], fname)
            if q == "position":  # first sample: x, y at 0.3 of 1.5 m, z at 0.9 of its own 1.0 m limit
                assert usage[0, i] == np.float32(0.9)
            t_p, v_p = series[platform_path(w, q)]
            assert_recorded(t_p, v_p, data.t_s, values, PLATFORM_DETAIL_TOLERANCE * np.broadcast_to(limit, (3,)))
            np.testing.assert_array_equal(series[f"/platform/{w}/{q}/limit_max"][1], [limit, limit])
            np.testing.assert_array_equal(series[f"/platform/{w}/{q}/limit_min"][1], [-limit, -limit])
            if limit.ndim:  # per-axis limits are drawn one line per axis
                assert series[f"/platform/{w}/{q}/limit_max"][1].shape == (2, 3)
    aggregation = read_static(path, "SeriesLines:aggregation_policy")
    assert {aggregation[envelope_usage_path(q)][0] for q, _, _ in ENVELOPE_QUANTITIES} == {3}  # 3 = Max


def test_cockpit_rate_and_the_time_held_at_the_tilt_rate_limit_have_panels(written):
    """No view showed the tilt-rate or the sphere-rate usage (the tilt rate is the limit washouts reach most): the
    envelope tab has the cockpit's |omega| against the sphere's rate limit, and each washout's time held at its
    tilt-rate limit so far (the flags' count times dt: at the end, the report's "time at a limit")."""
    path, data = written
    series = read_scalar_series(path)
    t_r, rate = series[envelope_usage_path("rate")]
    expected = np.column_stack([np.sqrt(np.sum(data.washouts[w].omega_radps ** 2, axis=1)) / np.radians(30.0)
                                for w in WASHOUTS])  # fmt: skip
    assert_recorded(t_r, rate, data.t_s, expected, 0.002)
    np.testing.assert_array_equal(series["/envelope/rate/limit"][1], [1.0, 1.0])
    t_h, held = series[envelope_usage_path("tilt_rate_held")]
    dt = 1.0 / 120.0
    for i, w in enumerate(WASHOUTS):
        flags = data.platforms[w].saturated["tilt_rate"]
        assert held[-1, i] == pytest.approx(flags.sum() * dt, rel=1e-6)
        np.testing.assert_allclose(np.interp(data.t_s, t_h, held[:, i]), np.cumsum(flags) * dt, atol=0.1 * dt + 1e-6)
    names = {v["ViewBlueprint:display_name"][0]: v for v in _views(path).values()}
    assert names["cockpit rate / limit (30 deg/s)"]["ViewBlueprint:space_origin"] == ["/envelope/rate"]
    assert names["time at tilt-rate limit [s]"]["ViewBlueprint:space_origin"] == ["/envelope/tilt_rate_held"]


def test_smooth_platform_traces_are_thinned_within_the_stated_tolerance(tmp_path):
    """Smooth position and velocity keep a few per cent of the steps; random acceleration keeps (nearly) all."""
    base = make_data(n=1200)
    t = base.t_s
    smooth = np.column_stack([np.sin(0.5 * t), 0.5 * np.cos(0.3 * t), 0.2 * np.sin(t)])
    platforms = {
        w: PlatformSeries(smooth, 0.5 * smooth, p.acc_mps2, p.wheel_radps, p.saturated)
        for w, p in base.platforms.items()
    }
    data = RecordingData(**{**base.__dict__, "platforms": platforms})
    write_recording(tmp_path / "r.rrd", data)
    series = read_scalar_series(tmp_path / "r.rrd")
    for w in WASHOUTS:
        for q, values, limit in (("position", smooth, (1.5, 1.5, 1.0)), ("velocity", 0.5 * smooth, (2.0,) * 3)):
            t_rec, v_rec = series[platform_path(w, q)]
            assert t_rec.size < t.size / 10  # thinned
            assert_recorded(t_rec, v_rec, t, values, PLATFORM_DETAIL_TOLERANCE * np.array(limit))
        assert series[platform_path(w, "acceleration")][0].size > 0.9 * t.size  # random: (nearly) every sample


def _state_at(t_change: np.ndarray, states: np.ndarray, t: np.ndarray) -> np.ndarray:
    """The state in force at each time of ``t`` (latest change at or before it), from a lane read back."""
    i = np.searchsorted(t_change, t + 1e-9, side="right") - 1
    return np.where(i >= 0, states[np.maximum(i, 0)], "")  # before the first change: no state


def _bars_read_back(t_ch: np.ndarray, states: np.ndarray, t_s: np.ndarray) -> list[tuple[int, int, str]]:
    """The bars of a lane read back: (first sample, last sample, state) of each stretch of a non-empty state."""
    at = _state_at(t_ch, states, t_s)
    out, k = [], 0
    while k < at.size:
        if at[k]:
            end = k
            while end + 1 < at.size and at[end + 1] == at[k]:
                end += 1
            out.append((k, end, str(at[k])))
            k = end + 1
        else:
            k += 1
    return out


def assert_bars(found: list[tuple[int, int, str]], flags: dict[str, np.ndarray], dt: float) -> None:
    """A lane's bars against per-sample flags (name -> bool (N,)), the rule stated in review/lane_bars.py: every
    flagged sample inside a bar; each bar begins and ends on a flagged sample; two bars more than MERGE_GAP_S (in
    whole samples) apart; a bar's state the names flagged somewhere inside it, in the flags' order, joined by "+"."""
    from washbench.analysis.cues import MERGE_GAP_S

    anyflag = np.any(np.column_stack(list(flags.values())), axis=1)
    inside = np.zeros(anyflag.size, dtype=bool)
    for start, end, state in found:
        inside[start : end + 1] = True
        assert anyflag[start] and anyflag[end]
        assert state == "+".join(k for k, f in flags.items() if np.any(f[start : end + 1]))
    assert np.array_equal(inside & anyflag, anyflag)  # every flagged sample in a bar
    gap = round(MERGE_GAP_S / dt)
    for (_, end, _), (start, _, _) in itertools.pairwise(found):
        assert start - end > gap


def test_limit_lanes_show_the_saturation_flags_as_stretches(written):
    """One lane per washout; a bar per stretch held at a limit (stretches under MERGE_GAP_S apart joined: a bar per
    change of kinds was a few pixels wide and its words cut to "sw", "sur"), named by the kinds held at inside it as
    the console and the report spell them ("pos+tilt_rate"), the view's title giving their readable names."""
    path, data = written
    lanes = read_component(path, "StateChange:state")
    dt = float(data.t_s[1] - data.t_s[0])
    for w in WASHOUTS:
        sat = data.platforms[w].saturated
        flags = {k: sat[k] for k in ("pos", "rate", "tilt_rate")}  # data order; "vel" is never reached
        t_ch, joined = lanes[washout_lane_path(data, w)]
        found = _bars_read_back(t_ch, joined, data.t_s)
        assert len(found) >= 2
        assert_bars(found, flags, dt)
    # every lane's path reads as a group and a name (the viewer labels each lane with it): one lane per washout
    assert sorted(k for k in lanes if not k.startswith("/false_cues/")) == [
        "/limits/1_small-angle", "/limits/2_large-angle", "/limits/3_unrestricted", "/phase"]  # fmt: skip
    labels = read_static(path, "StateConfiguration:labels")
    values = read_static(path, "StateConfiguration:values")
    shown = dict(zip(values[washout_lane_path(data, "small-angle")], labels[washout_lane_path(data, "small-angle")],
                     strict=True))  # fmt: skip
    assert all(k == v for k, v in shown.items()) and "pos+tilt_rate" in shown
    (view,) = [v for v in _views(path).values() if v["ViewBlueprint:display_name"][0].startswith("Limits held")]
    title = view["ViewBlueprint:display_name"][0]
    assert "pos stage position" in title and "tilt_rate tilt-rate limit" in title and "vel " not in title


def test_false_cue_lanes_and_events(written):
    """Each washout's cue lane has a bar per stretch of false cues (analysis.cues, the rule of metrics.csv; stretches
    under MERGE_GAP_S apart joined, as the events), its state the DOFs classified false inside it, its text their
    two-letter words ("Sw He"), which the view's title explains; every listed false-cue event is a WARN line at its
    start."""
    from washbench.analysis.cues import FALSE, classify, dof_thresholds, false_events

    path, data = written
    lanes = read_component(path, "StateChange:state")
    labels = read_static(path, "StateConfiguration:labels")
    values = read_static(path, "StateConfiguration:values")
    thresholds, rest = dof_thresholds()
    ac = np.column_stack([data.aircraft.perceived_f_mps2, np.rad2deg(data.aircraft.perceived_omega_radps)])
    n_events = 0
    words = {"surge": "Su", "sway": "Sw", "heave": "He", "roll": "Ro", "pitch": "Pi", "yaw": "Ya"}
    dt = float(data.t_s[1] - data.t_s[0])
    for i, w in enumerate(WASHOUTS):
        m = data.washouts[w]
        sim = np.column_stack([m.perceived_f_mps2, np.rad2deg(m.perceived_omega_radps)])
        names = [d[0] for d in DOFS]
        cls = [classify(ac[:, j], sim[:, j], thresholds[j], rest[j]) for j in range(6)]
        assert cue_lane_path(data, w) == f"/false_cues/{i + 1}_{w}"
        t_ch, states = lanes[cue_lane_path(data, w)]
        found = _bars_read_back(t_ch, states, data.t_s)
        assert found
        assert_bars(found, {d: cls[j] == FALSE for j, d in enumerate(names)}, dt)
        shown = dict(zip(values[cue_lane_path(data, w)], labels[cue_lane_path(data, w)], strict=True))
        for _, _, state in found:
            assert shown[state] == " ".join(words[d] for d in state.split("+"))
        n_events += sum(len(false_events(cls[j], sim[:, j] - rest[j], dt, names[j])) for j in range(6))
    assert n_events > 0  # the synthetic data has false cues
    t_ev, text = read_component(path, "TextLog:text")["/events/false_cues"]
    assert len(text) == n_events and all(": false " in s and " cue until " in s for s in text)
    assert np.all(np.diff(t_ev) >= 0)
    (view,) = [v for v in _views(path).values() if v["ViewBlueprint:display_name"][0].startswith("False cues")]
    assert all(f"{c} {d}" in view["ViewBlueprint:display_name"][0] for d, c in words.items())


def test_saturation_onset_events(written):
    path, data = written
    expected_onsets = []
    for w in WASHOUTS:
        for kind in ("pos", "rate", "tilt_rate"):
            flags = data.platforms[w].saturated[kind]
            rising = np.flatnonzero(np.diff(flags.astype(int), prepend=0) == 1)
            expected_onsets += [(data.t_s[i], f"{w}: {kind} limit") for i in rising]
    t_ev, text = read_component(path, "TextLog:text")["/events/saturation"]
    assert len(text) == len(expected_onsets)
    got = sorted(
        (round(float(tt), 6), s.lstrip().split("  ", 1)[1].split(" reached")[0])
        for tt, s in zip(t_ev, text, strict=True)
    )
    # each text starts with its time, right-aligned (the events table's time column was cut to "+3...": hidden)
    assert all(s.startswith(f"{tt:7.2f} s  ") for tt, s in zip(t_ev, text, strict=True))
    assert got == sorted((round(float(tt), 6), s) for tt, s in expected_onsets)
    assert "   1.50 s  small-angle: pos limit reached for 0.167 s" in text  # 20 samples at 120 Hz, from k = 180
    assert "   0.04 s  small-angle: rate limit reached for 0.008 s" in text  # 1 sample, k = 5
    _, levels = read_component(path, "TextLog:level")["/events/saturation"]
    assert set(levels) == {"WARN"}


def test_phases_as_a_lane_and_as_events(written):
    path, data = written
    t, text = read_component(path, "TextLog:text")["/events/phases"]
    np.testing.assert_allclose(t, [p[1] for p in data.phases], atol=1e-9)
    assert [s.split()[3] for s in text] == ["entry", "hold", "exit"]
    t_ch, states = read_component(path, "StateChange:state")[phase_lane_path()]
    np.testing.assert_allclose(t_ch, [p[1] for p in data.phases], atol=1e-9)
    assert list(states) == ["entry", "hold", "exit"]


def test_metrics_markdown_document_and_provenance_properties(written):
    path, _ = written
    docs = read_text_documents(path)
    assert docs["/metrics"] == METRICS
    media = [
        ch.to_record_batch().column("TextDocument:media_type").to_pylist()[0][0]
        for ch in RrdReader(str(path)).stream()
        if ch.entity_path == "/metrics"
    ]
    assert media == ["text/markdown"]
    assert read_properties(path) == {"washbench_version": "0.1.0", "params_sha256": "ab" * 32}


def test_properties_must_be_strings(tmp_path):
    with pytest.raises(ValueError, match="properties"):
        write_recording(tmp_path / "x.rrd", make_data(n=20), {"seed": 42})  # type: ignore[dict-item]
    assert list(tmp_path.iterdir()) == []


def _held(t_rec: np.ndarray, v_rec: np.ndarray, t: np.ndarray) -> np.ndarray:
    """What the 3D view shows at each time of ``t``: the latest recorded row at or before it."""
    i = np.searchsorted(t_rec, t + 1e-9, side="right") - 1
    assert np.all(i >= 0)
    return v_rec[i]


def test_3d_scene_relative_heading_scalar_last_and_30_hz(written):
    """Poses at most at 30 Hz; the pose the view holds is within 0.1 deg and 1 mm of the pose at every 30 Hz step."""
    path, data = written
    quats = read_component(path, "Transform3D:quaternion")
    trans = read_component(path, "Transform3D:translation")
    stride = 4  # 120 Hz -> 30 Hz
    k = np.arange(0, data.t_s.size, stride)
    # aircraft: relative to its initial heading; checked with scipy's ZYX Euler angles
    t_ac, q_rec = quats["/world/aircraft/body"]
    assert np.all(np.isin(np.round(t_ac * 120).astype(int), np.append(k, data.t_s.size - 1)))
    assert q_rec.dtype == np.float32  # rerun stores quaternions as float32
    q_ac = _held(t_ac, q_rec, data.t_s[k])
    ypr = Rotation.from_quat(data.aircraft.q[k], scalar_first=True).as_euler("ZYX")
    ypr0 = Rotation.from_quat(data.aircraft.q[0], scalar_first=True).as_euler("ZYX")
    ypr[:, 0] -= ypr0[0]
    x_fwd, z_down = np.array([1.0, 0.0, 0.0]), np.array([0.0, 0.0, 1.0])
    got = Rotation.from_quat(q_ac.astype(np.float64))  # scipy reads scalar-last
    want = Rotation.from_euler("ZYX", ypr)
    assert np.degrees((got * want.inv()).magnitude()).max() <= 0.1 + 1e-4
    for v in (x_fwd, z_down):
        np.testing.assert_allclose(got.apply(v), want.apply(v), atol=np.radians(0.1) + 1e-6)
    np.testing.assert_allclose(got[0].as_euler("ZYX")[0], 0.0, atol=1e-6)
    # cockpits: attitude unchanged (the simulator starts at yaw 0), translated by the stage position
    static_t = read_static(path, "Transform3D:translation")
    offsets = []
    for w in WASHOUTS:
        t_q, q = quats[f"/world/atlas/{w}/cockpit"]
        held = Rotation.from_quat(_held(t_q, q, data.t_s[k]).astype(np.float64))
        truth = Rotation.from_quat(data.washouts[w].q[k], scalar_first=True)
        assert np.degrees((held * truth.inv()).magnitude()).max() <= 0.1 + 1e-4
        t_p, pos = trans[f"/world/atlas/{w}/cockpit"]
        np.testing.assert_allclose(_held(t_p, pos, data.t_s[k]), data.platforms[w].pos_m[k], atol=1e-3 + 1e-6)
        offsets.append(static_t[f"/world/atlas/{w}"][0][1])
    gaps = np.diff([static_t["/world/aircraft"][0][1], *offsets])
    sphere_plus_travel = data.envelope.sphere_diameter_m + 2 * data.envelope.pos_m[1]
    assert np.all(gaps >= sphere_plus_travel)  # spheres at the extremes of their travel never overlap
    labels = read_static(path, "Points3D:labels")
    assert labels["/world/labels"] == [AIRCRAFT, *WASHOUTS]  # one label per object
    assert not any(k != "/world/labels" for k in read_static(path, "Boxes3D:labels"))


def test_slow_3d_poses_are_held_within_the_stated_tolerance(tmp_path):
    """A cockpit turning at 0.5 deg/s and then still: far fewer than 30 poses a second, each held within 0.1 deg."""
    base = make_data(n=2400)
    t = base.t_s
    yaw = np.radians(0.5) * np.minimum(t, 10.0)  # 0.5 deg/s for 10 s, then still
    q = Rotation.from_euler("ZYX", np.column_stack([yaw, 0.01 * np.sin(0.2 * t), 0 * t])).as_quat(scalar_first=True)
    pos = np.column_stack([0.02 * np.sin(0.1 * t), 0 * t, 0 * t])
    washouts = {w: MotionSeries(m.f_mps2, m.omega_radps, m.perceived_f_mps2, m.perceived_omega_radps, q)
                for w, m in base.washouts.items()}  # fmt: skip
    platforms = {
        w: PlatformSeries(pos, p.vel_mps, p.acc_mps2, p.wheel_radps, p.saturated) for w, p in base.platforms.items()
    }
    data = RecordingData(**{**base.__dict__, "washouts": washouts, "platforms": platforms})
    write_recording(tmp_path / "r.rrd", data)
    t_q, q_rec = read_component(tmp_path / "r.rrd", "Transform3D:quaternion")[f"/world/atlas/{WASHOUTS[0]}/cockpit"]
    t_p, p_rec = read_component(tmp_path / "r.rrd", "Transform3D:translation")[f"/world/atlas/{WASHOUTS[0]}/cockpit"]
    k = np.arange(0, t.size, 4)
    assert t_q.size < 0.4 * k.size and np.all(np.diff(t_q) <= 1.0 + 1e-9)
    held = Rotation.from_quat(_held(t_q, q_rec, t[k]).astype(np.float64))
    assert np.degrees((held * Rotation.from_quat(q[k], scalar_first=True).inv()).magnitude()).max() <= 0.1 + 1e-4
    np.testing.assert_allclose(_held(t_p, p_rec, t[k]), pos[k], atol=1e-3 + 1e-6)


def test_quaternion_order_conversion_matches_scipy():
    q_wxyz = Rotation.from_rotvec([[0.3, -0.2, 1.1], [0.0, 0.0, 0.0], [2.0, 1.0, -0.5]]).as_quat(scalar_first=True)
    np.testing.assert_allclose(
        Rotation.from_quat(quat_wxyz_to_xyzw(q_wxyz)).as_matrix(),
        Rotation.from_quat(q_wxyz, scalar_first=True).as_matrix(),
        atol=1e-15,
    )


def _views(path: Path) -> dict[str, dict[str, list]]:
    """Stored blueprint: view id -> its components (own and properties), plus "name", "class", "origin"."""
    views: dict[str, dict[str, list]] = {}
    for entity, comps in read_blueprint_components(path).items():
        parts = entity.strip("/").split("/")
        if parts[0] == "view":
            views.setdefault(parts[1], {}).update(comps)
    return views


def _containers(path: Path) -> dict[str, dict[str, list]]:
    return {
        e.strip("/").split("/")[1]: c for e, c in read_blueprint_components(path).items() if e.startswith("/container/")
    }


def test_blueprint_stacks_the_perceived_panels_on_the_whole_manoeuvre(written):
    path, data = written
    views = _views(path)
    by_name = {v["ViewBlueprint:display_name"][0]: (vid, v) for vid, v in views.items()}
    t_end_ns = round(data.t_s[-1] * 1e9)
    perceived = []
    series = read_scalar_series(path)
    for dof, _, _, unit in DOFS:
        vid, v = by_name[f"perceived {dof} [{unit}]"]
        perceived.append(vid)
        assert v["ViewBlueprint:space_origin"] == [f"/perceived/{dof}"]
        assert v["TimeAxis:view_range"] == [{"start": 0, "end": t_end_ns}]  # whole manoeuvre on opening
        assert v["VisibleTimeRanges:ranges"][0]["range"] == {"start": None, "end": None}  # all data queried
        assert v["PlotLegend:visible"] == [False]  # the legend has a view of its own
        lo, hi = v["ScalarAxis:range"][0]
        m = series[perceived_path(dof)][1]
        assert lo < m.min() and hi > m.max()  # every trace inside the fixed range
        # two multiples of the power of ten below its height at least (the viewer's rule, with the pixels, is
        # checked in tests/test_viewer_layout.py)
        step = 10.0 ** np.floor(np.log10(hi - lo))
        assert np.floor(hi / step) - np.ceil(lo / step) >= 1, (dof, lo, hi)
    # a tab named "Perceived": a top row (the phase lane over the left column, the legend over the right one), then
    # two columns (surge, sway, heave | roll, pitch, yaw)
    containers = _containers(path)
    (tab,) = [c for c in containers.values() if c.get("ContainerBlueprint:display_name") == ["Perceived"]]
    top_id, columns_id = (c.split("/")[1] for c in tab["ContainerBlueprint:contents"])
    phase_id, legend_id = (c.split("/")[1] for c in containers[top_id]["ContainerBlueprint:contents"])
    assert views[phase_id]["ViewBlueprint:class_identifier"] == ["StateTimeline"]
    assert views[phase_id]["ViewContents:query"] == [f"+ {phase_lane_path()}"]
    assert views[legend_id]["ViewBlueprint:class_identifier"] == ["2D"]
    assert views[legend_id]["ViewBlueprint:space_origin"] == ["/legend/perceived"]
    columns = [containers[c.split("/")[1]] for c in containers[columns_id]["ContainerBlueprint:contents"]]
    assert len(columns) == 2
    shown = [c.split("/")[1] for column in columns for c in column["ContainerBlueprint:contents"]]
    assert shown == perceived
    assert not any(v["ViewBlueprint:class_identifier"] == ["TimeSeries"] and v["ViewBlueprint:space_origin"][0]
                   .startswith("/legend") for v in views.values())  # no empty plot for a legend  # fmt: skip
    for name in ("Raw motion", "Atlas envelope", "Atlas small-angle", "Atlas unrestricted"):
        assert any(c.get("ContainerBlueprint:display_name") == [name] for c in containers.values())
    assert {f"{q} / limit" for q, _, _ in ENVELOPE_QUANTITIES} <= {n.split(" (")[0] for n in by_name}
    # panels collapsed so the plots get the screen (2 = Collapsed)
    comps = read_blueprint_components(path)
    assert comps["/blueprint_panel"]["PanelBlueprint:state"] == [2]
    assert comps["/selection_panel"]["PanelBlueprint:state"] == [2]
    assert comps["/time_panel"]["TimePanelBlueprint:state"] == [2]


def test_blueprint_3d_camera_frames_the_aircraft_and_every_platform(written):
    """Every object centre within 40 deg of the line of sight: inside the side pane (2:1) at rerun's 55 deg vertical
    field of view, about 45 deg each side horizontally."""
    path, _ = written
    (scene,) = [v for v in _views(path).values() if v["ViewBlueprint:class_identifier"] == ["3D"]]
    eye = np.array(scene["EyeControls3D:position"][0])
    target = np.array(scene["EyeControls3D:look_target"][0])
    np.testing.assert_allclose(scene["EyeControls3D:eye_up"][0], [0, 0, -1])  # NED: up is -z
    static_t = read_static(path, "Transform3D:translation")
    centres = [static_t["/world/aircraft"][0]] + [static_t[f"/world/atlas/{w}"][0] for w in WASHOUTS]
    sight = (target - eye) / np.linalg.norm(target - eye)
    for c in centres:
        to_c = (np.array(c) - eye) / np.linalg.norm(np.array(c) - eye)
        assert np.degrees(np.arccos(np.clip(to_c @ sight, -1, 1))) < 40.0


def _relative_luminance(rgb: tuple[int, int, int]) -> float:
    """WCAG 2 relative luminance of an sRGB colour."""
    c = np.array(rgb) / 255.0
    lin = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
    return float(lin @ [0.2126, 0.7152, 0.0722])


def _contrast(a: tuple[int, int, int], b: tuple[int, int, int]) -> float:
    la, lb = sorted((_relative_luminance(a), _relative_luminance(b)), reverse=True)
    return (la + 0.05) / (lb + 0.05)


def _series_colours(path: Path) -> dict[str, list[int]]:
    return read_static(path, "SeriesLines:colors")


def _rgba(rgb: tuple[int, int, int]) -> int:
    r, g, b = rgb
    return (r << 24) | (g << 16) | (b << 8) | 0xFF


def divmod_rgba(packed: int) -> tuple[int, int, int]:
    """An opaque 0xRRGGBBAA colour as (r, g, b); fails on a translucent one (its look depends on the background)."""
    assert packed & 0xFF == 0xFF, hex(packed)
    return (packed >> 24) & 0xFF, (packed >> 16) & 0xFF, (packed >> 8) & 0xFF


def test_colours_fixed_and_the_aircraft_readable_on_both_themes(written):
    path, _ = written
    colours = _series_colours(path)
    blue, orange, green = (31, 119, 180), (255, 127, 14), (44, 160, 44)
    aircraft = rerun_log.series_color(AIRCRAFT)
    for dof, _, _, _ in DOFS:
        assert colours[perceived_path(dof)] == [_rgba(c) for c in (blue, orange, green, aircraft)]
        assert colours[raw_path(dof)] == colours[perceived_path(dof)]
    for q, _, _ in ENVELOPE_QUANTITIES:
        assert colours[envelope_usage_path(q)] == [_rgba(c) for c in (blue, orange, green)]
    # the reference trace reads on the viewer's plots, light (255,255,255) and dark (13,13,13), measured on its
    # screenshots (WCAG >= 3:1 for graphics); so do the perception thresholds and the bound, in colours apart
    threshold = tuple(int(c) for c in divmod_rgba(colours[f"/perceived/{DOFS[0][0]}/threshold"][0]))
    for colour in (aircraft, threshold, (120, 120, 120)):
        assert _contrast(colour, (255, 255, 255)) >= 3.0 and _contrast(colour, (13, 13, 13)) >= 3.0, colour
    widths = read_static(path, "SeriesLines:widths")[perceived_path("surge")]
    assert widths[-1] > max(widths[:-1])  # the aircraft drawn wider (and last, on top)


def test_washout_names_come_from_the_data(tmp_path):
    """User-named variants: the names, their order and fixed colours for the known three, distinct spare ones."""
    names = ("large-angle", "cw1-soft", "small-angle", "my_variant")
    path = tmp_path / "r.rrd"
    data = make_data(n=60, washouts=names)
    write_recording(path, data)
    lines = read_static(path, "SeriesLines:names")
    assert lines[perceived_path("yaw")] == [*names, AIRCRAFT]
    colours = _series_colours(path)[perceived_path("yaw")]
    assert colours[0] == _rgba((255, 127, 14)) and colours[2] == _rgba((31, 119, 180))
    assert len(set(colours)) == 5
    lanes = read_component(path, "StateChange:state")
    assert washout_lane_path(data, "my_variant") == "/limits/4_my_variant" and "/limits/4_my_variant" in lanes
    views = {v["ViewBlueprint:display_name"][0] for v in _views(path).values()}
    assert {
        "cw1-soft: position [m] (x red, y green, z blue)",
        "my_variant: wheels [rad/s] (w1 red, w2 green, w3 blue)",
    } <= views


def test_rerun_cli_verifies_the_file(written):
    path, _ = written
    proc = subprocess.run(
        [str(find_rerun()), "rrd", "verify", str(path)], capture_output=True, text=True, timeout=120, check=False
    )
    assert proc.returncode == 0, proc.stderr
    assert "1 file verified without error" in proc.stdout + proc.stderr


def test_writes_only_the_rrd_into_the_folder(tmp_path):
    write_recording(tmp_path / "out" / "r.rrd", make_data(n=50, washouts=("small-angle",)))
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["r.rrd"]


def test_exception_while_writing_leaves_no_partial_file(tmp_path, monkeypatch):
    dest = tmp_path / "r.rrd"
    write_recording(dest, make_data(n=50))
    before = dest.read_bytes()

    def boom(*args, **kwargs):
        raise RuntimeError("disk full (simulated)")

    monkeypatch.setattr(rerun_log.scene3d, "send_scene", boom)  # fails after the motion and platform columns were sent
    with pytest.raises(RuntimeError, match="simulated"):
        write_recording(dest, make_data(n=50))
    with pytest.raises(RuntimeError, match="simulated"):
        write_recording(tmp_path / "new.rrd", make_data(n=50))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.rrd"]
    assert dest.read_bytes() == before


def test_inconsistent_shapes_are_rejected_before_writing(tmp_path):
    good = make_data(n=50)
    bad_q = MotionSeries(good.aircraft.f_mps2, good.aircraft.omega_radps, good.aircraft.perceived_f_mps2,
                         good.aircraft.perceived_omega_radps, good.aircraft.q[:, :3])  # fmt: skip
    cases = {
        "aircraft.q": RecordingData(**{**good.__dict__, "aircraft": bad_q}),
        "same keys": RecordingData(**{**good.__dict__, "platforms": {}}),
        "t_s": RecordingData(**{**good.__dict__, "t_s": good.t_s[::-1]}),
    }
    for needle, data in cases.items():
        with pytest.raises(ValueError, match=needle):
            write_recording(tmp_path / "x.rrd", data)
    assert list(tmp_path.iterdir()) == []


def test_same_inputs_same_traces(tmp_path):
    data = make_data(n=120)
    write_recording(tmp_path / "a.rrd", data)
    write_recording(tmp_path / "b.rrd", data)
    a, b = read_scalar_series(tmp_path / "a.rrd"), read_scalar_series(tmp_path / "b.rrd")
    assert a.keys() == b.keys()
    for k in a:
        np.testing.assert_array_equal(a[k][0], b[k][0])
        np.testing.assert_array_equal(a[k][1], b[k][1])


def test_write_time_15000_samples_three_washouts(tmp_path):
    """Prints the write time of a 15,000-sample, 3-washout recording (run with -s to see it). Not a timed assert."""
    data = make_data(n=15_000)
    start = time.perf_counter()
    write_recording(tmp_path / "big.rrd", data)
    elapsed = time.perf_counter() - start
    size_mb = (tmp_path / "big.rrd").stat().st_size / 1e6
    print(f"\nwrite_recording: 15,000 samples x 3 washouts in {elapsed:.3f} s, {size_mb:.1f} MB")
    t_rec, v_rec = read_scalar_series(tmp_path / "big.rrd")[perceived_path("yaw")]
    sources = [*data.washouts.values(), data.aircraft]
    expected = np.column_stack([np.rad2deg(m.perceived_omega_radps[:, 2]) for m in sources])
    tol = motion_tolerances(tmp_path / "big.rrd", perceived_path("yaw"), 4)
    assert_recorded(t_rec, v_rec, data.t_s, expected, tol)


def test_rerun_disabled_by_environment_is_an_error_not_an_empty_file(tmp_path):
    code = (
        "import sys; sys.path.insert(0, 'tests'); from test_rerun_log import make_data; "
        "from washbench.review.rerun_log import write_recording; "
        f"write_recording({str(tmp_path / 'r.rrd')!r}, make_data(n=20))"
    )
    root = Path(__file__).resolve().parent.parent
    out = subprocess.run(
        [sys.executable, "-c", code], env={**os.environ, "RERUN": "off"}, cwd=root, capture_output=True, text=True,
        timeout=120, check=False,
    )  # fmt: skip
    assert out.returncode != 0 and "RERUN=off" in out.stderr
    assert list(tmp_path.iterdir()) == []
