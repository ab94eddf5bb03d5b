"""``washbench run SCRIPT.xml``: JSBSim's own bundled scripts flown in place with the washouts in lockstep.

Four scripts: the AH-1S helicopter, the 737 in a steady turn, the C172 cruise that resets twice (three run
segments) and the F-16 test that flies into the ground at about 128 s (a crash, the data up to it kept).
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import inprocess
import jsbsim
import numpy as np
import pyarrow.parquet as pq
import pytest

from washbench.cueing.variants import DEFAULT_WASHOUTS
from washbench.errors import WashbenchError
from washbench.flight.scripts import bundled_script, load_script_info
from washbench.io.metrics_csv import read_metrics_csv
from washbench.runs.cue import run_cue
from washbench.runs.options import load_options
from washbench.runs.outputs import Outputs
from washbench.runs.pipeline import run_script

FILES = ["figures", "flight.json", "flight.parquet", "metrics.csv", "ranking.csv", "recording.rrd", "report.md",
         "run.json", "traces.parquet"]  # fmt: skip


@pytest.fixture(scope="module")
def out(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("scripts")


@pytest.fixture(scope="module")
def runs(out: Path) -> dict[str, list]:
    return {
        "ah1s_flight_test": run_script(bundled_script("ah1s_flight_test"), out, load_options(max_time_s=6.0)),
        "737_cruise_steady_turn": run_script(
            bundled_script("737_cruise_steady_turn"), out, load_options(max_time_s=4.0)
        ),
        "c172_cruise_8K": run_script(bundled_script("c172_cruise_8K"), out, load_options(max_time_s=52.0)),
        "f16_test": run_script(bundled_script("f16_test"), out, load_options(max_time_s=140.0)),
    }


@pytest.mark.parametrize(("name", "aircraft"), [("ah1s_flight_test", "ah1s"), ("737_cruise_steady_turn", "737")])
def test_one_run_gives_a_full_result_folder(name: str, aircraft: str, runs: dict[str, list], out: Path) -> None:
    (s,) = runs[name]
    folder = out / aircraft / name
    assert s.ok and s.run_dir == folder
    assert sorted(p.name for p in folder.iterdir()) == FILES
    flight = json.loads((folder / "flight.json").read_text())
    assert flight["aircraft"] == aircraft and flight["status"] == "ok" and flight["stopped_by_time_limit"]
    dt = flight["dt_s"]
    assert dt == load_script_info(bundled_script(name)).dt_s  # the script's own step
    t = pq.read_table(folder / "flight.parquet").column("t_s").to_numpy()
    assert np.array_equal(t, np.arange(len(t)) * dt)  # t = k * dt
    rows = read_metrics_csv(folder / "metrics.csv")
    assert len(rows) == 6 * len(DEFAULT_WASHOUTS) and all(r.integral_error >= 0 for r in rows)
    with (folder / "ranking.csv").open() as f:
        assert [r["washout"] for r in csv.DictReader(f)] != []


def test_run_equals_cue_of_its_flight(runs: dict[str, list], out: Path, tmp_path: Path) -> None:
    """As for manoeuvres: cueing flight.parquet gives the lockstep run's metrics bit for bit."""
    folder = out / "ah1s" / "ah1s_flight_test"
    assert run_cue(folder / "flight.parquet", tmp_path / "cue", run=load_options(outputs=Outputs(recording=False))) == 0
    assert (tmp_path / "cue" / "metrics.csv").read_bytes() == (folder / "metrics.csv").read_bytes()


