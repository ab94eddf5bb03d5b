"""``--help`` teaches: every command's help ends with two or three examples that the real parser accepts, and the
top-level help names the documentation."""

from __future__ import annotations

import shlex
import subprocess
import sys
from pathlib import Path

import pytest

from washbench.cli import build_parser
from washbench.cli_examples import EXAMPLES, subcommands

COMMANDS = sorted(subcommands(build_parser()))


def _washbench_parts(line: str) -> list[list[str]]:
    """The ``washbench ...`` commands of an example line (split at ``&&`` and ``|``), as argv lists."""
    parts = []
    for chunk in line.replace("&&", "|").split("|"):
        words = shlex.split(chunk)
        if words and words[0] == "washbench":
            parts.append(words[1:])
    return parts


def test_every_command_has_examples() -> None:
    assert set(EXAMPLES) == set(COMMANDS)
    assert all(2 <= len(lines) <= 3 for lines in EXAMPLES.values())


@pytest.mark.parametrize("command", COMMANDS)
def test_examples_parse_and_end_the_help(command: str, capsys: pytest.CaptureFixture[str]) -> None:
    parser = build_parser()
    for line in EXAMPLES[command]:
        argv_list = _washbench_parts(line)
        assert argv_list and argv_list[0][0] == command, line
        for argv in argv_list:
            args = parser.parse_args(argv)  # a usage error exits 2 and fails the test
            assert args.command == argv[0]
    with pytest.raises(SystemExit) as info:
        parser.parse_args([command, "--help"])
    assert info.value.code == 0
    out = capsys.readouterr().out
    tail = out.rstrip().splitlines()[-len(EXAMPLES[command]) :]
    assert [t.strip() for t in tail] == list(EXAMPLES[command])  # the last lines, unwrapped
    assert "examples:" in out


def test_top_level_help_names_the_docs() -> None:
    proc = subprocess.run([sys.executable, "-m", "washbench", "--help"], capture_output=True, text=True, check=True)
    assert "docs/tutorial/getting-started.md" in proc.stdout
    assert "docs/reference/commands.md" in proc.stdout


RUN_AS_WRITTEN = [("validate", 0), ("examples", 0), ("examples", 1), ("run", 2)]
"""Examples that need no file of the user's: each must work as written, in a shell, in an empty folder (the
first example of ``validate --help`` named ``manoeuvres/*.yaml``, which is nowhere: issue 38, item 6; ``run``'s
JSBSim script by name was "no such file": issue 52, item 9)."""


@pytest.mark.parametrize(("command", "index"), RUN_AS_WRITTEN)
def test_examples_that_need_no_file_of_yours_run_as_written(command: str, index: int, tmp_path: Path) -> None:
    line = EXAMPLES[command][index]
    washbench = f"{shlex.quote(sys.executable)} -m washbench"
    script = " ".join(washbench if word == "washbench" else word for word in line.split(" "))
    proc = subprocess.run(["bash", "-c", script], cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, (line, proc.stderr)
    assert "Traceback" not in proc.stderr
