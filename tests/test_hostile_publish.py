"""Hardening, second round (issue 25): sweep, tune, omct and examples publish their result set whole.

``cue``'s set is signalled at every file in ``test_hostile_round2.py``; here each other command that builds a set
in a stage is signalled as its first and (but omct) as its last new file lands (SIGINT, SIGTERM), and run with a
file-size limit (a full disk): the folder then holds exactly the previous set (or, had the signal come during the
swap, the new one, whole), one line names the file, and nothing of the stage is left. The suite is signalled the
moment its process server appears (the worker start).
"""

from __future__ import annotations

import hashlib
import os
import re
import resource
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from hostile import assert_clean_error, live_processes, long_suite, short, tree, washbench

from washbench.io.outfolder import JOURNAL_PREFIX, MANIFEST, OLD_PREFIX, STAGE_PREFIX
from washbench.io.paths import MANOEUVRES_DIR

MANOEUVRE = MANOEUVRES_DIR / "c172" / "aileron_3211.yaml"


def digest(folder: Path) -> dict[str, str]:
    """Every file under ``folder`` (the manifest excepted: it records the time) -> SHA-256 of its bytes."""
    return {
        str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(folder.rglob("*"))
        if p.is_file() and p.name != MANIFEST
    }


def leftovers(out: Path) -> list[str]:
    return [p for p in os.listdir(out) if p.startswith((STAGE_PREFIX, OLD_PREFIX, JOURNAL_PREFIX))]