def test_a_script_that_resets_gives_one_result_per_run(runs: dict[str, list], out: Path) -> None:
    segs = runs["c172_cruise_8K"]
    folder = out / "c172x" / "c172_cruise_8K"
    assert [s.manoeuvre for s in segs] == [f"c172_cruise_8K/run_{i}" for i in (1, 2, 3)]
    assert sorted(p.name for p in folder.iterdir()) == ["run_1", "run_2", "run_3"]
    tables = [pq.read_table(folder / f"run_{i}" / "flight.parquet") for i in (1, 2, 3)]
    # the script resets at 25 s: two whole runs (the sample before each reset dropped), then 2 s of the third
    dt = segs[0].dt_s
    assert [t.num_rows for t in tables[:2]] == [round(25.0 / dt), round(25.0 / dt)]
    assert tables[2].num_rows == pytest.approx(2.0 / dt, abs=3)  # the time limit counts the reset steps too
    for t in tables:  # each run starts at t = 0 from the same initial conditions (reset01: 4000 ft)
        assert t.column("t_s")[0].as_py() == 0.0
        assert t.column("altitude_ft")[0].as_py() == pytest.approx(tables[0].column("altitude_ft")[0].as_py())
    # run 2 flies 36 K colder (its script sets delta-T by run_id): a different flight
    assert not np.array_equal(tables[0].column("f_x_mps2").to_numpy(), tables[1].column("f_x_mps2").to_numpy())
    for s in segs:
        assert s.ok and (s.run_dir / "recording.rrd").is_file() and len(s.metrics) == 6 * len(DEFAULT_WASHOUTS)


def test_reset_count_matches_jsbsim(tmp_path: Path) -> None:
    """Independently: JSBSim's own loop, counting time jumping back, sees the same two resets."""
    fdm = jsbsim.FGFDMExec(jsbsim.get_default_root_dir(), None)
    fdm.set_debug_level(0)
    fdm.set_output_path(str(tmp_path))  # the script's output files are opened at load: not in the package
    fdm.load_script(str(bundled_script("c172_cruise_8K")))
    fdm.disable_output()
    fdm.run_ic()
    resets, prev = 0, fdm.get_sim_time()
    for _ in range(round(52.0 / fdm.get_delta_t())):  # the same 52 s of simulated steps as the run above
        fdm.run()
        if fdm.get_sim_time() < prev:
            resets += 1
        prev = fdm.get_sim_time()
    assert resets == 2 and fdm["simulation/run_id"] == 2


def test_f16_flies_into_the_ground_and_is_reported_as_a_crash(runs: dict[str, list], out: Path) -> None:
    (s,) = runs["f16_test"]
    assert not s.ok and "the airframe touched the ground" in s.reason
    crash_t = float(s.reason.split("t=")[1].split(" s")[0])
    assert 120.0 < crash_t < 135.0
    folder = out / "f16" / "f16_test"
    flight = json.loads((folder / "flight.json").read_text())
    assert flight["status"] == "failed" and not flight["stopped_by_time_limit"]
    t = pq.read_table(folder / "flight.parquet").column("t_s").to_numpy()
    assert t[-1] == pytest.approx(crash_t - s.dt_s, abs=0.006)  # kept up to the crash (reason: 2 decimals)
    run = json.loads((folder / "run.json").read_text())
    assert run["ok"] is False and "FAILED" in (folder / "report.md").read_text()


