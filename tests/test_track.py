"""``washbench track``: JSBSim in the loop with the pilot model, through a washout, for real (a short task: two
runs of 23 s per condition), its files read back, determinism, and bad task files as one line each."""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

from tests.inprocess import washbench
from washbench.errors import WashbenchError
from washbench.flight.fly import fly
from washbench.flight.manoeuvre import load_manoeuvre
from washbench.pilot.model import PilotContext
from washbench.pilot.plugins import load_pilot_plugin
from washbench.review.rrd_read import read_properties, read_scalar_series, read_text_documents

SHORT_TASK = """\
name: short_roll
description: a short roll task for the tests (4 s of run-in, a window of 20.48 s)
aircraft: c172p
axis: roll
rate_hz: 100
start:
  air: {altitude_ft: 4000, airspeed_kts: 95, heading_deg: 90}
hold: {altitude_ft: 4000, airspeed_kts: 95}
measurement_s: 20.48
run_in_s: 4.0
fade_in_s: 2.0
runs: 2
seed: 5
target:
  multiples: [2, 5, 9, 12, 15, 19, 28, 45]
  rms_deg: 2.0
disturbance:
  multiples: [3, 6, 10, 13, 16, 21, 31, 53]
  rms_deg: 2.0
"""


@pytest.fixture(scope="module")
def tracked(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    folder = tmp_path_factory.mktemp("track")
    task = folder / "short_roll.yaml"
    task.write_text(SHORT_TASK)
    out = folder / "out"
    done = washbench("track", task, "--out", out, "--washout", "small-angle", "--quiet", timeout=300)
    assert done.returncode == 0, done.stderr
    assert "closest to flight: small-angle" in done.stdout
    return task, out


def test_every_file_is_written_and_says_the_same(tracked: tuple[Path, Path]) -> None:
    _, out = tracked
    for name in ("report.md", "track.json", "measures.csv", "frf.csv", "signals.parquet", "recording.rrd",
                 "figures/bode.png", "figures/variance.png", "figures/motion.png"):  # fmt: skip
        assert (out / name).is_file(), name
    summary = json.loads((out / "track.json").read_text())
    names = [c["name"] for c in summary["conditions"]]
    assert names == ["aircraft", "no-motion", "small-angle"]
    assert all(c["ok"] for c in summary["conditions"])
    report = (out / "report.md").read_text()
    first = report.split("\n\n")[1]
    assert first.startswith("**Verdict: small-angle leaves the simulator pilot's control closest to flight**")
    rows = {r["condition"]: r for r in csv.DictReader(io_text(out / "measures.csv"))}
    for c in summary["conditions"]:
        for key, value in c["measures"].items():
            got = rows[c["name"]][key]
            assert (got == "" and value is None) or float(got) == pytest.approx(value, rel=1e-8), key
    assert summary["provenance"]["task"]["sha256"]


def io_text(path: Path):  # type: ignore[no-untyped-def]
    import io

    return io.StringIO(path.read_text())


def test_the_pilot_adapts_and_the_loop_is_what_the_frequency_domain_predicts(tracked: tuple[Path, Path]) -> None:
    """JSBSim's closed loop against the prediction the adaptation made from the calibration: error variance
    within 15 % and the crossovers within 10 % (two runs; the remnant and JSBSim's couplings the rest); no motion:
    no vestibular gain; the aircraft's motion: a vestibular gain and a disturbance crossover above no motion's."""
    _, out = tracked
    summary = json.loads((out / "track.json").read_text())
    by = {c["name"]: c for c in summary["conditions"]}
    for c in by.values():
        m, p = c["measures"], c["prediction"]
        assert m["error_var_deg2"] == pytest.approx(p["error_var_deg2"], rel=0.15)
        assert m["disturbance_crossover_radps"] == pytest.approx(p["disturbance_crossover_radps"], rel=0.10)
        assert m["target_crossover_radps"] == pytest.approx(p["target_crossover_radps"], rel=0.10)
        assert p["stable"]
    assert by["no-motion"]["measures"]["vestibular_gain"] == 0.0
    assert by["aircraft"]["measures"]["vestibular_gain"] > 0.0
    assert by["aircraft"]["measures"]["disturbance_crossover_radps"] > by["no-motion"]["measures"][
        "disturbance_crossover_radps"]  # fmt: skip
    assert 0.0 < by["small-angle"]["measures"]["motion_gain_1radps"] < 1.2


def test_signals_and_recording_hold_the_runs(tracked: tuple[Path, Path]) -> None:
    """signals.parquet: every sample of every run; the recording: the first run of each condition, the same
    numbers, with the report and the provenance."""
    _, out = tracked
    table = pq.read_table(out / "signals.parquet").to_pydict()
    n = round((4.0 + 20.48) * 100)
    assert len(table["t_s"]) == 3 * 2 * n
    cond = np.array(table["condition"])
    run = np.array(table["run"])
    first = (cond == "aircraft") & (run == 1)
    error_deg = np.array(table["error_deg"])[first]
    series = read_scalar_series(out / "recording.rrd")
    t, values = series["/track/error"]
    assert values.shape == (n, 3)
    assert np.array_equal(values[:, 0], error_deg)
    assert t[1] - t[0] == pytest.approx(0.01)
    _, tilt = series["/track/platform"]  # the one washout's cockpit, rolling with the aircraft
    assert tilt.shape == (n,) and 0.1 < np.max(np.abs(tilt)) < 20.0
    assert read_text_documents(out / "recording.rrd")["/report"].startswith("# Pilot in the loop")
    assert "task.sha256" in read_properties(out / "recording.rrd")
    # the commanded aileron is the trim plus the pilot's control plus the disturbance: the control moves
    assert np.std(np.array(table["control"])[first]) > 0.0


def test_same_task_same_bits(tracked: tuple[Path, Path], tmp_path: Path) -> None:
    """Deterministic from the task's seed: a second command gives the same measures, responses and signals."""
    task, out = tracked
    again = tmp_path / "again"
    done = washbench("track", task, "--out", again, "--washout", "small-angle", "--quiet", "--no-figures",
                     "--no-recording", timeout=300)  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert (again / "measures.csv").read_bytes() == (out / "measures.csv").read_bytes()
    assert (again / "frf.csv").read_bytes() == (out / "frf.csv").read_bytes()
    a = pq.read_table(out / "signals.parquet")
    b = pq.read_table(again / "signals.parquet")
    assert a.equals(b)
    assert not (again / "recording.rrd").exists() and not (again / "figures").exists()


def test_report_draws_the_figures_again_from_the_files(tracked: tuple[Path, Path], tmp_path: Path) -> None:
    import shutil

    _, out = tracked
    copy = tmp_path / "copy"
    shutil.copytree(out, copy)
    shutil.rmtree(copy / "figures")
    done = washbench("report", copy)
    assert done.returncode == 0, done.stderr
    assert (copy / "figures" / "bode.png").read_bytes() == (out / "figures" / "bode.png").read_bytes()
    assert (copy / "report.md").read_text() == (out / "report.md").read_text()


@pytest.mark.parametrize(
    ("edit", "where"),
    [
        ("  multiples: [3, 6, 10, 13, 16, 21, 31, 53]", "disturbance.multiples: shares"),
        ("measurement_s: 20.48", "measurement_s: must be a whole number"),
        ("axis: roll", "axis: "),
        ("hold: {altitude_ft: 4000, airspeed_kts: 95}", "hold.bank_deg: the pilot model flies the roll axis"),
    ],
)
def test_a_bad_task_file_is_one_line_naming_file_line_and_field(tmp_path: Path, edit: str, where: str) -> None:
    bad = {
        "  multiples: [3, 6, 10, 13, 16, 21, 31, 53]": "  multiples: [3, 5, 10, 13, 16, 21, 31, 53]",
        "measurement_s: 20.48": "measurement_s: 20.485",
        "axis: roll": "axis: yaw",
        "hold: {altitude_ft: 4000, airspeed_kts: 95}": "hold: {altitude_ft: 4000, airspeed_kts: 95, bank_deg: 10}",
    }[edit]
    task = tmp_path / "bad.yaml"
    task.write_text(SHORT_TASK.replace(edit, bad))
    done = washbench("track", task, "--out", tmp_path / "out", "--quiet")
    assert done.returncode == 2
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in done.stderr
    line = SHORT_TASK.replace(edit, bad).splitlines().index(bad) + 1
    assert f"{task}:{line}: " in lines[0] and where in lines[0], lines[0]
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())


