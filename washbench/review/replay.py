"""``washbench replay FILE.rrd``: open a recording in the rerun viewer (native where there is a display, else web)."""

from __future__ import annotations

import contextlib
import importlib.util
import os
import re
import shutil
import signal
import subprocess
import sys
import threading
import time
import warnings
from collections import deque
from pathlib import Path

from washbench.errors import WashbenchError, located, printable

__all__ = ["check_recording", "find_rerun", "replay_command", "start_web_viewer", "stop_viewer"]

RRD_MAGIC = b"RRF2"
"""First four bytes of every .rrd file written by rerun 0.41."""

_URL_RE = re.compile(r"connect at (http://\S+)")
_ANSI_RE = re.compile(r"\x1b\[[0-9;]*m")


def check_recording(path: Path) -> None:
    """Raise WashbenchError (one line) unless ``path`` is a readable .rrd file with a recording in it.

    Reads the whole file once with ``rerun.chunk.RrdReader`` (pyarrow only), so a truncated or corrupt file is caught
    here rather than in the viewer.
    """
    path = Path(path)
    if not path.exists():
        raise WashbenchError(located(path, "no such file"))
    if not path.is_file():
        raise WashbenchError(located(path, "not a file"))
    if path.suffix != ".rrd":
        raise WashbenchError(located(path, "not an .rrd file (expected a recording written by washbench run)"))
    try:
        with path.open("rb") as fh:
            head = fh.read(len(RRD_MAGIC))
    except OSError as exc:
        raise WashbenchError(located(path, f"cannot read: {exc.strerror}")) from None
    if head != RRD_MAGIC:
        raise WashbenchError(located(path, "not a rerun recording (no RRF2 header)"))
    from rerun.chunk import RrdReader

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # a file without footer is legal; we scan it fully below anyway
            reader = RrdReader(str(path))
            recordings = reader.recordings()
            for _ in reader.stream():
                pass
    except (RuntimeError, ValueError, OSError) as exc:
        problem = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        problem = problem.replace(f"Failed to read RRD file at {path}: ", "")
        raise WashbenchError(located(path, f"corrupt recording: {problem}")) from None
    if not recordings:
        raise WashbenchError(located(path, "the file holds no recording (only a blueprint?)"))


def find_rerun() -> Path:
    """The rerun viewer executable: the binary bundled in the rerun-sdk wheel, else ``rerun`` next to the running
    Python, else ``rerun`` on PATH. Raises WashbenchError if none exists.

    The bundled binary is preferred over the ``bin/rerun`` wrapper script because the wrapper runs the binary as a
    grandchild, which would survive terminating the wrapper.
    """
    exe = "rerun.exe" if sys.platform.startswith("win") else "rerun"
    spec = importlib.util.find_spec("rerun_cli")
    if spec is not None and spec.origin is not None:
        bundled = Path(spec.origin).parent / exe
        if bundled.is_file() and os.access(bundled, os.X_OK):
            return bundled
    beside = Path(sys.executable).parent / exe  # bin/ of a venv (Scripts\ on Windows)
    if beside.is_file() and os.access(beside, os.X_OK):
        return beside
    found = shutil.which("rerun")
    if found is None:
        raise WashbenchError("rerun: viewer executable not found (install rerun-sdk==0.41.0 in this environment)")
    return Path(found)


def _has_display(platform: str | None = None, environ: dict[str, str] | None = None) -> bool:
    """Whether the native viewer can open a window: always on macOS and Windows desktops; elsewhere (Linux, BSD)
    only with an X11 or Wayland display (``DISPLAY`` / ``WAYLAND_DISPLAY``), e.g. not over plain SSH."""
    platform = sys.platform if platform is None else platform
    environ = os.environ if environ is None else environ
    if platform == "darwin" or platform.startswith(("win", "cygwin")):
        return not environ.get("SSH_CONNECTION")  # a remote shell on a desktop machine has no window either
    return bool(environ.get("DISPLAY") or environ.get("WAYLAND_DISPLAY"))


def _die_with_parent() -> None:
    """In the viewer's child process (Linux): receive SIGTERM when washbench ends, even by SIGKILL."""
    import ctypes

    with contextlib.suppress(OSError, AttributeError):
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(1, signal.SIGTERM, 0, 0, 0)  # PR_SET_PDEATHSIG


