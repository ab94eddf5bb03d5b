"""The ranking rule of a run: the parameter file's ``ranking:`` section, overridden by ``--rank-by``.

::

    ranking:
      by: weighted            # score (default) | false-cue | weighted
      dof_weights: {surge: 1, sway: 1, heave: 1, roll: 2, pitch: 2, yaw: 0.5}

The rules are :mod:`washbench.analysis.ranking`'s; the rule used is recorded in the provenance (``ranking``).
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import Field

from washbench.analysis.ranking import DOFS, RankRule
from washbench.errors import WashbenchError
from washbench.io.yamlio import StrictModel, read_yaml, validate_data

Weight = Annotated[float, Field(ge=0.0, le=1e6, allow_inf_nan=False)]


class DofWeights(StrictModel):
    """User weights of the DOFs (>= 0; missing DOFs weigh 0)."""

    surge: Weight = 0.0
    sway: Weight = 0.0
    heave: Weight = 0.0
    roll: Weight = 0.0
    pitch: Weight = 0.0
    yaw: Weight = 0.0


class RankingSection(StrictModel):
    """The ``ranking:`` section of a parameter file."""

    by: Literal["score", "false-cue", "weighted"] = "score"
    dof_weights: DofWeights | None = None


class _File(StrictModel):
    ranking: RankingSection = RankingSection()


def load_rank_rule(params_path: Path | None, rank_by: str | None = None) -> RankRule:
    """The rule of ``params_path``'s ``ranking:`` section (default: ``score``), ``by`` replaced by ``rank_by``.

    WashbenchError (file, line, field) for a bad section, or for ``weighted`` without any positive DOF weight.
    """
    data, lines = read_yaml(Path(params_path)) if params_path is not None else (None, {})
    return rank_rule_from_data(params_path, data, lines, rank_by)


def rank_rule_from_data(
    params_path: Path | None, data: Any, lines: dict[Any, int], rank_by: str | None = None
) -> RankRule:
    """:func:`load_rank_rule` of a parameter file already read (``read_yaml``: its data and line map; ``data`` is
    ignored without ``params_path``: the bundled file's section is never used)."""
    section = RankingSection()
    if params_path is not None and isinstance(data, dict) and "ranking" in data:
        section = validate_data(Path(params_path), {"ranking": data["ranking"]}, lines, _File).ranking
    by = rank_by or section.by
    weights = section.dof_weights.model_dump() if section.dof_weights is not None else {}
    if by == "weighted" and not any(v > 0.0 for v in weights.values()):
        where = f"{params_path}: " if params_path is not None else ""
        raise WashbenchError(
            f"{where}ranking.dof_weights: the 'weighted' ranking needs DOF weights in the parameter file's "
            "ranking: section (at least one positive)"
        )
    try:
        return RankRule(by=by, dof_weights=tuple((d, float(weights.get(d, 0.0))) for d in DOFS) if weights else ())
    except ValueError as exc:
        raise WashbenchError(str(exc)) from None
