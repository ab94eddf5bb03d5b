"""End-to-end physics of the three washouts, against first principles, closed forms and an independent ODE.

Everything here is computed WITHOUT the package's own filters, rotations or vestibular model:

- a continuous-time, single-plane model of each washout (pitch plane for surge, roll plane for sway and roll
  rate) written from the paper's block diagrams with plain trigonometry and ``scipy.signal`` transfer functions,
  integrated by ``scipy.integrate.solve_ivp``;
- closed forms: the translational high-pass step response, the steady tilt atan(f/g), the head specific force
  of a tilted cockpit at rest, the equilibrium of the unrestricted washout in a steady coordinated turn;
- perception with the otolith transfer function (Eq. 11) simulated by ``scipy.signal.lsim``.

Frames (DESIGN.md): body x forward, y right, z down; NED inertial; g_I = [0, 0, +g]; f = a - g.
"""

import math

import numpy as np
import pytest
from scipy import signal
from scipy.integrate import solve_ivp
from scipy.optimize import fsolve
from scipy.spatial.transform import Rotation

from washbench.cueing import WASHOUT_NAMES, cue_trace, load_washout_params
from washbench.platform import load_platform_limits

G = 9.80665
DT = 1.0 / 120.0
PARAMS = load_washout_params()
LIMITS = load_platform_limits()
K_TILT = PARAMS.tilt.gain_per_s
TILT_RATE_MAX = math.radians(PARAMS.tilt.rate_limit_degps)
TRANSLATION_SAT = ("pos", "vel", "acc", "rate", "angacc")


def rest(n: int) -> tuple[np.ndarray, np.ndarray]:
    f = np.zeros((n, 3))
    f[:, 2] = -G
    return f, np.zeros((n, 3))


def euler_zyx(q: np.ndarray) -> np.ndarray:
    """(N, 3) roll, pitch, yaw (rad) of scalar-first body->inertial quaternions, via scipy."""
    return Rotation.from_quat(q[:, [1, 2, 3, 0]]).as_euler("ZYX")[:, ::-1]


def smooth_ramp(t: np.ndarray | float, t0: float, rise: float) -> np.ndarray | float:
    """0 before t0, 1 after t0 + rise, a half cosine in between (continuous first derivative)."""
    s = np.clip((np.asarray(t) - t0) / rise, 0.0, 1.0)
    return 0.5 - 0.5 * np.cos(np.pi * s)


def otolith_perceived(f: np.ndarray) -> np.ndarray:
    """Eq. 11 (tau_L 5.33, tau_S 0.66, tau_a 13.2, K 0.4) by scipy.signal.lsim, started in steady state."""
    sys = signal.TransferFunction([0.4 * 13.2, 1.0], np.polymul([5.33, 1.0], [0.66, 1.0]))
    t = np.arange(len(f)) * DT
    ss = sys.to_ss()
    x0 = -np.linalg.solve(ss.A, ss.B[:, 0] * f[0])  # steady state of the first sample (DC gain 1)
    _, y, _ = signal.lsim(ss, f, t, X0=x0)
    return y


# ---------------------------------------------------------------- independent continuous single-plane washout


class _Lti:
    """A SISO transfer function as continuous state space (scipy.signal), stepped inside an ODE."""

    def __init__(self, num: list[float], den: list[float]) -> None:
        if len(den) == 1:  # a static gain: no state
            self.a, self.b, self.c, self.d = np.zeros((0, 0)), np.zeros((0, 1)), np.zeros((1, 0)), np.array([[num[0]]])
        else:
            self.a, self.b, self.c, self.d = signal.tf2ss(num, den)
        self.n = self.a.shape[0]

    def steady(self, u: float) -> np.ndarray:
        return -np.linalg.solve(self.a, self.b[:, 0] * u) if self.n else np.zeros(0)

    def out(self, x: np.ndarray, u: float) -> float:
        return float(self.c[0] @ x + self.d[0, 0] * u) if self.n else float(self.d[0, 0] * u)

    def dx(self, x: np.ndarray, u: float) -> np.ndarray:
        return self.a @ x + self.b[:, 0] * u if self.n else np.zeros(0)


