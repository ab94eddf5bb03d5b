"""The command-line front end: sub-commands exist and usage errors are one line."""

import subprocess
import sys


def run(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "washbench", *args], capture_output=True, text=True)


def test_help_lists_every_subcommand() -> None:
    out = run("--help")
    assert out.returncode == 0
    for name in ("cue", "fly", "validate", "schema", "run", "suite", "report", "replay"):
        assert name in out.stdout


def test_unknown_subcommand_is_one_line_exit_2() -> None:
    out = run("fluy")
    assert out.returncode == 2
    assert "Traceback" not in out.stderr
    assert len(out.stderr.strip().splitlines()) == 1
