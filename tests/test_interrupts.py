"""SIGINT and SIGTERM at several moments: workers stop at once, nothing half-built stays, nothing appears later."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from hostile import live_processes, short, tree

from washbench.io.result_files import STAGE_PREFIX


def previous_suite(out: Path) -> list[str]:
    """A folder holding a previous suite's results (what an interrupted suite must leave untouched)."""
    run = out / "c172p" / "earlier"
    run.mkdir(parents=True)
    (run / "run.json").write_text(json.dumps({"aircraft": "c172p", "manoeuvre": "earlier", "ok": True}))
    (out / "report.md").write_text("# the previous suite\n")
    (out / "suite.json").write_text(json.dumps({"washbench": "suite", "entries": ["c172p", "report.md"]}))
    return tree(out)


def start(*args: object) -> subprocess.Popen[str]:
    """``washbench ARGS`` in its own process group (so every process it starts can be found afterwards)."""
    return subprocess.Popen(
        [sys.executable, "-m", "washbench", *map(str, args)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )


def wait_for_no_process(pgid: int, timeout_s: float = 10.0) -> list[str]:
    deadline = time.monotonic() + timeout_s
    while (left := live_processes(pgid)) and time.monotonic() < deadline:
        time.sleep(0.1)
    return left


@pytest.fixture(scope="module")
def manoeuvres(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("long")
    for i in range(3):
        short(folder, name=f"long_{i}", seconds=3600)  # far longer than any test waits: always stopped mid-flight
    return folder


@pytest.mark.parametrize(
    ("sig", "delay_s", "group", "status", "word"),
    [
        (signal.SIGINT, 0.5, False, 130, "interrupted"),  # while loading
        (signal.SIGTERM, 2.5, False, 143, "terminated"),  # while the workers start
        (signal.SIGINT, None, True, 130, "interrupted"),  # while they fly; a terminal's Ctrl-C reaches every process
    ],
)
def test_suite_stops_at_once_and_leaves_the_previous_results(
    manoeuvres: Path, tmp_path: Path, sig: signal.Signals, delay_s: float | None, group: bool, status: int, word: str
) -> None:
    out = tmp_path / "out"
    before = previous_suite(out)
    proc = start("suite", manoeuvres, "--out", out, "--jobs", "2")
    if delay_s is None:  # flying: the command, its process server and two workers are up, and a second more
        deadline = time.monotonic() + 60
        while len(live_processes(proc.pid)) < 4 and proc.poll() is None and time.monotonic() < deadline:
            time.sleep(0.05)
        time.sleep(1.0)
    else:
        time.sleep(delay_s)
    if group:
        os.killpg(proc.pid, sig)
    else:
        proc.send_signal(sig)
    _, err = proc.communicate(timeout=60)
    if proc.returncode == -sig and delay_s is not None and delay_s < 1:
        # the signal can come before Python has started (or, seen once, as it ends): the default action ends the
        # process, which a shell reports as the same 130 (128 + SIGINT); at most the one line was printed
        assert "Traceback" not in err and err.strip() in ("", f"washbench: {word}"), err
    else:
        assert proc.returncode == status, err
        assert "Traceback" not in err and "KeyboardInterrupt" not in err, err
        # once the runs had begun, the line says what was lost and that nothing was written (issue 52, item 6d)
        lost = (f"washbench: {word}: 0 of 3 manoeuvres had finished; their runs are discarded and nothing was "
                f"written to {out} (its earlier results stay as they were)")  # fmt: skip
        last = err.strip().splitlines()[-1]
        assert last == lost if group else last in (f"washbench: {word}", lost), err
    assert wait_for_no_process(proc.pid) == []
    assert tree(out) == before  # no half-built folder, no lock, nothing new
    time.sleep(1.0)
    assert tree(out) == before  # and nothing appears later


def test_an_interrupted_suite_says_how_many_runs_it_discards(manoeuvres: Path, tmp_path: Path) -> None:
    """Issue 52, item 6 (d): Ctrl-C after the first of three manoeuvres finished: the last line says that one had
    finished, that its run is discarded and that nothing was written (the earlier results stay as they were)."""
    out = tmp_path / "out"
    before = previous_suite(out)
    first = short(tmp_path, name="first", seconds=1)
    proc = start("suite", first, manoeuvres / "long_0.yaml", manoeuvres / "long_1.yaml", "--out", out, "--jobs", "1",
                 "--no-recording", "--no-figures")  # fmt: skip
    seen = []
    assert proc.stderr is not None
    for line in proc.stderr:  # the progress lines (plain: stderr is a pipe); the first run's comes once it is counted
        seen.append(line)
        if line.startswith("[ 1/3] ok"):
            break
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    err = "".join(seen) + err
    assert proc.returncode == 130, err
    assert err.strip().splitlines()[-1] == (
        f"washbench: interrupted: 1 of 3 manoeuvres had finished; their runs are discarded and nothing was written to "
        f"{out} (its earlier results stay as they were)"), err
    assert tree(out) == before


def test_run_terminated_in_flight_removes_its_half_built_folder(manoeuvres: Path, tmp_path: Path) -> None:
    out = tmp_path / "out"
    proc = start("run", manoeuvres / "long_0.yaml", "--out", out)
    time.sleep(3.0)
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 143, err
    # progress lines come first (stderr is not a terminal); the interruption is the one last line
    assert err.strip().splitlines()[-1] == "washbench: terminated" and "Traceback" not in err, err
    assert tree(out) == []


def test_what_a_run_killed_outright_leaves_goes_with_the_next_run(manoeuvres: Path, tmp_path: Path) -> None:
    """SIGKILL (no handler runs) while a run builds its folder: its hidden stage stays in ``OUT/c172p/``; the next
    run into the same ``OUT`` removes it (its process is gone) and publishes beside the earlier result."""
    out = tmp_path / "out"
    first = start("run", short(tmp_path, name="earlier", seconds=1), "--out", out, "--quiet")
    assert first.wait(timeout=120) == 0
    proc = start("run", manoeuvres / "long_0.yaml", "--out", out, "--quiet")
    deadline = time.monotonic() + 60
    while not list((out / "c172p").glob(f"{STAGE_PREFIX}*/long_0")) and time.monotonic() < deadline:
        time.sleep(0.05)
    time.sleep(0.5)  # flying, the stage made
    proc.kill()
    proc.wait(timeout=30)
    assert [p.name for p in (out / "c172p").iterdir() if p.name.startswith(STAGE_PREFIX)] == [
        f"{STAGE_PREFIX}{proc.pid}"
    ]
    nxt = start("run", short(tmp_path, name="level", seconds=1), "--out", out, "--quiet")
    _, err = nxt.communicate(timeout=120)
    assert nxt.returncode == 0, err
    assert sorted(p.name for p in (out / "c172p").iterdir()) == ["earlier", "level"]
    assert sorted(p.name for p in out.iterdir()) == ["c172p"]  # the killed run's lock file went with it too


def _wrapped_interrupt(by_signal: bool) -> None:
    """What Python makes of Ctrl-C landing while a module imported mid-command creates a pydantic model (seen in
    CI: ``RuntimeError: Error calling __set_name__ ...``, the KeyboardInterrupt as its cause)."""
    from washbench.io import interrupts

    try:
        if by_signal:
            interrupts.interrupt(signal.SIGINT, None)  # what the handler does when the signal lands: counted, raised
        raise KeyboardInterrupt  # raised by code, no signal
    except KeyboardInterrupt as exc:
        raise RuntimeError("Error calling __set_name__ on 'PydanticDescriptorProxy' instance") from exc


def test_a_signal_wrapped_by_python_still_ends_in_one_line(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    import washbench.cli as cli
    from washbench.io.paths import MANOEUVRES_DIR

    manoeuvre = str(MANOEUVRES_DIR / "c172" / "takeoff.yaml")
    monkeypatch.setattr(cli, "_dispatch", lambda args: _wrapped_interrupt(by_signal=True))
    assert cli.main(["validate", manoeuvre]) == 130
    assert capsys.readouterr().err.strip().splitlines()[-1] == "washbench: interrupted"
    # no signal received: a KeyboardInterrupt raised by code beneath another error is that error, as before
    monkeypatch.setattr(cli, "_dispatch", lambda args: _wrapped_interrupt(by_signal=False))
    with pytest.raises(RuntimeError, match="__set_name__"):
        cli.main(["validate", manoeuvre])


class _InterruptsItsSchema:
    """A field type whose schema sends this process SIGINT the first time pydantic builds it (as a Ctrl-C that lands
    while a deferred model is built at its first use)."""

    sent = False

    @classmethod
    def __get_pydantic_core_schema__(cls, source: object, handler: object) -> object:
        from pydantic_core import core_schema

        if not cls.sent:
            cls.sent = True
            os.kill(os.getpid(), signal.SIGINT)  # the handler runs at the next bytecode, inside the build
        return core_schema.no_info_plain_validator_function(int, serialization=core_schema.to_string_ser_schema())


def test_a_ctrl_c_while_a_model_is_built_acts_once_it_is_built() -> None:
    """A model's schema is built at its first use (``defer_build``); pydantic-core turned a KeyboardInterrupt raised
    inside that build into a SchemaError traceback. Held back (``StrictModel.model_rebuild``), the Ctrl-C is a
    KeyboardInterrupt after the build, and the model is complete: the next use does not build it again."""
    from washbench.io import interrupts
    from washbench.io.yamlio import StrictModel

    class Model(StrictModel):
        value: _InterruptsItsSchema

    assert not Model.__pydantic_complete__
    before = signal.signal(signal.SIGINT, interrupts.interrupt)  # the command's handler
    try:
        with pytest.raises(KeyboardInterrupt):
            Model.model_validate({"value": 3})
        assert _InterruptsItsSchema.sent
        assert Model.__pydantic_complete__  # built whole, then interrupted
        assert Model.model_validate({"value": 4}).value == 4
    finally:
        signal.signal(signal.SIGINT, before)
