"""Input reading and validation, result writers, read back from real files."""

import math
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from washbench.errors import WashbenchError
from washbench.io.columns import INPUT_COLUMNS, washout_columns
from washbench.io.metrics_csv import MetricRow, metrics_csv_text, read_metrics_csv, write_metrics_csv
from washbench.io.motion_file import read_motion
from washbench.io.parquet_files import read_traces, write_traces

DT = 1 / 120


def columns(n: int = 240) -> dict[str, np.ndarray]:
    """A 2 s level-flight-ish trace with some motion, plus one extra state column."""
    t = np.arange(n) * DT
    return {
        "t_s": t,
        "f_x_mps2": 0.5 * np.sin(t),
        "f_y_mps2": np.zeros(n),
        "f_z_mps2": np.full(n, -9.80665) + 0.1 * np.cos(3 * t),
        "omega_x_degps": 10.0 * np.sin(2 * t),
        "omega_y_degps": np.zeros(n),
        "omega_z_degps": np.full(n, 1.25),
        "altitude_ft": 3000.0 + t,
    }


def write_csv(path: Path, cols: dict[str, np.ndarray], fmt=repr) -> Path:
    names = list(cols)
    lines = [",".join(names)]
    for i in range(len(cols[names[0]])):
        lines.append(",".join(fmt(float(cols[c][i])) for c in names))
    path.write_text("\n".join(lines) + "\n")
    return path


def test_csv_and_parquet_read_the_same(tmp_path: Path) -> None:
    cols = columns()
    m_csv = read_motion(write_csv(tmp_path / "in.csv", cols))
    pq.write_table(pa.table(cols), tmp_path / "in.parquet")
    m_pq = read_motion(tmp_path / "in.parquet")
    for m in (m_csv, m_pq):
        assert np.array_equal(m.t_s, cols["t_s"])
        assert m.dt_s == pytest.approx(DT, rel=1e-12)
        assert np.array_equal(m.f_mps2[:, 2], cols["f_z_mps2"])
        np.testing.assert_allclose(m.omega_radps[:, 0], np.radians(cols["omega_x_degps"]), rtol=1e-15)
        assert np.array_equal(m.omega_degps[:, 0], cols["omega_x_degps"])
        assert list(m.extra) == ["altitude_ft"] and np.array_equal(m.extra["altitude_ft"], cols["altitude_ft"])


def test_integer_time_and_trailing_blank_lines(tmp_path: Path) -> None:
    p = tmp_path / "ints.csv"
    p.write_text(",".join(INPUT_COLUMNS) + "\n0,0,0,-10,0,0,0\n1,0,0,-10,0,0,0\n2, 1 ,0,-10,0,0,0\n\n\n")
    m = read_motion(p)
    assert m.n == 3 and m.dt_s == 1.0 and m.f_mps2[2, 0] == 1.0


def error_of(path: Path) -> str:
    with pytest.raises(WashbenchError) as info:
        read_motion(path)
    msg = str(info.value)
    assert "\n" not in msg and str(path) in msg
    return msg


def test_bad_inputs_name_file_line_and_problem(tmp_path: Path) -> None:
    cols = columns(10)
    header = ",".join(cols)

    c = dict(cols)
    del c["f_y_mps2"]
    assert "missing column 'f_y_mps2'" in error_of(write_csv(tmp_path / "a.csv", c))

    c = dict(cols, f_x_mps2=cols["f_x_mps2"].copy())
    c["f_x_mps2"][4] = math.nan
    assert error_of(write_csv(tmp_path / "b.csv", c)).endswith("b.csv:6: f_x_mps2: value is NaN")

    c = dict(cols, omega_z_degps=cols["omega_z_degps"].copy())
    c["omega_z_degps"][7] = -math.inf
    assert error_of(write_csv(tmp_path / "c.csv", c)).endswith("c.csv:9: omega_z_degps: value is infinite")

    c = dict(cols, t_s=cols["t_s"].copy())
    c["t_s"][5] = c["t_s"][4]
    assert "c2.csv:7: t_s: time does not increase" in error_of(write_csv(tmp_path / "c2.csv", c))

    c = dict(cols, t_s=cols["t_s"].copy())
    c["t_s"][6] += 0.1 * DT
    assert "d.csv:8: t_s: time step is not uniform" in error_of(write_csv(tmp_path / "d.csv", c))

    p = tmp_path / "e.csv"
    p.write_text(header + "\n" + "0,1,2,3,4,5,6,7\n" + "x,1,2,3,4,5,6,7\n")
    assert "e.csv:3: t_s: not a number: 'x'" in error_of(p)

    p = tmp_path / "f.csv"
    p.write_text(header + "\n0,1,2,3,4,5,6,7\n0.1,1,2,3,4,5,6\n")
    assert "f.csv:3: wrong number of fields" in error_of(p)

    p = tmp_path / "g.csv"
    p.write_text(header + "\n0,1,2,3,4,5,6,7\n\n0.2,1,2,3,4,5,6,7\n")
    assert "g.csv:3: t_s: missing value" in error_of(p)

    p = tmp_path / "h.csv"
    p.write_text("")
    assert "the file is empty" in error_of(p)
    p.write_text(header + "\n")
    assert "no data rows" in error_of(p)
    p.write_text(header + "\n0,1,2,3,4,5,6,7\n")
    assert "only one data row" in error_of(p)

    assert "no such file" in error_of(tmp_path / "nope.csv")
    assert "unknown file type '.dat'" in error_of(tmp_path / "x.dat")
    (tmp_path / "dir.csv").mkdir()
    assert "is a folder" in error_of(tmp_path / "dir.csv")

    p = tmp_path / "bin.csv"
    p.write_bytes(header.encode() + b"\n0,1,2,3,4,5,\xff\xfe,7\n1,1,2,3,4,5,6,7\n")
    assert "not a readable CSV file" in error_of(p)


