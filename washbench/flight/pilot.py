"""The scripted pilot: cascaded PI loops run at every JSBSim step, compiled (:func:`pilot_step`, numba).

Its parameters, state and the inputs of a step live in one float64 array (:data:`PARAMS`, :data:`STATE`,
:data:`INPUTS`), so a step is one compiled call on it (fly's loop makes it part of its own compiled step,
:mod:`washbench.flight.stepper`); :class:`Pilot` keeps the Python interface (``begin_phase``, ``step``, the
commands as attributes). The arithmetic is that of the former plain-Python pilot, operation for operation: the
flights are the same bits.

Loops (angles in rad, rates in rad/s, speeds in kt, heights in ft):

- roll: path target (heading, ground track to the runway centreline) -> bank command
  (limited to ``bank_max_deg``) -> roll-rate command (P, limited to ``rate_max_degps``)
  -> aileron (feed-forward of the steady-roll aileron, proportional to p / V, plus PI on the
  roll-rate error, so a roll stops as soon as its command does). The heading hold leads the
  roll-out by the turn rate times half the roll-out time; the centreline track is PI on the
  offset, and with ``wing_low`` the bank also balances the measured side force of the slip.
- pitch: path target (altitude -> climb-rate command; glide path -> climb rate; flare ->
  sink proportional to wheel height) -> pitch command (PI on the flight-path-angle error; with
  the throttle fixed, airspeed is held by energy: the path angle that gives the wanted airspeed
  rate, gamma + (vdot - vdot_cmd) / g) -> pitch-rate command (P plus the steady
  turn's pitch rate g/V sin^2(phi)/cos(phi)) -> elevator (PI on pitch-rate error).
- body-rate modes (aerobatics: no Euler angle in the loop, so nothing jumps through the
  vertical or inverted): the ailerons track the roll angle about the body x axis of a
  constant roll rate (``roll_rate_degps``: p_cmd = p_target + K (p_target t - integral of p),
  so 0 holds the roll attitude of the phase start), the elevator a pitch rate or a load factor. The load-factor loop
  commands the pitch rate of a pull in the plane of symmetry, q = g (n - z_D) / V with
  z_D = cos(phi) cos(theta) the vertical component of the body z axis (continuous through
  the vertical), plus a PI correction on the measured load factor; it never pulls the wing
  past ``alpha_max_deg`` (a pilot eases the pull at the buffet: over the top of a loop the
  load factor asked for may be more than the wing can give).
- load-factor protection (when the profile gives ``nz_pull_max``/``nz_push_min``): in the
  air every pitch-rate command is clamped to the rates that keep the load factor inside
  those limits, as a pilot eases off the pull before the limit.
- power: airspeed on the throttle or a fixed throttle, slew-rate limited. The throttle holds the
  specific energy rate gamma + vdot / g at what the path and the airspeed command
  (vdot_cmd = speed error / ``speed_tau_s``, limited) need together (PI, TECS-like), so it cuts
  power when the elevator levels off and the airspeed settles without overshoot.
- yaw: in the air the rudder drives sideslip to zero (PI) with a yaw damper about the
  coordinated yaw rate and a rudder feed-forward from the roll (against adverse yaw); with
  ``wing_low`` (crosswind landing: the ailerons then bank into the wind to hold the track) and
  on the ground it holds the runway heading (PI, with yaw-rate damping; the rudder starts
  central at touchdown) plus a PI correction of the centreline offset, with nosewheel steering.

Surface commands are rate limited (``surface_rate_per_s``), as a pilot's hands are.
Integrators start from the current control or attitude at each phase (bumpless), stop
integrating while their output saturates (anti-windup) and while the gear is on the
ground for the loops the gear constrains. Proportional gains are scaled with
(V_ref / V)^2 to keep the loop bandwidth as the dynamic pressure changes.
"""

from __future__ import annotations

import math
import struct
from typing import Any

import numpy as np

from washbench.flight.manoeuvre_schema import Hold, Runway
from washbench.flight.profile import PilotProfile
from washbench.numerics.jitcache import announce_compile
from washbench.numerics.lazyjit import LazyJit, lazy_njit  # numba imported at the first step, not here

D2R = math.pi / 180.0
G_FPS2 = 32.174
KT_TO_FPS = 1852.0 / 3600.0 / 0.3048
G_KTPS = G_FPS2 / KT_TO_FPS  # standard gravity in kt/s
G_MPS2 = 9.80665
SIDE_FORCE_FILTER_S = 0.5  # time constant of the filter on the lateral specific force, s
TWO_PI = 2.0 * math.pi  # as in washbench.flight.geo.wrap_pi, which the step inlines

