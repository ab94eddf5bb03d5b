"""Hardening, fourth round (issue 54): every expensive computation bounded before it starts, platform plugins held to
their contract, last round's leftovers.

The commands run for real (in the test process where :mod:`inprocess` can, else as subprocesses under a time limit);
each test fails on the code before the fix (docs/hardening.md, "Round four").
"""

from __future__ import annotations

import itertools
import json
import math
import os
import re
import resource
import signal
import subprocess
import sys
import time
from pathlib import Path

import inprocess
import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from hostile import assert_clean_error, washbench
from test_live import _send_samples, free_udp_port, motion, saved

from washbench.errors import Terminated, WashbenchError
from washbench.io import interrupts
from washbench.io.paths import DATA_DIR
from washbench.io.readback import RunDoc, read_doc
from washbench.runs.options import load_options

G = 9.80665
CAP_ENV = "WASHBENCH_MAX_MEMORY_GB"  # (washbench.io.CAP_ENV; spelt here so this file loads on older code)


def signal_file(path: Path, seconds: float, rate_hz: float = 120.0) -> Path:
    """A multi-axis recording of ``seconds`` at ``rate_hz`` (the signal of bench/cue_bench.py), as Parquet."""
    n = round(seconds * rate_hz)
    t = np.arange(n) / rate_hz
    cols = {
        "t_s": t,
        "f_x_mps2": 1.5 * np.sin(0.3 * t) + 0.3 * np.sin(7.1 * t),
        "f_y_mps2": 0.8 * np.sin(0.17 * t + 1.0),
        "f_z_mps2": -G * (1.0 + 0.3 * np.sin(0.11 * t)),
        "omega_x_degps": 15.0 * np.sin(0.5 * t),
        "omega_y_degps": 5.0 * np.sin(0.23 * t + 0.4),
        "omega_z_degps": 3.0 * np.sin(0.07 * t),
    }
    pq.write_table(pa.table(cols), path)
    return path


@pytest.fixture(scope="module")
def short_input(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Three seconds at 120 Hz."""
    return signal_file(tmp_path_factory.mktemp("in") / "short.parquet", 3.0)


def limited(address_space_gb: float):
    """A ``preexec_fn`` that limits the child's address space (what ``ulimit -v`` does): the code before the fix
    would otherwise take the machine's memory."""

    def apply() -> None:
        limit = int(address_space_gb * 1e9)
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))

    return apply


def command(*args: object, env: dict[str, str] | None = None, timeout: float = 300, preexec=None):
    """``python -m washbench ARGS`` as a subprocess (an environment or a limit of its own)."""
    return subprocess.run([sys.executable, "-m", "washbench", *map(str, args)], capture_output=True, text=True,
                          timeout=timeout, env=env, preexec_fn=preexec)  # fmt: skip


# ------------------------------------------------------------------------------ 1. the bound, bounded before it starts


def test_the_bound_on_a_30_minute_recording_is_refused_before_it_starts(tmp_path: Path) -> None:
    """Issue 54, item 1: ``cue m30.parquet --washout bound`` (30 min at 120 Hz) passed 4.3 GB within a minute, and
    under a 6 GB address-space limit ended in ``MemoryError: std::bad_alloc``. Now: one line before the bound
    starts, naming the samples, the memory it needs, what limits it and the options that make it smaller, and
    how many samples would fit."""
    src = signal_file(tmp_path / "m30.parquet", 30 * 60.0)
    out = tmp_path / "out"
    env = {k: v for k, v in os.environ.items() if k != CAP_ENV}
    proc = command("cue", src, "--out", out, "--washout", "bound", "--washout", "small-angle", "--no-recording",
                   "--no-figures", "--quiet", env=env, preexec=limited(6.0))  # fmt: skip
    (line,) = assert_clean_error(proc, "washout bound", "216,000 samples")
    need = float(re.search(r"about ([\d.]+) GB at the peak", line).group(1))
    assert need > 4.0, line  # more than the default cap: refused whatever the machine has
    assert "--start-s" in line and "--resample" in line and "samples would fit" in line, line
    fit = int(re.search(r"\(([\d,]+) samples would fit\)", line).group(1).replace(",", ""))
    assert 2 <= fit < 216_000, line
    assert not out.exists() or not any(out.rglob("traces.parquet"))