def hp2(wn: float) -> _Lti:
    return _Lti([1.0, 0.0, 0.0], [1.0, 2 * wn, wn * wn])  # Eq. 2


def lp2(wn: float) -> _Lti:
    return _Lti([4 * wn * wn], [1.0, 4 * wn, 4 * wn * wn])  # Eq. 3


def hp1(wn: float) -> _Lti:
    return _Lti([1.0], [1.0]) if wn == 0.0 else _Lti([1.0, 0.0], [1.0, wn])  # Eq. 6, wn = 0: identity


def deriv(w2: float) -> _Lti:
    return _Lti([w2, 0.0], [1.0, w2])  # Eq. 8


def plane_reference(washout: str, plane: str, t: np.ndarray, f_lat, f_z, rate) -> dict[str, np.ndarray]:
    """Continuous washout confined to one plane, written from the paper's block diagrams.

    plane "pitch": attitude angle a = pitch theta, lateral axis x (surge), rotation about body y.
    plane "roll": a = roll phi, lateral axis y (sway), rotation about body x.
    In one plane the body rate equals the Euler-angle rate, L_IS is a plane rotation, and the tilt
    coordination rate K (g_S x f)/(|g_S||f|) has one component:
      pitch: g_S = g(-sin a, 0, cos a): (g_S x f)_y / g = cos a f_x + sin a f_z
      roll:  g_S = g(0, sin a, cos a): (g_S x f)_x / g = sin a f_z - cos a f_y.
    f_lat(t), f_z(t): aircraft specific force (m/s^2); rate(t): aircraft body rate in the plane (rad/s).
    Returns the tilt angle a, head lateral/vertical specific force and head rate in the plane, and the
    platform's lateral/vertical position, sampled at t.
    """
    tr = PARAMS.translational_highpass_wn_radps
    lp = PARAMS.tilt.lowpass_wn_radps
    rot = PARAMS.rotational.highpass_wn_radps
    lat_wn = tr.x if plane == "pitch" else tr.y
    lat_lp = lp.x if plane == "pitch" else lp.y
    sgn = 1.0 if plane == "pitch" else -1.0  # pitch: x_I = cos f_x + sin f_z; roll: y_I = cos f_y - sin f_z
    small = washout == "small-angle"
    rot_wn = 0.0 if washout == "unrestricted" else (rot.pitch if plane == "pitch" else rot.roll)
    blocks = {
        "hp_lat": hp2(lat_wn),
        "hp_z": hp2(tr.z),
        "lp_a": lp2(lat_lp),  # small-angle: on the tilt rate; others: on f_lat
        "lp_z": lp2(lp.z),  # others: on f_z
        "hp_rot": hp1(rot_wn),
        "est": deriv(PARAMS.head.derivative_wn_radps),  # small-angle head rate (Eq. 8 on the Euler angle)
    }
    names = list(blocks)
    sizes = [blocks[k].n for k in names]
    offs = np.cumsum([0, *sizes])
    n_f = int(offs[-1])

    def tilt_raw(a: float, fl: float, fz: float) -> float:
        c = math.cos(a) * fl + math.sin(a) * fz if plane == "pitch" else math.sin(a) * fz - math.cos(a) * fl
        return K_TILT * c / math.hypot(fl, fz)

    def parts(tt: float, y: np.ndarray):
        a = y[n_f]
        xs = {k: y[offs[i] : offs[i + 1]] for i, k in enumerate(names)}
        fl, fz, w = f_lat(tt), f_z(tt), rate(tt)
        if small:
            raw = tilt_raw(a, fl, fz)
            w_tilt = float(np.clip(blocks["lp_a"].out(xs["lp_a"], raw), -TILT_RATE_MAX, TILT_RATE_MAX))
            u_lp = (raw, 0.0)
        else:
            fl_f = blocks["lp_a"].out(xs["lp_a"], fl)
            fz_f = blocks["lp_z"].out(xs["lp_z"], fz)
            w_tilt = float(np.clip(tilt_raw(a, fl_f, fz_f), -TILT_RATE_MAX, TILT_RATE_MAX))
            u_lp = (fl, fz)
        a_dot = w_tilt + blocks["hp_rot"].out(xs["hp_rot"], w)
        ca, sa = math.cos(a), math.sin(a)
        u_lat = ca * fl + sgn * sa * fz  # L_IS f, lateral inertial component
        u_z = -sgn * sa * fl + ca * fz + G  # vertical, + g_I
        acc_lat = blocks["hp_lat"].out(xs["hp_lat"], u_lat)
        acc_z = blocks["hp_z"].out(xs["hp_z"], u_z)
        return xs, a, a_dot, u_lp, w, u_lat, u_z, acc_lat, acc_z

    def rhs(tt: float, y: np.ndarray) -> np.ndarray:
        xs, a, a_dot, u_lp, w, u_lat, u_z, acc_lat, acc_z = parts(tt, y)
        d = np.empty_like(y)
        ins = {"hp_lat": u_lat, "hp_z": u_z, "lp_a": u_lp[0], "lp_z": u_lp[1], "hp_rot": w, "est": a}
        for i, k in enumerate(names):
            d[offs[i] : offs[i + 1]] = blocks[k].dx(xs[k], ins[k])
        d[n_f] = a_dot
        d[n_f + 1 : n_f + 3] = (acc_lat, acc_z)  # velocity
        d[n_f + 3 : n_f + 5] = y[n_f + 1 : n_f + 3]  # position
        return d

    fl0, fz0, w0 = f_lat(t[0]), f_z(t[0]), rate(t[0])
    assert fl0 == 0.0 and fz0 == -G and w0 == 0.0  # the reference starts level at rest
    y0 = np.zeros(n_f + 5)
    for i, k in enumerate(names):
        u0 = {"hp_lat": 0.0, "hp_z": 0.0, "lp_a": 0.0 if small else fl0, "lp_z": fz0, "hp_rot": 0.0, "est": 0.0}[k]
        y0[offs[i] : offs[i + 1]] = blocks[k].steady(u0)
    sol = solve_ivp(rhs, (t[0], t[-1]), y0, t_eval=t, max_step=DT, rtol=1e-8, atol=1e-10)
    assert sol.success
    out = {k: np.empty(len(t)) for k in ("angle", "head_f_lat", "head_f_z", "head_rate", "pos_lat", "pos_z")}
    for j, tt in enumerate(t):
        y = sol.y[:, j]
        xs, a, a_dot, _, _, _, _, acc_lat, acc_z = parts(tt, y)
        ca, sa = math.cos(a), math.sin(a)
        # head: L_SI (a - g_I), R_SS = 0
        out["head_f_lat"][j] = ca * acc_lat - sgn * sa * (acc_z - G)
        out["head_f_z"][j] = sgn * sa * acc_lat + ca * (acc_z - G)
        out["head_rate"][j] = blocks["est"].out(xs["est"], a) if small else a_dot
        out["angle"][j] = a
        out["pos_lat"][j] = y[n_f + 3]
        out["pos_z"][j] = y[n_f + 4]
    return out


