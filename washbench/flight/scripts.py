"""JSBSim's own scripts as manoeuvres: the script's aircraft, initial conditions and events fly it.

``washbench run SCRIPT.xml`` flies a JSBSim script (``<runscript>``: ``<use aircraft=... initialize=...>``,
``<run start end dt>`` with its events) instead of a YAML manoeuvre. There is no scripted pilot: the
script's events (and the aircraft's own autopilot, where it has one) are the pilot. The recorder is the
manoeuvres' (:mod:`washbench.flight.fly`): sample ``k`` is the state at ``t = k * dt``, and JSBSim's
eyepoint acceleration ``accelerations/a-pilot-*`` (computed before the forces of the step) read after
step ``k + 1`` belongs to sample ``k`` (the one-frame lag removed).

Run segments: a script that resets (``simulation/reset``; JSBSim's time jumps back to 0) gives one
segment per run, named ``run_1``, ``run_2``, ... The sample before a reset has no pilot acceleration
of its own (the step that would have produced it reset the model) and is dropped; the state after the
reset is sample 0 of the next segment.

Crash monitor: :meth:`washbench.flight.monitor.Monitor.for_script` (non-finite state, an airframe
contact point on the ground while no landing gear is, the centre of gravity below the ground, load
factors beyond any aircraft's). A
crash stops the flight; what was recorded up to it is kept and the segment is ``failed`` with the time
and cause.

The scripts shipped in the jsbsim package (``jsbsim.get_default_root_dir()/scripts``) are found by name
(:func:`bundled_script`); their aircraft are JSBSim's own. The script's ``<output>`` directives are
neutralised (they would write into the current folder or open sockets; :mod:`washbench.flight.jsbsim_xml`), and
its console messages are silenced.
"""

from __future__ import annotations

import math
import re
import tempfile
from array import array
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from washbench.errors import WashbenchError, located
from washbench.flight.columns import FLIGHT_COLUMNS
from washbench.flight.console import quiet_stdout
from washbench.flight.fly import FPS_TO_KT, FT_S2_TO_M_S2, R2D, StepHook
from washbench.flight.jsbsim_xml import aircraft_for_jsbsim, read_xml, script_for_jsbsim
from washbench.flight.manoeuvre import aircraft_path
from washbench.flight.monitor import Monitor
from washbench.io.atomic import atomic_path, write_text_atomic
from washbench.io.budget import check_samples
from washbench.io.paths import jsbsim_root
from washbench.io.progress import duration_text
from washbench.io.result_files import FLIGHT_FILE, FLIGHT_JSON

SEGMENT_PREFIX = "run_"

#: Names of a script flight's ``flight.parquet`` columns, in order: a subset of a manoeuvre's
#: (:data:`washbench.flight.columns.FLIGHT_COLUMNS`), with the same meanings.
SCRIPT_COLUMN_NAMES: tuple[str, ...] = (
    "t_s", "f_x_mps2", "f_y_mps2", "f_z_mps2", "omega_x_degps", "omega_y_degps", "omega_z_degps",
    "phi_deg", "theta_deg", "psi_deg", "alpha_deg", "beta_deg", "vc_kts", "gs_kts", "altitude_ft", "h_agl_ft",
    "nz", "wow",
)  # fmt: skip
#: (name, description) of those columns; time counts from the segment's start.
SCRIPT_COLUMNS: tuple[tuple[str, str], ...] = tuple(
    (n, "time since the segment's start, s (k * dt)" if n == "t_s" else dict(FLIGHT_COLUMNS)[n])
    for n in SCRIPT_COLUMN_NAMES
)

_STATE = (
    "attitude/phi-rad",
    "attitude/theta-rad",
    "attitude/psi-rad",
    "velocities/p-rad_sec",
    "velocities/q-rad_sec",
    "velocities/r-rad_sec",
    "aero/alpha-rad",
    "aero/beta-rad",
    "velocities/vc-kts",
    "velocities/vg-fps",
    "position/h-sl-ft",
    "position/h-agl-ft",
    "simulation/sim-time-sec",
)
_AFTER = ("accelerations/a-pilot-x-ft_sec2", "accelerations/a-pilot-y-ft_sec2", "accelerations/a-pilot-z-ft_sec2",
          "accelerations/Nz")  # fmt: skip


