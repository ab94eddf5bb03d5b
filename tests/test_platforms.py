"""Platforms of every kind (``--platform FILE``, docs/platforms.md), end to end on real JSBSim flights.

A hexapod file made here (never bundled) is flown with every washout that can drive it on a gentle (C172 coordinated
turn) and a violent (Columbia 400 aerobatics) flight: the legs are recomputed independently from the platform's
position and attitude in traces.parquet (numpy and scipy's Rotation, not washbench's kinematics) and must stay
within the stroke, the leg speeds and accelerations within their limits, and agree with the leg columns.
"""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest
from scipy.spatial.transform import Rotation

from washbench.io.paths import DATA_DIR

# a geometry of its own: smaller than the bundled one, joints off the platform plane, asymmetric pairs
BASE = [[1.30, -0.25, 0.05], [1.30, 0.25, 0.0], [-0.43, 1.25, 0.0], [-0.87, 1.0, 0.02], [-0.87, -1.0, 0.0],
        [-0.43, -1.25, 0.0]]  # fmt: skip
PLATFORM = [[0.60, -0.72, 0.35], [0.60, 0.72, 0.35], [0.32, 0.88, 0.35], [-0.93, 0.17, 0.35], [-0.93, -0.17, 0.35],
            [0.32, -0.88, 0.35]]  # fmt: skip
LMIN, LMAX, VMAX, AMAX = 1.45, 2.05, 0.6, 7.0
DT = 1.0 / 120.0  # both flights' step (checked below)

HEXAPOD_WASHOUTS = ("small-angle", "large-angle", "adaptive", "adaptive-large-angle", "optimal", "mpc")


def washbench(*args: object, timeout: float = 300) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "washbench", *map(str, args)], capture_output=True, text=True,
                          timeout=timeout)  # fmt: skip


def hexapod_file(path: Path) -> Path:
    neutral_z = -1.83  # legs near mid-stroke at neutral
    lines = [
        "kind: hexapod",
        "name: test hexapod (made for this test)",
        f"base_joints_m: {BASE}",
        f"platform_joints_m: {PLATFORM}",
        f"neutral_m: [0.0, 0.0, {neutral_z}]",
        f"leg_length_m: {{min: {LMIN}, max: {LMAX}}}",
        f"leg_velocity_limit_mps: {VMAX}",
        f"leg_acceleration_limit_mps2: {AMAX}",
    ]
    path.write_text("\n".join(lines) + "\n")
    return path


def legs_from_pose(pos: np.ndarray, q_wxyz: np.ndarray) -> np.ndarray:
    """Leg lengths (N, 6) from the MRP position (N, 3) and attitude (N, 4, scalar first), scipy's rotation."""
    rot = Rotation.from_quat(q_wxyz[:, [1, 2, 3, 0]]).as_matrix()  # scipy: scalar last
    b = np.array(BASE)
    a = np.array(PLATFORM)
    n = np.array([0.0, 0.0, -1.83])
    return np.stack([np.linalg.norm(n + pos + rot @ a[i] - b[i], axis=1) for i in range(6)], axis=1)