LEVEL = """\
name: level
aircraft: c172p
start:
  air: {altitude_ft: 4000, airspeed_kts: 95, heading_deg: 90}
phases:
  - name: level
    hold: {wings_level: true, altitude_ft: 4000, airspeed_kts: 95}
    until: {duration_s: 3}
"""


def test_fly_command_hook_sees_each_sample_and_sends_what_it_returns(tmp_path: Path) -> None:
    """fly(command_hook=...): called once per sample that sends commands, with that sample's attitude and rates,
    after the step hook got the sample before; what it returns is what is recorded (the aileron here)."""
    (tmp_path / "level.yaml").write_text(LEVEL)
    m = load_manoeuvre(tmp_path / "level.yaml")
    seen: list[tuple[int, float, float]] = []
    hooked: list[int] = []

    def step(k: int, f: np.ndarray, w: np.ndarray) -> None:
        hooked.append(k)

    def command(k: int, state: np.ndarray, commands: tuple[float, ...]) -> tuple[float, ...]:
        assert hooked[-1:] == ([k - 1] if k else [])
        seen.append((k, float(state[0]), float(state[3])))
        return (0.01 * math.sin(0.01 * k), *commands[1:])

    result = fly(m, step_hook=step, command_hook=command)
    assert result.ok, result.reason
    ks = [s[0] for s in seen]
    n = len(result.t_s)
    assert ks == list(range(n - 1))  # every sample but the last (no command after the end)
    phi = np.radians(result.columns["phi_deg"][: n - 1])
    assert np.allclose([s[1] for s in seen], phi, rtol=0, atol=1e-12)
    assert np.allclose(result.columns["aileron"][: n - 1], 0.01 * np.sin(0.01 * np.arange(n - 1)), atol=0)