@dataclass(frozen=True)
class ScriptInfo:
    """What a JSBSim script file says about itself: ``name`` (the file stem, names the result folder),
    ``aircraft`` and ``initialize`` (the model and its initial-conditions file), ``dt_s`` and ``end_s``."""

    path: Path
    name: str
    aircraft: str
    initialize: str
    dt_s: float
    end_s: float
    aircraft_root: Path
    description: str = ""


@dataclass
class ScriptSegment:
    """One run of a script: its recorded columns (:data:`SCRIPT_COLUMNS`), status and reason."""

    name: str
    columns: dict[str, np.ndarray]
    status: str = "ok"
    reason: str = ""

    @property
    def ok(self) -> bool:
        return self.status == "ok"

    @property
    def n(self) -> int:
        return len(self.columns["t_s"])


@dataclass
class ScriptFlight:
    """A flown script: its info, the FDM step and one :class:`ScriptSegment` per run."""

    info: ScriptInfo
    dt_s: float
    segments: list[ScriptSegment] = field(default_factory=list)
    stopped_by_limit: bool = False


DEFAULT_MAX_TIME_S = 1200.0
"""A JSBSim script is flown for at most this much simulated time [s] unless ``--max-time-s`` says otherwise: 20 min
(144,000 steps at 120 Hz, up to about 230 MB of results with three washouts) covers the aircraft tests among JSBSim's
scripts; the orbits and balloon flights (3 h and more, up to 600,000 s) would write gigabytes."""
LONG_RUN_S = 120.0
"""A script flown for longer than this [s] is announced with its expected size and duration before it starts."""
BYTES_PER_STEP = 260.0
BYTES_PER_STEP_WASHOUT = 290.0
BYTES_PER_STEP_WASHOUT_RECORDING = 160.0
"""Result size per recorded step, at most: flight.parquet and the aircraft's traces, then per washout its traces and
its part of recording.rrd. Measured on ``c172_cruise_8K.xml`` for 20 s (2,400 steps, three washouts, a gust:
4.0 MB, 1,650 bytes a step); smooth flights compress better (``ball.xml``, 60 s at 100 Hz: 790 bytes a step)."""
STEPS_PER_S = 750.0
"""Steps flown, cued and written per second of wall time with three washouts and a recording, start-up included,
measured on this project's 2-core machine under load (``ball.xml``, 6,000 steps: 8.1 s): an order of magnitude for
the announcement only."""


@dataclass(frozen=True)
class ScriptPlan:
    """What flying a script will take: ``time_s`` simulated (its ``<run end>`` or the cap), ``steps``,
    ``size_bytes`` of results (estimated), ``wall_s`` (estimated) and whether the cap cut the script short."""

    info: ScriptInfo
    time_s: float
    steps: int
    size_bytes: float
    wall_s: float
    capped: bool

    @property
    def long(self) -> bool:
        return self.capped or self.time_s > LONG_RUN_S

    def text(self) -> str:
        """One line: what will be flown, how big and how long, and how to change it."""

        mb = self.size_bytes / 1e6
        line = (
            f"{self.info.name}: flying {duration_text(self.time_s)} simulated ({self.steps:,} steps of "
            f"{self.info.dt_s:.6g} s): up to about {_mb(mb)} MB of results and {duration_text(self.wall_s)} "
            "(estimated)"
        )
        if self.capped:
            whole = self.info.end_s
            line += (
                f"; the script runs {duration_text(whole)} ({whole:g} s): stopped at the default cap of "
                f"{DEFAULT_MAX_TIME_S:g} s, --max-time-s {whole:g} flies it all (up to about "
                f"{_mb(self.size_bytes * whole / self.time_s / 1e6)} MB)"
            )
        return line


def _mb(x: float) -> str:
    """Megabytes to two significant digits below 10, whole (with thousands separators) above."""
    return f"{x:.2g}" if x < 10 else f"{x:,.0f}"


def plan_limit_s(max_time_s: float | None) -> float:
    """The simulated time a script is flown for at most: ``--max-time-s``, else :data:`DEFAULT_MAX_TIME_S`."""
    return DEFAULT_MAX_TIME_S if max_time_s is None else max_time_s