def start_web_viewer(
    path: Path, *, web_port: int = 0, grpc_port: int = 0, timeout_s: float = 60.0
) -> tuple[subprocess.Popen[str], str]:
    """Start ``rerun --web-viewer`` on ``path``, listening on 127.0.0.1 only; return (process, viewer URL).

    Port 0 lets the system choose free ports. The process runs in its own session; its combined output is drained by
    a background thread. Raises WashbenchError if the viewer exits or prints no address within ``timeout_s``.
    """
    cmd = [
        str(find_rerun()),
        "--web-viewer",
        "--bind",
        "127.0.0.1",
        "--web-viewer-port",
        str(web_port),
        "--port",
        str(grpc_port),
        str(path),
    ]
    env = {**os.environ, "NO_COLOR": "1"}
    proc = subprocess.Popen(
        cmd,
        stdin=subprocess.DEVNULL,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        env=env,
        start_new_session=True,
        preexec_fn=_die_with_parent if sys.platform.startswith("linux") else None,
    )
    found: list[str] = []
    tail: deque[str] = deque(maxlen=5)
    ready = threading.Event()

    def drain() -> None:
        if proc.stdout is None:  # cannot happen with stdout=PIPE; keeps the type checker honest
            return
        for raw in proc.stdout:
            line = _ANSI_RE.sub("", raw).rstrip()
            tail.append(line)
            match = _URL_RE.search(line)
            if match and not found:
                found.append(match.group(1))
                ready.set()
        ready.set()  # output closed: the process is gone

    threading.Thread(target=drain, name="rerun-web-viewer-output", daemon=True).start()
    ready.wait(timeout_s)
    if not found:
        stop_viewer(proc)
        last = " | ".join(line for line in tail if line) or "no output"
        raise WashbenchError(located(path, f"the rerun web viewer did not start: {last}"))
    return proc, found[0]


def stop_viewer(proc: subprocess.Popen[str], timeout_s: float = 10.0) -> None:
    """Terminate a viewer started by :func:`start_web_viewer` (SIGTERM, then SIGKILL after ``timeout_s``)."""
    if proc.poll() is None:
        proc.terminate()
        try:
            proc.wait(timeout_s)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait(timeout_s)


def replay_command(paths: Path | list[Path], web: bool) -> int:
    """Open one recording, or the comparison of two (:mod:`washbench.review.compare`), in the rerun viewer.

    The native viewer where a display exists (a macOS or Windows desktop, or DISPLAY / WAYLAND_DISPLAY set) and
    ``web`` is false; otherwise the web viewer on 127.0.0.1 with system-chosen ports, whose address is printed; it
    runs until Ctrl-C (status 130, as any command). Returns the exit status. The comparison recording lives in a
    temporary folder removed when the viewer stops. SIGTERM stops the viewer too (status 143), and a viewer
    outlives washbench in no case (Linux: not even a SIGKILL of washbench, through the parent-death signal).
    """
    files = [Path(p) for p in (paths if isinstance(paths, list) else [paths])]
    if len(files) not in (1, 2):
        raise WashbenchError(f"replay: expected one recording, or two to compare, got {len(files)}")
    for f in files:
        check_recording(f)
    if len(files) == 1:
        return _replay(files[0], web)
    import tempfile

    from washbench.review.compare import write_comparison  # deferred: rerun

    with tempfile.TemporaryDirectory(prefix="washbench-compare-") as tmp:
        out = Path(tmp) / "comparison.rrd"
        left_out = write_comparison(files[0], files[1], out)
        print(f"washbench: comparing {files[0]} with {files[1]}", flush=True)
        for note in left_out:
            print(f"washbench: note: {printable(note)}", flush=True)
        return _replay(out, web)


def _replay(path: Path, web: bool) -> int:
    if not web and _has_display():
        return subprocess.run([str(find_rerun()), "--bind", "127.0.0.1", str(path)], check=False).returncode
    proc, url = start_web_viewer(path)
    print(f"washbench: rerun web viewer for {path} at {url}", flush=True)
    print("washbench: open it in a browser on this machine (or forward both ports); Ctrl-C stops it", flush=True)
    try:
        while proc.poll() is None:
            time.sleep(0.2)
    finally:  # Ctrl-C goes on to the command's handler: "washbench: interrupted", status 130
        with contextlib.suppress(ProcessLookupError):
            stop_viewer(proc)
    return proc.returncode
