"""The washout stage: the adaptive washouts against the classical ones and finite differences, and a user's plugin
(docs/examples/first_order_washout.py) through every command, loaded from a file and from an entry point; bad
plugins refused in one line."""

from __future__ import annotations

import csv
import os
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

from washbench.analysis.signals import SignalSpec, generate
from washbench.cli import main
from washbench.cueing import CueingBank, cue_trace
from washbench.cueing.params import ADAPTIVE_KINDS, CLASSICAL_KINDS
from washbench.cueing.variants import Washout, apply_overrides, load_param_file
from washbench.platform import load_platform_limits

ROOT = Path(__file__).resolve().parent.parent
EXAMPLE = ROOT / "docs" / "examples" / "first_order_washout.py"
PLUGIN = f"{EXAMPLE}:FirstOrder"
SHORT_TURN = ROOT / "tests" / "data" / "study" / "short_turn.yaml"
DT = 1.0 / 120.0
BASE, _ = load_param_file(None)
LIMITS = load_platform_limits()
PAIRS = list(zip(CLASSICAL_KINDS, ADAPTIVE_KINDS, strict=True))


def _mixed_input(n: int = 3600) -> tuple[np.ndarray, np.ndarray]:
    """60 s of motion on every axis: steps, sines, a sustained bank-like rate (f in m/s^2, omega in rad/s)."""
    t = np.arange(n) * DT
    f = np.zeros((n, 3))
    w = np.zeros((n, 3))
    f[:, 0] = 2.0 * np.sin(0.5 * t) + 1.5 * (t > 20)
    f[:, 1] = 1.0 * (t > 5) - 1.0 * (t > 35)
    f[:, 2] = -9.80665 + np.sin(t) - 2.0 * (t > 40)
    w[:, 0] = 0.3 * np.sin(0.3 * t) + 0.4 * (t > 45)
    w[:, 1] = 0.1 * np.cos(0.7 * t)
    w[:, 2] = 0.1 + 0.2 * (t > 30)
    return f, w


def _params(**overrides: float | str) -> object:
    return apply_overrides(BASE, overrides, "test")


@pytest.mark.parametrize("start", ["steady", "rest"])
def test_adaptive_with_rates_zero_is_the_classical_washout(start: str) -> None:
    f, w = _mixed_input()
    off = _params(**{"adaptive.rate_translational": 0, "adaptive.rate_tilt": 0})
    washouts = [Washout(k, k, off) for pair in PAIRS for k in pair]
    tr = cue_trace(f, w, DT, washouts, None, LIMITS, filter_start=start)
    for classical, adaptive in PAIRS:
        a, b = tr[classical], tr[adaptive]
        for field in ("pos_m", "q", "head_f_mps2", "head_omega_radps", "sp_pos_m", "sp_q"):
            np.testing.assert_allclose(getattr(b, field), getattr(a, field), rtol=0, atol=1e-12, err_msg=field)
    on = cue_trace(f, w, DT, [Washout(k, k, BASE) for k in ADAPTIVE_KINDS], None, LIMITS, filter_start=start)
    for classical, adaptive in PAIRS:  # and adaptation does change them
        assert np.abs(on[adaptive].head_f_mps2 - tr[classical].head_f_mps2).max() > 0.05


def _adaptation(kind: str, f: np.ndarray, w: np.ndarray, p0: float, k0: float) -> dict:
    params = _params(
        **{
            "adaptive.rate_translational": 0,
            "adaptive.rate_tilt": 0,
            "adaptive.translational_gain.initial": p0,
            "tilt.gain_per_s": k0,
            "tilt.rate_limit_degps": "off",
        }
    )
    bank = CueingBank([Washout(kind, kind, params)], None, LIMITS, DT)
    bank.steps(f, w)
    return bank.adaptation()[kind]


