"""User-facing errors: one line, printed by the CLI without a traceback."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path


class WashbenchError(Exception):
    """An error caused by the user's input or environment, reported as one line.

    The message must name the file (and where known the line and the field) and the
    problem, e.g. ``manoeuvres/c172/turn.yaml:14: phases[2].hold.bank_deg: expected a
    number, got 'thirty'``. The CLI prints it after ``washbench: error:`` and exits 2.

    A file with several problems gives one error holding all of them: :attr:`problems`
    (one line each, the first is the message); ``str()`` stays one line and says how many
    more there are (``washbench validate`` prints every one).
    """

    def __init__(self, message: str, more: Sequence[str] = ()) -> None:
        self.problems: tuple[str, ...] = (message, *more)
        text = message if not more else f"{message} (and {len(more)} more problem{'s' if len(more) > 1 else ''})"
        super().__init__(text)

    def __reduce__(self) -> tuple[type[WashbenchError], tuple[str, tuple[str, ...]]]:
        """Pickled with every problem (an error raised in a child process, :mod:`washbench.runs.beside`)."""
        return type(self), (self.problems[0], self.problems[1:])


class Terminated(BaseException):
    """SIGTERM arrived: raised in the main thread by the CLI's handler so cleanup code runs (exit 143).

    A BaseException like :class:`KeyboardInterrupt`, so ``except Exception`` does not swallow it.
    """


def located(path: str | Path, problem: str, line: int | None = None, field: str | None = None) -> str:
    """Format ``FILE[:LINE]: [FIELD: ]PROBLEM`` as one line."""
    where = str(path) if line is None else f"{path}:{line}"
    what = problem if field is None else f"{field}: {problem}"
    return f"{where}: {what}".replace("\n", " ")


def printable(text: str) -> str:
    """``text`` safe for a terminal: control characters (escape sequences, carriage returns, C1 codes) and bytes
    that were not UTF-8 shown as ``\\x1b``-style escapes, so a quoted input can never drive the terminal."""
    out = []
    for ch in text:
        code = ord(ch)
        if code < 0x20 or 0x7F <= code < 0xA0:
            out.append(f"\\x{code:02x}")
        elif 0xDC80 <= code <= 0xDCFF:  # a byte that was not UTF-8 (surrogateescape)
            out.append(f"\\x{code - 0xDC00:02x}")
        elif 0xD800 <= code <= 0xDFFF:
            out.append(f"\\u{code:04x}")
        else:
            out.append(ch)
    return "".join(out)
