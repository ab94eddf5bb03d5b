"""``metrics.csv``: a washout's metrics per degree of freedom, one row each (:class:`MetricRow`), written and read.

Columns ``washout,dof,npc,integral_error,max_error`` (:mod:`washbench.analysis.metrics`) then the cue classification
(:mod:`washbench.analysis.cues`) ``cue_correct_frac,cue_scaled_frac,cue_false_frac,cue_missing_frac`` (time
fractions), on the heave row the motion sickness dose values ``msdv_mps15,msdv_aircraft_mps15`` (ISO 2631-1 Wf,
m/s^1.5: the simulator pilot's and the aircraft pilot's, :mod:`washbench.perception.sickness`),
``false_cue_events`` (``start_s-end_s@peak`` joined by ``;``) and on the heave row the predicted motion-sickness
incidence ``msi_pct,msi_aircraft_pct`` (%, subjective vertical conflict, :mod:`washbench.perception.svc`), then the
felt error's terms ``felt_error,felt_false,jolt`` (:mod:`washbench.analysis.felt`: the error beyond the perception
threshold and its false part, m/s^2*s or deg; on surge, sway and heave the jolt the platform adds, m/s^2), one row
per washout and DOF (surge, sway, heave, roll, pitch, yaw). Floats are written with ``repr`` (exact round trip); an
undefined NPC (flat signal) is an empty field; PC = -1 gives ``inf``.
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

from washbench.errors import WashbenchError, located
from washbench.io.atomic import write_text_atomic
from washbench.io.csv_numbers import csv_number

METRICS_COLUMNS = (
    "washout", "dof", "npc", "integral_error", "max_error",
    "cue_correct_frac", "cue_scaled_frac", "cue_false_frac", "cue_missing_frac",
    "msdv_mps15", "msdv_aircraft_mps15", "false_cue_events", "msi_pct", "msi_aircraft_pct",
    "felt_error", "felt_false", "jolt",
)  # fmt: skip
"""metrics.csv columns; files written before the cue classification have the first five only, before the MSI the
first twelve, before the felt error the first fourteen (all still read)."""
METRICS_TEXT_COLUMNS = ("washout", "dof", "false_cue_events")
N_BASE_METRICS_COLUMNS = 5
N_PRE_MSI_METRICS_COLUMNS = 12
N_PRE_FELT_METRICS_COLUMNS = 14


@dataclass(frozen=True)
class MetricRow:
    """One row of ``metrics.csv``: a washout's metrics for one DOF (units: :mod:`washbench.analysis.metrics`).

    The cue classification (:mod:`washbench.analysis.cues`): time fractions ``cue_*_frac`` (NaN where not
    classified, e.g. a study's evaluation) and the false-cue events as ``start-end@peak;...`` text. On the heave row,
    the motion sickness dose values (MSDV, m/s^1.5, ISO 2631-1 Wf) of the simulator pilot and of the aircraft pilot
    and their predicted motion-sickness incidence at the end of the manoeuvre (MSI, %, the 6-DOF subjective
    vertical conflict model of :mod:`washbench.perception.svc`: one value per pilot, of all six DOFs) (NaN on the
    other rows). The felt error's terms (:mod:`washbench.analysis.felt`): ``felt_error`` and ``felt_false`` (m/s^2*s;
    deg), ``jolt`` (m/s^2; NaN on the rotational rows) (NaN where not computed, e.g. a file written before them).
    """

    washout: str
    dof: str
    npc: float
    integral_error: float
    max_error: float
    cue_correct_frac: float = math.nan
    cue_scaled_frac: float = math.nan
    cue_false_frac: float = math.nan
    cue_missing_frac: float = math.nan
    msdv_mps15: float = math.nan
    msdv_aircraft_mps15: float = math.nan
    false_cue_events: str = ""
    msi_pct: float = math.nan
    msi_aircraft_pct: float = math.nan
    felt_error: float = math.nan
    felt_false: float = math.nan
    jolt: float = math.nan



def metrics_csv_text(rows: Iterable[MetricRow]) -> str:
    """The text of metrics.csv for ``rows`` (header, then one line per row; NaN -> empty field)."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(METRICS_COLUMNS)
    for r in rows:
        w.writerow(
            [getattr(r, c) if c in METRICS_TEXT_COLUMNS else csv_number(getattr(r, c)) for c in METRICS_COLUMNS]
        )
    return buf.getvalue()


def write_metrics_csv(path: str | Path, rows: Iterable[MetricRow]) -> None:
    """Write metrics.csv atomically (floats as ``repr``: exact round trip; NaN as an empty field)."""
    write_text_atomic(path, metrics_csv_text(rows))


def read_metrics_csv(path: str | Path) -> list[MetricRow]:
    """Read metrics.csv back (empty fields -> NaN). Raises WashbenchError on a malformed file."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise WashbenchError(located(path, f"cannot read: {getattr(exc, 'strerror', None) or exc}")) from None
    reader = csv.reader(io.StringIO(text))
    header = next(reader, None)
    known = (METRICS_COLUMNS, METRICS_COLUMNS[:N_PRE_FELT_METRICS_COLUMNS], METRICS_COLUMNS[:N_PRE_MSI_METRICS_COLUMNS],
             METRICS_COLUMNS[:N_BASE_METRICS_COLUMNS])  # fmt: skip
    if header is None or tuple(header) not in known:
        raise WashbenchError(located(path, f"expected header {','.join(METRICS_COLUMNS)}", line=1))
    ncol = len(header)
    rows = []
    for line, rec in enumerate(reader, start=2):
        if len(rec) != ncol:
            raise WashbenchError(located(path, f"expected {ncol} fields, got {len(rec)}", line=line))
        try:
            values = {c: v if c in METRICS_TEXT_COLUMNS else (math.nan if v == "" else float(v))
                      for c, v in zip(header, rec, strict=True)}  # fmt: skip
        except ValueError as exc:
            raise WashbenchError(located(path, f"not a number: {exc}", line=line)) from None
        rows.append(MetricRow(**values))
    return rows
