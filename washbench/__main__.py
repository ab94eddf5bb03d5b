"""``python -m washbench`` and the ``washbench`` console script.

The command-line module is imported inside :func:`entry`, with SIGINT and SIGTERM held back until it has loaded
(:func:`washbench.io.interrupts.signals_held`), so a Ctrl-C or SIGTERM that arrives while it loads (the first
fraction of a second) still ends in one line and status 130 or 143, not an import traceback or an extension
module's panic. The
SIGTERM handler and the hook that sends again a signal swallowed in a finalizer (:mod:`washbench.io.interrupts`,
on the lowest floor) are installed first: importlib runs weakref callbacks while modules load, and a Ctrl-C raised
in one was swallowed ("Exception ignored") and the command went on.
"""

from __future__ import annotations

import signal
import sys

from washbench.errors import Terminated
from washbench.io import collector, interrupts, pages


def entry() -> int:
    """Import the CLI and run it; the console script's entry point."""
    collector.tune()  # before the imports, which allocate most of the objects the collector would scan
    pages.small_pages()  # before numpy is imported (it reads the setting then)
    signal.signal(signal.SIGTERM, interrupts.terminate)  # the CLI installs the same for the command
    signal.signal(signal.SIGINT, interrupts.interrupt)  # Python's own, counted: a plugin's KeyboardInterrupt is not one
    sys.unraisablehook = interrupts.signal_in_finalizer
    try:
        # a Ctrl-C or SIGTERM while the CLI loads is noted and acted on once it has loaded: raised inside an
        # extension module's initialisation (pydantic-core importing datetime), it ended the process in a Rust
        # panic (status 1) instead of this one line
        with interrupts.signals_held():
            from washbench.io import entry_points  # deferred: signals

            entry_points.read_pydantic_plugins()  # another package's broken metadata: a warning, not a traceback
            from washbench.cli import main  # deferred: signals

        return main()
    except KeyboardInterrupt:  # before the CLI's own handling starts (importing, parsing the arguments)
        print("washbench: interrupted", file=sys.stderr)
        return 130
    except Terminated:
        print("washbench: terminated", file=sys.stderr)
        return 143


if __name__ == "__main__":
    raise SystemExit(entry())
