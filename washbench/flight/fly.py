"""Fly a manoeuvre: JSBSim + scripted pilot + recorder + monitor, and write the results.

Time base: sample ``k`` is the state at ``t = k * dt``. JSBSim's eyepoint acceleration
(``accelerations/a-pilot-*``) and ``accelerations/Nz`` are computed before the forces of the
step, so they lag one frame: the value read after step ``k + 1`` belongs to sample ``k``.
The loop therefore reads the state at ``k``, runs the pilot, steps the FDM, then reads the
accelerations and completes row ``k``.
"""

from __future__ import annotations

import json
import math
import struct
import sys
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from washbench.errors import WashbenchError
from washbench.flight.checks import evaluate
from washbench.flight.columns import COLUMN_NAMES
from washbench.flight.fdm import make_fdm
from washbench.flight.manoeuvre import Manoeuvre, load_manoeuvre
from washbench.flight.manoeuvre_schema import Until
from washbench.flight.monitor import BIG, Monitor
from washbench.flight.openloop import OpenLoop
from washbench.flight.pilot import INPUTS_OFFSET, OUTPUTS_OFFSET, PACK_INPUTS, UNPACK_OUTPUTS, Pilot
from washbench.flight.profile import load_profile
from washbench.io.atomic import atomic_path, write_text_atomic
from washbench.io.provenance import build_provenance, parquet_metadata
from washbench.io.result_files import FLIGHT_FILE, FLIGHT_JSON

FT_S2_TO_M_S2 = 0.3048
R2D = 180.0 / math.pi
FPS_TO_KT = 3600.0 * 0.3048 / 1852.0

StepHook = Callable[[int, np.ndarray, np.ndarray], None]
BlockHook = Callable[[int, np.ndarray, np.ndarray], None]

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

#: One recorded row (the flight.parquet columns, raw, before the unit conversion of :func:`_columns`).
_ROW = struct.Struct(f"={len(COLUMN_NAMES)}d")


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


def _end_reached(u: Until, t_phase: float, turned: float, rolled: float, pitched: float, vc: float, h: float,
                 agl: float, phi: float, theta: float, alpha: float, events: set[str]) -> bool:  # fmt: skip
    """Whether any end condition of the phase holds (angles in deg, heights in ft).

    ``turned``, ``rolled`` and ``pitched`` are magnitudes since the phase began: of the heading
    change, and of the integrals of the body rates p and q.
    """
    if u.duration_s is not None and t_phase >= u.duration_s - 1e-9:
        return True
    if u.event is not None and u.event in events:
        return True
    return (
        (u.turned_deg is not None and turned >= u.turned_deg)
        or (u.rolled_deg is not None and rolled >= u.rolled_deg)
        or (u.pitched_deg is not None and pitched >= u.pitched_deg)
        or (u.airspeed_above_kts is not None and vc >= u.airspeed_above_kts)
        or (u.airspeed_below_kts is not None and vc <= u.airspeed_below_kts)
        or (u.altitude_above_ft is not None and h >= u.altitude_above_ft)
        or (u.altitude_below_ft is not None and h <= u.altitude_below_ft)
        or (u.agl_above_ft is not None and agl >= u.agl_above_ft)
        or (u.agl_below_ft is not None and agl <= u.agl_below_ft)
        or (u.bank_above_deg is not None and abs(phi) >= u.bank_above_deg)
        or (u.pitch_above_deg is not None and theta >= u.pitch_above_deg)
        or (u.pitch_below_deg is not None and theta <= u.pitch_below_deg)
        or (u.alpha_above_deg is not None and alpha >= u.alpha_above_deg)
    )


def _duration_only(u: Until) -> float | None:
    """``duration_s - 1e-9`` (the threshold :func:`_end_reached` uses) if the phase ends only by its duration."""
    others = u.model_dump(exclude={"duration_s", "timeout_s"}, exclude_none=True)
    return u.duration_s - 1e-9 if u.duration_s is not None and not others else None


