"""tools/screenshot.py: a real native-viewer screenshot under Xvfb (skipped without the apt packages)."""

from __future__ import annotations

import struct
import subprocess
import sys
from pathlib import Path

import pytest
from test_rerun_log import make_data

from washbench.review.rerun_log import write_recording

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tools"))
import screenshot  # noqa: E402


def test_missing_packages_are_named_with_exit_status_2(monkeypatch, capsys, tmp_path):
    monkeypatch.setattr(screenshot.shutil, "which", lambda name: None)
    assert screenshot.main([str(tmp_path / "r.rrd"), str(tmp_path / "o.png")]) == 2
    err = capsys.readouterr().err
    assert "Xvfb (package xvfb)" in err and "apt-get install -y xvfb" in err
    assert not (tmp_path / "o.png").exists()


@pytest.mark.skipif(bool(screenshot.missing_requirements()), reason="needs xvfb and mesa-vulkan-drivers (apt)")
def test_screenshot_of_a_tab_in_the_light_theme(tmp_path):
    rrd = tmp_path / "r.rrd"
    write_recording(rrd, make_data(n=240))
    out = tmp_path / "shot.png"
    proc = subprocess.run(
        [sys.executable, str(ROOT / "tools" / "screenshot.py"), str(rrd), str(out), "--tab", "envelope",
         "--time", "1.0", "--theme", "light", "--size", "640x360"],
        capture_output=True, text=True, timeout=180, check=False,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    head = out.read_bytes()[:24]
    assert head[:8] == b"\x89PNG\r\n\x1a\n"
    width, height = struct.unpack(">II", head[16:24])
    assert (width, height) in ((640, 360), (1280, 720))  # the window size, or twice it at the viewer's scale 2
    try:
        from PIL import Image
    except ImportError:  # Pillow is not a dependency; the theme is checked where it happens to be installed
        return
    corner = Image.open(out).convert("RGB").getpixel((width - 4, height // 2))
    assert min(corner) > 200  # light theme: a near-white background
