"""Vestibular models against their continuous transfer functions (scipy.signal) and closed forms."""

import math

import numpy as np
import pytest
import scipy.signal

from washbench.errors import WashbenchError
from washbench.io.yamlio import load_yaml_model
from washbench.perception import ZACHARIAS, CanalParams, OtolithParams, VestibularModel, VestibularParams
from washbench.perception.thresholds import STANDARD_GRAVITY_MPS2, deadband
from washbench.perception.vestibular import canal_model, otolith_model

DTS = (1 / 50, 1 / 120, 1 / 1000)
G = STANDARD_GRAVITY_MPS2


def otolith_continuous(p: OtolithParams | None = None) -> scipy.signal.TransferFunction:
    """Eq. 11 written out independently of the package."""
    p = p or OtolithParams()
    return scipy.signal.TransferFunction([p.K * p.tau_a_s, 1.0], np.polymul([p.tau_L_s, 1.0], [p.tau_S_s, 1.0]))


def canal_continuous(p: CanalParams | None = None) -> scipy.signal.TransferFunction:
    """Eq. 12 written out independently of the package."""
    p = p or CanalParams()
    den = np.polymul(np.polymul([p.T_L_s, 1.0], [p.T_S_s, 1.0]), [p.T_a_s, 1.0])
    return scipy.signal.TransferFunction([p.T_L_s * p.T_a_s, 0.0, 0.0], den)


def grid(duration_s: float, dt: float) -> np.ndarray:
    return np.arange(round(duration_s / dt) + 1) * dt


def test_paper_defaults() -> None:
    o, c = OtolithParams(), CanalParams()
    assert (o.K, o.tau_L_s, o.tau_S_s, o.tau_a_s) == (0.4, 5.33, 0.66, 13.2)
    assert (c.T_L_s, c.T_S_s, c.T_a_s) == (10.2, 0.1, 30.0)
    assert VestibularParams().thresholds is None  # dead band off by default


@pytest.mark.parametrize("dt", DTS)
@pytest.mark.parametrize("which", ["otolith", "canal"])
def test_step_and_sine_match_lsim(which: str, dt: float) -> None:
    """Zero start, a step at 2 s plus a 0.4 Hz sine: equal to scipy's continuous simulation (linear input)."""
    model = otolith_model(OtolithParams(), dt) if which == "otolith" else canal_model(CanalParams(), dt)
    sys = otolith_continuous() if which == "otolith" else canal_continuous()
    t = grid(40.0, dt)
    u = np.where(t >= 2.0, 1.5, 0.0) + 0.7 * np.where(t >= 2.0, np.sin(2 * np.pi * 0.4 * (t - 2.0)), 0.0)
    y = model.apply(u)
    _, y_ref, _ = scipy.signal.lsim(sys, u, t)
    assert np.max(np.abs(y - y_ref)) < 1e-9


def test_otolith_step_matches_closed_form() -> None:
    """Unit step: y = 1 - A exp(-t/tau_L) - B exp(-t/tau_S), A, B from partial fractions by hand."""
    p = OtolithParams()
    a = (p.tau_L_s - p.K * p.tau_a_s) / (p.tau_L_s - p.tau_S_s)
    b = (p.K * p.tau_a_s - p.tau_S_s) / (p.tau_L_s - p.tau_S_s)
    dt = 1 / 1000
    t = grid(30.0, dt)
    u = np.ones_like(t)
    u[0] = 0.0  # the step happens over the first interval (linear between samples)
    y = otolith_model(p, dt).apply(u)
    ts = t - dt / 2  # a ramp over one step is a step delayed by half a step, to O(dt^2)
    exact = 1 - a * np.exp(-ts / p.tau_L_s) - b * np.exp(-ts / p.tau_S_s)
    assert np.max(np.abs(y[1:] - exact[1:])) < 1e-5
    assert y[-1] == pytest.approx(1.0 - a * math.exp(-30 / p.tau_L_s), abs=1e-5)


