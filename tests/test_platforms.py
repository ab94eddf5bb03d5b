"""Platforms of every kind (``--platform FILE``, docs/platforms.md), end to end on real JSBSim flights.

A hexapod file made here (never bundled) is flown with every washout that can drive it on a gentle (C172 coordinated
turn) and a violent (Columbia 400 aerobatics) flight: the legs are recomputed independently from the platform's
position and attitude in traces.parquet (numpy and scipy's Rotation, not washbench's kinematics) and must stay
within the stroke, the leg speeds and accelerations within their limits, and agree with the leg columns.
"""

import json
import subprocess
from pathlib import Path
from types import SimpleNamespace

import inprocess
import numpy as np
import pyarrow.parquet as pq
import pytest
import yaml
from ceiling_helpers import check_ceiling_below_every_washout
from scipy.spatial.transform import Rotation

from washbench.cueing.params import DEFAULT_PARAMS_PATH
from washbench.io.paths import DATA_DIR
from washbench.review.result_data import load_result

# a geometry of its own: smaller than the bundled one, joints off the platform plane, asymmetric pairs
BASE = [[1.30, -0.25, 0.05], [1.30, 0.25, 0.0], [-0.43, 1.25, 0.0], [-0.87, 1.0, 0.02], [-0.87, -1.0, 0.0],
        [-0.43, -1.25, 0.0]]  # fmt: skip
PLATFORM = [[0.60, -0.72, 0.35], [0.60, 0.72, 0.35], [0.32, 0.88, 0.35], [-0.93, 0.17, 0.35], [-0.93, -0.17, 0.35],
            [0.32, -0.88, 0.35]]  # fmt: skip
LMIN, LMAX, VMAX, AMAX = 1.45, 2.05, 0.6, 7.0
DT = 1.0 / 120.0  # both flights' step (checked below)

HEXAPOD_WASHOUTS = ("small-angle", "large-angle", "adaptive", "adaptive-large-angle", "optimal", "mpc")


def washbench(*args: object, timeout: float = 300) -> subprocess.CompletedProcess:
    return inprocess.washbench(*args, timeout=timeout)


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