def test_a_lower_cap_refuses_what_fits_the_default_and_says_which_limit(short_input: Path, tmp_path: Path) -> None:
    """The cap is WASHBENCH_MAX_MEMORY_GB (documented, docs/reference/environment.md): below what a process already
    holds, the bound of a 3 s recording is refused, naming the variable; a value that is not a positive number of
    GB is one line too."""
    out = tmp_path / "out"
    env = {**os.environ, CAP_ENV: "0.01"}
    proc = inprocess.washbench("cue", short_input, "--out", out, "--washout", "bound", "--no-recording",
                               "--no-figures", "--quiet", env=env)  # fmt: skip
    (line,) = assert_clean_error(proc, "washout bound", "360 samples", CAP_ENV)
    assert f"under the cap {CAP_ENV}=0.01 sets (10 MB per process)" in line, line
    for bad in ("0", "-1", "nan", "inf", "lots"):
        proc = inprocess.washbench("cue", short_input, "--out", tmp_path / "o2", "--washout", "bound",
                                   "--no-recording", "--no-figures", "--quiet",
                                   env={**os.environ, CAP_ENV: bad})  # fmt: skip
        assert_clean_error(proc, f"{CAP_ENV}={bad}")


def test_the_room_knows_the_address_space_limit() -> None:
    """Under ``ulimit -v`` (RLIMIT_AS) the room is at most that limit less the address space in use, and the reason
    names it (independent of the machine: a 2 GB limit is below what this machine has and the default cap)."""
    code = ("from washbench.io import cost; r = cost.memory_room(); "
            "print(r.bytes, cost._status()['VmSize'], '|', r.why)")  # fmt: skip
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120,
                          preexec_fn=limited(2.0))  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    numbers, why = proc.stdout.split("|")
    room, used = (float(x) for x in numbers.split())
    assert room <= 2e9 - used + 1e6 and "address-space limit, ulimit -v (2 GB)" in why, proc.stdout


def test_the_bound_s_model_is_above_what_it_takes(tmp_path: Path) -> None:
    """The model is an upper estimate of the peak (measured here in a fresh process, as bench/cost_calibration.py
    measures it), on the part that peaks highest: the replay's translation plan, 3,600 samples."""
    from washbench.io import cost

    root = Path(__file__).resolve().parents[1]
    proc = subprocess.run([sys.executable, str(root / "bench" / "cost_calibration.py"), "--one", "translation",
                           "3600"], capture_output=True, text=True, timeout=600)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    measured = json.loads(proc.stdout.strip().splitlines()[-1])["memory"]
    model, _ = cost._part(cost.BOUND_TRANSLATION, 3600)
    assert 0.3 * model < measured < model, (measured, model)


# ---------------------------------------------------------------------- 2, 3. the MPC horizon with preview, slow MPC


def _params_file(tmp_path: Path, name: str, section: str) -> Path:
    path = tmp_path / name
    path.write_text((DATA_DIR / "cw1.yaml").read_text() + section)
    return path


@pytest.mark.parametrize(
    ("kind", "section", "expected"),
    [
        ("mpc", "mpc:\n  preview_s: 20\n  prediction_step_s: 0.0083334\n", "2,400 prediction intervals"),
        ("mpc", "mpc:\n  preview_s: 10\n  prediction_step_s: 0.0083334\n", "1,200 prediction intervals"),
        ("mpc-unrestricted", "mpc-unrestricted:\n  preview_s: 20\n  prediction_step_s: 0.0083334\n",
         "2,400 prediction intervals"),
        ("mpc-unrestricted", "mpc-unrestricted:\n  preview_s: 20\n  solver: {iter_limit: 100000}\n",
         "a horizon of 200 intervals (preview_s) x solver.iter_limit 100000 = 20,000,000"),
    ],
)  # fmt: skip
def test_a_preview_that_makes_the_horizon_too_long_is_refused_in_the_file(tmp_path: Path, kind: str, section: str,
                                                                          expected: str) -> None:  # fmt: skip
    """Issue 54, item 2: ``mpc: {preview_s: 20, prediction_step_s: 0.0083334}`` (both inside their ranges) gave a
    2,400-step horizon past the 500-step cap and the work bound: 4.3 GB in 17 s, or MemoryError. Now one line
    naming the file and the key, before anything runs, with the prediction step that would do."""
    params = _params_file(tmp_path, "p.yaml", section)
    with pytest.raises(WashbenchError, match=re.escape(expected)) as err:
        load_options(params_path=params, washouts=[kind])
    text = str(err.value)
    assert str(params) in text and kind in text, text


