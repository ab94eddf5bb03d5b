"""``washbench cue`` end to end in a subprocess: real washouts, real files written and read back."""

import math
import subprocess
import sys
from pathlib import Path

import inprocess
import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from washbench.analysis.metrics import DOFS
from washbench.cueing import WASHOUT_NAMES
from washbench.cueing.variants import DEFAULT_WASHOUTS
from washbench.io.columns import INPUT_COLUMNS, washout_columns
from washbench.io.metrics_csv import read_metrics_csv
from washbench.io.motion_file import read_motion
from washbench.io.parquet_files import read_traces
from washbench.io.paths import DATA_DIR
from washbench.perception import VestibularModel

G = 9.80665
DT = 1 / 120


def synthetic() -> dict[str, np.ndarray]:
    """20 s at 120 Hz: level flight, a 2 m/s^2 surge step 2-6 s, a +-20 deg/s roll doublet 8-10 s."""
    t = np.arange(20 * 120 + 1) * DT
    return {
        "t_s": t,
        "f_x_mps2": np.where((t >= 2.0) & (t < 6.0), 2.0, 0.0),
        "f_y_mps2": np.zeros_like(t),
        "f_z_mps2": np.full_like(t, -G),
        "omega_x_degps": np.where((t >= 8.0) & (t < 9.0), 20.0, 0.0) - np.where((t >= 9.0) & (t < 10.0), 20.0, 0.0),
        "omega_y_degps": np.zeros_like(t),
        "omega_z_degps": np.zeros_like(t),
        "altitude_ft": 3000.0 + 0.5 * t,
    }


def write_csv(path: Path, cols: dict[str, np.ndarray]) -> Path:
    rows = [",".join(cols)]
    n = len(next(iter(cols.values())))
    rows += [",".join(repr(float(cols[c][i])) for c in cols) for i in range(n)]
    path.write_text("\n".join(rows) + "\n")
    return path


def cue(*args: str | Path) -> subprocess.CompletedProcess[str]:
    return inprocess.washbench("cue", *args, timeout=300)


@pytest.fixture(scope="module")
def inputs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    d = tmp_path_factory.mktemp("inputs")
    cols = synthetic()
    pq.write_table(pa.table(cols), d / "trace.parquet")
    return {"csv": write_csv(d / "trace.csv", cols), "parquet": d / "trace.parquet"}


@pytest.mark.parametrize("kind", ["csv", "parquet"])
def test_cue_writes_traces_and_metrics(kind: str, inputs: dict[str, Path], tmp_path: Path) -> None:
    out = tmp_path / "new" / "results"  # created if missing
    res = cue(inputs[kind], "--out", out)
    assert res.returncode == 0, res.stderr
    assert "2401 rows" in res.stdout and f"wrote {out}" in res.stdout
    assert sorted(p.name for p in out.iterdir()) == [
        ".washbench.json",  # the manifest: what washbench wrote here (washbench/io/outfolder.py)
        "figures",
        "metrics.csv",
        "ranking.csv",
        "recording.rrd",
        "report.md",
        "run.json",
        "traces.parquet",
    ]

    rows = read_metrics_csv(out / "metrics.csv")
    assert len(rows) == 6 * len(DEFAULT_WASHOUTS)
    assert [(r.washout, r.dof) for r in rows] == [(w, d) for w in DEFAULT_WASHOUTS for d in DOFS]
    for r in rows:
        assert math.isnan(r.npc) or r.npc >= 1.0 - 1e-12
        assert r.integral_error >= 0.0 and r.max_error >= 0.0
    by = {(r.washout, r.dof): r for r in rows}
    for w in WASHOUT_NAMES:
        assert math.isnan(by[w, "heave"].npc)  # the aircraft pilot's perceived heave is flat (-g throughout)
        assert by[w, "surge"].npc < 1.5 and by[w, "roll"].npc < 1.5  # the cues follow the aircraft somewhat

    table = read_traces(out / "traces.parquet")
    cols = synthetic()
    assert np.array_equal(table["t_s"], cols["t_s"])
    assert np.array_equal(table["altitude_ft"], cols["altitude_ft"])
    for c in INPUT_COLUMNS[1:]:
        assert np.array_equal(table[f"aircraft.{c}"], cols[c]), c
    sat = [c.removeprefix("small-angle.sat_") for c in table if c.startswith("small-angle.sat_")]
    assert sat
    expected = ["t_s", *(c for c in table if c.startswith("aircraft."))]
    for w in DEFAULT_WASHOUTS:
        expected += washout_columns(w, sat)
    assert list(table) == [*expected, "altitude_ft"]
    assert set(np.unique(table["small-angle.sat_tilt_rate"])) <= {0, 1}

    # perception columns are the vestibular model of the written head motion (independent recomputation)
    vm = VestibularModel(DT)
    w = "large-angle"
    f = np.column_stack([table[f"{w}.f_{a}_mps2"] for a in "xyz"])
    om = np.radians(np.column_stack([table[f"{w}.omega_{a}_degps"] for a in "xyz"]))
    p = vm.perceive(f, om)
    np.testing.assert_allclose(table[f"{w}.perceived_f_x_mps2"], p.f_mps2[:, 0], atol=1e-12)
    np.testing.assert_allclose(table[f"{w}.perceived_omega_x_degps"], np.degrees(p.omega_radps[:, 0]), atol=1e-10)
    # aircraft pilot: level start, perceived heave stays at -g
    np.testing.assert_allclose(table["aircraft.perceived_f_z_mps2"], -G, atol=1e-12)
    # metric recomputed from the written columns with numpy alone: max |error| of roll in deg/s
    roll_err = np.abs(table["aircraft.perceived_omega_x_degps"] - table[f"{w}.perceived_omega_x_degps"]).max()
    assert by[w, "roll"].max_error == pytest.approx(roll_err, rel=1e-9)


