"""Reading one result folder back for the report: only the files in it, nothing flown or cued again.

A result folder is what ``washbench run`` writes (and ``washbench cue``: the same files, fewer of them):
``metrics.csv`` and ``traces.parquet`` are required; ``run.json`` (status, perceived motion, provenance, date) and
``flight.json`` (phases, checks) are used when present. The washout names come from ``metrics.csv`` (in the order
written there), so user-named washouts need no list anywhere. Platform limits for the envelope usage come from the
provenance stored with the result (the platform file's values), never from a file outside the folder.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from washbench.analysis.felt import DEFAULT_MEASURE, FeltMeasure, felt_key, felt_motion
from washbench.analysis.metrics import DOFS, integral_abs_error
from washbench.errors import WashbenchError, located
from washbench.io.columns import (
    AIRCRAFT,
    TIME_COLUMN,
    acc_columns,
    leg_columns,
    omega_platform_columns,
    perceived_f_columns,
    perceived_omega_columns,
    pos_columns,
    q_columns,
    vel_columns,
    wheel_columns,
)
from washbench.io.metrics_csv import MetricRow, read_metrics_csv
from washbench.io.provenance import read_parquet_provenance
from washbench.io.readback import FlightDoc, RunDoc, check_provenance, read_doc
from washbench.io.result_files import FLIGHT_JSON, METRICS_FILE, RUN_FILE, TRACES_FILE
from washbench.platform.hexapod import HexapodModel, MotionEnvelope
from washbench.platform.limits import PlatformLimits, wheel_jacobian
from washbench.platform.rig import RigModel


@dataclass(eq=False)
class ResultData:
    """What the report shows of one result folder (arrays on the traces' time grid, N samples).

    ``perceived``: source (``aircraft`` or a washout) -> (N, 6) surge, sway, heave [m/s^2], roll, pitch, yaw [deg/s];
    ``usage``: envelope panel -> washout -> (N,) |value| / limit (empty without platform limits);
    ``saturated``: washout -> limit kind -> bool (N,); ``motion``: DOF -> the aircraft pilot's perceived motion
    (m/s^2*s or deg, :func:`washbench.analysis.ranking.perceived_motion`).
    """

    folder: Path
    title: str
    washouts: list[str]
    metrics: list[MetricRow]
    t_s: np.ndarray
    dt_s: float
    perceived: dict[str, np.ndarray]
    saturated: dict[str, dict[str, np.ndarray]]
    usage: dict[str, dict[str, np.ndarray]]
    motion: dict[str, float]
    ok: bool | None = None  # None: the folder does not say (a cue result)
    reason: str = ""
    phases: list[tuple[str, float, float]] = field(default_factory=list)
    checks: list[dict[str, Any]] = field(default_factory=list)
    provenance: dict[str, Any] | None = None
    created_utc: str | None = None

    @property
    def n(self) -> int:
        """Number of samples."""
        return int(self.t_s.shape[0])

    @property
    def duration_s(self) -> float:
        """Duration covered by the samples [s]: N steps of dt (each sample stands for one step)."""
        return self.n * self.dt_s


def is_result_folder(folder: Path) -> bool:
    """True if ``folder`` holds the two files every result has (metrics.csv with a washout column, traces.parquet)."""
    return (folder / METRICS_FILE).is_file() and (folder / TRACES_FILE).is_file()


def _read_json(path: Path, model: Any) -> dict[str, Any] | None:
    """``path`` checked as strictly as a user's file (:mod:`washbench.io.readback`), or None when absent."""

    return read_doc(path, model)


def _washout_order(metrics: list[MetricRow]) -> list[str]:
    return list(dict.fromkeys(r.washout for r in metrics))


def perceived_motion_of(
    perceived_aircraft: np.ndarray, dt_s: float, measure: FeltMeasure = DEFAULT_MEASURE
) -> dict[str, float]:
    """Integral of |perceived(t) - perceived(0)| dt per DOF from the (N, 6) aircraft columns (metrics.csv units:
    m/s^2 and deg/s), and under ``felt_<dof>`` the felt motion above threshold (``measure``'s)."""
    plain = {
        d: integral_abs_error(x, np.full_like(x, x[0]), dt_s)
        for d, x in zip(DOFS, np.ascontiguousarray(perceived_aircraft.T), strict=True)
    }
    felt = felt_motion(perceived_aircraft[:, :3], np.radians(perceived_aircraft[:, 3:]), dt_s, measure)
    return plain | {felt_key(d): float(v) for d, v in zip(DOFS, felt, strict=True)}


def _limits_from(prov: dict[str, Any] | None) -> Any:
    """PlatformLimits from the provenance's platform values, or None when the result does not carry them."""
    values = ((prov or {}).get("platform") or {}).get("values")
    if not values:
        return None
    from pydantic import ValidationError

    kind = values.get("kind", "atlas") if isinstance(values, dict) else "atlas"
    model = {"hexapod": HexapodModel, "rig": RigModel}.get(kind, PlatformLimits)
    if kind not in ("atlas", "hexapod", "rig"):  # a plugin's platform: the envelope it exposes, if any
        model, values = MotionEnvelope, values.get("envelope")
        if not isinstance(values, dict):
            return None
    try:
        return model.model_validate_json(json.dumps(values))  # JSON mode: arrays are tuples
    except ValidationError:
        return None


def leg_usage(table: dict[str, np.ndarray], washouts: list[str], hexapod: Any) -> dict[str, dict[str, np.ndarray]]:
    """A hexapod's leg usage per panel and washout: each leg's |l_i - mid-stroke| / half-stroke (panels ``leg 1``
    ... ``leg 6``: 1 = at an end of its stroke), and the fastest leg's |dl/dt| / leg velocity limit (``leg speed``,
    0 at the first sample)."""
    lo, hi = hexapod.leg_length_m.min, hexapod.leg_length_m.max
    mid, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
    time = np.asarray(table[TIME_COLUMN], dtype=np.float64) if TIME_COLUMN in table else None
    out: dict[str, dict[str, np.ndarray]] = {f"leg {i}": {} for i in range(1, 7)}
    out["leg speed"] = {}
    for w in washouts:
        cols = leg_columns(w)
        if not all(c in table for c in cols):
            continue
        legs = np.column_stack([np.asarray(table[c], dtype=np.float64) for c in cols])
        for i in range(6):
            out[f"leg {i + 1}"][w] = np.abs(legs[:, i] - mid) / half
        if time is not None and time.shape[0] > 1:
            speed = np.zeros(time.shape[0])
            speed[1:] = np.max(np.abs(np.diff(legs, axis=0)), axis=1) / np.diff(time)
            out["leg speed"][w] = speed / hexapod.leg_velocity_limit_mps
    return {k: v for k, v in out.items() if v}


def _angles_zyx(q: np.ndarray) -> np.ndarray:
    """Roll, pitch, yaw (N, 3), rad, of attitudes (N, 4) [w, x, y, z] (ZYX Euler angles, the rig's gimbals; yaw
    unwrapped)."""
    w, x, y, z = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    roll = np.arctan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y))
    pitch = np.arcsin(np.clip(2.0 * (w * y - z * x), -1.0, 1.0))
    yaw = np.unwrap(np.arctan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z)))
    return np.column_stack([roll, pitch, yaw])


