"""The pilot model's measures of a washout, predicted without flying it: what the studies (``sweep``, ``tune``)
take as an objective (``--pilot TASK``).

Prepared once per task (:meth:`PilotObjective.prepare`, JSBSim flies): the loop's calibration and the aircraft
condition's runs, as ``washbench track`` flies them (:mod:`washbench.pilot.measure`). Then per candidate washout,
without JSBSim (:meth:`PilotObjective.measures`): its motion filter on the task's axis from the aircraft
condition's recorded head motion cued through it and its platform (the compiled washouts, whole-trace form), the
pilot model adapted to it (:mod:`washbench.pilot.adapt`), and the adaptation's prediction of the measures
(:mod:`washbench.pilot.compare`'s, but predicted): error and control variances, the two open loops' crossovers
and phase margins, the parameters, and the distance from flight against the aircraft condition's prediction. The
prediction is the frequency-domain model the pilot adapts with: ``washbench track``'s report sets it beside what
JSBSim flew (within a few percent on the bundled tasks, docs/pilot-model.md). About 0.3 s of CPU a candidate.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from washbench.cueing.variants import Washout
from washbench.perception.vestibular import VestibularParams, model_params
from washbench.pilot.adapt import Prediction, adapt
from washbench.pilot.compare import DISTANCE_MEASURES, distance
from washbench.pilot.loop import AIRCRAFT, Condition, RunSignals
from washbench.pilot.measure import Calibration, calibrate, measure_condition, motion_filter
from washbench.pilot.params import MultimodalParams
from washbench.pilot.senses import DEFAULT_VESTIBULAR
from washbench.pilot.task import Task, load_task, pilot_params

_DEG2 = (180.0 / math.pi) ** 2

PREDICTED = (*DISTANCE_MEASURES, "visual_gain", "lead_s", "vestibular_gain", "motion_gain_1radps", "distance_pct")
"""The columns :meth:`PilotObjective.measures` gives, in order."""


def predicted_measures(p: MultimodalParams, pred: Prediction) -> dict[str, float]:
    """The measures of :data:`washbench.pilot.compare.DISTANCE_MEASURES` and the parameters, as predicted."""
    return {
        "error_var_deg2": pred.error_variance * _DEG2,
        "control_var": pred.control_variance,
        "target_crossover_radps": pred.target.frequency_radps,
        "target_phase_margin_deg": pred.target.phase_margin_deg,
        "disturbance_crossover_radps": pred.disturbance.frequency_radps,
        "disturbance_phase_margin_deg": pred.disturbance.phase_margin_deg,
        "visual_gain": p.visual_gain,
        "lead_s": p.lead_s,
        "vestibular_gain": p.vestibular_gain,
    }


@dataclass
class PilotObjective:
    """A task prepared for predicting the pilot model's measures of candidate washouts (module docstring)."""

    task: Task
    task_path: Path
    calibration: Calibration
    vestibular: VestibularParams
    params: MultimodalParams
    aircraft_runs: Sequence[RunSignals]
    reference: dict[str, float]

    @classmethod
    def prepare(cls, task_path: Path, aircraft_dirs: Sequence[Path] = (), vestibular: str | None = None,
                runs: int | None = None) -> PilotObjective:  # fmt: skip
        """Load the task, calibrate its loop and fly its aircraft condition (JSBSim; ``runs``: how many, default
        the task's)."""
        task, manoeuvre = load_task(task_path, aircraft_dirs)
        vest = model_params(vestibular or DEFAULT_VESTIBULAR)
        params = pilot_params(task, MultimodalParams)
        calib, _ = calibrate(task, manoeuvre, params, vest, task.adaptation)
        if runs is not None and runs != task.runs:
            copy = task.model_copy(update={"runs": runs})
            copy._source, copy._lines, copy._aircraft_dirs = task._source, task._lines, task._aircraft_dirs
            task = copy
        aircraft = measure_condition(task, manoeuvre, Condition(AIRCRAFT), calib, vest,
                                     motion_filter(Condition(AIRCRAFT), [], task), params=params)  # fmt: skip
        pred = aircraft.prediction
        if pred is None:  # the built-in model always predicts
            raise RuntimeError("no prediction for the aircraft condition")
        reference = predicted_measures(MultimodalParams.model_validate(_only_params(aircraft.params)), pred)
        return cls(task, Path(task_path), calib, vest, params, aircraft.runs, reference)

    def measures(self, washout: Washout, limits: Any, filter_start: str = "steady") -> dict[str, float]:
        """The predicted measures of ``washout`` on its platform ``limits`` (:data:`PREDICTED`)."""
        cond = Condition(washout.name, washout, limits)
        motion = motion_filter(cond, self.aircraft_runs, self.task, filter_start)
        p, pred = adapt(self.params, self.calibration.setting(self.task, motion, self.vestibular),
                        self.task.adaptation)  # fmt: skip
        out = predicted_measures(p, pred)
        out["motion_gain_1radps"] = abs(complex(motion(_ONE)[0]))
        out["distance_pct"] = distance(out, self.reference) if pred.stable else math.inf
        return out

    @property
    def label(self) -> str:
        return f"{self.task.aircraft}/{self.task.name}"


_ONE = np.array([1.0])


def _only_params(described: dict[str, Any]) -> dict[str, Any]:
    """The model's parameters out of its description (without the realised delays)."""
    return {k: v for k, v in described.items() if k in MultimodalParams.model_fields}
