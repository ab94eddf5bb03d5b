"""The project configuration file (washbench.io.config), driven through the real ``washbench`` command.

Each test writes a small project into a temporary folder and runs ``python -m washbench`` there (subprocess, with
that folder as the working directory): defaults from ``washbench.toml`` or ``[tool.washbench]`` in ``pyproject.toml``
found upwards, a flag on the command line winning, the file recorded in the provenance, and bad keys or values as
one line naming file, line and key with exit status 2.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import shutil
import subprocess
from pathlib import Path

import inprocess
import pytest

from washbench.cli import _config_defaults, build_parser
from washbench.io.config import discover
from washbench.io.paths import AIRCRAFT_DIR, DATA_DIR, MANOEUVRES_DIR
from washbench.io.provenance import sha256_file

REPO = Path(__file__).resolve().parents[1]


def washbench(cwd: Path, *args: str) -> subprocess.CompletedProcess[str]:
    env = dict(os.environ, PYTHONPATH=str(REPO) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    env.pop("WASHBENCH_AIRCRAFT_PATH", None)
    env.pop("WASHBENCH_CONFIG_USED", None)
    return inprocess.washbench(*args, cwd=cwd, env=env, timeout=300)


def small_csv(path: Path) -> Path:
    rows = ["t_s,f_x_mps2,f_y_mps2,f_z_mps2,omega_x_degps,omega_y_degps,omega_z_degps"]
    for k in range(360):
        t = k / 120
        rows.append(f"{t!r},{0.5 * math.sin(t)!r},0.0,-9.80665,{3 * math.sin(2 * t)!r},0.0,0.0")
    path.write_text("\n".join(rows) + "\n")
    return path


def one_error_line(proc: subprocess.CompletedProcess[str]) -> str:
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in proc.stderr, proc.stderr
    return lines[0]


def test_defaults_from_washbench_toml_found_upwards_and_a_flag_wins(tmp_path: Path) -> None:
    project = tmp_path / "study"
    (project / "params").mkdir(parents=True)
    (project / "logs").mkdir()
    mine = (DATA_DIR / "cw1.yaml").read_text().replace("name: CW1", "name: MY-CW", 1)
    assert "MY-CW" in mine
    (project / "params" / "my_cw.yaml").write_text(mine)
    config = project / "washbench.toml"
    config.write_text('# the study\nparams = "params/my_cw.yaml"\nout = "results"\n')
    small_csv(project / "logs" / "small.csv")
    # run from a subfolder: the file is found upwards; its paths are relative to its own folder
    proc = washbench(project / "logs", "cue", "small.csv", "--no-recording", "--no-figures")
    assert proc.returncode == 0, proc.stderr
    run = json.loads((project / "results" / "run.json").read_text())
    prov = run["provenance"]
    assert prov["params"]["name"] == "MY-CW"
    assert prov["config"] == {"path": str(config), "sha256": sha256_file(config)}
    # and in the report, as docs/how-to/configuration.md says (issue 38, item 5)
    digest = hashlib.sha256(config.read_bytes()).hexdigest()
    report = (project / "results" / "report.md").read_text()
    assert f"| configuration file | `{config}` (SHA-256 `{digest}`) |" in report
    # a flag wins over the file
    proc = washbench(
        project / "logs", "cue", "small.csv", "--out", "here", "--params", str(DATA_DIR / "cw1.yaml"),
        "--no-recording", "--no-figures",
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    prov = json.loads((project / "logs" / "here" / "run.json").read_text())["provenance"]
    assert prov["params"]["name"] == "CW1" and prov["config"]["path"] == str(config)


def test_no_config_no_record(tmp_path: Path) -> None:
    small_csv(tmp_path / "small.csv")
    proc = washbench(tmp_path, "cue", "small.csv", "--out", "r", "--no-recording", "--no-figures")
    assert proc.returncode == 0, proc.stderr
    assert "config" not in json.loads((tmp_path / "r" / "run.json").read_text())["provenance"]


def test_out_is_still_required_without_a_config(tmp_path: Path) -> None:
    proc = washbench(tmp_path, "cue", "x.csv")
    assert proc.returncode == 2 and "--out" in proc.stderr


def test_aircraft_dir_from_pyproject_tool_table(tmp_path: Path) -> None:
    project = tmp_path / "proj"
    models = project / "models"
    shutil.copytree(AIRCRAFT_DIR / "columbia400", models / "mycolumbia")
    (models / "mycolumbia" / "columbia400.xml").rename(models / "mycolumbia" / "mycolumbia.xml")
    text = (MANOEUVRES_DIR / "columbia400" / "stall_recovery.yaml").read_text()
    (project / "my_stall.yaml").write_text(text.replace("aircraft: columbia400", "aircraft: mycolumbia"))
    # without the table, the aircraft is unknown (models/ is not a folder washbench searches by itself)
    (project / "pyproject.toml").write_text('[project]\nname = "study"\n')
    proc = washbench(project, "validate", "my_stall.yaml")
    assert "unknown aircraft 'mycolumbia'" in one_error_line(proc)
    (project / "pyproject.toml").write_text('[project]\nname = "study"\n\n[tool.washbench]\naircraft-dir = "models"\n')
    proc = washbench(project, "validate", "my_stall.yaml")
    assert proc.returncode == 0, proc.stderr


@pytest.mark.parametrize(
    ("name", "text", "expected"),
    [
        (
            "washbench.toml",
            'out = "r"\nparms = "cw.yaml"\n',
            "washbench.toml:2: parms: unknown key (did you mean 'params'?)",
        ),
        (
            "pyproject.toml",
            '[project]\nname = "x"\n\n[tool.washbench]\nout = "r"\njobs = 0\n',
            "pyproject.toml:6: tool.washbench.jobs: expected a whole number of at least 1 process, got 0",
        ),
        ("washbench.toml", 'jobs = "four"\n', "washbench.toml:1: jobs: expected a whole number of at least 1 process"),
        ("washbench.toml", '\nparams = "missing.yaml"\n', "washbench.toml:2: params: no such file"),
        ("washbench.toml", 'aircraft-dir = ["nowhere"]\n', "washbench.toml:1: aircraft-dir: no such folder"),
        ("washbench.toml", "out = \n", "washbench.toml:1: not valid TOML"),
    ],
)
def test_bad_key_or_value_is_one_line_naming_file_line_and_key(
    tmp_path: Path, name: str, text: str, expected: str
) -> None:
    (tmp_path / name).write_text(text)
    small_csv(tmp_path / "small.csv")
    line = one_error_line(washbench(tmp_path, "cue", "small.csv", "--out", "r"))
    assert line.startswith("washbench: error: " + str(tmp_path / expected.split(":", 1)[0]))
    assert expected.split(":", 1)[1] in line
    assert not (tmp_path / "r").exists()  # nothing written


def test_jobs_and_precedence_in_one_folder(tmp_path: Path) -> None:
    """washbench.toml wins over pyproject.toml in the same folder; --jobs on the command line wins over both."""
    (tmp_path / "pyproject.toml").write_text("[tool.washbench]\njobs = 5\n")
    (tmp_path / "washbench.toml").write_text('jobs = 3\nout = "suite-out"\n')
    config = discover(tmp_path)
    assert config is not None and config.path == tmp_path / "washbench.toml"
    parser = build_parser()
    _config_defaults(parser, config)
    args = parser.parse_args(["suite"])
    assert args.jobs == 3 and args.out == tmp_path / "suite-out"
    assert parser.parse_args(["suite", "--jobs", "1", "--out", "x"]).jobs == 1
    # a pyproject.toml without the table is passed over on the way up
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "pyproject.toml").write_text('[project]\nname = "x"\n')
    found = discover(tmp_path / "sub")
    assert found is not None and found.path == tmp_path / "washbench.toml"


def test_a_bundled_platform_by_name(tmp_path: Path) -> None:
    """Issue 52, item 5: the file's ``platform`` takes the bundled names ``--platform`` takes (a file beside the
    configuration of that name would win)."""
    (tmp_path / "washbench.toml").write_text('platform = "rig2dof"\nout = "r"\n')
    small_csv(tmp_path / "small.csv")
    proc = washbench(tmp_path, "cue", "small.csv", "--no-recording", "--no-figures")
    assert proc.returncode == 0, proc.stderr
    prov = json.loads((tmp_path / "r" / "run.json").read_text())["provenance"]
    assert prov["platform"]["path"] == "washbench:data/rig2dof.yaml"
    (tmp_path / "washbench.toml").write_text('platform = "rig3"\nout = "r"\n')
    line = one_error_line(washbench(tmp_path, "cue", "small.csv"))
    assert "washbench.toml:1: platform: no such file" in line and "nor a bundled name (atlas, hexapod, rig2dof)" in line
