"""The names of the files in washbench's result folders: the one place they are spelt.

A result folder of one flight or recorded trace (``washbench run``, ``cue``; a suite's ``<aircraft>/<manoeuvre>/``)::

    flight.json      the flight's summary: manoeuvre, phases, checks (run, fly)
    flight.parquet   the flown trace (run, fly)
    traces.parquet   input, washout, platform and perceived columns
    metrics.csv      washout,dof,npc,... (one row per washout and DOF)
    recording.rrd    the rerun recording (unless --no-recording)
    run.json         the summary: status, motion per DOF, saturations, provenance (marks the folder as a result)
    ranking.csv      the washouts ranked by the run's rule
    report.md        the report, with its figures in figures/

A ``washbench track`` result set (its own ``--out``): ``report.md``, ``figures/``, ``recording.rrd`` and
``track.json`` (the summary), ``measures.csv`` (one row per condition), ``frf.csv`` (the responses at the forcing
frequencies) and ``signals.parquet`` (every run's samples).

A suite's folder adds, at its top: ``metrics.csv``, ``comparison.csv``, ``ranking.csv``, ``report.md``,
``figures/`` and ``suite.json`` (written last; it marks the folder as a suite's).

Besides the results, washbench keeps hidden names in an output folder (:func:`is_own_hidden`): the lock
``.washbench.lock``, the manifest ``.washbench.json`` and what a publication in progress uses
(:mod:`washbench.io.outfolder`): ``.washbench-stage-PID/``, ``.washbench-old-PID/`` and the journal
``.washbench-swap-PID``; also ``.NAME.XXXXXXXX.tmp`` (an atomic write in progress) and, from older versions,
``.NAME.partial-PID`` and ``.NAME.old-PID``.
"""

from __future__ import annotations

import re

FLIGHT_JSON = "flight.json"
FLIGHT_FILE = "flight.parquet"
TRACES_FILE = "traces.parquet"
METRICS_FILE = "metrics.csv"
RECORDING_FILE = "recording.rrd"
RUN_FILE = "run.json"
RANKING_FILE = "ranking.csv"
REPORT_FILE = "report.md"
FIGURES_DIR = "figures"
COMPARISON_FILE = "comparison.csv"
SUITE_FILE = "suite.json"
TRACK_FILE = "track.json"
TRACK_MEASURES_FILE = "measures.csv"
TRACK_FRF_FILE = "frf.csv"
TRACK_SIGNALS_FILE = "signals.parquet"

RUN_FILES = (FLIGHT_JSON, FLIGHT_FILE, TRACES_FILE, METRICS_FILE, RECORDING_FILE, RUN_FILE, RANKING_FILE,
             REPORT_FILE, FIGURES_DIR)  # fmt: skip
"""Everything a ``washbench run`` result folder of a manoeuvre holds."""

SUITE_FILES = (METRICS_FILE, COMPARISON_FILE, RANKING_FILE, REPORT_FILE)
"""A suite's own files at its top (besides ``figures/`` and ``suite.json``, which ``suite.json`` lists)."""

LOCK_NAME = ".washbench.lock"
"""The lock of an output folder (:mod:`washbench.io.lock`)."""
MANIFEST = ".washbench.json"
"""The manifest: which command wrote the folder and every top-level name it wrote (:mod:`washbench.io.outfolder`)."""
STAGE_PREFIX = ".washbench-stage-"
OLD_PREFIX = ".washbench-old-"
JOURNAL_PREFIX = ".washbench-swap-"
PROBE_PREFIX = ".washbench-probe-"

_TMP = re.compile(r"^\..+\.tmp$")
_LEGACY = re.compile(r"^\..+\.(?:partial|old)-(?P<pid>\d+)$")
_PUBLISHING = re.compile(r"^\.washbench-(?:stage|old|swap)-(?P<pid>\d+)(?:\.tmp)?$")


def is_own_hidden(name: str) -> bool:
    """Names washbench keeps in an output folder besides the results (lock, manifest, leftovers)."""
    return (
        name in (LOCK_NAME, MANIFEST)
        or name.startswith((STAGE_PREFIX, OLD_PREFIX, JOURNAL_PREFIX, PROBE_PREFIX))
        or _TMP.match(name) is not None
        or _LEGACY.match(name) is not None
    )


def is_legacy_leftover(name: str) -> bool:
    """``.NAME.partial-PID`` or ``.NAME.old-PID``: what an interrupted run of an older version left."""
    return _LEGACY.match(name) is not None


def publication_pid(name: str) -> int | None:
    """The process ID in the name of a publication's leftover (``.washbench-stage-PID``, ``.washbench-old-PID``,
    the journal ``.washbench-swap-PID`` and its ``.tmp``, a legacy ``.NAME.partial-PID``), or None for any
    other name."""
    match = _PUBLISHING.match(name) or _LEGACY.match(name)
    return int(match.group("pid")) if match else None