def one_search_step(folder: Path) -> Path:
    """The bundled parameter file with one programme of the best achieved's search instead of three: the search runs
    on the hexapod and the rig as it does on the Atlas (its steps cost about 3.5 s each on 3000 hexapod samples)."""
    path = folder / "one_search_step.yaml"
    path.write_text(DEFAULT_PARAMS_PATH.read_text().rstrip("\n") + "\nbound:\n  search_steps: 1\n")
    return path


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
        # the bound (its replay and ceiling.csv) on the gentle flight only: its replay's programmes on the violent
        # flight's 8369 samples would double the fixture's time (the ceiling there: test_the_ceiling_is_below...)
        bound = ("bound",) if label == "gentle" else ()
        washouts = [a for w in (*HEXAPOD_WASHOUTS, *bound) for a in ("--washout", w)]
        proc = washbench("cue", flight, "--out", root / label, "--platform", platform, *washouts, "--no-recording",
                         "--no-figures", "--quiet", "--params", one_search_step(root))  # fmt: skip
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
    at their stroke or speed (every washout but mpc, which plans against the legs: the next test)."""
    table = pq.read_table(hexapod_runs["violent"]).to_pydict()
    for washout in (w for w in HEXAPOD_WASHOUTS if w != "mpc"):
        pos = np.column_stack([table[f"{washout}.pos_{a}_m"] for a in "xyz"])
        q = np.column_stack([table[f"{washout}.q_{c}"] for c in "wxyz"])
        legs = legs_from_pose(pos, q)
        assert np.sum(table[f"{washout}.sat_pos"]) > 0, washout
        assert legs.max() > LMAX - 0.05 or legs.min() < LMIN + 0.05, washout


def test_the_mpc_plans_inside_the_legs_on_the_violent_flight(hexapod_runs):
    """The MPC plans against the legs (linearised about the current pose, docs/optimal-mpc.md): the legs of its set
    points (sp_pos, sp_q), recomputed independently, stay within the stroke, so the hexapod's scaling towards neutral
    (sat_pos) is not needed, on the flight where the small-angle washout's set points leave the stroke on a third of
    the samples or more; and the MPC uses its workspace (a leg within 2 cm of an end of the stroke)."""
    table = pq.read_table(hexapod_runs["violent"]).to_pydict()

    def set_point_legs(washout: str) -> np.ndarray:
        pos = np.column_stack([table[f"{washout}.sp_pos_{a}_m"] for a in "xyz"])
        q = np.column_stack([table[f"{washout}.sp_q_{c}"] for c in "wxyz"])
        return legs_from_pose(pos, q / np.linalg.norm(q, axis=1, keepdims=True))

    def outside(legs: np.ndarray) -> float:
        return float(np.mean(np.any((legs < LMIN) | (legs > LMAX), axis=1)))

    mpc = set_point_legs("mpc")
    assert outside(mpc) <= 1e-3
    assert np.mean(table["mpc.sat_pos"]) <= 1e-3
    assert mpc.max() > LMAX - 0.02 or mpc.min() < LMIN + 0.02
    assert outside(set_point_legs("small-angle")) > 0.3


def test_inside_its_limits_the_hexapod_reaches_the_set_point(hexapod_runs):
    table = pq.read_table(hexapod_runs["gentle"]).to_pydict()
    w = "large-angle"
    free = ~np.any([np.asarray(table[f"{w}.sat_{k}"], dtype=bool) for k in ("pos", "vel", "acc")], axis=0)
    free[0] = False
    assert free.sum() > 100
    for a in "xyz":
        np.testing.assert_array_equal(np.asarray(table[f"{w}.pos_{a}_m"])[free],
                                      np.asarray(table[f"{w}.sp_pos_{a}_m"])[free])  # fmt: skip


@pytest.mark.parametrize("washout", ["unrestricted", "adaptive-unrestricted"])
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


RIG = ("kind: rig\nname: test rig\n"
       "roll: {angle_limit_deg: 15.0, rate_limit_degps: 30.0, acceleration_limit_degps2: 200.0}\n"
       "pitch: {angle_limit_deg: 12.0, rate_limit_degps: 25.0, acceleration_limit_degps2: 150.0}\n"
       "heave: {position_limit_m: 0.1, velocity_limit_mps: 0.3, acceleration_limit_mps2: 3.0}\n")  # fmt: skip


@pytest.fixture(scope="module")
def rig_run(flights: dict[str, Path], tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The violent flight on a rig of the test's own (large-angle and optimal): the result folder."""
    root = tmp_path_factory.mktemp("rig")
    rig = root / "rig.yaml"
    rig.write_text(RIG)
    proc = washbench("cue", flights["violent"], "--out", root / "out", "--platform", rig, "--washout",
                     "large-angle", "--washout", "optimal", "--no-recording", "--no-figures", "--quiet")  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    return root / "out"


def test_the_rig_s_envelope_figure_shows_each_angle_against_its_stop(rig_run):
    """The report's envelope panels on a rig: each gimbal's angle over its stop (scipy's ZYX angles, not
    washbench's), the heave over its travel, the rates and accelerations over their limits (at most 1, reached on
    the violent flight), and the figure drawn by ``washbench report``."""
    (traces,) = rig_run.rglob("traces.parquet")
    table = pq.read_table(traces).to_pydict()
    data = load_result(traces.parent)
    assert list(data.usage) == ["roll", "pitch", "heave", "rate", "acceleration"]
    for w in ("large-angle", "optimal"):
        q = np.column_stack([table[f"{w}.q_{c}"] for c in "wxyz"])
        _, pitch, roll = Rotation.from_quat(q[:, [1, 2, 3, 0]]).as_euler("ZYX", degrees=True).T
        np.testing.assert_allclose(data.usage["roll"][w], np.abs(roll) / 15.0, atol=1e-9)
        np.testing.assert_allclose(data.usage["pitch"][w], np.abs(pitch) / 12.0, atol=1e-9)
        rate = np.maximum(np.abs(np.diff(roll)) / 30.0, np.abs(np.diff(pitch)) / 25.0) / DT
        np.testing.assert_allclose(data.usage["rate"][w][1:], np.maximum(rate, np.abs(np.diff(table[f"{w}.pos_z_m"]))
                                   / DT / 0.3), rtol=1e-6, atol=1e-9)  # fmt: skip
        for panel in ("rate", "acceleration"):
            assert data.usage[panel][w].max() <= 1.0 + 1e-6
    assert max(data.usage["roll"][w].max() for w in ("large-angle", "optimal")) == pytest.approx(1.0, abs=1e-6)
    proc = washbench("report", traces.parent)
    assert proc.returncode == 0, proc.stderr
    assert (traces.parent / "figures" / "envelope.png").stat().st_size > 10000