MPC_CORNERS = {
    # the documented ranges' ends (the prediction step's lower end is the sample step, 1/120 s here)
    "horizon_steps": (1, 500),
    "prediction_step_s": (1 / 120, 5.0),
    "preview_s": (0.0, 20.0),
    "iter_limit": (1, 100_000),
}


@pytest.mark.parametrize("kind", ["mpc", "mpc-unrestricted"])
def test_every_corner_of_the_mpc_ranges_is_refused_or_fits(kind: str) -> None:
    """At every corner of the documented ranges the parameters are refused (the horizon, preview included, past
    its limit, or the work bound) or the QP the model says it builds fits under the default cap with room for the
    rest of a command (0.5 GB); and the refusal is exactly where the rule says."""
    from washbench.cueing import mpc, mpc_unrestricted
    from washbench.cueing.mpc import MpcParams
    from washbench.cueing.mpc_unrestricted import MpcUnrestrictedParams
    from washbench.io import cost

    model, top = (MpcParams, mpc.MAX_HORIZON) if kind == "mpc" else (MpcUnrestrictedParams,
                                                                     mpc_unrestricted.MAX_HORIZON)  # fmt: skip
    steps = (1, top)
    seen = {"refused": 0, "fits": 0}
    for h, tp, pv, it in itertools.product(steps, *(MPC_CORNERS[k] for k in list(MPC_CORNERS)[1:])):
        section = {"horizon_steps": h, "prediction_step_s": tp, "preview_s": pv, "solver": {"iter_limit": it}}
        n = max(h, math.ceil(pv / tp - 1e-9))
        too_big = n > top or n * it > mpc.MAX_WORK
        try:
            model.model_validate(section)
        except Exception as exc:
            assert too_big, (section, exc)
            seen["refused"] += 1
            continue
        assert not too_big, section
        est = cost.mpc(kind, n, 1 / 120, hexapod=True)
        assert est.memory_bytes < cost.DEFAULT_CAP_GB * cost.GB - 0.5e9, (section, est)
        seen["fits"] += 1
    assert seen["refused"] and seen["fits"], seen


def test_a_slow_mpc_says_so_on_a_whole_recording_too(monkeypatch: pytest.MonkeyPatch,
                                                     capsys: pytest.CaptureFixture[str]) -> None:  # fmt: skip
    """Issue 54, item 3: the "slower than real time" note lived in ``step()``, and ``trace()`` (``cue``, every
    preview run) called ``_step()`` directly: 12 min 54 s of 5 s of flight without a word. Now ``trace()`` times its
    first samples as ``step()`` does, and before it starts says what the model estimates when that is long (the
    building of the QP when the washout is made, the recording's samples when its trace starts); the set points are
    the same bits either way."""
    from washbench.cueing import mpc
    from washbench.cueing.algorithm import WashoutContext

    limits = load_options().limits
    n = mpc.ESTIMATE_AFTER_STEPS + 5
    t = np.arange(n) / 120.0
    f = np.column_stack([0.5 * np.sin(t), np.zeros(n), np.full(n, -G)])
    w = np.zeros((n, 3))

    def trace() -> tuple[np.ndarray, np.ndarray]:
        algo = mpc.MpcWashout(mpc.MpcParams(preview_s=0.5), WashoutContext(1 / 120, G, limits, "steady", (0.0,) * 3))
        algo.start(f[0], w[0])
        return algo.trace(f, w)

    quiet = trace()
    err = capsys.readouterr().err  # (the timed note depends on the machine: only the model's notes are checked)
    assert "its QP takes about" not in err and f"{n} samples: about" not in err, err
    monkeypatch.setattr(mpc, "SLOW_FACTOR", 0.0)  # any speed is slow: the timed note is tested
    timed = trace()
    err = capsys.readouterr().err
    assert err.count("(timed on 20 after the first): a minute of flight takes about") == 1, err
    from washbench.io import cost

    monkeypatch.setattr(cost, "LONG_S", -1.0)  # any estimate is long: the model's notes are tested
    loud = trace()
    err = capsys.readouterr().err
    assert err.count("washbench: note: washout mpc: a horizon of 20 intervals: its QP takes about") == 1, err
    assert f"washbench: note: washout mpc: {n} samples: about" in err, err
    for a, b, c in zip(quiet, timed, loud, strict=True):
        assert np.array_equal(a, b) and np.array_equal(a, c)


