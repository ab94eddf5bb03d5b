"""Fly a manoeuvre: JSBSim + scripted pilot + recorder + monitor, and write the results.

Time base: sample ``k`` is the state at ``t = k * dt``. JSBSim's eyepoint acceleration
(``accelerations/a-pilot-*``) and ``accelerations/Nz`` are computed before the forces of the
step, so they lag one frame: the value read after step ``k + 1`` belongs to sample ``k``.
The loop therefore reads the state at ``k``, runs the pilot, steps the FDM, then reads the
accelerations and completes row ``k``.

Per step, the Python loop reads the JSBSim properties (the accelerations the last step produced and the state
now) into the slots of :mod:`washbench.flight.stepper` with one ``struct.pack_into``, makes one compiled call
(which completes the last row, runs the monitor's checks, the events, the phase's end conditions and the
scripted pilot, and writes the new row into a preallocated array), writes the five commands and steps JSBSim.
What needs Python (a phase start, an event's time, a failure's message, open-loop inputs, the mixture schedule,
the hooks, progress) is asked for by the call's return code. Measured by ``bench/marginal_bench.py``.
"""

from __future__ import annotations

import json
import math
import sys
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from washbench.errors import WashbenchError
from washbench.flight import stepper as st
from washbench.flight.checks import evaluate
from washbench.flight.columns import COLUMN_NAMES
from washbench.flight.fdm import make_fdm
from washbench.flight.manoeuvre import Manoeuvre, load_manoeuvre
from washbench.flight.manoeuvre_schema import Until
from washbench.flight.monitor import Monitor
from washbench.flight.openloop import OpenLoop
from washbench.flight.pilot import Pilot
from washbench.flight.profile import load_profile
from washbench.io.atomic import atomic_path, write_text_atomic
from washbench.io.outfolder import result_set
from washbench.io.provenance import build_provenance, parquet_metadata
from washbench.io.result_files import FLIGHT_FILE, FLIGHT_JSON

FT_S2_TO_M_S2 = 0.3048
R2D = 180.0 / math.pi
FPS_TO_KT = 3600.0 * 0.3048 / 1852.0

StepHook = Callable[[int, np.ndarray, np.ndarray], None]
BlockHook = Callable[[int, np.ndarray, np.ndarray], None]
CommandHook = Callable[[int, np.ndarray, tuple[float, ...]], tuple[float, ...]]

#: Properties read every step (verified to exist at start-up: JSBSim ignores typos silently).
STATE_PROPERTIES = (
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
    "flight-path/psi-gt-rad",
    "velocities/h-dot-fps",
    "position/h-sl-ft",
    "position/h-agl-ft",
    "position/lat-geod-rad",
    "position/long-gc-rad",
    "gear/wow",
    "fcs/flap-pos-deg",
    "propulsion/engine/engine-rpm",
    "accelerations/a-pilot-x-ft_sec2",
    "accelerations/a-pilot-y-ft_sec2",
    "accelerations/a-pilot-z-ft_sec2",
    "accelerations/Nz",
    "velocities/vtrue-kts",
)
CONTROL_PROPERTIES = (
    "fcs/aileron-cmd-norm",
    "fcs/elevator-cmd-norm",
    "fcs/rudder-cmd-norm",
    "fcs/steer-cmd-norm",
    "fcs/throttle-cmd-norm",
    "fcs/mixture-cmd-norm",
    "fcs/flap-cmd-norm",
    "fcs/left-brake-cmd-norm",
    "fcs/right-brake-cmd-norm",
)

_ROWS_FIRST = 1 << 14
"""Rows allocated at the start (2 min 16 s at 120 Hz); the array doubles when full."""
_NZ, _AIL = COLUMN_NAMES.index("nz"), COLUMN_NAMES.index("aileron")
_TOTAL_SLOTS = (st.I_PHI, st.I_THETA, st.I_P, st.I_Q, st.I_R, st.I_VC, st.I_H, st.I_AGL, st.I_ALPHA)
"""The state summed for the monitor's non-finite check, in the order the compiled step sums it."""