def fly(
    manoeuvre: Manoeuvre,
    step_hook: StepHook | None = None,
    progress: bool = False,
    probes: Sequence[str] = (),
    block_hook: BlockHook | None = None,
    block_size: int = 120,
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

    pilot = Pilot(profile, m.runway, dt)
    pilot.set_controls(ail_w.get_double_value(), elev_w.get_double_value(), rud_w.get_double_value())
    pilot_buf, pilot_w, pilot_kernel = pilot.buffer, pilot.w, pilot.kernel
    pack_inputs, unpack_outputs = PACK_INPUTS, UNPACK_OUTPUTS
    brakes = pilot.brakes  # changes only at a phase start
    monitor = Monitor.for_profile(profile)
    openloop = OpenLoop(fdm, profile, pilot)
    probe_gets = [n.get_double_value for n in _nodes(fdm, tuple(probes))]
    probe_rows: list[list[float]] = [[] for _ in probe_gets]
    frame = setup.frame
    lat0, lon0, mlat, mlon = frame.lat0, frame.lon0, frame.m_per_rad_lat, frame.m_per_rad_lon
    has_runway = setup.threshold_ne_m is not None
    rw_c = math.cos(setup.runway_heading_rad or 0.0)
    rw_s = math.sin(setup.runway_heading_rad or 0.0)
    nan, pi, two_pi = math.nan, math.pi, 2 * math.pi
    mix_h_ft, mix_norm = zip(*profile.engine.mixture_schedule, strict=True)  # interpolated once a second
    mix_every = max(1, round(1.0 / dt))
    cg_h = profile.geometry.cg_height_on_ground_ft
    alpha_stall_deg = profile.limits.alpha_stall_deg

    rows = bytearray()  # the recorded rows, ncol float64 each (native byte order)
    rows_extend = rows.extend
    pack = _ROW.pack  # struct packs a row of floats several times faster than array('d').extend converts one
    run = fdm.run
    nz_max, nz_min = monitor.nz_max, monitor.nz_min
    vne, h_collapsed, alpha_max = monitor.vne, monitor.h_collapsed, monitor.alpha_max
    ncol = len(COLUMN_NAMES)
    phases_out: list[tuple[str, float, float]] = []
    events: dict[str, list[float]] = {"touchdown_times_s": [], "touchdown_sinks_fps": [], "liftoff_times_s": []}
    reason = ""
    iphase = -1
    phase_k0 = 0
    u: Until | None = None
    end_s: float | None = None
    psi_prev = p_prev = q_prev = 0.0
    turned = 0.0
    rolled = pitched = 0.0  # integrals of the body rates p and q over the phase, rad (trapezoidal rule)
    phase_events: set[str] = set()
    was_wow = wow_get() > 0.5
    airborne_since = 0.0
    lifted = not was_wow  # an air start has no lift-off to report
    nz_last = 1.0  # load factor of the last sample (before the first step: level flight or at rest)
    fy_last = 0.0  # and its lateral specific force, m/s^2
    k = 0
    k_sent = 0  # samples handed to block_hook so far
    # progress: overwritten in place on a terminal; otherwise (a log file, CI) a line per phase and every 5 s
    tty = progress and sys.stderr.isatty()
    report_every_s = 0.5 if tty else 5.0
    next_report = time.monotonic() + report_every_s
    nphases = len(m.phases)

    while True:
        t = k * dt
        phi, theta, psi = phi_get(), theta_get(), psi_get()
        p, q, r = p_get(), q_get(), r_get()
        alpha, beta, vc = alpha_get(), beta_get(), vc_get()
        vg, trk, hdot = vg_get(), trk_get(), hdot_get()
        h, agl, lat, lon = h_get(), agl_get(), lat_get(), lon_get()
        wow = wow_get() > 0.5
        north = (lat - lat0) * mlat  # LocalFrame and the runway frame, inline (hot path)
        east = (lon - lon0) * mlon
        if has_runway:
            x_rw = north * rw_c + east * rw_s
            y_rw = -north * rw_s + east * rw_c
        else:
            x_rw = y_rw = nan
        sw = 0.0
        for g in struct_gets:
            sw += g()

        total = phi + theta + p + q + r + vc + h + agl + alpha
        # the monitor's state checks, inlined (hot path); it is asked for the cause only when one fails
        problem = None
        if (not -BIG < total < BIG or sw > 0.0 or vc > vne or agl < h_collapsed
                or (not wow and (alpha > alpha_max or alpha < -alpha_max))):  # fmt: skip
            problem = monitor.state(total, vc, alpha, agl, wow, sw)
        # events at this sample
        if wow and not was_wow:
            sink = -hdot
            events["touchdown_times_s"].append(t)
            events["touchdown_sinks_fps"].append(sink)
            phase_events.add("touchdown")
            problem = problem or monitor.touchdown(sink)
        if not wow:
            if was_wow:
                airborne_since = t
                lifted = False
            if not lifted and agl - cg_h > 3.0 and t - airborne_since >= 0.5:
                lifted = True
                events["liftoff_times_s"].append(t)
                phase_events.add("liftoff")
        elif vg * FPS_TO_KT < 1.0:
            phase_events.add("stopped")
        if alpha * R2D >= alpha_stall_deg:
            phase_events.add("stall")
        was_wow = wow
        if problem:
            reason = f"t={t:.2f} s: {problem}"
            break

        # phase sequencing
        if iphase >= 0:
            d = psi - psi_prev
            if d > pi:
                d -= two_pi
            elif d < -pi:
                d += two_pi
            turned += d
            rolled += 0.5 * (p_prev + p) * dt
            pitched += 0.5 * (q_prev + q) * dt
        psi_prev = psi
        p_prev, q_prev = p, q
        advance = iphase < 0
        if u is not None:
            t_phase = (k - phase_k0) * dt
            if end_s is not None:  # a phase that ends only after a duration (most): no call needed
                advance = t_phase >= end_s
            elif _end_reached(u, t_phase, abs(turned) * R2D, abs(rolled) * R2D, abs(pitched) * R2D, vc, h, agl,
                              phi * R2D, theta * R2D, alpha * R2D, phase_events):  # fmt: skip
                advance = True
            elif u.duration_s is None and t_phase >= u.timeout_s:
                reason = (
                    f"t={t:.2f} s: phase '{m.phases[iphase].name}' did not reach its end condition "
                    f"within {u.timeout_s:g} s"
                )
                break
        final = False
        if advance:
            if iphase >= 0:
                phases_out.append((m.phases[iphase].name, phase_k0 * dt, t))
            iphase += 1
            if iphase == nphases:
                final = True
            else:
                phase = m.phases[iphase]
                u = phase.until
                end_s = _duration_only(u)
                phase_k0 = k
                turned = rolled = pitched = 0.0
                phase_events = set()
                pilot.begin_phase(phase.hold, theta, thr_w.get_double_value(), flap_get())
                openloop.begin_phase(phase.inputs, phase.name)
                flapc_w.set_double_value(pilot.flaps_cmd)
                lbrk_w.set_double_value(pilot.brakes)
                rbrk_w.set_double_value(pilot.brakes)
                brakes = pilot.brakes
                if progress:  # a line at each phase start (in place on a terminal)
                    _progress(m.name, iphase, nphases, phase.name, t, tty)

        if final:
            ail, elev, rud, thr = pilot.aileron, pilot.elevator, pilot.rudder, pilot.throttle
        else:
            # Pilot.step inlined: the inputs packed into the pilot's slots, one compiled call, the commands unpacked
            pack_inputs(pilot_buf, INPUTS_OFFSET, phi, theta, psi, p, q, r, beta, vc, vg, trk, hdot, h, agl,
                        x_rw * 3.2808399, y_rw * 3.2808399, 1.0 if wow else 0.0, nz_last, alpha, vt_get(),
                        fy_last)  # fmt: skip
            pilot_kernel(pilot_w)
            ail, elev, rud, steer, thr = unpack_outputs(pilot_buf, OUTPUTS_OFFSET)
            if openloop.active:  # the phase's open-loop inputs, on top of or instead of the pilot's commands
                ail, elev, rud, thr = openloop.apply((k - phase_k0) * dt, ail, elev, rud, thr)
            ail_set(ail)
            elev_set(elev)
            rud_set(rud)
            steer_set(steer)
            thr_set(thr)
            if k % mix_every == 0:
                mix_w.set_double_value(float(np.interp(h, mix_h_ft, mix_norm)))
        run()
        if probe_gets:
            for get, out in zip(probe_gets, probe_rows, strict=True):
                out.append(get())
        ax, ay, az = ax_get(), ay_get(), az_get()
        nz = nz_get()
        nz_last = nz
        fy_last = ay * FT_S2_TO_M_S2
        # raw values in JSBSim's units; converted column by column after the loop (same bits, fewer operations)
        rows_extend(pack(k, ax, ay, az, p, q, r, phi, theta, psi, alpha, beta, vc, vg, h, agl, hdot, north, east, lat,
                     lon, x_rw, y_rw, nz, ail, elev, rud, thr, flap_get(), brakes, rpm_get(), wow,
                     iphase if not final else nphases - 1))  # fmt: skip
        if step_hook is not None:
            step_hook(k, np.array((ax * FT_S2_TO_M_S2, fy_last, az * FT_S2_TO_M_S2)), np.array((p, q, r)))
        if block_hook is not None and k + 1 - k_sent == block_size:
            k_sent = _send_block(block_hook, rows, k_sent, ncol)
        if final:
            break
        if not wow and (nz > nz_max or nz < nz_min):
            reason = f"t={t:.2f} s: {monitor.load_factor(nz)}"
            break
        k += 1
        if progress and k % 600 == 0 and time.monotonic() > next_report:
            next_report = time.monotonic() + report_every_s
            _progress(m.name, iphase, nphases, m.phases[iphase].name, t, tty)

    if block_hook is not None and len(rows) // _ROW.size > k_sent:
        _send_block(block_hook, rows, k_sent, ncol)
    if reason and 0 <= iphase < nphases:  # the phase the flight stopped in, up to the last recorded sample
        phases_out.append((m.phases[iphase].name, phase_k0 * dt, max(len(rows) // _ROW.size - 1, 0) * dt))
    if tty:
        sys.stderr.write("\r\033[K")
        sys.stderr.flush()

    columns = _columns(np.frombuffer(rows, dtype=np.float64).reshape(-1, ncol), dt)
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


def _send_block(hook: BlockHook, rows: bytearray, k0: int, ncol: int) -> int:
    """Give ``hook`` the recorded samples from ``k0`` on (f in m/s^2, omega in rad/s); return the new count."""
    with memoryview(rows) as view:
        raw = np.frombuffer(view[k0 * _ROW.size :], dtype=np.float64).reshape(-1, ncol).copy()
    hook(k0, raw[:, 1:4] * FT_S2_TO_M_S2, raw[:, 4:7])
    return k0 + raw.shape[0]


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

    from washbench.io.parquet_files import write_parquet

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
    from washbench.io.outfolder import result_set

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
