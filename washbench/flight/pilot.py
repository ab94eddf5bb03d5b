"""The scripted pilot: cascaded PI loops run at every JSBSim step, in plain Python floats.

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

from washbench.flight.manoeuvre_schema import Hold, Runway
from washbench.flight.profile import PilotProfile

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


class Pilot:
    """Closed-loop pilot for one flight; ``begin_phase`` at each phase, ``step`` at every FDM step.

    After ``step`` the commands are in ``aileron``, ``elevator`` (+ nose down), ``rudder``
    (+ nose left), ``steer``, ``throttle``; ``flaps_cmd`` (0..1 of full travel) and
    ``brakes`` change only at phase starts.
    """

    def __init__(self, profile: PilotProfile, runway: Runway | None, dt_s: float) -> None:
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
        """One control update from the current state (rad, rad/s, kt, ft, ft/s).

        ``vc`` and ``vt`` are the calibrated and true airspeeds (kt), ``nz`` the last measured load
        factor (g), ``alpha`` the angle of attack (rad) and ``fy_mps2`` the last measured lateral specific force
        (body y, m/s^2).
        """
        # Hot path (every FDM step): the clamps are written inline and repeated values kept in locals. Every
        # expression keeps the operations and their order of the plain form, so the commands are the same bits.
        dt = self.dt
        vmin = self.vmin
        surf = self.surf_rate
        v = vc if vc > vmin else vmin
        sc = (self.vref / v) ** 2
        air = not wow
        vt_min = vt if vt > vmin else vmin
        vtk = vt_min * KT_TO_FPS  # ft/s
        vt_prev = self.vt_prev
        if vt_prev < 0.0:
            vt_prev = vt
        vdot = self.vdot
        vdot += ((vt - vt_prev) / dt - vdot) * self.a_vdot
        self.vdot = vdot
        self.vt_prev = vt
        self.fy_f += (fy_mps2 - self.fy_f) * self.a_fy
        cphi = math.cos(phi)
        cth = math.cos(theta)
        sphi = math.sin(phi)
        if self.speed_on_throttle or self.pitch_mode == PITCH_SPEED:
            # the true-airspeed rate (kt/s) that closes the calibrated airspeed error in speed_tau_s, limited
            x = (self.speed_target - vc) / self.tau_v
            vdot_max = self.vdot_max
            x = -vdot_max if x < -vdot_max else vdot_max if x > vdot_max else x
            vdot_cmd = x * vt / vc if vc > 1.0 else x
        else:
            vdot_cmd = 0.0  # not used

        # ---- lateral: bank -> roll rate -> aileron
        mode = self.lat_mode
        p_max = self.p_max
        if mode == LAT_RATE:  # track the roll angle about the body x axis: target rate x time in the phase
            self.rolled += p * dt
            self.t_phase += dt
            x = self.k_phi * (self.lat_target * self.t_phase - self.rolled)
            p_cmd = self.lat_target + (-p_max if x < -p_max else p_max if x > p_max else x)
        else:
            if mode == LAT_BANK:
                phi_cmd = self.lat_target
            elif mode == LAT_HEADING:
                # lead the roll-out: aim at the heading the turn reaches while the bank comes off, the
                # turn rate g tan(phi) / V times half the roll-out time |phi| / p_max + 1 / k_phi
                bank = -1.0 if phi < -1.0 else 1.0 if phi > 1.0 else phi
                lead = G_FPS2 * math.tan(bank) / vtk * 0.5 * (abs(bank) / p_max + 1 / self.k_phi)
                x = self.k_hdg * ((self.lat_target - psi - lead + math.pi) % TWO_PI - math.pi)
                bmax = self.bank_max
                phi_cmd = -bmax if x < -bmax else bmax if x > bmax else x
            elif mode == LAT_TRACK and air:
                # PI on the offset: the integral finds the bank a wing-low slip needs with no offset left
                off = self.k_y * (y_rw_ft + self.i_y)
                imax = self.icpt_max
                if -imax < off < imax:
                    x = self.i_y + self.k_y_i * y_rw_ft * dt
                    lim = self.i_y_max
                    self.i_y = -lim if x < -lim else lim if x > lim else x
                trk_cmd = self.rw_hdg - (-imax if off < -imax else imax if off > imax else off)
                phi_cmd = self.k_trk * ((trk_cmd - track + math.pi) % TWO_PI - math.pi)
                if self.wing_low:  # bank into the wind as far as the side force of the slip needs: g sin(phi) = -f_y
                    x = -self.fy_f / (G_MPS2 * cth)
                    phi_cmd += math.asin(-0.5 if x < -0.5 else 0.5 if x > 0.5 else x)
                bmax = self.bank_max
                phi_cmd = -bmax if phi_cmd < -bmax else bmax if phi_cmd > bmax else phi_cmd
            else:
                phi_cmd = 0.0
            x = self.k_phi * (phi_cmd - phi)
            p_cmd = -p_max if x < -p_max else p_max if x > p_max else x
        e = p_cmd - p
        # feed-forward of the aileron a steady roll at p_cmd needs (roll damping: proportional to p / V)
        ail_ff = self.k_pff * p_cmd * (self.vref / vt_min)
        ail = ail_ff + self.i_p + sc * self.kp_p * e
        if air and -1.0 < ail < 1.0:
            self.i_p += self.ki_p * e * dt
        d = (-1.0 if ail < -1.0 else 1.0 if ail > 1.0 else ail) - self.aileron
        self.aileron += -surf if d < -surf else surf if d > surf else d

        # ---- pitch: path -> pitch -> pitch rate -> elevator
        mode = self.pitch_mode
        path_err = 0.0  # flight-path-angle error of the path modes (rad), for the throttle
        g_v = G_FPS2 / vtk  # pitch rate per g of a pull, rad/s
        z_down = cphi * cth  # vertical component of the body z axis
        if mode == PITCH_RATE:
            q_cmd = self.pitch_target
        elif mode == PITCH_NZ:
            en = self.pitch_target - nz
            q_cmd = g_v * (self.pitch_target - z_down) + self.i_n + self.k_n * en
            q_stall = q + self.k_alpha * (self.alpha_max - alpha)  # the pitch rate that keeps alpha at its limit
            if q_cmd > q_stall:
                q_cmd = q_stall
            elif air:
                self.i_n += self.k_n_i * en * dt
        else:
            th_min, th_max = self.th_min, self.th_max
            if mode == PITCH_ATT:
                th_cmd = self.pitch_target
            else:
                if mode == PITCH_SPEED:
                    # energy split: at a fixed throttle the power fixes gamma + vdot / g, so the path angle
                    # that gives the wanted acceleration differs from the present one by (vdot - vdot_cmd) / g
                    evs = (vdot - vdot_cmd) / G_KTPS
                else:
                    if mode == PITCH_ALT:
                        x = self.k_alt * (self.pitch_target - h_msl)
                        vs_max = self.vs_max
                        vs_cmd = -vs_max if x < -vs_max else vs_max if x > vs_max else x
                    elif mode == PITCH_VS:
                        vs_cmd = self.pitch_target
                    elif mode == PITCH_GLIDE:
                        h_gp = self.rw_elev + (self.aim_ft - x_rw_ft) * self.tan_gp
                        vs_cmd = -gs_fps * self.tan_gp + self.k_gp * (h_gp - h_msl)
                    else:  # flare: sink proportional to the height of the wheels
                        hw = h_agl - self.cg_h
                        vs_cmd = -(hw / self.tau if hw / self.tau > self.sink_min else self.sink_min)
                    evs = (vs_cmd - hdot) / (v * KT_TO_FPS)  # flight-path angle error, rad
                    path_err = (vs_cmd - hdot) / vtk
                th_cmd = self.i_path + self.kvs * evs
                if air and th_min < th_cmd < th_max:
                    self.i_path += self.kvs_i * evs * dt
            th_cmd = th_min if th_cmd < th_min else th_max if th_cmd > th_max else th_cmd
            x = self.k_th * (th_cmd - theta)
            q_max = self.q_max
            q_cmd = -q_max if x < -q_max else q_max if x > q_max else x
            if air and cphi > 0.2:
                q_cmd += g_v * sphi * sphi / cphi
        if air and self.nz_protect:  # load-factor protection
            q_hi = g_v * (self.n_hi - z_down) + self.k_n * (self.n_hi - nz)
            q_lo = g_v * (self.n_lo - z_down) + self.k_n * (self.n_lo - nz)
            q_cmd = q_hi if q_cmd > q_hi else q_lo if q_cmd < q_lo else q_cmd
        e = q_cmd - q
        u = self.i_q + sc * self.kp_q * e
        if (air or (vc >= self.vr and e > 0.0)) and -1.0 < u < 1.0:  # on the ground: the rotation from Vr
            self.i_q += self.ki_q * e * dt
        d = -(-1.0 if u < -1.0 else 1.0 if u > 1.0 else u) - self.elevator
        self.elevator += -surf if d < -surf else surf if d > surf else d

        # ---- power
        if self.speed_on_throttle:
            # total energy: the throttle holds the specific energy rate gamma + vdot / g at what the path and
            # the speed commands need together (PI; the integrator stops where it would push a limit further)
            e = path_err + (vdot_cmd - vdot) / G_KTPS
            thr = self.i_thr + self.kt * e
            if (thr < 1.0 or e < 0.0) and (thr > 0.0 or e > 0.0):
                x = self.i_thr + self.kt_i * e * dt
                self.i_thr = 0.0 if x < 0.0 else 1.0 if x > 1.0 else x
        elif self.throttle_target >= 0.0:
            thr = self.throttle_target
        else:
            thr = self.throttle
        thr = 0.0 if thr < 0.0 else 1.0 if thr > 1.0 else thr
        d = thr - self.throttle
        t_rate = self.thr_rate
        self.throttle += -t_rate if d < -t_rate else t_rate if d > t_rate else d

        # ---- yaw: coordination in the air, runway heading in the flare (decrab) and on the ground
        if wow or self.wing_low:
            if wow and not self.was_wow:  # touchdown: the tyres now hold the side force, the rudder starts central
                self.i_psi = 0.0
            if self.centreline and wow:  # PI on the centreline offset: aim the nose back at it
                off = self.kg_y * (y_rw_ft + self.i_y_ground)
                ymax = self.kg_ymax
                if -ymax < off < ymax:
                    x = self.i_y_ground + self.kg_y_i * y_rw_ft * dt
                    lim = self.ig_y_max
                    self.i_y_ground = -lim if x < -lim else lim if x > lim else x
                psi_cmd = self.rw_hdg - (-ymax if off < -ymax else ymax if off > ymax else off)
            elif self.centreline:
                psi_cmd = self.rw_hdg
            else:
                psi_cmd = psi
            e = (psi_cmd - psi + math.pi) % TWO_PI - math.pi
            k = 1.0 if wow else sc
            yaw = self.i_psi + k * (self.kg_psi * e - self.kg_r * r)  # + : nose right wanted
            if -1.0 < yaw < 1.0:
                self.i_psi += self.kg_i * e * dt
            yaw = -1.0 if yaw < -1.0 else 1.0 if yaw > 1.0 else yaw
            d = -yaw - self.rudder
            self.rudder += -surf if d < -surf else surf if d > surf else d
            self.steer = self.steer_sign * self.rudder if wow else 0.0
            self.i_beta = -self.rudder
        else:
            r_coord = g_v * sphi * cth
            # rudder with the roll (aileron-rudder interconnect: against the adverse yaw), then PI on the sideslip
            rud = -self.k_ari * ail_ff - (self.i_beta + sc * self.kb * beta) + sc * self.kyd * (r - r_coord)
            if -1.0 < rud < 1.0:
                self.i_beta += self.kb_i * beta * dt
            d = (-1.0 if rud < -1.0 else 1.0 if rud > 1.0 else rud) - self.rudder
            self.rudder += -surf if d < -surf else surf if d > surf else d
            self.steer = 0.0
            self.i_psi = -self.rudder
        self.was_wow = wow