def _compare_plane(washout: str, plane: str, f: np.ndarray, w: np.ndarray, f_lat, f_z, rate, tol: dict) -> None:
    t = np.arange(len(f)) * DT
    tr = cue_trace(f, w, DT, [washout], PARAMS, LIMITS)[washout]
    assert all(tr.saturation_counts[k] == 0 for k in TRANSLATION_SAT)  # the platform follows exactly
    ref = plane_reference(washout, plane, t, f_lat, f_z, rate)
    lat, ang = (0, 1) if plane == "pitch" else (1, 0)
    eul = euler_zyx(tr.q)
    other = [i for i in range(3) if i != ang]
    assert np.abs(eul[:, other]).max() < 1e-9  # stays in its plane
    np.testing.assert_allclose(eul[:, ang], ref["angle"], atol=tol["angle"], rtol=0)
    np.testing.assert_allclose(tr.head_f_mps2[:, lat], ref["head_f_lat"], atol=tol["f"], rtol=0)
    np.testing.assert_allclose(tr.head_f_mps2[:, 2], ref["head_f_z"], atol=tol["f"], rtol=0)
    np.testing.assert_allclose(tr.head_omega_radps[:, ang], ref["head_rate"], atol=tol["rate"], rtol=0)
    np.testing.assert_allclose(tr.pos_m[:, lat], ref["pos_lat"], atol=tol["pos"], rtol=0)
    np.testing.assert_allclose(tr.pos_m[:, 2], ref["pos_z"], atol=tol["pos"], rtol=0)


