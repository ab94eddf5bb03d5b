"""One way to read back a file washbench wrote: checked as strictly as a user's input.

``run.json``, ``flight.json``, ``suite.json`` and the provenance (in ``run.json`` or in a Parquet file's
metadata) are validated against the fields washbench reads from them (other fields are ignored, so newer
files stay readable); ``traces.parquet`` columns must be numeric with a finite, increasing time. A file
edited by hand or damaged is one line naming it and the field (exit 2 through the CLI), never a
traceback. A ``suite.json`` result entry must be a relative path that stays inside the suite folder
without passing through a symbolic link (:func:`suite_member`).
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any, Literal

from pydantic import (
    BaseModel,
    ConfigDict,
    StrictBool,
    StrictFloat,
    StrictInt,
    StrictStr,
    ValidationError,
    model_validator,
)

from washbench.errors import WashbenchError, located

Number = StrictFloat | StrictInt


class _Loose(BaseModel):
    """Known fields typed strictly; unknown ones allowed (a newer washbench may add fields)."""

    model_config = ConfigDict(extra="allow")


class FileRecord(_Loose):
    name: StrictStr | None = None
    path: StrictStr | None = None
    sha256: StrictStr | None = None
    values: dict[str, Any] | None = None
    provenance: Provenance | None = None


class WashoutRecord(_Loose):
    name: StrictStr
    kind: StrictStr
    values: dict[str, Any] | None = None


class Turbulence(_Loose):
    severity: StrictStr
    seed: StrictInt


#: The ranking rules and DOFs a recorded ``ranking`` may name (:data:`washbench.analysis.ranking.RANK_BY`, ``DOFS``;
#: written out here so that this module imports no analysis code; a test keeps them equal).
RANK_RULES = ("felt", "score", "false-cue", "weighted")
RANK_DOFS = ("surge", "sway", "heave", "roll", "pitch", "yaw")


class FeltMeasureDoc(_Loose):
    """The felt error's parameters a result was ranked with (:class:`washbench.analysis.felt.FeltMeasure`)."""

    thresholds: dict[Literal["f_x_mps2", "f_y_mps2", "f_z_mps2", "omega_x_degps", "omega_y_degps", "omega_z_degps"],
                     Number] | None = None  # fmt: skip
    deadband: StrictBool | None = None
    false_weight: Number | None = None
    jolt_time_s: Number | None = None
    jerk_deadband_mps3: Number | None = None
    felt_floor_s: Number | None = None

    @model_validator(mode="after")
    def _sensible(self) -> FeltMeasureDoc:
        for name, v in (*(self.thresholds or {}).items(), ("false_weight", self.false_weight),
                        ("jolt_time_s", self.jolt_time_s), ("jerk_deadband_mps3", self.jerk_deadband_mps3),
                        ("felt_floor_s", self.felt_floor_s)):  # fmt: skip
            if v is not None and not (math.isfinite(v) and 0.0 <= v <= 1e6):
                raise ValueError(f"{name}: expected a finite number from 0 to 1e6, got {v!r}")
        if any(v <= 0.0 for v in (self.thresholds or {}).values()) or (self.felt_floor_s or 1.0) <= 0.0:
            raise ValueError("thresholds and felt_floor_s must be above 0")
        return self


class Ranking(_Loose):
    """The ranking rule a result was written with; ``report`` ranks by it again, so it is checked as an input."""

    by: Literal["felt", "score", "false-cue", "weighted"] = "score"
    dof_weights: dict[Literal["surge", "sway", "heave", "roll", "pitch", "yaw"], Number] | None = None
    tie_relative: Number | None = None
    tie_absolute: Number | None = None
    measure: FeltMeasureDoc | None = None

    @model_validator(mode="after")
    def _sensible(self) -> Ranking:
        for name, v in (*(self.dof_weights or {}).items(), ("tie_relative", self.tie_relative),
                        ("tie_absolute", self.tie_absolute)):  # fmt: skip
            if v is not None and not (math.isfinite(v) and 0.0 <= v <= 1e6):
                raise ValueError(f"{name}: expected a finite number from 0 to 1e6, got {v!r}")
        if self.tie_relative is not None and self.tie_relative > 1.0:
            raise ValueError(f"tie_relative: expected 0..1, got {self.tie_relative!r}")
        if self.by == "weighted" and not any(v > 0.0 for v in (self.dof_weights or {}).values()):
            raise ValueError("rule 'weighted' needs dof_weights with at least one positive weight")
        return self


class Provenance(_Loose):
    ranking: Ranking | None = None
    manoeuvre: FileRecord | None = None
    aircraft: FileRecord | None = None
    pilot_profile: FileRecord | None = None
    input: FileRecord | None = None
    params: FileRecord | None = None
    platform: FileRecord | None = None
    washouts: list[WashoutRecord] | None = None
    turbulence: Turbulence | None = None
    software: dict[str, StrictStr | None] | None = None


class MotionValue(_Loose):
    value: Number


