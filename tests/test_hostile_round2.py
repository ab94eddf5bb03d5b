"""Hardening, second round (issue 25): every command owns, locks, builds and publishes its --out the same way.

Each test drives the real command in a subprocess under a time limit and checks the exit status, the one line
naming the file, no traceback, a canary folder beside --out untouched, links inside --out not followed, no mixed
result set after a signal, nothing left by a killed run after the next one, and no process left.
"""

from __future__ import annotations

import gzip
import hashlib
import json
import os
import resource
import signal
import socket
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest
from hostile import REPLACING_NOTE, assert_clean_error, live_processes, long_suite, short, tree, washbench

from washbench.analysis.signals import SignalSpec, generate
from washbench.io.motion_file import write_motion
from washbench.io.outfolder import JOURNAL_PREFIX, MANIFEST, OLD_PREFIX, STAGE_PREFIX, recover
from washbench.io.paths import MANOEUVRES_DIR

JSBSIM_C172X = "c172x"


def motion_csv(path: Path, seconds: float = 2.0, rate_hz: float = 50.0) -> Path:
    sig = generate(SignalSpec("sine", "f_x", 1.0, 0.5, seconds, rate_hz, 0.0))
    write_motion(path, sig.t_s, sig.f_mps2, sig.omega_radps)
    return path


def digest(folder: Path) -> dict[str, str]:
    """Every file under ``folder`` (hidden ones too) -> SHA-256 of its bytes; links as ``link:TARGET``."""
    out = {}
    for p in sorted(folder.rglob("*")):
        rel = str(p.relative_to(folder))
        if p.is_symlink():
            out[rel] = f"link:{os.readlink(p)}"
        elif p.is_file():
            out[rel] = hashlib.sha256(p.read_bytes()).hexdigest()
    return out


def canary(root: Path) -> tuple[Path, dict[str, str]]:
    """A folder beside --out with a file a hostile link points at; returns it and its digest."""
    c = root / "canary"
    c.mkdir()
    (c / "victim.txt").write_text("the user's own file\n")
    (c / "perceived.pdf").write_text("the user's figure\n")
    return c, digest(c)


