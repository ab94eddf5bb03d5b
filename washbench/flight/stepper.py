"""The compiled part of :func:`washbench.flight.fly.fly`'s loop: one call per JSBSim step.

What runs at every step and needs nothing but arithmetic is here, compiled (numba, ``cache=True``, no fast-math):
completing the last recorded row with the accelerations its step produced, the load-factor check, the local and
runway positions, the monitor's state checks, the events (touchdown, lift-off, stopped, stall), the phase's
integrals and end conditions, the scripted pilot (:func:`washbench.flight.pilot.pilot_step`) and writing the
row of the sample. The loop in Python reads the JSBSim properties into the slots (one ``struct.pack_into``), calls
:func:`flight_step`, writes the commands and steps JSBSim. Whatever needs Python (a phase start, an event time,
a failure's message, the open-loop inputs, the mixture schedule, the block and step hooks, progress, a fuller row
array) is asked for by a bit of the returned code, so a step that needs none of it costs one compiled call.

Every expression keeps the operations and their order of the Python loop it replaces, so the flights are the
same bits (``bench/flight_digest.py``).

Slots (one float64 array, :data:`SLOTS`): the flight's constants, the phase's end conditions (NaN: not set,
which no comparison meets, as ``None`` was), the loop's state, the commands to write, and the inputs of a step:
the accelerations, load factor, flap angle and engine speed the previous step produced, then the state read before
this step, then up to four airframe contact points' weight-on-wheels.
"""

from __future__ import annotations

import math
import struct
from pathlib import Path

import numpy as np

from washbench.flight.monitor import BIG
from washbench.flight.pilot import NSLOTS as PILOT_NSLOTS
from washbench.flight.pilot import (
    S_AILERON,
    S_ELEVATOR,
    S_RUDDER,
    S_STEER,
    S_THROTTLE,
    X_ALPHA,
    X_BETA,
    X_FY_MPS2,
    X_GS_FPS,
    X_H_AGL,
    X_H_MSL,
    X_HDOT,
    X_NZ,
    X_P,
    X_PHI,
    X_PSI,
    X_Q,
    X_R,
    X_THETA,
    X_TRACK,
    X_VC,
    X_VT,
    X_WOW,
    X_X_RW_FT,
    X_Y_RW_FT,
    pilot_step,
)
from washbench.numerics.jitcache import announce_compile, drop_stale_cache
from washbench.numerics.lazyjit import LazyJit, lazy_njit  # numba imported at the first step, not here

FT_S2_TO_M_S2 = 0.3048  # as washbench.flight.fly (which imports this module)
R2D = 180.0 / math.pi
FPS_TO_KT = 3600.0 * 0.3048 / 1852.0
NSTRUCT = 4
"""Airframe contact points read into their own slots; more are summed in Python into the last one."""