# Tolerances: the discrete washout (Tustin filters, one-sample attitude delay in L_IS and g_S, Euler
# integration of the set point) differs from the continuous model by O(dt) = 1/120 s. Measured worst
# cases: angle 7e-4 rad (of 0.25 rad), head f 6.4e-3 m/s^2, head rate 9.5e-4 rad/s (of 0.13), platform
# 4.7 mm (of 0.76 m); the bounds are about twice that, far below what a sign or frame error would give.
TOL = {"angle": 1.5e-3, "f": 0.015, "rate": 2e-3, "pos": 0.01}


@pytest.mark.parametrize("washout", WASHOUT_NAMES)
def test_surge_profile_matches_independent_continuous_washout(washout):
    n = int(30 / DT)
    amp = 2.5

    def f_lat(tt):
        return amp * (smooth_ramp(tt, 1.0, 1.0) - smooth_ramp(tt, 15.0, 2.0))

    def f_z(tt):
        return -G

    def rate(tt):
        return 0.0

    t = np.arange(n) * DT
    f, w = rest(n)
    f[:, 0] = f_lat(t)
    _compare_plane(washout, "pitch", f, w, f_lat, f_z, rate, TOL)


@pytest.mark.parametrize("washout", WASHOUT_NAMES)
def test_sway_and_roll_rate_profile_matches_independent_continuous_washout(washout):
    n = int(30 / DT)

    def f_lat(tt):
        return 1.5 * (smooth_ramp(tt, 1.0, 1.0) - smooth_ramp(tt, 12.0, 2.0))

    def f_z(tt):
        return -G - 2.0 * (smooth_ramp(tt, 4.0, 0.5) - smooth_ramp(tt, 6.0, 0.5))

    def rate(tt):
        return math.radians(8.0) * (smooth_ramp(tt, 17.0, 1.0) - smooth_ramp(tt, 19.0, 1.0))

    t = np.arange(n) * DT
    f, w = rest(n)
    f[:, 1] = f_lat(t)
    f[:, 2] = f_z(t)
    w[:, 0] = rate(t)
    _compare_plane(washout, "roll", f, w, f_lat, f_z, rate, TOL)


# ---------------------------------------------------------------- sustained specific force: tilt coordination


