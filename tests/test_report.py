"""Report, figures and provenance: one short real flight with custom parameter and platform files, read back."""

from __future__ import annotations

import csv
import datetime
import hashlib
import importlib.metadata
import json
import re
import shutil
import subprocess
from pathlib import Path

import inprocess
import numpy as np
import pyarrow.parquet as pq
import pytest
from report_helpers import check_images, check_tables, without_pdf_links

from washbench.io.paths import AIRCRAFT_DIR, DATA_DIR, jsbsim_root
from washbench.io.provenance import PARQUET_KEY
from washbench.review.figures import minmax_decimate
from washbench.review.numbers import sig
from washbench.review.palette import AIRCRAFT_COLOR, WASHOUT_COLORS, washout_colors
from washbench.review.report import NO_FIGURES, write_result_report

MANOEUVRE = """\
name: short_bank
aircraft: c172p
start:
  air: {altitude_ft: 3000, airspeed_kts: 90, heading_deg: 45}
environment:
  turbulence: {severity: light, seed: 7}
phases:
  - name: level
    hold: {wings_level: true, altitude_ft: 3000, airspeed_kts: 90}
    until: {duration_s: 3}
  - name: bank
    hold: {bank_deg: -25, altitude_ft: 3000, airspeed_kts: 90}
    until: {duration_s: 6}
checks:
  - {name: banked, signal: phi_deg, stat: min, phases: [bank], max: -10}
"""


def washbench(*args: str | Path) -> subprocess.CompletedProcess[str]:
    return inprocess.washbench(*args, timeout=600)


def sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


@pytest.fixture(scope="module")
def inputs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    folder = tmp_path_factory.mktemp("inputs")
    manoeuvre = folder / "short_bank.yaml"
    manoeuvre.write_text(MANOEUVRE)
    params = folder / "my_cw.yaml"
    text = (DATA_DIR / "cw1.yaml").read_text()
    params.write_text(re.sub(r"^name: CW1\b", "name: CW1-report-test", text, count=1, flags=re.M))
    platform = folder / "my_atlas.yaml"
    text = (DATA_DIR / "atlas.yaml").read_text()
    platform.write_text(
        re.sub(r"^name: .*$", "name: Atlas narrow", text, count=1, flags=re.M).replace("x: 1.5", "x: 0.5", 1)
    )
    return {"manoeuvre": manoeuvre, "params": params, "platform": platform}