@pytest.mark.parametrize("kind", ADAPTIVE_KINDS)
def test_adaptation_gradient_matches_finite_differences(kind: str) -> None:
    """The gradient the steepest descent follows against central differences of the cost J, with the gains held
    (rates 0) at p0 +- e on all three axes and k0 +- e: the sum of the three components of each gradient.

    The translational gradient is exact for the discrete channel (agrees to FD noise). The tilt gradient neglects
    the attitude's effect on the translational channel's input (docs/washouts.md, interpretation A4): measured
    within 6 % on this input; 15 % allowed, which still catches a wrong sign or a missing term."""
    n = 1200
    t = np.arange(n) * DT
    f = np.column_stack([1.5 * np.sin(0.8 * t) + 0.5, 0.8 * np.sin(1.1 * t), -9.80665 + 0.5 * np.sin(t)])
    w = np.column_stack([0.05 * np.sin(0.3 * t), 0.04 * np.cos(0.5 * t), np.full(n, 0.02)])
    p0, k0, e = 1.0, 0.4, 1e-6
    a = _adaptation(kind, f, w, p0, k0)
    fd_p = (_adaptation(kind, f, w, p0 + e, k0)["cost"] - _adaptation(kind, f, w, p0 - e, k0)["cost"]) / (2 * e)
    fd_k = (_adaptation(kind, f, w, p0, k0 + e)["cost"] - _adaptation(kind, f, w, p0, k0 - e)["cost"]) / (2 * e)
    assert abs(fd_p) > 0.1 and abs(fd_k) > 0.1  # the check means something
    assert a["grad_p"].sum() == pytest.approx(fd_p, rel=1e-4)
    assert a["grad_k"].sum() == pytest.approx(fd_k, rel=0.15)


@pytest.mark.parametrize("kind", ADAPTIVE_KINDS)
def test_sustained_specific_force_ends_as_tilt_at_neutral(kind: str) -> None:
    """A 1.5 m/s^2 surge step held for 80 s: the stage returns to centre and the cockpit pitches until gravity gives
    the simulator pilot the aircraft's specific force (its direction to 1 deg)."""
    sig = generate(SignalSpec(kind="step", axis="f_x", amplitude=1.5, duration_s=80.0, rate_hz=120.0, start_s=1.0))
    tr = cue_trace(sig.f_mps2, sig.omega_radps, DT, [Washout(kind, kind, BASE)], None, LIMITS)[kind]
    assert np.abs(tr.pos_m[-1]).max() < 0.01
    assert np.abs(tr.vel_mps[-1]).max() < 0.01
    f_a, f_s = sig.f_mps2[-1], tr.head_f_mps2[-1]
    angle = np.degrees(np.arccos(np.clip(f_a @ f_s / np.linalg.norm(f_a) / np.linalg.norm(f_s), -1.0, 1.0)))
    assert angle < 1.0


@pytest.mark.parametrize(
    "spec",
    [
        SignalSpec(kind="step", axis="f_y", amplitude=4.0, duration_s=30.0),
        SignalSpec(kind="doublet", axis="f_x", amplitude=6.0, frequency_hz=0.2, duration_s=30.0),
        SignalSpec(kind="chirp", axis="roll", amplitude=60.0, frequency_hz=2.0, duration_s=30.0),
        SignalSpec(kind="multisine", axis="f_z", amplitude=5.0, frequency_hz=0.5, duration_s=30.0),
    ],
    ids=lambda s: f"{s.kind}-{s.axis}",
)
def test_gains_stay_in_bounds_and_the_platform_in_its_limits(spec: SignalSpec) -> None:
    """Fast adaptation (rates x20) on stress signals: gains within their bounds at every step, platform limits held."""
    fast = _params(**{"adaptive.rate_translational": 20, "adaptive.rate_tilt": 20})
    sig = generate(spec)
    bank = CueingBank([Washout(k, k, fast) for k in ADAPTIVE_KINDS], None, LIMITS, DT)
    a = fast.adaptive
    lim = LIMITS.translation
    for k in range(0, len(sig.t_s), 60):
        rows = bank.steps(sig.f_mps2[k : k + 60], sig.omega_radps[k : k + 60])
        for name, st in bank.adaptation().items():
            assert np.all(st["p"] >= a.translational_gain.min) and np.all(st["p"] <= a.translational_gain.max), name
            assert np.all(st["k"] >= a.tilt_gain_per_s.min) and np.all(st["k"] <= a.tilt_gain_per_s.max), name
        assert np.all(np.abs(rows[:, :, 0:3]) <= np.array(lim.position_limit_m.xyz))
        assert np.all(np.abs(rows[:, :, 3:6]) <= np.array(lim.velocity_limit_mps.xyz))
        assert np.all(np.isfinite(rows))


