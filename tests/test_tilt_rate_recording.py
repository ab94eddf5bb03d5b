"""The envelope tab's tilt rate, end to end: ``washbench cue`` on a sustained surge step writes the real .rrd, read back
with pyarrow (:mod:`washbench.review.rrd_read`), checked against what does not come from the recording: the limit
in the parameter file (read as YAML here), the exact per-sample ``sat_tilt_rate`` flags in traces.parquet, and the
closed-form steady tilt asin(a/g) of a specific force (a, 0, -sqrt(g^2 - a^2)) held."""

import math
from pathlib import Path

import inprocess
import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
import yaml

from washbench.io.parquet_files import read_traces
from washbench.io.paths import DATA_DIR
from washbench.review.rerun_log import ENVELOPE_TOLERANCE
from washbench.review.rrd_read import read_scalar_series, read_static

G = 9.80665
DT = 1 / 120
A = 2.0  # m/s^2: the surge held; its start tilt rate, 0.4 1/s x A/g = 4.7 deg/s, is above the 3 deg/s limit
T_STEP, T_END = 2.0, 40.0  # s: the step, and the end (16 tilt time constants 1/0.4 s after it)
TILTED = ("small-angle", "large-angle", "adaptive")
MONOTONIC = ("small-angle", "large-angle")  # gain 0.4 1/s: no overshoot (cw1.yaml), so |rate| integrates to the tilt


@pytest.fixture(scope="module")
def cued(tmp_path_factory: pytest.TempPathFactory) -> Path:
    d = tmp_path_factory.mktemp("tilt")
    t = np.arange(round(T_END / DT) + 1) * DT
    on = t >= T_STEP
    cols = {
        "t_s": t,
        "f_x_mps2": np.where(on, A, 0.0),
        "f_y_mps2": np.zeros_like(t),
        "f_z_mps2": np.where(on, -math.sqrt(G * G - A * A), -G),  # |f| = g throughout: the tilt is asin(a/g)
        "omega_x_degps": np.zeros_like(t),
        "omega_y_degps": np.zeros_like(t),
        "omega_z_degps": np.zeros_like(t),
    }
    pq.write_table(pa.table(cols), d / "step.parquet")
    out = d / "out"
    args = [a for w in (*TILTED, "replay") for a in ("--washout", w)]
    res = inprocess.washbench("cue", d / "step.parquet", "--out", out, *args, "--no-figures", timeout=300)
    assert res.returncode == 0, res.stderr
    return out


def _limit_degps() -> float:
    """The tilt-rate limit of the default parameter file, read as plain YAML (not through washbench's model)."""
    return float(yaml.safe_load((DATA_DIR / "cw1.yaml").read_text())["tilt"]["rate_limit_degps"])


def test_tilt_rate_never_above_its_limit_and_at_it_when_flagged(cued: Path) -> None:
    """Every washout with tilt coordination has a line, the reference none; every recorded value is at most the
    limit in the parameter file and equal to it (float32) on every recorded sample the exact per-sample flags mark;
    between recorded samples (drawn as straight lines) every flagged step is within the stored interpolation
    tolerance of the limit; the limit line is at the file's limit; the limit was reached (the test means something)."""
    path = cued / "recording.rrd"
    series, names = read_scalar_series(path), read_static(path, "SeriesLines:names")
    assert names["/envelope/tilt_rate"] == list(TILTED)  # no line for replay: it has no tilt coordination
    limit = _limit_degps()
    _, v_lim = series["/envelope/tilt_rate/limit"]
    np.testing.assert_allclose(v_lim, [limit, limit], rtol=1e-12)  # the file's deg/s through rad/s and back
    t, rate = series["/envelope/tilt_rate"]
    tol = float(np.max(read_static(path, "interpolation_tolerance")["/envelope/tilt_rate"]))
    table = read_traces(cued / "traces.parquet")
    t_all = np.asarray(table["t_s"])
    k = np.rint(t / DT).astype(int)
    np.testing.assert_allclose(t, t_all[k], atol=1e-9)  # recorded at steps
    lim32 = float(np.float32(limit))
    for j, w in enumerate(TILTED):
        flags = np.asarray(table[f"{w}.sat_tilt_rate"]) == 1
        assert flags.sum() >= 50, w  # held at the limit for a while
        assert rate[:, j].min() >= 0.0 and rate[:, j].max() <= lim32, (w, rate[:, j].max())
        np.testing.assert_array_equal(rate[flags[k], j], lim32)
        drawn = np.interp(t_all, t, rate[:, j])
        assert np.all(np.abs(drawn[flags] - limit) <= tol + 1e-6 * limit), w


def test_tilt_reached_is_the_integral_of_the_logged_rate_and_asin_a_over_g(cued: Path) -> None:
    """The tilt angle a washout reaches, integrated from the recorded rate (linear between recorded samples, as the
    viewer draws it), is the closed form asin(a/g) within what the recording may lose: the interpolation tolerance
    stored with the entity times the time, plus the convergence left after 16 time constants. For the classical
    washouts, which reach it without overshoot (the adaptive one's gain overshoots: its |rate| integrates to more)."""
    t, rate = read_scalar_series(cued / "recording.rrd")["/envelope/tilt_rate"]
    tol = float(np.max(read_static(cued / "recording.rrd", "interpolation_tolerance")["/envelope/tilt_rate"]))
    assert tol == pytest.approx(ENVELOPE_TOLERANCE * _limit_degps())
    expected = math.degrees(math.asin(A / G))  # 11.8 deg
    for j, w in enumerate(TILTED):
        if w not in MONOTONIC:
            continue
        reached = float(np.sum(0.5 * (rate[1:, j] + rate[:-1, j]) * np.diff(t)))
        bound = tol * T_END + 0.5 * DT * _limit_degps() + 1e-3 * expected
        assert abs(reached - expected) <= bound, (w, reached, expected, bound)
    assert bound < 0.03 * expected  # the check is tight enough to mean something