@pytest.mark.parametrize("washout", WASHOUT_NAMES)
@pytest.mark.parametrize(("axis", "amp"), [(0, 2.0), (0, -2.0), (1, 2.0), (1, -2.0)], ids=["+x", "-x", "+y", "-y"])
def test_sustained_specific_force_step_is_felt_with_its_sign(washout, axis, amp):
    n = int(60 / DT)
    k0 = 120
    f, w = rest(n)
    f[k0:, axis] = amp
    tr = cue_trace(f, w, DT, [washout], PARAMS, LIMITS)[washout]
    head = tr.head_f_mps2[:, axis]
    # onset: the translational channel accelerates the platform along the force (NED x or y, the simulator
    # faces north); the head feels the step at once. The bilinear filter's first sample is the mean of the
    # continuous step response over the first interval, about 1 - wn dt = 0.97 of the step (sway wn 3.5).
    assert np.sign(tr.acc_mps2[k0, axis]) == np.sign(amp)
    assert np.sign(tr.pos_m[k0 + 30, axis]) == np.sign(amp)
    assert head[k0] == pytest.approx(amp, rel=0.04)
    # sustained: tilted so that gravity supplies it. |f| at the head is g, its direction that of the aircraft's f
    expected = G * amp / math.hypot(amp, G)
    assert head[-1] == pytest.approx(expected, abs=1e-3)
    assert tr.head_f_mps2[-1, 2] == pytest.approx(-G * G / math.hypot(amp, G), abs=1e-3)
    roll, pitch, _ = euler_zyx(tr.q)[-1]
    if axis == 0:  # f_x > 0: nose UP (pitch > 0) presses the pilot into the seat back
        assert pitch == pytest.approx(math.atan(amp / G), abs=1e-4)
    else:  # f_y > 0: roll LEFT (phi < 0) so that gravity pushes the pilot towards +y ... and vice versa
        assert roll == pytest.approx(-math.atan(amp / G), abs=1e-4)
    assert np.sign(head[-int(20 / DT) :]).min() == np.sign(amp) == np.sign(head[-int(20 / DT) :]).max()
    # the classical washout's transient false cue: the high-pass step response (1 - wn t) e^{-wn t} dips to
    # -e^{-2} of the step at t = 2/wn; the growing tilt only fills it in, never deepens it
    assert (np.sign(amp) * head[k0:]).min() > -abs(amp) * math.exp(-2.0)
    # perceived (Eq. 11 by lsim): same sign as the aircraft pilot's from the onset on, and close in the end
    p_sim = otolith_perceived(head)
    p_air = otolith_perceived(f[:, axis])
    assert (np.sign(amp) * p_sim[k0 + 1 :] > 0).all()
    assert p_sim[-1] == pytest.approx(p_air[-1], rel=0.03)
    # the platform comes back towards the centre (low-order filters: a residual offset ~ f/wn^2 at most)
    wn = (PARAMS.translational_highpass_wn_radps.x, PARAMS.translational_highpass_wn_radps.y)[axis]
    assert abs(tr.pos_m[-1, axis]) < abs(amp) / wn**2


@pytest.mark.parametrize("washout", WASHOUT_NAMES)
@pytest.mark.parametrize(("fx", "fy"), [(3.0, 0.0), (0.0, -2.0), (2.0, 1.5)])
def test_tilted_cockpit_at_rest_feels_gravity_components(washout, fx, fy):
    # a sustained specific force from the first sample: the simulator starts tilted and at rest
    n = 240
    f, w = rest(n)
    f[:, 0] = fx
    f[:, 1] = fy
    tr = cue_trace(f, w, DT, [washout], PARAMS, LIMITS)[washout]
    assert np.abs(tr.pos_m).max() < 1e-12 and np.abs(tr.acc_mps2).max() < 1e-9
    roll, pitch, _ = euler_zyx(tr.q)[0]
    # f_head = L_SI (0 - g_I) = [g sin(theta), -g sin(phi) cos(theta), -g cos(phi) cos(theta)]
    expected = [G * math.sin(pitch), -G * math.sin(roll) * math.cos(pitch), -G * math.cos(roll) * math.cos(pitch)]
    np.testing.assert_allclose(tr.head_f_mps2, np.tile(expected, (n, 1)), atol=1e-9)
    # ... and that is the aircraft's specific force scaled to |g|
    np.testing.assert_allclose(expected, G * f[0] / np.linalg.norm(f[0]), atol=1e-9)
    if fy == 0.0:  # the brief's case: pitched nose up by theta, f = [g sin theta, 0, -g cos theta]
        assert pitch == pytest.approx(math.atan2(fx, G), abs=1e-12) and pitch > 0


