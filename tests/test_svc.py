"""The 6-DOF subjective vertical conflict model (MSI): against its closed forms for vertical motion, scipy's lsim,
an independent solve_ivp of the published equations, the gravity a rotation leaves, and the O'Hanlon-McCauley
frequency of greatest sickness."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import pytest
from scipy import signal
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation
from scipy.stats import norm

from washbench.perception import svc

G = 9.80665


def _vertical(a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Head specific force (z down) and zero rotation for a vertical acceleration ``a`` (up positive)."""
    f = np.zeros((len(a), 3))
    f[:, 2] = -(G + a)
    return f, np.zeros_like(f)


def test_vertical_conflict_is_the_closed_form_filter() -> None:
    """Vertical motion only: |v_s - hv_s| = |G(s) a| with G = (1 - K_a) s / ((1 + K_ac) tau s^2 + s + K_vc),
    simulated by scipy.signal.lsim (first-order hold, as the model's input) from rest on the deviation from the
    first sample (the model starts in the steady state of its first sample)."""
    dt = 1 / 120
    t = np.arange(int(120 / dt)) * dt
    a = 1.2 * np.sin(2 * np.pi * 0.13 * t) + 0.7 * np.sin(2 * np.pi * 0.41 * t + 1.0) + np.where(t > 30, 0.8, 0.0)
    out = svc.svc_msi(*_vertical(a), dt)
    _, y, _ = signal.lsim(signal.lti(*svc.vertical_conflict_tf()), a - a[0], t)
    np.testing.assert_allclose(out.conflict_mps2, np.abs(y), atol=2e-7)
    assert np.max(np.abs(y)) > 0.4  # a conflict worth the Hill function (b = 0.5 m/s^2)


def test_two_hours_at_0_2_hz_settle_at_the_closed_form_incidence() -> None:
    """1 m/s^2 at 0.2 Hz for 2 h: MSI = P (1 - 1/sqrt(1 + k^2)) (1 - e^-T/tau_I (1 + T/tau_I)), k = |G| A / b (the
    mean of the Hill function over a period, through the 12-min second-order lag); 43 % with In1."""
    dt = 1 / 60
    t = np.arange(int(7200 / dt) + 1) * dt
    out = svc.svc_msi(*_vertical(np.sin(2 * np.pi * 0.2 * t)), dt)
    s = 2j * np.pi * 0.2
    k = abs(0.9 * s / (3.0 * s * s + s + 5.0)) / 0.5  # In1: K_a 0.1, K_ac 0.5, tau 2 s, K_vc 5, b 0.5 m/s^2
    lag = 1 - math.exp(-10) * 11  # T / tau_I = 7200 / 720
    expected = 85 * (1 - 1 / math.sqrt(1 + k * k)) * lag
    assert out.msi_pct[-1] == pytest.approx(expected, rel=2e-4)
    assert out.msi_pct[-1] == pytest.approx(svc.steady_msi_vertical(1.0, 0.2) * lag, rel=2e-4)
    assert 40 < out.msi_pct[-1] < 46
    assert np.all(np.diff(out.msi_pct) >= -1e-12)  # the critically damped lag of a non-negative input


def test_sickest_frequency_is_near_o_hanlon_and_mccauley() -> None:
    """The steady MSI against frequency at a fixed acceleration peaks at sqrt(K_vc / ((1 + K_ac) tau)) / 2 pi =
    0.205 Hz; the O'Hanlon-McCauley fit (Lloyd 1989: MSI = 100 Phi((log10(a_rms/g) - mu)/0.4), mu = -0.819 +
    2.32 log10(omega)^2, omega in rad/s) peaks at 1 rad/s = 0.159 Hz; seasickness is greatest near 0.16-0.2 Hz."""
    freqs = np.linspace(0.05, 0.5, 451)
    svc_curve = [svc.steady_msi_vertical(1.0, f) for f in freqs]
    f_svc = freqs[int(np.argmax(svc_curve))]
    ohm = [norm.cdf((math.log10(1 / math.sqrt(2) / G) + 0.819 - 2.32 * math.log10(2 * np.pi * f) ** 2) / 0.4)
           for f in freqs]  # fmt: skip
    f_ohm = freqs[int(np.argmax(ohm))]
    assert f_svc == pytest.approx(math.sqrt(5 / 3) / (2 * np.pi), abs=1e-3)
    assert f_ohm == pytest.approx(1 / (2 * np.pi), abs=1e-3)
    assert 0.155 <= f_ohm < f_svc <= 0.21
    # the simulated model agrees with the closed form away from the peak too (1 h at 0.1 and 0.33 Hz)
    dt = 1 / 30
    t = np.arange(int(3600 / dt) + 1) * dt
    lag = 1 - math.exp(-5) * 6
    for f in (0.1, 0.33):
        out = svc.svc_msi(*_vertical(np.sin(2 * np.pi * f * t)), dt)
        assert out.msi_pct[-1] == pytest.approx(svc.steady_msi_vertical(1.0, f) * lag, rel=1e-3)


