"""The standard measurement: the loop calibrated once per task, then each condition adapted, flown and measured.

1. :func:`calibrate`: the controlled element (attitude per unit control, at every forcing frequency) measured in
   closed loop in the aircraft's own motion, noise off, in two steps: a probe, the scripted pilot holding the
   task's axis with both sets of sines added to its command (:data:`PROBE_SCALE` of the task's amplitudes through
   an integrator of unit gain: safe on any aircraft), then :data:`CALIBRATION_PASSES` run(s) of the loop the pilot
   model flies, adapted to what the probe measured, with the disturbance scaled by it, so that in every run the
   disturbance moves the attitude by the task's ``rms_deg`` (its amplitudes ``A_k / |H_c(j w_k)|``, as the
   cited designs insert their disturbance before the controlled element).
2. :func:`motion_filter`: a washout's describing function on the task's axis (simulator over aircraft pilot's
   rate at each forcing frequency), from the aircraft condition's recorded head motion cued through the washout
   and its platform (the same compiled washouts as in the loop, whole-trace form).
3. :func:`measure_condition`: the pilot adapted to the condition (:mod:`washbench.pilot.adapt`), then
   ``task.runs`` runs flown (:func:`washbench.pilot.loop.fly_run`), with the same remnant seeds in every condition
   (common random numbers: a difference between conditions is the condition's), then measured
   (:mod:`washbench.pilot.identify`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from washbench.cueing import cue_trace
from washbench.errors import WashbenchError
from washbench.flight.manoeuvre import Manoeuvre
from washbench.perception.vestibular import VestibularParams
from washbench.pilot.adapt import LoopSetting, Prediction, adapt, canal_response
from washbench.pilot.forcing import Multisine, base_frequency, lowest_crest_phases, shaped_amplitudes
from washbench.pilot.identify import Decomposition, Identified, decompose, identify, window_spectrum
from washbench.pilot.loop import AIRCRAFT, NO_MOTION, Condition, RunSignals, fly_run
from washbench.pilot.model import PilotContext, PilotModel
from washbench.pilot.multimodal import MultimodalPilot
from washbench.pilot.params import AdaptParams, MultimodalParams
from washbench.pilot.response import Constant, Measured, motion_response
from washbench.pilot.senses import SENSED
from washbench.pilot.task import ForcingFunction, Task, probe_manoeuvre

PilotFactory = Callable[[Any, PilotContext], PilotModel]

PROBE_SCALE = 0.5
"""The calibration probe's amplitudes, as a fraction of the task's (through an integrator of unit gain)."""
CALIBRATION_PASSES = 1
"""Calibration runs with the pilot model after the probe."""


def forcing(task: Task, f: ForcingFunction, which: str) -> Multisine:
    """A forcing function of the task in rad of attitude (amplitudes shaped to its RMS; phases given or of the
    lowest crest factor for the task's seed, a different stream for the target and the disturbance)."""
    w = np.asarray(f.multiples) * base_frequency(task.measurement_s)
    a = shaped_amplitudes(w, math.radians(f.rms_deg), f.shaping.lead_s, f.shaping.lag_s)
    if f.phases_rad is not None:
        phases = np.asarray(f.phases_rad, dtype=float)
    else:
        seed = int(np.random.SeedSequence([task.seed, 1 if which == "target" else 2]).generate_state(1)[0])
        phases = lowest_crest_phases(w, a, task.measurement_s, seed)
    return Multisine(np.asarray(f.multiples), a, phases, task.measurement_s)


def run_seed(task: Task, index: int) -> int:
    """The remnant seed of run ``index`` (the same in every condition)."""
    return int(np.random.SeedSequence([task.seed, 3, index]).generate_state(1)[0])


@dataclass(frozen=True)
class Calibration:
    """What every condition shares: the forcing functions (target in rad; disturbance in control units, scaled
    through the measured controlled element) and that controlled element."""

    target: Multisine
    disturbance: Multisine
    plant: Measured

    def setting(self, task: Task, motion: Measured | Constant, vestibular: VestibularParams) -> LoopSetting:
        """The :class:`washbench.pilot.adapt.LoopSetting` of a condition with motion filter ``motion``."""
        return LoopSetting(
            w_target=self.target.frequencies_radps, a_target=self.target.amplitudes,
            w_disturbance=self.disturbance.frequencies_radps, a_disturbance=self.disturbance.amplitudes,
            plant=self.plant, motion=motion, canals=canal_response(vestibular.canals), dt_s=task.dt_s,
        )  # fmt: skip


def signals_of(r: RunSignals) -> dict[str, np.ndarray]:
    """A run's signals as :func:`washbench.pilot.identify.identify` takes them."""
    return {"error": r.error_rad, "control": r.control, "attitude": r.attitude_rad, "disturbance": r.disturbance,
            "aircraft_rate": r.aircraft_rate_radps, "head_rate": r.head_rate_radps}  # fmt: skip


def _checked(r: RunSignals, task: Task, condition: str, what: str) -> RunSignals:
    if not r.ok:
        raise WashbenchError(f"task {task.name} ({task.aircraft}, {task.axis}), {condition}: {what} did not fly to "
                             f"its end: {r.reason}")  # fmt: skip
    return r


def calibrate(task: Task, manoeuvre: Manoeuvre, params: MultimodalParams, vestibular: VestibularParams,
              settings: AdaptParams) -> tuple[Calibration, MultimodalParams]:  # fmt: skip
    """Step 1 of the module docstring: the calibration and the pilot adapted to the aircraft's own motion (the
    calibration runs fly without the perception noises, for a clean measurement; the adaptation counts them)."""
    target = forcing(task, task.target, "target")
    unit = forcing(task, task.disturbance, "disturbance")
    w_b = base_frequency(task.measurement_s)
    kt, kd = np.asarray(task.target.multiples), np.asarray(task.disturbance.multiples)
    # the probe: the scripted pilot holds the axis, both sets of sines on its command through 1/(j w) (an
    # integrator of unit gain), PROBE_SCALE of the task's amplitude
    probe = Multisine(np.concatenate([target.multiples, unit.multiples]),
                      np.concatenate([target.amplitudes, unit.amplitudes]) * PROBE_SCALE,
                      np.concatenate([target.phases_rad, unit.phases_rad]), task.measurement_s)  # fmt: skip
    probe = probe.scaled(probe.frequencies_radps)
    silent = Multisine(target.multiples, np.zeros_like(target.amplitudes), target.phases_rad, task.measurement_s)
    run = _checked(fly_run(task, probe_manoeuvre(task), Condition(AIRCRAFT), None, silent, probe, vestibular),
                   task, AIRCRAFT, "the calibration probe")  # fmt: skip
    found = identify([signals_of(run)], task.window_steps, w_b, kt, kd)
    plant = Measured(*found.plant())
    calib = Calibration(target, unit.scaled(1.0 / np.abs(plant(unit.frequencies_radps))), plant)
    adapted = adapt(params, calib.setting(task, Constant(1.0), vestibular), settings)[0]
    pilot = adapted.model_copy(update={"visual_noise_rad2s": 0.0, "vestibular_noise_rad2ps": 0.0})
    for _ in range(CALIBRATION_PASSES):  # then in the loop the pilot model flies, adapted to what was measured
        ctx = PilotContext(dt_s=task.dt_s, axis=task.axis, steps=task.steps, seed=run_seed(task, 0))
        run = _checked(fly_run(task, manoeuvre, Condition(AIRCRAFT), MultimodalPilot(pilot, ctx), target,
                               calib.disturbance, vestibular), task, AIRCRAFT, "the calibration run")  # fmt: skip
        found = identify([signals_of(run)], task.window_steps, w_b, kt, kd)
        plant = Measured(*found.plant())
        calib = Calibration(target, unit.scaled(1.0 / np.abs(plant(unit.frequencies_radps))), plant)
        adapted = adapt(params, calib.setting(task, Constant(1.0), vestibular), settings)[0]
        pilot = adapted.model_copy(update={"visual_noise_rad2s": 0.0, "vestibular_noise_rad2ps": 0.0})
    return calib, adapted


def motion_filter(condition: Condition, aircraft_runs: Sequence[RunSignals], task: Task,
                  filter_start: str = "steady") -> Measured | Constant:  # fmt: skip
    """Step 2: the condition's motion filter on the task's axis at every forcing frequency (1 for the aircraft's
    own motion, 0 for none; a washout's from the aircraft condition's head motion cued through it)."""
    if condition.name == AIRCRAFT:
        return Constant(1.0)
    if condition.name == NO_MOTION or condition.washout is None:
        return Constant(0.0)
    axis = SENSED[task.axis][0]
    bins = np.sort(np.concatenate([task.target.multiples, task.disturbance.multiples]))
    ratios = []
    for run in aircraft_runs:
        cols = run.flight.columns
        n = task.steps
        f = np.column_stack([cols["f_x_mps2"], cols["f_y_mps2"], cols["f_z_mps2"]])[:n]
        w = np.radians(np.column_stack([cols["omega_x_degps"], cols["omega_y_degps"], cols["omega_z_degps"]]))[:n]
        trace = cue_trace(f, w, task.dt_s, [condition.washout], None, condition.limits, filter_start)
        sim = window_spectrum(trace[condition.washout.name].head_omega_radps[:, axis], task.window_steps)
        ac = window_spectrum(w[:, axis], task.window_steps)
        ratios.append((sim[bins], ac[bins]))
    sim_mean = np.mean([r[0] for r in ratios], axis=0)
    ac_mean = np.mean([r[1] for r in ratios], axis=0)
    return motion_response(bins * base_frequency(task.measurement_s), sim_mean / ac_mean)


@dataclass
class ConditionResult:
    """One condition measured: the pilot as flown (``params``, the built-in model's, or a plugin's description),
    the prediction the adaptation made (None for a plugin), the motion filter it adapted to, the responses at the
    forcing frequencies, the variance decompositions (error, control, its visual and vestibular parts) and the
    runs."""

    condition: Condition
    params: dict[str, Any]
    prediction: Prediction | None
    motion: Measured | Constant
    identified: Identified
    error: Decomposition
    control: Decomposition
    control_visual: Decomposition | None
    control_vestibular: Decomposition | None
    runs: list[RunSignals] = field(repr=False)

    @property
    def name(self) -> str:
        return self.condition.name


def measure_condition(
    task: Task,
    manoeuvre: Manoeuvre,
    condition: Condition,
    calibration: Calibration,
    vestibular: VestibularParams,
    motion: Measured | Constant,
    *,
    params: MultimodalParams | None = None,
    factory: PilotFactory | None = None,
    plugin_params: Any = None,
    keep_platform: bool = False,
    progress: Callable[[str], None] | None = None,
) -> ConditionResult:
    """Step 3: the built-in model with ``params`` adapted to ``condition`` (``task.adaptation``), or a plugin's
    ``factory(plugin_params, context)`` as it is; ``task.runs`` runs; the measures."""
    prediction = None
    if factory is None:
        base = params if params is not None else MultimodalParams()
        base, prediction = adapt(base, calibration.setting(task, motion, vestibular), task.adaptation)
    w_all = np.sort(np.concatenate([calibration.target.frequencies_radps, calibration.disturbance.frequencies_radps]))
    runs = []
    described: dict[str, Any] = {}
    for i in range(task.runs):
        ctx = PilotContext(dt_s=task.dt_s, axis=task.axis, steps=task.steps, seed=run_seed(task, i),
                           frequencies_radps=w_all, plant=calibration.plant(w_all), motion=motion(w_all))  # fmt: skip
        model: Any = MultimodalPilot(base, ctx) if factory is None else factory(plugin_params, ctx)
        if progress is not None:
            progress(f"{condition.name}: run {i + 1}/{task.runs}")
        run = fly_run(task, manoeuvre, condition, model, calibration.target, calibration.disturbance, vestibular,
                      keep_platform=keep_platform and i == 0)  # fmt: skip
        runs.append(_checked(run, task, condition.name, f"run {i + 1}"))
        describe = getattr(model, "describe", None)
        described = dict(describe()) if describe is not None else {}
    kt, kd = np.asarray(task.target.multiples), np.asarray(task.disturbance.multiples)
    window = task.window_steps
    found = identify([signals_of(r) for r in runs], window, base_frequency(task.measurement_s), kt, kd)

    def parts(key: str) -> Decomposition:
        return decompose([window_spectrum(getattr(r, key), window) for r in runs], window, kt, kd)

    has_parts = factory is None or hasattr(model, "contributions")
    return ConditionResult(
        condition=condition, params=described, prediction=prediction, motion=motion, identified=found,
        error=parts("error_rad"), control=parts("control"),
        control_visual=parts("control_visual") if has_parts else None,
        control_vestibular=parts("control_vestibular") if has_parts else None, runs=runs,
    )  # fmt: skip
