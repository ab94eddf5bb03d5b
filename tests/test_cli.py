"""The command-line front end: sub-commands exist and usage errors are one line."""

import os
import subprocess
import sys

from washbench.runs.beside import NO_BESIDE_ENV


def run(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "washbench", *args], capture_output=True, text=True)


def test_help_lists_every_subcommand() -> None:
    out = run("--help")
    assert out.returncode == 0
    for name in ("cue", "fly", "validate", "schema", "run", "suite", "report", "replay", "live", "send"):
        assert name in out.stdout


def test_unknown_subcommand_is_one_line_exit_2() -> None:
    out = run("fluy")
    assert out.returncode == 2
    assert "Traceback" not in out.stderr
    assert len(out.stderr.strip().splitlines()) == 1


SHORT_FLIGHT = """\
name: short
aircraft: c172p
start:
  air: {altitude_ft: 4000, airspeed_kts: 95, heading_deg: 90}
phases:
  - name: level
    hold: {wings_level: true, altitude_ft: 4000, airspeed_kts: 95}
    until: {duration_s: 1}
checks:
  - {name: altitude held, signal: altitude_ft, stat: max_deviation, max: 60}
"""

HEAVY = ("scipy.linalg", "scipy.signal", "scipy.stats", "scipy.spatial", "rerun.", "rerun_sdk", "matplotlib.")


def imported_by(args: list[str]) -> set[str]:
    """The heavy packages a washbench command imports (it runs in a fresh interpreter), all in one process: the
    figures are not drawn in a child beside the recording (washbench.runs.beside), where their imports would not
    be seen here (the child's are the command's, forked)."""
    code = (
        "import sys, contextlib, io\n"
        "from washbench.cli import main\n"
        "with contextlib.redirect_stdout(io.StringIO()):\n"
        f"    status = main({args!r})\n"
        f"print(status, *sorted({{'.'.join(m.split('.')[:2 if m.startswith('scipy.') else 1])"
        f" for m in sys.modules if m.startswith({HEAVY!r}) or m in ('rerun', 'matplotlib')}}))\n"
    )
    env = {**os.environ, NO_BESIDE_ENV: "1"}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300, env=env)
    assert out.returncode == 0, out.stderr
    status, *names = out.stdout.split()
    assert status == "0", out.stdout
    return set(names)


def test_commands_import_only_what_they_need(tmp_path) -> None:
    # start-up cost: scipy.signal/stats (about 0.7 s), scipy.linalg (0.3 s, numba's BLAS probe) and rerun (0.4 s)
    (tmp_path / "m.yaml").write_text(SHORT_FLIGHT)
    lines = ["t_s,f_x_mps2,f_y_mps2,f_z_mps2,omega_x_degps,omega_y_degps,omega_z_degps"]
    lines += [f"{k / 120.0!r},0.1,0.0,-9.80665,1.0,0.0,0.0" for k in range(60)]
    (tmp_path / "in.csv").write_text("\n".join(lines) + "\n")
    # and matplotlib (0.5 s) only for figures
    assert imported_by(["validate", str(tmp_path / "m.yaml")]) == set()
    cue = ["cue", str(tmp_path / "in.csv"), "--out", str(tmp_path / "cue"), "--no-recording"]
    assert imported_by(cue) == {"matplotlib"}
    assert imported_by([*cue, "--no-figures"]) == set()
    no_rec = ["run", str(tmp_path / "m.yaml"), "--out", str(tmp_path / "r1"), "--quiet", "--no-recording"]
    assert imported_by([*no_rec, "--no-figures"]) == set()
    assert imported_by(no_rec) == {"matplotlib"}
    assert imported_by(["run", str(tmp_path / "m.yaml"), "--out", str(tmp_path / "r2"), "--quiet"]) == {
        "rerun", "matplotlib"
    }  # fmt: skip


def test_hints_a_new_user_expects(tmp_path, capsys) -> None:
    """Issue 52, item 10: one line each, naming what was meant: an option misspelt (``--output``), washouts given as
    one list, a manoeuvre file given to ``cue`` (``run`` flies it), a Python file given to ``--platform``."""
    from washbench.cli import main
    from washbench.io.paths import MANOEUVRES_DIR

    manoeuvre = MANOEUVRES_DIR / "c172" / "takeoff.yaml"
    cases = [
        (["suite", "--output", "r"], "the following arguments are required: --out (--output: did you mean --out?)"),
        (["run", "c172/takeoff", "--out", "r", "--output", "x"], "(--output: did you mean --out?)"),
        (["run", "c172/takeoff", "--out", str(tmp_path / "r"), "--washout", "small-angle,large-angle"],
         "--washout small-angle,large-angle: one washout per --washout; repeat it: --washout small-angle --washout "
         "large-angle"),
        (["cue", str(manoeuvre), "--out", str(tmp_path / "c")],
         f"{manoeuvre}: a manoeuvre file, which cue does not read (cue takes a recorded trace: CSV, Parquet, X-Plane "
         f"Data.txt, JSBSim CSV); fly it with the washouts: washbench run {manoeuvre} --out DIR"),
        (["cue", "c172/takeoff", "--out", str(tmp_path / "c")], "c172/takeoff: a bundled manoeuvre's name"),
        (["run", "c172/steep_trun", "--out", str(tmp_path / "r")], "did you mean c172/steep_turn?"),
        (["run", "c172/takeoff", "--out", str(tmp_path / "r"), "--platform", "mywork/box.py"],
         "load a plugin with --platform-plugin mywork/box.py:CLASS"),
    ]  # fmt: skip
    for argv, expected in cases:
        try:
            status = main(argv)
        except SystemExit as exc:  # argparse's usage errors
            status = exc.code
        err = capsys.readouterr().err.strip().splitlines()
        assert status == 2 and len(err) == 1 and expected in err[0], (argv, err)
    assert not (tmp_path / "r").exists() and not (tmp_path / "c").exists()
