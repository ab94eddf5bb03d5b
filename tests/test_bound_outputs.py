"""The ceiling, the bound's replay and the MPC's solver statistics through the real outputs of ``suite``, ``run``
and ``cue``; the MPC in ``omct``, ``sweep`` and ``tune``.

The ceiling is at most every washout's score and relative error per DOF, on the ranking's own measure (a washout
below it is a defect: the check fails). Checked here on a short real JSBSim flight through the suite's files; on
every bundled manoeuvre by ``WASHBENCH_BOUND_SUITE=<a suite folder run with --washout bound>`` or
``WASHBENCH_SLOW=1`` (flies them all), which ``.ci/run`` runs as a step after the README's test command.
"""

from __future__ import annotations

import csv
import json
import math
import os
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest
from ceiling_helpers import DOFS, check_ceiling_below_every_washout, read_csv, washbench

from washbench.cueing.params import DEFAULT_PARAMS_PATH
from washbench.io.paths import MANOEUVRES_DIR

CW1 = DEFAULT_PARAMS_PATH.read_text().rstrip("\n") + "\n"  # the bundled parameter file, a section added below

ALL = ["small-angle", "large-angle", "unrestricted", "adaptive", "optimal", "mpc", "bound"]
SHORT = """\
name: bound_doublet
description: the C172 elevator doublet, shortened (settle 1 s, doublet 1.2 s, response 2.5 s)
aircraft: c172p
start:
  air: {altitude_ft: 4000, airspeed_kts: 95, heading_deg: 90}
phases:
  - name: settle
    hold: {wings_level: true, altitude_ft: 4000, airspeed_kts: 95}
    until: {duration_s: 1}
  - name: doublet
    hold: {wings_level: true}
    inputs:
      elevator: {shape: doublet, amplitude_deg: 3, duration_s: 1.2, free: true}
      throttle: {free: true}
    until: {duration_s: 1.2}
  - name: response
    hold: {wings_level: true}
    inputs:
      elevator: {free: true}
      throttle: {free: true}
    until: {duration_s: 2.5}
"""



@pytest.fixture(scope="module")
def suite_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("short")
    (folder / "bound_doublet.yaml").write_text(SHORT)
    out = tmp_path_factory.mktemp("suite")
    washout_args = [a for w in ALL for a in ("--washout", w)]
    proc = washbench("suite", folder, "--out", out, "--jobs", "1", "--no-recording", "--no-figures", "--quiet",
                     *washout_args)  # fmt: skip
    assert proc.returncode == 0, proc.stdout + proc.stderr
    return out


def test_ceiling_below_every_washout_through_the_suite_outputs(suite_dir: Path) -> None:
    run = suite_dir / "c172p" / "bound_doublet"
    scores = check_ceiling_below_every_washout(run)
    assert list(scores) == ALL
    # the replay, planned with the whole flight known, beats every causal washout here
    assert scores["bound"] <= min(v for k, v in scores.items() if k != "bound")


def test_bound_scored_but_not_ranked_in_metrics_and_ranking(suite_dir: Path) -> None:
    for where in (suite_dir, suite_dir / "c172p" / "bound_doublet"):
        metrics = read_csv(where / "metrics.csv")
        assert [r["dof"] for r in metrics if r["washout"] == "bound"] == ["surge", "sway", "heave", "roll", "pitch",
                                                                          "yaw"]  # fmt: skip
        ranking = read_csv(where / "ranking.csv")
        bound = [r for r in ranking if r["washout"] == "bound"]
        assert len(bound) == 1 and bound[0]["rank"] == "" and math.isfinite(float(bound[0]["score"]))
        assert ranking[-1]["washout"] == "bound"
        ranks = sorted(int(r["rank"]) for r in ranking if r["washout"] != "bound")
        assert ranks[0] == 1 and max(ranks) <= len(ALL) - 1  # the six washouts ranked among themselves
    report = (suite_dir / "report.md").read_text()
    run_report = (suite_dir / "c172p" / "bound_doublet" / "report.md").read_text()
    for text in (report, run_report):
        assert "Against the ceiling" in text and "**The bracket: [" in text  # [ceiling, best achieved]
        assert "a certified lower bound on the ranking's own measure" in text
        assert "| - | bound |" in text  # no rank
    summary = report[report.index("## Summary") :].split("\n\n")[1]
    assert "bound score" in summary and summary.split("\n")[2].split("|")[6].strip() != "bound"  # never best


def test_mpc_solver_statistics_in_run_json_and_report(suite_dir: Path) -> None:
    run = suite_dir / "c172p" / "bound_doublet"
    doc = json.loads((run / "run.json").read_text())
    mpc = doc["algorithms"]["mpc"]
    assert mpc["solves"] == doc["steps"] and mpc["fallbacks"] == 0 and isinstance(mpc["fallbacks"], int)
    assert 1 <= mpc["iterations_median"] <= mpc["iterations_max"] <= 400
    assert "## Solver statistics" in (run / "report.md").read_text()


