"""Helpers for the hardening tests: the real command under a time limit, and what a clean failure looks like."""

from __future__ import annotations

import atexit
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import inprocess

#: A short level flight (one phase of ``{seconds}`` s); ``{name}`` and ``{extra}`` (top-level lines) vary.
SHORT = """\
name: {name}
aircraft: c172p
{extra}start:
  air: {{altitude_ft: 3000, airspeed_kts: 90, heading_deg: 360}}
phases:
  - name: level
    hold: {{wings_level: true, altitude_ft: 3000, airspeed_kts: 90}}
    until: {{duration_s: {seconds}}}
checks:
  - {{name: altitude held, signal: altitude_ft, stat: max_deviation, max: 50}}
"""


def short(folder: Path, name: str = "short", seconds: float = 1, extra: str = "", file: str | None = None) -> Path:
    """Write a short manoeuvre file into ``folder``; return its path."""
    path = folder / (file or f"{name}.yaml")
    path.write_text(SHORT.format(name=name, seconds=seconds, extra=extra))
    return path


def washbench(*args: object, timeout: float = 60, cwd: Path | None = None) -> subprocess.CompletedProcess[str]:
    """Run ``python -m washbench ARGS`` to its end, failing the test if it takes longer than ``timeout`` s: in the
    test process where the command allows (:func:`inprocess.washbench`), else as a subprocess."""
    return inprocess.washbench(*args, timeout=timeout, cwd=cwd)


#: A progress line (washbench.io.progress.Progress.line, in a log): printed once a command has run for 2 s, so its
#: presence depends on the machine's load, never on the error.
PROGRESS_LINE = re.compile(r"^(?:cue|suite|sweep|tune|omct): (?:\[[#-]+\] )?\s*\d+% \(")
#: The note that a command replaces earlier results of its own in its --out (washbench.io.owners), printed before it
#: starts: its presence depends on what the folder held before, never on the error.
REPLACING_NOTE = re.compile(r"^washbench: note: .* (?:holds earlier `washbench \w+` results|holds a suite of \d+ "
                            r"manoeuvres?|holds an earlier run of |holds \d+ `washbench run` results?)")  # fmt: skip


def assert_clean_error(proc: subprocess.CompletedProcess[str], *names: str, lines: int = 1) -> list[str]:
    """Exit 2, no traceback, ``lines`` stderr lines each starting ``washbench: error:``, mentioning ``names``.

    Progress lines (:data:`PROGRESS_LINE`) are not counted: whether one is printed depends on how long the
    command ran before it stopped (a loaded machine), not on what went wrong; nor is the note that earlier results
    are being replaced (:data:`REPLACING_NOTE`: it depends on what the folder held); every other line counts.
    """
    assert proc.returncode == 2, (proc.returncode, proc.stdout, proc.stderr)
    assert "Traceback" not in proc.stderr and "Traceback" not in proc.stdout, proc.stderr
    got = [line for line in proc.stderr.strip().splitlines()
           if not PROGRESS_LINE.match(line) and not REPLACING_NOTE.match(line)]  # fmt: skip
    assert len(got) == lines, got
    assert all(line.startswith("washbench") and ": error: " in line for line in got), got
    for name in names:
        assert name in proc.stderr, (name, proc.stderr)
    return got


def tree(root: Path) -> list[str]:
    """Every path under ``root`` (relative, sorted), hidden ones included."""
    return sorted(str(p.relative_to(root)) for p in root.rglob("*")) if root.exists() else []


def live_processes(pgid: int) -> list[str]:
    """Processes of process group ``pgid`` that are still running (zombies, already dead, excluded)."""
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
        except OSError:
            continue
        fields = stat[stat.rindex(")") + 2 :].split()
        state, group = fields[0], int(fields[2])
        if group == pgid and state != "Z":
            found.append(f"{entry.name} {stat[: stat.rindex(')') + 1]} {state}")
    return found


def long_suite(root: Path, *, output: int | None = subprocess.PIPE) -> subprocess.Popen[str]:
    """``washbench suite`` of two 3600 s manoeuvres (never finished while a test waits) into ``root/out`` with
    ``--jobs 2``, in its own process group (every process it starts can be found); ``output``: where its stdout
    and stderr go. Its temporary folder (``TMPDIR``) is ``root/tmp``, its own: the JSBSim scratch folders its
    workers make, and leave when killed, are not cleaned by a process of a test running beside it (``root/tmp``
    links to it)."""
    folder = root / "m"
    folder.mkdir()
    for i in range(2):
        short(folder, name=f"long_{i}", seconds=3600)
    # a short path: the suite's process server listens on a Unix socket in TMPDIR (at most 107 bytes of path)
    scratch = tempfile.mkdtemp(prefix="wb-")
    atexit.register(shutil.rmtree, scratch, True)
    (root / "tmp").symlink_to(scratch)
    return subprocess.Popen(
        [sys.executable, "-m", "washbench", "suite", str(folder), "--out", str(root / "out"), "--jobs", "2", "--quiet"],
        stdout=output,
        stderr=output,
        text=True,
        start_new_session=True,
        env={**os.environ, "TMPDIR": scratch},
    )
