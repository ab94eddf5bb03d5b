"""User-facing errors: one line, printed by the CLI without a traceback."""

from __future__ import annotations

from pathlib import Path


class WashbenchError(Exception):
    """An error caused by the user's input or environment, reported as one line.

    The message must name the file (and where known the line and the field) and the
    problem, e.g. ``manoeuvres/c172/turn.yaml:14: phases[2].hold.bank_deg: expected a
    number, got 'thirty'``. The CLI prints it after ``washbench: error:`` and exits 2.
    """


def located(path: str | Path, problem: str, line: int | None = None, field: str | None = None) -> str:
    """Format ``FILE[:LINE]: [FIELD: ]PROBLEM`` as one line."""
    where = str(path) if line is None else f"{path}:{line}"
    what = problem if field is None else f"{field}: {problem}"
    return f"{where}: {what}".replace("\n", " ")