# ---------------------------------------------------------------- heave: closed form of the translational channel


@pytest.mark.parametrize("washout", WASHOUT_NAMES)
def test_heave_onset_moves_platform_up_and_matches_closed_form(washout):
    n = int(10 / DT)
    k0 = 120
    d = -0.5 * G  # pull-up: f_z from -g to -1.5 g (more negative)
    f, w = rest(n)
    f[k0:, 2] += d
    tr = cue_trace(f, w, DT, [washout], PARAMS, LIMITS)[washout]
    wn = PARAMS.translational_highpass_wn_radps.z
    t = np.arange(n) * DT
    u = f[:, 2] + G  # inertial acceleration input of the channel (level cockpit): L_IS f + g_I
    # s^2/(s+wn)^2 then two integrators: acceleration and position, by scipy (input linear between samples,
    # which matches the bilinear filters to O((wn dt)^2)). Closed form for a step d:
    # a = d (1 - wn t) e^{-wn t}, z = d/wn^2 (1 - (1 + wn t) e^{-wn t}) -> d/wn^2 (up by 0.4 m).
    _, a_ref, _ = signal.lsim(signal.TransferFunction([1.0, 0.0, 0.0], [1.0, 2 * wn, wn * wn]), u, t)
    _, z_ref, _ = signal.lsim(signal.TransferFunction([1.0], [1.0, 2 * wn, wn * wn]), u, t)
    tt = t[k0:] - t[k0]
    np.testing.assert_allclose(z_ref[-1], d / wn**2 * (1 - (1 + wn * tt[-1]) * np.exp(-wn * tt[-1])), rtol=1e-3)
    assert tr.pos_m[k0 + 1, 2] < 0 and tr.vel_mps[k0 + 1, 2] < 0  # up is -z in NED
    assert tr.head_f_mps2[k0, 2] < -1.45 * G  # the pilot is pressed into the seat at once
    np.testing.assert_allclose(tr.acc_mps2[:, 2], a_ref, atol=0.005 * abs(d))
    # position: the semi-implicit Euler double integration leads the continuous one by about a sample (v dt)
    np.testing.assert_allclose(tr.pos_m[:, 2], z_ref, atol=0.025 * abs(d) / wn**2)
    np.testing.assert_allclose(tr.head_f_mps2[:, 2], tr.acc_mps2[:, 2] - G, atol=1e-12)  # level: f = a - g
    assert np.abs(euler_zyx(tr.q)).max() < 1e-12  # no tilt for a force along the body z axis
    assert tr.head_f_mps2[-1, 2] == pytest.approx(-G, abs=1e-3)  # sustained g-load is washed out


# ---------------------------------------------------------------- rotational channel


@pytest.mark.parametrize("washout", WASHOUT_NAMES)
@pytest.mark.parametrize("axis", [0, 1, 2], ids=["roll", "pitch", "yaw"])
@pytest.mark.parametrize("sign", [1.0, -1.0], ids=["pos", "neg"])
def test_rate_pulse_onset_has_the_same_sign_at_the_head(washout, axis, sign):
    n = int(8 / DT)
    k0 = 120
    rate = sign * math.radians(10.0)
    f, w = rest(n)
    w[k0 : k0 + 120, axis] = rate
    tr = cue_trace(f, w, DT, [washout], PARAMS, LIMITS)[washout]
    head = tr.head_omega_radps[:, axis]
    assert np.abs(head[:k0]).max() < 1e-15
    # onset: same sign from the first sample on, growing (platform angular acceleration limit / Eq. 8 lag)
    assert (sign * head[k0 : k0 + 24] > 0).all()
    peak = sign * head[k0 : k0 + 120].max() if sign > 0 else sign * head[k0 : k0 + 120].min()
    assert peak > 0.5 * abs(rate)
    others = [i for i in range(3) if i != axis]
    assert np.abs(tr.head_omega_radps[k0 : k0 + 24, others]).max() < 1e-3 * abs(rate)


