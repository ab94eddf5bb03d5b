"""``python -m washbench ARGS`` run inside the test process, with what a subprocess would give back.

A new interpreter costs a ``washbench`` command about 1-2 s of CPU before it does anything (its imports: numba,
rerun, matplotlib, pyarrow; numba's target and the kernels loaded from the cache; matplotlib's first figure), which
the test process has already paid: the test command starts some 300 of them. :func:`washbench` runs
:func:`washbench.cli.main` here instead, for the commands that neither start processes of their own nor depend on
being one (:data:`IN_PROCESS`), and falls back to a real subprocess for everything else (a plugin, an environment of
its own beyond washbench's own variables, another command).

What stays true of the command as a process:

- its standard output and error are captured at the file descriptors (1 and 2), so what JSBSim or any C library
  prints is caught as from a child, and ``sys.stdout``/``sys.stderr`` are new text streams on them (a pipe's
  encoding and error handlers, not a terminal);
- its exit status: the value ``main`` returns, a ``SystemExit``'s code (argparse), or 1 and the traceback on
  standard error for an exception that escapes, as Python prints it (so a test that says "no traceback" still
  catches one);
- nothing it changes outlives it: the working folder, the environment, the signal handlers, ``sys.argv`` and the
  unraisable hook are restored;
- a command that hangs ends the test worker after ``timeout`` s with every thread's traceback
  (``faulthandler``), where a subprocess would have been killed at the same limit.
"""

from __future__ import annotations

import contextlib
import faulthandler
import io
import os
import signal
import subprocess
import sys
import tempfile
import threading
import traceback
from pathlib import Path

#: The commands run in the test process: they start no process of their own (``suite`` does, ``live`` serves and
#: starts viewers) and read no plugin (a washout or platform plugin is registered for the process).
IN_PROCESS = frozenset({"cue", "fly", "run", "report", "validate", "schema", "signal", "examples", "omct", "track"})
#: ... and these with ``--from`` (the flights already flown) or one manoeuvre file to fly (more are flown in a pool
#: of processes).
STUDIES = frozenset({"sweep", "tune"})
#: Options that load code into the process or make it serve: such a command runs as a subprocess.
SUBPROCESS_OPTIONS = ("--washout-plugin", "--platform-plugin", "--jobs", "--dask")


def in_process(args: list[str]) -> bool:
    """Whether ``washbench ARGS`` can run in the test process (:data:`IN_PROCESS`, :data:`STUDIES`, no
    :data:`SUBPROCESS_OPTIONS`)."""
    command = next((a for a in args if not a.startswith("-")), None)
    if command not in IN_PROCESS | STUDIES:
        return False
    if any(a == o or a.startswith(o + "=") for a in args for o in SUBPROCESS_OPTIONS):
        return False
    return command not in STUDIES or _one_flight_or_none(args)


def _one_flight_or_none(args: list[str]) -> bool:
    """Whether a study (``sweep``, ``tune``) flies at most one manoeuvre here: ``--from`` (none) or one file (its
    training and ``--test`` manoeuvres, as washbench's own parser reads them); an argument error: yes (it stops
    before flying anything)."""
    from washbench.cli import build_parser

    try:
        with contextlib.redirect_stderr(io.StringIO()), contextlib.redirect_stdout(io.StringIO()):
            ns = build_parser().parse_args(args)
    except SystemExit:
        return True
    flights = [*ns.manoeuvres, *(getattr(ns, "test", None) or [])]
    return ns.from_dir is not None or (len(flights) == 1 and Path(flights[0]).is_file())


