"""The ranking rule of a run: the parameter file's ``ranking:`` section, overridden by ``--rank-by``.

::

    ranking:
      by: weighted            # felt (default) | score | false-cue | weighted
      dof_weights: {surge: 1, sway: 1, heave: 1, roll: 2, pitch: 2, yaw: 0.5}
      thresholds: zacharias   # zacharias (default) | none | {f_x_mps2: 0.17, ..., omega_z_degps: 2.6}
      false_cue_weight: 1.0   # the felt error's lambda, jolt time, jerk dead band (analysis/felt.py)
      jolt_time_s: 1.0
      jerk_deadband_mps3: 50.0

The rules are :mod:`washbench.analysis.ranking`'s, the felt error's terms :mod:`washbench.analysis.felt`'s;
``--thresholds`` replaces the section's ``thresholds``. The rule used is recorded in the provenance (``ranking``).
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import Field

from washbench.analysis.felt import FALSE_WEIGHT, FELT_FLOOR_S, JERK_DEADBAND_MPS3, JOLT_TIME_S, FeltMeasure
from washbench.analysis.ranking import DOFS, RANK_BY, RankRule
from washbench.errors import WashbenchError
from washbench.io.yamlio import StrictModel, read_yaml, validate_data
from washbench.perception.thresholds import ZACHARIAS, Thresholds

Weight = Annotated[float, Field(ge=0.0, le=1e6, allow_inf_nan=False)]

THRESHOLD_CHOICES = ("zacharias", "none")
"""``--thresholds``: the perception thresholds of the felt error (Zacharias 1978, or none: no dead band)."""


class DofWeights(StrictModel):
    """User weights of the DOFs (>= 0; missing DOFs weigh 0)."""

    surge: Weight = 0.0
    sway: Weight = 0.0
    heave: Weight = 0.0
    roll: Weight = 0.0
    pitch: Weight = 0.0
    yaw: Weight = 0.0


class ThresholdValues(StrictModel):
    """Perception thresholds of one's own (every one > 0: they are also the DOFs' units), m/s^2 and deg/s."""

    f_x_mps2: Annotated[float, Field(gt=0.0, le=100.0, allow_inf_nan=False)] = ZACHARIAS.f_x_mps2
    f_y_mps2: Annotated[float, Field(gt=0.0, le=100.0, allow_inf_nan=False)] = ZACHARIAS.f_y_mps2
    f_z_mps2: Annotated[float, Field(gt=0.0, le=100.0, allow_inf_nan=False)] = ZACHARIAS.f_z_mps2
    omega_x_degps: Annotated[float, Field(gt=0.0, le=1000.0, allow_inf_nan=False)] = ZACHARIAS.omega_x_degps
    omega_y_degps: Annotated[float, Field(gt=0.0, le=1000.0, allow_inf_nan=False)] = ZACHARIAS.omega_y_degps
    omega_z_degps: Annotated[float, Field(gt=0.0, le=1000.0, allow_inf_nan=False)] = ZACHARIAS.omega_z_degps


class RankingSection(StrictModel):
    """The ``ranking:`` section of a parameter file."""

    by: Literal["felt", "score", "false-cue", "weighted"] = "felt"
    dof_weights: DofWeights | None = None
    thresholds: Literal["zacharias", "none"] | ThresholdValues = "zacharias"
    false_cue_weight: Annotated[float, Field(ge=0.0, le=100.0, allow_inf_nan=False)] = FALSE_WEIGHT
    jolt_time_s: Annotated[float, Field(ge=0.0, le=100.0, allow_inf_nan=False)] = JOLT_TIME_S
    jerk_deadband_mps3: Annotated[float, Field(ge=0.0, le=1e6, allow_inf_nan=False)] = JERK_DEADBAND_MPS3


class _File(StrictModel):
    ranking: RankingSection = RankingSection()


def load_rank_rule(
    params_path: Path | None, rank_by: str | None = None, thresholds: str | None = None
) -> RankRule:
    """The rule of ``params_path``'s ``ranking:`` section (default: ``felt`` with Zacharias's thresholds), ``by``
    replaced by ``rank_by`` and the thresholds by ``thresholds`` (``zacharias`` or ``none``).

    WashbenchError (file, line, field) for a bad section, or for ``weighted`` without any positive DOF weight.
    """
    data, lines = read_yaml(Path(params_path)) if params_path is not None else (None, {})
    return rank_rule_from_data(params_path, data, lines, rank_by, thresholds)


def _measure(section: RankingSection, thresholds: str | None) -> FeltMeasure:
    chosen = thresholds if thresholds is not None else section.thresholds
    values = chosen if isinstance(chosen, ThresholdValues) else ZACHARIAS
    return FeltMeasure(
        thresholds=Thresholds.model_validate(values.model_dump()),
        deadband=chosen != "none",
        false_weight=section.false_cue_weight,
        jolt_time_s=section.jolt_time_s,
        jerk_deadband_mps3=section.jerk_deadband_mps3,
        felt_floor_s=FELT_FLOOR_S,
    )


def rank_rule_from_data(
    params_path: Path | None,
    data: Any,
    lines: dict[Any, int],
    rank_by: str | None = None,
    thresholds: str | None = None,
) -> RankRule:
    """:func:`load_rank_rule` of a parameter file already read (``read_yaml``: its data and line map; ``data`` is
    ignored without ``params_path``: the bundled file's section is never used)."""
    section = RankingSection()
    if params_path is not None and isinstance(data, dict) and "ranking" in data:
        section = validate_data(Path(params_path), {"ranking": data["ranking"]}, lines, _File).ranking
    if rank_by is not None and rank_by not in RANK_BY:
        raise WashbenchError(f"--rank-by: unknown rule {rank_by!r} (valid: {', '.join(RANK_BY)})")
    if thresholds is not None and thresholds not in THRESHOLD_CHOICES:
        raise WashbenchError(f"--thresholds: unknown choice {thresholds!r} (valid: {', '.join(THRESHOLD_CHOICES)})")
    by = rank_by or section.by
    weights = section.dof_weights.model_dump() if section.dof_weights is not None else {}
    if by == "weighted" and not any(v > 0.0 for v in weights.values()):
        where = f"{params_path}: " if params_path is not None else ""
        raise WashbenchError(
            f"{where}ranking.dof_weights: the 'weighted' ranking needs DOF weights in the parameter file's "
            "ranking: section (at least one positive)"
        )
    try:
        return RankRule(by=by, dof_weights=tuple((d, float(weights.get(d, 0.0))) for d in DOFS) if weights else (),
                        measure=_measure(section, thresholds))  # fmt: skip
    except ValueError as exc:
        raise WashbenchError(str(exc)) from None