# ------------------------------------------------------------------------ 4. omct of the bound on a hexapod or a rig


@pytest.mark.parametrize("platform", ["hexapod.yaml", "rig2dof.yaml"])
def test_omct_of_the_bound_on_a_hexapod_or_a_rig(platform: str) -> None:
    """Issue 54, item 4: ``omct --platform <hexapod> --washout bound`` ended in ``AttributeError: 'HexapodModel'
    object has no attribute 'translation'`` (the estimate handed the model to the replay where the Atlas-shaped
    limits belong). Now the estimate is the model's (:mod:`washbench.io.cost`) and the bound runs (one test, its
    highest frequency, at 10 Hz)."""
    from washbench.analysis import omct
    from washbench.cueing.variants import select_washouts
    from washbench.platform.model import load_platform_model
    from washbench.runs import omct as omct_run

    model = load_platform_model(DATA_DIR / platform)
    entries = select_washouts(["bound", "large-angle"], (), None)
    points, _ = omct_run.measure(entries, model, rate_hz=10.0, tests=omct.TESTS[3:4],
                                 frequencies_radps=omct.FREQUENCIES_RADPS[-1:])  # fmt: skip
    assert {p.washout for p in points} == {"bound", "large-angle"}
    assert all(math.isfinite(p.gain) for p in points)


def test_omct_announces_the_runs_of_a_costly_washout_once(capsys: pytest.CaptureFixture[str],
                                                          monkeypatch: pytest.MonkeyPatch) -> None:  # fmt: skip
    """The OMCT's runs of the bound (and of the MPC washouts) are estimated all at once before the first run and
    announced once; the runs themselves say nothing more."""
    from washbench.analysis import omct
    from washbench.cueing.variants import select_washouts
    from washbench.io import cost
    from washbench.runs import omct as omct_run

    monkeypatch.setattr(cost, "LONG_S", -1.0)
    entries = select_washouts(["bound", "mpc"], (), None)
    top = omct.FREQUENCIES_RADPS[-1]
    omct_run.measure(entries, load_options().limits, rate_hz=10.0, tests=omct.TESTS[:2], frequencies_radps=(top,))
    err = capsys.readouterr().err
    n = round(omct.timing(top, omct_run.slowest_decay(entries)).duration_s * 10.0) + 1
    assert err.count("washbench: note:") == 1, err
    assert f"omct: washout bound, mpc: 2 runs, {2 * n:,} samples in all: about" in err, err


# ---------------------------------------------------------------------------- 5. a hexapod with singular poses


def test_a_hexapod_singular_inside_its_stroke_gives_a_readable_run_json(tmp_path: Path) -> None:
    """Issue 54, item 5: the bundled hexapod with its platform joints in reverse order and legs of 0.5..6 m reaches
    poses where its leg Jacobian is singular; the whole run was done, then the command ended with exit 2 saying
    run.json was damaged (``Infinity`` written for the unbounded relaxation rates). Now they are null, run.json
    reads back, and the report says why."""
    text = (DATA_DIR / "hexapod.yaml").read_text()
    start, end = text.index("platform_joints_m:"), text.index("neutral_m:")
    head, *rows = [line for line in text[start:end].splitlines() if line.strip()]
    text = text[:start] + "\n".join([head, *reversed(rows)]) + "\n\n" + text[end:]
    text = text.replace("leg_length_m: {min: 2.151, max: 3.261}", "leg_length_m: {min: 0.5, max: 6.0}")
    platform = tmp_path / "singular.yaml"
    platform.write_text(text)
    src = signal_file(tmp_path / "in.parquet", 1.0)
    out = tmp_path / "out"
    proc = washbench("cue", src, "--out", out, "--platform", platform, "--washout", "bound", "--no-recording",
                     "--no-figures", "--quiet", timeout=600)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    run = json.loads((out / "run.json").read_text())
    relax = run["bound"]["relaxation"]
    assert relax["kind"] == "hexapod" and relax["rate_radps"] == [None, None, None], relax
    assert "singular poses inside its legs' stroke" in (out / "report.md").read_text()
    read_doc(out / "run.json", RunDoc)  # as every command that reads results reads it