def script_plan(info: ScriptInfo, max_time_s: float | None, washouts: int = 3, recording: bool = True) -> ScriptPlan:
    """The plan of flying ``info`` with ``--max-time-s`` ``max_time_s`` (None: up to :data:`DEFAULT_MAX_TIME_S`)."""
    capped = max_time_s is None and info.end_s > DEFAULT_MAX_TIME_S
    limit = DEFAULT_MAX_TIME_S if max_time_s is None else max_time_s
    time_s = min(info.end_s, limit)
    steps = round(time_s / info.dt_s)
    per_washout = BYTES_PER_STEP_WASHOUT + (BYTES_PER_STEP_WASHOUT_RECORDING if recording else 0.0)
    per_step = BYTES_PER_STEP + washouts * per_washout
    return ScriptPlan(info, time_s, steps, steps * per_step, steps * washouts / 3.0 / STEPS_PER_S, capped)


def scripts_dir() -> Path:
    """The scripts shipped in the jsbsim package."""
    return jsbsim_root() / "scripts"


def is_runscript(path: Path) -> bool:
    """True for an XML file whose root element is a JSBSim ``<runscript>`` (cheap: reads the first element; no
    entity is expanded before it)."""
    import xml.etree.ElementTree as ET

    try:
        for _, elem in ET.iterparse(path, events=("start",)):
            return elem.tag == "runscript"
    except (ET.ParseError, OSError):
        return False
    return False


def bundled_scripts() -> list[str]:
    """The names of the scripts shipped with JSBSim (files whose root element is ``<runscript>``)."""
    return sorted(p.stem for p in scripts_dir().glob("*.xml") if is_runscript(p))


def bundled_script(name: str) -> Path:
    """A script shipped with JSBSim by name (``c1723`` or ``c1723.xml``); WashbenchError with the closest names (or
    all of them) if unknown or not a script."""
    stem = name[:-4] if name.endswith(".xml") else name
    path = scripts_dir() / f"{stem}.xml"
    if not path.is_file() or not is_runscript(path):
        import difflib

        known = bundled_scripts()
        close = difflib.get_close_matches(stem, known, n=3, cutoff=0.6)
        hint = f"did you mean {', '.join(close)}?" if close else f"the {len(known)} scripts: {', '.join(known)}"
        if path.is_file():
            raise WashbenchError(f"--jsbsim-scripts: {name!r} ships with JSBSim but is not a script (no <runscript>); "
                                 f"{hint}")  # fmt: skip
        raise WashbenchError(f"--jsbsim-scripts: no script {name!r} ships with JSBSim; {hint}")
    return path


def is_script(path: Path) -> bool:
    """True for a ``.xml`` file (a JSBSim script), as opposed to a YAML manoeuvre."""
    return path.suffix.lower() == ".xml"


def load_script_info(path: str | Path, aircraft_dirs: Sequence[Path] = ()) -> ScriptInfo:
    """Read a script's header; WashbenchError (file, line, what) if it is not a usable JSBSim script.

    The aircraft is looked up along washbench's search path (``aircraft_dirs``, an ``aircraft/`` folder next
    to the script, washbench's bundled aircraft, JSBSim's own)."""

    path = Path(path)
    root = read_xml(path)
    if root.tag != "runscript":
        raise WashbenchError(located(path, f"not a JSBSim script: the root element is <{root.tag}>, not <runscript>"))
    use = root.find("use")
    run = root.find("run")
    if use is None or not use.get("aircraft"):
        raise WashbenchError(located(path, "<use aircraft=...> is missing: which aircraft does the script fly?"))
    if run is None:
        raise WashbenchError(located(path, "<run> is missing"))
    aircraft = str(use.get("aircraft"))
    root_dir = aircraft_path(aircraft, path, aircraft_dirs)
    if root_dir is None:
        raise WashbenchError(
            located(path, f"<use aircraft={aircraft!r}>: unknown aircraft (neither washbench's nor JSBSim's)")
        )
    try:
        dt = float(run.get("dt", "nan"))
        end = float(run.get("end", "nan"))
    except ValueError:
        raise WashbenchError(located(path, "<run>: dt and end must be numbers")) from None
    if not (dt > 0.0 and math.isfinite(dt)) or not (end > 0.0 and math.isfinite(end)):
        raise WashbenchError(located(path, f"<run>: needs dt > 0 and end > 0 s, got dt={dt:g}, end={end:g}"))
    desc = (root.findtext("description") or root.get("name") or "").strip()
    name = re.sub(r"[^A-Za-z0-9_-]", "_", path.stem)
    return ScriptInfo(path, name, aircraft, str(use.get("initialize", "")), dt, end, root_dir, " ".join(desc.split()))