@pytest.fixture(scope="module")
def run_dir(inputs: dict[str, Path], tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("run")
    proc = washbench(
        "run", inputs["manoeuvre"], "--out", out, "--params", inputs["params"], "--platform", inputs["platform"],
        "--quiet",
    )  # fmt: skip
    assert proc.returncode == 0, proc.stdout + proc.stderr
    return out / "c172p" / "short_bank"


def test_run_json_records_what_made_the_result(run_dir: Path, inputs: dict[str, Path]) -> None:
    doc = json.loads((run_dir / "run.json").read_text())
    prov = doc["provenance"]
    assert prov["params"]["name"] == "CW1-report-test"
    assert prov["params"]["sha256"] == sha256(inputs["params"])
    assert prov["params"]["path"] == str(inputs["params"])
    assert prov["platform"]["name"] == "Atlas narrow"
    assert prov["platform"]["sha256"] == sha256(inputs["platform"])
    assert prov["platform"]["values"]["translation"]["position_limit_m"]["x"] == 0.5
    assert prov["manoeuvre"] == {"path": str(inputs["manoeuvre"]), "sha256": sha256(inputs["manoeuvre"])}
    assert prov["turbulence"] == {"severity": "light", "seed": 7}
    # bundled files are named as bundled, the same on every machine, with their hash (issue 38, item 8)
    assert prov["aircraft"]["name"] == "c172p" and prov["aircraft"]["path"] == "jsbsim:aircraft/c172p/c172p.xml"
    assert prov["aircraft"]["sha256"] == sha256(jsbsim_root() / "aircraft" / "c172p" / "c172p.xml")
    assert prov["aircraft"]["bundled"] == f"jsbsim {importlib.metadata.version('jsbsim')}"
    assert prov["pilot_profile"]["path"] == "washbench:aircraft/c172p/pilot.yaml"
    assert prov["pilot_profile"]["sha256"] == sha256(AIRCRAFT_DIR / "c172p" / "pilot.yaml")
    sw = prov["software"]
    for key, dist in (("jsbsim", "jsbsim"), ("rerun", "rerun-sdk"), ("numpy", "numpy"), ("washbench", "washbench")):
        assert sw[key] == importlib.metadata.version(dist)
    assert sw["numpy"] == np.__version__
    created = datetime.datetime.fromisoformat(doc["created_utc"].replace("Z", "+00:00"))
    assert abs((datetime.datetime.now(datetime.UTC) - created).total_seconds()) < 3600


def test_parquet_metadata_holds_the_provenance_but_no_date(run_dir: Path) -> None:
    run_prov = json.loads((run_dir / "run.json").read_text())["provenance"]
    traces = json.loads(pq.read_schema(run_dir / "traces.parquet").metadata[PARQUET_KEY])
    assert traces == run_prov
    flight = json.loads(pq.read_schema(run_dir / "flight.parquet").metadata[PARQUET_KEY])
    assert flight["manoeuvre"] == run_prov["manoeuvre"] and flight["turbulence"] == run_prov["turbulence"]
    assert "params" not in flight  # washbench fly uses no washout parameters
    for name in ("traces.parquet", "flight.parquet"):
        meta = b"".join(k + v for k, v in pq.read_schema(run_dir / name).metadata.items())
        assert b"created" not in meta and datetime.date.today().isoformat().encode() not in meta, name


def test_report_header_names_the_inputs_and_versions(run_dir: Path, inputs: dict[str, Path]) -> None:
    text = (run_dir / "report.md").read_text()
    header = text.split("## Ranking")[0]
    needles = ["CW1-report-test", sha256(inputs["params"]), "Atlas narrow", sha256(inputs["platform"])]
    needles += [sha256(inputs["manoeuvre"]), "light, seed 7", "JSBSim 1.3.3", f"numpy {np.__version__}"]
    for needle in needles:
        assert needle in header, needle
    # no absolute path of this machine for a bundled file (a checkout's aircraft/, site-packages' jsbsim/)
    assert str(AIRCRAFT_DIR) not in header and str(jsbsim_root()) not in header
    assert "`washbench:aircraft/c172p/pilot.yaml` (bundled with washbench" in header


def test_every_linked_figure_exists_and_is_an_image(run_dir: Path) -> None:
    assert check_images(run_dir / "report.md") == 3  # perceived motion, false and missing cues, platform envelope


def test_every_table_is_well_formed(run_dir: Path) -> None:
    # provenance, ranking, where the felt error comes from, cue classification, motion sickness dose, three metric
    # tables, time at a limit, checks, phases
    assert check_tables(run_dir / "report.md") == 11


def test_report_reads_like_a_table(run_dir: Path) -> None:
    text = (run_dir / "report.md").read_text()
    assert (
        "| washout | surge (m/s²·s) | sway (m/s²·s) | heave (m/s²·s) | roll (deg) | pitch (deg) | yaw (deg) |" in text
    )
    assert "| washout | surge (m/s²) |" in text and "roll (deg/s)" in text
    assert not re.search(r"\d[eE][+-]?\d", text.split("| provenance |")[0] + text.split("## Ranking")[1])
    # the best value of each DOF is bold: the minimum of metrics.csv
    with (run_dir / "metrics.csv").open() as f:
        rows = list(csv.DictReader(f))
    best = min(float(r["integral_error"]) for r in rows if r["dof"] == "roll")
    table = text.split("Integral of |perceived error|")[1].split("\n\n")[1]
    assert f"**{sig(best)}**" in table


def test_saturation_is_given_in_seconds_and_percent(run_dir: Path) -> None:
    text = (run_dir / "report.md").read_text()
    traces = pq.read_table(run_dir / "traces.parquet")
    n = traces.num_rows
    flags = traces.column("unrestricted.sat_tilt_rate").to_numpy()
    steps = int(flags.sum())
    assert steps > 0  # the bank needs more tilt than the 3 deg/s tilt-rate limit gives
    line = next(ln for ln in text.splitlines() if ln.startswith("| tilt-rate limit"))
    cells = [c.strip() for c in line.strip("|").split("|")]
    seconds, percent = re.fullmatch(r"([\d.]+) s \(([\d.]+) %\)", cells[3]).groups()
    assert float(seconds) == pytest.approx(steps / 120.0, rel=5e-3)
    assert float(percent) == pytest.approx(100.0 * steps / n, rel=5e-2)


def test_report_is_regenerated_from_the_files_alone(run_dir: Path, inputs: dict[str, Path], tmp_path: Path) -> None:
    copy = tmp_path / "copy"
    shutil.copytree(run_dir, copy)
    shutil.rmtree(copy / "figures")
    (copy / "report.md").unlink()
    hidden = tmp_path / "hidden"
    hidden.mkdir()
    for f in inputs.values():  # no manoeuvre, parameter or platform file to read: nothing can be flown or cued
        shutil.move(f, hidden / f.name)
    try:
        proc = washbench("report", copy)
    finally:
        for f in inputs.values():
            shutil.move(hidden / f.name, f)
    assert proc.returncode == 0, proc.stderr
    # the same report, with the PDF versions the run left to `washbench report` now linked
    assert without_pdf_links((copy / "report.md").read_text()) == (run_dir / "report.md").read_text()
    assert check_images(copy / "report.md", vector=True) == 3
    for name in ("perceived.png", "envelope.png", "cues.png"):
        assert (copy / "figures" / name).read_bytes() == (run_dir / "figures" / name).read_bytes(), name


def test_cue_results_get_the_same_report(run_dir: Path, tmp_path: Path) -> None:
    out = tmp_path / "cue"
    variant = "sa_slow_tilt=small-angle,tilt.gain_per_s=0.2"
    proc = washbench("cue", run_dir / "flight.parquet", "--out", out, "--washout", "small-angle", "--variant", variant,
                     "--no-recording")  # (the recording's provenance: test_recording_properties_hold_the_provenance)
    assert proc.returncode == 0, proc.stderr
    prov = json.loads(pq.read_schema(out / "traces.parquet").metadata[PARQUET_KEY])
    assert prov["input"]["sha256"] == sha256(run_dir / "flight.parquet")
    flown = json.loads(pq.read_schema(run_dir / "flight.parquet").metadata[PARQUET_KEY])
    assert prov["input"]["provenance"] == flown  # what made the input travels with it
    assert prov["params"]["name"] == "CW1" and prov["params"]["sha256"] == sha256(DATA_DIR / "cw1.yaml")
    small, variant_rec = prov["washouts"]
    assert small == {"name": "small-angle", "kind": "small-angle"}  # the file's own parameters
    assert variant_rec["name"] == "sa_slow_tilt" and variant_rec["values"]["tilt"]["gain_per_s"] == 0.2
    text = write_result_report(out).read_text()
    assert sha256(run_dir / "flight.parquet") in text and flown["manoeuvre"]["sha256"] in text
    assert "| sa_slow_tilt |" in text and "sa_slow_tilt vs small-angle (% better)" in text
    assert "| washouts | small-angle, sa_slow_tilt (small-angle) with its own values |" in text
    assert check_images(out / "report.md") == 4  # input as read, perceived, cues, envelope
    assert text.split("\n## ")[1].startswith("Input as read")


def test_no_figures_then_report_draws_them_with_their_pdfs(run_dir: Path, tmp_path: Path) -> None:
    out = tmp_path / "lean"
    proc = washbench("cue", run_dir / "flight.parquet", "--out", out, "--no-figures", "--no-recording")
    assert proc.returncode == 0, proc.stderr
    assert not (out / "figures").exists() and not (out / "recording.rrd").exists()
    text = (out / "report.md").read_text()
    assert NO_FIGURES in text and ".png" not in text
    assert check_tables(out / "report.md") >= 5  # every table is still there
    # the same cue with figures gives the same tables, and `washbench report` draws what --no-figures left out
    full = tmp_path / "full"
    assert washbench("cue", run_dir / "flight.parquet", "--out", full, "--no-recording").returncode == 0
    def rows(t: str) -> list[str]:
        return [ln for ln in t.splitlines() if ln.startswith("|") and not ln.startswith("| created |")]

    assert rows(text) == rows((full / "report.md").read_text())
    proc = washbench("report", out)
    assert proc.returncode == 0, proc.stderr
    assert check_images(out / "report.md", vector=True) == 3
    for name in ("perceived.png", "envelope.png", "cues.png"):  # drawn from the files = drawn by the cue from memory
        assert (out / "figures" / name).read_bytes() == (full / "figures" / name).read_bytes(), name


def test_user_named_washouts_come_from_the_data(run_dir: Path, tmp_path: Path) -> None:
    copy = tmp_path / "renamed"
    shutil.copytree(run_dir, copy)
    (copy / "metrics.csv").write_text((run_dir / "metrics.csv").read_text().replace("unrestricted,", "my-variant,"))
    table = pq.read_table(run_dir / "traces.parquet")
    renamed = table.rename_columns([c.replace("unrestricted.", "my-variant.") for c in table.column_names])
    pq.write_table(renamed.replace_schema_metadata(table.schema.metadata), copy / "traces.parquet")
    text = write_result_report(copy).read_text()
    assert "| my-variant |" in text and "my-variant vs small-angle" in text
    assert "unrestricted" not in text.split("## Ranking")[1]  # (the provenance still says what was run)
    check_images(copy / "report.md")


def test_report_of_a_missing_or_foreign_folder_is_one_line(tmp_path: Path) -> None:
    for target in (tmp_path / "nope", tmp_path):
        proc = washbench("report", target)
        assert proc.returncode == 2 and "Traceback" not in proc.stderr
        assert len(proc.stderr.strip().splitlines()) == 1, proc.stderr


def test_washout_colours_are_fixed_distinct_and_the_recordings() -> None:
    from washbench.review import blueprint

    names = ["my-a", "large-angle", "my-b", "small-angle", "unrestricted"]
    colors = washout_colors(names)
    for name, rgb in WASHOUT_COLORS.items():
        assert colors.get(name, rgb) == rgb  # (the bound's fixed grey: not among these names)
    assert len(set(colors.values())) == len(colors)
    assert [blueprint.series_color(w, names) for w in names] == [colors[w] for w in names]
    assert blueprint.series_color("aircraft") == AIRCRAFT_COLOR


@pytest.mark.parametrize("x", [5.058e-05, 83.88, 0.99951, 9.996, -12345.0, 1.0, 0.1, 123.4, -0.000123456])
def test_number_format_has_three_significant_digits_and_no_exponent(x: float) -> None:
    text = sig(x)
    assert "e" not in text.lower()
    assert float(text) == pytest.approx(float(f"{x:.3g}"), rel=1e-12)


def test_decimation_keeps_every_peak() -> None:
    rng = np.random.default_rng(1)
    t = np.arange(100_003) / 120.0
    y = np.cumsum(rng.normal(size=t.size))
    y[777] = 1e3  # a one-sample spike
    tt, yy = minmax_decimate(t, y, buckets=500)
    assert tt.size <= 1000 and np.all(np.diff(tt) >= 0)
    assert yy.max() == y.max() and yy.min() == y.min()
    assert 1e3 in yy and t[777] in tt


def test_flat_provenance_for_the_recording(run_dir: Path, inputs: dict[str, Path]) -> None:
    from washbench.io.provenance import flat_strings

    doc = json.loads((run_dir / "run.json").read_text())
    flat = flat_strings(doc["provenance"], doc["created_utc"])
    assert flat["params.sha256"] == sha256(inputs["params"]) and flat["params.name"] == "CW1-report-test"
    assert flat["turbulence.seed"] == "7" and flat["software.jsbsim"] == "1.3.3"
    assert flat["created_utc"] == doc["created_utc"]
    assert all(isinstance(v, str) for v in flat.values()) and not any(".values." in k for k in flat)


def test_time_beyond_the_threshold_counts_the_felt_samples(run_dir: Path) -> None:
    text = (run_dir / "report.md").read_text()
    row = next(ln for ln in text.splitlines() if ln.startswith("|") and "beyond the perception threshold" in ln)
    values = [float(c) for c in row.strip("|").split("|")[1:]]
    roll = pq.read_table(run_dir / "traces.parquet").column("aircraft.perceived_omega_x_degps").to_numpy()
    # rolling into a 25 deg bank is felt (Zacharias roll threshold 3.0 deg/s around the rate perceived at the start),
    # for less than the manoeuvre
    assert values[3] == pytest.approx(float(np.count_nonzero(np.abs(roll - roll[0]) > 3.0)) / 120.0, rel=5e-3)
    assert 0.0 < values[3] < roll.size / 120.0


def test_envelope_shows_the_angular_acceleration_the_lanes_flag(run_dir: Path) -> None:
    from washbench.review.result_data import load_result

    data = load_result(run_dir)
    limit = json.loads((run_dir / "run.json").read_text())["provenance"]["platform"]["values"]["rotation"]
    table = pq.read_table(run_dir / "traces.parquet")
    for w in data.washouts:
        omega = np.column_stack([table.column(f"{w}.omega_platform_{a}_degps").to_numpy() for a in "xyz"])
        alpha = np.linalg.norm(np.gradient(omega, 1.0 / 120.0, axis=0), axis=1)  # central differences, deg/s^2
        usage = data.usage["sphere ang. acc."][w]
        assert usage.max() <= 1.0 + 1e-9
        # a step's backward difference lies within the neighbouring central differences' range (smooth traces)
        assert np.max(usage) == pytest.approx(np.max(alpha) / limit["acceleration_limit_degps2"], rel=0.25, abs=1e-3)
        flags = data.saturated[w].get("angacc")
        if flags is not None and flags.any():
            assert np.max(usage[flags]) == pytest.approx(1.0, abs=1e-6)


def test_recording_properties_hold_the_provenance(run_dir: Path, inputs: dict[str, Path]) -> None:
    from washbench.review.rerun_log import read_properties

    props = read_properties(run_dir / "recording.rrd")
    doc = json.loads((run_dir / "run.json").read_text())
    assert props["params.sha256"] == sha256(inputs["params"]) and props["params.name"] == "CW1-report-test"
    assert props["platform.sha256"] == sha256(inputs["platform"]) and props["turbulence.seed"] == "7"
    assert props["software.jsbsim"] == "1.3.3" and props["created_utc"] == doc["created_utc"]


def test_false_cue_time_is_given_in_seconds(run_dir: Path) -> None:
    """Issue 52, item 10: "False-cue time (sum over DOFs, manoeuvre lengths): 0.262" could not be read; it is the
    time with a false cue in seconds, added up over the DOFs, against the manoeuvre's length, each washout's equal to
    the false-cue time fractions of metrics.csv times that length."""
    text = (run_dir / "report.md").read_text()
    line = next(ln for ln in text.splitlines() if ln.startswith("Time with a false cue"))
    n = pq.read_table(run_dir / "traces.parquet").num_rows
    length_s = (n - 1) / 120.0
    m = re.fullmatch(r"Time with a false cue, added up over the six DOFs \(a second with false cues in two DOFs "
                     r"counts twice\): (.*), of a ([\d.]+) s manoeuvre\.", line)  # fmt: skip
    assert m is not None, line
    assert float(m[2]) == pytest.approx(length_s, rel=5e-3)
    rows = list(csv.DictReader((run_dir / "metrics.csv").open()))
    for part in m[1].split(", "):
        washout, seconds = re.fullmatch(r"(\S+) ([\d.]+) s", part).groups()
        frac = sum(float(r["cue_false_frac"]) for r in rows if r["washout"] == washout)
        assert float(seconds) == pytest.approx(frac * length_s, rel=5e-3, abs=1e-9), washout
    assert "False-cue time (sum over DOFs" not in text


def test_the_felt_error_s_parts_add_up_to_the_ranking_s_value(run_dir: Path) -> None:
    """The report's "Where the felt error comes from": each row's DOF parts add up to the washout's felt error in
    ranking.csv, and each part is its DOF's term worked by hand from metrics.csv and run.json (Zacharias 1978's
    thresholds as the units, a false cue counted twice, 1 s per m/s^2 of jolt: docs/metrics.md)."""
    units = {"surge": 0.17, "sway": 0.17, "heave": 0.28, "roll": 3.0, "pitch": 3.6, "yaw": 2.6}
    text = (run_dir / "report.md").read_text()
    head = text.index("**Where the felt error comes from**")
    lines = text[head:].splitlines()[2:]
    table = lines[: next(i for i, ln in enumerate(lines) if not ln.startswith("|"))]
    columns = [c.strip() for c in table[0].strip("|").split("|")]
    assert columns == ["washout", *units, "felt error", "false", "jolts"]
    ranked = {r["washout"]: float(r["score"]) for r in csv.DictReader((run_dir / "ranking.csv").open())}
    metrics = {(r["washout"], r["dof"]): r for r in csv.DictReader((run_dir / "metrics.csv").open())}
    motion = json.loads((run_dir / "run.json").read_text())["perceived_motion"]
    felt = sum(float(motion[f"felt_{d}"]["value"]) / u for d, u in units.items())
    rows = [[c.strip() for c in ln.strip("|").split("|")] for ln in table[2:]]
    assert {r[0] for r in rows} == set(ranked)
    for name, *cells in rows:
        parts = [0.0 if c == "< 0.0001" else float(c) for c in cells[:6]]
        assert sum(parts) == pytest.approx(ranked[name], rel=5e-3, abs=6e-4)
        assert float(cells[6]) == pytest.approx(ranked[name], rel=5e-3)
        for (d, u), shown in zip(units.items(), parts, strict=True):
            m = metrics[(name, d)]
            jolt = float(m["jolt"] or 0.0) if d in ("surge", "sway", "heave") else 0.0
            term = (float(m["felt_error"]) + float(m["felt_false"]) + 1.0 * jolt) / u / felt
            assert shown == pytest.approx(term, rel=5e-3, abs=1e-4), (name, d)