def test_cue_of_the_flight_gives_the_run_s_bound_bit_for_bit(suite_dir: Path, tmp_path: Path) -> None:
    """run cues the bound after the flight on the flight read back; cue gives the bank the whole input at once: the
    same set points, platform and costs."""
    run = suite_dir / "c172p" / "bound_doublet"
    proc = washbench("cue", run / "flight.parquet", "--out", tmp_path / "c", "--washout", "small-angle", "--washout",
                     "bound", "--no-recording", "--no-figures", "--quiet")  # fmt: skip
    assert proc.returncode == 0, proc.stdout + proc.stderr
    cued = {(r["washout"], r["dof"]): r for r in read_csv(tmp_path / "c" / "ceiling.csv")}
    ran = {(r["washout"], r["dof"]): r for r in read_csv(run / "ceiling.csv")}
    for name in ("small-angle", "bound"):
        for dof in ("score", *DOFS):
            assert cued[(name, dof)]["relative_error"] == ran[(name, dof)]["relative_error"]
            if dof != "score":  # (the score's ceiling sums the run's DOF weights: the same here, both runs)
                assert cued[(name, dof)]["ceiling"] == ran[(name, dof)]["ceiling"]
    a = pq.read_table(tmp_path / "c" / "traces.parquet", columns=["bound.pos_x_m", "bound.q_w"])
    b = pq.read_table(run / "traces.parquet", columns=["bound.pos_x_m", "bound.q_w"])
    assert a.equals(b)


def test_a_washout_below_the_ceiling_fails_the_check_and_is_flagged_in_the_report(suite_dir: Path, tmp_path: Path):
    """The check above can fail: a ceiling.csv whose ceiling is above a washout's relative error is refused, and
    the report flags a washout named in run.json's ``below_ceiling``."""
    from washbench.review.bound_section import bound_lines

    run = suite_dir / "c172p" / "bound_doublet"
    for name in ("ranking.csv", "metrics.csv"):
        (tmp_path / name).write_text((run / name).read_text())
    rows = read_csv(run / "ceiling.csv")
    lowest = min(float(r["relative_error"]) for r in rows if r["dof"] == "score")  # the bound's replay
    for r in rows:
        if r["dof"] == "score":
            r["ceiling"] = repr(lowest * 1.01)
    doc = json.loads((run / "run.json").read_text())
    doc["bound"]["below_ceiling"] = ["bound"]
    (tmp_path / "run.json").write_text(json.dumps(doc))
    with (tmp_path / "ceiling.csv").open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    with pytest.raises(AssertionError, match="beats the ceiling"):
        check_ceiling_below_every_washout(tmp_path)
    assert any("bound below the ceiling**: a defect" in line for line in bound_lines(tmp_path))


def test_mpc_failures_provoked_by_a_tiny_iteration_limit_are_counted_and_reported(suite_dir: Path, tmp_path: Path):
    """``mpc.solver.iter_limit: 1``: no solve ends (but perhaps the first); every other step falls back (the
    first step's plan continued, then braking), counted in run.json and the report; no NaN in traces.parquet, no
    platform limit reached."""
    params = tmp_path / "p.yaml"
    params.write_text(CW1 + "mpc:\n  solver: {iter_limit: 1}\n")
    out = tmp_path / "c"
    proc = washbench("cue", suite_dir / "c172p" / "bound_doublet" / "flight.parquet", "--out", out, "--washout", "mpc",
                     "--params", params, "--no-recording", "--no-figures", "--quiet")  # fmt: skip
    assert proc.returncode == 0, proc.stdout + proc.stderr
    doc = json.loads((out / "run.json").read_text())
    mpc = doc["algorithms"]["mpc"]
    # (a first step from the steady start may already be optimal after one iteration)
    assert mpc["solves"] == doc["steps"] and doc["steps"] - 1 <= mpc["fallbacks"] <= doc["steps"]
    assert 0 < mpc["brakes"] <= mpc["fallbacks"] and mpc["iterations_max"] == 1
    report = (out / "report.md").read_text()
    assert f"| mpc | {mpc['solves']} | {mpc['fallbacks']} |" in report
    assert "## Solver statistics" in report and "A fallback is a step whose solve failed" in report
    table = pq.read_table(out / "traces.parquet")
    cols = [c for c in table.column_names if c.startswith("mpc.")]
    values = np.column_stack([table.column(c).to_numpy() for c in cols])
    assert np.isfinite(values).all()
    assert not any(table.column(c).to_numpy().any() for c in cols if ".sat_" in c)  # no limit reached
    from washbench.platform.limits import load_platform_limits

    pos = np.column_stack([table.column(f"mpc.pos_{a}_m").to_numpy() for a in "xyz"])
    assert (np.abs(pos) < np.array(load_platform_limits().translation.position_limit_m.xyz)).all()