# ---- a user's plugin through the commands


def _wb(*args: str, env: dict | None = None, cwd: Path | None = None) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "washbench", *args],
        capture_output=True,
        text=True,
        timeout=240,
        env=env,
        cwd=cwd,
    )


@pytest.fixture(scope="module")
def plugin_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """`washbench suite` (its worker process loads the plugin from its file again) of a short turn with the plugin
    beside large-angle and the adaptive large-angle washout; the suite runs each manoeuvre as `washbench run` does."""
    out = tmp_path_factory.mktemp("plugin_run")
    r = _wb(
        "suite", str(SHORT_TURN), "--washout-plugin", PLUGIN, "--washout", "first-order", "--washout", "large-angle",
        "--washout", "adaptive-large-angle", "--out", str(out), "--no-recording", "--no-figures",
    )  # fmt: skip
    assert r.returncode == 0, r.stderr
    return out / "c172p" / "short_turn"


def test_plugin_runs_like_a_built_in(plugin_run: Path) -> None:
    rows = list(csv.DictReader((plugin_run / "metrics.csv").open()))
    assert {r["washout"] for r in rows} == {"first-order", "large-angle", "adaptive-large-angle"}
    ranking = {r["washout"] for r in csv.DictReader((plugin_run / "ranking.csv").open())}
    assert ranking == {"first-order", "large-angle", "adaptive-large-angle"}
    t = pq.read_table(plugin_run / "traces.parquet")
    lim = LIMITS.translation.position_limit_m.xyz
    for w in ("first-order", "adaptive-large-angle"):
        for j, ax in enumerate("xyz"):
            assert np.abs(t[f"{w}.pos_{ax}_m"].to_numpy()).max() <= lim[j]
    # the plugin's head motion is the platform's: it tilts forward/right as the aircraft's rates say, not zero
    assert np.abs(t["first-order.omega_x_degps"].to_numpy()).max() > 0.5


def test_plugin_in_sweep_and_tune_gives_the_run_s_scores(plugin_run: Path, tmp_path: Path) -> None:
    results = plugin_run.parent.parent
    r = _wb(
        "sweep", str(SHORT_TURN), "--from", str(results), "--washout-plugin", PLUGIN, "--washout", "first-order",
        "--set", "first-order.scale=0.5,0.8", "--out", str(tmp_path / "sweep"),
    )  # fmt: skip
    assert r.returncode == 0, r.stderr
    rows = list(csv.DictReader((tmp_path / "sweep" / "sweep.csv").open()))
    run_score = {r["washout"]: float(r["score"]) for r in csv.DictReader((plugin_run / "ranking.csv").open())}
    at_default = [float(r["score"]) for r in rows if float(r["first-order.scale"]) == 0.5]
    assert at_default == [run_score["first-order"]]  # the default scale 0.5: the run's own score, bit for bit
    r = _wb(
        "tune", str(SHORT_TURN), "--from", str(results), "--washout-plugin", PLUGIN, "--washout", "first-order",
        "--tune", "first-order.scale=0.2:1", "--budget", "8", "--out", str(tmp_path / "tune"),
    )  # fmt: skip
    assert r.returncode == 0, r.stderr
    assert "first-order" in (tmp_path / "tune" / "tuned.yaml").read_text()


