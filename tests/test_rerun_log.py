"""The rerun recording: write real .rrd files, read them back with rerun's own reader and check every trace.

The data is synthetic but shaped like the pipeline's (N samples at dt = 1/120 s, three washouts). Expected values come
from the inputs and from independent tools (scipy's Rotation for quaternion order, numpy edge detection for saturation
onsets, the rerun CLI for file validity).
"""

from __future__ import annotations

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
    MotionSeries,
    PlatformEnvelope,
    PlatformSeries,
    RecordingData,
    envelope_usage_path,
    perceived_path,
    platform_path,
    quat_wxyz_to_xyzw,
    raw_path,
    read_component,
    read_scalar_series,
    read_text_documents,
    write_recording,
)

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
            saturated={"pos": burst, "rate": (k % 300) == 5, "vel": np.zeros(n, dtype=bool)},
        )
    return RecordingData(
        title="c172p / coordinated_turn",
        t_s=t,
        aircraft=motion(),
        washouts={w: motion() for w in washouts},
        platforms=platforms,
        envelope=PlatformEnvelope(pos_m=(1.5, 1.5, 1.0), vel_mps=2.0, acc_mps2=5.0, wheel_radps=40.0),
        phases=[("entry", 0.0, t[n // 5]), ("hold", t[n // 5], t[n // 2]), ("exit", t[n // 2], t[-1])],
        metrics_markdown=METRICS,
    )


@pytest.fixture(scope="module")
def written(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, RecordingData]:
    data = make_data()
    path = tmp_path_factory.mktemp("rec") / "recording.rrd"
    write_recording(path, data)
    return path, data


def test_time_axis_is_k_dt_to_the_nanosecond(written):
    path, data = written
    series = read_scalar_series(path)
    t, _ = series[perceived_path("surge", AIRCRAFT)]
    assert t.shape == data.t_s.shape
    np.testing.assert_allclose(t, data.t_s, rtol=0, atol=0.5e-9 + 1e-15)


def test_motion_traces_equal_the_inputs(written):
    path, data = written
    series = read_scalar_series(path)
    sources = {AIRCRAFT: data.aircraft, **data.washouts}
    for dof, sig, axis, _unit in DOFS:
        for src, m in sources.items():
            _, perceived = series[perceived_path(dof, src)]
            _, raw = series[raw_path(dof, src)]
            assert perceived.dtype == np.float64
            if sig == "f":  # m/s^2, stored unchanged
                np.testing.assert_array_equal(perceived, m.perceived_f_mps2[:, axis])
                np.testing.assert_array_equal(raw, m.f_mps2[:, axis])
            else:  # shown in deg/s
                np.testing.assert_allclose(perceived, m.perceived_omega_radps[:, axis] * 180 / np.pi, rtol=1e-14)
                np.testing.assert_allclose(raw, m.omega_radps[:, axis] * 180 / np.pi, rtol=1e-14)


def test_platform_traces_and_envelope_usage(written):
    path, data = written
    series = read_scalar_series(path)
    for q, fname, _unit in ENVELOPE_QUANTITIES:
        limit = np.asarray(getattr(data.envelope, fname), dtype=float)  # scalar, or per axis (position)
        t_lim, v_lim = series[f"/envelope/{q}/limit"]
        np.testing.assert_array_equal(v_lim, [1.0, 1.0])
        np.testing.assert_allclose(t_lim, data.t_s[[0, -1]], atol=1e-9)
        for w in WASHOUTS:
            values = getattr(data.platforms[w], fname)
            _, usage = series[envelope_usage_path(q, w)]
            expected = np.linalg.norm(values / limit, ord=np.inf, axis=1)
            np.testing.assert_allclose(usage, expected, rtol=1e-15)
            if q == "position":  # first sample: x, y at 0.3 of 1.5 m, z at 0.9 of its own 1.0 m limit
                assert usage[0] == 0.9
            np.testing.assert_array_equal(series[platform_path(w, q)][1], values)
            np.testing.assert_array_equal(series[f"/platform/{w}/{q}/limit_max"][1], [limit, limit])
            np.testing.assert_array_equal(series[f"/platform/{w}/{q}/limit_min"][1], [-limit, -limit])
            if limit.ndim:  # per-axis limits are drawn one line per axis
                assert series[f"/platform/{w}/{q}/limit_max"][1].shape == (2, 3)


def test_saturation_markers_and_onset_events(written):
    path, data = written
    series = read_scalar_series(path)
    expected_onsets = []
    for w in WASHOUTS:
        for kind, panel in (("pos", "position"), ("rate", "other")):
            flags = data.platforms[w].saturated[kind]
            t, v = series[f"/envelope/{panel}/saturation/{w}/{kind}"]
            np.testing.assert_allclose(t, data.t_s[flags], atol=1e-9)
            np.testing.assert_array_equal(v, np.ones(flags.sum()))
            rising = np.flatnonzero(np.diff(flags.astype(int), prepend=0) == 1)
            expected_onsets += [(data.t_s[i], f"{w}: {kind} limit") for i in rising]
        assert not any(k.endswith(f"{w}/vel") for k in series), "a limit never reached must not get markers"
    t_ev, text = read_component(path, "TextLog:text")["/events/saturation"]
    assert len(text) == len(expected_onsets)
    got = sorted((round(float(tt), 6), s.split(" reached")[0]) for tt, s in zip(t_ev, text, strict=True))
    assert got == sorted((round(float(tt), 6), s) for tt, s in expected_onsets)
    _, levels = read_component(path, "TextLog:level")["/events/saturation"]
    assert set(levels) == {"WARN"}


def test_phases_on_the_timeline(written):
    path, data = written
    t, text = read_component(path, "TextLog:text")["/events/phases"]
    np.testing.assert_allclose(t, [p[1] for p in data.phases], atol=1e-9)
    assert [s.split()[1] for s in text] == ["entry", "hold", "exit"]


def test_metrics_markdown_document(written):
    path, _ = written
    docs = read_text_documents(path)
    assert docs["/metrics"] == METRICS
    media = [
        ch.to_record_batch().column("TextDocument:media_type").to_pylist()[0][0]
        for ch in RrdReader(str(path)).stream()
        if ch.entity_path == "/metrics"
    ]
    assert media == ["text/markdown"]


def test_3d_scene_quaternions_are_scalar_last_and_platforms_side_by_side(written):
    path, data = written
    quats = read_component(path, "Transform3D:quaternion")
    trans = read_component(path, "Transform3D:translation")
    x_fwd = np.array([1.0, 0.0, 0.0])
    for entity, m in [("/world/aircraft", data.aircraft)] + [(f"/world/atlas/{w}", data.washouts[w]) for w in WASHOUTS]:
        _, q_xyzw = quats[entity]
        assert q_xyzw.shape == (data.t_s.size, 4)
        assert q_xyzw.dtype == np.float32  # rerun stores quaternions as float32
        # Independent check of the order: scipy reads rerun's quaternion as scalar-last and must rotate "forward" as
        # the scalar-first input does.
        np.testing.assert_allclose(
            Rotation.from_quat(q_xyzw.astype(np.float64)).apply(x_fwd),
            Rotation.from_quat(m.q, scalar_first=True).apply(x_fwd),
            atol=1e-6,
        )
    offsets = []
    for w in WASHOUTS:
        _, tr = trans[f"/world/atlas/{w}"]
        offset = tr.astype(np.float64) - data.platforms[w].pos_m
        np.testing.assert_allclose(offset, np.tile(offset[0], (len(offset), 1)), atol=1e-6)  # stage moves the sphere
        offsets.append(offset[0])
    gaps = np.diff(np.array(offsets)[:, 1])
    sphere_plus_travel = data.envelope.sphere_diameter_m + 2 * data.envelope.pos_m[1]
    assert np.all(gaps >= sphere_plus_travel)  # spheres at the extremes of their travel never overlap


def test_quaternion_order_conversion_matches_scipy():
    q_wxyz = Rotation.from_rotvec([[0.3, -0.2, 1.1], [0.0, 0.0, 0.0], [2.0, 1.0, -0.5]]).as_quat(scalar_first=True)
    np.testing.assert_allclose(
        Rotation.from_quat(quat_wxyz_to_xyzw(q_wxyz)).as_matrix(),
        Rotation.from_quat(q_wxyz, scalar_first=True).as_matrix(),
        atol=1e-15,
    )


def test_blueprint_stored_with_one_panel_per_dof(written):
    path, _ = written
    reader = RrdReader(str(path))
    assert len(reader.recordings()) == 1
    (blueprint,) = reader.blueprints()
    names = set()
    for ch in reader.stream(store=blueprint):
        batch = ch.to_record_batch()
        if "ViewBlueprint:display_name" in batch.schema.names:
            names.update(row[0] for row in batch.column("ViewBlueprint:display_name").to_pylist() if row)
    for dof, _, _, unit in DOFS:
        assert f"Perceived {dof} ({unit})" in names
    assert "Specific force surge (m/s^2)" in names and "Angular velocity yaw (deg/s)" in names
    assert "Aircraft attitude and Atlas platforms (NED)" in names
    assert {f"Envelope: {q} (max |axis| / limit)" for q, _, _ in ENVELOPE_QUANTITIES} <= names
    assert "Other limits reached (rate)" in names
    assert "Metrics" in names


def test_series_have_fixed_colours_per_washout(written):
    path, _ = written
    colours: dict[str, set[int]] = {}
    for ch in RrdReader(str(path)).stream():
        batch = ch.to_record_batch()
        if ch.is_static and "SeriesLines:colors" in batch.schema.names:
            src = ch.entity_path.rsplit("/", 1)[-1]
            if ch.entity_path.startswith(("/perceived/", "/raw/", "/envelope/")) and src != "limit":
                colours.setdefault(src, set()).add(batch.column("SeriesLines:colors").to_pylist()[0][0])
    assert set(colours) == {AIRCRAFT, *WASHOUTS}
    assert all(len(c) == 1 for c in colours.values()), colours  # one colour per source everywhere
    assert len({next(iter(c)) for c in colours.values()}) == 4  # and four distinct colours


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

    monkeypatch.setattr(rerun_log, "_send_scene", boom)  # fails after the motion and platform columns were sent
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
    series = read_scalar_series(tmp_path / "big.rrd")
    assert len(series[perceived_path("yaw", "unrestricted")][1]) == 15_000


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
