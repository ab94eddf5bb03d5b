"""Screenshot a washbench recording in the native rerun viewer, headless: Xvfb plus Mesa's software Vulkan (lavapipe).

    tools/screenshot.py RECORDING.rrd OUT.png [--tab NAME] [--time S] [--theme light|dark] [--size 1920x1080]

Starts a private X server (Xvfb, first free display) and the rerun viewer bundled with rerun-sdk on it (WGPU_BACKEND
vulkan, a throw-away HOME so no user settings leak in, the theme written into that HOME's viewer settings), waits until
the recording is loaded, selects the tab whose name contains NAME (default: the first), puts the time cursor at S
seconds (default: the middle of the recording), saves the screenshot (the window size in pixels) and stops both
processes.

Needs the Debian packages ``xvfb mesa-vulkan-drivers libvulkan1 libegl1 libgl1-mesa-dri`` (see
docs/review.md); says which are missing and exits with status 2 when they are not there.
"""

from __future__ import annotations

import argparse
import ctypes.util
import os
import shutil
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

APT_PACKAGES = "xvfb mesa-vulkan-drivers libvulkan1 libegl1 libgl1-mesa-dri"
VIEWER_STATE = Path(__file__).with_name("viewer_state.ron")
"""rerun 0.41's saved viewer state (egui options and app options, no window or recording state), as the viewer writes
it on quitting, with THEME for the theme: the viewer ignores a partial file, so the whole state is kept here."""
LAVAPIPE_ICDS = ("/usr/share/vulkan/icd.d/lvp_icd.x86_64.json", "/usr/share/vulkan/icd.d/lvp_icd.aarch64.json")