@dataclass
class FlightResult:
    """A flown manoeuvre: the recorded columns (flight.parquet) and the summary (flight.json)."""

    name: str
    aircraft: str
    dt_s: float
    columns: dict[str, np.ndarray]
    phases: list[tuple[str, float, float]]
    checks: list[tuple[str, float, str, bool]]
    status: str  # "ok" or "failed"
    reason: str = ""
    events: dict[str, list[float]] = field(default_factory=dict)
    probes: dict[str, np.ndarray] = field(default_factory=dict)  # fly(probes=...): JSBSim properties after each step

    @property
    def ok(self) -> bool:
        return self.status == "ok"

    @property
    def t_s(self) -> np.ndarray:
        """The time base, s (``k * dt``): the ``t_s`` column."""
        return self.columns["t_s"]

    @property
    def duration_s(self) -> float:
        """Time of the last recorded sample, s (0 when nothing was recorded)."""
        return float(self.t_s[-1]) if len(self.t_s) else 0.0


def _nodes(fdm: object, names: tuple[str, ...]) -> list[object]:
    pm = fdm.get_property_manager()  # type: ignore[attr-defined]
    missing = [n for n in names if not pm.hasNode(n)]
    if missing:
        raise WashbenchError(f"the JSBSim model lacks the properties {', '.join(missing)}")
    return [pm.get_node(n) for n in names]