def rig_usage(table: dict[str, np.ndarray], washouts: list[str], rig: Any) -> dict[str, dict[str, np.ndarray]]:
    """A rig's usage per panel and washout: each present gimbal's |angle| / its angle limit (``roll``, ``pitch``,
    ``yaw``; ZYX Euler angles of the attitude columns) and the heave's |down position| / its travel (``heave``), then
    the largest over those axes of |rate| / rate limit (``rate``: the angles' and the heave's first differences) and
    of |acceleration| / acceleration limit (``acceleration``: their second differences), 0 where undefined (the first
    one or two samples)."""
    time = np.asarray(table[TIME_COLUMN], dtype=np.float64) if TIME_COLUMN in table else None
    axes = [(name, j, ax) for j, (name, ax) in enumerate((("roll", rig.roll), ("pitch", rig.pitch),
                                                         ("yaw", rig.yaw))) if ax is not None]  # fmt: skip
    out: dict[str, dict[str, np.ndarray]] = {name: {} for name, _, _ in axes}
    if rig.heave is not None:
        out["heave"] = {}
    out["rate"], out["acceleration"] = {}, {}
    for w in washouts:
        cols = q_columns(w)
        if not all(c in table for c in cols):
            continue
        angles = _angles_zyx(np.column_stack([np.asarray(table[c], dtype=np.float64) for c in cols]))
        series = [(angles[:, j], math.radians(ax.angle_limit_deg), math.radians(ax.rate_limit_degps),
                   math.radians(ax.acceleration_limit_degps2), name) for name, j, ax in axes]  # fmt: skip
        z = pos_columns(w)[2]
        if rig.heave is not None and z in table:
            h = rig.heave
            series.append((np.asarray(table[z], dtype=np.float64), h.position_limit_m, h.velocity_limit_mps,
                           h.acceleration_limit_mps2, "heave"))  # fmt: skip
        n = series[0][0].shape[0] if series else 0
        rate, acc = np.zeros(n), np.zeros(n)
        for x, lim, rate_lim, acc_lim, name in series:
            out[name][w] = np.abs(x) / lim
            if time is not None and n > 2:
                dt = np.diff(time)
                v = np.diff(x) / dt
                rate[1:] = np.maximum(rate[1:], np.abs(v) / rate_lim)
                acc[2:] = np.maximum(acc[2:], np.abs(np.diff(v) / dt[1:]) / acc_lim)
        if time is not None and n > 2:
            out["rate"][w], out["acceleration"][w] = rate, acc
    return {k: v for k, v in out.items() if v}


