"""washbench run end to end: real JSBSim flights, washouts in lockstep, files and the recording read back."""

from __future__ import annotations

import csv
import json
import re
import subprocess
from pathlib import Path

import inprocess
import numpy as np
import pyarrow.parquet as pq
import pytest
from test_rerun_log import assert_recorded, motion_tolerances

from washbench.cueing.variants import DEFAULT_WASHOUTS
from washbench.io.paths import MANOEUVRES_DIR
from washbench.review.rerun_log import read_scalar_series, read_text_documents
from washbench.review.rrd_read import read_static

MANOEUVRES = [MANOEUVRES_DIR / "c172" / "coordinated_turn.yaml", MANOEUVRES_DIR / "c172" / "takeoff.yaml"]
DOF_COLUMNS = {
    "surge": "perceived_f_x_mps2",
    "sway": "perceived_f_y_mps2",
    "heave": "perceived_f_z_mps2",
    "roll": "perceived_omega_x_degps",
    "pitch": "perceived_omega_y_degps",
    "yaw": "perceived_omega_z_degps",
}


def washbench(*args: str | Path) -> subprocess.CompletedProcess[str]:
    return inprocess.washbench(*args, timeout=600)


@pytest.fixture(scope="module", params=MANOEUVRES, ids=lambda p: p.stem)
def run_dir(request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("run")
    proc = washbench("run", request.param, "--out", out, "--quiet")
    assert proc.returncode == 0, proc.stdout + proc.stderr
    (folder,) = [p for p in out.glob("*/*") if p.is_dir()]
    return folder


def test_run_writes_every_file_and_nothing_else(run_dir: Path) -> None:
    names = sorted(p.name for p in run_dir.iterdir())
    assert names == sorted(
        [
            "flight.json",
            "flight.parquet",
            "traces.parquet",
            "metrics.csv",
            "recording.rrd",
            "run.json",
            "ranking.csv",
            "report.md",
            "figures",
        ]
    )
    assert sorted(p.name for p in (run_dir / "figures").iterdir()) == [
        "cues.png", "envelope.png", "perceived.png"
    ]  # PNG only: `washbench report` adds the PDFs
    assert not list(run_dir.parent.glob(".*")), "temporary folders left behind"
    flight = json.loads((run_dir / "flight.json").read_text())
    assert flight["status"] == "ok"
    assert all(c["passed"] for c in flight["checks"])
    with (run_dir / "metrics.csv").open() as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 6 * len(DEFAULT_WASHOUTS)
    assert {r["washout"] for r in rows} == set(DEFAULT_WASHOUTS)
    for r in rows:
        assert float(r["integral_error"]) >= 0.0 and float(r["max_error"]) >= 0.0
        assert r["npc"] == "" or float(r["npc"]) >= 0.5  # NPC >= K/2 for K = 1


def test_traces_hold_cue_columns_and_flight_state(run_dir: Path) -> None:
    table = pq.read_table(run_dir / "traces.parquet")
    names = set(table.column_names)
    for col in ("t_s", "aircraft.f_x_mps2", "aircraft.perceived_omega_z_degps", "phi_deg", "h_agl_ft", "wow"):
        assert col in names
    for w in ("small-angle", "large-angle", "unrestricted"):
        for col in ("pos_x_m", "q_w", "wheel_1_radps", "perceived_f_z_mps2"):
            assert f"{w}.{col}" in names
    flight = pq.read_table(run_dir / "flight.parquet")
    assert np.array_equal(table.column("t_s").to_numpy(), flight.column("t_s").to_numpy())
    assert np.array_equal(table.column("aircraft.f_z_mps2").to_numpy(), flight.column("f_z_mps2").to_numpy())


def test_fly_then_cue_gives_the_same_numbers_bit_for_bit(run_dir: Path, tmp_path: Path) -> None:
    manoeuvre = MANOEUVRES_DIR / "c172" / f"{run_dir.name}.yaml"
    assert washbench("fly", manoeuvre, "--out", tmp_path / "fly", "--quiet").returncode == 0
    # the numbers only (the run's figures and recording are checked against its traces below)
    proc = washbench("cue", tmp_path / "fly" / "flight.parquet", "--out", tmp_path / "cue", "--no-figures",
                     "--no-recording")  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert (tmp_path / "cue" / "metrics.csv").read_bytes() == (run_dir / "metrics.csv").read_bytes()
    a = pq.read_table(tmp_path / "cue" / "traces.parquet")
    b = pq.read_table(run_dir / "traces.parquet")
    assert a.column_names == b.column_names
    for name in a.column_names:
        x, y = a.column(name).to_numpy(), b.column(name).to_numpy()
        assert np.array_equal(x, y, equal_nan=x.dtype.kind == "f"), name


def test_recording_holds_the_computed_traces(run_dir: Path) -> None:
    """Stated precision, against traces.parquet: at each recorded step the value is float32(trace value) exactly;
    between recorded steps linear interpolation is within 1 % of the DOF's perception threshold (angular rates in
    deg/s) and 0.2 % of its panel's height; recorded times are steps of the trace, within 0.5 ns."""
    traces = pq.read_table(run_dir / "traces.parquet")
    t = traces.column("t_s").to_numpy()
    rrd = run_dir / "recording.rrd"
    series = read_scalar_series(rrd)
    sources = (*DEFAULT_WASHOUTS, "aircraft")  # the aircraft last, drawn on top
    assert read_static(rrd, "SeriesLines:names")["/perceived/surge"] == list(sources)
    rows = 0
    for dof, col in DOF_COLUMNS.items():
        raw_col = col.removeprefix("perceived_")
        for entity, column in ((f"/perceived/{dof}", col), (f"/raw/{dof}", raw_col)):
            rec_t, values = series[entity]
            expected = np.column_stack([traces.column(f"{source}.{column}").to_numpy() for source in sources])
            # raw angular rates went deg/s -> rad/s -> deg/s on their way (float64, relative 1e-16): float32 of it may
            # round to the neighbouring float32 where the value sits on a rounding boundary
            ulps = 1 if entity.startswith("/raw/") and dof in ("roll", "pitch", "yaw") else 0
            tol = motion_tolerances(rrd, entity, len(sources))
            assert_recorded(rec_t, values, t, expected, tol, ulps=ulps)
            rows += rec_t.size
    assert rows < 0.5 * 12 * t.size  # thinned: most steps lie on the lines between recorded ones
    text = "\n".join(read_text_documents(rrd).values())
    assert "integral of |error|" in text and "| washout | surge | sway | heave | roll | pitch | yaw |" in text
    ranked = [line.split(" | ")[1] for line in text.splitlines() if re.match(r"^\| \d+( \(tie\))? \| ", line)]
    assert sorted(ranked) == sorted(DEFAULT_WASHOUTS)  # the ranking, first (issue 38, item 10)
    size_per_step = rrd.stat().st_size / len(t)
    print(f"\nrecording: {size_per_step:.0f} bytes per step ({len(t)} steps), {rows / 12 / t.size:.1%} of the rows")
    assert size_per_step < 250  # was 2,030, then 1,122 (takeoff) before float32 and thinning (issue 14)


def test_run_summary_is_consistent(run_dir: Path) -> None:
    summary = json.loads((run_dir / "run.json").read_text())
    flight = json.loads((run_dir / "flight.json").read_text())
    assert summary["ok"] is True
    assert summary["checks_total"] == len(flight["checks"])
    n = pq.read_metadata(run_dir / "traces.parquet").num_rows
    assert summary["steps"] == n
    assert set(summary["perceived_motion"]) == set(DOF_COLUMNS) | {f"felt_{d}" for d in DOF_COLUMNS}


def test_aircraft_attitude_matches_scipy_rotation() -> None:
    from scipy.spatial.transform import Rotation

    from washbench.runs.chain import aircraft_attitude

    rng = np.random.default_rng(0)
    phi, theta, psi = rng.uniform(-180, 180, 500), rng.uniform(-90, 90, 500), rng.uniform(0, 360, 500)
    expected = Rotation.from_euler("ZYX", np.column_stack([psi, theta, phi]), degrees=True).as_quat(scalar_first=True)
    np.testing.assert_allclose(aircraft_attitude(phi, theta, psi), expected, atol=1e-15)