def test_sweep_and_tune_take_optimal_and_mpc_weights_as_keys(suite_dir: Path, tmp_path: Path) -> None:
    """``sweep --set optimal.pitch.position=...`` gives each point the score a ``cue`` with that value in the
    parameter file gives (two paths, one number); ``tune --tune mpc.heave.direct_force=...`` evaluates its budget and
    writes a tuned file whose value lies in the interval."""
    short = tmp_path / "m"
    short.mkdir()
    (short / "bound_doublet.yaml").write_text(SHORT)
    from washbench.cli import main  # in this process: the three commands share one start-up

    assert main(["sweep", str(short), "--from", str(suite_dir), "--washout", "optimal", "--set",
                 "optimal.pitch.position=0.1,3", "--out", str(tmp_path / "s"), "--quiet", "--jobs",
                 "1"]) == 0  # fmt: skip
    rows = read_csv(tmp_path / "s" / "sweep.csv")
    key = next(k for k in rows[0] if "position" in k)
    score_key = next(k for k in rows[0] if k.startswith("score"))
    points = {float(r[key]): float(r[score_key]) for r in rows}
    assert set(points) == {0.1, 3.0} and points[0.1] != points[3.0]
    params = tmp_path / "p.yaml"
    params.write_text(CW1 + "optimal:\n  pitch: {position: 3}\n")
    flight = suite_dir / "c172p" / "bound_doublet" / "flight.parquet"
    assert main(["cue", str(flight), "--out", str(tmp_path / "c"), "--washout", "optimal", "--params", str(params),
                 "--no-recording", "--no-figures", "--quiet"]) == 0  # fmt: skip
    score = float(read_csv(tmp_path / "c" / "ranking.csv")[0]["score"])
    assert score == pytest.approx(points[3.0], rel=1e-9)
    assert main(["tune", str(short), "--from", str(suite_dir), "--washout", "mpc", "--tune",
                 "mpc.heave.direct_force=0.5:2", "--budget", "6", "--out", str(tmp_path / "t"), "--quiet", "--jobs",
                 "1"]) == 0  # fmt: skip
    import yaml

    tuned = yaml.safe_load((tmp_path / "t" / "tuned.yaml").read_text())
    assert 0.5 <= tuned["mpc"]["heave"]["direct_force"] <= 2.0
    assert len(read_csv(tmp_path / "t" / "tune.csv")) == 6
    from washbench.cueing.variants import load_washout_params

    loaded = load_washout_params(tmp_path / "t" / "tuned.yaml")  # the file as a user's parameter file
    assert loaded.sections["mpc"]["heave"]["direct_force"] == tuned["mpc"]["heave"]["direct_force"]


def test_mpc_omct_measures_its_unconstrained_law_at_the_omct_amplitudes() -> None:
    """At the OMCT's amplitudes no constraint of the MPC binds, and a QP with no active constraint is a linear
    function of its state and input: halving the input leaves gain and phase unchanged (superposition) and the point
    is marked linear. At four times the amplitude the plan's constraints bind inside the horizon: the gain changes
    by more than 1 % (measured 0.863 to 0.834), a non-linearity that no limit flag reports (docs/optimal-mpc.md)."""
    from washbench.analysis import omct
    from washbench.cueing.variants import select_washouts
    from washbench.platform.limits import load_platform_limits
    from washbench.runs.omct import measure

    entries = select_washouts(["mpc"], (), None)
    test = next(t for t in omct.TESTS if t.name == "f_x_to_f_x")
    pts = {}
    for scale in (0.5, 1.0, 4.0):
        points, _ = measure(entries, load_platform_limits(), rate_hz=60.0, tests=[test], frequencies_radps=[1.0],
                            amplitude_scale=scale)  # fmt: skip
        pts[scale] = points[0]
    half, one, four = pts[0.5], pts[1.0], pts[4.0]
    assert one.linear and half.linear and one.saturated == ()
    assert half.gain == pytest.approx(one.gain, rel=5e-4) and half.phase_deg == pytest.approx(one.phase_deg, abs=0.01)
    assert 0.5 < one.gain < 1.0  # measured 0.863: the MPC's surge cue at 1 rad/s
    assert abs(four.gain / one.gain - 1.0) > 0.01


@pytest.mark.skipif(not (os.environ.get("WASHBENCH_BOUND_SUITE") or os.environ.get("WASHBENCH_SLOW")),
                    reason="every bundled manoeuvre: WASHBENCH_BOUND_SUITE=<suite folder> or WASHBENCH_SLOW=1 "
                    "(5-6 min on two cores; .ci/run runs it)")  # fmt: skip
def test_ceiling_below_every_washout_on_every_bundled_manoeuvre(tmp_path: Path) -> None:
    given = os.environ.get("WASHBENCH_BOUND_SUITE")
    out = Path(given) if given else None
    if out is None:
        out = tmp_path / "suite"
        proc = washbench("suite", "--out", out, "--no-recording", "--no-figures", "--quiet",
                         *[a for w in ALL for a in ("--washout", w)])  # fmt: skip
        assert proc.returncode == 0, proc.stdout + proc.stderr
    bundled = sorted(p.relative_to(MANOEUVRES_DIR).with_suffix("") for p in MANOEUVRES_DIR.rglob("*.yaml"))
    doc = json.loads((out / "suite.json").read_text())
    runs = [out / e["result"] for e in doc["manoeuvres"] if e.get("result")]
    assert len(runs) == len(bundled) == len(doc["manoeuvres"])
    for run in runs:
        scores = check_ceiling_below_every_washout(run)
        assert set(ALL) <= set(scores), run