SLOTS: tuple[str, ...] = (
    # the flight's constants
    "dt", "lat0", "lon0", "mlat", "mlon", "has_runway", "rw_c", "rw_s", "vne", "h_collapsed", "alpha_max",
    "nz_max", "nz_min", "sink_max", "cg_h", "alpha_stall_deg", "mix_every", "block_size", "every_sample", "progress",
    # the phase: its index, first sample, end conditions, and what the row records
    "iphase", "phase_k0", "u_duration", "u_event", "u_turned", "u_rolled", "u_pitched", "u_vc_above", "u_vc_below",
    "u_h_above", "u_h_below", "u_agl_above", "u_agl_below", "u_bank_above", "u_pitch_above", "u_pitch_below",
    "u_alpha_above", "u_timeout", "openloop", "final", "row_phase", "brakes",
    # the loop's state
    "mode", "nrows", "pending", "row_wow", "done_row", "sample", "turned", "rolled", "pitched", "psi_prev", "p_prev",
    "q_prev", "was_wow", "airborne_since", "lifted", "nz_last", "fy_last", "ev_liftoff", "ev_touchdown",
    "ev_stopped", "ev_stall", "total", "sw",
    # the commands to write (the pilot's, or the open-loop inputs' once Python applied them)
    "ail", "elev", "rud", "steer", "thr",
    # the inputs of a step: what the previous step produced, then the state now
    "ax", "ay", "az", "nz", "flap", "rpm", "phi", "theta", "psi", "p", "q", "r", "alpha", "beta", "vc", "vg", "trk",
    "hdot", "h", "agl", "lat", "lon", "wow", "vt", "struct0", "struct1", "struct2", "struct3",
)  # fmt: skip
# fmt: off
(
    F_DT, F_LAT0, F_LON0, F_MLAT, F_MLON, F_HAS_RUNWAY, F_RW_C, F_RW_S, F_VNE, F_H_COLLAPSED, F_ALPHA_MAX,
    F_NZ_MAX, F_NZ_MIN, F_SINK_MAX, F_CG_H, F_ALPHA_STALL_DEG, F_MIX_EVERY, F_BLOCK_SIZE, F_EVERY_SAMPLE, F_PROGRESS,
    F_IPHASE, F_PHASE_K0, U_DURATION, U_EVENT, U_TURNED, U_ROLLED, U_PITCHED, U_VC_ABOVE, U_VC_BELOW,
    U_H_ABOVE, U_H_BELOW, U_AGL_ABOVE, U_AGL_BELOW, U_BANK_ABOVE, U_PITCH_ABOVE, U_PITCH_BELOW,
    U_ALPHA_ABOVE, U_TIMEOUT, F_OPENLOOP, F_FINAL, F_ROW_PHASE, F_BRAKES,
    F_MODE, F_NROWS, F_PENDING, F_ROW_WOW, F_DONE_ROW, F_SAMPLE, F_TURNED, F_ROLLED, F_PITCHED, F_PSI_PREV, F_P_PREV,
    F_Q_PREV, F_WAS_WOW, F_AIRBORNE_SINCE, F_LIFTED, F_NZ_LAST, F_FY_LAST, F_EV_LIFTOFF, F_EV_TOUCHDOWN,
    F_EV_STOPPED, F_EV_STALL, F_TOTAL, F_SW,
    F_AIL, F_ELEV, F_RUD, F_STEER, F_THR,
    I_AX, I_AY, I_AZ, I_NZ, I_FLAP, I_RPM, I_PHI, I_THETA, I_PSI, I_P, I_Q, I_R, I_ALPHA, I_BETA, I_VC, I_VG, I_TRK,
    I_HDOT, I_H, I_AGL, I_LAT, I_LON, I_WOW, I_VT, I_STRUCT0, I_STRUCT1, I_STRUCT2, I_STRUCT3,
) = range(98)
# fmt: on
NSLOTS = len(SLOTS)
"""The loop's own slots; the pilot's (:data:`washbench.flight.pilot.NSLOTS`) follow them in the same array."""
EVENT_SLOTS = {"liftoff": F_EV_LIFTOFF, "touchdown": F_EV_TOUCHDOWN, "stopped": F_EV_STOPPED, "stall": F_EV_STALL}
"""The flag slot of each event (``u_event`` holds one of these slots, or -1)."""

PACK_STEP = struct.Struct(f"={NSLOTS - I_AX}d").pack_into
"""Packs a step's inputs (slots ``ax`` .. ``struct3``) at byte offset :data:`INPUTS_OFFSET`."""
INPUTS_OFFSET = I_AX * 8
UNPACK_COMMANDS = struct.Struct("=5d").unpack_from
"""Unpacks the commands (aileron, elevator, rudder, steer, throttle) from byte offset :data:`COMMANDS_OFFSET`."""
COMMANDS_OFFSET = F_AIL * 8

# modes of a call
MODE_STEP, MODE_RESUME, MODE_FINISH = 0, 1, 2
"""A whole step; the rest of a step after Python started a phase (pilot and row); only completing the last row."""

