"""Tracking-task files: the YAML schema, its checks, and the manoeuvre JSBSim flies for each run.

A task names the aircraft and where it flies (an air start, as a manoeuvre's), the axis the pilot model controls
(``roll``: bank angle with the ailerons; ``pitch``: pitch angle with the elevator), the two multisine forcing
functions (:mod:`washbench.pilot.forcing`: the target the pilot follows and the disturbance it rejects), the
measurement (``measurement_s`` of every run, after ``run_in_s``; ``runs`` runs), the seed, the pilot model's
parameters and how it adapts. Everything the pilot model does not fly is held by the scripted pilot (``hold``,
as in a manoeuvre's phase): for a roll task the altitude and airspeed with elevator and throttle and zero sideslip
with the rudder; for a pitch task the wings level with the ailerons and zero sideslip, the throttle fixed at trim.
docs/reference/task-format.md lists every key; errors name the file, the line and the field.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import Field, PrivateAttr, create_model

from washbench.errors import WashbenchError, located
from washbench.flight.manoeuvre import Manoeuvre
from washbench.flight.manoeuvre_schema import LATERAL_TARGETS, PITCH_TARGETS, Environment, Hold, Start
from washbench.io.names import Identifier
from washbench.io.yamlio import Loc, StrictModel, format_field_path, line_of, read_yaml, validate_data
from washbench.pilot.params import AdaptParams

#: The published measurement window (Zaal et al. 2009; Pool et al. 2011): 8192 samples at 100 Hz.
MEASUREMENT_S = 81.92
#: The published run-in before it (a run of 90 s).
RUN_IN_S = 8.08

Multiple = Annotated[int, Field(ge=1, le=100_000)]


class Shaping(StrictModel):
    """The amplitude shaping filter ``|(1 + lead_s j w)^2 / (1 + lag_s j w)^2|`` (:mod:`washbench.pilot.forcing`)."""

    lead_s: Annotated[float, Field(ge=0.0, le=10.0)] = 0.1
    """T_1, s."""
    lag_s: Annotated[float, Field(ge=0.0, le=10.0)] = 0.8
    """T_2, s."""


class ForcingFunction(StrictModel):
    """A multisine forcing function: whole numbers of periods in the measurement window, shaped amplitudes."""

    multiples: Annotated[tuple[Multiple, ...], Field(min_length=1, max_length=64)]
    """n_k: each sine's number of periods in the measurement window (frequency n_k 2 pi / measurement_s), rising."""
    rms_deg: Annotated[float, Field(gt=0.0, le=20.0)]
    """RMS of the attitude the signal asks (target) or would cause through the aircraft's dynamics alone
    (disturbance, inserted on the control and scaled by the measured dynamics), deg."""
    shaping: Shaping = Shaping()
    """The amplitude shaping filter."""
    phases_rad: tuple[float, ...] | None = None
    """phi_k, rad (default: of 256 random sets from the task's seed, the one with the lowest crest factor)."""


class TaskFields(StrictModel):
    """The fields of a task file, as the schema states them (:func:`load_task` adds the checks between them)."""

    name: Identifier
    """Identifier of the task (names the result folder)."""
    description: str = ""
    """Free text: what is flown and why."""
    aircraft: Identifier
    """JSBSim model name, as in a manoeuvre (needs a pilot profile for the axes the scripted pilot holds)."""
    pilot_profile: str | None = None
    """Path of the scripted pilot's profile YAML, relative to this file (default: searched for the aircraft)."""
    axis: Literal["roll", "pitch"]
    """The axis the pilot model flies: roll (bank angle, ailerons) or pitch (pitch angle, elevator)."""
    rate_hz: Annotated[int, Field(ge=50, le=1000)] = 100
    """Flight-model rate, Hz; measurement_s and run_in_s must be whole numbers of steps."""
    start: Start
    """Where the flight starts: an air start (as a manoeuvre's start.air)."""
    environment: Environment = Environment()
    """Wind and turbulence (as a manoeuvre's)."""
    hold: Hold = Hold()
    """What the scripted pilot holds on the other axes (as a manoeuvre phase's hold, without a target on the task's
    axis)."""
    measurement_s: Annotated[float, Field(gt=0.0, le=600.0)] = MEASUREMENT_S
    """T_m: the measurement window of every run, s (the forcing functions' period)."""
    run_in_s: Annotated[float, Field(ge=0.0, le=120.0)] = RUN_IN_S
    """Flown before the window and not measured, s."""
    fade_in_s: Annotated[float, Field(ge=0.0, le=60.0)] = 4.0
    """The forcing functions rise from zero over this time at the start of each run (within the run-in), s."""
    runs: Annotated[int, Field(ge=1, le=50)] = 5
    """Runs per condition, averaged in the frequency domain."""
    seed: Annotated[int, Field(ge=0, lt=2**31)] = 0
    """Seed of the forcing functions' phases (when not given) and of the pilot model's remnant."""
    target: ForcingFunction
    """The target forcing function f_t (attitude the pilot follows)."""
    disturbance: ForcingFunction
    """The disturbance forcing function f_d (on the control, rejected)."""
    pilot: dict[str, Any] = Field(default_factory=dict)
    """The pilot model's parameters (the built-in model: docs/pilot-model.md; a plugin: its Params)."""
    adaptation: AdaptParams = AdaptParams()
    """How the pilot model adapts to each condition."""