def test_bad_parquet(tmp_path: Path) -> None:
    p = tmp_path / "junk.parquet"
    p.write_bytes(b"this is not parquet at all")
    assert "not a readable Parquet file" in error_of(p)
    cols = columns(10)
    cols["f_z_mps2"] = cols["f_z_mps2"].copy()
    cols["f_z_mps2"][3] = math.nan
    pq.write_table(pa.table(cols), tmp_path / "nan.parquet")
    assert error_of(tmp_path / "nan.parquet").endswith("nan.parquet: f_z_mps2: row 4: value is NaN")
    cols = columns(10)
    cols["f_x_mps2"] = np.array(["a"] * 10)
    pq.write_table(pa.table(cols), tmp_path / "str.parquet")
    assert "str.parquet: f_x_mps2: row 1: not a number: 'a'" in error_of(tmp_path / "str.parquet")


def test_time_rounded_to_few_digits(tmp_path: Path) -> None:
    """6-decimal times at 120 Hz lie within 6e-5 of a step of the grid: on it (tolerance 1e-3 of a step);
    3-decimal times (up to 0.06 of a step off) are not, and the error says how far off and what to do."""
    m = read_motion(write_csv(tmp_path / "r6.csv", columns(20), fmt=lambda v: f"{v:.6f}"))
    assert m.dt_s == pytest.approx(DT, rel=1e-4)
    msg = error_of(write_csv(tmp_path / "r3.csv", columns(20), fmt=lambda v: f"{v:.3f}"))
    assert "time step is not uniform" in msg and "of a step off a uniform grid" in msg
    assert msg.endswith("resample with --resample 120")


def test_traces_round_trip(tmp_path: Path) -> None:
    n = 50
    rng = np.random.default_rng(0)
    names = ["t_s", *washout_columns("large-angle", ["pos", "rate"])]
    table = {name: rng.normal(size=n) for name in names}
    table["large-angle.sat_pos"] = (rng.random(n) > 0.5).astype(np.int8)
    table["phase"] = np.array(["climb"] * n, dtype=object)
    write_traces(tmp_path / "traces.parquet", table)
    back = read_traces(tmp_path / "traces.parquet")
    assert list(back) == list(table)
    for k, v in table.items():
        assert np.array_equal(back[k], v)
    assert "large-angle.q_w" in back and "large-angle.wheel_3_radps" in back
    assert "large-angle.perceived_omega_z_degps" in back


def test_metrics_csv_exact_round_trip_nan_empty_inf(tmp_path: Path) -> None:
    rows = [
        MetricRow("small-angle", "surge", 1.0 / 3.0, 0.1 + 0.2, 1e-300),
        MetricRow("small-angle", "sway", math.nan, 2.0, 3.0),
        MetricRow("small-angle", "heave", math.inf, 5e-324, 12345.678901234567),
    ]
    path = tmp_path / "metrics.csv"
    write_metrics_csv(path, rows)
    text = path.read_text()
    assert text == metrics_csv_text(rows)
    lines = text.splitlines()
    assert lines[0] == ("washout,dof,npc,integral_error,max_error,cue_correct_frac,cue_scaled_frac,"
                        "cue_false_frac,cue_missing_frac,msdv_mps15,msdv_aircraft_mps15,false_cue_events,"
                        "msi_pct,msi_aircraft_pct,felt_error,felt_false,jolt")
    assert lines[2] == "small-angle,sway,,2.0,3.0,,,,,,,,,,,,"  # no cue classification, no dose: empty fields
    assert lines[3].split(",")[2] == "inf"
    back = read_metrics_csv(path)
    first5 = lambda r: (r.washout, r.dof, r.npc, r.integral_error, r.max_error)  # noqa: E731
    assert first5(back[0]) == first5(rows[0]) and first5(back[2]) == first5(rows[2])
    assert math.isnan(back[1].npc) and back[1].integral_error == 2.0
    assert [p.name for p in tmp_path.iterdir()] == ["metrics.csv"]  # no temporary files left behind
    # a file written before the MSI (twelve columns) is still read, its MSI NaN
    old = tmp_path / "old" / "metrics.csv"
    old.parent.mkdir()
    old.write_text("\n".join(",".join(line.split(",")[:12]) for line in lines) + "\n")
    back_old = read_metrics_csv(old)
    assert first5(back_old[2]) == first5(rows[2]) and math.isnan(back_old[2].msi_pct)


def test_dt_of_a_fixed_step_grid_is_recovered_exactly(tmp_path: Path) -> None:
    """t = k*dt written by a fixed-step simulator gives back dt itself, not the mean step."""
    from washbench.io.columns import INPUT_COLUMNS
    from washbench.io.motion_file import read_motion

    for hz in (30, 47, 120, 333, 1000):
        dt = 1.0 / hz
        n = 7201
        cols = {c: np.zeros(n) for c in INPUT_COLUMNS}
        cols["t_s"] = np.arange(n) * dt
        cols["f_z_mps2"] = np.full(n, -9.81)
        path = tmp_path / f"grid{hz}.parquet"
        pq.write_table(pa.table(cols), path)
        assert read_motion(path).dt_s == dt