def fly(
    manoeuvre: Manoeuvre,
    step_hook: StepHook | None = None,
    progress: bool = False,
    probes: Sequence[str] = (),
    block_hook: BlockHook | None = None,
    block_size: int = 120,
    command_hook: CommandHook | None = None,
) -> FlightResult:
    """Fly ``manoeuvre`` to its end (or to a crash) and return the recording and check results.

    ``step_hook(k, f_mps2, omega_radps)`` is called once per recorded sample, in order, as soon
    as the sample is final (specific force at the eyepoint in m/s^2 and body rates in rad/s,
    body axes x forward, y right, z down). ``block_hook(k0, f_mps2, omega_radps)`` gets the same
    samples ``block_size`` at a time as (M, 3) arrays (samples ``k0 .. k0 + M - 1``; the last block
    may be shorter), without a Python call per sample.
    ``probes`` names JSBSim properties read after each
    step (sample ``k``: the value the step from ``k`` produced, e.g. a surface position), returned
    in ``FlightResult.probes``.
    ``command_hook(k, state, commands) -> commands`` is called at every step that sends commands, after the
    scripted pilot and the phase's open-loop inputs (and after ``step_hook`` got sample ``k - 1``): ``state`` is
    a read-only view of sample ``k``'s attitude and body rates (phi, theta, psi, p, q, r; rad, rad/s) and
    ``commands`` the (aileron, elevator, rudder, throttle) about to be sent; what it returns is sent and recorded
    (a pilot model flying an axis the phase left free, :mod:`washbench.pilot.loop`).
    """
    m = manoeuvre
    profile = load_profile(m.aircraft_files.profile)
    fdm, setup = make_fdm(m, profile)
    dt = m.dt_s
    (phi_get, theta_get, psi_get, p_get, q_get, r_get, alpha_get, beta_get, vc_get, vg_get, trk_get, hdot_get,
     h_get, agl_get, lat_get, lon_get, wow_get, flap_get, rpm_get, ax_get, ay_get, az_get,
     nz_get, vt_get) = [n.get_double_value for n in _nodes(fdm, STATE_PROPERTIES)]  # fmt: skip
    ail_w, elev_w, rud_w, steer_w, thr_w, mix_w, flapc_w, lbrk_w, rbrk_w = _nodes(fdm, CONTROL_PROPERTIES)
    ail_set, elev_set, rud_set = ail_w.set_double_value, elev_w.set_double_value, rud_w.set_double_value
    steer_set, thr_set = steer_w.set_double_value, thr_w.set_double_value
    structure = _nodes(fdm, tuple(f"contact/unit[{i}]/WOW" for i in profile.geometry.structure_contacts))
    struct_gets = [n.get_double_value for n in structure]

    fw, pilot_slots = st.new_slots()  # the loop's slots (washbench.flight.stepper), then the pilot's
    state_now = fw[st.I_PHI : st.I_R + 1]  # sample k's attitude and body rates, for command_hook (a view)
    state_now.flags.writeable = False
    pilot = Pilot(profile, m.runway, dt, pilot_slots)
    pilot.set_controls(ail_w.get_double_value(), elev_w.get_double_value(), rud_w.get_double_value())
    monitor = Monitor.for_profile(profile)
    openloop = OpenLoop(fdm, profile, pilot)
    probe_gets = [n.get_double_value for n in _nodes(fdm, tuple(probes))]
    probe_rows: list[list[float]] = [[] for _ in probe_gets]
    frame = setup.frame
    mix_h_ft, mix_norm = zip(*profile.engine.mixture_schedule, strict=True)  # interpolated once a second
    # airframe contact points: four slots (unused ones read 0; more than four summed into the last)
    padded = [*struct_gets, _zero, _zero, _zero, _zero]
    s0, s1, s2, s3 = *padded[:3], (_summed(struct_gets[3:]) if len(struct_gets) > 4 else padded[3])

    # the loop's slots: constants, then the state the Python loop kept before
    fw[st.F_DT] = dt
    fw[st.F_LAT0], fw[st.F_LON0] = frame.lat0, frame.lon0
    fw[st.F_MLAT], fw[st.F_MLON] = frame.m_per_rad_lat, frame.m_per_rad_lon
    fw[st.F_HAS_RUNWAY] = setup.threshold_ne_m is not None
    fw[st.F_RW_C] = math.cos(setup.runway_heading_rad or 0.0)
    fw[st.F_RW_S] = math.sin(setup.runway_heading_rad or 0.0)
    fw[st.F_VNE], fw[st.F_H_COLLAPSED], fw[st.F_ALPHA_MAX] = monitor.vne, monitor.h_collapsed, monitor.alpha_max
    fw[st.F_NZ_MAX], fw[st.F_NZ_MIN], fw[st.F_SINK_MAX] = monitor.nz_max, monitor.nz_min, monitor.sink_max
    fw[st.F_CG_H] = profile.geometry.cg_height_on_ground_ft
    fw[st.F_ALPHA_STALL_DEG] = profile.limits.alpha_stall_deg
    fw[st.F_MIX_EVERY] = max(1, round(1.0 / dt))
    fw[st.F_BLOCK_SIZE] = block_size if block_hook is not None else 1 << 62
    fw[st.F_EVERY_SAMPLE] = step_hook is not None
    fw[st.F_PROGRESS] = progress
    fw[st.F_IPHASE] = -1.0
    was_wow = wow_get() > 0.5
    fw[st.F_WAS_WOW] = was_wow
    fw[st.F_LIFTED] = not was_wow  # an air start has no lift-off to report
    fw[st.F_NZ_LAST] = 1.0  # load factor of the last sample (before the first step: level flight or at rest)
    fw[st.F_MODE] = st.MODE_STEP
    rows = np.empty((_ROWS_FIRST, len(COLUMN_NAMES)))  # the raw rows (columns converted after the loop), grown x2
    step = st.compiled_flight_step()
    run = fdm.run
    pack_step, unpack_commands = st.PACK_STEP, st.UNPACK_COMMANDS
    inputs_at, commands_at = st.INPUTS_OFFSET, st.COMMANDS_OFFSET

    phases_out: list[tuple[str, float, float]] = []
    events: dict[str, list[float]] = {"touchdown_times_s": [], "touchdown_sinks_fps": [], "liftoff_times_s": []}
    reason = ""
    iphase = -1
    phase_k0 = 0
    u: Until | None = None
    k_sent = 0  # samples handed to block_hook so far
    # progress: overwritten in place on a terminal; otherwise (a log file, CI) a line per phase and every 5 s
    tty = progress and sys.stderr.isatty()
    report_every_s = 0.5 if tty else 5.0
    next_report = time.monotonic() + report_every_s
    nphases = len(m.phases)

    while True:
        # what the last step produced (completes its row) and the state now: one pack, one compiled call
        pack_step(fw, inputs_at, ax_get(), ay_get(), az_get(), nz_get(), flap_get(), rpm_get(), phi_get(),
                  theta_get(), psi_get(), p_get(), q_get(), r_get(), alpha_get(), beta_get(), vc_get(), vg_get(),
                  trk_get(), hdot_get(), h_get(), agl_get(), lat_get(), lon_get(), wow_get(), vt_get(), s0(), s1(),
                  s2(), s3())  # fmt: skip
        code = step(fw, rows)
        if code:  # something for Python: in the order the loop did it
            if code & (st.C_SAMPLE | st.C_BLOCK | st.C_NZ | st.C_PROGRESS):  # the last row is complete
                j = int(fw[st.F_DONE_ROW])
                if code & st.C_SAMPLE:
                    _sample_hook(step_hook, rows, j)
                if code & st.C_BLOCK:
                    k_sent = _send_block(block_hook, rows, k_sent, j + 1)
                if code & st.C_NZ:
                    reason = f"t={j * dt:.2f} s: {monitor.load_factor(float(rows[j, _NZ]))}"
                    break
                if code & st.C_PROGRESS and time.monotonic() > next_report:
                    next_report = time.monotonic() + report_every_s
                    _progress(m.name, iphase, nphases, m.phases[iphase].name, j * dt, tty)
            if code & st.C_FULL:
                grown = np.empty((2 * rows.shape[0], rows.shape[1]))
                grown[: rows.shape[0]] = rows
                rows = grown
                code = step(fw, rows)
            k = int(fw[st.F_SAMPLE])
            t = k * dt
            if code & st.C_TOUCHDOWN:
                events["touchdown_times_s"].append(t)
                events["touchdown_sinks_fps"].append(-float(fw[st.I_HDOT]))
            if code & st.C_LIFTOFF:
                events["liftoff_times_s"].append(t)
            if code & (st.C_STATE | st.C_HARD):
                problem = None
                if code & st.C_STATE:
                    phi, theta, p, q, r, vc, h, agl, alpha = (float(fw[i]) for i in _TOTAL_SLOTS)
                    total = phi + theta + p + q + r + vc + h + agl + alpha
                    problem = monitor.state(total, vc, alpha, agl, bool(fw[st.I_WOW] > 0.5), float(fw[st.F_SW]))
                if code & st.C_TOUCHDOWN:
                    problem = problem or monitor.touchdown(-float(fw[st.I_HDOT]))
                reason = f"t={t:.2f} s: {problem}"
                break
            if code & st.C_TIMEOUT:
                reason = (
                    f"t={t:.2f} s: phase '{m.phases[iphase].name}' did not reach its end condition "
                    f"within {u.timeout_s:g} s"  # type: ignore[union-attr]
                )
                break
            if code & st.C_ADVANCE:
                if iphase >= 0:
                    phases_out.append((m.phases[iphase].name, phase_k0 * dt, t))
                iphase += 1
                if iphase == nphases:
                    fw[st.F_FINAL] = 1.0
                    fw[st.F_ROW_PHASE] = nphases - 1
                else:
                    phase = m.phases[iphase]
                    u = phase.until
                    phase_k0 = k
                    _begin_phase(fw, u, iphase, k)
                    pilot.begin_phase(phase.hold, float(fw[st.I_THETA]), thr_w.get_double_value(), flap_get())
                    openloop.begin_phase(phase.inputs, phase.name)
                    flapc_w.set_double_value(pilot.flaps_cmd)
                    lbrk_w.set_double_value(pilot.brakes)
                    rbrk_w.set_double_value(pilot.brakes)
                    fw[st.F_BRAKES] = pilot.brakes
                    fw[st.F_OPENLOOP] = openloop.active or command_hook is not None
                    if progress:  # a line at each phase start (in place on a terminal)
                        _progress(m.name, iphase, nphases, phase.name, t, tty)
                fw[st.F_MODE] = st.MODE_RESUME
                code = step(fw, rows)  # the pilot's step and the row
                fw[st.F_MODE] = st.MODE_STEP
                if iphase == nphases:  # the last sample: no command sent, one more step for its accelerations
                    run()
                    for get, out in zip(probe_gets, probe_rows, strict=True):
                        out.append(get())
                    pack_step(fw, inputs_at, ax_get(), ay_get(), az_get(), nz_get(), flap_get(), rpm_get(),
                              *[0.0] * (st.NSLOTS - st.I_PHI))  # fmt: skip
                    fw[st.F_MODE] = st.MODE_FINISH
                    code = step(fw, rows)
                    if code & st.C_SAMPLE:
                        _sample_hook(step_hook, rows, int(fw[st.F_DONE_ROW]))
                    if code & st.C_BLOCK:
                        k_sent = _send_block(block_hook, rows, k_sent, int(fw[st.F_DONE_ROW]) + 1)
                    break
            if code & st.C_OPENLOOP:  # the phase's open-loop inputs, on top of or instead of the pilot's commands
                ail, elev, rud, _, thr = unpack_commands(fw, commands_at)
                commands = openloop.apply((k - phase_k0) * dt, ail, elev, rud, thr)
                if command_hook is not None:
                    commands = command_hook(k, state_now, commands)
                fw[st.F_AIL], fw[st.F_ELEV], fw[st.F_RUD], fw[st.F_THR] = commands
                rows[k, _AIL : _AIL + 4] = commands
            if code & st.C_MIX:
                mix_w.set_double_value(float(np.interp(float(fw[st.I_H]), mix_h_ft, mix_norm)))
        ail, elev, rud, steer, thr = unpack_commands(fw, commands_at)
        ail_set(ail)
        elev_set(elev)
        rud_set(rud)
        steer_set(steer)
        thr_set(thr)
        run()
        if probe_gets:
            for get, out in zip(probe_gets, probe_rows, strict=True):
                out.append(get())

    nrows = int(fw[st.F_NROWS])
    if block_hook is not None and nrows > k_sent:
        _send_block(block_hook, rows, k_sent, nrows)
    if reason and 0 <= iphase < nphases:  # the phase the flight stopped in, up to the last recorded sample
        phases_out.append((m.phases[iphase].name, phase_k0 * dt, max(nrows - 1, 0) * dt))
    if tty:
        sys.stderr.write("\r\033[K")
        sys.stderr.flush()

    columns = _columns(rows[:nrows], dt)
    results = evaluate(list(m.checks), columns, phases_out, events, dt) if not reason else []
    checks = [(c.name, c.measured, c.limit, c.passed) for c in results]
    for (phase_name, axis), steps in openloop.clipped.items():  # asked beyond the surface travel: not flown as asked
        checks.append((f"{axis} input within its travel in '{phase_name}'", steps * dt, "0 s clipped", False))
    status = "ok"
    if reason:
        status = "failed"
    elif not all(c[3] for c in checks):
        status = "failed"
        reason = "checks failed: " + ", ".join(
            f"{c[0]}" + (f" ({c[1]:.3g} s clipped at the stop)" if c[2] == "0 s clipped" else "")
            for c in checks
            if not c[3]
        )
    probed = {name: np.array(v) for name, v in zip(probes, probe_rows, strict=True)}
    return FlightResult(m.name, m.aircraft, dt, columns, phases_out, checks, status, reason, events, probed)