# --------------------------------------------------------------------------- 6, 7. platform plugins, their contract

PLATFORM_PLUGIN = '''
import sys

import numpy as np
from washbench.platform.hexapod import MotionEnvelope


def box(t=0.2, rate=30.0):
    return {"name": "box", "translation": {
        "position_limit_m": {"x": t, "y": t, "z": t}, "velocity_limit_mps": {"x": 1, "y": 1, "z": 1},
        "acceleration_limit_mps2": {"x": 5, "y": 5, "z": 5}},
        "rotation": {"rate_limit_degps": rate, "acceleration_limit_degps2": 100, "catch_up_fraction": 0.5}}


class P:
    """A platform that follows its set points within a box, and misbehaves as ``BAD`` says."""

    platform_name = "p"
    unlimited_rotation = True
    BAD = "BAD_CASE"

    def __init__(self, params, context):
        self.k = -1

    @staticmethod
    def envelope(params):
        if P.BAD == "envelope raises":
            raise RuntimeError("no envelope today")
        if P.BAD == "envelope exits":
            sys.exit(0)
        env = MotionEnvelope.model_validate(box())
        if P.BAD == "envelope NaN":  # built past the model's checks
            t = env.translation
            nan = t.position_limit_m.model_construct(x=float("nan"), y=0.2, z=0.2)
            t = t.model_construct(position_limit_m=nan, velocity_limit_mps=t.velocity_limit_mps,
                                  acceleration_limit_mps2=t.acceleration_limit_mps2)
            return env.model_construct(name="box", translation=t, rotation=env.rotation)
        return env

    def start(self, pos, q):
        return np.clip(pos, -0.2, 0.2), q

    def step(self, pos, q):
        self.k += 1
        p = np.clip(pos, -0.2, 0.2)
        flags = [0, 0, 0, 0, 0]
        if self.k == 50:
            if P.BAD == "string flags":
                flags = ["0", "1", "0", "0", "0"]
            elif P.BAD == "flag 0.5":
                flags = [0.5, 0, 0, 0, 0]
            elif P.BAD == "NaN flag":
                flags = [float("nan"), 0, 0, 0, 0]
            elif P.BAD == "huge pose":
                p = np.array([1e150, 0.0, 0.0])
            elif P.BAD == "complex position":
                p = p + 1e-3j
            elif P.BAD == "exit in step":
                sys.exit(0)
        if P.BAD == "writes the set points" and pos.flags.writeable:
            pos[:] = 99.0
        return p, q, flags
'''

BAD_PLATFORMS = {
    # what the plugin does -> what the one line says
    "string flags": "sample 50: the flags are str",
    "flag 0.5": "sample 50: flags must be five 0/1 values ([0.5, 0, 0, 0, 0])",
    "NaN flag": "sample 50: flags must be five 0/1 values ([nan, 0, 0, 0, 0])",
    "huge pose": "sample 50: the position is more than 1000 m from neutral ([1e+150, 0, 0])",
    "complex position": "sample 50: the position pos_m are complex numbers, not real numbers",
    "exit in step": "sample 50: called sys.exit(0) (a platform may not end the command)",
    "envelope raises": "envelope(): raised RuntimeError: no envelope today",
    "envelope exits": "envelope(): called sys.exit(0) (a platform may not end the command)",
    "envelope NaN": "envelope(): not Atlas-shaped limits of finite numbers",
}


def plugin(folder: Path, bad: str) -> Path:
    path = folder / ("plat_" + re.sub(r"\W", "_", bad) + ".py")
    path.write_text(PLATFORM_PLUGIN.replace("BAD_CASE", bad))
    return path