def _reference_rhs(p: svc.SvcParams, u_of_t: Callable[[float], tuple[np.ndarray, np.ndarray]]) -> Callable:
    """The published In1 equations (docs/fidelity.md), written again with numpy vectors, for solve_ivp."""
    c1, c0 = 1 / p.tau_d_s + 1 / p.tau_a_s, 1 / (p.tau_d_s * p.tau_a_s)

    def rhs(t: float, x: np.ndarray) -> np.ndarray:
        w, f = u_of_t(t)
        xs, dxs, vs, hvs, xh, xvc, g, dm, m = (x[0:3], x[3:6], x[6:9], x[9:12], x[12:15], x[15:18], x[18:21],
                                               x[21], x[22])  # fmt: skip
        ws = c1 * dxs + c0 * xs + w
        hf = (p.k_a * (f - g) + p.k_vc * xvc + p.k_ac * (f - vs + hvs)) / (1 + p.k_ac)
        hws = (xh + p.k_w * w + p.k_wc * ws) / (1 + p.k_wc)
        r = (np.linalg.norm(vs - hvs) / p.b_mps2) ** p.n
        return np.concatenate([
            dxs, -c1 * dxs - c0 * xs - w,
            (f - vs) / p.tau_s - np.cross(ws, vs),
            (hf - hvs) / p.tau_s - np.cross(hws, hvs),
            -(xh + p.k_w * w + p.k_wc * (ws - hws)) / p.tau_d_s,
            vs - hvs,
            -np.cross(w, g),
            [(-2 * p.tau_i_s * dm - m + p.p_pct * r / (1 + r)) / p.tau_i_s**2, dm],
        ])  # fmt: skip

    return rhs


@pytest.mark.parametrize("params", [svc.IN1, svc.WADA2018, svc.SvcParams(n=3.0, b_mps2=0.3)],
                         ids=["in1", "wada2018", "hill-n3"])  # fmt: skip
def test_six_dof_motion_against_an_independent_solve_ivp(params: svc.SvcParams) -> None:
    """A smooth roll to 25 deg held (tilt coordination), a surge pulse and a yaw sine, 40 s: the compiled RK4 on
    120 Hz samples against solve_ivp (DOP853, tight tolerances) of the equations written again in the test, on
    the same motion as functions of time."""
    dt = 1 / 120
    t = np.arange(int(40 / dt) + 1) * dt
    phi0 = np.radians(25.0)

    def motion(tt: np.ndarray | float) -> tuple[np.ndarray, np.ndarray]:
        tt = np.asarray(tt, dtype=float)
        ramp = (tt >= 5) & (tt < 9)
        phi = np.where(tt < 5, 0.0, np.where(ramp, phi0 * (1 - np.cos(np.pi * (tt - 5) / 4)) / 2, phi0))
        p_rate = np.where(ramp, phi0 * np.pi / 8 * np.sin(np.pi * (tt - 5) / 4), 0.0)
        w = np.stack([p_rate, np.zeros_like(tt), 0.3 * np.sin(2 * np.pi * 0.25 * tt)], axis=-1)
        ax = np.where((tt >= 20) & (tt < 26), 1.5 * np.sin(np.pi * (tt - 20) / 6) ** 2, 0.0)
        f = np.stack([ax, G * np.sin(phi), -G * np.cos(phi)], axis=-1)  # gravity in the rolled head, plus surge
        return w, f

    w, f = motion(t)
    out = svc.svc_msi(f, w, dt, params)
    x0 = svc.steady_state(f[0], params)
    sol = solve_ivp(_reference_rhs(params, motion), (0, t[-1]), x0, method="DOP853", t_eval=t[::120],
                    rtol=1e-9, atol=1e-11)  # fmt: skip
    conflict = np.linalg.norm(sol.y[6:9] - sol.y[9:12], axis=0)
    # the model holds the input linear between samples: an error of (dt^2 / 8) u'' at most, about 1e-5 here
    np.testing.assert_allclose(out.conflict_mps2[::120], conflict, rtol=1e-4, atol=1e-6)
    np.testing.assert_allclose(out.msi_pct[::120], sol.y[22], rtol=1e-4, atol=1e-9)
    assert out.msi_pct[-1] > 1e-4 and conflict.max() > 0.2