def test_cli_suite_with_bundled_scripts(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """``washbench suite --jsbsim-scripts NAME ...`` (in this process, one job: the CLI path without a pool)."""
    from washbench.cli import main

    argv = ["suite", "--jsbsim-scripts", "c1723", "737_cruise_steady_turn", "--max-time-s", "3", "--jobs", "1"]
    assert main([*argv, "--out", str(tmp_path / "s"), "--quiet"]) == 0
    with (tmp_path / "s" / "ranking.csv").open() as f:
        assert sorted({r["manoeuvre"] for r in csv.DictReader(f)}) == ["737_cruise_steady_turn", "c1723"]
    assert "c1723" in (tmp_path / "s" / "report.md").read_text()
    capsys.readouterr()
    assert main(["suite", "--jsbsim-scripts", "c9999", "--out", str(tmp_path / "b")]) == 2
    err = capsys.readouterr().err
    assert "no script 'c9999' ships with JSBSim; the " in err and "scripts: 737_cruise" in err
    assert len(err.strip().splitlines()) == 1


def test_bad_scripts_are_one_line(tmp_path: Path) -> None:
    p = tmp_path / "broken.xml"
    p.write_text('<runscript name="x">\n  <use aircraft="c172x" initialize="reset00"/>\n  <run start="0" end="5">\n')
    with pytest.raises(WashbenchError, match=r"broken\.xml:4: not well-formed XML"):
        load_script_info(p)
    p.write_text('<runscript>\n  <use aircraft="nope" initialize="reset00"/>\n  <run start="0" end="5" dt="0.01"/>\n'
                 "</runscript>\n")  # fmt: skip
    with pytest.raises(WashbenchError, match=r"<use aircraft='nope'>: unknown aircraft"):
        run_script(p, tmp_path / "out")
    assert not (tmp_path / "out").exists()
    p.write_text("<fdm_config/>\n")
    with pytest.raises(WashbenchError, match="not a JSBSim script: the root element is <fdm_config>"):
        load_script_info(p)


def test_a_script_that_sets_an_output_property_flies_as_plain_jsbsim(tmp_path: Path) -> None:
    """Issue 38, item 2: JSBSim's ``c1723.xml`` sets ``simulation/output/log_rate_hz`` in an event (a property its
    aircraft's ``<output>`` creates). washbench neutralises the directive instead of removing it: the script flies
    to the same end, step for step, as plain JSBSim (run here in a scratch folder), and writes no CSV of JSBSim's."""
    script = bundled_script("c1723")
    plain = jsbsim.FGFDMExec(str(jsbsim.get_default_root_dir()), None)
    plain.set_debug_level(0)
    plain.set_output_path(str(tmp_path / "plain"))
    (tmp_path / "plain").mkdir()
    assert plain.load_script(str(script))
    plain.run_ic()
    steps = 0
    while plain.run():
        steps += 1
    assert plain.get_property_value("simulation/output/log_rate_hz") == 10.0  # the event did set it

    work = tmp_path / "work"
    work.mkdir()
    proc = inprocess.washbench("run", script, "--out", work / "out", "--no-recording", "--no-figures", "--quiet",
                               timeout=120, cwd=work)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert "Traceback" not in proc.stderr and "No property" not in proc.stderr
    flight = json.loads((work / "out" / "c172x" / "c1723" / "flight.json").read_text())
    assert flight["status"] == "ok"
    t = pq.read_table(work / "out" / "c172x" / "c1723" / "flight.parquet").column("t_s").to_numpy()
    # the same run to within JSBSim's last step or two (when run() says False; t = k * dt from 0 here)
    assert t[-1] == pytest.approx(plain.get_sim_time(), abs=2.5 * flight["dt_s"])
    assert abs(len(t) - steps) <= 2
    assert not list(work.rglob("*.csv")) or all("out" in p.relative_to(work).parts for p in work.rglob("*.csv"))


def test_a_script_event_jsbsim_cannot_do_is_a_failed_run_not_a_traceback(tmp_path: Path) -> None:
    """JSBSim's ``737_cruise_steady_turn_simplex.xml`` sets ``simulation/do_simplex_trim``, which this JSBSim build
    lacks: plain JSBSim raises from ``run()`` at 0.1 s. washbench keeps what was flown and says why, in one line."""
    (s,) = run_script(bundled_script("737_cruise_steady_turn_simplex"), tmp_path, load_options(max_time_s=2.0))
    assert not s.ok
    assert "JSBSim stopped the script" in s.reason and "simulation/do_simplex_trim" in s.reason
    assert "\n" not in s.reason
    flight = json.loads((tmp_path / "737" / "737_cruise_steady_turn_simplex" / "flight.json").read_text())
    assert flight["status"] == "failed"