def _structure_contacts(fdm: object) -> list[object]:
    """``contact/unit[i]/WOW`` nodes of the airframe's structural contact points (not landing gear)."""
    pm = fdm.get_property_manager()  # type: ignore[attr-defined]
    out = []
    i = 0
    while pm.hasNode(f"contact/unit[{i}]/WOW") or pm.hasNode(f"gear/unit[{i}]/WOW"):
        if pm.hasNode(f"contact/unit[{i}]/WOW") and not pm.hasNode(f"gear/unit[{i}]/WOW"):
            out.append(pm.get_node(f"contact/unit[{i}]/WOW"))
        i += 1
    return out


def _make_fdm(info: ScriptInfo, output_dir: Path) -> object:
    """The FDM with the script loaded and initialised. The script's and the aircraft's ``<output>`` directives
    are neutralised before JSBSim reads them (:mod:`washbench.flight.jsbsim_xml`: copies in ``output_dir``, a
    temporary folder, each directive a CSV file there logging nothing; the properties they create stay for the
    script's events), and output is switched off, so JSBSim writes nothing and opens no socket."""
    import jsbsim

    root = aircraft_for_jsbsim(info.aircraft_root, info.aircraft, output_dir / "aircraft")
    script = script_for_jsbsim(info.path.resolve(), output_dir)
    with quiet_stdout():
        fdm = jsbsim.FGFDMExec(str(jsbsim_root()), None)
        fdm.set_debug_level(0)
        fdm.set_output_path(str(output_dir))
        fdm.set_aircraft_path(str(root))
        try:
            ok = fdm.load_script(str(script))
        except Exception as exc:  # JSBSim raises plain exceptions on broken scripts or models
            raise WashbenchError(located(info.path, f"JSBSim could not load the script ({exc})")) from None
        if not ok:
            raise WashbenchError(located(info.path, "JSBSim could not load the script"))
        fdm.disable_output()
        fdm.run_ic()
    return fdm


def fly_script(
    path: str | Path,
    *,
    max_time_s: float | None = None,
    segment_hook: Callable[[int, float], StepHook | None] | None = None,
    aircraft_dirs: Sequence[Path] = (),
) -> ScriptFlight:
    """Fly a JSBSim script to its end, a crash or ``max_time_s`` of simulated time (summed over segments).

    ``segment_hook(i, dt_s)`` is called when segment ``i`` starts and may return a step hook
    ``hook(k, f_mps2, omega_radps)`` called once per recorded sample of it, in order (eyepoint specific
    force m/s^2 and body rates rad/s, body axes x forward, y right, z down).
    """

    info = load_script_info(path, aircraft_dirs)
    span_s = min(info.end_s, math.inf if max_time_s is None else max_time_s)
    check_samples(span_s / info.dt_s, f"<run end={info.end_s:g} dt={info.dt_s:g}> (give --max-time-s)", info.path)
    with tempfile.TemporaryDirectory(prefix="washbench-jsbsim-") as junk:
        return _fly(info, _make_fdm(info, Path(junk)), max_time_s, segment_hook)