@pytest.mark.parametrize("washout", WASHOUT_NAMES)
def test_body_rate_of_a_pitched_simulator_is_felt_about_the_body_axis(washout):
    # A yaw rate about the body z axis of a nose-up cockpit must be felt about the body z axis, not as roll.
    # Quaternion washouts: Eq. 17 integrates body rates, Eq. 18 measures body rates. Small-angle: T_s (Eq. 4)
    # turns r into Euler rates phi_dot = r tan(theta), psi_dot = r / cos(theta), and R_S (Eq. 9) gives back
    # p = phi_dot - sin(theta) psi_dot = 0. (Treating r as an Euler or inertial rate would show
    # -r sin(theta) = -2.9 deg/s of roll.)
    n = int(4 / DT)
    k0 = 120
    fx = 3.0
    f = np.tile([fx, 0.0, -G], (n, 1))
    w = np.zeros((n, 3))
    r = math.radians(10.0)
    w[k0:, 2] = r
    tr = cue_trace(f, w, DT, [washout], PARAMS, LIMITS)[washout]
    theta = math.atan2(fx, G)
    assert euler_zyx(tr.q)[k0 - 1, 1] == pytest.approx(theta, abs=1e-12)
    head = tr.head_omega_radps[k0 : k0 + 12]
    # the first 0.1 s: the platform's angular acceleration ramp about body z, no roll or pitch yet
    assert (head[:, 2] > 0).all()
    assert np.abs(head[:, :2]).max() < 0.02 * r


def test_heading_turns_the_translational_cue_with_the_simulator():
    # unrestricted: yaw the cockpit by 90 deg (to face east), then a surge onset must move the platform EAST
    n = int(10 / DT)
    f, w = rest(n)
    t = np.arange(n) * DT
    w[:, 2] = math.radians(30.0) * (smooth_ramp(t, 0.5, 0.5) - smooth_ramp(t, 3.5, 0.5))
    k0 = int(5 / DT)
    f[k0:, 0] = 2.0
    tr = cue_trace(f, w, DT, ["unrestricted"], PARAMS, LIMITS)["unrestricted"]
    yaw = euler_zyx(tr.q)[k0 - 1, 2]
    assert yaw == pytest.approx(math.radians(90.0), abs=math.radians(1.0))  # 30 deg/s for 3 s
    move = (tr.pos_m[k0 + 60] - tr.pos_m[k0 - 1])[:2]  # horizontal (the tilt adds a little heave)
    heading = np.array([math.cos(yaw), math.sin(yaw)])
    assert move @ heading > 0.05
    assert abs(move[0] * heading[1] - move[1] * heading[0]) < 1e-3 * np.linalg.norm(move)
    assert tr.head_f_mps2[k0 + 1, 0] > 1.8  # and the pilot feels the onset forward


# ---------------------------------------------------------------- coordinated turn


def coordinated_turn(speed_mps: float, bank_deg: float = 30.0, duration_s: float = 90.0):
    """Level coordinated turn entered from wings level: roll in over 3 s, then hold the bank.

    Pilot at the centre of gravity: f = [0, 0, -g / cos(phi)] (no side force); turn rate about the
    inertial vertical Omega = g tan(phi) / V, in body axes [phi_dot, Omega sin(phi), Omega cos(phi)].
    """
    n = int(duration_s / DT)
    t = np.arange(n) * DT
    phi = math.radians(bank_deg) * smooth_ramp(t, 2.0, 3.0)
    phi_dot = np.gradient(phi, DT)
    om = G * np.tan(phi) / speed_mps
    f = np.zeros((n, 3))
    f[:, 2] = -G / np.cos(phi)
    w = np.stack([phi_dot, om * np.sin(phi), om * np.cos(phi)], axis=1)
    return f, w