def envelope_usage(table: dict[str, np.ndarray], washouts: list[str], limits: Any) -> dict[str, dict[str, np.ndarray]]:
    """Envelope usage per panel and washout: max over axes |value| / limit (stage), |omega| / rate limit (sphere).

    The sphere's angular acceleration is |omega_k - omega_(k-1)| / dt (the body-rate change per step the platform
    limits, :func:`washbench.platform.kinematics.track_rotation`) over its limit, 0 at the first sample. The wheel
    limit is the fastest any wheel turns with the sphere at its rate limit (as in the recording).
    """

    t = limits.translation
    rate_limit_degps = limits.rotation.rate_limit_degps
    acc_limit_degps2 = limits.rotation.acceleration_limit_degps2
    time = np.asarray(table[TIME_COLUMN], dtype=np.float64) if TIME_COLUMN in table else None
    atlas = isinstance(limits, PlatformLimits)  # else a plugin's envelope: no sphere, no wheels
    wheel_max = (float(np.max(np.linalg.norm(wheel_jacobian(limits), axis=1)) * math.radians(rate_limit_degps))
                 if atlas else math.nan)  # fmt: skip
    rate_name, angacc_name = ("sphere rate", "sphere ang. acc.") if atlas else ("rate", "ang. acc.")
    out: dict[str, dict[str, np.ndarray]] = {
        "position": {}, "velocity": {}, "acceleration": {}, rate_name: {}, angacc_name: {}, "wheel speed": {},
    }  # fmt: skip
    for w in washouts:
        stage = (
            ("position", pos_columns(w), t.position_limit_m.xyz),
            ("velocity", vel_columns(w), t.velocity_limit_mps.xyz),
            ("acceleration", acc_columns(w), t.acceleration_limit_mps2.xyz),
        )
        for label, cols, lim in stage:
            if all(c in table for c in cols):
                ratios = [np.abs(table[c]) / m for c, m in zip(cols, lim, strict=True)]
                out[label][w] = np.max(np.column_stack(ratios), axis=1)
        cols = omega_platform_columns(w)
        if all(c in table for c in cols):
            omega = np.column_stack([table[c] for c in cols])
            out[rate_name][w] = np.linalg.norm(omega, axis=1) / rate_limit_degps
            if time is not None and time.shape[0] > 1:
                alpha = np.zeros(time.shape[0])
                alpha[1:] = np.linalg.norm(np.diff(omega, axis=0), axis=1) / np.diff(time)
                out[angacc_name][w] = alpha / acc_limit_degps2
        cols = wheel_columns(w)
        if atlas and all(c in table for c in cols):
            out["wheel speed"][w] = np.max(np.abs(np.column_stack([table[c] for c in cols])), axis=1) / wheel_max
    return {k: v for k, v in out.items() if v}


