"""Issue 26, recorded inputs through ``washbench cue`` (the command's entry, ``main``), with logs written here:

- JSBSim's own CSV logged below the simulation rate: the pilot accelerations are moved back one simulation
  frame, not one row; against the same flight as washbench records it (one-frame lag removed, 120 Hz);
- decimal-comma files: the hint, and ``--decimal ,`` reading them.
"""

from __future__ import annotations

from pathlib import Path

import jsbsim
import numpy as np
import pyarrow.csv as pacsv
import pyarrow.parquet as pq
import pytest

from washbench.cli import main
from washbench.flight.scripts import bundled_script, fly_script

SCRIPT = "c172_cruise_8K"
SECONDS = 14.0
START_S = 2.0  # the script starts untrimmed: its first second is a transient no 10 Hz log can follow
G0 = 9.80665


@pytest.fixture(scope="module")
def flown(tmp_path_factory: pytest.TempPathFactory) -> dict:
    """The script flown by washbench (reference: lag removed, every 120 Hz frame) and by JSBSim with its own CSV
    output at 120 Hz and at 10 Hz (every 12th frame)."""
    d = tmp_path_factory.mktemp("jsbsim_logs")
    (seg,) = fly_script(bundled_script(SCRIPT), max_time_s=SECONDS).segments
    logs = {}
    for rate in (120, 10):
        csv_path = d / f"log_{rate}.csv"
        directive = d / f"out_{rate}.xml"
        directive.write_text(
            f'<?xml version="1.0"?>\n<output name="{csv_path}" type="CSV" rate="{rate}">\n  <rates> ON </rates>\n'
            + "".join(f"  <property> accelerations/a-pilot-{a}-ft_sec2 </property>\n" for a in "xyz")
            + "</output>\n"
        )
        fdm = jsbsim.FGFDMExec(jsbsim.get_default_root_dir(), None)
        fdm.set_debug_level(0)
        fdm.set_output_path(str(d))
        fdm.load_script(str(bundled_script(SCRIPT)))
        fdm.set_output_directive(str(directive))
        fdm.run_ic()
        while fdm.get_sim_time() < SECONDS:
            fdm.run()
        del fdm
        logs[rate] = csv_path
    return {"ref": seg.columns, "logs": logs, "dir": d}


def cue_f(path: Path, out: Path, *extra: str) -> tuple[np.ndarray, np.ndarray]:
    argv = ["cue", str(path), "--out", str(out), "--washout", "large-angle", "--no-recording", "--no-figures"]
    assert main([*argv, "--quiet", *extra]) in (0, 1)
    t = pq.read_table(out / "traces.parquet")
    return t["t_s"].to_numpy(), np.column_stack([t[f"aircraft.f_{a}_mps2"].to_numpy() for a in "xyz"])


def reference_at(flown: dict, t: np.ndarray) -> np.ndarray:
    ref = flown["ref"]
    return np.column_stack([np.interp(t, ref["t_s"], ref[f"f_{a}_mps2"]) for a in "xyz"])


def test_a_10hz_jsbsim_log_is_shifted_one_frame_not_one_row(flown: dict, tmp_path: Path, capsys) -> None:
    """With the frame time given, the 10 Hz log's specific force matches the 120 Hz recording at its rows (within
    the linear interpolation over a twelfth of a row); shifted by a row it would be 11 frames early: many times
    further off."""
    t, f = cue_f(flown["logs"][10], tmp_path / "a", "--jsbsim-dt", str(1 / 120), "--start-s", str(START_S))
    out = capsys.readouterr().out
    assert "back one frame of 0.00833333 s (frame from --jsbsim-dt), interpolated between rows 0.0999996 s" in out
    ref = reference_at(flown, t)
    ref_next_row = reference_at(flown, t + 0.1 - 1 / 120)  # what the row shift gave: 11 frames ahead

    def rms(x: np.ndarray) -> float:
        return float(np.sqrt(np.mean(np.sum(x**2, axis=1))))

    err, row_err = rms(f - ref), rms(ref_next_row - ref)
    assert err < 0.02 and row_err > 5 * err, (err, row_err)  # measured 0.013 and 0.10 m/s^2
    # worst: the autopilot's step at 5.008 s, which no 10 Hz log resolves (measured 0.10 against 0.78 m/s^2)
    assert np.abs(f - ref).max() < 0.2 * np.abs(ref_next_row - ref).max()