@pytest.mark.parametrize("dt", DTS)
@pytest.mark.parametrize("freq_hz", [0.05, 0.5, 2.0])
@pytest.mark.parametrize("which", ["otolith", "canal"])
def test_sine_steady_state_matches_freqresp(which: str, freq_hz: float, dt: float) -> None:
    """Long sine: amplitude and phase of the last periods equal |H(jw)| and arg H(jw) (scipy freqresp)."""
    model = otolith_model(OtolithParams(), dt) if which == "otolith" else canal_model(CanalParams(), dt)
    sys = otolith_continuous() if which == "otolith" else canal_continuous()
    w = 2 * np.pi * freq_hz
    duration = 600.0  # the slowest pole (30 s) has decayed by exp(-20) by the end
    t = grid(duration, dt)
    y = model.apply(np.sin(w * t))
    _, h = scipy.signal.freqresp(sys, [w])
    expected = np.abs(h[0]) * np.sin(w * t + np.angle(h[0]))
    tail = t > duration - 2.0 / freq_hz
    # input linear between samples: a sine is seen attenuated by about (w dt)^2 / 12, nothing else
    tol = np.abs(h[0]) * (1.05 * (w * dt) ** 2 / 12 + 1e-8)
    assert np.max(np.abs(y[tail] - expected[tail])) < tol


@pytest.mark.parametrize("dt", DTS)
def test_steady_state_start(dt: float) -> None:
    """Constant input: otolith output equals it from the first sample (DC gain 1); canals give exactly ~0."""
    n = round(60 / dt)
    f = np.tile([1.3, -0.4, -G], (n, 1))
    w = np.tile([0.2, -0.1, 0.5], (n, 1))
    vm = VestibularModel(dt)
    p = vm.perceive(f, w)
    assert np.max(np.abs(p.f_mps2 - f)) < 1e-12
    assert np.max(np.abs(p.omega_radps)) < 1e-12
    assert vm.otolith.dc_gain == pytest.approx(1.0, abs=1e-14)
    assert vm.canals.dc_gain == pytest.approx(0.0, abs=1e-14)


def test_level_start_perceives_minus_g_and_then_responds() -> None:
    """Level flight then a 1 m/s^2 heave step at 5 s: perceived heave is -g until the step, no start transient."""
    dt = 1 / 120
    t = grid(20.0, dt)
    f = np.zeros((t.size, 3))
    f[:, 2] = -G + np.where(t >= 5.0, -1.0, 0.0)
    p = VestibularModel(dt).perceive(f, np.zeros_like(f))
    before = t < 5.0
    assert np.max(np.abs(p.f_mps2[before, 2] + G)) < 1e-12
    assert np.max(np.abs(p.f_mps2[:, :2])) == 0.0
    # after the step: the closed-form unit step response of Eq. 11, scaled by -1 m/s^2 (no overshoot: K tau_a < tau_L)
    o = OtolithParams()
    a = (o.tau_L_s - o.K * o.tau_a_s) / (o.tau_L_s - o.tau_S_s)
    b = (o.K * o.tau_a_s - o.tau_S_s) / (o.tau_L_s - o.tau_S_s)
    ts = t[~before] - 5.0 + dt / 2
    exact = -G - (1 - a * np.exp(-ts / o.tau_L_s) - b * np.exp(-ts / o.tau_S_s))
    assert np.max(np.abs(p.f_mps2[~before, 2] - exact)) < 1e-3
    assert np.all(np.diff(p.f_mps2[~before, 2]) < 0)


def test_canal_ramp_gives_zero_in_the_long_run() -> None:
    """Double zero at s = 0: a steady angular acceleration is perceived as a constant-rate that decays to 0."""
    dt = 1 / 120
    t = grid(400.0, dt)
    w = np.zeros((t.size, 3))
    w[:, 2] = 0.01 * t  # rad/s, ramp
    y = canal_model(CanalParams(), dt).apply(w[:, 2])
    assert abs(y[-1]) < 1e-4 * 0.01 * 30  # T_L T_a alpha exp(-t/30)-type tail is tiny after 400 s


def test_repeated_time_constants_rejected() -> None:
    with pytest.raises(ValueError, match="must differ"):
        otolith_model(OtolithParams(tau_L_s=1.0, tau_S_s=1.0), 0.01)


