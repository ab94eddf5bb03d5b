"""Discretised washout filters against their continuous transfer functions (scipy.signal)."""

import numpy as np
import pytest
from scipy import signal

from washbench.cueing import filters
from washbench.cueing.filters import discretise, run_filter

DT = 1.0 / 120.0

CASES = [
    ("translational high-pass surge", filters.translational_highpass(1.5)),
    ("translational high-pass sway", filters.translational_highpass(3.5)),
    ("tilt low-pass surge", filters.tilt_lowpass(1.5)),
    ("tilt low-pass sway", filters.tilt_lowpass(3.5)),
    ("rotational high-pass", filters.rotational_highpass(0.5)),
    ("derivative estimator", filters.derivative_estimator(12.5)),
]


def discrete_freqresp(coef: np.ndarray, w: np.ndarray, dt: float) -> np.ndarray:
    """H(z) = C (zI - A)^-1 B + D at z = exp(j w dt), evaluated with numpy from the packed matrices."""
    a = coef[:4].reshape(2, 2)
    b = coef[4:6]
    c = coef[6:8]
    out = []
    for wk in w:
        z = np.exp(1j * wk * dt)
        out.append(c @ np.linalg.solve(z * np.eye(2) - a, b) + coef[8])
    return np.array(out)


@pytest.mark.parametrize(("name", "tf"), CASES, ids=[c[0] for c in CASES])
def test_frequency_response_matches_continuous(name, tf):
    w = np.logspace(-2, 1.3, 40)  # 0.01 .. 20 rad/s, well below Nyquist (377 rad/s)
    h_disc = discrete_freqresp(discretise(tf, DT), w, DT)
    # the bilinear transform maps the continuous response exactly at the pre-warped frequency
    w_warped = 2.0 / DT * np.tan(w * DT / 2.0)
    _, h_warped = signal.freqresp(signal.lti(*tf), w_warped)
    np.testing.assert_allclose(h_disc, h_warped, rtol=1e-9, atol=1e-12)
    # and close to it at the same frequency: warping is (w dt)^2 / 12 < 0.25 % in frequency here
    _, h_cont = signal.freqresp(signal.lti(*tf), w)
    np.testing.assert_allclose(h_disc, h_cont, rtol=1e-2, atol=1e-6)


@pytest.mark.parametrize(("name", "tf"), CASES, ids=[c[0] for c in CASES])
def test_sine_response_matches_lsim(name, tf):
    n = 2400
    t = np.arange(n) * DT
    u = np.sin(0.8 * t) + 0.5 * np.sin(3.0 * t + 0.3)
    _, y_cont, _ = signal.lsim(signal.lti(*tf), u, t)
    y_disc = run_filter(discretise(tf, DT), u, False)
    scale = np.abs(y_cont).max()
    # the inputs start at u(0) = 0.15 (a small step): allow the first samples a Tustin-sized error
    np.testing.assert_allclose(y_disc[60:], y_cont[60:], atol=3e-3 * scale)


@pytest.mark.parametrize(("name", "tf"), CASES, ids=[c[0] for c in CASES])
def test_step_response_matches_continuous(name, tf):
    n = 1200
    # Tustin treats the input as linear between samples: the sampled step 0 -> 1 at k = 0 is a ramp over
    # the step before, i.e. (to second order) a continuous step at -dt/2.
    _, y_half = signal.step(signal.lti(*tf), T=np.arange(2 * n) * (DT / 2))
    y_cont = y_half[1::2]  # the continuous step response at t_k + dt/2
    y_disc = run_filter(discretise(tf, DT), np.ones(n), False)
    scale = max(1.0, np.abs(y_cont).max())
    np.testing.assert_allclose(y_disc, y_cont, atol=2e-2 * scale)
    np.testing.assert_allclose(y_disc[12:], y_cont[12:], atol=2e-3 * scale)


@pytest.mark.parametrize(("name", "tf"), CASES, ids=[c[0] for c in CASES])
def test_steady_start_has_no_transient(name, tf):
    coef = discretise(tf, DT)
    u = np.full(500, 3.7)
    y = run_filter(coef, u, True)
    dc_gain = tf[0][-1] / tf[1][-1]
    np.testing.assert_allclose(y, dc_gain * 3.7, atol=1e-12)


def test_translational_highpass_double_integrated_keeps_offset_a_over_wn_squared():
    # s^2/(s+wn)^2 then 1/s^2 is 1/(s+wn)^2: a sustained acceleration a leaves the position at a / wn^2
    wn, a = 1.5, 2.0
    coef = discretise(filters.translational_highpass(wn), DT)
    y = run_filter(coef, np.full(int(20 / DT), a), False)
    v = np.cumsum(y) * DT
    p = np.cumsum(v) * DT
    assert p[-1] == pytest.approx(a / wn**2, rel=1e-3)


def test_unrestricted_rotational_highpass_is_identity():
    coef = discretise(filters.rotational_highpass(0.0), DT)
    u = np.random.default_rng(1).normal(size=300)
    np.testing.assert_array_equal(run_filter(coef, u, True), u)


def test_derivative_estimator_differentiates_a_ramp():
    coef = discretise(filters.derivative_estimator(12.5), DT)
    t = np.arange(600) * DT
    y = run_filter(coef, 0.7 * t, False)
    assert y[-1] == pytest.approx(0.7, rel=1e-9)


def test_cutoffs_match_paper_text():
    # paper: CW1 surge low-pass cut-off 0.31 Hz, high-pass 0.37 Hz (-3 dB), with wn in rad/s
    for tf, f_hz in ((filters.tilt_lowpass(1.5), 0.307), (filters.translational_highpass(1.5), 0.371)):
        h = discrete_freqresp(discretise(tf, DT), np.array([2 * np.pi * f_hz]), DT)
        assert abs(h[0]) == pytest.approx(1 / np.sqrt(2), abs=0.01)


@pytest.mark.parametrize("dt", [1 / 50, 1 / 120, 1 / 1000])
@pytest.mark.parametrize("name,tf", [*CASES, ("identity", filters.rotational_highpass(0.0))])
def test_discretise_equals_scipy_bilinear_bit_for_bit(name: str, tf, dt: float) -> None:
    # the numpy Tustin transform replaces scipy.signal (import time); it must give the same coefficients
    num, den = tf
    expected = np.zeros(filters.NCOEF)
    if len(den) == 1:
        expected[8] = num[-1] / den[0]
    else:
        ad, bd, cd, dd, _ = signal.cont2discrete(signal.tf2ss(num, den), dt, method="bilinear")
        n = ad.shape[0]
        a2 = np.zeros((2, 2))
        a2[:n, :n] = ad
        expected[:4], expected[4 : 4 + n], expected[6 : 6 + n], expected[8] = a2.ravel(), bd[:, 0], cd[0], dd[0, 0]
    np.testing.assert_array_equal(discretise(tf, dt), expected)
