"""Work beside the command in a forked child (washbench.runs.beside): where it runs, what comes back, what a
failure on either side leaves; and a cued result the same, file for file, with the figures drawn beside the
recording or after it in one process."""

from __future__ import annotations

import copyreg
import multiprocessing
import os
import signal
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.csv as pacsv
import pytest

from washbench.errors import WashbenchError
from washbench.runs import beside as beside_mod
from washbench.runs.beside import NO_BESIDE_ENV, beside, can_fork

pytestmark = pytest.mark.skipif(not can_fork(), reason="no second usable CPU, or not Linux: nothing is forked")


def _write_pid(path: Path) -> None:
    """This process's PID into ``path``, whole the moment it exists (written aside, then renamed)."""
    path.with_suffix(".tmp").write_text(str(os.getpid()))
    path.with_suffix(".tmp").replace(path)


def test_the_work_runs_in_another_process_while_the_block_runs(tmp_path: Path) -> None:
    mark, order = tmp_path / "pid", []
    with beside(lambda: (_write_pid(mark), time.sleep(0.2))) as forked:
        order.append("block")
    assert forked
    pid = int(mark.read_text())  # written by the time the block's end has waited for the child
    assert pid != os.getpid()
    with pytest.raises(ProcessLookupError):  # reaped: no zombie left
        os.kill(pid, 0)