def _send_block(hook: BlockHook, rows: np.ndarray, k0: int, n: int) -> int:
    """Give ``hook`` the recorded samples ``k0 .. n - 1`` (f in m/s^2, omega in rad/s); return ``n``."""
    raw = rows[k0:n].copy()
    hook(k0, raw[:, 1:4] * FT_S2_TO_M_S2, raw[:, 4:7])
    return n


def _sample_hook(hook: StepHook, rows: np.ndarray, k: int) -> None:
    """Give ``hook`` sample ``k``: f in m/s^2 and omega in rad/s, body axes."""
    ax, ay, az, p, q, r = rows[k, 1:7].tolist()
    hook(k, np.array((ax * FT_S2_TO_M_S2, ay * FT_S2_TO_M_S2, az * FT_S2_TO_M_S2)), np.array((p, q, r)))


def _zero() -> float:
    """An unused contact point's slot."""
    return 0.0


def _summed(gets: list[Callable[[], float]]) -> Callable[[], float]:
    """The contact points beyond the fourth, read as one sum (only its sign counts: any contact > 0 fails)."""

    def read() -> float:
        total = 0.0
        for g in gets:
            total += g()
        return total

    return read


def _nan_if_none(x: float | None) -> float:
    return math.nan if x is None else x


def _begin_phase(fw: np.ndarray, u: Until, iphase: int, k: int) -> None:
    """Set the slots of a phase starting at sample ``k``: its end conditions (NaN: not given, which no comparison
    meets), a cleared event set and cleared integrals of the heading change and the body rates."""
    fw[st.F_IPHASE] = fw[st.F_ROW_PHASE] = iphase
    fw[st.F_PHASE_K0] = k
    fw[st.U_DURATION] = u.duration_s - 1e-9 if u.duration_s is not None else math.nan
    fw[st.U_EVENT] = st.EVENT_SLOTS[u.event] if u.event is not None else -1
    for slot, value in ((st.U_TURNED, u.turned_deg), (st.U_ROLLED, u.rolled_deg), (st.U_PITCHED, u.pitched_deg),
                        (st.U_VC_ABOVE, u.airspeed_above_kts), (st.U_VC_BELOW, u.airspeed_below_kts),
                        (st.U_H_ABOVE, u.altitude_above_ft), (st.U_H_BELOW, u.altitude_below_ft),
                        (st.U_AGL_ABOVE, u.agl_above_ft), (st.U_AGL_BELOW, u.agl_below_ft),
                        (st.U_BANK_ABOVE, u.bank_above_deg), (st.U_PITCH_ABOVE, u.pitch_above_deg),
                        (st.U_PITCH_BELOW, u.pitch_below_deg), (st.U_ALPHA_ABOVE, u.alpha_above_deg)):  # fmt: skip
        fw[slot] = _nan_if_none(value)
    fw[st.U_TIMEOUT] = u.timeout_s if u.duration_s is None else math.nan
    fw[st.F_TURNED] = fw[st.F_ROLLED] = fw[st.F_PITCHED] = 0.0
    for slot in st.EVENT_SLOTS.values():
        fw[slot] = 0.0