def load_result(folder: Path, table: Mapping[str, np.ndarray] | None = None, *, series: bool = True) -> ResultData:
    """Read one result folder (module docstring). WashbenchError naming the file when a required one is bad.

    ``table``: the traces.parquet columns already in memory (the run that just wrote them), read from the file
    when None. ``series=False``: only the time and the saturation flags are read (for tables: ranking, metrics,
    time at a limit); ``perceived`` and ``usage`` are then empty.
    """
    import pyarrow as pa
    import pyarrow.parquet as pq

    folder = Path(folder)
    if not folder.is_dir():
        raise WashbenchError(located(folder, "no such folder"))
    if not is_result_folder(folder):
        raise WashbenchError(located(folder, f"not a result folder: it needs {METRICS_FILE} and {TRACES_FILE}"))
    metrics = read_metrics_csv(folder / METRICS_FILE)
    washouts = _washout_order(metrics)
    traces_path = folder / TRACES_FILE
    if table is None:
        try:
            names = set(pq.read_schema(traces_path).names)
        except (OSError, ValueError, pa.ArrowException) as exc:
            raise WashbenchError(located(traces_path, f"not a readable Parquet file ({exc})")) from None
    else:
        names = set(table)
    perceived_cols = [c for src in (AIRCRAFT, *washouts) for c in (*perceived_f_columns(src),
                                                                    *perceived_omega_columns(src))]  # fmt: skip
    missing = [c for c in (TIME_COLUMN, *perceived_cols) if c not in names]
    if missing:
        raise WashbenchError(located(traces_path, f"missing column {missing[0]!r}"))
    want = [TIME_COLUMN] + (perceived_cols if series else perceived_cols[:6])  # (the aircraft's six first)
    for w in washouts:
        if series:
            want += [c for c in (*pos_columns(w), *vel_columns(w), *acc_columns(w), *omega_platform_columns(w),
                                 *wheel_columns(w), *leg_columns(w), *q_columns(w)) if c in names]  # fmt: skip
        want += sorted(c for c in names if c.startswith(f"{w}.sat_"))
    if table is None:
        try:
            arrow = pq.read_table(traces_path, columns=want, use_threads=False)
        except (OSError, ValueError, pa.ArrowException) as exc:
            raise WashbenchError(located(traces_path, f"not a readable Parquet file ({exc})")) from None
        for c in want:  # read back as strictly as a user's input
            kind = arrow.schema.field(c).type
            numeric = pa.types.is_floating(kind) or pa.types.is_integer(kind) or pa.types.is_boolean(kind)
            if not numeric or arrow.column(c).null_count:
                what = f"holds {kind}, not numbers" if not numeric else "has empty values"
                raise WashbenchError(located(traces_path, f"column {c!r} {what} (edited or damaged?)"))
        table = {c: arrow.column(c).to_numpy(zero_copy_only=False) for c in want}
    t = np.asarray(table[TIME_COLUMN], dtype=np.float64)
    if t.shape[0] < 2:
        raise WashbenchError(located(traces_path, "fewer than 2 samples"))
    if not (np.all(np.isfinite(t)) and np.all(np.diff(t) > 0)):
        raise WashbenchError(located(traces_path, f"{TIME_COLUMN}: not finite and increasing (edited or damaged?)"))

    run = _read_json(folder / RUN_FILE, RunDoc) or {}
    flight = _read_json(folder / FLIGHT_JSON, FlightDoc) or {}
    dt = float(run.get("dt_s") or flight.get("dt_s") or (t[-1] - t[0]) / (t.shape[0] - 1))
    perceived = {
        src: np.column_stack([table[c] for c in (*perceived_f_columns(src), *perceived_omega_columns(src))])
        for src in ((AIRCRAFT, *washouts) if series else (AIRCRAFT,))
    }
    saturated = {
        w: {c.split(".sat_", 1)[1]: np.asarray(table[c]) != 0 for c in want if c.startswith(f"{w}.sat_")}
        for w in washouts
    }
    if run.get("provenance"):
        prov = check_provenance(run["provenance"], folder / RUN_FILE)
    else:
        prov = check_provenance(read_parquet_provenance(traces_path), traces_path)
    limits = _limits_from(prov)
    if limits is None or not series:
        usage = {}
    elif isinstance(limits, HexapodModel):
        usage = leg_usage(table, washouts, limits)
    elif isinstance(limits, RigModel):
        usage = rig_usage(table, washouts, limits)
    else:
        usage = envelope_usage(table, washouts, limits)
    motion_doc = run.get("perceived_motion")
    if isinstance(motion_doc, dict) and set(motion_doc) >= set(DOFS):
        motion = {d: float(v["value"]) for d, v in motion_doc.items()}  # as the suite ranked it
    else:
        measure = FeltMeasure.from_record(((prov or {}).get("ranking") or {}).get("measure"))
        motion = perceived_motion_of(perceived[AIRCRAFT], dt, measure)
    aircraft, manoeuvre = run.get("aircraft") or flight.get("aircraft"), run.get("manoeuvre") or flight.get("name")
    title = f"{aircraft} / {manoeuvre}" if aircraft and manoeuvre else folder.name
    ok = run.get("ok")
    if ok is None and flight:
        ok = flight.get("status") == "ok"
    return ResultData(
        folder=folder,
        title=title,
        washouts=washouts,
        metrics=metrics,
        t_s=t,
        dt_s=dt,
        perceived=perceived,
        saturated=saturated,
        usage=usage,
        motion=motion,
        ok=ok,
        reason=str(run.get("reason") or flight.get("reason") or ""),
        phases=[(str(p["name"]), float(p["t_start_s"]), float(p["t_end_s"])) for p in flight.get("phases", [])],
        checks=list(flight.get("checks", [])),
        provenance=prov,
        created_utc=run.get("created_utc"),
    )