# bits of the returned code: what Python must do
C_SAMPLE = 1  # a row is complete (slot done_row): call the step hook
C_BLOCK = 2  # a block of rows is complete: call the block hook
C_NZ = 4  # the completed row's load factor is beyond the limits in flight: stop
C_PROGRESS = 8  # report progress (600 samples more)
C_FULL = 16  # the row array is full: grow it and call again
C_TOUCHDOWN = 32  # touchdown at this sample (record its time and sink rate)
C_LIFTOFF = 64  # lift-off at this sample
C_STATE = 128  # the monitor's state checks failed: stop
C_HARD = 256  # touchdown beyond the sink-rate limit: stop
C_TIMEOUT = 512  # the phase did not end within its timeout: stop
C_ADVANCE = 1024  # the phase ended (or the first one starts): Python starts the next, then calls with MODE_RESUME
C_OPENLOOP = 2048  # apply the phase's open-loop inputs to the commands (and the row)
C_MIX = 4096  # set the mixture from the schedule

# flight.parquet's raw row (washbench.flight.columns order)
(R_K, R_AX, R_AY, R_AZ, R_P, R_Q, R_R, R_PHI, R_THETA, R_PSI, R_ALPHA, R_BETA, R_VC, R_VG, R_H, R_AGL, R_HDOT,
 R_NORTH, R_EAST, R_LAT, R_LON, R_XRW, R_YRW, R_NZ, R_AIL, R_ELEV, R_RUD, R_THR, R_FLAP, R_BRAKES, R_RPM, R_WOW,
 R_PHASE) = range(33)  # fmt: skip


def new_slots() -> tuple[np.ndarray, np.ndarray]:
    """Zeroed slots: the loop's and the pilot's after them (for :data:`PACK_STEP`, :data:`UNPACK_COMMANDS` and the
    compiled step), and the pilot's part (a view, for :class:`washbench.flight.pilot.Pilot`)."""
    slots = np.zeros(NSLOTS + PILOT_NSLOTS)
    return slots, slots[NSLOTS:]


_cache_checked = False


def compiled_flight_step() -> object:
    """:func:`flight_step`'s numba dispatcher (compiled, or loaded from numba's cache, at its first call; announced)."""
    global _cache_checked
    if not _cache_checked:  # here, not at import: it imports numba (0.4 s) and fly's module is imported by validate
        # the compiled step inlines the pilot's: its cache is stale when pilot.py changes
        drop_stale_cache(__file__, [Path(__file__).resolve().parent / "pilot.py"])
        _cache_checked = True
    fn = flight_step
    if isinstance(fn, LazyJit):
        fn = fn.compiled()
    announce_compile(fn)
    return fn