def washbench(
    *args: object, timeout: float = 60, cwd: Path | None = None, env: dict[str, str] | None = None
) -> subprocess.CompletedProcess[str]:
    """Run ``python -m washbench ARGS`` to its end and return its status and output (text).

    In this process when called from its main thread, :func:`in_process` allows, and ``env`` (the whole
    environment; None: this process's) differs from this process's only in washbench's own variables
    (``WASHBENCH_*``: read when a command runs, not when a module is imported); else as a subprocess (``timeout``
    s at most)."""
    argv = [str(a) for a in args]
    # a command in another thread (tests that run several at once) is a process: the file descriptors and the
    # signal handlers are the process's
    here = threading.current_thread() is threading.main_thread()
    if not here or not in_process(argv) or not _only_washbench_variables(env):
        return subprocess.run([sys.executable, "-m", "washbench", *argv], capture_output=True, text=True,
                              timeout=timeout, cwd=cwd, env=env)  # fmt: skip
    return _run_here(argv, timeout, cwd, env)


def _only_washbench_variables(env: dict[str, str] | None) -> bool:
    if env is None:
        return True
    changed = {k for k in env.keys() | os.environ.keys() if env.get(k) != os.environ.get(k)}
    return all(k.startswith("WASHBENCH_") for k in changed)


def _run_here(
    argv: list[str], timeout: float, cwd: Path | None, env: dict[str, str] | None
) -> subprocess.CompletedProcess[str]:
    from washbench.cli import main

    for stream in (sys.stdout, sys.stderr):
        stream.flush()
    saved_fds = (os.dup(1), os.dup(2))
    streams = (sys.stdout, sys.stderr, sys.argv, sys.unraisablehook)
    folder, environ = os.getcwd(), dict(os.environ)
    handlers = {sig: signal.getsignal(sig) for sig in (signal.SIGINT, signal.SIGTERM)}
    with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
        os.dup2(out.fileno(), 1)
        os.dup2(err.fileno(), 2)
        # a pipe's text streams: UTF-8, strict on stdout, backslashreplace on stderr (Python's own choice)
        sys.stdout = open(1, "w", encoding="utf-8", errors="strict", closefd=False)  # noqa: SIM115
        sys.stderr = open(2, "w", encoding="utf-8", errors="backslashreplace", closefd=False)  # noqa: SIM115
        sys.argv = [str(Path(sys.executable).parent / "washbench"), *argv]
        faulthandler.dump_traceback_later(timeout, exit=True, file=saved_fds[1])
        try:
            if cwd is not None:
                os.chdir(cwd)
            if env is not None:
                os.environ.clear()
                os.environ.update(env)
            status = _status(main, argv)
        finally:
            faulthandler.cancel_dump_traceback_later()
            for stream in (sys.stdout, sys.stderr):
                with contextlib.suppress(OSError, ValueError):  # a command that closed its stdout (a broken pipe)
                    stream.flush()
            for fd, saved_fd in ((1, saved_fds[0]), (2, saved_fds[1])):
                os.dup2(saved_fd, fd)
                os.close(saved_fd)
            sys.stdout, sys.stderr, sys.argv, sys.unraisablehook = streams
            os.chdir(folder)
            os.environ.clear()
            os.environ.update(environ)
            for sig, handler in handlers.items():
                signal.signal(sig, handler)
        texts = []
        for f in (out, err):
            f.seek(0)
            texts.append(io.TextIOWrapper(f, encoding="utf-8", newline=None).read())  # text=True's universal newlines
    return subprocess.CompletedProcess(["washbench", *argv], status, texts[0], texts[1])


def _status(main, argv: list[str]) -> int:
    """The exit status ``main(argv)`` gives as a process: its return value, a SystemExit's code, or 1 with the
    traceback on standard error for an exception that escapes."""
    try:
        status = main(argv)
    except SystemExit as exc:
        if exc.code is None or isinstance(exc.code, int):
            return exc.code or 0
        print(exc.code, file=sys.stderr)
        return 1
    except KeyboardInterrupt:  # the test run's own Ctrl-C (the command's signals are its own processes' business)
        raise
    except BaseException:
        traceback.print_exc()
        return 1
    return 0 if status is None else int(status)
