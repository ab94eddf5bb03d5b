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

A suite's folder adds, at its top: ``metrics.csv``, ``comparison.csv``, ``ranking.csv``, ``report.md``,
``figures/`` and ``suite.json`` (written last; it marks the folder as a suite's).
"""

from __future__ import annotations

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

RUN_FILES = (FLIGHT_JSON, FLIGHT_FILE, TRACES_FILE, METRICS_FILE, RECORDING_FILE, RUN_FILE, RANKING_FILE,
             REPORT_FILE, FIGURES_DIR)  # fmt: skip
"""Everything a ``washbench run`` result folder of a manoeuvre holds."""

SUITE_FILES = (METRICS_FILE, COMPARISON_FILE, RANKING_FILE, REPORT_FILE)
"""A suite's own files at its top (besides ``figures/`` and ``suite.json``, which ``suite.json`` lists)."""