@pytest.fixture(scope="module")
def flights(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    root = tmp_path_factory.mktemp("flights")
    out = {}
    for label, manoeuvre in (("gentle", "c172/coordinated_turn"), ("violent", "columbia400/aerobatics")):
        proc = washbench("fly", manoeuvre, "--out", root / label, "--quiet")
        assert proc.returncode == 0, proc.stderr
        out[label] = root / label / "flight.parquet"
    # the gentle flight's first 25 s (the settle, the roll-in and the turn's start: 3000 of its 10114 samples) is
    # gentle enough and keeps the module's shared cueing of six washouts within the test command's budget
    gentle = pq.read_table(out["gentle"])
    pq.write_table(gentle.slice(0, 3000), root / "gentle_25s.parquet")
    out["gentle"] = root / "gentle_25s.parquet"
    return out


@pytest.fixture(scope="module")
def hexapod_runs(flights: dict[str, Path], tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    root = tmp_path_factory.mktemp("hexapod")
    platform = hexapod_file(root / "my_hexapod.yaml")
    out = {}
    for label, flight in flights.items():
        washouts = [a for w in HEXAPOD_WASHOUTS for a in ("--washout", w)]
        proc = washbench("cue", flight, "--out", root / label, "--platform", platform, *washouts, "--no-recording",
                         "--no-figures", "--quiet")  # fmt: skip
        assert proc.returncode == 0, proc.stderr
        (traces,) = (root / label).rglob("traces.parquet")
        out[label] = traces
    return out


@pytest.mark.parametrize("label", ["gentle", "violent"])
@pytest.mark.parametrize("washout", HEXAPOD_WASHOUTS)
def test_hexapod_legs_stay_within_stroke_and_limits(hexapod_runs, label, washout):
    table = pq.read_table(hexapod_runs[label]).to_pydict()
    t = np.asarray(table["t_s"])
    assert np.allclose(np.diff(t), DT, rtol=1e-6)
    pos = np.column_stack([table[f"{washout}.pos_{a}_m"] for a in "xyz"])
    q = np.column_stack([table[f"{washout}.q_{c}"] for c in "wxyz"])
    legs = legs_from_pose(pos, q)
    assert legs.min() >= LMIN and legs.max() <= LMAX
    speed = np.abs(np.diff(legs, axis=0)) / DT
    assert speed.max() <= VMAX
    acc = np.abs(np.diff(legs, 2, axis=0)) / DT**2
    assert acc.max() <= AMAX * (1 + 1e-9)  # (second differences of recomputed lengths: rounding of ~1e-13 m / dt^2)
    columns = np.column_stack([table[f"{washout}.leg_{i}_m"] for i in range(1, 7)])
    np.testing.assert_allclose(columns, legs, rtol=0, atol=1e-9)
    assert f"{washout}.wheel_1_radps" not in table  # the Atlas's own columns are not on a hexapod


def test_the_violent_flight_drives_the_hexapod_to_its_limits(hexapod_runs):
    """The limit-respecting path is exercised: set points beyond the workspace (scaled towards neutral), legs
    at their stroke or speed."""
    table = pq.read_table(hexapod_runs["violent"]).to_pydict()
    for washout in HEXAPOD_WASHOUTS:
        pos = np.column_stack([table[f"{washout}.pos_{a}_m"] for a in "xyz"])
        q = np.column_stack([table[f"{washout}.q_{c}"] for c in "wxyz"])
        legs = legs_from_pose(pos, q)
        assert np.sum(table[f"{washout}.sat_pos"]) > 0, washout
        assert legs.max() > LMAX - 0.05 or legs.min() < LMIN + 0.05, washout


def test_inside_its_limits_the_hexapod_reaches_the_set_point(hexapod_runs):
    table = pq.read_table(hexapod_runs["gentle"]).to_pydict()
    w = "large-angle"
    free = ~np.any([np.asarray(table[f"{w}.sat_{k}"], dtype=bool) for k in ("pos", "vel", "acc")], axis=0)
    free[0] = False
    assert free.sum() > 100
    for a in "xyz":
        np.testing.assert_array_equal(np.asarray(table[f"{w}.pos_{a}_m"])[free],
                                      np.asarray(table[f"{w}.sp_pos_{a}_m"])[free])  # fmt: skip


@pytest.mark.parametrize("washout", ["unrestricted", "adaptive-unrestricted", "bound"])
def test_washouts_that_cannot_drive_a_hexapod_are_refused_in_one_line(flights, tmp_path, washout):
    platform = hexapod_file(tmp_path / "h.yaml")
    out = tmp_path / "out"
    proc = washbench("cue", flights["gentle"], "--out", out, "--platform", platform, "--washout", washout, "--quiet")
    assert proc.returncode != 0
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in proc.stderr and washout in lines[0], proc.stderr
    assert not out.exists() or not any(out.rglob("traces.parquet"))


def test_an_unknown_platform_kind_is_refused_naming_file_line_and_field(flights, tmp_path):
    bad = tmp_path / "blimp.yaml"
    bad.write_text("name: x\nkind: blimp\n")
    proc = washbench("cue", flights["gentle"], "--out", tmp_path / "out", "--platform", bad, "--quiet")
    assert proc.returncode != 0
    expected = f"{bad}:2: kind: unknown platform kind 'blimp' (valid: atlas, hexapod, rig)"
    assert proc.stderr.strip().endswith(expected) and len(proc.stderr.strip().splitlines()) == 1, proc.stderr


def test_kind_atlas_is_todays_atlas_bit_for_bit(flights, tmp_path):
    atlas = tmp_path / "atlas.yaml"
    atlas.write_text("kind: atlas\n" + (DATA_DIR / "atlas.yaml").read_text())
    tables = []
    for name, extra in (("default", []), ("kind", ["--platform", atlas])):
        proc = washbench("cue", flights["gentle"], "--out", tmp_path / name, *extra, "--no-recording", "--no-figures",
                         "--quiet")  # fmt: skip
        assert proc.returncode == 0, proc.stderr
        (traces,) = (tmp_path / name).rglob("traces.parquet")
        tables.append(pq.read_table(traces))
    assert tables[0].column_names == tables[1].column_names
    assert not any(".leg_" in c for c in tables[0].column_names)
    for c in tables[0].column_names:  # bit for bit (NaN input columns included)
        a, b = (t.column(c).to_numpy() for t in tables)
        assert a.dtype == b.dtype and a.tobytes() == b.tobytes(), c


def test_a_rig_stays_within_its_angles_and_rates(flights, tmp_path):
    rig = tmp_path / "rig.yaml"
    rig.write_text(
        "kind: rig\nname: test rig\n"
        "roll: {angle_limit_deg: 15.0, rate_limit_degps: 30.0, acceleration_limit_degps2: 200.0}\n"
        "pitch: {angle_limit_deg: 12.0, rate_limit_degps: 25.0, acceleration_limit_degps2: 150.0}\n"
        "heave: {position_limit_m: 0.1, velocity_limit_mps: 0.3, acceleration_limit_mps2: 3.0}\n"
    )
    proc = washbench("cue", flights["violent"], "--out", tmp_path / "out", "--platform", rig, "--washout",
                     "large-angle", "--washout", "optimal", "--no-recording", "--no-figures", "--quiet")  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    (traces,) = (tmp_path / "out").rglob("traces.parquet")
    table = pq.read_table(traces).to_pydict()
    for w in ("large-angle", "optimal"):
        q = np.column_stack([table[f"{w}.q_{c}"] for c in "wxyz"])
        yaw, pitch, roll = Rotation.from_quat(q[:, [1, 2, 3, 0]]).as_euler("ZYX", degrees=True).T
        assert np.abs(roll).max() <= 15.0 + 1e-9 and np.abs(pitch).max() <= 12.0 + 1e-9
        assert np.abs(yaw).max() < 1e-9  # no yaw axis
        assert np.abs(np.diff(roll)).max() / DT <= 30.0 * (1 + 1e-9)
        assert np.abs(np.diff(pitch)).max() / DT <= 25.0 * (1 + 1e-9)
        z = np.asarray(table[f"{w}.pos_z_m"])
        assert np.abs(z).max() <= 0.1 and np.abs(np.diff(z)).max() / DT <= 0.3 * (1 + 1e-9)
        assert np.abs(table[f"{w}.pos_x_m"]).max() == 0.0 and np.abs(table[f"{w}.pos_y_m"]).max() == 0.0
        assert np.sum(table[f"{w}.sat_pos"]) > 0  # the violent flight reaches the stops


PLUGIN = '''
import numpy as np
from pydantic import BaseModel


class Params(BaseModel):
    travel_m: float = 0.2


class BoxPlatform:
    """A toy platform: the set point's translation clipped to a box, the attitude as set."""

    platform_name = "box"
    Params = Params

    def __init__(self, params, context):
        self.travel = (params or Params()).travel_m
        self.dt = context.dt_s

    def start(self, pos, q):
        return np.clip(pos, -self.travel, self.travel), q

    def step(self, pos, q):
        p = np.clip(pos, -self.travel, self.travel)
        return p, q, (int(np.any(p != pos)), 0, 0, 0, 0)


class Broken(BoxPlatform):
    platform_name = "broken"

    def step(self, pos, q):
        return pos, q, (2, 0, 0, 0, 0)
'''


def test_a_platform_plugin_drives_the_washouts_and_is_recorded(flights, tmp_path):
    plugin = tmp_path / "box.py"
    plugin.write_text(PLUGIN)
    file = tmp_path / "tiny.yaml"
    file.write_text("kind: box\nname: tiny box\ntravel_m: 0.02\n")
    out = tmp_path / "out"
    proc = washbench("cue", flights["gentle"], "--out", out, "--platform-plugin", f"{plugin}:BoxPlatform",
                     "--platform", file, "--washout", "large-angle", "--no-recording", "--no-figures",
                     "--quiet")  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    (traces,) = out.rglob("traces.parquet")
    table = pq.read_table(traces).to_pydict()
    pos = np.column_stack([table[f"large-angle.pos_{a}_m"] for a in "xyz"])
    sp = np.column_stack([table[f"large-angle.sp_pos_{a}_m"] for a in "xyz"])
    np.testing.assert_array_equal(pos, np.clip(sp, -0.02, 0.02))  # the plugin's motion, the washout's set points
    assert np.abs(sp).max() > 0.05 and np.sum(table["large-angle.sat_pos"]) > 0
    # the head motion is the plugin's: the platform's acceleration is the second difference of its position
    acc = np.asarray(table["large-angle.acc_x_mps2"])
    np.testing.assert_allclose(acc[2:], np.diff(pos[:, 0], 2) / DT**2, atol=1e-6)
    (run,) = out.rglob("run.json")
    record = json.loads(run.read_text())["provenance"]["platform"]
    assert record["path"] == str(file) and record["values"]["kind"] == "box" and len(record["sha256"]) == 64


def test_a_broken_platform_plugin_is_one_line(flights, tmp_path):
    plugin = tmp_path / "box.py"
    plugin.write_text(PLUGIN)
    proc = washbench("cue", flights["gentle"], "--out", tmp_path / "out", "--platform-plugin", f"{plugin}:Broken",
                     "--washout", "large-angle", "--quiet")  # fmt: skip
    assert proc.returncode != 0
    assert len(proc.stderr.strip().splitlines()) == 1 and "Traceback" not in proc.stderr, proc.stderr
    assert "platform broken" in proc.stderr and "flags" in proc.stderr
    assert not any((tmp_path / "out").rglob("traces.parquet"))


def test_the_recording_draws_the_hexapods_legs_as_long_as_the_leg_columns(flights, tmp_path):
    platform = hexapod_file(tmp_path / "h.yaml")
    out = tmp_path / "out"
    proc = washbench("cue", flights["violent"], "--out", out, "--platform", platform, "--washout", "large-angle",
                     "--no-figures", "--quiet")  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    from washbench.review.rrd_read import read_component

    (rrd,) = out.rglob("recording.rrd")
    (traces,) = out.rglob("traces.parquet")
    table = pq.read_table(traces).to_pydict()
    t_s = np.asarray(table["t_s"])
    legs = np.column_stack([table[f"large-angle.leg_{i}_m"] for i in range(1, 7)])
    t, strips = read_component(rrd, "LineStrips3D:strips")["/world/hexapod/large-angle/legs"]
    assert len(t) > 100
    rows = np.searchsorted(t_s, t - 1e-9)
    drawn = np.array([[np.linalg.norm(np.subtract(s[1], s[0], dtype=float)) for s in row] for row in strips])
    np.testing.assert_allclose(drawn, legs[rows], atol=2e-5)  # float32 in the recording
    np.testing.assert_allclose(np.asarray(strips[0][0][0], float), BASE[0], atol=1e-6)  # leg 1 starts at base joint 1
    titles = _titles(rrd)  # the titles name the hexapod (they said "Atlas")
    assert {"Hexapod per washout", "Hexapod envelope"} <= titles and not any("Atlas" in t for t in titles)


def _geometry():
    from washbench.platform.hexapod import HexapodModel

    model = HexapodModel.model_validate_json(json.dumps({
        "kind": "hexapod", "name": "t", "base_joints_m": BASE, "platform_joints_m": PLATFORM,
        "neutral_m": [0.0, 0.0, -1.83], "leg_length_m": {"min": LMIN, "max": LMAX},
        "leg_velocity_limit_mps": VMAX, "leg_acceleration_limit_mps2": AMAX,
    }))  # fmt: skip
    return model, model.geometry()


def test_forward_kinematics_recovers_the_pose_of_the_legs():
    from washbench.platform.hexapod_kinematics import forward_kinematics, leg

    _, geo = _geometry()
    rng = np.random.default_rng(4)
    work = np.zeros(48)
    for _ in range(20):
        p = tuple(rng.uniform(-0.1, 0.1, 3))
        rot = Rotation.from_rotvec(rng.uniform(-0.1, 0.1, 3))
        x, y, z, w = rot.as_quat()
        legs = legs_from_pose(np.array([p]), np.array([[w, x, y, z]]))[0]
        assert np.allclose([leg(geo, i, p, (w, x, y, z)) for i in range(6)], legs, atol=1e-12, rtol=0)
        p_fk, q_fk, ok = forward_kinematics(geo, legs, (0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0), work)
        assert ok
        np.testing.assert_allclose(p_fk, p, atol=1e-10)
        angle = (Rotation.from_quat([q_fk[1], q_fk[2], q_fk[3], q_fk[0]]).inv() * rot).magnitude()
        assert angle < 1e-10


def test_a_set_point_beyond_the_workspace_is_scaled_to_its_edge():
    from washbench.platform.hexapod_kinematics import reachable

    _, geo = _geometry()
    rot = Rotation.from_rotvec([0.3, -0.2, 0.1])
    x, y, z, w = rot.as_quat()
    p, q, scaled = reachable(geo, (0.8, -0.5, 0.4), (w, x, y, z))
    assert scaled == 1
    legs = legs_from_pose(np.array([p]), np.array([q]))[0]
    assert legs.min() >= LMIN and legs.max() <= LMAX
    assert min(legs.min() - LMIN, LMAX - legs.max()) < 1e-6  # the largest scale: a leg at its stroke's end
    s = p[0] / 0.8  # the same scale on translation and rotation, towards neutral
    np.testing.assert_allclose(p, [0.8 * s, -0.5 * s, 0.4 * s], rtol=1e-12)
    np.testing.assert_allclose(Rotation.from_quat([q[1], q[2], q[3], q[0]]).as_rotvec(), s * rot.as_rotvec(),
                               atol=1e-12)  # fmt: skip


def _recorded_pose(rrd: Path, entity: str, table: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The cockpit's recorded pose (rows of traces.parquet it stands for, quaternion scalar last, translation)."""
    from washbench.review.rrd_read import read_component

    t_q, q = read_component(rrd, "Transform3D:quaternion")[entity]
    t_p, p = read_component(rrd, "Transform3D:translation")[entity]
    np.testing.assert_array_equal(t_q, t_p)
    rows = np.searchsorted(np.asarray(table["t_s"]), t_q - 1e-9)
    return rows, np.asarray(q, dtype=np.float64), np.asarray(p, dtype=np.float64)


def _titles(rrd: Path) -> set[str]:
    from washbench.review.rrd_read import read_blueprint_components

    names = set()
    for comps in read_blueprint_components(rrd).values():
        for key in ("ViewBlueprint:display_name", "ContainerBlueprint:display_name"):
            names.update(str(n) for n in comps.get(key) or [])
    return names


def test_a_rig_and_a_plugins_platform_are_recorded_with_titles_naming_them(flights, tmp_path):
    """docs/platforms.md said: on a rig or a plugin's platform the recording is not written. Now it is: the rig drawn
    as a base and the cockpit at the pose in traces.parquet (scipy checks the attitude), its angles against its stops
    in the envelope tab; the plugin's platform (no envelope) with its time series and its pose; every title names
    the platform, none says Atlas."""
    from washbench.review.rrd_read import read_scalar_series

    plugin = tmp_path / "box.py"
    plugin.write_text(PLUGIN)
    runs = {"rig": ("--platform", DATA_DIR / "rig2dof.yaml"), "box": ("--platform-plugin", f"{plugin}:BoxPlatform")}
    for label, option in runs.items():
        out = tmp_path / label
        proc = washbench("cue", flights["gentle"], "--out", out, *option, "--washout", "large-angle", "--no-figures",
                         "--quiet")  # fmt: skip
        assert proc.returncode == 0, proc.stderr
        (rrd,) = out.rglob("recording.rrd")
        (traces,) = out.rglob("traces.parquet")
        table = pq.read_table(traces).to_pydict()
        titles = _titles(rrd)
        word = {"rig": "Rig", "box": "box"}[label]
        assert f"{word} per washout" in titles and f"{word} large-angle" in titles and f"{word} envelope" in titles
        assert f"Aircraft (from its initial heading) and {word} cockpits" in titles
        assert not any("Atlas" in t for t in titles), titles
        rows, q, p = _recorded_pose(rrd, "/world/platform/large-angle/cockpit", table)
        assert len(rows) > 100
        q_traces = np.column_stack([table[f"large-angle.q_{a}"] for a in "wxyz"])[rows]
        pos = np.column_stack([table[f"large-angle.pos_{a}_m"] for a in "xyz"])[rows]
        angle = (Rotation.from_quat(q) * Rotation.from_quat(q_traces, scalar_first=True).inv()).magnitude()
        assert np.degrees(angle).max() < 1e-3  # float32 in the recording
        np.testing.assert_allclose(p, pos, atol=1e-6)
        series = read_scalar_series(rrd)
        assert "/platform/large-angle/position/axes" in series  # the time series, whatever the platform
        if label == "rig":  # its angles against its 20 deg stops (rig2dof.yaml), scipy's ZYX angles
            t_a, usage = series["/envelope/angle"]
            q_all = np.column_stack([table[f"large-angle.q_{a}"] for a in "wxyz"])
            yaw_pitch_roll = Rotation.from_quat(q_all, scalar_first=True).as_euler("ZYX")
            expected = np.max(np.abs(yaw_pitch_roll[:, 1:]), axis=1) / np.radians(20.0)
            k = np.searchsorted(np.asarray(table["t_s"]), t_a - 1e-9)
            usage = usage.reshape(len(t_a), -1)[:, 0]
            np.testing.assert_allclose(usage, expected[k], atol=1e-5)
            assert 0.2 < usage.max() <= 1.0 + 1e-6
        else:  # no envelope: no usage panel of the stage, no limit line
            assert "/envelope/position" not in series and "/platform/large-angle/position/limit_max" not in series