@pytest.fixture(scope="module")
def signals(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """Short `washbench signal` inputs for cue, written once."""
    d = tmp_path_factory.mktemp("signals")
    out = {"step": d / "step.csv", "sine": d / "sine.csv"}
    assert main(["signal", "step", "--axis", "f_y", "--amplitude", "2", "--duration-s", "8",
                 "--out", str(out["step"])]) == 0  # fmt: skip
    assert main(["signal", "sine", "--axis", "roll", "--amplitude", "10", "--frequency-hz", "0.5", "--duration-s", "5",
                 "--out", str(out["sine"])]) == 0  # fmt: skip
    return out


def test_plugin_in_cue(signals: dict[str, Path], tmp_path: Path) -> None:
    status = main(["cue", str(signals["step"]), "--washout-plugin", PLUGIN, "--washout", "first-order",
                   "--washout", "adaptive", "--out", str(tmp_path / "cue"), "--no-recording",
                   "--no-figures"])  # fmt: skip
    assert status == 0
    washouts = {row["washout"] for row in csv.DictReader((tmp_path / "cue" / "metrics.csv").open())}
    assert washouts == {"first-order", "adaptive"}


TILT_PLUGIN = '''
import math
import numpy as np
from scipy.signal import lfilter


class LowpassTilt:
    """Tilt only: roll, pitch follow asin(-f_y/g), asin(f_x/g) through a first-order low-pass; a whole-trace form."""

    washout_name = "lowpass-tilt"

    def __init__(self, params, context):
        self.b = math.exp(-1.0 * context.dt_s)
        self.g = context.gravity_mps2

    def _target(self, f):
        return (-math.asin(max(-1.0, min(1.0, f[1] / self.g))), math.asin(max(-1.0, min(1.0, f[0] / self.g))))

    @staticmethod
    def _q(phi, theta):
        return (math.cos(phi / 2) * math.cos(theta / 2), math.sin(phi / 2) * math.cos(theta / 2),
                math.cos(phi / 2) * math.sin(theta / 2), -math.sin(phi / 2) * math.sin(theta / 2))

    def start(self, f, omega):
        self.y = list(self._target(f))
        return (0.0, 0.0, 0.0), self._q(*self.y)

    def step(self, f, omega):
        t = self._target(f)
        self.y = [(1 - self.b) * t[j] + self.b * self.y[j] for j in range(2)]
        return (0.0, 0.0, 0.0), self._q(*self.y)

    def trace(self, f, omega):
        g = self.g
        targets = np.column_stack([-np.arcsin(np.clip(f[:, 1] / g, -1, 1)), np.arcsin(np.clip(f[:, 0] / g, -1, 1))])
        y = np.column_stack([lfilter([1 - self.b], [1, -self.b], targets[:, j], zi=[self.b * self.y[j]])[0]
                             for j in range(2)])
        phi, theta = y[:, 0] / 2, y[:, 1] / 2
        q = np.column_stack([np.cos(phi) * np.cos(theta), np.sin(phi) * np.cos(theta), np.cos(phi) * np.sin(theta),
                             -np.sin(phi) * np.sin(theta)])
        return np.zeros((len(f), 3)), q
'''


def test_plugin_trace_form_equals_its_steps_and_serves_the_omct(tmp_path: Path) -> None:
    """A plugin with a whole-trace form: cue_trace (which uses it) equals the bank stepping it sample by sample, and
    `washbench omct` measures it (through that form: the OMCT's 1.8 million samples in seconds)."""
    from washbench.cueing import registry

    plugin = tmp_path / "tilt.py"
    plugin.write_text(TILT_PLUGIN)
    registry.load_plugin(f"{plugin}:LowpassTilt")
    f, w = _mixed_input(1200)
    washouts = [Washout("lowpass-tilt", "lowpass-tilt", BASE, f"{plugin}:LowpassTilt")]
    whole = cue_trace(f, w, DT, washouts, None, LIMITS)["lowpass-tilt"]
    bank = CueingBank(washouts, None, LIMITS, DT)
    rows = np.stack([bank.step(f[k], w[k])[0].copy() for k in range(len(f))])
    np.testing.assert_allclose(whole.q, rows[:, 9:13], rtol=0, atol=1e-12)
    np.testing.assert_allclose(whole.head_f_mps2, rows[:, 16:19], rtol=0, atol=1e-9)
    with warnings.catch_warnings():
        # the tilt passes no yaw on: its yaw-to-yaw gain is 0 at every frequency, which a log gain axis cannot show
        # (the Bode plot keeps that axis linear and its legend says "no motion") and whose phase is undefined; a
        # user saw three warnings from numpy and matplotlib
        warnings.simplefilter("error")
        status = main(["omct", "--washout-plugin", f"{plugin}:LowpassTilt", "--washout", "lowpass-tilt",
                       "--out", str(tmp_path / "omct")])  # fmt: skip
    assert status == 0
    rows = list(csv.DictReader((tmp_path / "omct" / "omct.csv").open()))
    yaw = [r for r in rows if r["washout"] == "lowpass-tilt" and r["test"] == "yaw_to_yaw"]
    assert yaw and all(float(r["gain"]) == 0.0 for r in yaw)
    assert (tmp_path / "omct" / "bode_yaw_to_yaw.png").stat().st_size > 10_000


def test_plugin_from_an_entry_point(signals: dict[str, Path], tmp_path: Path) -> None:
    """An installed package's plugin, found through the washbench.washouts entry-point group (no flag)."""
    site = tmp_path / "site"
    dist = site / "myplugin-0.1.dist-info"
    dist.mkdir(parents=True)
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: myplugin\nVersion: 0.1\n")
    (dist / "entry_points.txt").write_text("[washbench.washouts]\nfirst-order = my_first_order:FirstOrder\n")
    (site / "my_first_order.py").write_text(EXAMPLE.read_text())
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(site), *filter(None, [os.environ.get("PYTHONPATH")])])}
    r = _wb("cue", str(signals["sine"]), "--washout", "first-order", "--out", str(tmp_path / "cue"), "--no-recording",
            "--no-figures", env=env)  # fmt: skip
    assert r.returncode == 0, r.stderr
    assert "first-order" in (tmp_path / "cue" / "metrics.csv").read_text()


