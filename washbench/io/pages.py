"""Memory pages for a washbench process: numpy's arrays on ordinary 4 KiB pages, not transparent huge pages.

On Linux numpy asks the kernel (``madvise(MADV_HUGEPAGE)``) to back every large array with 2 MiB pages. Where
transparent huge pages are enabled on request (``/sys/kernel/mm/transparent_hugepage/enabled`` = ``madvise``, as on
these machines) and their ``defrag`` setting is ``madvise`` too, the kernel then compacts memory in the page fault
that first touches each such page, in the command's own time. A washbench command allocates fresh arrays of
megabytes all the time (a 30-minute cue's columns are 1.7 MB each, its review arrays 7 MB), so it paid this again
and again: measured here (issue 39), the recording of a 30-minute cue took 2.4-2.8 s with numpy's default against
1.6-2.0 s with 4 KiB pages (three alternated pairs); gathering its 12 motion arrays of 216,000 x 4 took 0.42-0.81 s
(0.35-0.68 s of it in the kernel) against 0.10 s; the whole ``washbench cue`` with every output took 6.9-7.6 s
(2.7-3.3 s of it in the kernel) against 5.3-6.4 s (1.1-1.6 s), four alternated pairs (docs/development.md).

:func:`small_pages`, at the start of every washbench process (the command's :func:`washbench.__main__.entry`; the
test session), sets numpy's own switch, the environment variable ``NUMPY_MADVISE_HUGEPAGE`` = 0, which numpy reads
as it is imported; the processes a command starts (a suite's process server and workers, a study's cluster) inherit
it. A value the user has set is left as it is. Results do not depend on it: only how the kernel backs the memory.
"""

from __future__ import annotations

import os
import sys

#: numpy's environment variable: 0 = no ``madvise(MADV_HUGEPAGE)`` on array data, 1 = advise it (Linux default).
NUMPY_HUGEPAGE_ENV = "NUMPY_MADVISE_HUGEPAGE"


def small_pages() -> None:
    """No huge-page advice for numpy's arrays in this process and the processes it starts, unless the user has set
    :data:`NUMPY_HUGEPAGE_ENV` (to anything but blanks). Called before numpy is imported (numpy reads the variable
    then); if numpy is imported already (a caller's process), its switch is set directly."""
    if os.environ.get(NUMPY_HUGEPAGE_ENV, "").strip():  # the user's (empty: unset; numpy's import would fail on it)
        return
    os.environ[NUMPY_HUGEPAGE_ENV] = "0"
    if "numpy" in sys.modules:  # numpy has read the variable already: its switch (what it calls itself at import)
        from numpy._core import multiarray

        multiarray._set_madvise_hugepage(False)