class Task(TaskFields):
    """A checked task file (:func:`load_task`): the fields, and where it came from (:attr:`source`)."""

    _source: Path | None = PrivateAttr(default=None)
    _lines: dict[Loc, int] = PrivateAttr(default_factory=dict)
    _aircraft_dirs: tuple[Path, ...] = PrivateAttr(default=())

    @property
    def source(self) -> Path | None:
        """The task file (None when built in Python)."""
        return self._source

    @property
    def lines(self) -> dict[Loc, int]:
        """The task file's YAML line map (field path -> line)."""
        return self._lines

    @property
    def dt_s(self) -> float:
        return 1.0 / self.rate_hz

    @property
    def window_steps(self) -> int:
        return round(self.measurement_s * self.rate_hz)

    @property
    def run_in_steps(self) -> int:
        return round(self.run_in_s * self.rate_hz)

    @property
    def steps(self) -> int:
        """Samples of one run (run-in and window)."""
        return self.run_in_steps + self.window_steps


def check_task(task: TaskFields, path: Path, lines: dict[Loc, int]) -> list[str]:
    """The problems a schema cannot see, one located line each."""
    out: list[str] = []

    def add(loc: Loc, problem: str) -> None:
        out.append(located(path, problem, line=line_of(lines, loc), field=format_field_path(loc)))

    for key in ("measurement_s", "run_in_s"):
        steps = getattr(task, key) * task.rate_hz
        if abs(steps - round(steps)) > 1e-6:
            add((key,), f"must be a whole number of flight-model steps at {task.rate_hz} Hz (got {steps:.6g} steps)")
    if task.start.air is None:
        add(("start",), "a task starts in the air (start.air)")
    if task.fade_in_s > task.run_in_s:
        add(("fade_in_s",), f"must not exceed run_in_s ({task.run_in_s:g} s): the window is measured at full amplitude")
    nyquist = math.pi * task.rate_hz
    w_b = 2.0 * math.pi / task.measurement_s
    for which in ("target", "disturbance"):
        f: ForcingFunction = getattr(task, which)
        m = f.multiples
        if list(m) != sorted(set(m)):
            add((which, "multiples"), "must rise, each number once")
        if m and m[-1] * w_b > nyquist / 4.0:
            add((which, "multiples"), f"{m[-1]} periods in the window is {m[-1] * w_b:.3g} rad/s, beyond a quarter "
                f"of the Nyquist frequency ({nyquist / 4.0:.3g} rad/s)")  # fmt: skip
        if f.phases_rad is not None and len(f.phases_rad) != len(m):
            add((which, "phases_rad"), f"{len(f.phases_rad)} phases for {len(m)} sines")
    shared = sorted(set(task.target.multiples) & set(task.disturbance.multiples))
    if shared:
        add(("disturbance", "multiples"), f"shares {', '.join(map(str, shared))} with the target's: each frequency "
            "must belong to one forcing function")  # fmt: skip
    own = LATERAL_TARGETS if task.axis == "roll" else PITCH_TARGETS
    for key in own:
        if getattr(task.hold, key) is not None:
            add(("hold", key), f"the pilot model flies the {task.axis} axis: the scripted pilot holds no {key} here")
    if task.axis == "pitch" and task.hold.airspeed_kts is not None and task.hold.throttle is None:
        add(("hold", "airspeed_kts"), "a pitch task flies with the throttle fixed (the airspeed is free)")
    return out