class RunDoc(_Loose):
    aircraft: StrictStr | None = None
    manoeuvre: StrictStr | None = None
    ok: StrictBool | None = None
    reason: StrictStr | None = None
    dt_s: Number | None = None
    created_utc: StrictStr | None = None
    provenance: Provenance | None = None
    perceived_motion: dict[str, MotionValue] | None = None


class Phase(_Loose):
    name: StrictStr
    t_start_s: Number
    t_end_s: Number


class Check(_Loose):
    name: StrictStr | None = None
    measured: Number | None = None
    passed: StrictBool | None = None


class FlightDoc(_Loose):
    aircraft: StrictStr | None = None
    name: StrictStr | None = None
    status: StrictStr | None = None
    reason: StrictStr | None = None
    dt_s: Number | None = None
    phases: list[Phase] = []
    checks: list[Check] = []


class SuiteEntry(_Loose):
    file: StrictStr = ""
    ok: StrictBool | None = None
    reason: StrictStr | None = None
    aircraft: StrictStr | None = None
    manoeuvre: StrictStr | None = None
    result: StrictStr | None = None


class SuiteDoc(_Loose):
    washbench: StrictStr | None = None
    created_utc: StrictStr | None = None
    provenance: Provenance | None = None
    manoeuvres: list[SuiteEntry]
    entries: list[StrictStr] | None = None


FileRecord.model_rebuild()


def _problem(exc: ValidationError) -> str:
    err = exc.errors()[0]
    where = ".".join(str(p) for p in err["loc"]) or "(the document)"
    return f"{where}: {err['msg'].lower()}"


def _refused(path: Path, problem: str) -> WashbenchError:
    return WashbenchError(located(path, f"not as washbench writes it: {problem} (edited or damaged? write it again)"))


def read_doc(path: Path, model: type[_Loose]) -> dict[str, Any] | None:
    """The JSON object in ``path`` checked against ``model`` (as read, a dict), or None if there is no such file.

    Raises WashbenchError (one line: file, field, problem) for anything else, including a symbolic link.
    """
    if path.is_symlink():
        raise _refused(path, "a symbolic link")
    if not path.exists():
        return None
    try:
        doc = json.loads(path.read_bytes().decode("utf-8"), parse_constant=_no_constant)
    except (OSError, UnicodeDecodeError, ValueError, RecursionError) as exc:
        raise _refused(path, f"not readable JSON ({exc})") from None
    if not isinstance(doc, dict):
        raise _refused(path, f"a JSON {type(doc).__name__}, not an object")
    check_doc(doc, model, path)
    return doc


def _no_constant(name: str) -> None:
    raise ValueError(f"{name} is not a number washbench writes")


def json_text(doc: Any) -> str:
    """``doc`` as the JSON text :func:`read_doc` reads back (indented): a float that is not finite written as null
    (JSON has no infinity; Python's ``Infinity`` and ``NaN`` are refused when read), so no result washbench writes
    is one it refuses later."""

    def finite(value: Any) -> Any:
        if isinstance(value, float):
            return value if math.isfinite(value) else None
        if isinstance(value, dict):
            return {k: finite(v) for k, v in value.items()}
        if isinstance(value, list | tuple):
            return [finite(v) for v in value]
        return value

    return json.dumps(finite(doc), indent=2, allow_nan=False) + "\n"


def check_doc(doc: Any, model: type[_Loose], path: Path) -> None:
    """Validate ``doc`` against ``model``; WashbenchError naming ``path`` and the field otherwise."""
    try:
        model.model_validate(doc)
    except ValidationError as exc:
        raise _refused(path, _problem(exc)) from None
    except RecursionError:
        raise _refused(path, "nested too deeply") from None
    for key in ("dt_s",):
        value = doc.get(key) if isinstance(doc, dict) else None
        if value is not None and not (math.isfinite(value) and value > 0):
            raise _refused(path, f"{key}: expected a positive number, got {value!r}")


def check_provenance(prov: Any, path: Path) -> dict[str, Any] | None:
    """The provenance read from ``path`` (run.json or Parquet metadata) if it is as washbench writes it."""
    if prov is None:
        return None
    if not isinstance(prov, dict):
        raise _refused(path, "provenance: expected an object")
    try:
        Provenance.model_validate(prov)
    except ValidationError as exc:
        raise _refused(path, "provenance." + _problem(exc)) from None
    return prov


def suite_member(suite_dir: Path, rel: str, path: Path) -> Path:
    """``suite_dir / rel`` for a result entry of ``path`` (suite.json), proven to stay inside the suite folder.

    Refused: an absolute path, ``..``, an empty part, or any symbolic link on the way (one line naming
    ``path`` and the entry).
    """
    parts = Path(rel).parts
    if not rel or Path(rel).is_absolute() or any(p in ("..", ".", "") for p in parts):
        raise _refused(path, f"result {rel!r} is not a folder inside the suite folder")
    here = suite_dir
    for part in parts:
        here = here / part
        if here.is_symlink():
            raise _refused(path, f"result {rel!r} passes through a symbolic link ({here}): not followed")
    return here