def test_a_10hz_jsbsim_log_without_its_frame_time_is_not_shifted_and_says_so(flown: dict, tmp_path: Path,
                                                                              capsys) -> None:  # fmt: skip
    t, f = cue_f(flown["logs"][10], tmp_path / "b")
    out = capsys.readouterr().out
    assert "lag the other columns by one simulation frame, but the log's rows are 0.0999996 s apart" in out
    assert "NOT shifted (give the script's <run dt> with --jsbsim-dt S" in out
    logged = pacsv.read_csv(flown["logs"][10])["/fdm/jsbsim/accelerations/a-pilot-z-ft_sec2"].to_numpy()
    np.testing.assert_allclose(f[:, 2], logged[: len(t)] * 0.3048, rtol=1e-12)  # the rows as logged


def test_a_120hz_jsbsim_log_is_shifted_one_row(flown: dict, tmp_path: Path, capsys) -> None:
    t, f = cue_f(flown["logs"][120], tmp_path / "c")
    assert "shifted back one frame of 0.00833333 s = one row (frame from JSBSim's default" in capsys.readouterr().out
    inside = t < flown["ref"]["t_s"][-1]  # the recorder's last sample has no next frame to take its value from
    np.testing.assert_allclose(f[inside], reference_at(flown, t[inside]), rtol=0, atol=1e-9)


def test_a_decimal_comma_file_gets_the_hint_and_reads_with_decimal_comma(tmp_path: Path, capsys) -> None:
    """A semicolon CSV with decimal commas (as a German or French spreadsheet writes it): refused with the hint,
    then read with ``--decimal ,`` to the same metrics as the same numbers written with decimal points."""
    dot = tmp_path / "dot.csv"
    assert main(["signal", "sine", "--axis", "heave", "--amplitude", "1.5", "--frequency-hz", "0.5", "--duration-s",
                 "6", "--out", str(dot)]) == 0  # fmt: skip
    lines = dot.read_text().splitlines()
    comma = tmp_path / "comma.csv"
    comma.write_text("\n".join([lines[0].replace(",", ";")] + [ln.replace(",", ";").replace(".", ",")
                                                               for ln in lines[1:]]) + "\n")  # fmt: skip
    capsys.readouterr()
    base = ["--washout", "large-angle", "--no-recording", "--no-figures", "--quiet"]
    assert main(["cue", str(comma), "--out", str(tmp_path / "x"), *base]) == 2
    err = capsys.readouterr().err
    assert "comma.csv:2: t_s: not a number: '0,0' (a decimal comma? read the file with --decimal ,)" in err, err
    assert main(["cue", str(comma), "--out", str(tmp_path / "c"), "--decimal", ",", *base]) == 0
    assert main(["cue", str(dot), "--out", str(tmp_path / "d"), *base]) == 0
    assert (tmp_path / "c" / "metrics.csv").read_text() == (tmp_path / "d" / "metrics.csv").read_text()
    assert main(["cue", str(dot), "--out", str(tmp_path / "e"), "--decimal", ",", "--delimiter", ",", *base]) == 2
    assert "--decimal ,: the delimiter is ',' too" in capsys.readouterr().err


def write_log(path: Path, t: np.ndarray, f: np.ndarray, w: np.ndarray, names: str = "t,ax,ay,az,p,q,r") -> Path:
    """A hand-made log: time, three specific forces, three rates, in the units the caller chose."""
    rows = np.column_stack([t, f, w])
    path.write_text(names + "\n" + "\n".join(",".join(f"{v:.9g}" for v in r) for r in rows) + "\n")
    return path


