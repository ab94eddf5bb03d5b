"""``washbench replay``: bad files are one-line errors; the web viewer really serves (loopback only, bounded time)."""

from __future__ import annotations

import os
import queue
import re
import signal
import subprocess
import sys
import threading
import time
import urllib.error
import urllib.request
from pathlib import Path

import inprocess
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from washbench.cli import main
from washbench.errors import WashbenchError
from washbench.review.replay import check_recording, find_rerun, start_web_viewer, stop_viewer
from washbench.review.rerun_log import MotionSeries, PlatformEnvelope, PlatformSeries, RecordingData, write_recording

HTTP_TIMEOUT_S = 10.0


@pytest.fixture(scope="module")
def recording(tmp_path_factory: pytest.TempPathFactory) -> Path:
    n = 240
    rng = np.random.default_rng(3)
    t = np.arange(n) / 120.0

    def motion() -> MotionSeries:
        q = Rotation.from_rotvec(rng.normal(0, 0.2, (n, 3))).as_quat(scalar_first=True)
        return MotionSeries(*(rng.normal(size=(n, 3)) for _ in range(4)), q=q)

    platform = PlatformSeries(*(rng.normal(0, 0.3, (n, 3)) for _ in range(4)), saturated={"pos": np.zeros(n, bool)})
    data = RecordingData(
        title="c172p / replay test",
        t_s=t,
        aircraft=motion(),
        washouts={"small-angle": motion()},
        platforms={"small-angle": platform},
        envelope=PlatformEnvelope(pos_m=1.5, vel_mps=1.5, acc_mps2=9.81, wheel_radps=40.0),
        phases=[("hold", 0.0, float(t[-1]))],
        metrics_markdown="| metric | value |\n|---|---|\n| NPC | 0.9 |\n",
    )
    path = tmp_path_factory.mktemp("replay") / "recording.rrd"
    write_recording(path, data)
    return path


def run_cli(*args: str) -> subprocess.CompletedProcess[str]:
    return inprocess.washbench(*args, timeout=60)


def assert_one_line_error(out: subprocess.CompletedProcess[str], *needles: str) -> None:
    assert out.returncode == 2
    assert "Traceback" not in out.stderr
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("washbench: error: "), out.stderr
    for needle in needles:
        assert needle in lines[0]


def test_missing_file(tmp_path):
    assert_one_line_error(run_cli("replay", str(tmp_path / "nope.rrd")), "nope.rrd", "no such file")


def test_not_an_rrd_by_name(tmp_path):
    path = tmp_path / "metrics.csv"
    path.write_text("dof,npc\nsurge,0.9\n")
    assert_one_line_error(run_cli("replay", str(path)), "metrics.csv", "not an .rrd file")


def test_not_an_rrd_by_content(tmp_path):
    path = tmp_path / "fake.rrd"
    path.write_text("this is not a recording\n")
    assert_one_line_error(run_cli("replay", str(path)), "fake.rrd", "not a rerun recording")


def test_directory_is_rejected(tmp_path):
    folder = tmp_path / "dir.rrd"
    folder.mkdir()
    with pytest.raises(WashbenchError, match="not a file"):
        check_recording(folder)


def test_truncated_recording_is_corrupt(recording, tmp_path, capsys):
    data = recording.read_bytes()
    path = tmp_path / "cut.rrd"
    path.write_bytes(data[: len(data) * 2 // 3])
    assert main(["replay", "--web", str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "cut.rrd: corrupt recording:" in err[0], err


def test_good_recording_passes_the_check(recording):
    check_recording(recording)


def test_rerun_executable_is_the_bundled_binary():
    exe = find_rerun()
    out = subprocess.run([str(exe), "--version"], capture_output=True, text=True, timeout=60, check=False)
    assert out.returncode == 0 and "0.41" in out.stdout


def http_get(url: str) -> tuple[int, bytes]:
    with urllib.request.urlopen(url, timeout=HTTP_TIMEOUT_S) as resp:
        return resp.status, resp.read()


def test_web_viewer_serves_on_loopback(recording):
    proc, url = start_web_viewer(recording, timeout_s=60)
    try:
        match = re.match(r"http://127\.0\.0\.1:(\d+)\?url=rerun%2Bhttp%3A%2F%2Flocalhost%3A(\d+)%2Fproxy$", url)
        assert match, url
        status, body = http_get(f"http://127.0.0.1:{match.group(1)}/")
        assert status == 200 and b"<html" in body.lower() and b"rerun" in body.lower()
    finally:
        stop_viewer(proc)
    assert proc.returncode is not None
    with pytest.raises((urllib.error.URLError, ConnectionError)):
        http_get(f"http://127.0.0.1:{match.group(1)}/")


def test_cli_without_display_serves_the_web_viewer_until_interrupted(recording):
    """``washbench replay FILE`` with no DISPLAY: prints the address, serves it, stops cleanly on Ctrl-C (SIGINT),
    saying so, with status 130."""
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    proc = subprocess.Popen(
        [sys.executable, "-m", "washbench", "replay", str(recording)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    )
    lines: queue.Queue[str] = queue.Queue()
    threading.Thread(target=lambda: [lines.put(line) for line in proc.stdout], daemon=True).start()
    try:
        url = None
        deadline = time.monotonic() + 60
        while url is None and time.monotonic() < deadline:
            try:
                line = lines.get(timeout=1)
            except queue.Empty:
                assert proc.poll() is None, proc.stderr.read()
                continue
            found = re.search(r"web viewer for .* at (http://127\.0\.0\.1:\d+)\S*", line)
            url = found.group(1) if found else None
        assert url is not None, "no address printed within 60 s"
        status, _ = http_get(url + "/")
        assert status == 200
        proc.send_signal(signal.SIGINT)
        assert proc.wait(timeout=30) == 130  # as every command after Ctrl-C (issue 26, item 8)
        assert "washbench: interrupted" in proc.stderr.read()
        with pytest.raises((urllib.error.URLError, ConnectionError)):
            http_get(url + "/")  # the viewer went down with the command
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait(10)


@pytest.mark.parametrize(("sig", "status"), [(signal.SIGTERM, 143), (signal.SIGKILL, -9)])
def test_the_web_viewer_stops_with_washbench_however_it_is_stopped(recording, sig, status):
    """SIGTERM (and on Linux even SIGKILL) of ``washbench replay`` takes the viewer it started down with it."""
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    proc = subprocess.Popen(
        [sys.executable, "-m", "washbench", "replay", "--web", str(recording)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    )
    try:
        line = proc.stdout.readline()  # the address, once the viewer serves
        found = re.search(r"at (http://127\.0\.0\.1:\d+)", line)
        assert found, line + proc.stderr.read()
        url = found.group(1)
        proc.send_signal(sig)
        assert proc.wait(timeout=30) == status
        if sig == signal.SIGTERM:
            assert proc.stderr.read().strip() == "washbench: terminated"
        deadline = time.monotonic() + 15
        while time.monotonic() < deadline:
            try:
                http_get(url + "/")
            except (urllib.error.URLError, ConnectionError):
                break
            time.sleep(0.2)
        else:
            pytest.fail("the viewer still serves after washbench ended")
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait(10)
