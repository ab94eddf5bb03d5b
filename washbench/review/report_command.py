"""``washbench report DIR``: a result folder's or a suite folder's report written again from its files.

Apart from :mod:`washbench.review.report` (one result) and :mod:`washbench.review.suite_report` (a suite, built
from the same pieces) because it chooses between the two.
"""

from __future__ import annotations

import os
from pathlib import Path

from washbench.errors import WashbenchError, located, printable
from washbench.io.lock import output_lock
from washbench.io.outfolder import recover
from washbench.io.result_files import SUITE_FILE, TRACK_FILE
from washbench.review.palette import PALETTE_ENV, palette_name
from washbench.review.report import write_result_report
from washbench.review.result_data import is_result_folder
from washbench.review.suite_report import write_suite_report
from washbench.review.track_report import write_track_report


def report_command(results_dir: Path, palette: str | None = None) -> int:
    """``washbench report DIR``: write report.md and the figures (PNG and PDF) again from a result or suite folder's
    files. ``palette`` (:data:`washbench.review.palette.PALETTES`) is set for this process as
    ``$WASHBENCH_PALETTE`` would be (every figure of a suite is drawn with it)."""

    if palette is not None:
        os.environ[PALETTE_ENV] = palette_name(palette)

    folder = Path(results_dir)
    if not folder.is_dir():
        raise WashbenchError(located(folder, "no such folder"))
    with output_lock(folder):  # no other washbench command writes into it meanwhile
        recover(folder)
        if (folder / TRACK_FILE).is_file():  # a washbench track result set
            path = write_track_report(folder, figures=True, palette=palette_name(palette))
        elif is_result_folder(folder) and not (folder / SUITE_FILE).exists():
            path = write_result_report(folder, pdf=True)
        else:
            path = write_suite_report(folder, regenerate_results=True)
    print(f"report: {printable(str(path))}")
    return 0
