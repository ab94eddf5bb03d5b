"""Telban-Cardullo vestibular models: their transfer functions and step responses (scipy.signal, independently)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

from washbench.perception.vestibular import MODELS, VestibularModel, canal_tf, model_params, otolith_tf

TC = MODELS["telban-cardullo"]


def published_canal() -> signal.lti:
    """5.73 * 80 s^2 (0.06 s + 1) / ((5.73 s + 1)(0.005 s + 1)(80 s + 1)), built here from the constants."""
    num = np.polymul([5.73 * 80.0, 0.0, 0.0], [0.06, 1.0])
    den = np.polymul(np.polymul([5.73, 1.0], [0.005, 1.0]), [80.0, 1.0])
    return signal.lti(num, den)


def published_otolith() -> signal.lti:
    """(10 s + 1) / ((5 s + 1)(0.016 s + 1))."""
    return signal.lti([10.0, 1.0], np.polymul([5.0, 1.0], [0.016, 1.0]))


def test_transfer_functions_are_the_published_ones() -> None:
    for mine, ref in ((canal_tf(TC.canals), published_canal()), (otolith_tf(TC.otolith), published_otolith())):
        num, den = mine
        w = np.array([0.01, 0.1, 1.0, 10.0, 100.0])
        _, h_mine = signal.freqs(num, den, worN=w)
        _, h_ref = signal.freqs(ref.num, ref.den, worN=w)
        np.testing.assert_allclose(h_mine, h_ref, rtol=1e-12)


@pytest.mark.parametrize("rate_hz", [120.0, 1000.0])
def test_step_responses_equal_the_continuous_ones(rate_hz: float) -> None:
    """A step (ramped over one sample, as the first-order hold sees it) through the discretised models equals
    scipy.signal.lsim of the continuous transfer functions (same input assumption: linear between samples)."""
    dt = 1.0 / rate_hz
    t = np.arange(int(120.0 / dt)) * dt
    u = np.minimum(t / dt, 1.0)  # 0 at t = 0, 1 from the next sample on
    model = VestibularModel(dt, TC)
    zeros = np.zeros((t.size, 3))
    p = model.perceive(np.column_stack([u, zeros[:, :2]]), np.column_stack([u, zeros[:, :2]]), start="steady")
    for got, ref in ((p.omega_radps[:, 0], published_canal()), (p.f_mps2[:, 0], published_otolith())):
        _, y, _ = signal.lsim(ref, u, t)
        np.testing.assert_allclose(got, y, atol=2e-6 * max(1.0, float(np.max(np.abs(y)))))


def test_step_response_shape() -> None:
    """Canal: the lead's spike T_N/T_S = 12 at once, about 1 after the fast pole, then washout (5.73 s) and
    adaptation (80 s) below zero; otolith: DC gain 1, an overshoot to tau_A/tau_L = 2 on the way."""
    canal = published_canal()
    _, y0 = signal.step(canal, T=np.linspace(0.0, 0.05, 501))
    assert y0[0] == pytest.approx(12.0, rel=1e-6)
    # once the 5 ms pole has gone: the washout/adaptation pair's step response plus the lead's (T_N - T_S) times
    # its derivative (the lead-lag's first-order effect)
    a, b, lead = 1 / 5.73, 1 / 80.0, 0.06 - 0.005
    te = 0.05
    slow = (a * np.exp(-a * te) - b * np.exp(-b * te)) / (a - b)
    dslow = (-a * a * np.exp(-a * te) + b * b * np.exp(-b * te)) / (a - b)
    assert y0[-1] == pytest.approx(slow + lead * dslow, rel=1e-3)
    _, y1 = signal.step(canal, T=np.linspace(0.0, 300.0, 30001))
    assert y1[3000] < 0.0 and abs(y1[-1]) < 0.05  # below zero at 30 s (adaptation), back near 0 at 300 s
    _, yo = signal.step(published_otolith(), T=np.linspace(0, 100, 20001))
    assert yo[-1] == pytest.approx(1.0, rel=1e-3) and np.max(yo) == pytest.approx(2.0, rel=2e-2)
    model = VestibularModel(0.01, TC)
    assert model.otolith.dc_gain == pytest.approx(1.0) and abs(model.canals.dc_gain) < 1e-12


def test_model_names() -> None:
    assert model_params(None) == MODELS["young-meiry"] and model_params("telban-cardullo") == TC
    with pytest.raises(ValueError, match="valid: young-meiry, telban-cardullo"):
        model_params("hosman")