def _fly(
    info: ScriptInfo,
    fdm: object,
    max_time_s: float | None,
    segment_hook: Callable[[int, float], StepHook | None] | None,
) -> ScriptFlight:
    """The recording loop of :func:`fly_script`."""
    dt = float(fdm.get_delta_t())  # type: ignore[attr-defined]
    pm = fdm.get_property_manager()  # type: ignore[attr-defined]
    missing = [n for n in (*_STATE, *_AFTER) if not pm.hasNode(n)]
    if missing:
        raise WashbenchError(located(info.path, f"the model lacks the properties {', '.join(missing)}"))
    gets = [pm.get_node(n).get_double_value for n in _STATE]
    ax_get, ay_get, az_get, nz_get = (pm.get_node(n).get_double_value for n in _AFTER)
    wow_get = pm.get_node("gear/wow").get_double_value if pm.hasNode("gear/wow") else (lambda: 0.0)
    structure = [n.get_double_value for n in _structure_contacts(fdm)]
    monitor = Monitor.for_script()
    flight = ScriptFlight(info=info, dt_s=dt)
    limit_steps = math.inf if max_time_s is None else round(max_time_s / dt)
    ncol = len(SCRIPT_COLUMN_NAMES)
    run = fdm.run  # type: ignore[attr-defined]

    def new_segment() -> tuple[array, StepHook | None]:
        return array("d"), segment_hook(len(flight.segments), dt) if segment_hook is not None else None

    def close(rows: array, status: str = "ok", reason: str = "") -> None:
        data = np.frombuffer(rows, dtype=np.float64).reshape(-1, ncol) if rows else np.zeros((0, ncol))
        cols = {n: np.ascontiguousarray(data[:, i]) for i, n in enumerate(SCRIPT_COLUMN_NAMES)}
        cols["wow"] = cols["wow"].astype(np.int8)
        flight.segments.append(ScriptSegment(f"{SEGMENT_PREFIX}{len(flight.segments) + 1}", cols, status, reason))

    rows, hook = new_segment()
    k = 0
    total = 0
    with quiet_stdout():
        while True:
            phi, theta, psi, p, q, r, alpha, beta, vc, vg, h, agl, t_sim = (g() for g in gets)
            wow = wow_get() > 0.5
            sw = 0.0
            if not wow:  # on its gear, a tail skid or wing tip scraping is no crash (c172_cross_wind's oscillation)
                for g in structure:
                    sw += g()
            t = k * dt
            problem = monitor.state(phi + theta + p + q + r + vc + h + agl + alpha, vc, alpha, agl, wow, sw)
            if problem:
                close(rows, "failed", f"t={t:.2f} s: {problem}")
                return flight
            if total >= limit_steps:
                flight.stopped_by_limit = True
                break
            try:
                going = run()
            except Exception as exc:  # JSBSim raises on a script event it cannot do (a property its build lacks)
                close(rows, "failed", f"t={t:.2f} s: JSBSim stopped the script: {str(exc).strip()}")
                return flight
            if not going:
                break  # the script's end: the last state has no pilot acceleration of its own
            total += 1
            if fdm.get_sim_time() < t_sim - 0.5 * dt:  # type: ignore[attr-defined]
                close(rows)  # a reset: the sample before it is dropped, the state now is the next run's sample 0
                rows, hook = new_segment()
                k = 0
                continue
            fx, fy, fz = ax_get() * FT_S2_TO_M_S2, ay_get() * FT_S2_TO_M_S2, az_get() * FT_S2_TO_M_S2
            nz = nz_get()
            rows.extend((t, fx, fy, fz, p * R2D, q * R2D, r * R2D, phi * R2D, theta * R2D, psi * R2D % 360.0,
                         alpha * R2D, beta * R2D, vc, vg * FPS_TO_KT, h, agl, nz, 1.0 if wow else 0.0))  # fmt: skip
            if hook is not None:
                hook(k, np.array((fx, fy, fz)), np.array((p, q, r)))
            if not wow:
                problem = monitor.load_factor(nz)
                if problem:
                    close(rows, "failed", f"t={t:.2f} s: {problem}")
                    return flight
            k += 1
    close(rows)
    return flight


def write_script_flight(out_dir: Path, flight: ScriptFlight, seg: ScriptSegment) -> None:
    """``flight.parquet`` (:data:`SCRIPT_COLUMNS`) and ``flight.json`` of one segment, atomically."""
    import json

    import pyarrow as pa
    import pyarrow.parquet as pq

    info = flight.info
    table = pa.table({n: seg.columns[n] for n in SCRIPT_COLUMN_NAMES})
    table = table.replace_schema_metadata({"washbench.script": str(info.path), "washbench.aircraft": info.aircraft})
    with atomic_path(out_dir / FLIGHT_FILE) as tmp:
        pq.write_table(table, tmp)
    doc = {
        "name": info.name,
        "aircraft": info.aircraft,
        "script_file": str(info.path),
        "description": info.description,
        "initialize": info.initialize,
        "segment": seg.name,
        "segments": len(flight.segments),
        "status": seg.status,
        "reason": seg.reason,
        "dt_s": flight.dt_s,
        "samples": seg.n,
        "duration_s": float(seg.columns["t_s"][-1]) if seg.n else 0.0,
        "stopped_by_time_limit": flight.stopped_by_limit,
    }
    write_text_atomic(out_dir / FLIGHT_JSON, json.dumps(doc, indent=2) + "\n")
