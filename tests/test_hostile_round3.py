"""Hardening, third round (issue 37): plugins that misbehave, the configuration file, ``live`` against whatever
reaches its port, the solvers' effort.

Each test drives the real command in a subprocess under a time limit and checks the exit status, the one line
naming the file or the washout, no traceback, and what was (or was not) written.
"""

from __future__ import annotations

import csv
import math
import os
import re
import signal
import socket
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import inprocess
import numpy as np
import pytest
from hostile import assert_clean_error, short, tree, washbench
from test_live import DT, _send_samples, free_udp_port, in_thread, live, motion, run_json, saved, wait_listening

from washbench.analysis.signals import SignalSpec, generate
from washbench.errors import WashbenchError
from washbench.io.motion_file import write_motion
from washbench.live import packets
from washbench.live.link import Link
from washbench.live.saved_input import INPUT_FILE
from washbench.runs.cue import run_cue
from washbench.runs.options import load_options
from washbench.runs.outputs import Outputs

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


@pytest.mark.slow
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
    return inprocess.washbench(*args, cwd=cwd, timeout=120, env=full)


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


# ------------------------------------------------------------------------------------------ live



def test_a_gap_is_filled_only_as_far_as_the_arrival_clock_allows() -> None:
    """The source's time jumps 3000 s forward while 1 ms passes: a new segment, no sample made up (before: 360,000
    held samples here, 1.5e9 with a 2 us step); a stray t = 0 in a stream at t = 100 s and the stream going on:
    no gap filled (before: 12,000 held samples); a real 0.5 s gap that took 0.5 s: its 59 samples held."""
    m = motion(240, t0=100.0)
    link = Link(dt_s=DT)
    outs = []
    arrival = 0.0
    for s in m[:120]:
        outs += link.push(s, arrival)
        arrival += DT
    jump = (m[119][0] + 3000.0, *m[119][1:])
    outs += link.push(jump, arrival + 0.001)
    assert link.counts.lost == 0 and link.counts.time_jumps == 1 and outs[-1].new_segment and len(outs) == 121

    link = Link(dt_s=DT)
    outs = []
    arrival = 0.0
    for k, s in enumerate(m):
        if k == 100:
            outs += link.push((0.0, *s[1:]), arrival)  # the stray datagram
        outs += link.push(s, arrival)
        arrival += DT
    assert link.counts.lost == 0 and link.counts.restarts == 1 and link.counts.time_jumps == 1
    assert len(outs) == 241  # every sample once, the stray too; none made up

    link = Link(dt_s=DT)
    outs = []
    for k, s in enumerate(m):
        if 60 <= k < 120:
            continue  # lost in the network: 0.5 s with nothing, and the arrival clock shows it
        outs += link.push(s, k * DT)
    assert link.counts.lost == 60 and link.counts.time_jumps == 0 and len(outs) == 240


def test_tiny_time_steps_stop_the_session_and_save_what_arrived(tmp_path: Path) -> None:
    """Ten samples 2 us apart, then one at t = 3000 s: one line, exit 2, the samples received saved (before: held
    samples without end, deaf to SIGTERM; or, with any first 8 steps under 1 us, no file)."""
    m = [(k * 2e-6, *s[1:]) for k, s in enumerate(motion(10))] + [(3000.0, *motion(1)[0][1:])]
    port = free_udp_port()
    th = in_thread(_send_samples(port, "washbench", m))
    with pytest.raises(WashbenchError, match=r"time step.*2e-06 s, outside 0.0001..10 s.*8 sample\(s\) received"):
        live(tmp_path, "washbench", port)
    th.join(10)
    got = saved(tmp_path / "live")
    assert got.shape == (8, 7) and (got[:, 0] == [k * 2e-6 for k in range(8)]).all()


def test_rate_hz_out_of_range_is_refused_before_listening(tmp_path: Path) -> None:
    with pytest.raises(WashbenchError, match=r"--rate-hz: expected 0.1..10000 Hz, got 1e\+300"):
        live(tmp_path, "washbench", free_udp_port(), rate_hz=1e300)
    assert not (tmp_path / "live").exists()


