"""The options of a run, loaded once: one frozen :class:`RunOptions` that ``run``, ``cue``, ``suite`` (and its
workers) and ``live`` are given instead of a dozen loose keywords.

:func:`load_options` checks what the command line said and reads each file once: the parameter file (parsed once
for its base set, its ``variants:`` and its ``ranking:`` section, and hashed from the same bytes for the
provenance), the platform file (likewise), the vestibular model. What
it loads (the washouts, the platform limits, the ranking rule) and the run-wide part of the provenance go with
the options, so a suite's worker process is handed the options as they are (picklable) and reads none of these
files again.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from washbench.analysis.ranking import RankRule
from washbench.cueing import registry
from washbench.cueing.params import DEFAULT_PARAMS_PATH, WashoutParams, check_filter_start
from washbench.cueing.variants import (
    ALL_WASHOUTS,
    Washout,
    check_platform,
    default_on,
    defaulted_sections,
    param_file_from_data,
    select_from,
)
from washbench.errors import WashbenchError
from washbench.io.provenance import build_provenance, file_record, merge_provenance
from washbench.io.yamlio import read_yaml_digest
from washbench.perception.vestibular import VestibularParams, model_params, model_record
from washbench.platform.model import PlatformModel, resolve_platform
from washbench.runs.outputs import DEFAULT_OUTPUTS, Outputs
from washbench.runs.rank_rule import rank_rule_from_data


@dataclass(frozen=True, kw_only=True)
class RunOptions:
    """Everything a run is told besides its input and its output folder, with the files it names loaded.

    As given (the command line): ``params_path``, ``platform_path`` (None: the bundled files), ``washout_names``
    (``--washout``; None: the default), ``variants`` (``--variant`` texts), ``aircraft_dirs``, ``outputs``,
    ``filter_start`` (``steady`` or ``rest``), ``max_time_s`` (JSBSim scripts), ``rank_by``, ``vestibular`` (the
    model's name; None: the default), ``thresholds`` (the felt error's: ``zacharias``, ``none``; None: the
    parameter file's ``ranking:`` section, else Zacharias).
    Loaded: ``params`` (the parameter file's base set), ``washouts`` (what runs,
    :func:`washbench.cueing.variants.select_washouts`), ``limits``, ``rank_rule``, ``vestibular_params``,
    ``plugins`` (the washout plugins loaded in this process, ``FILE.py:NAME``, for worker processes) and
    ``provenance`` (the run-wide records: parameters, washouts, platform, ranking, vestibular model; no date).
    """

    params_path: Path | None = None
    platform_path: Path | None = None
    washout_names: tuple[str, ...] | None = None
    variants: tuple[str, ...] = ()
    aircraft_dirs: tuple[Path, ...] = ()
    outputs: Outputs = DEFAULT_OUTPUTS
    filter_start: str = "steady"
    max_time_s: float | None = None
    rank_by: str | None = None
    vestibular: str | None = None
    thresholds: str | None = None
    params: WashoutParams
    washouts: tuple[Washout, ...]
    limits: PlatformModel
    rank_rule: RankRule
    vestibular_params: VestibularParams
    plugins: tuple[str, ...] = ()
    provenance: Mapping[str, Any] = field(default_factory=dict, repr=False)

    @property
    def washout_order(self) -> tuple[str, ...]:
        """The washouts' names in the order they run (and appear in every output)."""
        return tuple(w.name for w in self.washouts)

    def provenance_for(
        self, manoeuvre_path: Path | None = None, turbulence: Any = None, aircraft_files: Any = None
    ) -> dict[str, Any]:
        """The provenance of one result (:func:`washbench.io.provenance.build_provenance`): the run's records with
        the manoeuvre's (its file, turbulence and aircraft files) when one was flown."""
        if manoeuvre_path is None:
            return dict(self.provenance)
        own = build_provenance(manoeuvre_path=manoeuvre_path, turbulence=turbulence, aircraft_files=aircraft_files)
        return merge_provenance(own, self.provenance)


def check_max_time(max_time_s: float | None) -> None:
    """``--max-time-s``: None or a positive, finite number of seconds (WashbenchError otherwise)."""
    if max_time_s is not None and not (math.isfinite(max_time_s) and max_time_s > 0.0):
        raise WashbenchError(f"--max-time-s: expected a positive number of seconds, got {max_time_s:g}")


def load_options(
    *,
    params_path: Path | None = None,
    platform_path: Path | None = None,
    washouts: Sequence[str] | None = None,
    variants: Sequence[str] = (),
    aircraft_dirs: Sequence[Path] = (),
    outputs: Outputs = DEFAULT_OUTPUTS,
    filter_start: str = "steady",
    max_time_s: float | None = None,
    rank_by: str | None = None,
    vestibular: str | None = None,
    thresholds: str | None = None,
) -> RunOptions:
    """The options of a run (:class:`RunOptions`), each file read once.

    Raises WashbenchError (one line: file, line, field) for a bad parameter file, variant, platform file, ranking
    section, filter start or ``--max-time-s``: before anything is flown or written.
    """

    check_filter_start(filter_start)
    check_max_time(max_time_s)
    source = params_path or DEFAULT_PARAMS_PATH  # (as given: the provenance records the path as the user wrote it)
    data, lines, params_sha = read_yaml_digest(Path(source))  # the parameter file, read and parsed once
    params, from_file = param_file_from_data(Path(source), data, lines)
    chosen = select_from(washouts, variants, params, from_file)
    limits, resolved, platform_sha = resolve_platform(platform_path)
    platform_source = platform_path or resolved
    if (washouts is None and not variants) or ALL_WASHOUTS in (washouts or ()):
        # the default set, or all: those of its washouts that can drive this platform, never silently (issue 52, item 8)
        chosen, left_out = default_on(chosen, limits, "the default" if washouts is None else "all the")
        if left_out:
            print(f"washbench: note: {left_out}", file=sys.stderr)
    check_platform(chosen, limits)  # a washout named that cannot drive this platform: refused before anything is flown
    rule = rank_rule_from_data(params_path, data, lines, rank_by, thresholds)
    vestibular_params = model_params(vestibular)
    provenance = build_provenance(
        params_path=source,
        params=params,
        washouts=chosen,
        platform_path=platform_source,
        platform=limits,
        ranking=rule.record(),
        vestibular=model_record(vestibular),
        digests={str(source): params_sha, str(platform_source): platform_sha},  # not read again to hash them
        plugins={w.name: rec for w in chosen if (rec := registry.identity(w.kind, w.params)) is not None},
    )
    defaulted = defaulted_sections(Path(source), data)
    if defaulted:  # what the file left out came from the bundled set: say which, and which file
        provenance["params"]["defaults"] = {"sections": list(defaulted), **file_record(DEFAULT_PARAMS_PATH)}
    return RunOptions(
        params_path=params_path,
        platform_path=platform_path,
        washout_names=tuple(washouts) if washouts else None,
        variants=tuple(variants),
        aircraft_dirs=tuple(Path(d) for d in aircraft_dirs),
        outputs=outputs,
        filter_start=filter_start,
        max_time_s=max_time_s,
        rank_by=rank_by,
        vestibular=vestibular,
        thresholds=thresholds,
        params=params,
        washouts=chosen,
        limits=limits,
        rank_rule=rule,
        vestibular_params=vestibular_params,
        plugins=registry.plugin_specs(),
        provenance=provenance,
    )