#: Factor from the raw value recorded per step to each flight.parquet column (None: taken as it is).
_SCALE: dict[str, float | None] = {name: None for name in COLUMN_NAMES} | {
    "f_x_mps2": FT_S2_TO_M_S2, "f_y_mps2": FT_S2_TO_M_S2, "f_z_mps2": FT_S2_TO_M_S2,
    "omega_x_degps": R2D, "omega_y_degps": R2D, "omega_z_degps": R2D, "phi_deg": R2D, "theta_deg": R2D,
    "psi_deg": R2D, "alpha_deg": R2D, "beta_deg": R2D, "gs_kts": FPS_TO_KT, "climb_fpm": 60.0, "lat_deg": R2D,
    "lon_deg": R2D,
}  # fmt: skip


def _columns(raw: np.ndarray, dt: float) -> dict[str, np.ndarray]:
    """flight.parquet's columns from the raw rows of the loop (step counter, JSBSim units, radians)."""
    columns: dict[str, np.ndarray] = {}
    for i, name in enumerate(COLUMN_NAMES):
        scale = _SCALE[name]
        columns[name] = raw[:, i] * scale if scale is not None else np.ascontiguousarray(raw[:, i])
    columns["t_s"] = columns["t_s"] * dt  # t = k * dt, as in the loop
    columns["psi_deg"] = columns["psi_deg"] % 360.0
    columns["wow"] = columns["wow"].astype(np.int8)
    columns["phase"] = columns["phase"].astype(np.int16)
    return columns