def test_a_rig_stays_within_its_angles_and_rates(rig_run):
    (traces,) = rig_run.rglob("traces.parquet")
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

    @staticmethod
    def envelope(params):
        from washbench.platform.hexapod import MotionEnvelope

        t = (params or Params()).travel_m
        return MotionEnvelope.model_validate({"name": "box", "translation": {
            "position_limit_m": {"x": t, "y": t, "z": t}, "velocity_limit_mps": {"x": 1, "y": 1, "z": 1},
            "acceleration_limit_mps2": {"x": 5, "y": 5, "z": 5}},
            "rotation": {"rate_limit_degps": 30, "acceleration_limit_degps2": 100, "catch_up_fraction": 0.5}})

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
    # the plugin exposes its limits (envelope): the report's envelope figure draws the motion against them
    assert record["values"]["envelope"]["translation"]["position_limit_m"] == {"x": 0.02, "y": 0.02, "z": 0.02}
    data = load_result(traces.parent)
    assert set(data.usage) == {"position", "velocity", "acceleration", "rate", "ang. acc."}
    np.testing.assert_allclose(data.usage["position"]["large-angle"], np.abs(pos).max(axis=1) / 0.02, rtol=1e-12)
    omega = np.column_stack([table[f"large-angle.omega_platform_{a}_degps"] for a in "xyz"])
    np.testing.assert_allclose(data.usage["rate"]["large-angle"], np.linalg.norm(omega, axis=1) / 30.0, rtol=1e-12)


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
    in the envelope tab; the plugin's platform with its time series, its pose and its envelope box; every title names
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
        else:  # BoxPlatform exposes envelope(params): the stage's usage panel against its box
            assert "/envelope/position" in series


# --- the ceiling over a hexapod's and a rig's workspace (docs/yardstick.md, "Over a hexapod's or a rig's workspace")


def _trace_namespace(table: dict, washout: str) -> SimpleNamespace:
    """A washout's platform motion from traces.parquet, in SI (what analysis.relaxation.observed reads)."""

    def cols(fmt: str, axes: str = "xyz") -> np.ndarray:
        return np.column_stack([np.asarray(table[fmt.format(a)], dtype=np.float64) for a in axes])

    return SimpleNamespace(pos_m=cols(f"{washout}.pos_{{}}_m"), vel_mps=cols(f"{washout}.vel_{{}}_mps"),
                           acc_mps2=cols(f"{washout}.acc_{{}}_mps2"), q=cols(f"{washout}.q_{{}}", "wxyz"),
                           omega_radps=np.radians(cols(f"{washout}.omega_platform_{{}}_degps")))  # fmt: skip


def _ceiling_against_metrics(run_dir: Path, platform_file: Path, washouts: tuple[str, ...],
                             programmes: bool = True) -> dict[str, float]:
    """The ceiling of the flight in ``run_dir`` over the platform's relaxation as found (not widened), checked
    against every washout's integral error in metrics.csv (the metrics module's own numbers); the relaxation must
    hold every washout's motion as it is (nothing to widen). Returns the floors per DOF (``programmes=False``: only
    the relaxation's check, no floors)."""
    from washbench.analysis.ceiling import ceiling
    from washbench.analysis.relaxation import observed, relaxation_of, widened
    from washbench.io.units import G0_MPS2
    from washbench.platform.model import load_platform_model

    (traces,) = run_dir.rglob("traces.parquet")
    table = pq.read_table(traces).to_pydict()
    relax = relaxation_of(load_platform_model(platform_file), DT, G0_MPS2)
    seen = observed({w: _trace_namespace(table, w) for w in washouts}, DT, G0_MPS2)
    assert widened(relax, seen)[1] == [], seen  # the numerical bounds hold the platform's real motion
    if not programmes:
        return {}
    ac = "aircraft"
    f = np.column_stack([table[f"{ac}.f_{a}_mps2"] for a in "xyz"])
    w = np.radians(np.column_stack([table[f"{ac}.omega_{a}_degps"] for a in "xyz"]))
    pf = np.column_stack([table[f"{ac}.perceived_f_{a}_mps2"] for a in "xyz"])
    pw = np.radians(np.column_stack([table[f"{ac}.perceived_omega_{a}_degps"] for a in "xyz"]))
    ceil = ceiling(pf, pw, DT, relax, G0_MPS2, f_mps2=f, omega_radps=w)
    assert set(ceil.status.values()) <= {"Solved", "Exact"}, ceil.status
    (metrics,) = traces.parent.glob("metrics.csv")
    rows = [line.split(",") for line in metrics.read_text().splitlines()]
    head = rows[0]
    for r in rows[1:]:
        rec = dict(zip(head, r, strict=True))
        if rec["washout"] in washouts:
            err = float(rec["integral_error"])
            assert ceil.floor[rec["dof"]] <= err + 1e-9 * max(1.0, err), (rec, ceil.floor)
    return ceil.floor