def test_without_a_fork_the_work_runs_here_after_the_block(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(NO_BESIDE_ENV, "1")
    mark, order = tmp_path / "pid", []
    with beside(lambda: (order.append("work"), _write_pid(mark))) as forked:
        order.append("block")
    assert not forked and order == ["block", "work"] and int(mark.read_text()) == os.getpid()
    monkeypatch.delenv(NO_BESIDE_ENV)
    with beside(lambda: order.append("small"), fork=False) as forked:  # not worth a process
        assert not forked


def _fail_with_problems() -> None:
    raise WashbenchError("a.yaml:3: bank_deg: expected a number", ["a.yaml:4: second problem"])


def test_the_childs_error_is_raised_here_with_every_problem() -> None:
    with pytest.raises(WashbenchError) as info, beside(_fail_with_problems):
        pass
    assert info.value.problems == ("a.yaml:3: bank_deg: expected a number", "a.yaml:4: second problem")
    assert str(info.value) == "a.yaml:3: bank_deg: expected a number (and 1 more problem)"
    assert any("_fail_with_problems" in note for note in info.value.__notes__)  # the child's traceback


def _disk_full() -> None:
    raise OSError(28, "No space left on device")


def test_an_os_error_stays_an_os_error() -> None:
    with pytest.raises(OSError) as info, beside(_disk_full):
        pass
    assert info.value.errno == 28 and info.value.strerror == "No space left on device"


def _unpicklable() -> None:
    class LocalError(Exception):
        pass

    raise LocalError("made inside a function: pickle cannot find its class")


def test_an_exception_that_cannot_be_pickled_comes_back_as_its_text() -> None:
    with pytest.raises(RuntimeError, match="LocalError: made inside a function"), beside(_unpicklable):
        pass


class NeedsTwoError(Exception):
    def __init__(self, where: str, what: str) -> None:
        super().__init__(f"{where}: {what}")


def _rebuilt_otherwise() -> None:
    raise NeedsTwoError("figures/input.png", "pickles, but its arguments do not rebuild it")


def test_an_exception_that_pickles_but_does_not_rebuild_comes_back_as_its_text(monkeypatch: pytest.MonkeyPatch) -> None:
    # importing dask.distributed (another test's in-process `sweep --dask` in this worker) registers tblib's reducer
    # for every exception class defined by then, which rebuilds one without calling __init__: this class would then
    # rebuild, whatever the order the tests ran in. Its own pickling is the subject here.
    monkeypatch.delitem(copyreg.dispatch_table, NeedsTwoError, raising=False)
    with pytest.raises(RuntimeError, match=r"NeedsTwoError: figures/input\.png: pickles"), beside(_rebuilt_otherwise):
        pass


def test_a_child_killed_by_a_signal_is_named() -> None:
    with pytest.raises(RuntimeError, match="ended with signal 9"), beside(lambda: os.kill(os.getpid(), signal.SIGKILL)):
        pass


def test_an_error_in_the_block_kills_the_child_at_once(tmp_path: Path) -> None:
    mark = tmp_path / "pid"
    start = time.monotonic()
    with pytest.raises(KeyError), beside(lambda: (_write_pid(mark), time.sleep(60))):
        while not mark.exists():
            time.sleep(0.01)
        raise KeyError("the recording failed")
    assert time.monotonic() - start < 30  # not the child's 60 s: killed, not waited for
    with pytest.raises(ProcessLookupError):
        os.kill(int(mark.read_text()), 0)


def test_the_child_ignores_sigint_and_writes_nothing_to_the_terminal(
    tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    """Ctrl-C reaches the whole process group: the command decides, the child goes on until it is told."""
    mark = tmp_path / "done"

    def work() -> None:
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(0.1)
        mark.write_text("went on")

    print("buffered before the fork", end="")
    with beside(work):
        pass
    assert mark.read_text() == "went on"
    assert capfd.readouterr().out.count("buffered before the fork") == 1  # flushed once, by this process


def test_no_fork_with_a_second_thread_or_in_a_pool_worker(monkeypatch: pytest.MonkeyPatch) -> None:
    import threading

    stop = threading.Event()
    thread = threading.Thread(target=stop.wait)
    thread.start()
    try:
        assert not can_fork()  # a lock another thread holds at the fork would stay held in the child
    finally:
        stop.set()
        thread.join()
    assert can_fork()
    with ProcessPoolExecutor(1, mp_context=multiprocessing.get_context("fork")) as pool:
        assert not pool.submit(can_fork).result()  # a suite's worker: the cores are busy already


def _log(path: Path, n: int) -> None:
    t = np.arange(n) / 120.0
    cols = {
        "t_s": t,
        "f_x_mps2": 1.5 * np.sin(0.3 * t),
        "f_y_mps2": 0.8 * np.sin(0.17 * t + 1.0),
        "f_z_mps2": -9.80665 * (1.0 + 0.3 * np.sin(0.11 * t)),
        "omega_x_degps": 15.0 * np.sin(0.5 * t),
        "omega_y_degps": 5.0 * np.sin(0.23 * t + 0.4),
        "omega_z_degps": 3.0 * np.sin(0.07 * t),
    }
    pacsv.write_csv(pa.table(cols), path)


def test_a_cue_result_is_the_same_drawn_beside_or_after(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The figures, ranking and report drawn in children while the traces and the recording are written are the
    bytes drawn in one process after them; the report links the recording either way."""
    from washbench.runs.cue import run_cue

    src = tmp_path / "log.csv"
    _log(src, 2400)
    forks, fork = [], beside_mod._fork
    monkeypatch.setattr(beside_mod, "_fork", lambda work: forks.append(work) or fork(work))
    assert run_cue(src, tmp_path / "beside") == 0
    assert len(forks) == 2  # the input figure beside the cueing, the result's beside the recording
    monkeypatch.setenv(NO_BESIDE_ENV, "1")
    assert run_cue(src, tmp_path / "after") == 0
    assert len(forks) == 2
    names = ["metrics.csv", "ranking.csv", "figures/input.png", "figures/perceived.png", "figures/cues.png",
             "figures/envelope.png"]  # fmt: skip
    for name in names:
        assert (tmp_path / "beside" / name).read_bytes() == (tmp_path / "after" / name).read_bytes(), name
    report = [(tmp_path / d / "report.md").read_text().splitlines() for d in ("beside", "after")]
    strip = [[line for line in r if not line.startswith("| created |")] for r in report]  # the clock's minute
    assert strip[0] == strip[1]
    assert "Recording: [recording.rrd](recording.rrd) (`washbench replay recording.rrd`)." in report[0]
    assert (tmp_path / "beside" / "recording.rrd").stat().st_size > 0


HOLD_AND_FORK = """
import os, sys, time
from washbench.io.lock import output_lock
from washbench.runs.beside import beside

folder, report = sys.argv[1:3]

def child():  # the descriptors this child has open, then it lives on (until the command's death ends it)
    with open(report + ".tmp", "w") as f:
        f.write("\\n".join(os.readlink(f"/proc/self/fd/{fd}") for fd in os.listdir("/proc/self/fd")
                          if os.path.islink(f"/proc/self/fd/{fd}")))
    os.replace(report + ".tmp", report)
    time.sleep(60)

with output_lock(folder):
    with beside(child):
        print("forked", flush=True)
        time.sleep(60)
"""


def test_a_command_killed_outright_leaves_no_lock_in_its_child(tmp_path: Path) -> None:
    """The child forked beside a command does not hold the command's output lock (washbench.io.lock): killed
    outright (SIGKILL), the command's folder can be written by the next command at once, while its child may still
    be dying. (flock holds while any copy of the descriptor is open: the child closes the copy it was forked with.)"""
    import subprocess
    import sys

    from washbench.io.lock import output_lock
    from washbench.io.result_files import LOCK_NAME

    folder, report = tmp_path / "out", tmp_path / "child_fds"
    proc = subprocess.Popen([sys.executable, "-c", HOLD_AND_FORK, str(folder), str(report)], stdout=subprocess.PIPE,
                            text=True)  # fmt: skip
    try:
        assert proc.stdout is not None and proc.stdout.readline().strip() == "forked"
        deadline = time.monotonic() + 60
        while not report.exists() and time.monotonic() < deadline:
            time.sleep(0.01)
        child_fds = report.read_text().splitlines()
        assert str(folder / LOCK_NAME) not in child_fds  # the child has no copy of the lock
        with pytest.raises(WashbenchError, match="another washbench command"), output_lock(folder):
            pass  # the command itself holds it
    finally:
        proc.kill()
        proc.wait()
    with output_lock(folder):  # at once, whether or not the child has died yet
        pass
