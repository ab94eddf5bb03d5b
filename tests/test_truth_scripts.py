"""Issue 26, JSBSim scripts through the command line (``main``): a long script is announced with its expected size
and duration and capped (``--max-time-s`` to raise it); an unknown ``--jsbsim-scripts`` name lists only scripts,
with the closest names first."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from washbench.cli import main
from washbench.flight.scripts import bundled_script, bundled_scripts, scripts_dir


def long_script(tmp_path: Path, end_s: float) -> Path:
    """JSBSim's c172_cruise_8K, its <run end> set to ``end_s`` (a long flight written here)."""
    text = bundled_script("c172_cruise_8K").read_text()
    text, n = re.subn(r'(<run start="0\.?0?" end=")[^"]*(")', rf"\g<1>{end_s:g}\g<2>", text)
    assert n == 1, "the script's <run> was not found"
    path = tmp_path / "long_cruise.xml"
    path.write_text(text)
    return path


def size_bytes(folder: Path) -> int:
    return sum(p.stat().st_size for p in folder.rglob("*") if p.is_file())


def test_a_long_script_is_announced_and_capped(tmp_path: Path, capsys, monkeypatch: pytest.MonkeyPatch) -> None:
    """The cap is lowered to 20 s here to keep the test short (the default is 1200 s): a 300 s script flies 20 s,
    says so before it starts, and the size it announced is not exceeded by the size written (nor twice it)."""
    monkeypatch.setattr("washbench.flight.scripts.DEFAULT_MAX_TIME_S", 20.0)
    script = long_script(tmp_path, 300)
    out = tmp_path / "out"
    assert main(["run", str(script), "--out", str(out), "--quiet"]) == 0
    err = capsys.readouterr().err
    m = re.search(r"washbench: long_cruise: flying 20 s simulated \(2,400 steps of 0.0083333 s\): up to about ([\d.]+) "
                  r"MB of results and .* \(estimated\); the script runs 5 min 00 s \(300 s\): stopped at the default "
                  r"cap of 20 s, --max-time-s 300 flies it all \(up to about ([\d.]+) MB\)", err)  # fmt: skip
    assert m, err
    folder = out / "c172x" / "long_cruise"
    doc = json.loads((folder / "flight.json").read_text())
    assert doc["stopped_by_time_limit"] and doc["duration_s"] == pytest.approx(20.0, abs=0.02)
    announced, written = float(m.group(1)) * 1e6, size_bytes(folder)
    assert 0.5 < written / announced < 1.1, (written, announced)
    assert float(m.group(2)) == pytest.approx(15 * float(m.group(1)), rel=0.1)


def test_a_script_within_the_cap_flies_to_its_end_without_a_word(tmp_path: Path, capsys) -> None:
    script = long_script(tmp_path, 3)
    assert main(["run", str(script), "--out", str(tmp_path / "o"), "--quiet", "--no-recording", "--no-figures"]) == 0
    assert "flying" not in capsys.readouterr().err
    doc = json.loads((tmp_path / "o" / "c172x" / "long_cruise" / "flight.json").read_text())
    assert not doc["stopped_by_time_limit"]


def test_unknown_script_names_get_the_closest_scripts(tmp_path: Path, capsys) -> None:
    assert main(["suite", "--jsbsim-scripts", "c1732", "--out", str(tmp_path / "a")]) == 2
    err = capsys.readouterr().err
    assert "--jsbsim-scripts: no script 'c1732' ships with JSBSim; did you mean c1724, c1723, c1722?" in err
    assert main(["suite", "--jsbsim-scripts", "plotfile", "--out", str(tmp_path / "a")]) == 2
    err = capsys.readouterr().err
    assert "'plotfile' ships with JSBSim but is not a script (no <runscript>)" in err
    assert main(["suite", "--jsbsim-scripts", "zzz", "--out", str(tmp_path / "a")]) == 2
    listed = capsys.readouterr().err.split(" scripts: ")[1].strip().split(", ")
    xml = sorted(scripts_dir().glob("*.xml"))
    roots = {p.stem for p in xml if "<runscript" in p.read_text(errors="replace")}
    assert listed == sorted(roots) == bundled_scripts()
    assert "plotfile" not in listed and "unitconversions" not in listed and len(listed) < len(xml)