def test_the_hexapod_s_ceiling_is_below_every_washout_through_the_bound_outputs(hexapod_runs):
    """--washout bound on a hexapod: ceiling.csv below every washout (and the bound's replay, flown through the
    hexapod: its legs checked with the others above), the relaxation recorded, nothing widened."""
    run_dir = hexapod_runs["gentle"].parent
    scores = check_ceiling_below_every_washout(run_dir)
    assert set(scores) == {*HEXAPOD_WASHOUTS, "bound"}
    doc = json.loads((run_dir / "run.json").read_text())["bound"]["relaxation"]
    assert doc["kind"] == "hexapod" and doc["widened"] == []
    assert "found numerically, not proved" in (run_dir / "report.md").read_text()  # the report says so
    table = pq.read_table(hexapod_runs["gentle"]).to_pydict()
    legs = legs_from_pose(np.column_stack([table[f"bound.pos_{a}_m"] for a in "xyz"]),
                          np.column_stack([table[f"bound.q_{c}"] for c in "wxyz"]))  # fmt: skip
    assert legs.min() >= LMIN and legs.max() <= LMAX
    assert np.abs(np.diff(legs, axis=0)).max() / DT <= VMAX


def test_the_ceiling_is_below_every_washout_on_the_violent_flight(hexapod_runs, rig_run, tmp_path):
    """The Columbia 400's aerobatics on the test's hexapod: the ceiling over its relaxation is below every washout's
    integral error in every DOF, above 0 where the hexapod cannot follow (the aerobatics' load factors: heave), and
    each washout's motion on the hexapod and on the test's rig lies within the relaxation as found."""
    hexapod = hexapod_file(tmp_path / "h.yaml")
    floors = _ceiling_against_metrics(hexapod_runs["violent"].parent, hexapod, HEXAPOD_WASHOUTS)
    assert floors["heave"] > 0.0
    rig = tmp_path / "rig.yaml"
    rig.write_text(RIG)
    _ceiling_against_metrics(rig_run, rig, ("large-angle", "optimal"), programmes=False)  # (its LPs: 12 s of CPU)


def test_the_rig_s_ceiling_is_below_every_washout_through_the_bound_outputs(flights, tmp_path):
    """--washout bound on the test's rig (the gentle flight): ceiling.csv below every washout and the replay, above
    0 (a rig without surge or sway travel, and 0.1 m of heave, cannot give the turn's specific force), the rig's
    relaxation recorded with nothing widened (its bounds are its limits)."""
    rig = tmp_path / "rig.yaml"
    rig.write_text(RIG)
    out = tmp_path / "out"
    proc = washbench("cue", flights["gentle"], "--out", out, "--platform", rig, "--washout", "large-angle",
                     "--washout", "optimal", "--washout", "bound", "--no-recording", "--no-figures",
                     "--quiet", "--params", one_search_step(tmp_path))  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    (traces,) = out.rglob("traces.parquet")
    scores = check_ceiling_below_every_washout(traces.parent)
    assert set(scores) == {"large-angle", "optimal", "bound"}
    doc = json.loads((traces.parent / "run.json").read_text())["bound"]
    assert doc["relaxation"]["kind"] == "rig" and doc["relaxation"]["widened"] == []
    assert doc["ceiling"]["score"] > 0.0