def test_deadband_zacharias_values_and_shape() -> None:
    assert (ZACHARIAS.f_x_mps2, ZACHARIAS.f_y_mps2, ZACHARIAS.f_z_mps2) == (0.17, 0.17, 0.28)
    assert (ZACHARIAS.omega_x_degps, ZACHARIAS.omega_y_degps, ZACHARIAS.omega_z_degps) == (3.0, 3.6, 2.6)
    x = np.array([-1.0, -0.2, 0.0, 0.1, 0.5])
    np.testing.assert_allclose(deadband(x, 0.25), [-0.75, 0.0, 0.0, 0.0, 0.25])


def test_thresholds_applied_when_enabled() -> None:
    dt = 1 / 120
    t = grid(10.0, dt)
    f = np.tile([0.0, 0.0, -G], (t.size, 1))
    f[:, 0] = 0.1 * np.sin(t)  # below 0.17 m/s^2 everywhere
    w = np.zeros_like(f)
    w[:, 0] = np.radians(10.0) * np.sin(2 * t)  # well above 3 deg/s
    off = VestibularModel(dt).perceive(f, w)
    on = VestibularModel(dt, VestibularParams(thresholds=ZACHARIAS)).perceive(f, w)
    assert np.abs(off.f_mps2[:, 0]).max() > 0.05
    assert np.all(on.f_mps2[:, 0] == 0.0)
    np.testing.assert_allclose(on.f_mps2[:, 2], -G, atol=1e-12)  # resting heave is kept, not dead-banded away
    big = np.abs(off.omega_radps[:, 0]) > np.radians(3.0)
    expected = np.sign(off.omega_radps[big, 0]) * (np.abs(off.omega_radps[big, 0]) - np.radians(3.0))
    np.testing.assert_allclose(on.omega_radps[big, 0], expected, atol=1e-15)


def test_params_from_yaml_reject_unknown_key(tmp_path) -> None:
    good = tmp_path / "v.yaml"
    good.write_text("otolith:\n  K: 0.5\nthresholds: {}\n")
    p = load_yaml_model(good, VestibularParams)
    assert p.otolith.K == 0.5 and p.thresholds == ZACHARIAS
    bad = tmp_path / "bad.yaml"
    bad.write_text("canals:\n  T_L_s: 10.2\n  T_x_s: 1\n")
    with pytest.raises(WashbenchError, match=r"bad.yaml:3: canals.T_x_s: unknown key"):
        load_yaml_model(bad, VestibularParams)


def test_batch_axis_equals_single_axis() -> None:
    """Filtering (N, 3) at once equals filtering each column alone (bit for bit)."""
    rng = np.random.default_rng(1)
    u = rng.normal(size=(5000, 3))
    m = canal_model(CanalParams(), 1 / 120)
    y = m.apply(u)
    for i in range(3):
        assert np.array_equal(y[:, i], m.apply(u[:, i]))


@pytest.mark.parametrize("dt", DTS)
def test_sections_fed_in_chunks_equal_the_whole_trace_bit_for_bit(dt: float) -> None:
    # washbench cue feeds the vestibular models chunk by chunk (bounded memory); lfilter is the independent check
    rng = np.random.default_rng(7)
    u = np.cumsum(rng.normal(size=(3000, 3)), axis=0) * 0.01 + np.array([0.3, -0.2, -9.8])
    for model in (otolith_model(OtolithParams(), dt), canal_model(CanalParams(), dt)):
        expected = np.zeros_like(u)
        for (b1, b0), phi in zip(model.b, model.phi, strict=True):
            bb, aa = np.array([b1, b0]), np.array([1.0, -phi])
            zi = scipy.signal.lfilter_zi(bb, aa)[None, :] * u[0]
            expected += scipy.signal.lfilter(bb, aa, u, axis=0, zi=zi)[0]
        whole = model.apply(u)
        np.testing.assert_allclose(whole, expected, rtol=1e-10, atol=1e-10)  # input about 10: 1e-11 relative
        state = model.start(u[0])
        chunks = [model.run(u[a:b], state) for a, b in ((0, 1), (1, 1000), (1000, 1001), (1001, 3000))]
        np.testing.assert_array_equal(np.concatenate(chunks), whole)
