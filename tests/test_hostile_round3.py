"""Hardening, third round (issue 37): plugins that misbehave, the configuration file, ``live`` against whatever
reaches its port, the solvers' effort.

Each test drives the real command in a subprocess under a time limit and checks the exit status, the one line
naming the file or the washout, no traceback, and what was (or was not) written.
"""

from __future__ import annotations

import csv
import os
import signal
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest
from hostile import assert_clean_error, short, tree, washbench

from washbench.analysis.signals import SignalSpec, generate
from washbench.io.motion_file import write_motion

# ------------------------------------------------------------------------------------------ plugins

PLUGIN_HEAD = """\
import os
import sys
import time

import numpy as np


class Weird:
    '''A value whose conversions raise.'''

    def __float__(self):
        raise {weird}

    def __bool__(self):
        raise {weird}

    def __index__(self):
        raise {weird}


"""

PLUGIN_CLASS = """\
class P:
    washout_name = "p"

    def __init__(self, params, context):
        {init}
        self.k = 0

    def start(self, f, omega):
        return np.zeros(3), np.array([1.0, 0, 0, 0])

    def step(self, f, omega):
        self.k += 1
        if self.k > {after}:
            {step}
        return np.zeros(3), np.array([1.0, 0, 0, 0])
"""


def plugin_file(folder: Path, *, module: str = "", init: str = "pass", step: str = "pass", extra: str = "",
                weird: str = "RuntimeError('no number')", after: int = 100, name: str = "p.py") -> Path:  # fmt: skip
    """A washout plugin ``P`` (kind ``p``) whose ``step`` does ``step`` after ``after`` steps; ``extra``: more
    methods (indented 4); ``module``: a line run when the module loads."""
    path = folder / name
    text = PLUGIN_HEAD.format(weird=weird) + module + "\n\n" + PLUGIN_CLASS.format(init=init, step=step, after=after)
    path.write_text(text + extra)
    return path