# lateral modes
LAT_LEVEL, LAT_BANK, LAT_HEADING, LAT_RATE, LAT_TRACK = range(5)
# pitch modes
PITCH_HOLD, PITCH_ATT, PITCH_ALT, PITCH_VS, PITCH_GLIDE, PITCH_RATE, PITCH_FLARE, PITCH_SPEED, PITCH_NZ = range(9)

# ---- the pilot's slots: one float64 array holds its parameters, its state and the inputs of a step, so a step
# is one compiled call on one array (the inputs packed into it, the commands unpacked from it by struct).
PARAMS: tuple[str, ...] = (
    "dt", "vref", "vmin", "vr", "cg_h", "steer_sign", "flaps_full", "k_phi", "p_max", "kp_p", "ki_p", "k_pff",
    "bank_max", "k_th", "q_max", "kp_q", "ki_q", "th_min", "th_max", "n_hi", "n_lo", "nz_protect", "k_n", "k_n_i",
    "alpha_max", "k_alpha", "kvs", "kvs_i", "k_alt", "vs_max", "k_gp", "tau_v", "vdot_max", "tau_vdot", "a_vdot",
    "a_fy", "kt", "kt_i", "thr_rate", "surf_rate", "kb", "kb_i", "kyd", "k_ari", "k_hdg", "k_trk", "k_y",
    "icpt_max", "k_y_i", "i_y_max", "kg_psi", "kg_r", "kg_i", "kg_y", "kg_ymax", "kg_y_i", "ig_y_max", "tau",
    "sink_min", "rw_hdg", "rw_elev", "aim_ft", "sc_exp",
)
"""Slots set once per flight from the profile and the runway (gains, limits, per-step filter gains)."""
STATE: tuple[str, ...] = (
    "aileron", "elevator", "rudder", "steer", "throttle", "flaps_cmd", "brakes", "lat_mode", "lat_target",
    "pitch_mode", "pitch_target", "tan_gp", "speed_target", "speed_on_throttle", "throttle_target", "centreline",
    "wing_low", "i_p", "rolled", "t_phase", "i_q", "i_n", "i_path", "i_thr", "i_beta", "i_psi", "i_y", "i_y_ground",
    "vdot", "vt_prev", "fy_f", "was_wow",
)
"""Slots the pilot keeps from step to step: outputs (first, in the order the loop unpacks them), phase set-up
(modes as small integers, flags as 0/1), integrators and filters."""
INPUTS: tuple[str, ...] = (
    "phi", "theta", "psi", "p", "q", "r", "beta", "vc", "gs_fps", "track", "hdot", "h_msl", "h_agl", "x_rw_ft",
    "y_rw_ft", "wow", "nz", "alpha", "vt", "fy_mps2",
)
"""Slots of one step's inputs (:meth:`Pilot.step`'s arguments in order; ``wow`` as 0/1)."""
# fmt: off
(
    P_DT, P_VREF, P_VMIN, P_VR, P_CG_H, P_STEER_SIGN, P_FLAPS_FULL, P_K_PHI, P_P_MAX, P_KP_P, P_KI_P, P_K_PFF,
    P_BANK_MAX, P_K_TH, P_Q_MAX, P_KP_Q, P_KI_Q, P_TH_MIN, P_TH_MAX, P_N_HI, P_N_LO, P_NZ_PROTECT, P_K_N, P_K_N_I,
    P_ALPHA_MAX, P_K_ALPHA, P_KVS, P_KVS_I, P_K_ALT, P_VS_MAX, P_K_GP, P_TAU_V, P_VDOT_MAX, P_TAU_VDOT, P_A_VDOT,
    P_A_FY, P_KT, P_KT_I, P_THR_RATE, P_SURF_RATE, P_KB, P_KB_I, P_KYD, P_K_ARI, P_K_HDG, P_K_TRK, P_K_Y,
    P_ICPT_MAX, P_K_Y_I, P_I_Y_MAX, P_KG_PSI, P_KG_R, P_KG_I, P_KG_Y, P_KG_YMAX, P_KG_Y_I, P_IG_Y_MAX, P_TAU,
    P_SINK_MIN, P_RW_HDG, P_RW_ELEV, P_AIM_FT, P_SC_EXP,
) = range(0, 63)
(
    S_AILERON, S_ELEVATOR, S_RUDDER, S_STEER, S_THROTTLE, S_FLAPS_CMD, S_BRAKES, S_LAT_MODE, S_LAT_TARGET,
    S_PITCH_MODE, S_PITCH_TARGET, S_TAN_GP, S_SPEED_TARGET, S_SPEED_ON_THROTTLE, S_THROTTLE_TARGET, S_CENTRELINE,
    S_WING_LOW, S_I_P, S_ROLLED, S_T_PHASE, S_I_Q, S_I_N, S_I_PATH, S_I_THR, S_I_BETA, S_I_PSI, S_I_Y, S_I_Y_GROUND,
    S_VDOT, S_VT_PREV, S_FY_F, S_WAS_WOW,
) = range(63, 95)
(
    X_PHI, X_THETA, X_PSI, X_P, X_Q, X_R, X_BETA, X_VC, X_GS_FPS, X_TRACK, X_HDOT, X_H_MSL, X_H_AGL, X_X_RW_FT,
    X_Y_RW_FT, X_WOW, X_NZ, X_ALPHA, X_VT, X_FY_MPS2,
) = range(95, 115)
# fmt: on
NSLOTS = len(PARAMS) + len(STATE) + len(INPUTS)
OUTPUTS_OFFSET = S_AILERON * 8
"""Byte offset of aileron, elevator, rudder, steer, throttle (:data:`UNPACK_OUTPUTS`)."""
INPUTS_OFFSET = X_PHI * 8
"""Byte offset of the inputs (:data:`PACK_INPUTS`)."""
PACK_INPUTS = struct.Struct(f"={len(INPUTS)}d").pack_into
UNPACK_OUTPUTS = struct.Struct("=5d").unpack_from


