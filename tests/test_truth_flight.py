"""Issue 26: manoeuvre files that used to fly or validate wrongly without a word, driven through the command line.

- an ``amplitude_deg`` beyond a surface's travel (the c172p rudder stops at +-16 deg, its pilot profile's
  ``surfaces``, copied from the model's flight-control system): refused when the file is loaded where no base can
  fit it, else flown with the time clipped at the stop reported as a failed check in flight.json;
- ``aircraft: 737`` (a number where text is expected): a hint to quote it.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from flight_helpers import write

from washbench.cli import main
from washbench.flight.scripts import bundled_script

RUDDER = """\
    name: rudder_kick
    aircraft: c172p
    start:
      air: {{altitude_ft: 4000, airspeed_kts: 95, heading_deg: 90}}
    phases:
      - name: settle
        hold: {{wings_level: true, altitude_ft: 4000, airspeed_kts: 95}}
        until: {{duration_s: 1}}
      - name: kick
        hold: {{altitude_ft: 4000, airspeed_kts: 95}}
        inputs:
          rudder: {{shape: {shape}, amplitude_deg: {amp}, start_s: 0.5{extra}, free: true}}
        until: {{duration_s: 2}}
"""


def test_a_doublet_wider_than_the_whole_rudder_travel_is_refused_at_load(tmp_path: Path, capsys) -> None:
    f = write(tmp_path, "kick.yaml", RUDDER.format(shape="doublet", amp=30, extra=", duration_s: 1.0"))
    assert main(["validate", str(f)]) == 2
    err = capsys.readouterr().err
    assert "kick.yaml:12: phases[1].inputs.rudder.amplitude_deg:" in err
    assert "swings 60 deg, more than the whole surface travel -15.997..15.997 deg" in err


def test_a_step_past_the_stop_flies_and_reports_the_clipped_time(tmp_path: Path, capsys) -> None:
    """A +20 deg step from the trimmed rudder (about 0 deg) asks 20 deg of a 16 deg travel from 0.5 s to the phase
    end (1.5 s = 180 steps at 120 Hz): the flight fails a check measuring 1.5 s clipped."""
    f = write(tmp_path, "kick.yaml", RUDDER.format(shape="step", amp=20, extra=""))
    assert main(["validate", str(f)]) == 0  # 20 deg fits the 32 deg travel from some base: known only in flight
    out = tmp_path / "out"
    assert main(["fly", str(f), "--out", str(out), "--quiet"]) == 1
    doc = json.loads((out / "flight.json").read_text())
    (check,) = [c for c in doc["checks"] if "travel" in c["name"]]
    assert check["name"] == "rudder input within its travel in 'kick'" and not check["passed"]
    assert check["measured"] == pytest.approx(1.5, abs=1.5 / 120)
    assert doc["status"] == "failed" and "clipped at the stop" in doc["reason"]
    assert "failed, 0/1 checks passed" in capsys.readouterr().out


def test_a_step_within_the_travel_is_flown_as_asked(tmp_path: Path) -> None:
    f = write(tmp_path, "kick.yaml", RUDDER.format(shape="step", amp=10, extra=""))
    out = tmp_path / "out"
    assert main(["fly", str(f), "--out", str(out), "--quiet"]) == 0
    assert json.loads((out / "flight.json").read_text())["checks"] == []


def test_a_number_where_text_is_expected_gets_the_hint_to_quote_it(tmp_path: Path, capsys) -> None:
    text = RUDDER.format(shape="step", amp=10, extra="").replace("aircraft: c172p", "aircraft: 737")
    f = write(tmp_path, "m.yaml", text)
    assert main(["validate", str(f)]) == 2
    err = capsys.readouterr().err
    assert "m.yaml:2: aircraft: expected text, got 737 (write it in quotes: '737')" in err


def test_validate_takes_what_suite_takes_and_reports_every_independent_mistake(tmp_path: Path, capsys) -> None:
    """A folder holding a good manoeuvre, a JSBSim script (read as a script, not as YAML) and a manoeuvre with three
    independent mistakes in two phases and a check: every file checked, every mistake reported with its line."""
    folder = tmp_path / "mine"
    folder.mkdir()
    write(folder, "good.yaml", RUDDER.format(shape="step", amp=10, extra=""))
    bad = RUDDER.format(shape="doublet", amp=3, extra="") + """\
      - name: again
        hold: {altitude_ft: 4000, airspeed_kts: 95}
        inputs:
          aileron: {shape: pulse, amplitude_deg: 2, free: true}
        until: {duration_s: 2}
    checks:
      - {name: yaw, signal: omega_r_degps, stat: max, max: 5}
    """
    write(folder, "bad.yaml", bad)
    (folder / "cruise.xml").write_text(bundled_script("c172_cruise_8K").read_text())
    (folder / "notes.xml").write_text("<notes>not a script: skipped in a folder</notes>\n")
    assert main(["validate", str(folder)]) == 2
    out, err = capsys.readouterr()
    assert sorted(out.splitlines()) == sorted([f"{folder / 'cruise.xml'}: OK", f"{folder / 'good.yaml'}: OK"])
    problems = [ln for ln in err.splitlines() if ln.startswith("washbench: error:")]
    assert len(problems) == 3, err
    assert "bad.yaml:12: phases[1].inputs.rudder.shape: a doublet needs 'duration_s'" in problems[0]
    assert "bad.yaml:17: phases[2].inputs.aileron.shape: a pulse needs 'duration_s'" in problems[1]
    assert "bad.yaml:20: checks[0].signal: unknown signal 'omega_r_degps' (did you mean 'omega_z_" in problems[2]
    assert main(["validate", str(folder / "cruise.xml")]) == 0  # a script named directly: not read as YAML
    broken = folder / "broken.xml"
    broken.write_text("<runscript>\n  <use aircraft='c172x'/>\n</runscript>\n")
    assert main(["validate", str(broken)]) == 2
    assert "broken.xml: <run> is missing" in capsys.readouterr().err

