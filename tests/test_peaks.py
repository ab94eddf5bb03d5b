"""washbench.numerics.peaks against scipy.signal.find_peaks (the reference it reproduces without its import)."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.signal

from washbench.numerics.peaks import find_peaks, local_maxima, prominences


def signals() -> list[np.ndarray]:
    rng = np.random.default_rng(7)
    t = np.arange(3000) / 120.0
    damped = np.exp(-0.15 * t) * np.sin(2 * np.pi * 0.4 * t) + 0.02 * t
    out = [
        damped,
        damped + 0.01 * rng.normal(size=t.size),
        np.round(damped * 20) / 20,  # quantised: flat runs of every length, at peaks and in valleys
        np.cumsum(rng.normal(size=500)),
        rng.normal(size=20000),  # white noise: a third of the samples are peaks, most of them barely prominent
        rng.integers(0, 4, size=400).astype(float),  # plateaus everywhere, also at both ends
        np.array([1.0, 1.0, 2.0, 2.0, 2.0, 1.0, 3.0, 3.0]),  # a flat peak, and a plateau at the end
        np.array([0.0, 1.0]),
        np.zeros(10),
    ]
    return out


@pytest.mark.parametrize("k", range(len(signals())))
def test_peaks_and_prominences_are_scipys(k: int) -> None:
    x = signals()[k]
    reference, _ = scipy.signal.find_peaks(x)
    assert np.array_equal(local_maxima(x), reference)
    if reference.size:
        expected = scipy.signal.peak_prominences(x, reference)[0]
        np.testing.assert_allclose(prominences(x, reference), expected, rtol=0, atol=0)
    span = float(np.ptp(x))
    for fraction in (0.0, 0.05, 0.1, 0.3, 0.9):
        for y in (x, -x):
            expected, _ = scipy.signal.find_peaks(y, prominence=fraction * span)
            assert np.array_equal(find_peaks(y, fraction * span), expected)


def test_a_signal_that_is_not_one_dimensional_is_refused() -> None:
    with pytest.raises(ValueError, match="1-D"):
        local_maxima(np.zeros((3, 3)))


def test_an_oscillation_check_does_not_import_scipy_signal() -> None:
    """The reason for this module: a run whose manoeuvre checks an oscillation paid 0.8 s for scipy.signal."""
    import subprocess
    import sys

    code = (
        "import sys, numpy as np\n"
        "from washbench.flight.checks import oscillation\n"
        "t = np.arange(2400) / 120.0\n"
        "o = oscillation(np.exp(-0.3 * t) * np.sin(2 * np.pi * 0.5 * t), 1 / 120.0)\n"
        "print(round(o.period_s, 2), 'scipy.signal' in sys.modules)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["2.0", "False"]