def test_sweep_takes_the_pilot_model_as_an_objective(tracked: tuple[Path, Path], tmp_path: Path) -> None:
    """``sweep --pilot TASK``: the pilot model's predicted measures for every grid point (sweep_pilot.csv): less
    roll motion, farther from flight, and the full-motion candidate within a few percent of the aircraft."""
    task, _ = tracked
    out = tmp_path / "sweep"
    done = washbench("sweep", "c172/elevator_doublet", "--set", "scale.angular_velocity=0.25,1", "--washout",
                     "unrestricted", "--pilot", task, "--out", out, "--quiet", timeout=300)  # fmt: skip
    assert done.returncode == 0, done.stderr
    rows = list(csv.DictReader(io_text(out / "sweep_pilot.csv")))
    assert [float(r["scale.angular_velocity"]) for r in rows] == [0.25, 1.0]
    far, near = (float(r["distance_pct"]) for r in rows)
    assert far > near
    assert float(rows[1]["motion_gain_1radps"]) > 3.0 * float(rows[0]["motion_gain_1radps"])
    assert float(rows[1]["vestibular_gain"]) > float(rows[0]["vestibular_gain"])


def test_the_docs_pilot_plugin_flies_and_a_broken_one_is_one_line(tracked: tuple[Path, Path], tmp_path: Path) -> None:
    """--pilot-plugin: the example of docs/pilot-model.md flies the task in every condition (its parameters from
    the task file's pilot: section, its contributions reported); a plugin that raises is one line naming it."""
    import re

    task, _ = tracked
    page = (Path(__file__).resolve().parents[1] / "docs" / "pilot-model.md").read_text()
    section = page[page.index("## 10. Your own pilot model"):]
    code = re.search(r"```python\n(.*?)```", section, flags=re.S).group(1)  # type: ignore[union-attr]
    (tmp_path / "my_pilot.py").write_text(code)
    mine = tmp_path / "task.yaml"
    mine.write_text(task.read_text() + "pilot: {gain: 1.2}\n")
    out = tmp_path / "out"
    done = washbench("track", mine, "--out", out, "--washout", "small-angle", "--runs", "1", "--no-figures",
                     "--no-recording", "--quiet", "--pilot-plugin", f"{tmp_path / 'my_pilot.py'}:ProportionalPilot",
                     timeout=300)  # fmt: skip
    assert done.returncode in (0, 1), done.stderr  # a proportional pilot without delay may lose a condition
    summary = json.loads((out / "track.json").read_text())
    assert summary["pilot"]["model"] == "plugin" and summary["pilot"]["plugin"]["sha256"]
    ac = next(c for c in summary["conditions"] if c["name"] == "aircraft")
    assert ac["ok"] and ac["measures"]["visual_gain"] == 1.2 and ac["measures"]["control_vestibular_var"] == 0.0
    bad = "class Bad:\n    def __init__(self, params, context):\n        raise ValueError('no')\n"
    (tmp_path / "bad.py").write_text(bad)
    plugin = load_pilot_plugin(f"{tmp_path / 'bad.py'}:Bad")
    with pytest.raises(WashbenchError) as err:
        plugin.make(None, PilotContext(dt_s=0.01, axis="roll", steps=10, seed=0))
    assert str(err.value) == f"pilot plugin {tmp_path / 'bad.py'}:Bad: raised ValueError: no"
