"""MSDV (ISO 2631-1 Wf): the weighting against the standard's tabulated values and a sinusoid's closed form."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import signal

from washbench.perception import sickness

# Wf as tabulated for 0.1-0.63 Hz (ISO 2631-1:1997, motion-sickness weighting), 3 significant digits
WF_TABLE = {0.1: 0.695, 0.125: 0.895, 0.16: 1.006, 0.2: 0.992, 0.25: 0.854, 0.315: 0.619, 0.4: 0.384, 0.5: 0.224,
            0.63: 0.116}  # fmt: skip


def _analog(f_hz: float) -> complex:
    num, den = sickness.wf_tf()
    return complex(signal.freqs(num, den, worN=[2 * math.pi * f_hz])[1][0])


def test_weighting_matches_the_tabulated_curve() -> None:
    for f, w in WF_TABLE.items():
        assert abs(_analog(f)) == pytest.approx(w, abs=1.5e-3), f


def test_weighting_is_the_product_of_the_four_filters() -> None:
    """Independent: the four factors of the standard evaluated one by one at s = j 2 pi f."""
    p = sickness.WF_PARAMS
    for f in (0.01, 0.05, 0.16, 0.7, 3.0):
        s = 2j * math.pi * f
        w1, w2, w4, w5, w6 = (2 * math.pi * p[k] for k in ("f1_hz", "f2_hz", "f4_hz", "f5_hz", "f6_hz"))
        hh = s * s / (s * s + w1 * s / p["q1"] + w1 * w1)
        hl = w2 * w2 / (s * s + w2 * s / p["q2"] + w2 * w2)
        ht = 1 / (1 + s / (p["q4"] * w4) + s * s / (w4 * w4))
        hs = (s * s + w5 * s / p["q5"] + w5 * w5) / (s * s + w6 * s / p["q6"] + w6 * w6)
        assert _analog(f) == pytest.approx(hh * hl * ht * hs, rel=1e-12)


@pytest.mark.parametrize("rate_hz", [60.0, 120.0])
def test_discrete_filter_follows_the_analogue_one(rate_hz: float) -> None:
    sos = sickness.wf_sos(1.0 / rate_hz)
    # the band Wf weighs (above 1 Hz it is below -24 dB); the bilinear warping grows as (f dt)^2
    for f, rel in ((0.02, 1e-5), (0.05, 1e-5), (0.16, 1e-5), (0.5, 1e-3), (0.63, 1.5e-3), (1.0, 4e-3)):
        _, h = signal.sosfreqz(sos, worN=[f], fs=rate_hz)
        assert abs(h[0]) == pytest.approx(abs(_analog(f)), rel=rel), f


def test_msdv_of_a_sinusoid_is_its_closed_form() -> None:
    """A steady sinusoid A sin(2 pi f t) for T: MSDV^2 = (|Wf(f)| A)^2 T / 2 (the filter's start transient, worth
    a few seconds of signal, is measured by the difference of two lengths and removed)."""
    dt, f, amp = 1 / 120, 0.2, 1.5
    t = np.arange(int(600 / dt)) * dt
    a = amp * np.sin(2 * math.pi * f * t)
    m_long = sickness.msdv(a, dt) ** 2
    m_short = sickness.msdv(a[: len(a) // 2], dt) ** 2
    per_s = (m_long - m_short) / (t[-1] / 2)
    assert per_s == pytest.approx((abs(_analog(f)) * amp) ** 2 / 2, rel=1e-3)
    # and from the head's specific force: level flight (f_z = -g) plus the same motion gives the same dose
    assert sickness.head_msdv(-9.80665 - a, dt) == pytest.approx(math.sqrt(m_long), rel=1e-9)
    assert sickness.head_msdv(np.full(1000, -9.80665), dt) == 0.0


def test_hand_bilinear_and_filter_equal_scipy() -> None:
    """wf_sos (bilinear by hand, per factor) and sos_filter against scipy's bilinear_zpk and sosfilt."""
    dt = 1 / 120
    num, den = sickness.wf_tf()
    z, p, k = signal.tf2zpk(num, den)
    ref_sos = signal.zpk2sos(*signal.bilinear_zpk(z, p, k, 1 / dt))
    w = np.linspace(0.001, 3.0, 50)
    _, h_mine = signal.sosfreqz(sickness.wf_sos(dt), worN=w, fs=1 / dt)
    _, h_ref = signal.sosfreqz(ref_sos, worN=w, fs=1 / dt)
    np.testing.assert_allclose(h_mine, h_ref, rtol=1e-8, atol=1e-12)
    x = np.random.default_rng(3).normal(size=5000)
    sos = sickness.wf_sos(dt)
    np.testing.assert_allclose(sickness.sos_filter(sos, x), signal.sosfilt(sos, x), rtol=1e-10, atol=1e-13)