def test_live_locks_onto_the_first_sender(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A second sender (another time base) at once: its datagrams ignored, counted and named; the result is the
    first sender's stream alone (before: 802 datagrams became 2.78 million commands)."""
    port = free_udp_port()
    first, second = motion(240), motion(240, t0=500.0)

    def both() -> None:
        udp = (socket.AF_INET, socket.SOCK_DGRAM)
        with socket.socket(*udp) as a, socket.socket(*udp) as b:
            a.connect(("127.0.0.1", port))
            b.connect(("127.0.0.1", port))
            wait_listening(a)
            enc = packets.ENCODERS["washbench"]
            a.send(enc(0, first[0]))
            time.sleep(0.05)
            for k in range(1, 240):
                a.send(enc(k, first[k]))
                b.send(enc(k, second[k]))
                if k % 20 == 0:
                    time.sleep(0.002)

    th = in_thread(both)
    status, out = live(tmp_path, "washbench", port)
    th.join(10)
    assert status == 0
    c = run_json(out)["live"]["counts"]
    assert c["cued"] == 240 and c["other_senders"] == 239 and c["segments"] == 1 and c["lost_held"] == 0
    np.testing.assert_array_equal(saved(out), np.array(first))
    text = capsys.readouterr().out
    assert "ignored: locked onto 127.0.0.1:" in text and "datagrams from other senders 239" in text


def test_idle_timeout_fires_when_nothing_ever_arrives(tmp_path: Path) -> None:
    start = time.monotonic()
    with pytest.raises(WashbenchError, match=r"0 sample\(s\) received \(the source was quiet .*nothing arrived"):
        live(tmp_path, "washbench", free_udp_port())
    assert time.monotonic() - start < 60


def test_a_session_with_too_few_samples_keeps_the_earlier_session_s_files(tmp_path: Path) -> None:
    port = free_udp_port()
    th = in_thread(_send_samples(port, "washbench", motion(120)))
    status, out = live(tmp_path, "washbench", port)
    th.join(10)
    assert status == 0
    before = {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()}
    port = free_udp_port()
    th = in_thread(_send_samples(port, "washbench", motion(1)))
    with pytest.raises(WashbenchError, match=r"1 sample\(s\) received"):
        live(tmp_path, "washbench", port)
    th.join(10)
    after = {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()}
    assert after == before  # live_input.csv was deleted before


def test_a_killed_session_s_part_file_is_taken_back(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "live"
    out.mkdir()
    part = out / (INPUT_FILE + ".part")
    part.write_bytes(b"t_s,f_x_mps2,f_y_mps2,f_z_mps2,omega_x_degps,omega_y_degps,omega_z_degps,live_held\n0.0,1")
    port = free_udp_port()
    th = in_thread(_send_samples(port, "washbench", motion(120)))
    status, _ = live(tmp_path, "washbench", port)
    th.join(10)
    assert status == 0 and not part.exists() and saved(out).shape == (120, 7)
    assert "left by a session that was killed" in capsys.readouterr().out
    part.write_text("the user's own notes\n")  # not ours: still refused
    with pytest.raises(WashbenchError, match="washbench did not write this"):
        live(tmp_path, "washbench", free_udp_port())
    assert part.read_text() == "the user's own notes\n"


def test_flightgear_native_packets_get_a_hint(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    port = free_udp_port()
    native = b"\x00\x00\x00\x18" + bytes(404)  # FGNetFDM version 24, as JSBSim's type="FLIGHTGEAR" sends

    def go() -> None:
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
            s.connect(("127.0.0.1", port))
            wait_listening(s)
            for _ in range(5):
                s.send(native)

    th = in_thread(go)
    with pytest.raises(WashbenchError, match="0 sample"):
        live(tmp_path, "flightgear", port)
    th.join(10)
    text = capsys.readouterr().out
    assert text.count("FlightGear's native FDM format") == 1 and "--format flightgear" in text


def test_arrival_time_is_the_kernel_s_so_queue_time_counts() -> None:
    """A datagram that waited 0.2 s in the receive queue: its arrival stamp is from before the wait (before: the
    time recvfrom returned, so the wait was not in the latency)."""
    from washbench.runs.live import receiver

    udp = (socket.AF_INET, socket.SOCK_DGRAM)
    with socket.socket(*udp) as rx, socket.socket(*udp) as tx:
        rx.bind(("127.0.0.1", 0))
        recv, clock = receiver(rx)
        tx.sendto(b"x", rx.getsockname())
        sent = clock()
        time.sleep(0.2)
        data, _, arrival = recv()
        now = clock()
    assert data == b"x"
    if sys.platform.startswith("linux"):
        assert arrival <= sent + 5_000_000 and now - arrival >= 150_000_000


def test_send_jsbsim_into_live_jsbsim_equals_cue_of_the_file(tmp_path: Path) -> None:
    """JSBSim's one-frame lag is shifted back by live: send gives it to the samples again, so the live result is
    cue of the file sent, every metric (before: shifted twice, 0 of 138 metrics equal)."""
    m = motion(240)
    src = tmp_path / "in.csv"
    src.write_text("t_s,f_x_mps2,f_y_mps2,f_z_mps2,omega_x_degps,omega_y_degps,omega_z_degps\n"
                   + "".join(",".join(repr(v) for v in r) + "\n" for r in m))  # fmt: skip
    port = free_udp_port()

    def go() -> None:
        from washbench.runs.send import run_send

        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
            s.connect(("127.0.0.1", port))
            wait_listening(s)
        run_send("jsbsim", ("127.0.0.1", port), src, speed=8.0)

    th = in_thread(go)
    status, out = live(tmp_path, "jsbsim", port)
    th.join(10)
    assert status == 0
    np.testing.assert_allclose(saved(out), np.array(m), rtol=1e-15, atol=1e-13)
    run_cue(src, tmp_path / "orig", run=load_options(outputs=Outputs(recording=False, figures=False)))
    a = list(csv.DictReader((out / "metrics.csv").open()))
    b = list(csv.DictReader((tmp_path / "orig" / "metrics.csv").open()))
    assert len(a) == len(b) >= 6
    for ra, rb in zip(a, b, strict=True):
        assert ra.keys() == rb.keys()
        for k in ra:
            if ra[k] != rb[k]:
                assert float(ra[k]) == pytest.approx(float(rb[k]), rel=1e-9, abs=1e-12), (k, ra, rb)


def test_send_speed_out_of_range_is_one_line(tmp_path: Path) -> None:
    src = tmp_path / "in.csv"
    src.write_text("t_s,f_x_mps2,f_y_mps2,f_z_mps2,omega_x_degps,omega_y_degps,omega_z_degps\n0,0,0,-9.8,0,0,0\n"
                   "0.01,0,0,-9.8,0,0,0\n")  # fmt: skip
    for speed in ("1e-300", "nan", "1e300"):
        proc = washbench("send", src, "--to", "127.0.0.1:9", "--format", "washbench", "--speed", speed, timeout=60)
        assert_clean_error(proc, "--speed")


def test_a_plugin_blocking_in_step_does_not_make_live_deaf(tmp_path: Path) -> None:
    """SIGTERM while a plugin's step() blocks: live stops at once (143), the samples cued so far saved."""
    plugin = plugin_file(tmp_path, step="time.sleep(600)", after=50)
    port = free_udp_port()
    out = tmp_path / "live"
    proc = subprocess.Popen(
        [sys.executable, "-m", "washbench", "live", "--listen", f"127.0.0.1:{port}", "--format", "washbench",
         "--out", str(out), "--no-viewer", "--no-recording", "--no-figures", "--washout-plugin", f"{plugin}:P",
         "--washout", "p"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    try:
        _send_samples(port, "washbench", motion(120))()
        time.sleep(1.0)
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=30)
    finally:
        proc.kill()
    assert proc.returncode == 143, err
    assert "Traceback" not in err and "while the washouts were computing" in err, err
    assert saved(out).shape[0] >= 2


# ------------------------------------------------------------------------------------------ the rest


def test_two_samples_give_no_npc_not_inf() -> None:
    """Two points always correlate by exactly -1 or +1: NPC is undefined (nan, an empty CSV field), not inf."""
    from washbench.analysis.metrics import dof_metrics

    a = np.array([[1.0, 0.0, -9.8], [-1.0, 0.5, -9.0]])
    s = -a  # anti-correlated in every axis
    w = np.array([[0.1, 0.0, 0.2], [-0.1, 0.3, 0.0]])
    rows = dof_metrics("x", a, w, s, -w, 0.01)
    assert all(math.isnan(r.npc) for r in rows)
    assert rows[0].integral_error == pytest.approx(0.01 * (2 + 2) / 2)  # the trapezoid of |a - s| = 2, 2
    three = np.vstack([a, [[0.5, 0.1, -9.5]]])
    w3 = np.vstack([w, [[0.0, 0.1, 0.1]]])
    assert dof_metrics("x", three, w3, -three, -w3, 0.01)[0].npc == math.inf  # 3 samples: the documented limit


def test_the_wrote_line_shows_escapes_not_raw(tmp_path: Path) -> None:
    out = tmp_path / "a\x1b[2Jb.csv"
    proc = washbench("signal", "step", "--axis", "f_y", "--amplitude", "1", "--duration-s", "1", "--out", out)
    assert proc.returncode == 0, proc.stderr
    assert "\x1b" not in proc.stdout and "a\\x1b[2Jb.csv" in proc.stdout


@pytest.fixture(scope="module")
def small_suite(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("suite")
    out = root / "out"
    proc = washbench("suite", short(root, "brief", 1), "--jobs", "1", "--washout", "large-angle", "--out", out,
                     "--no-recording", timeout=240)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    return out


def _copy(src: Path, dest: Path) -> Path:
    subprocess.run(["cp", "-a", str(src), str(dest)], check=True)
    return dest


def _files(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def test_report_refuses_a_figures_link_before_rewriting_anything(small_suite: Path, tmp_path: Path) -> None:
    out = _copy(small_suite, tmp_path / "suite")
    victim = tmp_path / "victim"
    victim.mkdir()
    (out / "figures").rename(tmp_path / "moved")
    (out / "figures").symlink_to(victim, target_is_directory=True)
    before = _files(out / "c172p")
    proc = washbench("report", out, timeout=120)
    assert_clean_error(proc, "figures", "symbolic link")
    assert _files(out / "c172p") == before  # the run's report and figures were rewritten before the refusal
    assert list(victim.iterdir()) == []


@pytest.mark.parametrize(
    ("ranking", "expected"),
    [
        ({"by": "bogus"}, "provenance.ranking.by"),
        ({"by": "weighted", "dof_weights": {"surge": 0}}, "needs dof_weights"),
        ({"by": "score", "dof_weights": {"surge": -1}}, "surge: expected a finite number"),
        ({"by": "score", "tie_relative": "x"}, "provenance.ranking.tie_relative"),
    ],
)
def test_report_checks_the_ranking_rule_recorded_in_run_json(
    small_suite: Path, tmp_path: Path, ranking: dict, expected: str
) -> None:
    import json

    out = _copy(small_suite / "c172p" / "brief", tmp_path / "run")
    doc = json.loads((out / "run.json").read_text())
    doc["provenance"]["ranking"] = ranking
    (out / "run.json").write_text(json.dumps(doc))
    before = _files(out)
    assert_clean_error(washbench("report", out, timeout=120), "run.json", expected)
    assert _files(out) == before


def test_readback_knows_every_ranking_rule_and_dof() -> None:
    from washbench.analysis.ranking import DOFS, RANK_BY
    from washbench.io.readback import RANK_DOFS, RANK_RULES

    assert RANK_RULES == RANK_BY and RANK_DOFS == DOFS


# solvers' effort ---------------------------------------------------------------------------------


def test_mpc_effort_is_capped_in_the_parameter_file(tmp_path: Path) -> None:
    """iter_limit 1,000,000 and a 500-step horizon with 50,000: one line naming the file, the line and the key
    (before: accepted, no end within minutes)."""
    from washbench.io.paths import DATA_DIR

    base = (DATA_DIR / "cw1.yaml").read_text()
    cases = {
        "solver: {iter_limit: 1000000}": "mpc.solver.iter_limit",
        "horizon_steps: 500\n  solver: {iter_limit: 50000}": "500 x solver.iter_limit 50000 = 25,000,000",
    }
    for i, (section, expected) in enumerate(cases.items()):
        params = tmp_path / f"p{i}.yaml"
        params.write_text(base + f"mpc:\n  {section}\n")
        with pytest.raises(WashbenchError, match=re.escape(expected)) as err:
            load_options(params_path=params, washouts=["mpc"])
        assert str(params) in str(err.value)


def test_a_slow_mpc_says_how_long_a_minute_of_flight_takes(monkeypatch: pytest.MonkeyPatch,
                                                          capsys: pytest.CaptureFixture[str]) -> None:  # fmt: skip
    from washbench.cueing import mpc
    from washbench.cueing.algorithm import WashoutContext

    monkeypatch.setattr(mpc, "SLOW_FACTOR", 0.0)  # any speed counts as slow: the message is what is tested
    limits = load_options().limits
    algo = mpc.MpcWashout(None, WashoutContext(DT, 9.80665, limits, "steady", (0.0, 0.0, 0.0)))
    f, w = np.array([0.1, 0.0, -9.80665]), np.zeros(3)
    algo.start(f, w)
    a = [algo.step(f, w) for _ in range(mpc.ESTIMATE_AFTER_STEPS + 5)]
    err = capsys.readouterr().err
    # (round four: with SLOW_FACTOR 0 the model's note when the washout is made speaks too; the timed one, once)
    assert err.count("(timed on 20 after the first): a minute of flight takes about") == 1, err
    monkeypatch.setattr(mpc, "SLOW_FACTOR", 10.0)
    algo2 = mpc.MpcWashout(None, WashoutContext(DT, 9.80665, limits, "steady", (0.0, 0.0, 0.0)))
    algo2.start(f, w)
    b = [algo2.step(f, w) for _ in range(mpc.ESTIMATE_AFTER_STEPS + 5)]
    for (p1, q1), (p2, q2) in zip(a, b, strict=True):  # the timing changes no set point
        assert np.array_equal(p1, p2) and np.array_equal(q1, q2)


def test_omct_with_the_bound_estimates_its_time_and_caps_its_runs(capsys: pytest.CaptureFixture[str],
                                                                  monkeypatch: pytest.MonkeyPatch) -> None:  # fmt: skip
    """(Round four: the estimate is the cost model's, :mod:`washbench.io.cost`, not a timing run, announced when
    long; the cap is the memory the runs need, not a count of samples.)"""
    from washbench.analysis import omct
    from washbench.cueing.variants import select_washouts
    from washbench.io import cost
    from washbench.runs import omct as omct_run

    monkeypatch.setattr(cost, "LONG_S", -1.0)  # any estimate is long: the message is what is tested

    entries = select_washouts(["bound", "small-angle"], (), None)
    limits = load_options().limits
    sigma = omct_run.slowest_decay(entries)
    omct_run._estimate(entries, limits, omct.TESTS[:2], omct.FREQUENCIES_RADPS[:3], 120.0, sigma)
    err = capsys.readouterr().err
    assert re.search(r"washbench: note: omct: washout bound: 6 runs, [\d,]+ samples in all: about [\d hmins]+ and "
                     r"[\d.]+ [MG]B at the peak", err), err  # fmt: skip
    with pytest.raises(WashbenchError, match=r"omct: washout bound: 1 runs, [\d,]+ samples in all: about [\d.]+ GB at "
                                             r"the peak .* more than the .* this process may still take"):  # fmt: skip
        omct_run._estimate(entries, limits, omct.TESTS[:1], omct.FREQUENCIES_RADPS[:1], 1e5, sigma)


# determinism on a cluster ------------------------------------------------------------------------

MSDV_SCRIPT = """
import numpy as np
from washbench.perception.sickness import msdv
print(" ".join(msdv(np.random.default_rng(seed).standard_normal(100_003) * 0.3, 1 / 120).hex() for seed in range(20)))
"""


def test_msdv_is_the_same_bits_whatever_blas_threads_the_process_has() -> None:
    """A Dask worker runs BLAS on one thread (its nanny sets OPENBLAS_NUM_THREADS=1), a local run on every core:
    np.dot's split by threads changed the MSDV's last bit (7 of these 20 differed); the sum is now in sample order.
    Checked against math.fsum (correctly rounded) too."""
    got = {}
    for threads in ("1", "2"):
        env = {**os.environ, "OPENBLAS_NUM_THREADS": threads, "OMP_NUM_THREADS": threads}
        proc = subprocess.run([sys.executable, "-c", MSDV_SCRIPT], capture_output=True, text=True, env=env,
                              timeout=120)  # fmt: skip
        assert proc.returncode == 0, proc.stderr
        got[threads] = proc.stdout.split()
    assert got["1"] == got["2"] and len(got["1"]) == 20
    from washbench.perception.sickness import wf_weighted

    for seed, value in enumerate(got["1"][:3]):
        aw = wf_weighted(np.random.default_rng(seed).standard_normal(100_003) * 0.3, 1 / 120)
        exact = math.sqrt(math.fsum((aw * aw).tolist()) / 120)
        assert float.fromhex(value) == pytest.approx(exact, rel=1e-13)