@pytest.fixture(scope="module")
def flights(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A short manoeuvre flown once (``--from`` for the sweeps and tunes below); its file beside the flights."""
    root = tmp_path_factory.mktemp("flights")
    m = short(root, name="brief", seconds=5)
    proc = washbench("sweep", m, "--set", "tilt.gain_per_s=1", "--out", root / "sweep", "--quiet", timeout=120)
    assert proc.returncode == 0, proc.stderr
    return root / "sweep" / "flights"


def commands(flights: Path) -> dict[str, tuple[object, ...]]:
    """Each command's arguments (without --out), small enough to run in a few seconds."""
    m = flights.parent.parent / "brief.yaml"
    return {
        "sweep": ("sweep", m, "--set", "tilt.gain_per_s=1,2", "--from", flights, "--quiet"),
        "tune": ("tune", m, "--washout", "small-angle", "--tune", "tilt.gain_per_s=1:2", "--budget", "6",
                 "--from", flights, "--quiet"),
        "omct": ("omct", "--washout", "small-angle", "--rate-hz", "30", "--quiet"),
    }


@pytest.fixture(scope="module")
def previous(flights: Path, tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """Each command's complete result set, the previous set a signalled or failing run must leave whole."""
    out = {}
    for name, args in commands(flights).items():
        folder = tmp_path_factory.mktemp(name) / "out"
        proc = washbench(*args, "--out", folder, timeout=120)
        assert proc.returncode == 0, proc.stderr
        out[name] = folder
    return out


def _copy(folder: Path, dest: Path) -> Path:
    subprocess.run(["cp", "-a", str(folder), str(dest)], check=True)
    return dest


def _staged(out: Path) -> int:
    """Files in the command's staging folders now; a folder swapped in or removed while they are counted (the set
    just published) counts what was seen of it."""
    count = 0
    for stage in out.glob(STAGE_PREFIX + "*"):
        for folder, _, names in os.walk(stage):  # os.walk skips a folder gone meanwhile (rglob raised)
            count += sum(1 for name in names if os.path.isfile(os.path.join(folder, name)))
    return count


@pytest.mark.slow
@pytest.mark.parametrize("command", ["sweep", "tune", "omct"])
def test_a_signal_as_the_first_or_last_file_lands_leaves_one_whole_set(
    command: str, flights: Path, previous: dict[str, Path], tmp_path: Path
) -> None:
    base = previous[command]
    expected = digest(base)
    files = len(expected)
    assert files >= 3
    moments = ((1, signal.SIGINT), (files, signal.SIGTERM))
    if command == "omct":  # its Bode plots cost seconds each: the first file only (one plot new, the rest old)
        moments = moments[:1]
    for n, sig in moments:
        out = _copy(base, tmp_path / f"out{n}")
        proc = subprocess.Popen(
            [sys.executable, "-m", "washbench", *map(str, commands(flights)[command]), "--out", str(out)],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        deadline = time.monotonic() + 120
        while proc.poll() is None and _staged(out) < n and time.monotonic() < deadline:
            time.sleep(0.001)
        if proc.poll() is None:
            proc.send_signal(sig)
        _, err = proc.communicate(timeout=60)
        assert "Traceback" not in err, err
        after = digest(out)
        if proc.returncode == 0:  # the set was published before the signal: the new one, whole
            assert set(after) == set(expected), (command, n)
        else:
            assert proc.returncode in (130, 143), (command, n, err)
            assert after == expected, (command, n, sorted(set(after) ^ set(expected)))
        assert leftovers(out) == [], (command, n)
        assert not [p for p in tree(out) if p.endswith(".tmp")], (command, n)


def _file_size_limit(limit: int):  # a preexec_fn
    def apply() -> None:
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # writes beyond the limit fail with EFBIG, like a full disk
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

    return apply


@pytest.mark.parametrize("command", ["tune", "omct"])
def test_a_full_disk_leaves_the_previous_set_whole(
    command: str, flights: Path, previous: dict[str, Path], tmp_path: Path
) -> None:
    base = previous[command]
    out = _copy(base, tmp_path / "out")
    before = digest(out)
    biggest = max((p for p in base.rglob("*") if p.is_file()), key=lambda p: p.stat().st_size)
    proc = subprocess.run(
        [sys.executable, "-m", "washbench", *map(str, commands(flights)[command]), "--out", str(out)],
        capture_output=True,
        text=True,
        timeout=120,
        preexec_fn=_file_size_limit(biggest.stat().st_size // 2),
    )
    assert_clean_error(proc, str(out))
    assert digest(out) == before  # the previous set stands, whole
    assert leftovers(out) == [] and not [p for p in tree(out) if p.endswith(".tmp")]


def test_examples_on_a_full_disk_is_one_line_and_a_rerun_then_works(tmp_path: Path) -> None:
    dest = tmp_path / "mine"
    proc = subprocess.run(
        [sys.executable, "-m", "washbench", "examples", str(dest)],
        capture_output=True,
        text=True,
        timeout=60,
        preexec_fn=_file_size_limit(2000),  # smaller than several bundled manoeuvre files
    )
    assert_clean_error(proc, str(dest))
    assert not dest.exists() or tree(dest) == []  # nothing half-copied
    again = washbench("examples", dest, timeout=60)
    assert again.returncode == 0, again.stderr
    assert (dest / "manoeuvres" / "c172" / "aileron_3211.yaml").read_bytes() == MANOEUVRE.read_bytes()


def test_a_suite_signalled_as_its_workers_start_stops_in_one_line(tmp_path: Path) -> None:
    """SIGINT the moment the process server exists (the workers are being started): one line, status 130, no
    process left, nothing new in --out (the race the first round found at 0.35 s)."""
    proc = long_suite(tmp_path)
    out = tmp_path / "out"
    deadline = time.monotonic() + 60
    while len(live_processes(proc.pid)) < 2 and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.001)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    last = err.strip().splitlines()[-1]
    lost = (f"washbench: interrupted: 0 of 2 manoeuvres had finished; their runs are discarded and nothing was "
            f"written to {out} (nothing was left there)")  # once the runs had begun (issue 52, item 6d)
    assert "Traceback" not in err and last in ("washbench: interrupted", lost), err
    deadline = time.monotonic() + 10
    while (left := live_processes(proc.pid)) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert left == []
    assert not out.exists() or tree(out) == []


def test_a_forced_big_sweep_says_its_size_and_estimated_time_first(flights: Path, tmp_path: Path) -> None:
    """A grid beyond the bound needs --force, and then says, even with --quiet, its size and an estimated time
    (its first points timed) before the evaluations; the estimate is within a factor of 10 of the time taken."""
    m = flights.parent.parent / "brief.yaml"
    xs = ",".join(str(0.5 + 0.01 * i) for i in range(45))
    args = ("sweep", m, "--washout", "small-angle", "--set", f"translational_highpass_wn_radps.x={xs}",
            "--set", f"translational_highpass_wn_radps.y={xs}", "--from", flights, "--quiet")  # fmt: skip
    proc = washbench(*args, "--out", tmp_path / "refused", timeout=60)
    assert_clean_error(proc, "2025 points", "--force")
    proc = washbench(*args, "--force", "--out", tmp_path / "out", timeout=120)
    assert proc.returncode == 0, proc.stderr
    said = re.search(r"^sweep: 2025 candidate\(s\) x 1 flight\(s\) \(\d+ samples in all\): about (\d+) (s|min)",
                     proc.stderr, re.M)  # fmt: skip
    assert said, proc.stderr
    estimate_s = float(said[1]) * (60 if said[2] == "min" else 1)
    taken_s = float(re.search(r"evaluations \(.*\) in ([\d.]+) s", proc.stdout)[1])
    assert estimate_s <= 10 * taken_s + 1 and taken_s <= 10 * estimate_s + 1, (estimate_s, taken_s)