class Pilot:
    """Closed-loop pilot for one flight; ``begin_phase`` at each phase, ``step`` at every FDM step.

    After ``step`` the commands are in ``aileron``, ``elevator`` (+ nose down), ``rudder``
    (+ nose left), ``steer``, ``throttle``; ``flaps_cmd`` (0..1 of full travel) and
    ``brakes`` change only at phase starts.
    """

    def __init__(
        self, profile: PilotProfile, runway: Runway | None, dt_s: float, slots: np.ndarray | None = None
    ) -> None:
        """``slots``: a C-contiguous float64 array of :data:`NSLOTS` to keep the slots in (fly's loop gives the tail
        of its own slots, so that one compiled call takes both); else the pilot allocates its own."""
        if slots is None:
            slots = np.zeros(NSLOTS)
        if slots.dtype != np.float64 or slots.shape != (NSLOTS,) or not slots.flags.c_contiguous:
            raise ValueError(f"pilot slots must be a C-contiguous float64 array of {NSLOTS}")
        self.w = slots
        """The slots as the array :func:`pilot_step` takes."""
        self.buffer = slots
        """The same memory for :data:`PACK_INPUTS` and :data:`UNPACK_OUTPUTS` (offsets from the first slot)."""
        self.kernel = compiled_step()
        g = profile.gains
        self.dt = dt_s
        self.vref = g.reference_airspeed_kts
        self.vmin = profile.speeds.stall_kts
        self.vr = profile.speeds.vr_kts
        self.cg_h = profile.geometry.cg_height_on_ground_ft
        self.steer_sign = profile.engine.steer_sign
        self.flaps_full = profile.limits.flaps_full_cmd_deg
        # roll
        self.k_phi = g.roll.bank_to_rate
        self.p_max = g.roll.rate_max_degps * D2R
        self.kp_p = g.roll.kp
        self.ki_p = g.roll.ki
        self.k_pff = g.roll.rate_feedforward
        self.bank_max = g.roll.bank_max_deg * D2R
        # pitch
        self.k_th = g.pitch.pitch_to_rate
        self.q_max = g.pitch.rate_max_degps * D2R
        self.kp_q = g.pitch.kp
        self.ki_q = g.pitch.ki
        self.th_min = g.pitch.pitch_min_deg * D2R
        self.th_max = g.pitch.pitch_max_deg * D2R
        self.n_hi = g.pitch.nz_pull_max if g.pitch.nz_pull_max is not None else math.inf
        self.n_lo = g.pitch.nz_push_min if g.pitch.nz_push_min is not None else -math.inf
        # without limits the protection clamps nothing (q_hi is +inf or NaN, q_lo -inf or NaN): skipped
        self.nz_protect = g.pitch.nz_pull_max is not None or g.pitch.nz_push_min is not None
        self.k_n = g.pitch.nz_kp
        self.k_n_i = g.pitch.nz_ki
        self.alpha_max = g.pitch.alpha_max_deg * D2R
        self.k_alpha = g.pitch.alpha_to_rate
        # path
        self.kvs = g.path.climb_to_pitch
        self.kvs_i = g.path.climb_to_pitch_i
        self.k_alt = g.path.altitude_to_vs
        self.vs_max = g.path.vs_max_fps
        self.k_gp = g.path.glide_path_to_vs
        self.tau_v = g.path.speed_tau_s
        self.vdot_max = g.path.accel_max_ktps
        self.tau_vdot = g.path.speed_rate_filter_s
        self.a_vdot = dt_s / (self.tau_vdot + dt_s)  # gains of the first-order filters, per step
        self.a_fy = dt_s / (SIDE_FORCE_FILTER_S + dt_s)
        self.kt = g.path.energy_to_throttle
        self.kt_i = g.path.energy_to_throttle_i
        self.thr_rate = g.path.throttle_rate_per_s * dt_s
        self.surf_rate = g.surface_rate_per_s * dt_s
        # yaw
        self.kb = g.yaw.beta_kp
        self.kb_i = g.yaw.beta_ki
        self.kyd = g.yaw.yaw_damper
        self.k_ari = g.yaw.aileron_to_rudder
        # track
        self.k_hdg = g.track.heading_to_bank
        self.k_trk = g.track.track_to_bank
        self.k_y = g.track.offset_to_track_deg_per_ft * D2R
        self.icpt_max = g.track.intercept_max_deg * D2R
        self.k_y_i = g.track.offset_ki
        self.i_y_max = g.track.offset_integral_max_deg * D2R / self.k_y  # ft s
        # ground
        self.kg_psi = g.ground.heading_kp
        self.kg_r = g.ground.yaw_rate_kd
        self.kg_i = g.ground.heading_ki
        self.kg_y = g.ground.offset_to_heading_deg_per_ft * D2R
        self.kg_ymax = g.ground.offset_heading_max_deg * D2R
        self.kg_y_i = g.ground.offset_ki
        self.ig_y_max = g.ground.offset_integral_max_deg * D2R / self.kg_y  # ft s
        # flare
        self.tau = g.flare.tau_s
        self.sink_min = g.flare.sink_min_fps
        # runway
        self.rw_hdg = math.radians(runway.heading_deg) if runway is not None else 0.0
        self.rw_elev = runway.elevation_ft if runway is not None else 0.0
        self.aim_ft = runway.aim_point_ft if runway is not None else 0.0
        self.sc_exp = 2.0  # the gain scale (V_ref / V)^sc_exp (see pilot_step)
        # phase set-up
        self.lat_mode = LAT_LEVEL
        self.lat_target = 0.0
        self.pitch_mode = PITCH_HOLD
        self.pitch_target = 0.0
        self.tan_gp = 0.0
        self.speed_target = -1.0  # kt; < 0: none
        self.speed_on_throttle = False
        self.throttle_target = -1.0  # < 0: keep the current throttle
        self.centreline = False
        self.wing_low = False
        # integrators
        self.i_p = 0.0
        self.rolled = 0.0  # roll-rate mode: integral of p since the phase start, rad
        self.t_phase = 0.0  # and the time since then, s
        self.i_q = 0.0
        self.i_n = 0.0
        self.i_path = 0.0
        self.i_thr = 0.0
        self.i_beta = 0.0
        self.i_psi = 0.0
        self.i_y = 0.0  # centreline offset integrals (in the air, on the ground), ft s x their gain
        self.i_y_ground = 0.0
        # airspeed rate (true, kt/s), a filtered derivative
        self.vdot = 0.0
        self.vt_prev = -1.0
        self.fy_f = 0.0  # lateral specific force, filtered, m/s^2
        self.was_wow = False
        # outputs
        self.aileron = 0.0
        self.elevator = 0.0
        self.rudder = 0.0
        self.steer = 0.0
        self.throttle = 0.0
        self.flaps_cmd = 0.0
        self.brakes = 0.0

    def set_controls(self, aileron: float, elevator: float, rudder: float) -> None:
        """Start from the control positions the trim left: outputs and integrators (bumpless start)."""
        self.aileron, self.elevator, self.rudder = aileron, elevator, rudder
        self.i_p, self.i_q, self.i_beta, self.i_psi = aileron, -elevator, -rudder, -rudder

    def take_back(self, axis: str, command: float) -> None:
        """Take an axis back after open-loop inputs freed it: its loop starts from ``command`` (bumpless)."""
        if axis == "aileron":
            self.aileron = self.i_p = command
        elif axis == "elevator":
            self.elevator = command
            self.i_q = -command
        elif axis == "rudder":
            self.rudder = command
            self.i_beta = self.i_psi = -command
        elif axis == "throttle":
            self.throttle = self.i_thr = command

    def begin_phase(self, hold: Hold, theta: float, throttle: float, flaps_deg: float) -> None:
        """Set the loops for a phase from the current pitch (rad), throttle and flap angle."""
        self.centreline = bool(hold.centreline)
        self.wing_low = bool(hold.wing_low)
        if hold.bank_deg is not None:
            self.lat_mode, self.lat_target = LAT_BANK, hold.bank_deg * D2R
        elif hold.heading_deg is not None:
            self.lat_mode, self.lat_target = LAT_HEADING, hold.heading_deg * D2R
        elif hold.roll_rate_degps is not None:
            self.lat_mode, self.lat_target = LAT_RATE, hold.roll_rate_degps * D2R
            self.rolled = self.t_phase = 0.0
        elif hold.centreline:
            self.lat_mode = LAT_TRACK
        else:
            self.lat_mode, self.lat_target = LAT_LEVEL, 0.0

        self.throttle_target = hold.throttle if hold.throttle is not None else -1.0
        self.speed_target = hold.airspeed_kts if hold.airspeed_kts is not None else -1.0
        self.speed_on_throttle = hold.airspeed_kts is not None and hold.throttle is None
        previous_mode = self.pitch_mode
        if hold.pitch_deg is not None:
            self.pitch_mode, self.pitch_target = PITCH_ATT, hold.pitch_deg * D2R
        elif hold.altitude_ft is not None:
            self.pitch_mode, self.pitch_target = PITCH_ALT, hold.altitude_ft
        elif hold.vertical_speed_fpm is not None:
            self.pitch_mode, self.pitch_target = PITCH_VS, hold.vertical_speed_fpm / 60.0
        elif hold.glide_path_deg is not None:
            self.pitch_mode, self.tan_gp = PITCH_GLIDE, math.tan(hold.glide_path_deg * D2R)
        elif hold.pitch_rate_degps is not None:
            self.pitch_mode, self.pitch_target = PITCH_RATE, hold.pitch_rate_degps * D2R
        elif hold.load_factor is not None:
            self.pitch_mode, self.pitch_target = PITCH_NZ, hold.load_factor
            self.i_n = 0.0
        elif hold.flare:
            self.pitch_mode = PITCH_FLARE
        elif hold.airspeed_kts is not None and hold.throttle is not None:
            self.pitch_mode = PITCH_SPEED
        else:
            self.pitch_mode, self.pitch_target = PITCH_ATT, theta
        if self.pitch_mode != previous_mode or self.pitch_mode == PITCH_ATT:
            self.i_path = theta  # the path loops' integrators hold a pitch command: start from the present one
        self.i_thr = throttle
        self.throttle = throttle
        if hold.flaps_deg is not None:
            self.flaps_cmd = hold.flaps_deg / self.flaps_full
        else:
            self.flaps_cmd = flaps_deg / self.flaps_full
        if hold.brakes is not None:
            self.brakes = hold.brakes

    def step(
        self,
        phi: float,
        theta: float,
        psi: float,
        p: float,
        q: float,
        r: float,
        beta: float,
        vc: float,
        gs_fps: float,
        track: float,
        hdot: float,
        h_msl: float,
        h_agl: float,
        x_rw_ft: float,
        y_rw_ft: float,
        wow: bool,
        nz: float,
        alpha: float,
        vt: float,
        fy_mps2: float = 0.0,
    ) -> None:
        """One control update from the current state (rad, rad/s, kt, ft, ft/s): :func:`pilot_step`.

        ``vc`` and ``vt`` are the calibrated and true airspeeds (kt), ``nz`` the last measured load
        factor (g), ``alpha`` the angle of attack (rad) and ``fy_mps2`` the last measured lateral specific force
        (body y, m/s^2).
        """
        PACK_INPUTS(self.buffer, INPUTS_OFFSET, phi, theta, psi, p, q, r, beta, vc, gs_fps, track, hdot, h_msl, h_agl,
                    x_rw_ft, y_rw_ft, 1.0 if wow else 0.0, nz, alpha, vt, fy_mps2)  # fmt: skip
        self.kernel(self.w)


