"""How many CPUs this process may use: the default of ``--jobs``.

``os.cpu_count()`` counts the machine's CPUs, not the ones a process may run on. Two limits are applied, the
smaller wins:

- the CPU affinity mask (``os.sched_getaffinity``: ``taskset``, ``docker --cpuset-cpus``, a batch scheduler's
  cpuset);
- the cgroup CPU bandwidth quota (``docker --cpus``, Kubernetes CPU limits): cgroup v2 ``cpu.max``
  (``"QUOTA PERIOD"`` or ``"max PERIOD"``) of this process's cgroup and each of its ancestors, or cgroup v1
  ``cpu.cfs_quota_us`` / ``cpu.cfs_period_us`` (quota ``-1``: none). A quota of 1.5 CPUs counts as 2 (rounded
  up, as the JVM and .NET do: one more process than whole CPUs keeps the quota busy; the kernel shares it out).
"""

from __future__ import annotations

import math
import os
from pathlib import Path

CGROUP_ROOT = Path("/sys/fs/cgroup")
PROC_CGROUP = Path("/proc/self/cgroup")


def affinity_cpus() -> int | None:
    """The number of CPUs in this process's affinity mask; None where the platform has none (macOS, Windows)."""
    getaffinity = getattr(os, "sched_getaffinity", None)
    if getaffinity is None:
        return None
    try:
        return len(getaffinity(0)) or None
    except OSError:
        return None


def _read(path: Path) -> str | None:
    try:
        return path.read_text().strip()
    except (OSError, UnicodeDecodeError):
        return None


def _v2_quota(folder: Path) -> float | None:
    """CPUs allowed by ``folder/cpu.max`` (None: no such file, ``max``, or unreadable)."""
    text = _read(folder / "cpu.max")
    if not text:
        return None
    parts = text.split()
    if len(parts) != 2 or parts[0] == "max":
        return None
    try:
        quota, period = float(parts[0]), float(parts[1])
    except ValueError:
        return None
    return quota / period if quota > 0 and period > 0 else None


def _v1_quota(folder: Path) -> float | None:
    """CPUs allowed by ``cpu.cfs_quota_us`` / ``cpu.cfs_period_us`` in ``folder`` (None: no quota)."""
    quota, period = _read(folder / "cpu.cfs_quota_us"), _read(folder / "cpu.cfs_period_us")
    try:
        q, p = float(quota or "-1"), float(period or "0")
    except ValueError:
        return None
    return q / p if q > 0 and p > 0 else None


def _min(a: float | None, b: float | None) -> float | None:
    return b if a is None else a if b is None else min(a, b)


def cgroup_cpu_limit(root: Path = CGROUP_ROOT, proc_cgroup: Path = PROC_CGROUP) -> float | None:
    """The CPU bandwidth quota of this process's cgroup, in CPUs (may be fractional); None when there is none.

    The tightest quota on the way from the process's cgroup up to the root counts (a parent's limit binds its
    children). Inside a container the cgroup path in ``/proc/self/cgroup`` may not exist under the mounted root
    (a cgroup namespace shows ``/``): the mounted root's own files count too.
    """
    text = _read(proc_cgroup)
    if text is None:
        return None
    limit: float | None = None
    for line in text.splitlines():
        parts = line.split(":", 2)
        if len(parts) != 3:
            continue
        _, controllers, path = parts
        rel = path.strip().lstrip("/")
        if controllers == "":  # cgroup v2 (unified): /sys/fs/cgroup or /sys/fs/cgroup/unified
            for base in (root, root / "unified"):
                folder = base / rel
                while True:
                    limit = _min(limit, _v2_quota(folder))
                    if folder == base or base not in folder.parents:
                        break
                    folder = folder.parent
        elif "cpu" in controllers.split(","):  # cgroup v1: /sys/fs/cgroup/cpu,cpuacct or /sys/fs/cgroup/cpu
            for name in (controllers, "cpu", "cpu,cpuacct", "cpuacct,cpu"):
                base = root / name
                folder = base / rel
                while True:
                    limit = _min(limit, _v1_quota(folder))
                    if folder == base or base not in folder.parents:
                        break
                    folder = folder.parent
    return limit


def usable_cpus() -> int:
    """CPUs this process may use: the affinity mask's count, capped by the cgroup quota (rounded up); at least 1."""
    count = affinity_cpus() or os.cpu_count() or 1
    limit = cgroup_cpu_limit()
    if limit is not None:
        count = min(count, max(1, math.ceil(limit - 1e-9)))
    return max(1, count)
