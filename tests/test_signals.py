"""``washbench signal``: test signals on one axis, rotations physically consistent, written as a cue input."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import cumulative_simpson
from scipy.spatial.transform import Rotation

from washbench.analysis.signals import KINDS, SignalSpec, generate
from washbench.cli import main
from washbench.io.motion_file import read_motion

G = 9.80665
AXIS_VECTOR = {"roll": (1.0, 0.0, 0.0), "pitch": (0.0, 1.0, 0.0), "yaw": (0.0, 0.0, 1.0)}


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("axis", ["roll", "pitch", "yaw"])
def test_rotation_is_physically_consistent(kind: str, axis: str) -> None:
    """f = -R^T g_I for the attitude that integrates the angular velocity (scipy Rotation, Simpson)."""
    spec = SignalSpec(kind, axis, amplitude=20.0, frequency_hz=0.4, duration_s=12.0, rate_hz=200.0, start_s=0.5)
    sig = generate(spec)
    j = "xyz".index("xyz"[["roll", "pitch", "yaw"].index(axis)])
    rate = sig.omega_radps[:, j]
    assert np.all(np.delete(sig.omega_radps, j, axis=1) == 0.0)
    assert np.max(np.abs(rate)) <= math.radians(20.0) * (1 + 1e-12)
    # attitude: integral of the sampled rate (+ the signal's own start, from the first sample's f)
    angle0 = {"roll": math.atan2(-sig.f_mps2[0, 1], -sig.f_mps2[0, 2]), "pitch": math.asin(sig.f_mps2[0, 0] / G)}
    angle = angle0.get(axis, 0.0) + cumulative_simpson(rate, dx=sig.dt_s, initial=0.0)
    r = Rotation.from_rotvec(np.outer(angle, AXIS_VECTOR[axis]))
    expect = -r.inv().apply([0.0, 0.0, G])
    # the rate jumps in step, pulse, doublet: integrating the samples is then off by up to one sample of rate
    tol = math.radians(20.0) * sig.dt_s if kind in ("step", "pulse", "doublet") else 1e-6
    np.testing.assert_allclose(sig.f_mps2, expect, atol=tol * G)
    np.testing.assert_allclose(np.linalg.norm(sig.f_mps2, axis=1), G, rtol=1e-12)


def test_sine_rotation_oscillates_about_level_from_rest() -> None:
    sig = generate(SignalSpec("sine", "pitch", 10.0, 0.25, duration_s=8.0, rate_hz=100.0))
    w = 2 * math.pi * 0.25
    theta = -math.radians(10.0) / w * np.cos(w * sig.t_s)
    np.testing.assert_allclose(sig.f_mps2[:, 0], G * np.sin(theta), atol=1e-12)
    assert sig.omega_radps[0, 1] == 0.0  # at rest in rotation at the start


def test_translational_shapes() -> None:
    t0, f = 1.0, 0.5
    for kind, at, value in (
        ("step", (0.99, 1.0, 5.0), (0.0, 1.0, 1.0)),
        ("pulse", (0.99, 1.0, 2.99, 3.0), (0.0, 1.0, 1.0, 0.0)),
        ("doublet", (0.99, 1.0, 1.99, 2.0, 2.99, 3.0), (0.0, 1.0, 1.0, -1.0, -1.0, 0.0)),
    ):
        sig = generate(SignalSpec(kind, "f_y", 2.0, f, duration_s=6.0, rate_hz=100.0, start_s=t0))
        for t, v in zip(at, value, strict=True):
            k = round(t * 100)
            assert sig.f_mps2[k, 1] == pytest.approx(2.0 * v)
        assert np.all(sig.f_mps2[:, 2] == -G) and np.all(sig.omega_radps == 0.0)
    ms = generate(SignalSpec("multisine", "f_z", 1.0, 0.05, duration_s=60.0, rate_hz=100.0))
    assert np.max(np.abs(ms.f_mps2[:, 2] + G)) <= 1.0 + 1e-12
    spectrum = np.abs(np.fft.rfft(ms.f_mps2[:, 2] + G))
    freqs = np.fft.rfftfreq(ms.t_s.shape[0], 0.01)
    for k in range(6):  # the six components are there
        fk = 0.05 * 10 ** (k / 5)
        assert spectrum[np.argmin(np.abs(freqs - fk))] > 0.2 * spectrum.max()
    ch = generate(SignalSpec("chirp", "f_x", 1.0, 2.0, duration_s=40.0, rate_hz=100.0, start_s=0.0))
    x = ch.f_mps2[:, 0]
    crossings = ch.t_s[1:][(x[1:] > 0) != (x[:-1] > 0)]
    assert np.diff(crossings[-3:]).mean() == pytest.approx(0.25, rel=0.1)  # ends at 2 Hz (half period 0.25 s)
    # exponential sweep: the second half (0.2 -> 2 Hz) has ten times the zero crossings of the first
    first, second = np.sum((crossings > 0.1) & (crossings < 20.0)), np.sum(crossings >= 20.0)
    assert 8 * first <= second <= 12 * first


def test_signal_command_writes_a_cue_input(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    csv_file, pq_file = tmp_path / "s.csv", tmp_path / "s.parquet"
    for path in (csv_file, pq_file):
        args = ["signal", "doublet", "--axis", "roll", "--amplitude", "5", "--frequency-hz", "0.5"]
        assert main([*args, "--duration-s", "6", "--rate-hz", "50", "--out", str(path)]) == 0
    assert "doublet on roll, amplitude 5 deg/s at 0.5 Hz, 301 samples at 50 Hz" in capsys.readouterr().out
    a, b = read_motion(csv_file), read_motion(pq_file)
    sig = generate(SignalSpec("doublet", "roll", 5.0, 0.5, duration_s=6.0, rate_hz=50.0))
    for m in (a, b):
        np.testing.assert_array_equal(m.t_s, sig.t_s)
        np.testing.assert_array_equal(m.f_mps2, sig.f_mps2)
        np.testing.assert_allclose(m.omega_radps, sig.omega_radps, rtol=1e-15, atol=1e-18)
    out = tmp_path / "cue"
    assert main(["cue", str(csv_file), "--out", str(out), "--no-figures", "--no-recording"]) == 0
    assert (out / "traces.parquet").is_file() and (out / "metrics.csv").is_file()


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["sine", "--axis", "pitch", "--amplitude", "1"], "--frequency-hz must be a positive number, got None"),
        (["sine", "--axis", "pitch", "--amplitude", "1", "--frequency-hz", "70"], "Nyquist frequency 60 Hz"),
        (["step", "--axis", "f_x", "--amplitude", "nan"], "--amplitude must be a finite number"),
        (["step", "--axis", "f_x", "--amplitude", "1", "--duration-s", "0"], "--duration-s must be a positive"),
        (["step", "--axis", "f_x", "--amplitude", "1", "--ext", "x"], "unrecognized arguments"),
        (["sawtooth", "--axis", "f_x", "--amplitude", "1"], "unknown signal kind 'sawtooth' (valid: sine, step"),
        (["step", "--axis", "bob", "--amplitude", "1"], "unknown axis 'bob' (valid: f_x, f_y, f_z, roll"),
    ],
)
def test_signal_bad_input(tmp_path: Path, capsys: pytest.CaptureFixture[str], args: list[str], message: str) -> None:
    out = tmp_path / "s.csv"
    with pytest.raises(SystemExit) if "--ext" in args else _nothing():
        assert main(["signal", *args, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1
    assert not out.exists()


def test_signal_bad_extension(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "s.txt"
    assert main(["signal", "step", "--axis", "yaw", "--amplitude", "1", "--out", str(out)]) == 2
    assert f"{out}: unknown extension '.txt'" in capsys.readouterr().err
    assert not out.exists()


class _nothing:  # noqa: N801 (a context manager that does nothing)
    def __enter__(self) -> None:
        return None

    def __exit__(self, *exc: object) -> None:
        return None