def _progress(name: str, iphase: int, nphases: int, phase: str, t: float, tty: bool) -> None:
    line = f"{name}: phase {iphase + 1}/{nphases} '{phase}', t = {t:6.1f} s"
    sys.stderr.write(f"\r\033[K{line}" if tty else f"{line}\n")
    sys.stderr.flush()


def flight_summary(result: FlightResult, source: str = "") -> dict[str, object]:
    """The content of flight.json."""

    def num(x: float) -> float | None:
        return None if math.isnan(x) else round(float(x), 6)

    return {
        "name": result.name,
        "aircraft": result.aircraft,
        "manoeuvre_file": source,
        "status": result.status,
        "reason": result.reason,
        "dt_s": result.dt_s,
        "samples": len(result.t_s),
        "duration_s": result.duration_s,
        "phases": [{"name": n, "t_start_s": a, "t_end_s": b} for n, a, b in result.phases],
        "checks": [{"name": n, "measured": num(v), "limit": lim, "passed": ok} for n, v, lim, ok in result.checks],
        "events": {k: [round(x, 6) for x in v] for k, v in result.events.items()},
    }


def write_flight(
    out_dir: str | Path, result: FlightResult, source: str = "", provenance: Mapping[str, object] | None = None
) -> None:
    """Write ``out_dir/flight.parquet`` and ``out_dir/flight.json`` atomically.

    ``provenance`` (:mod:`washbench.io.provenance`, no date) goes into the Parquet metadata and flight.json.
    """
    import pyarrow as pa

    from washbench.io.parquet_files import write_parquet  # deferred: pyarrow

    out = Path(out_dir)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise WashbenchError(f"{out}: cannot create the output folder ({exc.strerror or exc})") from None
    table = pa.table({name: result.columns[name] for name in COLUMN_NAMES})
    meta = {b"washbench.manoeuvre": result.name.encode(), b"washbench.aircraft": result.aircraft.encode()}
    if provenance:
        meta.update(parquet_metadata(provenance))
    table = table.replace_schema_metadata(meta)
    with atomic_path(out / FLIGHT_FILE) as tmp:
        write_parquet(tmp, table)
    summary = flight_summary(result, source)
    if provenance:
        summary["provenance"] = dict(provenance)
    write_text_atomic(out / FLIGHT_JSON, json.dumps(summary, indent=2) + "\n")


def fly_command(manoeuvre_path: Path, out_dir: Path, progress: bool = True, aircraft_dirs: Sequence[Path] = ()) -> int:
    """``washbench fly FILE --out DIR``: 0 if flown with every check passing, else 1.

    The output folder is checked (and locked) before flying, so a bad ``--out`` costs no flight.
    """

    m = load_manoeuvre(manoeuvre_path, aircraft_dirs)
    with result_set(out_dir, "fly") as stage:  # the whole set replaces the previous one at once
        wall = time.monotonic()
        result = fly(m, progress=progress)
        wall = time.monotonic() - wall
        prov = build_provenance(
            manoeuvre_path=manoeuvre_path, turbulence=m.environment.turbulence, aircraft_files=m.aircraft_files
        )
        write_flight(stage, result, str(manoeuvre_path), prov)
    passed = sum(1 for c in result.checks if c[3])
    line = (
        f"{m.name} ({m.aircraft}): {result.status}, {passed}/{len(result.checks)} checks passed, "
        f"{result.duration_s:.1f} s flown in {wall:.1f} s -> {out_dir}"
    )
    if not result.ok:
        line += f" ({result.reason})"
    print(line)
    return 0 if result.ok else 1
