"""Issue 26 for the long commands, driven through ``main`` with manoeuvres written here:

- ``tune`` prints the training and the held-out test result (not only the training one) and warns when the tuned
  set got worse on the test manoeuvres; the numbers are checked against ``washbench cue`` of each flight with
  the starting and the tuned parameter file (the ranking rule over cue's own metrics: an independent path);
- ``suite``, ``sweep`` and ``tune`` print progress with the expected end (in a log: plain lines, no ``\\r``).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest
from flight_helpers import write

from washbench.analysis.ranking import perceived_motion, rank
from washbench.cli import main
from washbench.io.metrics_csv import read_metrics_csv

TURN = """\
    name: bank_left
    aircraft: c172p
    start:
      air: {altitude_ft: 3000, airspeed_kts: 100, heading_deg: 0}
    phases:
      - name: level
        hold: {wings_level: true, altitude_ft: 3000, airspeed_kts: 100}
        until: {duration_s: 2}
      - name: bank
        hold: {bank_deg: -25, altitude_ft: 3000, airspeed_kts: 100}
        until: {duration_s: 6}
"""
PULL = """\
    name: pull_up
    aircraft: c172p
    start:
      air: {altitude_ft: 3000, airspeed_kts: 100, heading_deg: 0}
    phases:
      - name: level
        hold: {wings_level: true, altitude_ft: 3000, airspeed_kts: 100}
        until: {duration_s: 2}
      - name: pull
        hold: {wings_level: true, airspeed_kts: 100}
        inputs:
          elevator: {shape: doublet, amplitude_deg: -3, start_s: 0.5, duration_s: 2, free: true}
        until: {duration_s: 6}
"""


@pytest.fixture(scope="module")
def studies(tmp_path_factory: pytest.TempPathFactory) -> dict:
    """One suite, then a tune on its flights (training: the turn; test: the pull-up), progress shown in a log."""
    d = tmp_path_factory.mktemp("studies")
    turn, pull = write(d, "turn.yaml", TURN), write(d, "pull.yaml", PULL)
    mp = pytest.MonkeyPatch()
    mp.setattr("washbench.io.progress.QUIET_FOR_S", 0.0)
    import contextlib
    import io

    out: dict = {"dir": d}
    try:
        for name, argv in (
            ("suite", ["suite", str(turn), str(pull), "--out", str(d / "suite"), "--jobs", "1", "--no-recording",
                       "--no-figures"]),
            ("tune", ["tune", str(turn), "--test", str(pull), "--washout", "large-angle", "--tune",
                      "tilt.gain_per_s=0.2:5", "--budget", "12", "--seed", "1", "--from", str(d / "suite"),
                      "--out", str(d / "tune")]),
            ("sweep", ["sweep", str(turn), str(pull), "--washout", "large-angle", "--set", "tilt.gain_per_s=0.4,2",
                       "--from", str(d / "suite"), "--out", str(d / "sweep")]),
        ):  # fmt: skip
            o, e = io.StringIO(), io.StringIO()
            with contextlib.redirect_stdout(o), contextlib.redirect_stderr(e):
                code = main(argv)
            out[name] = (code, o.getvalue(), e.getvalue())
    finally:
        mp.undo()
    return out


def cue_score(flight: Path, out: Path, params: Path | None) -> float:
    """The large-angle washout's score by ``washbench cue`` of a flight (ranking rule over cue's metrics)."""
    argv = ["cue", str(flight), "--out", str(out), "--washout", "large-angle", "--no-recording", "--no-figures"]
    assert main([*argv, *(["--params", str(params)] if params else []), "--quiet"]) == 0
    t = pq.read_table(out / "traces.parquet")
    f = np.column_stack([t[f"aircraft.perceived_f_{a}_mps2"].to_numpy() for a in "xyz"])
    w = np.radians(np.column_stack([t[f"aircraft.perceived_omega_{a}_degps"].to_numpy() for a in "xyz"]))
    dt = float(np.diff(t["t_s"].to_numpy()).mean())
    (row,) = rank(read_metrics_csv(out / "metrics.csv"), perceived_motion(f, w, dt))
    return row.score


def test_tune_prints_training_and_test_scores(studies: dict, tmp_path: Path) -> None:
    code, stdout, _ = studies["tune"]
    assert code == 0
    d = studies["dir"]
    pattern = r"mean score on the 1 (training|test) manoeuvre\(s\): CW1 ([\d.]+) -> tuned ([\d.]+) \((\w+)\)"
    found = {m[1]: (float(m[2]), float(m[3]), m[4]) for m in re.finditer(pattern, stdout)}
    assert set(found) == {"training", "test"}, stdout
    for group, name in (("training", "bank_left"), ("test", "pull_up")):
        flight = d / "suite" / "c172p" / name / "flight.parquet"
        base = cue_score(flight, tmp_path / f"{name}_base", None)
        tuned = cue_score(flight, tmp_path / f"{name}_tuned", d / "tune" / "tuned.yaml")
        a, b, verdict = found[group]
        assert (a, b) == pytest.approx((base, tuned), abs=6e-5)  # printed to 4 decimals
        assert verdict == ("better" if b < a else "worse" if b > a else "unchanged")
    a, b, _ = found["test"]
    assert ("warning: the tuned set scores worse than CW1 on the held-out test manoeuvres" in stdout) == (b > a)


@pytest.mark.parametrize(("command", "unit", "total"), [("suite", "manoeuvres", 2), ("tune", "evaluations", 12)])
def test_long_commands_print_their_expected_end(studies: dict, command: str, unit: str, total: int) -> None:
    code, _, stderr = studies[command]
    assert code == 0 and "\r" not in stderr  # a log: plain lines
    lines = [ln for ln in stderr.splitlines() if re.match(rf"{command}: +\d+% \(", ln)]
    assert lines, stderr
    for ln in lines:
        m = re.match(rf"{command}: +(\d+)% \((\d+) of {total} {unit}\)(, expected end \d\d:\d\d:\d\d \(in .*\)|, "
                     r"done in .*)", ln)  # fmt: skip
        assert m, ln
        assert int(m.group(1)) == round(100 * int(m.group(2)) / total)


def test_sweep_prints_its_expected_end(studies: dict) -> None:
    code, _, stderr = studies["sweep"]
    assert code == 0 and "\r" not in stderr
    assert re.search(r"^sweep: 100% \([\d,]+ of [\d,]+ steps\), done in \d+ s$", stderr, re.M), stderr