def turning_flight(n: int, dt: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A gentle S-turn: f about -g with swings up to 1.5 m/s^2, rates up to 10 deg/s (SI and deg/s)."""
    t = np.arange(n) * dt
    s = np.sin(2 * np.pi * 0.2 * t)
    f = np.column_stack([0.5 * s, 1.5 * s, -G0 + 0.3 * s])
    w = np.column_stack([10.0 * s, 2.0 * s, 5.0 * s])
    return t, f, w


def test_resample_checks_plausibility_first_and_refuses_a_1000_fold_growth(tmp_path: Path, capsys) -> None:
    """Time in ms declared as s (0.01 Hz apparent; item 2 of issue 26): the same warning with --resample as without
    (it was skipped), and the 10,000-fold growth refused before anything is written; --force resamples a real
    2 Hz log 195-fold."""
    t, f, w = turning_flight(600, 0.1)
    log = write_log(tmp_path / "ms.csv", t * 1000.0, f, w)
    cols = ["--columns", "t=t,f_x=ax,f_y=ay,f_z=az,omega_x=p,omega_y=q,omega_z=r"]
    base = ["--washout", "large-angle", "--no-recording", "--no-figures", "--quiet", *cols]
    out = tmp_path / "out"
    warning = "sample rate 0.01 Hz is outside 10 Hz .. 10000 Hz: is the time in ms? (read as s now; give the unit " \
              "with --columns t=COLUMN:ms,...)"  # fmt: skip
    assert main(["cue", str(log), "--out", str(tmp_path / "plain"), *base]) == 0
    assert warning in capsys.readouterr().err
    assert main(["cue", str(log), "--out", str(out), "--resample", "100", *base]) == 2
    err = capsys.readouterr().err
    assert warning in err and "--resample 100 would make 5,990,001 rows of 600 (9983 times" in err, err
    assert not out.exists()
    slow = write_log(tmp_path / "slow.csv", *turning_flight(40, 0.5))  # 2 Hz, 20 s: at 400 Hz 8001 rows
    assert main(["cue", str(slow), "--out", str(out), "--resample", "400", *base]) == 2
    err = capsys.readouterr().err
    assert "--resample 400 would make 7,801 rows of 40 (195 times): sample rate 2 Hz is outside" in err, err
    assert not out.exists()
    assert main(["cue", str(slow), "--out", str(out), "--resample", "400", "--force", *base]) == 0
    assert pq.read_metadata(out / "traces.parquet").num_rows == 7801


@pytest.mark.parametrize(
    ("unit", "scale", "expected"),
    [
        ("radps", 1.0, "or rates in degps? (read as radps now; give the unit with --columns omega_x=COLUMN:degps"),
        ("degps", np.pi / 180, "are the rates in radps? (read as degps now; give the unit with --columns "
                               "omega_x=COLUMN:radps"),
        ("radps", np.pi / 180 / 1000, "they are read as radps already: is a wrong column mapped?"),
    ],
)
def test_rate_unit_hints_follow_from_what_was_declared(tmp_path: Path, capsys, unit: str, scale: float,
                                                       expected: str) -> None:  # fmt: skip
    """Rates written in deg/s but declared :radps reach 10 * 57.3 * ... deg/s: the hint says they look like deg/s
    (item 4 of issue 26 found the opposite advice, 'use :radps', which was what had been written)."""
    t, f, w = turning_flight(1200, 1 / 120)
    w = w * 30.0 if unit == "radps" and scale == 1.0 else w  # 300 deg/s read as rad/s: 17,000 deg/s
    log = write_log(tmp_path / "r.csv", t, f, w * scale)
    cols = f"t=t,f_x=ax,f_y=ay,f_z=az,omega_x=p:{unit},omega_y=q:{unit},omega_z=r:{unit}"
    main(["cue", str(log), "--out", str(tmp_path / "o"), "--columns", cols, "--washout", "large-angle",
          "--no-recording", "--no-figures", "--quiet"])  # fmt: skip
    err = capsys.readouterr().err
    assert expected in err, err
    if unit == "radps":
        assert "(use :radps)" not in err and "COLUMN:radps" not in err


def test_force_unit_hint_names_the_unit_that_fits(tmp_path: Path, capsys) -> None:
    """Specific force written in g but declared in ft/s^2: the hint is g (read as ftps2, |f| is 0.3 m/s^2)."""
    t, f, w = turning_flight(1200, 1 / 120)
    log = write_log(tmp_path / "g.csv", t, f / G0, w)
    cols = "t=t,f_x=ax:ftps2,f_y=ay:ftps2,f_z=az:ftps2,omega_x=p,omega_y=q,omega_z=r"
    main(["cue", str(log), "--out", str(tmp_path / "o"), "--columns", cols, "--washout", "large-angle",
          "--no-recording", "--no-figures", "--quiet"])  # fmt: skip
    err = capsys.readouterr().err
    assert "far from g: is it in g? (read as ftps2 now; give the unit with --columns f_x=COLUMN:g,...)" in err


def test_cue_draws_the_input_as_read_and_links_it_first(tmp_path: Path) -> None:
    """A z-up, y-left sensor (--axes flu) logging g and rad/s, its roll rate column negated in the mapping: the
    input figure's legends say where each body signal came from, and report.md shows it first."""
    t, f, w = turning_flight(1200, 1 / 120)
    sensor_f = np.column_stack([f[:, 0], -f[:, 1], -f[:, 2]]) / G0  # body frd -> sensor flu, in g
    sensor_w = np.radians(np.column_stack([-w[:, 0], -w[:, 1], -w[:, 2]]))  # flu, rad/s; x stored negated
    log = write_log(tmp_path / "imu.csv", t, sensor_f, sensor_w)
    cols = "t=t,f_x=ax:g,f_y=ay:g,f_z=az:g,omega_x=-p:radps,omega_y=q:radps,omega_z=r:radps"
    out = tmp_path / "out"
    assert main(["cue", str(log), "--out", str(out), "--columns", cols, "--axes", "flu", "--washout", "large-angle",
                 "--no-recording", "--quiet"]) == 0  # fmt: skip
    png = out / "figures" / "input.png"
    assert png.read_bytes()[:4] == b"\x89PNG"
    report = (out / "report.md").read_text()
    first_section = report.split("\n## ")[1]
    assert first_section.startswith("Input as read") and "![input as read](figures/input.png)" in first_section
    assert main(["report", str(out)]) == 0  # drawn again from the result's files, with its PDF
    assert (out / "figures" / "input.pdf").read_bytes()[:5] == b"%PDF-"
    assert "[input.pdf](figures/input.pdf)" in (out / "report.md").read_text().split("\n## ")[1]
    traces = pq.read_table(out / "traces.parquet")
    got = np.column_stack([traces[f"aircraft.f_{a}_mps2"].to_numpy() for a in "xyz"])
    np.testing.assert_allclose(got, f, rtol=1e-6, atol=1e-6)  # what the figure shows: the body-frame input

    from washbench.io.input_format import input_format
    from washbench.review.input_figure import input_labels

    fmt = input_format(cols, None, "flu")
    from washbench.io.readers import read_samples

    labels = input_labels(read_samples(log, fmt).sources, "flu", tuple(fmt.columns), fmt.origin)
    assert labels == [
        "f_x ← +'ax' (g); sign: --axes flu: sensor x [m/s²]",
        "f_y ← −'ay' (g); sign: --axes flu: sensor y reversed [m/s²]",
        "f_z ← −'az' (g); sign: --axes flu: sensor z reversed [m/s²]",
        "omega_x ← −'p' (rad/s); sign: '-' in --columns, --axes flu: sensor x [deg/s]",
        "omega_y ← −'q' (rad/s); sign: --axes flu: sensor y reversed [deg/s]",
        "omega_z ← −'r' (rad/s); sign: --axes flu: sensor z reversed [deg/s]",
    ]


def test_the_frame_time_can_come_from_an_input_format_file(flown: dict, tmp_path: Path) -> None:
    spec = tmp_path / "jsbsim.yaml"
    spec.write_text("format: jsbsim\njsbsim_dt_s: 0.0083333333\n")
    t1, f1 = cue_f(flown["logs"][10], tmp_path / "a", "--input-format", str(spec))
    t2, f2 = cue_f(flown["logs"][10], tmp_path / "b", "--jsbsim-dt", "0.0083333333")
    assert np.array_equal(t1, t2) and np.array_equal(f1, f2)
    spec.write_text("format: jsbsim\njsbsim_dt_s: -1\n")
    assert main(["cue", str(flown["logs"][10]), "--out", str(tmp_path / "c"), "--input-format", str(spec)]) == 2
