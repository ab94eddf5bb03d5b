"""Real data through ``washbench cue``: JSBSim's own script flown once, written the ways other tools log it.

The reference is the trace of ``c172_cruise_8K.xml`` (shipped in the jsbsim package, flown in place for
25 s: a trimmed cruise, a heading change and a 30 ft/s cosine gust) cued cleanly on its uniform 120 Hz grid
from 2 s on (the untrimmed first second cut with ``--start-s``). Each variant (X-Plane-style 20 Hz CSV with
3-decimal, +-1 ms jittered time; X-Plane's Data.txt; semicolon CSV with comments, gzip; g and rad/s in a
z-up frame with a mapping; JSBSim's own CSV output) must give the same metrics within a tolerance:

* without resampling (only number formatting and unit conversions differ): every integral error within
  1e-4 of the aircraft pilot's perceived motion in its DOF (``M_d``, at least the ranking's motion floor);
* resampled (``--resample 120`` from 20 Hz): within 2 % of it, and the same ranking. The ranking's score
  is ``sum_d w_d E_d / M_d`` with weights summing to 1, so errors within 2 % of ``M_d`` move each score by
  at most 0.02; the smallest gap between two washouts' scores here is 0.045 (1.011, 1.111, 1.156), so even
  two scores moving 0.02 towards each other cannot swap: the decision a user takes from the result
  stands. Measured: 0.9 % (X-Plane style), 1.4e-6 (Data.txt, 7 decimals), 4.5e-7 (g, rad/s, us, z up),
  6.5e-7 (float32), 0 (semicolon CSV). ``tools/resample_effect.py`` measures resampling on more scripts.
"""

from __future__ import annotations

import gzip
import json
import math
from pathlib import Path

import jsbsim
import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from washbench.analysis.ranking import MOTION_FLOOR
from washbench.cueing.registry import REFERENCE_KINDS
from washbench.cueing.variants import DEFAULT_WASHOUTS
from washbench.errors import WashbenchError
from washbench.flight.scripts import bundled_script, fly_script
from washbench.io.input_format import InputFormat, input_format
from washbench.io.metrics_csv import read_metrics_csv
from washbench.runs.cue import CueOptions, run_cue
from washbench.runs.options import RunOptions, load_options
from washbench.runs.outputs import Outputs

G0 = 9.80665
FT = 0.3048
START_S = 2.0
SCRIPT = "c172_cruise_8K"
SECONDS = 25.0


@pytest.fixture(scope="module")
def trace() -> dict[str, np.ndarray]:
    """The script's pilot-head motion as washbench records it (one-frame lag of a-pilot removed)."""
    flight = fly_script(bundled_script(SCRIPT), max_time_s=SECONDS)
    (seg,) = flight.segments
    return seg.columns


