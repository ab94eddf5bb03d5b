"""``python -m washbench`` and the ``washbench`` console script.

The command-line module is imported inside :func:`entry`, so a Ctrl-C or SIGTERM that arrives while it loads
(the first fraction of a second) still ends in one line and status 130 or 143, not an import traceback.
"""

from __future__ import annotations

import signal
import sys


def _terminated(signum: int, frame: object) -> None:
    print("washbench: terminated", file=sys.stderr)
    raise SystemExit(143)


def entry() -> int:
    """Import the CLI and run it; the console script's entry point."""
    signal.signal(signal.SIGTERM, _terminated)  # until the CLI installs its own handler
    try:
        from washbench.cli import main

        return main()
    except KeyboardInterrupt:  # before the CLI's own handling starts (importing, parsing the arguments)
        print("washbench: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    raise SystemExit(entry())