@pytest.fixture(scope="module")
def motion(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return motion_csv(tmp_path_factory.mktemp("motion") / "motion.csv")


@pytest.fixture(scope="module")
def cued(motion: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """One complete cue result set (figures and recording), copied by the tests that need a previous set."""
    out = tmp_path_factory.mktemp("cued") / "out"
    proc = washbench("cue", motion, "--out", out, timeout=120)
    assert proc.returncode == 0, proc.stderr
    return out


def copy_of(folder: Path, dest: Path) -> Path:
    subprocess.run(["cp", "-a", str(folder), str(dest)], check=True)
    return dest


# ------------------------------------------------------------------------------------------ the lock, links


def test_a_link_planted_as_the_lock_is_refused_never_truncated(motion: Path, tmp_path: Path) -> None:
    """cue, fly, run, suite, omct, sweep, report: OUT/.washbench.lock -> a user's file: one line, file untouched."""
    victims, before = canary(tmp_path)
    m = short(tmp_path)
    commands = {
        "cue": ("cue", motion),
        "fly": ("fly", m),
        "run": ("run", m),
        "suite": ("suite", m),
        "omct": ("omct",),
        "sweep": ("sweep", m, "--set", "tilt.gain_per_s=1,2", "--quiet"),
        "report": ("report",),
    }

    def one(item: tuple[str, tuple[object, ...]]) -> tuple[subprocess.CompletedProcess[str], Path]:
        name, args = item
        out = tmp_path / f"out_{name}"
        out.mkdir()
        (out / ".washbench.lock").symlink_to(victims / "victim.txt")
        where = (out,) if name == "report" else ("--out", out)
        return washbench(*args, *where, timeout=90), out

    with ThreadPoolExecutor(2) as pool:
        for proc, out in pool.map(one, commands.items()):
            assert_clean_error(proc, ".washbench.lock", "symbolic link")
            assert tree(out) == [".washbench.lock"]
    assert digest(victims) == before


def test_links_inside_out_are_never_followed_when_replacing(cued: Path, motion: Path, tmp_path: Path) -> None:
    """cue into its own previous set whose figures/ became a link: refused before any work, target untouched."""
    victims, before = canary(tmp_path)
    out = copy_of(cued, tmp_path / "out")
    (out / "figures").rename(tmp_path / "moved")
    (out / "figures").symlink_to(victims, target_is_directory=True)
    set_before = digest(out)
    proc = washbench("cue", motion, "--out", out, timeout=60)
    assert_clean_error(proc, str(out / "figures"), "symbolic link")
    assert digest(victims) == before and digest(out) == set_before
    proc = washbench("report", out, timeout=60)  # report: the same refusal, nothing written through the link
    assert_clean_error(proc, str(out / "figures"), "symbolic link")
    assert digest(victims) == before and digest(out) == set_before


def test_report_never_leaves_the_suite_folder(cued: Path, tmp_path: Path) -> None:
    """A suite.json result entry climbing out, absolute, or through a link: one line, nothing read or written."""
    victims, before = canary(tmp_path)
    copy_of(cued, victims / "res")
    before = digest(victims)
    suite = tmp_path / "suite"
    suite.mkdir()
    copy_of(cued, suite / "inside")
    for result in ("../canary/res", str(victims / "res"), "linked"):
        (suite / "linked").unlink(missing_ok=True)
        (suite / "linked").symlink_to(victims / "res", target_is_directory=True)
        doc = {"washbench": "suite", "manoeuvres": [{"file": "x.yaml", "ok": True, "result": result}]}
        (suite / "suite.json").write_text(json.dumps(doc))
        proc = washbench("report", suite, timeout=60)
        assert_clean_error(proc, "suite.json", repr(result))
        assert digest(victims) == before


def test_examples_never_write_through_a_link(tmp_path: Path) -> None:
    victims, before = canary(tmp_path)
    dest = tmp_path / "proj"
    dest.mkdir()
    (dest / "manoeuvres").symlink_to(victims, target_is_directory=True)
    proc = washbench("examples", dest, timeout=30)
    assert_clean_error(proc, str(dest / "manoeuvres"), "already exists")
    assert digest(victims) == before and tree(dest) == ["manoeuvres"]
    (dest / "manoeuvres").unlink()
    assert washbench("examples", dest, timeout=30).returncode == 0
    assert washbench("examples", dest, timeout=30).returncode == 2  # never overwrites
    assert not any(n.startswith(".") for n in os.listdir(dest))


# ------------------------------------------------------------------------------------------ whose folder


def test_a_folder_holding_a_users_file_is_refused_by_every_command(motion: Path, tmp_path: Path) -> None:
    """cue, fly, sweep, tune, omct: a file of the same name as a result, written by the user, is never replaced."""
    m = short(tmp_path)
    commands = {
        "cue": (("cue", motion), "report.md"),
        "fly": (("fly", m), "flight.json"),
        "sweep": (("sweep", m, "--set", "tilt.gain_per_s=1,2", "--quiet"), "sweep.csv"),
        "tune": (
            ("tune", m, "--washout", "small-angle", "--tune", "tilt.gain_per_s=1:2", "--budget", "6"),
            "tuned.yaml",
        ),
        "omct": (("omct",), "report.md"),
    }

    def one(item: tuple[str, tuple[tuple[object, ...], str]]) -> tuple[str, subprocess.CompletedProcess[str], Path]:
        name, (args, mine) = item
        out = tmp_path / f"out_{name}"
        out.mkdir()
        (out / mine).write_text("the user's own notes\n")
        return name, washbench(*args, "--out", out, timeout=60), out / mine

    with ThreadPoolExecutor(2) as pool:
        for _, proc, mine in pool.map(one, commands.items()):
            assert_clean_error(proc, str(mine), "washbench did not write this")
            assert mine.read_text() == "the user's own notes\n"
            assert tree(mine.parent) == [mine.name]



def test_a_users_folder_inside_out_keeps_its_hidden_files(cued: Path, motion: Path, tmp_path: Path) -> None:
    """A folder of the user's put into a cue result folder holds files named like washbench's leftovers
    (``.notes.tmp``, ``.draft.partial-12``): the cue is refused naming the folder, and they are all still there
    (the leftover cleaning went one level down into every folder before the refusal)."""
    out = copy_of(cued, tmp_path / "out")
    mine = out / "mine"
    mine.mkdir()
    (mine / ".notes.tmp").write_text("the user's notes\n")
    (mine / ".draft.partial-12").mkdir()
    (mine / ".draft.partial-12" / "draft.md").write_text("a draft\n")
    before = digest(out)
    proc = washbench("cue", motion, "--out", out, "--no-figures", timeout=60)
    assert_clean_error(proc, str(mine))
    assert digest(out) == before

def test_a_second_cue_replaces_the_whole_previous_set(motion: Path, tmp_path: Path) -> None:
    """Two segments, then one: the old second segment does not stay beside the new result."""
    two = tmp_path / "two.csv"
    lines = motion.read_text().splitlines()
    two.write_text("\n".join([*lines, *lines[1:]]) + "\n")  # a time reset: two segments
    out = tmp_path / "out"
    assert washbench("cue", two, "--out", out, "--no-figures", "--no-recording", timeout=60).returncode == 0
    assert (out / "segment_2").is_dir()
    assert washbench("cue", motion, "--out", out, "--no-figures", "--no-recording", timeout=60).returncode == 0
    assert not (out / "segment_1").exists() and not (out / "segment_2").exists()
    assert json.loads((out / MANIFEST).read_text())["entries"] == sorted(p for p in os.listdir(out) if p[0] != ".")


def test_empty_out_and_non_utf8_paths_are_one_line(motion: Path, tmp_path: Path) -> None:
    for command in (("cue", motion), ("run", "c172/takeoff"), ("sweep", "c172", "--set", "a.b=1"), ("omct",)):
        proc = washbench(*command, "--out", "", timeout=30)
        assert proc.returncode == 2 and "Traceback" not in proc.stderr and "empty path" in proc.stderr
    bad = os.fsdecode(bytes(tmp_path) + b"/r\xe9sultats")
    proc = subprocess.run(
        [sys.executable, "-m", "washbench", "cue", str(motion), "--out", bad], capture_output=True, timeout=30
    )
    assert proc.returncode == 2 and b"Traceback" not in proc.stderr and b"not valid UTF-8" in proc.stderr
    assert b"\\xe9" in proc.stderr and len(proc.stderr.splitlines()) == 1
    assert tree(tmp_path) == []


# ------------------------------------------------------------------------------------------ JSBSim's own output

HOSTILE_SCRIPT = """<?xml version="1.0"?>
<runscript name="hostile">
  <use aircraft="c172x" initialize="reset01"/>
  <output name="../canary/climbed.csv" type="CSV" rate="10"/>
  <output name="{victim}" type="CSV" rate="10"/>
  <output name="localhost" type="SOCKET" protocol="TCP" port="{port}" rate="10"/>
  <output name="localhost" type="SOCKET" protocol="UDP" port="{port}" rate="10"/>
  <run start="0" end="0.5" dt="0.0083333"/>
</runscript>
"""


def test_jsbsim_output_directives_write_nothing_and_open_no_socket(tmp_path: Path) -> None:
    victims, before = canary(tmp_path)
    listener = socket.socket()
    listener.bind(("127.0.0.1", 0))
    listener.listen(1)
    listener.setblocking(False)
    udp = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    port = listener.getsockname()[1]
    udp.bind(("127.0.0.1", port))
    udp.setblocking(False)
    work = tmp_path / "work"
    work.mkdir()
    script = work / "hostile.xml"
    script.write_text(HOSTILE_SCRIPT.format(victim=victims / "victim.txt", port=port))
    proc = washbench(
        "run", script, "--out", work / "out", "--no-recording", "--no-figures", "--quiet", timeout=90, cwd=work
    )
    assert proc.returncode == 0, proc.stderr
    assert "Traceback" not in proc.stderr
    assert f"{script}: 4 JSBSim <output> directive(s) switched off" in proc.stderr
    assert digest(victims) == before
    assert not list(tmp_path.rglob("*.csv")) or all("out" in p.parts for p in tmp_path.rglob("*.csv"))
    with pytest.raises(BlockingIOError):
        listener.accept()
    with pytest.raises(BlockingIOError):
        udp.recv(1)
    listener.close()
    udp.close()


def test_a_users_aircraft_with_outputs_or_bad_xml(tmp_path: Path) -> None:
    """A user aircraft's <output> is switched off (said once); malformed, empty, billion-laughs XML: one line."""
    from washbench.io.paths import jsbsim_root

    victims, before = canary(tmp_path)
    src = jsbsim_root() / "aircraft" / "c172p"
    acdir = tmp_path / "aircraft"
    acdir.mkdir()
    copy_of(src, acdir / "c172p")
    model = acdir / "c172p" / "c172p.xml"
    text = model.read_text()
    model.write_text(
        text.replace("</fdm_config>", f'<output name="{victims / "victim.txt"}" type="CSV" rate="1"/></fdm_config>')
    )
    m = short(tmp_path)
    proc = washbench("fly", m, "--out", tmp_path / "out", "--aircraft-dir", acdir, "--quiet", timeout=90)
    assert proc.returncode == 0, proc.stderr
    assert f"{model}: 1 JSBSim <output> directive(s) switched off" in proc.stderr
    assert digest(victims) == before
    bombs = {
        "malformed": "<fdm_config><unclosed></fdm_config>",
        "empty": "",
        "laughs": '<?xml version="1.0"?><!DOCTYPE l [<!ENTITY a "lol"><!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;">]>'
        "<fdm_config>&b;</fdm_config>",
        "external": '<?xml version="1.0"?><!DOCTYPE l [<!ENTITY x SYSTEM "file:///etc/passwd">]><fdm_config>&x;'
        "</fdm_config>",
    }
    for what, xml in bombs.items():
        model.write_text(xml)
        proc = washbench("fly", m, "--out", tmp_path / f"o_{what}", "--aircraft-dir", acdir, timeout=60)
        assert_clean_error(proc, str(model))
        assert not (tmp_path / f"o_{what}").exists()



def test_jsbsim_state_files_never_land_outside_out(tmp_path: Path) -> None:
    """JSBSim writes ``initfile.T.xml`` into its output path (its own installation unless set) whenever
    ``simulation/write-state-file`` is written: a manoeuvre asking for it is refused in one line; an aircraft whose
    flight controls write it flies, and no such file appears in JSBSim's folder, the current folder or --out."""
    from washbench.io.paths import jsbsim_root

    def state_files() -> list[Path]:
        return [*jsbsim_root().glob("initfile*"), *tmp_path.rglob("initfile*")]

    before = state_files()
    m = short(tmp_path, name="wsf", seconds=0.2)
    wsf = "    inputs:\n      properties:\n        - {property: simulation/write-state-file, fixed: 1}\n"
    m.write_text(m.read_text().replace("    until:", wsf + "    until:"))
    proc = washbench("fly", m, "--out", tmp_path / "o1", "--quiet", timeout=60, cwd=tmp_path)
    assert_clean_error(proc, str(m), "simulation/write-state-file", "properties[0].property")
    assert not (tmp_path / "o1").exists()

    acdir = tmp_path / "aircraft"
    acdir.mkdir()
    copy_of(jsbsim_root() / "aircraft" / "c172p", acdir / "c172p")
    model = acdir / "c172p" / "c172p.xml"
    model.write_text(model.read_text().replace("</fdm_config>", (
        '<system name="w"><channel name="w"><fcs_function name="w/state"><function><value>1</value></function>'
        "<output>simulation/write-state-file</output></fcs_function></channel></system></fdm_config>")))  # fmt: skip
    proc = washbench("fly", short(tmp_path, seconds=0.2), "--out", tmp_path / "o2", "--aircraft-dir", acdir,
                     "--quiet", timeout=60, cwd=tmp_path)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert (tmp_path / "o2" / "flight.parquet").is_file()
    assert state_files() == before


# ------------------------------------------------------------------------------------------ full disk, signals


def _file_size_limit(limit: int):  # a preexec_fn
    def apply() -> None:
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # writes beyond the limit fail with EFBIG, like a full disk
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

    return apply


def test_a_recording_that_cannot_be_written_is_one_line_not_a_hang(cued: Path, motion: Path, tmp_path: Path) -> None:
    out = copy_of(cued, tmp_path / "out")
    before = digest(out)
    rrd = (out / "recording.rrd").stat().st_size
    traces = (out / "traces.parquet").stat().st_size
    assert rrd > traces  # the limit lets the traces through and stops the recording
    proc = subprocess.run(
        [sys.executable, "-m", "washbench", "cue", str(motion), "--out", str(out), "--no-figures"],
        capture_output=True,
        text=True,
        timeout=60,
        preexec_fn=_file_size_limit((rrd + traces) // 2),
    )
    assert_clean_error(proc, str(out / "recording.rrd"))
    assert "ERROR" not in proc.stderr and "WARN" not in proc.stderr  # no rerun SDK log lines
    assert digest(out) == before  # the previous set stands, whole



def test_a_disk_too_full_for_the_lock_names_the_folder(motion: Path, tmp_path: Path) -> None:
    """A disk so full that the folder and an empty probe file can be made but not one byte written (the lock's
    PID): one line naming the folder and the lock, not a bare 'No space left on device'; no folder left behind."""
    out = tmp_path / "out"
    proc = subprocess.run(
        [sys.executable, "-m", "washbench", "cue", str(motion), "--out", str(out), "--no-figures"],
        capture_output=True,
        text=True,
        timeout=60,
        preexec_fn=_file_size_limit(0),
    )
    assert_clean_error(proc, f"{out}: cannot write the lock .washbench.lock")
    assert not out.exists()


FINALIZER_SIGNAL = """
import os, signal, sys, time
from washbench.errors import Terminated
from washbench.io import interrupts

signal.signal(signal.SIGTERM, interrupts.terminate)
sys.unraisablehook = interrupts.signal_in_finalizer


class Stream:  # as the rerun SDK's RecordingStream: work done in __del__
    def __del__(self):
        os.kill(os.getpid(), signal.SIGTERM)
        t = time.monotonic()
        while time.monotonic() - t < 0.2:  # the handler runs in here, its exception is swallowed
            pass


try:
    Stream()
    t = time.monotonic()
    while time.monotonic() - t < 25:  # the signal sent again ends this at once; a loaded machine may delay it
        pass
    print("not signalled")
except Terminated:
    print("terminated in the command")
"""


def test_a_signal_raised_inside_a_finalizer_still_stops_the_command(tmp_path: Path) -> None:
    """A SIGTERM (or Ctrl-C) whose handler runs inside a ``__del__`` is swallowed by Python ("Exception ignored
    in ..."): the command went on and published (seen with ``run`` signalled as its recording.rrd landed, as the
    rerun SDK's RecordingStream was finalized). The signal is sent again and stops the command itself."""
    proc = subprocess.run([sys.executable, "-c", FINALIZER_SIGNAL], capture_output=True, text=True, timeout=60)
    assert proc.stdout.strip() == "terminated in the command", (proc.stdout, proc.stderr)
    assert "Exception ignored" not in proc.stderr and "Traceback" not in proc.stderr, proc.stderr


SIGNAL_WHILE_THE_CLI_LOADS = """
import os, signal, sys, time

sys.argv = ["washbench", "validate", sys.argv[1]]
from washbench import __main__ as console


class Stream:  # work in a finalizer while washbench.cli is imported, as importlib's module-lock weakref callbacks do
    def __del__(self):
        os.kill(os.getpid(), signal.SIGINT)
        t = time.monotonic()
        while time.monotonic() - t < 0.2:  # the handler runs in here, its KeyboardInterrupt is swallowed
            pass


class Finder:
    def find_spec(self, name, path=None, target=None):
        if name == "washbench.cli":
            sys.meta_path.remove(self)
            Stream()
        return None


sys.meta_path.insert(0, Finder())
sys.exit(console.entry())
"""


def test_a_ctrl_c_swallowed_while_the_cli_loads_still_stops_the_command(tmp_path: Path) -> None:
    """A Ctrl-C in the first fraction of a second, raised inside a finalizer while ``washbench.cli`` is imported,
    was swallowed ("Exception ignored") and the command ran to its end with status 0: the console entry installs
    the hook that sends it again before importing the CLI, so it ends the command (one line, 130)."""
    manoeuvre = str(MANOEUVRES_DIR / "c172" / "takeoff.yaml")
    proc = subprocess.run([sys.executable, "-c", SIGNAL_WHILE_THE_CLI_LOADS, manoeuvre], capture_output=True,
                          text=True, timeout=60)  # fmt: skip
    assert proc.returncode == 130, (proc.returncode, proc.stdout, proc.stderr)
    assert proc.stderr.strip() == "washbench: interrupted" and proc.stdout == "", (proc.stdout, proc.stderr)


SIGNAL_AS_AN_EXTENSION_LOADS = """
import os, signal, sys

sys.argv = ["washbench", "validate", sys.argv[1]]
from washbench import __main__ as console


class Finder:  # a Ctrl-C while pydantic-core (Rust, pyo3) initialises: it imports datetime then
    def find_spec(self, name, path=None, target=None):
        if name == "datetime":
            sys.meta_path.remove(self)
            os.kill(os.getpid(), signal.SIGINT)
        return None


assert "datetime" not in sys.modules
sys.meta_path.insert(0, Finder())
sys.exit(console.entry())
"""


def test_a_ctrl_c_while_an_extension_module_initialises_is_one_line(tmp_path: Path) -> None:
    """A Ctrl-C that lands inside an extension module's initialisation while the CLI loads (pydantic-core importing
    datetime) made pyo3 panic: a Rust backtrace, a Python traceback and status 1. It is held back until the CLI has
    loaded, then ends the command (one line, 130)."""
    manoeuvre = str(MANOEUVRES_DIR / "c172" / "takeoff.yaml")
    proc = subprocess.run([sys.executable, "-c", SIGNAL_AS_AN_EXTENSION_LOADS, manoeuvre], capture_output=True,
                          text=True, timeout=60)  # fmt: skip
    assert proc.returncode == 130, (proc.returncode, proc.stdout, proc.stderr)
    assert proc.stderr.strip() == "washbench: interrupted" and proc.stdout == "", (proc.stdout, proc.stderr)


@pytest.mark.slow
def test_run_signalled_as_its_recording_lands_keeps_the_previous_result(tmp_path: Path) -> None:
    """The real case (timing-dependent, so twice per signal): the previous result folder stays, one line, no
    traceback, status 130/143."""
    m = short(tmp_path, seconds=1)
    out = tmp_path / "out"
    args = [sys.executable, "-m", "washbench", "run", str(m), "--washout", "small-angle", "--quiet", "--out", str(out)]
    subprocess.run(args, check=True, capture_output=True, timeout=120)
    result = out / "c172p" / "short"
    before = digest(result)
    for sig, status in ((signal.SIGTERM, 143), (signal.SIGINT, 130), (signal.SIGTERM, 143), (signal.SIGINT, 130)):
        proc = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        deadline = time.monotonic() + 120
        while proc.poll() is None and time.monotonic() < deadline:
            if any((out / "c172p").glob(STAGE_PREFIX + "*/short/recording.rrd")):
                proc.send_signal(sig)
                break
            time.sleep(0.002)
        _, err = proc.communicate(timeout=120)
        assert proc.returncode == status, (sig, proc.returncode, err)
        said = [ln for ln in err.strip().splitlines() if not REPLACING_NOTE.match(ln)]  # (the rerun says it replaces)
        assert "Traceback" not in err and len(said) == 1, err
        assert digest(result) == before


def test_run_and_suite_on_a_full_disk_name_the_published_file(tmp_path: Path) -> None:
    """``run`` and ``suite`` build in hidden stage folders: a recording that cannot be written is named where
    it was going (``OUT/c172p/short/recording.rrd``), never in ``.washbench-stage-PID``, in the error line and in
    the suite's published failure reason."""
    m = short(tmp_path, seconds=1)
    common = ["--washout", "small-angle", "--quiet", "--no-figures"]
    limit = _file_size_limit(300_000)  # the traces (~80 kB) pass, the recording (~700 kB) does not
    out = tmp_path / "run"
    proc = subprocess.run([sys.executable, "-m", "washbench", "run", str(m), "--out", str(out), *common],
                          capture_output=True, text=True, timeout=120, preexec_fn=limit)  # fmt: skip
    assert_clean_error(proc, f"{out / 'c172p' / 'short' / 'recording.rrd'}: cannot write")
    assert "partial" not in proc.stderr and STAGE_PREFIX not in proc.stderr
    out = tmp_path / "suite"
    proc = subprocess.run([sys.executable, "-m", "washbench", "suite", str(m), "--out", str(out), "--jobs", "1",
                           *common], capture_output=True, text=True, timeout=120, preexec_fn=limit)  # fmt: skip
    assert proc.returncode == 1, proc.stderr
    reasons = [e["reason"] for e in json.loads((out / "suite.json").read_text())["manoeuvres"]]
    assert reasons == [f"{out / 'c172p' / 'short' / 'recording.rrd'}: cannot write: File too large"], reasons

def _stage_names(out: Path) -> set[str]:
    return {f"{s.name}/{p.name}" for s in out.glob(STAGE_PREFIX + "*") for p in s.iterdir()}


@pytest.mark.slow
def test_a_signal_whenever_a_file_lands_leaves_the_previous_set_whole(cued: Path, motion: Path, tmp_path: Path) -> None:
    """cue over its previous set, signalled (SIGINT, SIGTERM in turn) as the n-th new file lands in the stage, for
    n = 1, 2, ... until the run completes first: the folder then holds exactly the previous set (or, had the
    signal come during the swap, exactly the new one), and no stage, old folder or journal."""
    base = copy_of(cued, tmp_path / "base")
    expected = digest(base)
    expected.pop(MANIFEST, None)
    n, completed = 1, False
    while not completed and n <= 6:
        sig = (signal.SIGINT, signal.SIGTERM)[n % 2]
        out = copy_of(base, tmp_path / f"out{n}")
        proc = subprocess.Popen(
            [sys.executable, "-m", "washbench", "cue", str(motion), "--out", str(out)],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        landed: set[str] = set()
        while proc.poll() is None and len(landed) < n:
            landed |= _stage_names(out)
            time.sleep(0.002)
        if proc.poll() is None:
            proc.send_signal(sig)
        _, err = proc.communicate(timeout=60)
        completed = proc.returncode == 0
        assert "Traceback" not in err, err
        after = digest(out)
        after.pop(MANIFEST, None)
        if completed:  # the set was complete before the signal: the new one, whole
            assert set(after) == set(expected)
        else:
            assert proc.returncode in (130, 143), err
            assert after == expected, (n, sorted(set(after) ^ set(expected)))
        assert not [p for p in os.listdir(out) if p.startswith((STAGE_PREFIX, OLD_PREFIX, JOURNAL_PREFIX))]
        n += 1
    assert n > 2  # at least one run was signalled mid-way


def test_what_a_killed_run_leaves_goes_with_the_next_run(cued: Path, motion: Path, tmp_path: Path) -> None:
    out = copy_of(cued, tmp_path / "out")
    proc = subprocess.Popen(
        [sys.executable, "-m", "washbench", "cue", str(motion), "--out", str(out)],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    deadline = time.monotonic() + 60
    while not _stage_names(out) and time.monotonic() < deadline:
        time.sleep(0.005)
    proc.kill()
    proc.wait()
    (out / ".traces.parquet.k1ll3d00.tmp").write_bytes(b"x" * 1000)  # what atomic_path leaves when killed
    (out / "figures" / ".perceived.png.abcdefgh.tmp").write_bytes(b"x")
    leftovers = [p for p in tree(out) if p.split("/")[-1].startswith(".") and p != MANIFEST]
    assert any(STAGE_PREFIX in p for p in leftovers) and len(leftovers) >= 3
    assert washbench("cue", motion, "--out", out, "--no-figures", timeout=60).returncode == 0
    assert [p for p in tree(out) if p.split("/")[-1].startswith(".")] == [MANIFEST]


def test_a_publication_cut_by_a_kill_is_finished_by_the_next_run(tmp_path: Path) -> None:
    """The journal of a swap killed halfway: the next recover() completes it (never a mix of old and new)."""
    out = tmp_path / "out"
    stage = out / f"{STAGE_PREFIX}999999"
    old = out / f"{OLD_PREFIX}999999"
    for d in (stage, old):
        d.mkdir(parents=True)
    (old / "a.csv").write_text("old a")  # moved aside already
    (out / "b.csv").write_text("old b")  # not yet moved
    (out / "c.csv").write_text("new c")  # new, already moved in
    (stage / "a.csv").write_text("new a")  # new, not yet moved
    (out / "gone.csv").write_text("old only")  # old, not in the new set
    doc = {
        "stage": stage.name,
        "old": old.name,
        "previous": ["a.csv", "b.csv", "gone.csv"],
        "new": ["a.csv", "b.csv", "c.csv"],
    }
    (stage / "b.csv").write_text("new b")
    (out / f"{JOURNAL_PREFIX}999999").write_text(json.dumps(doc))
    recover(out)
    assert {p.name: p.read_text() for p in out.iterdir()} == {"a.csv": "new a", "b.csv": "new b", "c.csv": "new c"}


def test_workers_end_when_the_suite_is_killed(tmp_path: Path) -> None:
    proc = long_suite(tmp_path, output=subprocess.DEVNULL)
    out = tmp_path / "out"
    deadline = time.monotonic() + 60
    while len(live_processes(proc.pid)) < 4 and time.monotonic() < deadline:  # main, server, 2 workers
        time.sleep(0.1)
    assert len(live_processes(proc.pid)) >= 4
    from washbench.flight.jsbsim_xml import _SCRATCH_PREFIX

    scratch = tmp_path / "tmp"  # the suite's TMPDIR (hostile.long_suite)

    def killed_scratch() -> list[Path]:
        return [d for d in scratch.glob(f"{_SCRATCH_PREFIX}*") if d.name[len(_SCRATCH_PREFIX) :].split("-")[0] in pids]

    # the workers flying: each has made its JSBSim scratch folder (seconds after it starts on a loaded machine)
    deadline = time.monotonic() + 60
    while True:
        pids = {line.split()[0] for line in live_processes(proc.pid)}
        if len(killed_scratch()) >= 2 or time.monotonic() > deadline:
            break
        time.sleep(0.1)
    assert len(killed_scratch()) >= 2
    time.sleep(0.5)
    proc.kill()
    proc.wait()
    deadline = time.monotonic() + 10
    while (left := live_processes(proc.pid)) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert left == []
    stage = list(out.glob(STAGE_PREFIX + "*"))
    sizes = digest(stage[0]) if stage else {}
    time.sleep(1.0)
    assert (digest(stage[0]) if stage else {}) == sizes  # nobody writes into the stage any more
    # the killed workers' JSBSim scratch folders (no exit handler ran) go with the next process that makes one
    assert len(killed_scratch()) >= 2
    code = "from washbench.flight.jsbsim_xml import scratch_output_dir; scratch_output_dir()"
    subprocess.run([sys.executable, "-c", code], check=True, timeout=60, env={**os.environ, "TMPDIR": str(scratch)})
    assert killed_scratch() == []



def _server_started(pgid: int) -> bool:
    """A process server (forkserver) of process group ``pgid`` exists (it may still be importing)."""
    for line in live_processes(pgid):
        try:
            if b"forkserver" in Path(f"/proc/{line.split()[0]}/cmdline").read_bytes():
                return True
        except OSError:
            continue
    return False


def test_a_suite_killed_while_its_server_starts_leaves_no_process(tmp_path: Path) -> None:
    """Killed while its process server is still importing JSBSim and numba (seconds under load): the server, once
    started, finds its parent gone and ends at once (the parent-death request alone would come too late)."""
    proc = long_suite(tmp_path, output=subprocess.DEVNULL)
    deadline = time.monotonic() + 60
    while not _server_started(proc.pid) and time.monotonic() < deadline:
        time.sleep(0.005)
    assert _server_started(proc.pid)
    proc.kill()
    proc.wait()
    deadline = time.monotonic() + 20
    while (left := live_processes(proc.pid)) and time.monotonic() < deadline:
        time.sleep(0.1)
    for line in left:  # not to leave them to the rest of the session if the assertion fails
        os.kill(int(line.split()[0]), signal.SIGKILL)
    assert left == []


# ------------------------------------------------------------------------------------------ bounds, inputs


@pytest.mark.slow
def test_what_a_command_would_allocate_is_bounded_before_allocating(motion: Path, tmp_path: Path) -> None:
    script = tmp_path / "long.xml"
    script.write_text(
        '<runscript><use aircraft="c172x" initialize="reset01"/><run start="0" end="1e30" dt="0.0083333"/></runscript>'
    )
    bomb = tmp_path / "blank.csv.gz"
    with gzip.open(bomb, "wb", compresslevel=9) as fh:
        fh.write(b"t_s,f_x_mps2,f_y_mps2,f_z_mps2,omega_x_degps,omega_y_degps,omega_z_degps\n")
        fh.write(b"\n" * 30_000_000)
    m = short(tmp_path)
    cases = [
        (("omct", "--rate-hz", "1e8", "--out", tmp_path / "o1"), "--rate-hz"),
        (
            (
                "signal",
                "sine",
                "--axis",
                "f_x",
                "--amplitude",
                "1",
                "--frequency-hz",
                "1",
                "--duration-s",
                "1e9",
                "--out",
                tmp_path / "s.csv",
            ),
            "--duration-s",
        ),
        (
            (
                "signal",
                "sine",
                "--axis",
                "f_x",
                "--amplitude",
                "1",
                "--frequency-hz",
                "1",
                "--rate-hz",
                "1e12",
                "--out",
                tmp_path / "s.csv",
            ),
            "--rate-hz",
        ),
        (("omct", "--params", "/dev/zero", "--out", tmp_path / "o2"), "/dev/zero"),
        # by default a script is capped at 1200 s, announced (issue 26); asked to fly it all, it is refused first
        (("run", script, "--max-time-s", "1e30", "--out", tmp_path / "o3"), str(script)),
        (
            (
                "sweep",
                m,
                "--set",
                "tilt.gain_per_s=" + ",".join(str(i) for i in range(1, 80)),
                "--set",
                "translational_highpass_wn_radps.x=" + ",".join(str(i / 10) for i in range(1, 30)),
                "--out",
                tmp_path / "o4",
            ),
            "--force",
        ),
        (("cue", bomb, "--out", tmp_path / "o5"), str(bomb)),
        (
            (
                "tune",
                m,
                "--washout",
                "small-angle",
                "--tune",
                "tilt.gain_per_s=1:2",
                "--seed",
                "-1",
                "--out",
                tmp_path / "o6",
            ),
            "--seed",
        ),
        (
            (
                "tune",
                m,
                "--washout",
                "small-angle",
                "--tune",
                "tilt.gain_per_s=1:2",
                "--tune",
                "tilt.rate_limit_degps=1:3",
                "--budget",
                "6",
                "--out",
                tmp_path / "o7",
            ),
            "--budget 6",
        ),
        (("sweep", m, "--set", "tilt.gain_per_s=1,1.0", "--out", tmp_path / "o8"), "listed twice"),
    ]

    def one(case: tuple[tuple[object, ...], str]) -> tuple[subprocess.CompletedProcess[str], str, float]:
        t0 = time.monotonic()
        return washbench(*case[0], timeout=60), case[1], time.monotonic() - t0

    with ThreadPoolExecutor(2) as pool:
        for proc, name, wall_s in pool.map(one, cases):
            assert_clean_error(proc, name)
            assert wall_s < 30, (name, wall_s)
    assert sorted(os.listdir(tmp_path)) == ["blank.csv.gz", "long.xml", "short.yaml"]


def test_inputs_users_write(motion: Path, tmp_path: Path) -> None:
    """A CSV with a UTF-8 byte-order mark (Excel's "CSV UTF-8") is read; a YAML key with terminal escapes is
    quoted escaped."""
    bom = tmp_path / "bom.csv"
    bom.write_bytes(b"\xef\xbb\xbf" + motion.read_bytes())
    proc = washbench("cue", bom, "--out", tmp_path / "o", "--no-figures", "--no-recording", timeout=60)
    assert proc.returncode == 0, proc.stderr
    m = short(tmp_path, extra='"\\e[31mevil\\e[0m": 1\n')  # a YAML key holding ESC (double-quoted escape)
    proc = washbench("validate", m, timeout=30)
    assert proc.returncode == 2 and "\x1b" not in proc.stderr and "\\x1b[31mevil" in proc.stderr, proc.stderr


def test_dask_address_that_is_no_scheduler_is_one_line_quickly(tmp_path: Path) -> None:
    pytest.importorskip("dask.distributed")
    m = short(tmp_path)
    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen(1)
    port = server.getsockname()[1]
    for address in ("not an address:::", f"tcp://127.0.0.1:{port}"):
        t0 = time.monotonic()
        proc = washbench(
            "sweep",
            m,
            "--set",
            "tilt.gain_per_s=1,2",
            "--dask",
            address,
            "--quiet",
            "--out",
            tmp_path / "o",
            timeout=60,
        )
        assert_clean_error(proc, "--dask")
        assert time.monotonic() - t0 < 25
    server.close()


# ------------------------------------------------------------------------------------------ read back


@pytest.mark.slow
def test_report_on_tampered_result_files_rebuilds_or_refuses_cleanly(cued: Path, tmp_path: Path) -> None:
    """Hypothesis: washbench's own result files mutated (types, missing keys, text columns): `washbench report`
    either rebuilds the report (exit 0) or refuses with one line naming the file (exit 2); never a traceback."""
    from hypothesis import HealthCheck, example, given, settings
    from hypothesis import strategies as st

    from washbench.cli import main

    base = copy_of(cued, tmp_path / "base")
    doc = json.loads((base / "run.json").read_text())
    keys = sorted(doc)
    values = st.one_of(
        st.none(),
        st.booleans(),
        st.integers(-5, 5),
        st.floats(allow_nan=False),
        st.text(max_size=5),
        st.lists(st.integers(), max_size=2),
        st.dictionaries(st.text(max_size=3), st.integers(), max_size=2),
    )
    counter = iter(range(10_000))

    # derandomized: the same examples in every run (a CI run cannot fail by chance); the explicit ones are what a
    # random run once found (the input figure's legends and notes, read back from run.json)
    @settings(max_examples=12, deadline=None, suppress_health_check=list(HealthCheck), derandomize=True)
    @example(target="run.json", key="conversions", value=None, drop=False)
    @example(target="run.json", key="input_labels", value=[1, 2, 3, 4, 5, 6], drop=False)
    @given(
        target=st.sampled_from(["run.json", "traces.parquet", "metrics.csv", "flight.json", "provenance"]),
        key=st.sampled_from(keys),
        value=values,
        drop=st.booleans(),
    )
    def check(target: str, key: str, value: object, drop: bool) -> None:
        import pyarrow as pa
        import pyarrow.parquet as pq

        folder = copy_of(base, tmp_path / f"m{next(counter)}")
        if target == "run.json":
            d = json.loads((folder / "run.json").read_text())
            if drop:
                d.pop(key, None)
            else:
                d[key] = value
            (folder / "run.json").write_text(json.dumps(d))
        elif target == "provenance":
            d = json.loads((folder / "run.json").read_text())
            prov = d["provenance"]
            sub = sorted(prov)[keys.index(key) % len(prov)]
            prov[sub] = value
            (folder / "run.json").write_text(json.dumps(d))
        elif target == "flight.json":
            (folder / "flight.json").write_text(json.dumps({"phases": value, "checks": [value], "dt_s": value}))
        elif target == "metrics.csv":
            lines = (folder / "metrics.csv").read_text().splitlines()
            lines[1 + keys.index(key) % (len(lines) - 1)] = ",".join([str(value)] * (3 if drop else 6))
            (folder / "metrics.csv").write_text("\n".join(lines) + "\n")
        else:
            table = pq.read_table(folder / "traces.parquet")
            name = table.column_names[keys.index(key) % table.num_columns]
            col = pa.array([str(value)] * table.num_rows) if drop else pa.array(np.full(table.num_rows, np.nan))
            pq.write_table(table.set_column(table.column_names.index(name), name, col), folder / "traces.parquet")
        try:
            status = main(["report", str(folder)])
        except SystemExit as exc:  # argparse
            status = exc.code
        assert status in (0, 2)

    check()


def test_report_refusal_is_one_line_naming_file_and_field(cued: Path, tmp_path: Path) -> None:
    folder = copy_of(cued, tmp_path / "r")
    d = json.loads((folder / "run.json").read_text())
    d["perceived_motion"]["surge"]["value"] = "lots"
    (folder / "run.json").write_text(json.dumps(d))
    proc = washbench("report", folder, timeout=60)
    assert_clean_error(proc, str(folder / "run.json"), "perceived_motion.surge.value")
