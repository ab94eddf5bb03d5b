"""The default --jobs: CPUs this process may use (washbench.io.cpus), against the kernel's own affinity mask and
hand-made cgroup trees (v1 and v2, nested quotas, no quota)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from washbench.io.cpus import cgroup_cpu_limit, usable_cpus

REPO = Path(__file__).resolve().parents[1]


def write(path: Path, text: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)


def test_v2_quota_of_the_cgroup_and_the_tightest_ancestor(tmp_path: Path) -> None:
    root = tmp_path / "cg"
    write(tmp_path / "self", "0::/user.slice/job\n")
    write(root / "user.slice" / "job" / "cpu.max", "max 100000\n")
    assert cgroup_cpu_limit(root, tmp_path / "self") is None
    write(root / "user.slice" / "cpu.max", "250000 100000\n")  # the parent's 2.5 CPUs bind the child
    assert cgroup_cpu_limit(root, tmp_path / "self") == pytest.approx(2.5)
    write(root / "user.slice" / "job" / "cpu.max", "50000 100000\n")
    assert cgroup_cpu_limit(root, tmp_path / "self") == pytest.approx(0.5)


def test_v2_inside_a_namespace_uses_the_mounted_root(tmp_path: Path) -> None:
    root = tmp_path / "cg"
    write(tmp_path / "self", "0::/\n")
    write(root / "cpu.max", "150000 100000\n")
    assert cgroup_cpu_limit(root, tmp_path / "self") == pytest.approx(1.5)


def test_v1_quota_and_no_quota(tmp_path: Path) -> None:
    root = tmp_path / "cg"
    write(tmp_path / "self", "4:memory:/x\n2:cpu,cpuacct:/docker/abc\n0::/\n")
    write(root / "cpu,cpuacct" / "docker" / "abc" / "cpu.cfs_quota_us", "-1\n")
    write(root / "cpu,cpuacct" / "docker" / "abc" / "cpu.cfs_period_us", "100000\n")
    assert cgroup_cpu_limit(root, tmp_path / "self") is None
    write(root / "cpu,cpuacct" / "docker" / "abc" / "cpu.cfs_quota_us", "300000\n")
    assert cgroup_cpu_limit(root, tmp_path / "self") == pytest.approx(3.0)


def test_v1_path_not_under_the_mount_uses_the_mounted_root(tmp_path: Path) -> None:
    """A container without a cgroup namespace: /proc/self/cgroup names the host's path, the mount is the container's."""
    root = tmp_path / "cg"
    write(tmp_path / "self", "1:cpu:/docker/abc\n")
    write(root / "cpu" / "cpu.cfs_quota_us", "150000\n")
    write(root / "cpu" / "cpu.cfs_period_us", "100000\n")
    assert cgroup_cpu_limit(root, tmp_path / "self") == pytest.approx(1.5)


def test_a_quota_caps_the_count_rounded_up(monkeypatch: pytest.MonkeyPatch) -> None:
    """1.5 CPUs of quota on a machine with more allows 2 processes, 0.2 CPUs still one; no quota: the affinity mask."""
    import washbench.io.cpus as cpus

    monkeypatch.setattr(cpus, "affinity_cpus", lambda: 8)
    for quota, expected in ((None, 8), (1.5, 2), (0.2, 1), (2.0, 2), (64.0, 8)):
        monkeypatch.setattr(cpus, "cgroup_cpu_limit", lambda q=quota: q)
        assert cpus.usable_cpus() == expected, quota


def test_no_cgroup_files(tmp_path: Path) -> None:
    assert cgroup_cpu_limit(tmp_path / "none", tmp_path / "missing") is None


@pytest.mark.skipif(not hasattr(os, "sched_setaffinity"), reason="no CPU affinity on this platform")
def test_a_process_pinned_to_one_cpu_counts_one() -> None:
    """The kernel's affinity mask, set for a child process, is what the count follows (not the machine's CPUs)."""
    allowed = sorted(os.sched_getaffinity(0))
    code = "from washbench.io.cpus import usable_cpus; print(usable_cpus())"
    env = dict(os.environ, PYTHONPATH=str(REPO))
    out = subprocess.run(
        [sys.executable, "-c", code],
        env=env,
        capture_output=True,
        text=True,
        check=True,
        preexec_fn=lambda: os.sched_setaffinity(0, {allowed[0]}),
    ).stdout
    assert out.strip() == "1"
    assert usable_cpus() <= len(allowed)