def _slot(index: int, flag: bool = False) -> property:
    """An attribute of :class:`Pilot` kept in its slot ``index`` (a flag reads as a bool)."""

    def get(self: Pilot) -> Any:
        value = float(self.w[index])
        return value != 0.0 if flag else value

    def put(self: Pilot, value: float) -> None:
        self.w[index] = value

    return property(get, put)


_FLAGS = {"nz_protect", "speed_on_throttle", "centreline", "wing_low", "was_wow"}
for _i, _name in enumerate(PARAMS + STATE):
    setattr(Pilot, _name, _slot(_i, _name in _FLAGS))


def compiled_step() -> Any:
    """:func:`pilot_step`'s numba dispatcher (compiled, or loaded from numba's cache, at its first call; announced)."""
    fn = pilot_step
    if isinstance(fn, LazyJit):
        fn = fn.compiled()
    announce_compile(fn)
    return fn


@lazy_njit(cache=True, _nrt=False)
def pilot_step(w: np.ndarray) -> None:
    """One control update on the slots ``w`` (:data:`PARAMS`, :data:`STATE`, :data:`INPUTS`): reads the inputs, updates
    the state and the outputs in place.

    Compiled (numba, no fast-math: no fused multiply-add, no reordering); every expression keeps the operations and
    their order of the plain Python form, so the commands are the same bits as the interpreted function (tested
    against ``pilot_step.py_func`` on a list of Python floats).
    """
    phi = w[X_PHI]
    theta = w[X_THETA]
    psi = w[X_PSI]
    p = w[X_P]
    q = w[X_Q]
    r = w[X_R]
    beta = w[X_BETA]
    vc = w[X_VC]
    gs_fps = w[X_GS_FPS]
    track = w[X_TRACK]
    hdot = w[X_HDOT]
    h_msl = w[X_H_MSL]
    h_agl = w[X_H_AGL]
    x_rw_ft = w[X_X_RW_FT]
    y_rw_ft = w[X_Y_RW_FT]
    wow = w[X_WOW] != 0.0
    nz = w[X_NZ]
    alpha = w[X_ALPHA]
    vt = w[X_VT]
    fy_mps2 = w[X_FY_MPS2]
    # the clamps written inline, repeated values kept in locals
    dt = w[P_DT]
    vmin = w[P_VMIN]
    surf = w[P_SURF_RATE]
    v = vc if vc > vmin else vmin
    sc = (w[P_VREF] / v) ** w[P_SC_EXP]  # 2.0, from a slot: libm's pow, as CPython's (a literal 2 compiles to x * x)
    air = not wow
    vt_min = vt if vt > vmin else vmin
    vtk = vt_min * KT_TO_FPS  # ft/s
    vt_prev = w[S_VT_PREV]
    if vt_prev < 0.0:
        vt_prev = vt
    vdot = w[S_VDOT]
    vdot += ((vt - vt_prev) / dt - vdot) * w[P_A_VDOT]
    w[S_VDOT] = vdot
    w[S_VT_PREV] = vt
    w[S_FY_F] += (fy_mps2 - w[S_FY_F]) * w[P_A_FY]
    cphi = math.cos(phi)
    cth = math.cos(theta)
    sphi = math.sin(phi)
    if w[S_SPEED_ON_THROTTLE] != 0.0 or w[S_PITCH_MODE] == PITCH_SPEED:
        # the true-airspeed rate (kt/s) that closes the calibrated airspeed error in speed_tau_s, limited
        x = (w[S_SPEED_TARGET] - vc) / w[P_TAU_V]
        vdot_max = w[P_VDOT_MAX]
        x = -vdot_max if x < -vdot_max else vdot_max if x > vdot_max else x
        vdot_cmd = x * vt / vc if vc > 1.0 else x
    else:
        vdot_cmd = 0.0  # not used

    # ---- lateral: bank -> roll rate -> aileron
    mode = w[S_LAT_MODE]
    p_max = w[P_P_MAX]
    if mode == LAT_RATE:  # track the roll angle about the body x axis: target rate x time in the phase
        w[S_ROLLED] += p * dt
        w[S_T_PHASE] += dt
        x = w[P_K_PHI] * (w[S_LAT_TARGET] * w[S_T_PHASE] - w[S_ROLLED])
        p_cmd = w[S_LAT_TARGET] + (-p_max if x < -p_max else p_max if x > p_max else x)
    else:
        if mode == LAT_BANK:
            phi_cmd = w[S_LAT_TARGET]
        elif mode == LAT_HEADING:
            # lead the roll-out: aim at the heading the turn reaches while the bank comes off, the
            # turn rate g tan(phi) / V times half the roll-out time |phi| / p_max + 1 / k_phi
            bank = -1.0 if phi < -1.0 else 1.0 if phi > 1.0 else phi
            lead = G_FPS2 * math.tan(bank) / vtk * 0.5 * (abs(bank) / p_max + 1 / w[P_K_PHI])
            x = w[P_K_HDG] * ((w[S_LAT_TARGET] - psi - lead + math.pi) % TWO_PI - math.pi)
            bmax = w[P_BANK_MAX]
            phi_cmd = -bmax if x < -bmax else bmax if x > bmax else x
        elif mode == LAT_TRACK and air:
            # PI on the offset: the integral finds the bank a wing-low slip needs with no offset left
            off = w[P_K_Y] * (y_rw_ft + w[S_I_Y])
            imax = w[P_ICPT_MAX]
            if -imax < off < imax:
                x = w[S_I_Y] + w[P_K_Y_I] * y_rw_ft * dt
                lim = w[P_I_Y_MAX]
                w[S_I_Y] = -lim if x < -lim else lim if x > lim else x
            trk_cmd = w[P_RW_HDG] - (-imax if off < -imax else imax if off > imax else off)
            phi_cmd = w[P_K_TRK] * ((trk_cmd - track + math.pi) % TWO_PI - math.pi)
            if w[S_WING_LOW] != 0.0:  # bank into the wind as far as the side force of the slip needs: g sin(phi) = -f_y
                x = -w[S_FY_F] / (G_MPS2 * cth)
                phi_cmd += math.asin(-0.5 if x < -0.5 else 0.5 if x > 0.5 else x)
            bmax = w[P_BANK_MAX]
            phi_cmd = -bmax if phi_cmd < -bmax else bmax if phi_cmd > bmax else phi_cmd
        else:
            phi_cmd = 0.0
        x = w[P_K_PHI] * (phi_cmd - phi)
        p_cmd = -p_max if x < -p_max else p_max if x > p_max else x
    e = p_cmd - p
    # feed-forward of the aileron a steady roll at p_cmd needs (roll damping: proportional to p / V)
    ail_ff = w[P_K_PFF] * p_cmd * (w[P_VREF] / vt_min)
    ail = ail_ff + w[S_I_P] + sc * w[P_KP_P] * e
    if air and -1.0 < ail < 1.0:
        w[S_I_P] += w[P_KI_P] * e * dt
    d = (-1.0 if ail < -1.0 else 1.0 if ail > 1.0 else ail) - w[S_AILERON]
    w[S_AILERON] += -surf if d < -surf else surf if d > surf else d

    # ---- pitch: path -> pitch -> pitch rate -> elevator
    mode = w[S_PITCH_MODE]
    path_err = 0.0  # flight-path-angle error of the path modes (rad), for the throttle
    g_v = G_FPS2 / vtk  # pitch rate per g of a pull, rad/s
    z_down = cphi * cth  # vertical component of the body z axis
    if mode == PITCH_RATE:
        q_cmd = w[S_PITCH_TARGET]
    elif mode == PITCH_NZ:
        en = w[S_PITCH_TARGET] - nz
        q_cmd = g_v * (w[S_PITCH_TARGET] - z_down) + w[S_I_N] + w[P_K_N] * en
        q_stall = q + w[P_K_ALPHA] * (w[P_ALPHA_MAX] - alpha)  # the pitch rate that keeps alpha at its limit
        if q_cmd > q_stall:
            q_cmd = q_stall
        elif air:
            w[S_I_N] += w[P_K_N_I] * en * dt
    else:
        th_min, th_max = w[P_TH_MIN], w[P_TH_MAX]
        if mode == PITCH_ATT:
            th_cmd = w[S_PITCH_TARGET]
        else:
            if mode == PITCH_SPEED:
                # energy split: at a fixed throttle the power fixes gamma + vdot / g, so the path angle
                # that gives the wanted acceleration differs from the present one by (vdot - vdot_cmd) / g
                evs = (vdot - vdot_cmd) / G_KTPS
            else:
                if mode == PITCH_ALT:
                    x = w[P_K_ALT] * (w[S_PITCH_TARGET] - h_msl)
                    vs_max = w[P_VS_MAX]
                    vs_cmd = -vs_max if x < -vs_max else vs_max if x > vs_max else x
                elif mode == PITCH_VS:
                    vs_cmd = w[S_PITCH_TARGET]
                elif mode == PITCH_GLIDE:
                    h_gp = w[P_RW_ELEV] + (w[P_AIM_FT] - x_rw_ft) * w[S_TAN_GP]
                    vs_cmd = -gs_fps * w[S_TAN_GP] + w[P_K_GP] * (h_gp - h_msl)
                else:  # flare: sink proportional to the height of the wheels
                    hw = h_agl - w[P_CG_H]
                    vs_cmd = -(hw / w[P_TAU] if hw / w[P_TAU] > w[P_SINK_MIN] else w[P_SINK_MIN])
                evs = (vs_cmd - hdot) / (v * KT_TO_FPS)  # flight-path angle error, rad
                path_err = (vs_cmd - hdot) / vtk
            th_cmd = w[S_I_PATH] + w[P_KVS] * evs
            if air and th_min < th_cmd < th_max:
                w[S_I_PATH] += w[P_KVS_I] * evs * dt
        th_cmd = th_min if th_cmd < th_min else th_max if th_cmd > th_max else th_cmd
        x = w[P_K_TH] * (th_cmd - theta)
        q_max = w[P_Q_MAX]
        q_cmd = -q_max if x < -q_max else q_max if x > q_max else x
        if air and cphi > 0.2:
            q_cmd += g_v * sphi * sphi / cphi
    if air and w[P_NZ_PROTECT] != 0.0:  # load-factor protection
        q_hi = g_v * (w[P_N_HI] - z_down) + w[P_K_N] * (w[P_N_HI] - nz)
        q_lo = g_v * (w[P_N_LO] - z_down) + w[P_K_N] * (w[P_N_LO] - nz)
        q_cmd = q_hi if q_cmd > q_hi else q_lo if q_cmd < q_lo else q_cmd
    e = q_cmd - q
    u = w[S_I_Q] + sc * w[P_KP_Q] * e
    if (air or (vc >= w[P_VR] and e > 0.0)) and -1.0 < u < 1.0:  # on the ground: the rotation from Vr
        w[S_I_Q] += w[P_KI_Q] * e * dt
    d = -(-1.0 if u < -1.0 else 1.0 if u > 1.0 else u) - w[S_ELEVATOR]
    w[S_ELEVATOR] += -surf if d < -surf else surf if d > surf else d

    # ---- power
    if w[S_SPEED_ON_THROTTLE] != 0.0:
        # total energy: the throttle holds the specific energy rate gamma + vdot / g at what the path and
        # the speed commands need together (PI; the integrator stops where it would push a limit further)
        e = path_err + (vdot_cmd - vdot) / G_KTPS
        thr = w[S_I_THR] + w[P_KT] * e
        if (thr < 1.0 or e < 0.0) and (thr > 0.0 or e > 0.0):
            x = w[S_I_THR] + w[P_KT_I] * e * dt
            w[S_I_THR] = 0.0 if x < 0.0 else 1.0 if x > 1.0 else x
    elif w[S_THROTTLE_TARGET] >= 0.0:
        thr = w[S_THROTTLE_TARGET]
    else:
        thr = w[S_THROTTLE]
    thr = 0.0 if thr < 0.0 else 1.0 if thr > 1.0 else thr
    d = thr - w[S_THROTTLE]
    t_rate = w[P_THR_RATE]
    w[S_THROTTLE] += -t_rate if d < -t_rate else t_rate if d > t_rate else d

    # ---- yaw: coordination in the air, runway heading in the flare (decrab) and on the ground
    if wow or w[S_WING_LOW] != 0.0:
        if wow and w[S_WAS_WOW] == 0.0:  # touchdown: the tyres now hold the side force, the rudder starts central
            w[S_I_PSI] = 0.0
        if w[S_CENTRELINE] != 0.0 and wow:  # PI on the centreline offset: aim the nose back at it
            off = w[P_KG_Y] * (y_rw_ft + w[S_I_Y_GROUND])
            ymax = w[P_KG_YMAX]
            if -ymax < off < ymax:
                x = w[S_I_Y_GROUND] + w[P_KG_Y_I] * y_rw_ft * dt
                lim = w[P_IG_Y_MAX]
                w[S_I_Y_GROUND] = -lim if x < -lim else lim if x > lim else x
            psi_cmd = w[P_RW_HDG] - (-ymax if off < -ymax else ymax if off > ymax else off)
        elif w[S_CENTRELINE] != 0.0:
            psi_cmd = w[P_RW_HDG]
        else:
            psi_cmd = psi
        e = (psi_cmd - psi + math.pi) % TWO_PI - math.pi
        k = 1.0 if wow else sc
        yaw = w[S_I_PSI] + k * (w[P_KG_PSI] * e - w[P_KG_R] * r)  # + : nose right wanted
        if -1.0 < yaw < 1.0:
            w[S_I_PSI] += w[P_KG_I] * e * dt
        yaw = -1.0 if yaw < -1.0 else 1.0 if yaw > 1.0 else yaw
        d = -yaw - w[S_RUDDER]
        w[S_RUDDER] += -surf if d < -surf else surf if d > surf else d
        w[S_STEER] = w[P_STEER_SIGN] * w[S_RUDDER] if wow else 0.0
        w[S_I_BETA] = -w[S_RUDDER]
    else:
        r_coord = g_v * sphi * cth
        # rudder with the roll (aileron-rudder interconnect: against the adverse yaw), then PI on the sideslip
        rud = -w[P_K_ARI] * ail_ff - (w[S_I_BETA] + sc * w[P_KB] * beta) + sc * w[P_KYD] * (r - r_coord)
        if -1.0 < rud < 1.0:
            w[S_I_BETA] += w[P_KB_I] * beta * dt
        d = (-1.0 if rud < -1.0 else 1.0 if rud > 1.0 else rud) - w[S_RUDDER]
        w[S_RUDDER] += -surf if d < -surf else surf if d > surf else d
        w[S_STEER] = 0.0
        w[S_I_PSI] = -w[S_RUDDER]
    w[S_WAS_WOW] = 1.0 if wow else 0.0