def test_the_rig_s_relaxation_holds_its_attitudes_and_turns():
    """Independent of the relaxation's formulas: scipy's ZYX rotations at random angles within the test rig's
    stops, and random steps within its rates: gravity's body components within the bounds (and reaching them at
    the stops), every turn per sample within the bound."""
    from washbench.analysis.relaxation import relaxation_of
    from washbench.platform.rig import RigModel

    model = RigModel.model_validate(yaml.safe_load(RIG))
    relax = relaxation_of(model, DT, 9.80665)
    rng = np.random.default_rng(7)
    n = 20000
    roll = np.radians(rng.uniform(-15.0, 15.0, n))
    pitch = np.radians(rng.uniform(-12.0, 12.0, n))
    roll[:6] = np.radians([15.0, -15.0, 15.0, -15.0, 15.0, 0.0])  # the stops (and one axis at a time)
    pitch[:6] = np.radians([12.0, 12.0, -12.0, -12.0, 0.0, 12.0])
    rot = Rotation.from_euler("ZYX", np.column_stack([0 * roll, pitch, roll]))
    gam = 9.80665 * rot.as_matrix()[:, 2, :]  # R^T g_I: the third row of R
    lo, hi = np.array(relax.gravity_lo), np.array(relax.gravity_hi)
    assert np.all(gam >= lo - 1e-12) and np.all(gam <= hi + 1e-12)
    np.testing.assert_allclose([np.abs(gam[:, 0]).max(), np.abs(gam[:, 1]).max(), gam[:, 2].min()],
                               [hi[0], hi[1], lo[2]], rtol=1e-8)  # fmt: skip (the bounds keep 1e-9 for rounding)
    step = np.column_stack([rng.uniform(-1, 1, n) * np.radians(25.0), rng.uniform(-1, 1, n) * np.radians(30.0)]) * DT
    rot2 = Rotation.from_euler("ZYX", np.column_stack([0 * roll, pitch + step[:, 0], roll + step[:, 1]]))
    assert (rot.inv() * rot2).magnitude().max() <= relax.turn_step_rad


def test_the_hexapod_s_relaxation_holds_its_workspace(tmp_path):
    """Random poses within the test hexapod's stroke (legs by numpy and scipy's rotation, not washbench's): the
    attitude's gravity components and the MRP's distance from neutral within the relaxation's bounds."""
    from washbench.analysis.relaxation import relaxation_of
    from washbench.platform.model import load_platform_model

    model = load_platform_model(hexapod_file(tmp_path / "h.yaml"))
    relax = relaxation_of(model, DT, 9.80665)
    rng = np.random.default_rng(11)
    n = 200000
    pos = rng.uniform(-0.5, 0.5, (n, 3))
    rotvec = rng.uniform(-0.6, 0.6, (n, 3))
    q = Rotation.from_rotvec(rotvec).as_quat()[:, [3, 0, 1, 2]]
    legs = legs_from_pose(pos, q)
    inside = np.all((legs >= LMIN) & (legs <= LMAX), axis=1)
    assert inside.sum() > 1000
    gam = 9.80665 * Rotation.from_rotvec(rotvec[inside]).as_matrix()[:, 2, :]
    assert np.all(np.abs(gam[:, :2]) <= np.array(relax.gravity_hi[:2]))
    assert np.all(gam[:, 2] >= relax.gravity_lo[2])
    assert np.linalg.norm(pos[inside], axis=1).max() <= relax.pos_norm
    # the bounds are near the workspace, not vacuous (random poses reach 80 % of the surge bound: the extreme found
    # by the search is at a corner of the workspace that uniform sampling seldom hits)
    assert np.abs(gam[:, 0]).max() > 0.75 * relax.gravity_hi[0]
    assert np.linalg.norm(pos[inside], axis=1).max() > 0.5 * relax.pos_norm


def test_the_bound_on_a_plugin_platform_is_refused_in_one_line(flights, tmp_path):
    plugin = tmp_path / "box.py"
    plugin.write_text(PLUGIN)
    out = tmp_path / "out"
    proc = washbench("cue", flights["gentle"], "--out", out, "--platform-plugin", f"{plugin}:BoxPlatform",
                     "--washout", "bound", "--quiet")  # fmt: skip
    assert proc.returncode != 0
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in proc.stderr and "bound" in lines[0] and "workspace" in lines[0]
    assert not out.exists() or not any(out.rglob("traces.parquet"))