def unrestricted_turn_equilibrium(omega_body: np.ndarray) -> np.ndarray:
    """Head specific force of the unrestricted washout settled in a steady turn (f along body z).

    Steady state: the cockpit turns about the inertial vertical, so its body rate w_air + w_tilt is parallel
    to the gravity direction u = g_S/|g_S| (body axes); w_tilt = K u x f_hat = K (-u_y, u_x, 0) for
    f_hat = [0, 0, -1]. Three equations for u (unit): the part of w_air perpendicular to u cancels w_tilt.
    The platform then only turns, so the head feels f = -g u.
    """

    def eqs(v):
        u = v / np.linalg.norm(v)
        w_tilt = K_TILT * np.array([-u[1], u[0], 0.0])
        return omega_body + w_tilt - (omega_body @ u) * u

    u = fsolve(eqs, np.array([0.0, 0.0, 1.0]), xtol=1e-13)
    u /= np.linalg.norm(u)
    return -G * u


@pytest.mark.parametrize("speed_mps", [50.0, 100.0])
def test_coordinated_turn_is_bounded_and_has_no_sustained_false_cue(speed_mps):
    f, w = coordinated_turn(speed_mps)
    traces = cue_trace(f, w, DT, WASHOUT_NAMES, PARAMS, LIMITS)
    settled = int(30 / DT)
    for name, tr in traces.items():
        for field in ("pos_m", "q", "head_f_mps2", "head_omega_radps"):
            assert np.isfinite(getattr(tr, field)).all()
        assert all(tr.saturation_counts[k] == 0 for k in TRANSLATION_SAT), name  # inside every limit
        # during the roll-in every washout rolls the cockpit right and gives the known false sway cue to the
        # LEFT (f_y < 0; the aircraft pilot feels none) before the tilt coordination levels it again
        fy = tr.head_f_mps2[:, 1]
        first = int(np.argmax(np.abs(fy) > 0.1))
        assert fy[first] < 0 and fy[: int(8 / DT)].min() < -1.0
        if name != "unrestricted":
            # the rotational high-pass washes the turn rate out: level again, no sustained sway or surge
            assert np.abs(tr.head_f_mps2[settled:, :2]).max() < 0.05, name
            assert tr.head_f_mps2[-1, 2] == pytest.approx(-G, abs=1e-3)  # the 1.15 g is washed out too
            assert np.abs(tr.head_omega_radps[-1]).max() < math.radians(0.05)
    # unrestricted: the body rates are passed on without a high-pass while the tilt coordination holds the
    # cockpit level, so the part of the turn rate perpendicular to gravity (Omega sin(phi)) is fought by the
    # tilt rate K sin(alpha) <= 3 deg/s. It settles where the two cancel: a sustained residual tilt (false
    # surge/sway cue) inherent to the paper's unrestricted washout with this tilt gain.
    tr = traces["unrestricted"]
    om = G * math.tan(math.radians(30.0)) / speed_mps
    omega_body = om * np.array([0.0, 0.5, math.sqrt(3) / 2])
    if om * 0.5 < TILT_RATE_MAX:  # the tilt can hold it: closed-form equilibrium
        expected = unrestricted_turn_equilibrium(omega_body)
        np.testing.assert_allclose(tr.head_f_mps2[-int(5 / DT) :], np.tile(expected, (int(5 / DT), 1)), atol=0.01)
        assert tr.saturation_counts["tilt_rate"] < int(10 / DT)
    else:  # 3 deg/s is not enough: the tilt rate limit binds for good, the false cue stays bounded
        assert tr.saturated["tilt_rate"][-int(10 / DT) :].all()
    assert np.abs(tr.head_f_mps2[settled:, :2]).max() < G * math.sin(math.radians(20.0))
    assert np.linalg.norm(tr.head_f_mps2[-1]) == pytest.approx(G, rel=0.03)