def test_gravity_follows_the_head_and_a_held_posture_is_quiet() -> None:
    """g' = -omega x g: after a roll and a pitch at known rates, the model's gravity is the inertial down vector
    seen in the rotated head (scipy Rotation). A head held still, upright or tilted, feels no conflict."""
    dt = 1 / 120
    w = np.zeros((1300, 3))
    w[:600, 0] = np.radians(6.0)  # a roll of about 30 deg, a pause, then a pitch of about 20 deg (body axes)
    w[660:1260, 1] = np.radians(4.0)
    f = np.tile([0.0, 0.0, -G], (len(w), 1))  # the input f does not drive g; any f will do
    stream = svc.SvcStream(dt)
    stream.update(f, w)
    roll, pitch = (float(np.trapezoid(w[:, i], dx=dt)) for i in (0, 1))  # the model's input is linear in a step
    r = Rotation.from_rotvec([roll, 0, 0]) * Rotation.from_rotvec([0, pitch, 0])
    g_head = r.inv().apply([0.0, 0.0, -G])  # the initial gravity (-g0 along z) seen from the turned head
    np.testing.assert_allclose(stream._x[18:21], g_head, atol=1e-6)
    for tilt in (0.0, 20.0):
        rot = Rotation.from_euler("x", tilt, degrees=True)
        held = np.tile(rot.inv().apply([0.0, 0.0, -G]), (600, 1))
        out = svc.svc_msi(held, np.zeros_like(held), dt)
        assert np.max(out.conflict_mps2) < 1e-9 and out.msi_pct[-1] == 0.0


def test_chunks_give_the_same_bits_and_rest_start() -> None:
    dt = 1 / 100
    rng = np.random.default_rng(5)
    n = 3001
    f = np.tile([0.0, 0.0, -G], (n, 1)) + rng.normal(0, 0.5, (n, 3))
    w = rng.normal(0, 0.1, (n, 3))
    whole = svc.svc_msi(f, w, dt)
    s = svc.SvcStream(dt)
    parts = [s.update(f[a : a + 700], w[a : a + 700]) for a in range(0, n, 700)]
    np.testing.assert_array_equal(np.concatenate([p.msi_pct for p in parts]), whole.msi_pct)
    np.testing.assert_array_equal(np.concatenate([p.conflict_mps2 for p in parts]), whole.conflict_mps2)
    assert s.msi_pct == whole.msi_pct[-1] == svc.head_msi(f, w, dt)
    # from rest: the first sample is a step away from [0, 0, -g0], so a conflict follows at once
    rest = svc.svc_msi(f, w, dt, start="rest")
    assert rest.msi_pct[0] > 0.0 or rest.conflict_mps2[0] > 0.0


def test_bad_inputs_are_clear_errors() -> None:
    with pytest.raises(ValueError, match="shape"):
        svc.svc_msi(np.zeros((5, 2)), np.zeros((5, 2)), 0.01)
    with pytest.raises(ValueError, match="dt"):
        svc.SvcStream(0.0)
    with pytest.raises(ValueError, match="tau_i_s"):
        svc.SvcParams(tau_i_s=0.0)
    with pytest.raises(ValueError, match="k_vc"):
        svc.SvcParams(k_vc=math.nan)
    with pytest.raises(ValueError, match="k_vc"):
        svc.SvcParams(k_vc=0.0)  # no conflict integral: no steady state
    with pytest.raises(ValueError, match="non-zero"):
        svc.steady_state(np.zeros(3))  # free fall fixes no vertical
    # so a trace that starts in free fall (an all-zero file) starts from rest, upright: weightless from there on,
    # the sensed vertical leaves the internal one and the incidence grows from 0
    out = svc.svc_msi(np.zeros((600, 3)), np.zeros((600, 3)), 0.01)
    assert out.msi_pct[0] == 0.0 and np.all(np.isfinite(out.msi_pct)) and np.all(np.diff(out.msi_pct) >= 0.0)
    assert out.msi_pct[-1] > 0.0
