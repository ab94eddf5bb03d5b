"""Issue 38, item 7: the hardening tests' check of a clean failure does not depend on the machine's load.

``cue`` prints a progress line once it has run for 2 s (``washbench.io.progress``); on a loaded machine a command
that then fails prints it before its one error line. The check counts error lines, not stderr lines: a real
progress line (made by the real Progress, with a clock that says 3 s have passed) beside the error passes, any other
extra line still fails.
"""

from __future__ import annotations

import io
import subprocess

import pytest
from hostile import assert_clean_error

from washbench.io.progress import Progress

ERROR = "washbench: error: /tmp/out/recording.rrd: cannot write: File too large"


def _progress_line(tty: bool = False) -> str:
    ticks = iter([0.0, 3.0, 3.0, 3.0])
    stream = io.StringIO()
    Progress("cue", 216_000, stream=stream, tty=tty, clock=lambda: next(ticks), wall=lambda: 0.0).update(97_000)
    text = stream.getvalue()
    assert text.startswith(("cue:", "\r")), text
    return text.replace("\r\033[K", "").rstrip("\n")


def _proc(stderr: str) -> subprocess.CompletedProcess[str]:
    return subprocess.CompletedProcess(["washbench"], 2, "", stderr)


def test_a_progress_line_before_the_error_is_not_an_error_line() -> None:
    line = _progress_line()
    assert "45%" in line
    assert assert_clean_error(_proc(f"{line}\n{ERROR}\n"), "recording.rrd") == [ERROR]


def test_any_other_extra_line_still_fails() -> None:
    with pytest.raises(AssertionError):
        assert_clean_error(_proc(f"something else\n{ERROR}\n"), "recording.rrd")
    with pytest.raises(AssertionError):
        assert_clean_error(_proc(f"{ERROR}\n{ERROR}\n"), "recording.rrd")