def manoeuvre_data(task: TaskFields, probe: bool = False) -> dict[str, Any]:
    """The manoeuvre one run flies: the task's start and environment, one phase of run-in plus window with the
    task's axis free (its control fixed at trim; the pilot model's control is added to it each step). ``probe``:
    the scripted pilot holds the task's axis too (wings level; the start's altitude), for the first measurement
    of the controlled element (:func:`washbench.pilot.measure.calibrate`)."""
    inputs: dict[str, Any] = {}
    if not probe:
        inputs = {"aileron": {"free": True}} if task.axis == "roll" else {"elevator": {"free": True}}
    if task.axis == "pitch" and task.hold.throttle is None:
        inputs["throttle"] = {"free": True}
    hold = task.hold.model_dump(exclude_none=True)
    if (task.axis == "pitch" or probe) and not any(k in hold for k in LATERAL_TARGETS):
        hold["wings_level"] = True
    if probe and task.axis == "pitch" and task.start.air is not None:
        hold["altitude_ft"] = task.start.air.altitude_ft
    data: dict[str, Any] = {
        "name": task.name,
        "description": f"tracking task {task.name}: run-in and measurement window",
        "aircraft": task.aircraft,
        "rate_hz": task.rate_hz,
        "start": task.start.model_dump(exclude_none=True),
        "environment": task.environment.model_dump(exclude_none=True),
        "phases": [{"name": "track", "hold": hold, **({"inputs": inputs} if inputs else {}),
                    "until": {"duration_s": task.run_in_s + task.measurement_s,
                              "timeout_s": task.run_in_s + task.measurement_s + 1.0}}],
    }  # fmt: skip
    if task.pilot_profile is not None:
        data["pilot_profile"] = task.pilot_profile
    return data


def load_task(path: str | Path, aircraft_dirs: Sequence[Path] = ()) -> tuple[Task, Manoeuvre]:
    """Read and check a task file; return it with the manoeuvre each run flies (its aircraft found along the
    search path of :mod:`washbench.io.paths`, as a manoeuvre's; :func:`probe_manoeuvre` the calibration's). Raises
    WashbenchError holding every problem (one located line each)."""
    path = Path(path)
    data, lines = read_yaml(path)
    task = validate_data(path, data, lines, Task)
    problems = check_task(task, path, lines)
    if problems:
        raise WashbenchError(problems[0], problems[1:])
    context = {"source": path, "lines": lines, "aircraft_dirs": tuple(aircraft_dirs)}
    manoeuvre = validate_data(path, manoeuvre_data(task), lines, Manoeuvre, context=context)
    task._source, task._lines = path, lines
    task._aircraft_dirs = tuple(aircraft_dirs)
    return task, manoeuvre


def probe_manoeuvre(task: Task) -> Manoeuvre:
    """The manoeuvre of the calibration's probe (:func:`manoeuvre_data` with ``probe=True``)."""
    path = task.source or Path(f"<task {task.name}>")
    context = {"source": path, "lines": task.lines, "aircraft_dirs": task._aircraft_dirs}
    return validate_data(path, manoeuvre_data(task, probe=True), task.lines, Manoeuvre, context=context)


def pilot_params(task: Task, model: type[Any] | None) -> Any:
    """The task's ``pilot:`` section validated by ``model`` (a pilot model's ``Params``, a pydantic model; None: it
    takes none), errors located at ``pilot.<field>`` in the task file."""
    path = task.source or Path(f"<task {task.name}>")
    if model is None:
        if task.pilot:
            raise WashbenchError(located(path, "this pilot model takes no parameters", field="pilot"))
        return None
    wrapper = create_model("PilotSection", __base__=StrictModel, pilot=(model, ...))
    return validate_data(path, {"pilot": dict(task.pilot)}, task.lines, wrapper).pilot