def platform_trace(path: Path, n: int = 120) -> dict:
    """The washbench chain's whole-trace form (:func:`washbench.cueing.cue_trace`: the compiled washout, then the
    plugin behind it, :class:`washbench.cueing.bank.PluginPass`) of ``large-angle`` on the plugin's platform."""
    from washbench.cueing import cue_trace
    from washbench.cueing.variants import select_washouts
    from washbench.platform.plugins import PluginPlatform

    t = np.arange(n) / 120.0
    f = np.column_stack([2.0 * np.sin(2.0 * t), np.zeros(n), np.full(n, -G)])
    w = np.column_stack([np.zeros(n), 0.2 * np.sin(t), np.zeros(n)])
    platform = PluginPlatform(kind="p", name="p", source=f"{path}:P")
    return cue_trace(f, w, 1 / 120, select_washouts(["large-angle"], (), None), None, platform)


@pytest.mark.parametrize("bad", sorted(BAD_PLATFORMS))
def test_a_platform_plugin_is_held_to_its_contract_on_every_sample(bad: str, tmp_path: Path) -> None:
    """Issue 54, item 6: string flags, an ``envelope()`` that raises or gives a NaN limit, a pose of 1e150 m:
    tracebacks; a flag of 0.5 became 0 and a complex position lost its imaginary part (exit 0); a NaN flag was
    refused naming the last sample, not the bad one; ``sys.exit(0)`` in ``step()`` ended washbench with exit 0 and
    no message. Now each is one line naming the platform, its file and the sample (in the chain every command
    runs: the samples through :class:`washbench.cueing.bank.PluginPass`, the envelope where every command reads it,
    :meth:`washbench.platform.plugins.PluginPlatform.model_dump`)."""
    from washbench.platform.plugins import PluginPlatform

    path = plugin(tmp_path, bad)
    with pytest.raises(WashbenchError) as err:
        if bad.startswith("envelope"):
            PluginPlatform(kind="p", name="p", source=f"{path}:P").model_dump()
        else:
            platform_trace(path)
    text = str(err.value)
    assert text.startswith(f"platform p ({path}:P): ") and BAD_PLATFORMS[bad] in text and "\n" not in text, text


def test_a_platform_plugin_s_exit_is_one_line_from_the_command(short_input: Path, tmp_path: Path) -> None:
    """The same through ``washbench cue`` (a subprocess: it loads a plugin): exit 2, one line, nothing written
    (``sys.exit(0)`` in ``step()`` was exit 0 and silence)."""
    bad = "exit in step"
    path = plugin(tmp_path, bad)
    out = tmp_path / "out"
    proc = washbench("cue", short_input, "--out", out, "--platform-plugin", f"{path}:P", "--washout", "large-angle",
                     "--no-recording", "--no-figures", "--quiet")  # fmt: skip
    assert_clean_error(proc, f"platform p ({path}:P)", BAD_PLATFORMS[bad])
    assert not out.exists() or not any(out.rglob("traces.parquet"))


def test_a_platform_plugin_gets_read_only_copies_of_the_set_points(tmp_path: Path) -> None:
    """Issue 54, item 6: a plugin that wrote into the set-point arrays it was given changed the recorded
    ``sp_pos`` columns (washout plugins get read-only views). Now it gets read-only copies: the same traces as a
    plugin that writes nothing, bit for bit."""
    writer = platform_trace(plugin(tmp_path, "writes the set points"))["large-angle"]
    honest = platform_trace(plugin(tmp_path, "nothing"))["large-angle"]
    for field in ("sp_pos_m", "pos_m", "q"):
        assert np.array_equal(getattr(writer, field), getattr(honest, field)), field
    assert np.abs(honest.sp_pos_m).max() < 1.0 and np.abs(honest.sp_pos_m).max() > 0.0


def test_the_mpc_washouts_on_a_plugin_without_an_envelope_are_refused_before_anything_runs(tmp_path: Path) -> None:
    """Issue 54, item 7: ``mpc`` on a platform plugin without ``envelope()`` failed with an internal AttributeError
    text, ``mpc-unrestricted`` on one that declares unlimited rotation said "needs a platform of unlimited
    rotation" (the wrong reason), and a suite said so per manoeuvre after flying. Now the options refuse them (what
    every command loads before flying), naming the envelope."""
    from washbench.platform import plugins
    from washbench.platform.model import set_default_plugin

    path = tmp_path / "noenv.py"
    text = PLATFORM_PLUGIN.replace("BAD_CASE", "nothing")
    path.write_text(text.replace("    def envelope(params):", "    def no_envelope(params):"))
    kind = plugins.load_plugin(f"{path}:P")
    set_default_plugin(kind)
    try:
        for washout in ("mpc", "mpc-unrestricted"):
            with pytest.raises(WashbenchError, match=re.escape(f"washout {washout} ({washout}): plans against the "
                                                               "platform's envelope")):  # fmt: skip
                load_options(washouts=[washout])
    finally:
        set_default_plugin(None)
        plugins._LOADED.pop(kind, None)


