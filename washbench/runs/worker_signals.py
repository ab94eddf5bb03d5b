"""Imported first by the suite's process server (forkserver preload): Ctrl-C is the main process's business.

A Ctrl-C in a terminal reaches the whole process group. The suite's main process stops the workers itself
(at once, and removes what they half-built), so the process server and the workers it forks ignore SIGINT;
otherwise each would print its own KeyboardInterrupt traceback. SIGTERM keeps its default action (stop).
Importing this module anywhere else would make that process ignore Ctrl-C: only the suite names it.
"""

from __future__ import annotations

import signal

signal.signal(signal.SIGINT, signal.SIG_IGN)