@pytest.fixture(scope="module")
def step_csv(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A 4 s step in f_y at 120 Hz, as `washbench signal` writes it."""
    path = tmp_path_factory.mktemp("step") / "step.csv"
    sig = generate(SignalSpec("step", "f_y", 2.0, None, 4.0, 120.0, 0.5))
    write_motion(path, sig.t_s, sig.f_mps2, sig.omega_radps)
    return path


BAD_PLUGINS: dict[str, tuple[dict[str, str], str]] = {
    # what the plugin does -> (plugin_file arguments, what the one line says)
    "sys.exit(0) in step": ({"step": "sys.exit(0)"}, "step 100 (t = 0.833333 s): called sys.exit(0)"),
    "sys.exit(0) in the factory": ({"init": "sys.exit(0)"}, "making it: called sys.exit(0)"),
    "sys.exit(0) when the module loads": ({"module": "sys.exit(0)"}, "p.py:21: called sys.exit(0)"),
    "KeyboardInterrupt without Ctrl-C": ({"step": "raise KeyboardInterrupt"}, "raised KeyboardInterrupt (no signal"),
    "SystemExit from __float__": (
        {"step": "return [Weird(), 0, 0], [1, 0, 0, 0]", "weird": "SystemExit(4)"},
        "step 100 (t = 0.833333 s): called sys.exit(4)",
    ),
    "RuntimeError from __float__": ({"step": "return [Weird(), 0, 0], [1, 0, 0, 0]"}, "RuntimeError: no number"),
    "flags() returns a 2x2 array": (
        {"extra": "\n    def flags(self):\n        return np.ones((2, 2))\n"},
        "flags() returned array",
    ),
    "flags() value whose __bool__ raises": (
        {"extra": "\n    def flags(self):\n        return Weird(), False\n"},
        "flags(): raised RuntimeError: no number",
    ),
    "trace() returns a dict": (
        {"extra": "\n    def trace(self, f, omega):\n        return {'pos': 1, 'q': 2}\n"},
        "trace: returned dict, expected a tuple",
    ),
    "trace() returns values whose __float__ raises": (
        {"extra": "\n    def trace(self, f, omega):\n        return [[Weird()] * 3] * len(f), [[1, 0, 0, 0]] * 9\n"},
        "trace: raised RuntimeError: no number",
    ),
}


def test_a_plugin_s_exit_interrupt_or_odd_values_are_one_line(step_csv: Path, tmp_path: Path) -> None:
    """sys.exit() anywhere in a plugin (module, factory, step, a value's __float__), a KeyboardInterrupt with no
    Ctrl-C, flags() giving an array or values whose __bool__ raises, trace() giving a dict: exit 2 and one line
    naming the washout and where (they gave exit 0 with no result, exit 130 "interrupted", or tracebacks)."""

    def one(item: tuple[int, tuple[str, tuple[dict[str, str], str]]]) -> None:
        i, (case, (kwargs, expected)) = item
        folder = tmp_path / f"case{i}"
        folder.mkdir()
        plugin = plugin_file(folder, **kwargs)
        out = folder / "out"
        proc = washbench("cue", step_csv, "--washout-plugin", f"{plugin}:P", "--washout", "p", "--washout",
                         "large-angle", "--out", out, "--no-recording", "--no-figures", timeout=120)  # fmt: skip
        assert proc.returncode == 2, (case, proc.returncode, proc.stderr)
        assert_clean_error(proc, expected)
        assert not (out / "metrics.csv").exists(), case

    with ThreadPoolExecutor(2) as pool:
        list(pool.map(one, enumerate(BAD_PLUGINS.items())))


def test_an_entry_point_plugin_calling_sys_exit_is_one_line(step_csv: Path, tmp_path: Path) -> None:
    site = tmp_path / "site"
    dist = site / "exiting-0.1.dist-info"
    dist.mkdir(parents=True)
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: exiting\nVersion: 0.1\n")
    (dist / "entry_points.txt").write_text("[washbench.washouts]\nexiting = exiting_plugin:P\n")
    (site / "exiting_plugin.py").write_text("import sys\n\nsys.exit(0)\n")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(site), *filter(None, [os.environ.get("PYTHONPATH")])])}
    proc = subprocess.run(
        [sys.executable, "-m", "washbench", "cue", str(step_csv), "--washout", "exiting", "--out",
         str(tmp_path / "out"), "--no-recording", "--no-figures"],
        capture_output=True, text=True, timeout=120, env=env,
    )  # fmt: skip
    assert_clean_error(proc, "entry point exiting_plugin:P", "called sys.exit(0)")


def test_a_real_ctrl_c_while_a_plugin_steps_still_interrupts(step_csv: Path, tmp_path: Path) -> None:
    """The guard tells the plugin's KeyboardInterrupt from a real one: SIGINT while step() blocks is 130."""
    plugin = plugin_file(tmp_path, step="open(os.environ['READY'], 'w').close()\n            time.sleep(600)",
                         after=10)  # fmt: skip
    ready = tmp_path / "ready"
    proc = subprocess.Popen(
        [sys.executable, "-m", "washbench", "cue", str(step_csv), "--washout-plugin", f"{plugin}:P", "--washout", "p",
         "--out", str(tmp_path / "out"), "--no-recording", "--no-figures"],
        stderr=subprocess.PIPE, text=True, env={**os.environ, "READY": str(ready)},
    )  # fmt: skip
    try:
        deadline = time.monotonic() + 120
        while not ready.exists() and time.monotonic() < deadline and proc.poll() is None:
            time.sleep(0.05)
        assert ready.exists()
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=30)
    finally:
        proc.kill()
    assert proc.returncode == 130, err
    assert err.strip().splitlines()[-1] == "washbench: interrupted" and "Traceback" not in err, err


VANDAL = """

    def trace_base_and_write(self, a):
        while a is not None:
            try:
                a.flags.writeable = True
                a[...] = 50.0
            except (ValueError, TypeError):
                pass
            a = getattr(a, "base", None)
"""


def _metrics(path: Path, washout: str) -> list[dict[str, str]]:
    return [r for r in csv.DictReader(path.open()) if r["washout"] == washout]


def test_a_plugin_cannot_write_into_what_other_washouts_and_the_metrics_see(step_csv: Path, tmp_path: Path) -> None:
    """A plugin making its read-only inputs writeable again (through their base too) and writing into them: the
    other washout's metrics are those of a run without it (before: they changed)."""
    plugin = plugin_file(tmp_path, step="self.trace_base_and_write(f)\n            self.trace_base_and_write(omega)",
                         after=0, extra=VANDAL)  # fmt: skip
    alone = washbench("cue", step_csv, "--washout", "large-angle", "--out", tmp_path / "alone", "--no-recording",
                      "--no-figures", timeout=120)  # fmt: skip
    assert alone.returncode == 0, alone.stderr
    both = washbench("cue", step_csv, "--washout-plugin", f"{plugin}:P", "--washout", "p", "--washout", "large-angle",
                     "--out", tmp_path / "both", "--no-recording", "--no-figures", timeout=120)  # fmt: skip
    assert both.returncode == 0, both.stderr
    want = _metrics(tmp_path / "alone" / "metrics.csv", "large-angle")
    got = _metrics(tmp_path / "both" / "metrics.csv", "large-angle")
    assert want and got == want


TRACE_ONLY = """
    def trace(self, f, omega):
        # the whole-trace form: a constant 0.1 m surge set point (step() would fail)
        pos = np.zeros((len(f), 3))
        pos[:, 0] = 0.1
        return pos, np.tile([1.0, 0, 0, 0], (len(f), 1))
"""


def test_cue_uses_a_plugin_s_whole_trace_form(step_csv: Path, tmp_path: Path) -> None:
    """docs/washouts.md: the bench uses ``trace()`` for recorded files: cue gives the trace's set points (its
    step() raises; before, cue stepped it and failed)."""
    plugin = plugin_file(tmp_path, step="raise RuntimeError('step called')", after=0, extra=TRACE_ONLY)
    proc = washbench("cue", step_csv, "--washout-plugin", f"{plugin}:P", "--washout", "p", "--out", tmp_path / "out",
                     "--no-recording", "--no-figures", timeout=120)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    import pyarrow.parquet as pq

    t = pq.read_table(tmp_path / "out" / "traces.parquet")
    sp = t["p.sp_x_m"].to_numpy() if "p.sp_x_m" in t.column_names else None
    x = t["p.pos_x_m"].to_numpy()
    assert sp is None or (sp == 0.1).all()
    assert abs(x[-1] - 0.1) < 1e-3  # the platform reached the trace's 0.1 m set point (4 s at its limits)


# suite workers -----------------------------------------------------------------------------------


def _suite_with(tmp_path: Path, how: str) -> tuple[subprocess.CompletedProcess[str], Path]:
    """suite --jobs 2 of a 1 s and a 4 s manoeuvre with a plugin doing ``how`` after 200 steps (1.7 s: only in the
    longer one)."""
    step = {
        "exit": "sys.exit(0)",
        "os_exit": "os._exit(3)",
        "sigkill": "os.kill(os.getpid(), 9)",
    }[how]
    plugin = plugin_file(tmp_path, step=step, after=200)
    a, b = short(tmp_path, "brief", 1), short(tmp_path, "longer", 4)
    out = tmp_path / "out"
    proc = washbench("suite", a, b, "--jobs", "2", "--washout-plugin", f"{plugin}:P", "--washout", "p", "--washout",
                     "large-angle", "--out", out, "--no-recording", "--no-figures", timeout=240)  # fmt: skip
    return proc, out


@pytest.mark.parametrize("how", ["exit", "os_exit", "sigkill"])
def test_a_suite_run_whose_plugin_exits_or_whose_worker_dies_fails_alone(how: str, tmp_path: Path) -> None:
    """sys.exit() in a worker's plugin, a worker's os._exit or SIGKILL: that manoeuvre fails with a reason, the
    other is written, the suite's results too (before: nothing written, or a BrokenProcessPool traceback)."""
    proc, out = _suite_with(tmp_path, how)
    assert proc.returncode == 1, proc.stderr
    assert "Traceback" not in proc.stderr and "BrokenProcessPool" not in proc.stderr, proc.stderr
    assert "1/2 runs ok" in proc.stdout
    assert (out / "c172p" / "brief" / "metrics.csv").is_file()
    assert (out / "metrics.csv").is_file() and (out / "report.md").is_file()
    expected = {
        "exit": "called sys.exit(0)",
        "os_exit": "exited with status 3",
        "sigkill": "killed by SIGKILL",
    }[how]
    assert expected in proc.stderr, proc.stderr
    assert not [p for p in tree(out) if Path(p).name.startswith(".washbench-stage")], tree(out)


# ------------------------------------------------------------------------------------------ the configuration file


def _small_csv(path: Path) -> Path:
    sig = generate(SignalSpec("sine", "f_x", 1.0, 0.5, 2.0, 60.0, 0.0))
    write_motion(path, sig.t_s, sig.f_mps2, sig.omega_radps)
    return path


def _wb_in(cwd: Path, *args: object, env: dict[str, str] | None = None) -> subprocess.CompletedProcess[str]:
    full = {k: v for k, v in os.environ.items() if k not in ("WASHBENCH_CONFIG_USED", "WASHBENCH_SAFE_CONFIG")}
    full.update(env or {})
    return subprocess.run([sys.executable, "-m", "washbench", *map(str, args)], cwd=cwd, capture_output=True,
                          text=True, timeout=120, env=full)  # fmt: skip


DEEP = "x = " + "[" * 100_000 + "]" * 100_000 + "\n"

BAD_CONFIGS = {
    # file text -> what the one line says (after the file's name)
    "NUL in out": ('out = "re\\u0000sults"\n', "out: a path with a control character"),
    "escape in out": ('out = "\\u001b[2Jr"\n', "out: a path with a control character"),
    "arrays nested 100,000 deep": (DEEP, "nested too deeply"),
}


@pytest.mark.parametrize("case", sorted(BAD_CONFIGS))
def test_a_hostile_configuration_file_is_one_line(case: str, tmp_path: Path) -> None:
    text, expected = BAD_CONFIGS[case]
    (tmp_path / "washbench.toml").write_text(text)
    proc = _wb_in(tmp_path, "signal", "step", "--axis", "f_y", "--amplitude", "1", "--duration-s", "1", "--out",
                  "x.csv")  # fmt: skip
    assert_clean_error(proc, str(tmp_path / "washbench.toml"), expected)
    assert "\x1b" not in proc.stderr and not (tmp_path / "x.csv").exists()
    version = _wb_in(tmp_path, "--version")  # --version still answers (it was a RecursionError traceback)
    assert version.returncode == 0 and "Traceback" not in version.stderr, version.stderr


def test_an_8_gb_configuration_file_is_refused_unread(tmp_path: Path) -> None:
    config = tmp_path / "washbench.toml"
    with config.open("wb") as fh:
        fh.truncate(8 * 1024**3)  # sparse: no disk used
    proc = _wb_in(tmp_path, "signal", "step", "--axis", "f_y", "--amplitude", "1", "--out", "x.csv")
    assert_clean_error(proc, str(config), "larger than 10 MB")


def test_another_tool_s_deep_table_in_pyproject_is_passed_over(tmp_path: Path) -> None:
    (tmp_path / "pyproject.toml").write_text('[project]\nname = "x"\n\n[tool.other]\n' + DEEP)
    proc = _wb_in(tmp_path, "signal", "step", "--axis", "f_y", "--amplitude", "1", "--duration-s", "1", "--out",
                  "x.csv")  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert "configuration" not in proc.stderr


def test_a_configuration_with_a_byte_order_mark_is_used_and_named(tmp_path: Path) -> None:
    config = tmp_path / "washbench.toml"
    config.write_bytes(b'\xef\xbb\xbfout = "results"\n')
    _small_csv(tmp_path / "small.csv")
    proc = _wb_in(tmp_path, "cue", "small.csv", "--no-recording", "--no-figures")
    assert proc.returncode == 0, proc.stderr
    assert f"washbench: note: configuration from {config}" in proc.stderr.splitlines()
    assert (tmp_path / "results" / "metrics.csv").is_file()


@pytest.mark.skipif(not hasattr(os, "geteuid") or os.geteuid() != 0, reason="needs root to give a file away")
def test_a_configuration_another_user_owns_is_not_used_but_named(tmp_path: Path) -> None:
    """A washbench.toml in a parent folder that belongs to another user (uid 4242): not applied, a warning names
    it and how to trust it (git's safe.directory); trusted through WASHBENCH_SAFE_CONFIG it is used."""
    shared = tmp_path / "shared"
    mine = shared / "mine"
    mine.mkdir(parents=True)
    config = shared / "washbench.toml"
    config.write_text('out = "hijacked"\n')
    os.chown(config, 4242, 4242)
    os.chown(shared, 4242, 4242)
    _small_csv(mine / "small.csv")
    proc = _wb_in(mine, "cue", "small.csv", "--out", "r", "--no-recording", "--no-figures")
    assert proc.returncode == 0, proc.stderr
    assert f"{config} belongs to another user (uid 4242): not used" in proc.stderr
    assert "WASHBENCH_SAFE_CONFIG" in proc.stderr
    assert "configuration from" not in proc.stderr
    trusting = _wb_in(mine, "cue", "small.csv", "--no-recording", "--no-figures",
                      env={"WASHBENCH_SAFE_CONFIG": str(config)})  # fmt: skip
    assert trusting.returncode == 0, trusting.stderr
    assert (shared / "hijacked" / "metrics.csv").is_file()  # relative to the file's folder
    assert f"configuration from {config}" in trusting.stderr