BAD = {
    "raises": ("raise RuntimeError('boom')", "raised RuntimeError: boom"),
    "nan": ("return np.array([np.nan, 0, 0]), np.array([1.0, 0, 0, 0])", "not finite"),
    "shape": ("return np.zeros(2), np.array([1.0, 0, 0, 0])", "shapes"),
    "type": ("return 'up'", "expected a tuple"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_a_bad_plugin_is_one_line_naming_the_step(
    case: str, signals: dict[str, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    body, expected = BAD[case]
    plugin = tmp_path / "bad.py"
    plugin.write_text(
        f"import numpy as np\n\n\nclass Bad:\n    washout_name = 'bad-{case}'\n\n"
        "    def __init__(self, params, context):\n        self.k = 0\n\n"
        "    def start(self, f, omega):\n        return np.zeros(3), np.array([1.0, 0, 0, 0])\n\n"
        f"    def step(self, f, omega):\n        self.k += 1\n        if self.k < 50:\n"
        f"            return np.zeros(3), np.array([1.0, 0, 0, 0])\n        {body}\n"
    )
    out = tmp_path / "out"
    capsys.readouterr()
    status = main(["cue", str(signals["step"]), "--washout-plugin", f"{plugin}:Bad", "--washout", f"bad-{case}",
                   "--out", str(out), "--no-recording", "--no-figures"])  # fmt: skip
    err = capsys.readouterr().err
    assert status == 2
    lines = [line for line in err.strip().splitlines() if line.startswith("washbench: error")]
    assert len(lines) == 1 and "Traceback" not in err, err
    assert f"washout bad-{case}" in lines[0] and "step 49" in lines[0] and "t = 0.408333 s" in lines[0], lines[0]
    assert expected in lines[0]
    assert not (out / "metrics.csv").exists()


def test_a_plugin_file_that_does_not_load_is_one_line(tmp_path: Path) -> None:
    plugin = tmp_path / "broken.py"
    plugin.write_text("import numpy as np\n\nx = 1 / 0\n")
    r = _wb("omct", "--washout-plugin", f"{plugin}:X", "--washout", "x", "--out", str(tmp_path / "o"))
    assert r.returncode == 2
    assert r.stderr.strip().count("\n") == 0 and f"{plugin}:3: ZeroDivisionError" in r.stderr, r.stderr