def missing_requirements() -> list[str]:
    """What is missing to run the viewer headlessly (empty when everything is there)."""
    missing = []
    if shutil.which("Xvfb") is None:
        missing.append("Xvfb (package xvfb)")
    if ctypes.util.find_library("vulkan") is None:
        missing.append("the Vulkan loader (package libvulkan1)")
    if not any(Path(p).exists() for p in LAVAPIPE_ICDS):
        missing.append("Mesa's software Vulkan driver lavapipe (package mesa-vulkan-drivers)")
    return missing


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def _start_xvfb(size: str) -> tuple[subprocess.Popen[bytes], str]:
    """Xvfb on the first free display (it reports the number it took through a pipe)."""
    read_fd, write_fd = os.pipe()
    proc = subprocess.Popen(
        ["Xvfb", "-displayfd", str(write_fd), "-screen", "0", f"{size}x24", "-nolisten", "tcp"],
        pass_fds=(write_fd,),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    os.close(write_fd)
    with os.fdopen(read_fd) as fh:
        number = fh.readline().strip()
    if not number:
        proc.kill()
        raise RuntimeError("Xvfb did not start")
    return proc, f":{number}"


def _write_theme(home: Path, theme: str) -> None:
    """The viewer's saved state in a fresh HOME, with the theme preference (Light or Dark)."""
    store = home / ".local" / "share" / "rerun"
    store.mkdir(parents=True, exist_ok=True)
    state = VIEWER_STATE.read_text().replace("THEME", "Light" if theme == "light" else "Dark")
    (store / "app.ron").write_text(state)


def _wait_loaded(client: object, timeout_s: float) -> object:
    deadline = time.monotonic() + timeout_s
    state = None
    while time.monotonic() < deadline:
        try:
            state = client.get_state()  # type: ignore[attr-defined]
        except Exception:  # the viewer may not answer in its first seconds
            time.sleep(0.5)
            continue
        if state.recordings and not state.loading:
            return state
        time.sleep(0.5)
    raise RuntimeError(f"the viewer did not finish loading within {timeout_s:.0f} s")


def _select_tab(client: object, name: str) -> None:
    """Make the Tabs container show the tab (container or view) whose display name contains ``name``."""
    bp = client.get_blueprint(of="recording")  # type: ignore[attr-defined]
    doc = bp.blueprint
    names = {}
    for path, archetypes in doc.items():
        for arch in archetypes.values():
            if isinstance(arch, dict) and "display_name" in arch:
                names[path.lstrip("/")] = str(arch["display_name"])
    for arch in (a for archetypes in doc.values() for a in archetypes.values() if isinstance(a, dict)):
        if arch.get("container_kind") == "Tabs":
            for child in arch.get("contents", []):
                if name.lower() in names.get(child, "").lower():
                    arch["active_tab"] = child
                    client.set_blueprint(doc, of="recording")  # type: ignore[attr-defined]
                    return
    tabs = sorted(names.values())
    raise RuntimeError(f"no tab named like {name!r} (names: {', '.join(tabs)})")


def screenshot(rrd: Path, out: Path, *, tab: str | None, at_s: float | None, theme: str, size: str) -> None:
    """Take the screenshot (see the module docstring)."""
    from rerun.experimental import ViewerClient

    from washbench.review.replay import find_rerun

    xvfb, display = _start_xvfb(size)
    viewer = None
    try:
        with tempfile.TemporaryDirectory() as home, tempfile.TemporaryDirectory() as runtime:
            _write_theme(Path(home), theme)
            port = _free_port()
            env = {
                **os.environ,
                "DISPLAY": display,
                "WGPU_BACKEND": "vulkan",
                "HOME": home,
                "XDG_RUNTIME_DIR": runtime,
                "RERUN_ANALYTICS": "0",
            }
            env.pop("WAYLAND_DISPLAY", None)
            cmd = [str(find_rerun()), "--hide-welcome-screen", "--port", str(port), "--window-size", size, str(rrd)]
            viewer = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            deadline = time.monotonic() + 60.0
            client = None
            while client is None:
                if viewer.poll() is not None:
                    raise RuntimeError(f"the viewer exited with status {viewer.returncode}")
                try:
                    client = ViewerClient.connect(f"rerun+http://127.0.0.1:{port}/proxy")
                except Exception:
                    if time.monotonic() > deadline:
                        raise
                    time.sleep(0.5)
            state = _wait_loaded(client, 120.0)
            if tab:
                _select_tab(client, tab)
            timeline = state.recordings[0].timelines[0]
            t_s = at_s if at_s is not None else 0.5 * (timeline.start + timeline.end) * 1e-9
            client.set_time("time", duration=float(t_s), play_state="paused")
            if shutil.which("xdotool"):  # the pointer starts mid-screen, where it would raise a tooltip
                subprocess.run(["xdotool", "mousemove", "0", "0"], env=env, check=False, capture_output=True)
            time.sleep(4.0)  # let the software renderer draw a few frames
            out.parent.mkdir(parents=True, exist_ok=True)
            for attempt in range(3):  # a loaded machine's software renderer can miss the viewer's deadline
                try:
                    client.save_screenshot(str(out.resolve()))
                    break
                except TimeoutError:
                    if attempt == 2:
                        raise RuntimeError("the viewer sent no screenshot (timed out three times)") from None
                    time.sleep(5.0)
            for _ in range(40):
                if out.exists() and out.stat().st_size > 0:
                    break
                time.sleep(0.25)
    finally:
        for proc in (viewer, xvfb):
            if proc is not None and proc.poll() is None:
                proc.terminate()
                try:
                    proc.wait(10)
                except subprocess.TimeoutExpired:
                    proc.kill()
                    proc.wait(10)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("recording", type=Path, help=".rrd file")
    parser.add_argument("out", type=Path, help="PNG to write")
    parser.add_argument("--tab", help="tab to show (part of its name, e.g. 'envelope'); default the first")
    parser.add_argument("--time", type=float, dest="at_s", help="time cursor, seconds (default: the middle)")
    parser.add_argument("--theme", choices=("light", "dark"), default="dark")
    parser.add_argument("--size", default="1920x1080", help="window size in points, WIDTHxHEIGHT")
    args = parser.parse_args(argv)
    missing = missing_requirements()
    if missing:
        print(
            f"screenshot: missing {'; '.join(missing)}. Install with: apt-get install -y {APT_PACKAGES}",
            file=sys.stderr,
        )
        return 2
    if not args.recording.is_file():
        print(f"screenshot: {args.recording}: no such file", file=sys.stderr)
        return 2
    try:
        screenshot(args.recording, args.out, tab=args.tab, at_s=args.at_s, theme=args.theme, size=args.size)
    except RuntimeError as exc:
        print(f"screenshot: {args.recording}: {exc}", file=sys.stderr)
        return 1
    print(f"screenshot: wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