@lazy_njit(cache=True, _nrt=False)
def flight_step(f: np.ndarray, rows: np.ndarray) -> int:
    """One step of fly's loop on the slots ``f`` (the pilot's after the loop's) and the raw rows; returns the code.

    Compiled without numba's reference counting (``_nrt=False``, as the pilot's step): it allocates nothing and
    its arrays outlive the call, and the call from Python then skips a reference-count object per array argument.

    With a row pending (the previous step's), it is completed first from the inputs ``ax`` .. ``rpm``
    (``done_row``), then checked (load factor in flight). ``MODE_STEP`` then does the whole sample ``nrows``;
    ``MODE_RESUME`` only its pilot step and row (after Python started a phase); ``MODE_FINISH`` nothing more.
    """
    code = 0
    mode = f[F_MODE]
    pw = f[NSLOTS:]
    if f[F_PENDING] != 0.0:
        j = int(f[F_NROWS]) - 1
        ay = f[I_AY]
        nz = f[I_NZ]
        rows[j, R_AX] = f[I_AX]
        rows[j, R_AY] = ay
        rows[j, R_AZ] = f[I_AZ]
        rows[j, R_NZ] = nz
        rows[j, R_FLAP] = f[I_FLAP]
        rows[j, R_RPM] = f[I_RPM]
        f[F_NZ_LAST] = nz
        f[F_FY_LAST] = ay * FT_S2_TO_M_S2
        f[F_PENDING] = 0.0
        f[F_DONE_ROW] = j
        if f[F_EVERY_SAMPLE] != 0.0:
            code |= C_SAMPLE
        if (j + 1) % int(f[F_BLOCK_SIZE]) == 0:
            code |= C_BLOCK
        if mode == MODE_FINISH:
            return code
        if f[F_ROW_WOW] == 0.0 and (nz > f[F_NZ_MAX] or nz < f[F_NZ_MIN]):
            return code | C_NZ
        if f[F_PROGRESS] != 0.0 and (j + 1) % 600 == 0:
            code |= C_PROGRESS
    k = int(f[F_NROWS])
    if k >= rows.shape[0]:
        return code | C_FULL
    dt = f[F_DT]
    t = k * dt
    phi = f[I_PHI]
    theta = f[I_THETA]
    psi = f[I_PSI]
    p = f[I_P]
    q = f[I_Q]
    r = f[I_R]
    alpha = f[I_ALPHA]
    vc = f[I_VC]
    vg = f[I_VG]
    hdot = f[I_HDOT]
    h = f[I_H]
    agl = f[I_AGL]
    lat = f[I_LAT]
    lon = f[I_LON]
    wow = f[I_WOW] > 0.5
    north = (lat - f[F_LAT0]) * f[F_MLAT]  # LocalFrame and the runway frame, inline
    east = (lon - f[F_LON0]) * f[F_MLON]
    if f[F_HAS_RUNWAY] != 0.0:
        rw_c = f[F_RW_C]
        rw_s = f[F_RW_S]
        x_rw = north * rw_c + east * rw_s
        y_rw = -north * rw_s + east * rw_c
    else:
        x_rw = y_rw = math.nan
    if mode == MODE_STEP:
        f[F_SAMPLE] = k
        sw = 0.0
        sw += f[I_STRUCT0]
        sw += f[I_STRUCT1]
        sw += f[I_STRUCT2]
        sw += f[I_STRUCT3]
        total = phi + theta + p + q + r + vc + h + agl + alpha
        alpha_max = f[F_ALPHA_MAX]
        # the monitor's state checks (washbench.flight.monitor.Monitor.state gives the cause)
        if (not -BIG < total < BIG or sw > 0.0 or vc > f[F_VNE] or agl < f[F_H_COLLAPSED]
                or (not wow and (alpha > alpha_max or alpha < -alpha_max))):  # fmt: skip
            f[F_TOTAL] = total
            f[F_SW] = sw
            code |= C_STATE
        # events at this sample
        was_wow = f[F_WAS_WOW] != 0.0
        if wow and not was_wow:
            code |= C_TOUCHDOWN
            f[F_EV_TOUCHDOWN] = 1.0
            if -hdot > f[F_SINK_MAX]:
                code |= C_HARD
        if not wow:
            if was_wow:
                f[F_AIRBORNE_SINCE] = t
                f[F_LIFTED] = 0.0
            if f[F_LIFTED] == 0.0 and agl - f[F_CG_H] > 3.0 and t - f[F_AIRBORNE_SINCE] >= 0.5:
                f[F_LIFTED] = 1.0
                code |= C_LIFTOFF
                f[F_EV_LIFTOFF] = 1.0
        elif vg * FPS_TO_KT < 1.0:
            f[F_EV_STOPPED] = 1.0
        if alpha * R2D >= f[F_ALPHA_STALL_DEG]:
            f[F_EV_STALL] = 1.0
        f[F_WAS_WOW] = 1.0 if wow else 0.0
        if code & (C_STATE | C_HARD):
            return code

        # phase sequencing
        iphase = f[F_IPHASE]
        if iphase >= 0:
            d = psi - f[F_PSI_PREV]
            if d > math.pi:
                d -= 2 * math.pi
            elif d < -math.pi:
                d += 2 * math.pi
            f[F_TURNED] += d
            f[F_ROLLED] += 0.5 * (f[F_P_PREV] + p) * dt
            f[F_PITCHED] += 0.5 * (f[F_Q_PREV] + q) * dt
        f[F_PSI_PREV] = psi
        f[F_P_PREV] = p
        f[F_Q_PREV] = q
        if iphase < 0:
            return code | C_ADVANCE
        t_phase = (k - int(f[F_PHASE_K0])) * dt
        ev = int(f[U_EVENT])
        if (t_phase >= f[U_DURATION] or (ev >= 0 and f[ev] != 0.0)
                or abs(f[F_TURNED]) * R2D >= f[U_TURNED] or abs(f[F_ROLLED]) * R2D >= f[U_ROLLED]
                or abs(f[F_PITCHED]) * R2D >= f[U_PITCHED] or vc >= f[U_VC_ABOVE] or vc <= f[U_VC_BELOW]
                or h >= f[U_H_ABOVE] or h <= f[U_H_BELOW] or agl >= f[U_AGL_ABOVE] or agl <= f[U_AGL_BELOW]
                or abs(phi * R2D) >= f[U_BANK_ABOVE] or theta * R2D >= f[U_PITCH_ABOVE]
                or theta * R2D <= f[U_PITCH_BELOW] or alpha * R2D >= f[U_ALPHA_ABOVE]):  # fmt: skip
            return code | C_ADVANCE
        if t_phase >= f[U_TIMEOUT]:
            return code | C_TIMEOUT

    if f[F_FINAL] == 0.0:
        pw[X_PHI] = phi
        pw[X_THETA] = theta
        pw[X_PSI] = psi
        pw[X_P] = p
        pw[X_Q] = q
        pw[X_R] = r
        pw[X_BETA] = f[I_BETA]
        pw[X_VC] = vc
        pw[X_GS_FPS] = vg
        pw[X_TRACK] = f[I_TRK]
        pw[X_HDOT] = hdot
        pw[X_H_MSL] = h
        pw[X_H_AGL] = agl
        pw[X_X_RW_FT] = x_rw * 3.2808399
        pw[X_Y_RW_FT] = y_rw * 3.2808399
        pw[X_WOW] = 1.0 if wow else 0.0
        pw[X_NZ] = f[F_NZ_LAST]
        pw[X_ALPHA] = alpha
        pw[X_VT] = f[I_VT]
        pw[X_FY_MPS2] = f[F_FY_LAST]
        pilot_step(pw)
        f[F_STEER] = pw[S_STEER]
        if f[F_OPENLOOP] != 0.0:
            code |= C_OPENLOOP
        if k % int(f[F_MIX_EVERY]) == 0:
            code |= C_MIX
    ail = f[F_AIL] = pw[S_AILERON]
    elev = f[F_ELEV] = pw[S_ELEVATOR]
    rud = f[F_RUD] = pw[S_RUDDER]
    thr = f[F_THR] = pw[S_THROTTLE]
    # the row, but for what the step produces (completed at the next call)
    rows[k, R_K] = k
    rows[k, R_P] = p
    rows[k, R_Q] = q
    rows[k, R_R] = r
    rows[k, R_PHI] = phi
    rows[k, R_THETA] = theta
    rows[k, R_PSI] = psi
    rows[k, R_ALPHA] = alpha
    rows[k, R_BETA] = f[I_BETA]
    rows[k, R_VC] = vc
    rows[k, R_VG] = vg
    rows[k, R_H] = h
    rows[k, R_AGL] = agl
    rows[k, R_HDOT] = hdot
    rows[k, R_NORTH] = north
    rows[k, R_EAST] = east
    rows[k, R_LAT] = lat
    rows[k, R_LON] = lon
    rows[k, R_XRW] = x_rw
    rows[k, R_YRW] = y_rw
    rows[k, R_AIL] = ail
    rows[k, R_ELEV] = elev
    rows[k, R_RUD] = rud
    rows[k, R_THR] = thr
    rows[k, R_BRAKES] = f[F_BRAKES]
    rows[k, R_WOW] = 1.0 if wow else 0.0
    rows[k, R_PHASE] = f[F_ROW_PHASE]
    f[F_ROW_WOW] = 1.0 if wow else 0.0
    f[F_NROWS] = k + 1
    f[F_PENDING] = 1.0
    return code