def columns6(trace: dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    f = np.column_stack([trace[f"f_{a}_mps2"] for a in "xyz"])
    w = np.column_stack([trace[f"omega_{a}_degps"] for a in "xyz"])
    return trace["t_s"], f, w


def lean(**kw: object) -> RunOptions:
    """The run's options without recording or figures: these tests read the numbers."""
    return load_options(outputs=Outputs(recording=False, figures=False), **kw)  # type: ignore[arg-type]


def no_recording() -> RunOptions:
    return load_options(outputs=Outputs(recording=False))


def cue_dir(inp: Path, out: Path, capsys: pytest.CaptureFixture[str] | None = None, **kw: object) -> dict:
    # no figures: these tests read the numbers (the figures of a cue are tested in test_report.py)
    opts = CueOptions(start_s=kw.pop("start_s", START_S), **kw)  # type: ignore[arg-type]
    code = run_cue(inp, out, opts, lean())
    doc = json.loads((out / "run.json").read_text())
    doc["exit"] = code
    doc["metrics"] = {(r.washout, r.dof): r for r in read_metrics_csv(out / "metrics.csv")}
    doc["ranking"] = [line.split(",")[3] for line in (out / "ranking.csv").read_text().splitlines()[1:]]
    return doc


@pytest.fixture(scope="module")
def clean(trace: dict[str, np.ndarray], tmp_path_factory: pytest.TempPathFactory) -> dict:
    d = tmp_path_factory.mktemp("clean")
    pq.write_table(pa.table(trace), d / "clean.parquet")
    return cue_dir(d / "clean.parquet", d / "out")


def assert_same_metrics(doc: dict, ref: dict, rel: float) -> float:
    """Every washout's integral error within ``rel`` of the aircraft's perceived motion (at least the floor); the
    worst. Not the naive references': the replay integrates the specific force twice into its stage, so where it runs
    into a stop moves with the input's last digits (what these tests vary), not with how the input was read."""
    felt = {d: v["value"] for d, v in ref["perceived_motion"].items()}
    worst = 0.0
    for key, r in ref["metrics"].items():
        if key[0] in REFERENCE_KINDS:
            continue
        m = doc["metrics"][key]
        scale = max(felt[key[1]], MOTION_FLOOR[key[1]])
        worst = max(worst, abs(m.integral_error - r.integral_error) / scale)
    assert worst <= rel, worst
    return worst


def test_clean_trace_is_cued_from_the_window(clean: dict, trace: dict[str, np.ndarray]) -> None:
    assert clean["exit"] == 0 and clean["ok"] and clean["warnings"] == []
    assert clean["t_start_s"] == pytest.approx(START_S, abs=1 / 120) and clean["t_end_s"] == trace["t_s"][-1]
    assert clean["steps"] == int(np.sum(trace["t_s"] >= START_S))
    assert len(clean["ranking"]) == len(DEFAULT_WASHOUTS)


def test_xplane_style_csv_20hz_jittered_3_decimals(trace: dict[str, np.ndarray], clean: dict, tmp_path: Path) -> None:
    """Logged at 20 Hz with +-1 ms timing jitter, 3-decimal time: refused as it is, equal after --resample 120."""
    t, f, w = columns6(trace)
    rng = np.random.default_rng(7)
    tj = np.arange(0.0, t[-1] - 0.01, 0.05) + rng.uniform(-1e-3, 1e-3, size=len(np.arange(0.0, t[-1] - 0.01, 0.05)))
    tj[0] = 0.0
    vals = [np.interp(tj, t, x) for x in (*f.T, *w.T)]  # the signals at the true sample times
    lines = ["t_s,f_x_mps2,f_y_mps2,f_z_mps2,omega_x_degps,omega_y_degps,omega_z_degps"]
    lines += [f"{tj[i]:.3f}," + ",".join(f"{v[i]:.6f}" for v in vals) for i in range(len(tj))]
    p = tmp_path / "xplane_style.csv"
    p.write_text("\n".join(lines) + "\n")
    with pytest.raises(WashbenchError, match=r"time step is not uniform: .* resample with --resample 20$"):
        run_cue(p, tmp_path / "refused", options=CueOptions(start_s=START_S))
    assert not (tmp_path / "refused").exists()
    doc = cue_dir(p, tmp_path / "out", resample_hz=120.0)
    assert any("resampled to 120 Hz" in n for n in doc["conversions"])
    assert_same_metrics(doc, clean, 0.02)
    assert doc["ranking"] == clean["ranking"]


def data_txt(t: np.ndarray, f: np.ndarray, w_degps: np.ndarray) -> str:
    """X-Plane's Data.txt layout: pipe-separated, padded, rows Times, G-loads, Angular velocities (rad/s)."""
    heads = ["_real,_time", "_totl,_time", "Gload,norml", "Gload,axial", "Gload,_side", "____Q,rad/s",
             "____P,rad/s", "____R,rad/s"]  # fmt: skip
    w = np.radians(w_degps)
    # X-Plane's normal load is +1 g in level flight (up), axial forward, side right
    cols = [t + 812.5, t, -f[:, 2] / G0, f[:, 0] / G0, f[:, 1] / G0, w[:, 1], w[:, 0], w[:, 2]]
    out = ["|".join(f"{h:>12}" for h in heads) + "|"]
    out += ["|".join(f"{v:12.7f}" for v in row) + "|" for row in np.column_stack(cols)]
    return "\r\n".join(out) + "\r\n"


def test_xplane_data_txt(trace: dict[str, np.ndarray], clean: dict, tmp_path: Path) -> None:
    t, f, w = columns6(trace)
    p = tmp_path / "Data.txt"
    p.write_text(data_txt(t, f, w), newline="")
    doc = cue_dir(p, tmp_path / "out", start_s=START_S + 812.5)  # X-Plane's real time counts from its start
    assert doc["ok"] and doc["warnings"] == []
    assert any("Gload,norml" in n for n in doc["conversions"])
    assert_same_metrics(doc, clean, 1e-4)


def test_semicolon_csv_with_comments_gzip_and_padded_header(
    trace: dict[str, np.ndarray], clean: dict, tmp_path: Path
) -> None:
    t, f, w = columns6(trace)
    names = ["t_s", "f_x_mps2", "f_y_mps2", "f_z_mps2", "omega_x_degps", "omega_y_degps", "omega_z_degps", "note"]
    lines = ["# logged by some tool", "# units: SI", " ; ".join(names)]
    for i in range(len(t)):
        lines.append(";".join([repr(float(t[i])), *(repr(float(x)) for x in (*f[i], *w[i])), "cruise"]))
        if i == 1000:
            lines.append("# a comment in the middle")
    p = tmp_path / "log.csv.gz"
    p.write_bytes(gzip.compress(("\n".join(lines) + "\n").encode()))
    doc = cue_dir(p, tmp_path / "out")
    assert doc["ok"]
    assert_same_metrics(doc, clean, 1e-12)
    # a bad value is located on its line, comments counted
    lines[1500] = lines[1500].replace(";", ";x", 1)
    bad = tmp_path / "bad.csv"
    bad.write_text("\n".join(lines) + "\n")
    with pytest.raises(WashbenchError, match=r"bad\.csv:1501: f_x_mps2: not a number: 'x"):
        run_cue(bad, tmp_path / "never", options=CueOptions())


def test_g_radps_ms_z_up_with_a_mapping(trace: dict[str, np.ndarray], clean: dict, tmp_path: Path) -> None:
    """ax/ay/az in g from a z-up, y-left IMU, rates in rad/s, time in integer microseconds; mapped on the command line
    and by a YAML file, same metrics; float32 Parquet too."""
    t, f, w = columns6(trace)
    flu = np.diag([1.0, -1.0, -1.0])  # body -> sensor (x forward, y left, z up)
    fs, ws = f @ flu.T / G0, np.radians(w) @ flu.T
    table = {"time": np.round(t * 1e6 + 5e6).astype(np.int64)}
    table |= {n: fs[:, i] for i, n in enumerate(("ax", "ay", "az"))} | {n: ws[:, i] for i, n in enumerate("pqr")}
    p = tmp_path / "imu.parquet"
    pq.write_table(pa.table(table), p)
    mapping = "t=time:us,f_x=ax:g,f_y=ay:g,f_z=az:g,omega_x=p:radps,omega_y=q:radps,omega_z=r:radps"
    fmt = input_format(columns=mapping, axes="flu")
    doc = cue_dir(p, tmp_path / "out", fmt=fmt)
    assert doc["ok"] and doc["warnings"] == []
    assert_same_metrics(doc, clean, 1e-4)  # integer-us time: on the grid within 1e-3 of a step

    yaml_file = tmp_path / "imu.yaml"
    yaml_file.write_text(
        "axes: flu\ncolumns:\n  t: time:us\n  f_x: ax:g\n  f_y: ay:g\n  f_z: az:g\n"
        "  omega_x: p:radps\n  omega_y: q:radps\n  omega_z: r:radps\n"
    )
    doc2 = cue_dir(p, tmp_path / "out2", fmt=input_format(format_file=yaml_file))
    assert doc2["metrics"] == doc["metrics"]

    p32 = tmp_path / "f32.parquet"
    pq.write_table(
        pa.table({k: v.astype(np.float32) for k, v in trace.items() if k.endswith(("_s", "mps2", "degps"))}), p32
    )
    doc3 = cue_dir(p32, tmp_path / "out3")  # float32 time at 25 s: 2e-6 s = 2.4e-4 of a step off the grid at most
    assert_same_metrics(doc3, clean, 1e-4)


def test_jsbsim_own_csv_output_matches_the_recorder(trace: dict[str, np.ndarray], tmp_path: Path) -> None:
    """JSBSim's <output type="CSV"> of the same script, its a-pilot shifted back one row, equals washbench's
    own recording of the flight (to the 18 digits JSBSim prints)."""
    directive = tmp_path / "out.xml"
    csv_path = tmp_path / "jsbsim_out.csv"
    directive.write_text(
        f'<?xml version="1.0"?>\n<output name="{csv_path}" type="CSV" rate="120">\n  <rates> ON </rates>\n'
        + "".join(f"  <property> accelerations/a-pilot-{a}-ft_sec2 </property>\n" for a in "xyz")
        + "</output>\n"
    )
    root = jsbsim.get_default_root_dir()
    fdm = jsbsim.FGFDMExec(root, None)
    fdm.set_debug_level(0)
    fdm.set_output_path(str(tmp_path))  # the script's and aircraft's own outputs go here, not into the package
    fdm.load_script(str(bundled_script(SCRIPT)))
    fdm.set_output_directive(str(directive))
    fdm.run_ic()
    while fdm.get_sim_time() < 10.0:
        fdm.run()
    del fdm
    from washbench.io.readers import read_samples

    s = read_samples(csv_path)
    assert s.kind == "jsbsim" and any("shifted back one frame of 0.00833333 s = one row" in n for n in s.notes)
    n = s.n
    ref_f = np.column_stack([trace[f"f_{a}_mps2"] for a in "xyz"])[:n]
    ref_w = np.column_stack([trace[f"omega_{a}_degps"] for a in "xyz"])[:n]
    np.testing.assert_allclose(s.t_s, trace["t_s"][:n], atol=1e-9)
    np.testing.assert_allclose(s.f_mps2, ref_f, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(s.omega_degps, ref_w, rtol=1e-12, atol=1e-12)  # 'P (deg/s)' of <rates>


# --------------------------------------------------------------------------- wrong units and time


def base_cols(trace: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    keep = trace["t_s"] >= START_S
    return {k: v[keep] for k, v in trace.items() if k == "t_s" or k.endswith(("mps2", "degps"))}


def warnings_of(cols: dict[str, np.ndarray], tmp_path: Path, capsys: pytest.CaptureFixture[str], **kw: object) -> str:
    p = tmp_path / "w.parquet"
    pq.write_table(pa.table(cols), p)
    capsys.readouterr()
    run_cue(p, tmp_path / "wout", CueOptions(**kw), lean())  # type: ignore[arg-type]
    return capsys.readouterr().err


@pytest.mark.parametrize(
    ("case", "expected"),
    [
        ("time in ms", "sample rate 0.12 Hz is outside 10 Hz .. 10000 Hz: is the time in ms"),
        ("time in ns", "is outside 10 Hz .. 10000 Hz: is the time in ns?"),
        ("force in g", "far from g: is it in g? (read as mps2 now; give the unit with --columns f_x=COLUMN:g"),
        ("force in ft/s^2", "far from g: is it in ftps2? (read as mps2 now"),
        ("z up", "above zero: is the sensor's z axis up?"),
        ("rates in rad/s", "are the rates in radps? (read as degps now"),
        ("crash spike", "above 10 g: a crash or a spike?"),
        ("all zero", "the motion is all zero throughout"),
    ],
)
def test_wrong_units_warn(
    case: str, expected: str, trace: dict[str, np.ndarray], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    c = base_cols(trace)
    f_names = [f"f_{a}_mps2" for a in "xyz"]
    w_names = [f"omega_{a}_degps" for a in "xyz"]
    if case == "time in ms":
        c["t_s"] = c["t_s"] * 1000.0
    elif case == "time in ns":
        c["t_s"] = c["t_s"] * 1e9
    elif case == "force in g":
        c |= {n: c[n] / G0 for n in f_names}
    elif case == "force in ft/s^2":
        c |= {n: c[n] / FT for n in f_names}
    elif case == "z up":
        c |= {"f_y_mps2": -c["f_y_mps2"], "f_z_mps2": -c["f_z_mps2"]}
    elif case == "rates in rad/s":
        c |= {n: np.radians(c[n]) for n in w_names}
    elif case == "crash spike":
        c["f_z_mps2"] = c["f_z_mps2"].copy()
        c["f_z_mps2"][100] = -1100.0
    elif case == "all zero":
        c |= {n: np.zeros_like(c[n]) for n in (*f_names, *w_names)}
    err = warnings_of(c, tmp_path, capsys)
    lines = [x for x in err.splitlines() if x.startswith("washbench: warning:")]
    assert any(expected in x for x in lines), err
    # --strict: the same line is an error, nothing written
    with pytest.raises(WashbenchError, match="strict"):
        run_cue(tmp_path / "w.parquet", tmp_path / "strict", options=CueOptions(strict=True))
    assert not (tmp_path / "strict").exists()


def test_crash_in_the_data_is_reported_not_scored(trace: dict[str, np.ndarray], tmp_path: Path) -> None:
    c = base_cols(trace)
    c["f_z_mps2"] = c["f_z_mps2"].copy()
    c["f_z_mps2"][-5:] = -1100.0
    p = tmp_path / "crash.parquet"
    pq.write_table(pa.table(c), p)
    assert run_cue(p, tmp_path / "out", run=no_recording()) == 1
    doc = json.loads((tmp_path / "out" / "run.json").read_text())
    assert not doc["ok"] and "crash or spike" in doc["reason"]
    assert "FAILED" in (tmp_path / "out" / "report.md").read_text()


def test_time_problems(trace: dict[str, np.ndarray], tmp_path: Path) -> None:
    c = base_cols(trace)
    n = len(c["t_s"])
    # one dropped sample: refused with advice; accepted with --resample; a long gap: refused even then
    keep = np.ones(n, bool)
    keep[300] = False
    pq.write_table(pa.table({k: v[keep] for k, v in c.items()}), tmp_path / "drop.parquet")
    with pytest.raises(WashbenchError, match=r"drop\.parquet: t_s: row 301: time step is not uniform.*--resample 120"):
        run_cue(tmp_path / "drop.parquet", tmp_path / "o1", options=CueOptions(start_s=None))
    assert (
        run_cue(tmp_path / "drop.parquet", tmp_path / "o2", CueOptions(resample_hz=120), no_recording()) == 0
    )
    keep[400:430] = False
    pq.write_table(pa.table({k: v[keep] for k, v in c.items()}), tmp_path / "gap.parquet")
    with pytest.raises(WashbenchError, match=r"row 400: gap of 0.258332 s from .* longer than the largest allowed"):
        run_cue(tmp_path / "gap.parquet", tmp_path / "o3", options=CueOptions(resample_hz=120))
    assert run_cue(tmp_path / "gap.parquet", tmp_path / "o4", CueOptions(resample_hz=120, max_gap_s=0.3),
                   no_recording()) == 0  # fmt: skip
    # +-1 us jitter and Unix-epoch time are on the grid (within 1e-3 of a step): accepted as they are
    rng = np.random.default_rng(3)
    jit = dict(c, t_s=c["t_s"] + 1_764_600_000.0 + rng.uniform(-1e-6, 1e-6, n))
    pq.write_table(pa.table(jit), tmp_path / "epoch.parquet")
    assert run_cue(tmp_path / "epoch.parquet", tmp_path / "o5", run=no_recording()) == 0
    # a time reset splits into segments (own subfolders), or is refused with --no-split
    two = {k: np.concatenate([v, v]) for k, v in c.items()}
    pq.write_table(pa.table(two), tmp_path / "reset.parquet")
    with pytest.raises(WashbenchError, match=rf"row {n + 1}: time jumps back from .* \(a reset\?\)"):
        run_cue(tmp_path / "reset.parquet", tmp_path / "o6", options=CueOptions(split=False))
    assert run_cue(tmp_path / "reset.parquet", tmp_path / "o7", run=no_recording()) == 0
    a, b = (read_metrics_csv(tmp_path / "o7" / s / "metrics.csv") for s in ("segment_1", "segment_2"))
    assert a == b  # the same data cued twice, each from its own start
    assert sorted(p.name for p in (tmp_path / "o7").iterdir()) == [".washbench.json", "segment_1", "segment_2"]


def test_rest_start_feels_a_mid_manoeuvre_start(trace: dict[str, np.ndarray], tmp_path: Path) -> None:
    """A recording that begins in a 2 m/s^2 surge: steady start adapts it away, rest start perceives the
    step like the otolith's closed-form step response (K tau_a / (tau_L tau_S) at 0+, then decaying)."""
    t = np.arange(0, 2401) / 120.0
    c = {"t_s": t, "f_x_mps2": np.full_like(t, 2.0), "f_y_mps2": np.zeros_like(t), "f_z_mps2": np.full_like(t, -G0)}
    c |= {f"omega_{a}_degps": np.zeros_like(t) for a in "xyz"}
    pq.write_table(pa.table(c), tmp_path / "mid.parquet")
    from washbench.io.parquet_files import read_traces

    run_cue(tmp_path / "mid.parquet", tmp_path / "steady", run=lean())
    run_cue(tmp_path / "mid.parquet", tmp_path / "rest", run=lean(filter_start="rest"))
    steady = read_traces(tmp_path / "steady" / "traces.parquet")["aircraft.perceived_f_x_mps2"]
    rest = read_traces(tmp_path / "rest" / "traces.parquet")["aircraft.perceived_f_x_mps2"]
    assert np.allclose(steady, 2.0)
    # otolith step response (K tau_a s + 1)/((tau_L s + 1)(tau_S s + 1)) * 2/s, closed form
    k, ta, tl, ts = 0.4, 13.2, 5.33, 0.66
    tt = t + 1 / 240  # first-order hold: the step ramps over the step before the first sample
    step = 1 - (tl - k * ta) / (tl - ts) * np.exp(-tt / tl) - (ts - k * ta) / (ts - tl) * np.exp(-tt / ts)
    np.testing.assert_allclose(rest[120:], 2.0 * step[120:], rtol=2e-3)
    assert math.isclose(rest[-1], 2.0 * step[-1], rel_tol=1e-3)
    assert json.loads((tmp_path / "rest" / "run.json").read_text())["filter_start"] == "rest"
    # the washouts: from steady, the platform holds the sustained surge by a constant tilt and never moves;
    # from rest it starts level, gives an onset cue on the stage and tilts up to the same attitude
    from scipy.spatial.transform import Rotation

    for kind, moved in (("steady", False), ("rest", True)):
        tr = read_traces(tmp_path / kind / "traces.parquet")
        q = np.column_stack([tr[f"large-angle.q_{c}"] for c in "wxyz"])
        pitch = Rotation.from_quat(q, scalar_first=True).as_euler("ZYX", degrees=True)[:, 1]
        assert (np.max(np.abs(tr["large-angle.pos_x_m"])) > 0.01) == moved
        assert abs(pitch[-1] - math.degrees(math.atan2(2.0, G0))) < 0.3  # tilt coordination: -g_S along f
        assert (abs(pitch[0]) < 0.1) == moved


def test_cli_cue_with_options(trace: dict[str, np.ndarray], tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The command line: mapping, axes, window, resampling, no recording; a bad option is one line, exit 2."""
    from washbench.cli import main

    t, f, w = columns6(trace)
    lines = ["time_ms\tax\tay\taz\tp\tq\tr"]
    lines += [f"{t[i] * 1000:.6f}\t" + "\t".join(repr(float(x)) for x in (*f[i], *w[i])) for i in range(len(t))]
    p = tmp_path / "log.tsv"
    p.write_text("\n".join(lines) + "\n")
    out = tmp_path / "out"
    cols = "t=time_ms:ms,f_x=ax,f_y=ay,f_z=az,omega_x=p,omega_y=q,omega_z=r"
    argv = ["cue", str(p), "--out", str(out), "--columns", cols, "--start-s", "2", "--end-s", "20"]
    assert main([*argv, "--end-s", "3", "--no-figures"]) == 0  # an earlier run's recording
    assert (out / "recording.rrd").is_file()
    assert main([*argv, "--resample", "100", "--no-recording"]) == 0
    assert sorted(x.name for x in out.iterdir()) == [".washbench.json", "figures", "metrics.csv", "ranking.csv",
                                                      "report.md", "run.json", "traces.parquet"]  # fmt: skip
    doc = json.loads((out / "run.json").read_text())
    assert doc["dt_s"] == 0.01 and doc["t_start_s"] == pytest.approx(2.0, abs=0.01) and doc["t_end_s"] <= 20.0
    capsys.readouterr()
    assert main(["cue", str(p), "--out", str(tmp_path / "x"), "--columns", "t=time_ms:fortnights"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [
        "washbench: error: --columns: t: unknown time unit 'fortnights' (valid: s, ms, us, ns, min, timestamp)"
    ]
    assert not (tmp_path / "x").exists()


def test_bad_mapping_options_are_one_line(tmp_path: Path) -> None:
    with pytest.raises(WashbenchError, match=r"--columns: f_x: unknown specific force unit 'gee' \(valid: mps2"):
        input_format(columns="f_x=ax:gee")
    with pytest.raises(WashbenchError, match="--columns: unknown field 'fx'"):
        input_format(columns="fx=ax:g")
    with pytest.raises(WashbenchError, match="left-handed"):
        input_format(axes="fru")
    bad = tmp_path / "fmt.yaml"
    bad.write_text("axes: frd\ncolumns:\n  t: time:ms\n  f_q: ax:g\n")
    with pytest.raises(WashbenchError, match=r"fmt\.yaml:4: columns\.f_q: unknown field 'f_q'"):
        input_format(format_file=bad)
    assert InputFormat().axes == "frd"


def test_iso_timestamps_and_a_bad_one(tmp_path: Path) -> None:
    """Date-time text (ISO 8601, microseconds) counts from its first stamp; a broken stamp names its line."""
    import datetime as dt

    from washbench.io.readers import read_samples
    from washbench.io.resample import to_motion

    t0 = dt.datetime(2026, 12, 1, 19, 0, 0)
    stamps = [(t0 + dt.timedelta(microseconds=round(k * 1e6 / 120))).isoformat() for k in range(240)]
    lines = ["stamp,ax,ay,az,p,q,r", *(f"{s},0.1,0,-1,0,0,2" for s in stamps)]
    p = tmp_path / "ts.csv"
    p.write_text("\n".join(lines) + "\n")
    fmt = input_format(columns="t=stamp:timestamp,f_x=ax:g,f_y=ay:g,f_z=az:g,omega_x=p,omega_y=q,omega_z=r")
    m = to_motion(read_samples(p, fmt))
    assert m.t_s[0] == 0.0 and m.dt_s == pytest.approx(1 / 120, rel=1e-5)
    np.testing.assert_allclose(m.f_mps2[0], [0.1 * G0, 0.0, -G0], rtol=1e-15)
    assert m.omega_degps_out()[0, 2] == 2.0
    lines[101] = "yesterday,0.1,0,-1,0,0,2"
    p.write_text("\n".join(lines) + "\n")
    with pytest.raises(WashbenchError, match=r"ts\.csv:102: stamp: not a timestamp: 'yesterday'"):
        read_samples(p, fmt)