def test_washout_subset_and_determinism(inputs: dict[str, Path], tmp_path: Path) -> None:
    a, b = tmp_path / "a", tmp_path / "b"
    for out in (a, b):
        res = cue(inputs["csv"], "--out", out, "--washout", "unrestricted", "--washout", "small-angle", "--no-figures",
                  "--no-recording")  # the numbers are compared (figures and recordings: test_report, test_rerun_log)
        assert res.returncode == 0, res.stderr
    rows = read_metrics_csv(a / "metrics.csv")
    assert [r.washout for r in rows] == ["unrestricted"] * 6 + ["small-angle"] * 6
    table = read_traces(a / "traces.parquet")
    assert not any(c.startswith("large-angle.") for c in table)
    assert (a / "metrics.csv").read_bytes() == (b / "metrics.csv").read_bytes()
    tb = read_traces(b / "traces.parquet")
    assert all(np.array_equal(table[c], tb[c]) for c in table)


def bad_cases(d: Path) -> dict[str, tuple[list[str | Path], str]]:
    """name -> (extra CLI args with the input first, expected text in the error)."""
    cols = synthetic()

    def variant(name: str, **changes: object) -> Path:
        c = {k: v.copy() for k, v in cols.items()}
        for k, v in changes.items():
            if v is None:
                del c[k]
            else:
                idx, val = v  # type: ignore[misc]
                c[k][idx] = val
        return write_csv(d / name, c)

    t = cols["t_s"]
    empty = d / "empty.csv"
    empty.write_text("")
    junk = d / "junk.parquet"
    junk.write_bytes(b"PAR1 but not really")
    params = d / "params.yaml"
    cw1 = (DATA_DIR / "cw1.yaml").read_text()
    params.write_text(cw1 + "surge_gain: 1.0\n")  # the bundled set plus one unknown key
    params_line = len(cw1.splitlines()) + 1
    return {
        "missing column": ([variant("m.csv", f_y_mps2=None)], "m.csv: missing column 'f_y_mps2'"),
        "non-uniform": ([variant("u.csv", t_s=(100, t[100] + 0.2 * DT))], "u.csv:102: t_s: time step is not uniform"),
        "non-increasing": ([variant("i.csv", t_s=(50, t[49]))], "i.csv:52: t_s: time does not increase"),
        "nan": ([variant("n.csv", f_z_mps2=(7, math.nan))], "n.csv:9: f_z_mps2: value is NaN"),
        "inf": ([variant("f.csv", omega_y_degps=(9, math.inf))], "f.csv:11: omega_y_degps: value is infinite"),
        "empty": ([empty], "empty.csv: the file is empty"),
        "unreadable": ([junk], "junk.parquet: not a readable Parquet file"),
        "extension": ([d / "trace.dat"], "trace.dat: unknown file type '.dat'"),
        "washout": ([d / "ok.csv", "--washout", "big-angle"], "unknown washout 'big-angle' (valid: small-angle"),
        "params": ([d / "ok.csv", "--params", params], f"params.yaml:{params_line}: surge_gain: unknown key"),
    }


def test_bad_inputs_one_line_exit_2_nothing_written(tmp_path: Path) -> None:
    d = tmp_path / "in"
    d.mkdir()
    write_csv(d / "ok.csv", synthetic())
    (d / "trace.dat").write_text("t_s\n0\n")
    cases = bad_cases(d)
    # a results folder holding an earlier metrics.csv: a failing run must not touch it
    out = tmp_path / "out"
    out.mkdir()
    (out / "metrics.csv").write_text("earlier results\n")
    procs = {
        name: subprocess.Popen(
            [sys.executable, "-m", "washbench", "cue", *map(str, args), "--out", str(out)],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        for name, (args, _) in cases.items()
    }
    for name, proc in procs.items():
        _, err = proc.communicate(timeout=300)
        expected = cases[name][1]
        assert proc.returncode == 2, (name, err)
        assert "Traceback" not in err, name
        lines = err.strip().splitlines()
        assert len(lines) == 1, (name, err)
        assert lines[0].startswith("washbench: error: "), name
        assert expected in lines[0], (name, lines[0])
    assert sorted(p.name for p in out.iterdir()) == ["metrics.csv"]
    assert (out / "metrics.csv").read_text() == "earlier results\n"
    # a failing run does not even create a missing output folder
    res = cue(cases["nan"][0][0], "--out", tmp_path / "never")
    assert res.returncode == 2 and not (tmp_path / "never").exists()


def test_library_reads_what_the_cli_reads(inputs: dict[str, Path]) -> None:
    """CSV and Parquet give identical Motion objects (so identical results)."""
    a, b = read_motion(inputs["csv"]), read_motion(inputs["parquet"])
    assert a.dt_s == b.dt_s
    assert np.array_equal(a.f_mps2, b.f_mps2) and np.array_equal(a.omega_radps, b.omega_radps)