# ---------------------------------------------------------------------------------------- 8. the leftovers


def test_another_package_s_broken_entry_points_are_passed_over(tmp_path: Path) -> None:
    """Issue 54, item 8: a garbage ``entry_points.txt`` of an unrelated installed distribution made every command
    end in ``TypeError: Pair.__new__() missing 1 required positional argument`` (pydantic reads every
    distribution's entry points at its first model; so did washbench's plugin look-ups). Now one warning naming
    the distribution, and the command runs."""
    dist = tmp_path / "site" / "garbage-1.0.dist-info"
    dist.mkdir(parents=True)
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: garbage\nVersion: 1.0\n")
    (dist / "entry_points.txt").write_text("[console_scripts]\nthis is not an entry point\n")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(tmp_path / "site"), os.environ.get("PYTHONPATH", "")])}
    for args in (("validate", "c172/takeoff"),):
        proc = command(*args, env=env, timeout=120)
        assert proc.returncode == 0, proc.stderr
        assert "Traceback" not in proc.stderr
        warned = [line for line in proc.stderr.splitlines() if "garbage" in line]
        assert len(warned) == 1 and "its entry points cannot be read" in warned[0], proc.stderr


def test_live_stopped_while_a_plugin_blocks_keeps_every_sample_received(tmp_path: Path) -> None:
    """Issue 54, item 8: ``live`` with a plugin that blocks, stopped by SIGTERM, kept 49 of 200 received samples.
    Now every sample that arrived is saved (the one being cued, the link's held ones, the socket's queue), none
    cued again."""
    from test_hostile_round3 import plugin_file

    path = plugin_file(tmp_path, step="time.sleep(600)", after=50)
    port = free_udp_port()
    out = tmp_path / "live"
    proc = subprocess.Popen(
        [sys.executable, "-m", "washbench", "live", "--listen", f"127.0.0.1:{port}", "--format", "washbench",
         "--out", str(out), "--no-viewer", "--no-recording", "--no-figures", "--washout-plugin", f"{path}:P",
         "--washout", "p"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    try:
        _send_samples(port, "washbench", motion(200))()  # waits until live listens; then all 200 are in its socket
        time.sleep(0.5)
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=60)
    finally:
        proc.kill()
    assert proc.returncode == 143, err
    assert "the 200 sample(s) received are in" in err, err
    rows = saved(out)
    np.testing.assert_array_equal(rows, np.array(motion(200)))


@pytest.mark.parametrize("what", ["send", "cue"])
def test_a_fifo_with_no_writer_is_refused_not_waited_on(tmp_path: Path, what: str) -> None:
    """Issue 54, item 8: ``washbench send`` of a FIFO with no writer hung (so did ``cue``: both open the input
    several times). Now one line: not a regular file."""
    fifo = tmp_path / "in.csv"
    os.mkfifo(fifo)
    if what == "send":  # (a subprocess under a time limit: the code before the fix waits for ever)
        proc = command("send", fifo, "--to", "127.0.0.1:9", timeout=60)
    else:
        proc = washbench("cue", fifo, "--out", tmp_path / "out", timeout=60)
    assert_clean_error(proc, str(fifo), "is a FIFO (named pipe), not a regular file")


def test_a_run_records_the_statistics_of_the_whole_recording_washouts(tmp_path: Path) -> None:
    """Issue 54, item 8: in a suite (every ``run``), run.json had no solver statistics for the washouts cued after
    the flight on the whole recording (an MPC with preview, the bound), while ``cue`` records them. Now the run
    records them beside the lockstep's, in the listed order."""
    from test_ceiling import CRUISE

    (tmp_path / "level_cruise.yaml").write_text(CRUISE)
    out = tmp_path / "o"
    proc = washbench("run", tmp_path / "level_cruise.yaml", "--out", out, "--washout", "small-angle", "--washout",
                     "mpc", "--washout", "bound", "--variant", "ahead=mpc,mpc.preview_s=0.5", "--no-recording",
                     "--no-figures", "--quiet", timeout=600)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    algorithms = json.loads((out / "c172p" / "level_cruise" / "run.json").read_text())["algorithms"]
    assert list(algorithms) == ["mpc", "bound", "ahead"], algorithms
    n = json.loads((out / "c172p" / "level_cruise" / "run.json").read_text())["steps"]
    assert algorithms["ahead"]["solves"] == n and n - 1 <= algorithms["mpc"]["solves"] <= n, algorithms
    assert algorithms["bound"]["translation_solved"] == 1, algorithms


# ----------------------------------------------------------------------- 9. SIGTERM while the workers start


def test_a_signal_during_a_held_section_that_then_fails_ends_as_the_signal() -> None:
    """Issue 54, item 9: SIGTERM to the whole process group while ``suite --jobs 2`` started its workers ended in
    ``EOFError`` from multiprocessing's forkserver (the server had died of the same signal) and exit 1, not 143:
    the held section (``submit_all``) failed before the held signal was acted on. Now the signal wins."""
    old = signal.signal(signal.SIGTERM, interrupts.terminate)
    try:
        with pytest.raises(Terminated) as err, interrupts.signals_held():
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(0.01)  # (the handler runs between bytecodes)
            raise EOFError("unexpected EOF")  # what the dead server's socket gives
        assert isinstance(err.value.__cause__, EOFError)
        with pytest.raises(EOFError), interrupts.signals_held():  # no signal: the error is the error
            raise EOFError("unexpected EOF")
    finally:
        signal.signal(signal.SIGTERM, old)


HELD_IN_A_WORKER = """
import os, signal, sys
from washbench.io import interrupts

signal.signal(signal.SIGINT, signal.SIG_IGN)  # a suite's worker and process server: SIGINT is the main process's
signal.signal(signal.SIGTERM, signal.SIG_DFL)  # and SIGTERM ends them
with interrupts.signals_held():
    os.kill(os.getpid(), signal.SIGINT)
print("SIGINT ignored", flush=True)
with interrupts.signals_held():
    os.kill(os.getpid(), signal.SIGTERM)
print("still alive", flush=True)
"""


def test_a_signal_held_in_a_worker_is_acted_on_as_the_worker_would() -> None:
    """Found running the process-group SIGTERM of item 9 (once in 45 suites: exit 143 with a traceback ending in
    ``washbench.errors.Terminated``): a held section acted on a held signal by raising KeyboardInterrupt or
    Terminated whatever the process did with that signal, so a suite's process server or worker (SIGINT ignored,
    SIGTERM its default) building a model when the group's SIGTERM came printed a traceback, and a Ctrl-C raised
    in a worker that ignores it. Now the held signal is acted on as the handler the section replaced would have:
    ignored stays ignored, the default ends the process (by the signal, silently), washbench's raise."""
    proc = subprocess.run([sys.executable, "-c", HELD_IN_A_WORKER], capture_output=True, text=True, timeout=120)
    assert proc.stdout == "SIGINT ignored\n" and proc.returncode == -signal.SIGTERM, (proc.returncode, proc.stdout,
                                                                                        proc.stderr)  # fmt: skip
    assert proc.stderr == "", proc.stderr


def test_tune_announces_its_evaluations_when_they_take_long(capsys: pytest.CaptureFixture[str]) -> None:
    """The offline optimiser (``tune``, differential evolution): once the starting set is evaluated, the rest of the
    budget is announced at that evaluation's time when it is long, before the optimiser starts; nothing when short."""
    from types import SimpleNamespace

    from washbench.runs import tune

    flights = [SimpleNamespace(evaluator=SimpleNamespace(n=7200)), SimpleNamespace(evaluator=SimpleNamespace(n=3600))]
    tune._announce(0.1, 199, flights)  # 20 s: not long
    assert capsys.readouterr().err == ""
    tune._announce(2.0, 199, flights)  # 6 min 38 s
    err = capsys.readouterr().err
    assert err.startswith("washbench: note: tune: 199 more evaluation(s) on 2 training flight(s) (10,800 samples): at "
                          "most about 6 min 38 s at the starting set's 2 s each"), err  # fmt: skip

