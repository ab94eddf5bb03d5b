"""The first ``washbench run`` after an install (numba's cache empty) against the second (cache filled), timed in
the same run, and the first ``sweep`` after them (a study's evaluation compiled on top of the run's kernels).

    .venv/bin/python bench/first_run_bench.py [--manoeuvre c172/takeoff] [--repeat 2]

The cache is a new empty folder (``NUMBA_CACHE_DIR``), so the installed package's own cache is left alone. Prints
wall and CPU time (user + system, this command's processes) of the first run, the minimum of ``--repeat`` runs
with the cache filled, and their ratio (issue 39's aim: the first run at most twice the second). On a shared
machine the CPU ratio is the steadier figure; say how loaded the machine was with any figure.
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def timed(cmd: list[str], env: dict[str, str]) -> tuple[float, float]:
    """(wall s, CPU s) of one run of ``cmd``."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    done = subprocess.run(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode not in (0, 1):
        raise SystemExit(f"{' '.join(cmd)} failed ({done.returncode}): {done.stderr.strip()}")
    return wall, after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--manoeuvre", default="c172/takeoff")
    parser.add_argument("--repeat", type=int, default=2)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="wb-first-") as tmp:
        env = {**os.environ, "NUMBA_CACHE_DIR": str(Path(tmp) / "numba")}
        wb = [sys.executable, "-m", "washbench"]
        run = [*wb, "run", args.manoeuvre, "--quiet"]
        first = timed([*run, "--out", str(Path(tmp) / "first")], env)
        warm = [timed([*run, "--out", str(Path(tmp) / f"warm{i}")], env) for i in range(max(args.repeat, 1))]
        second = (min(w for w, _ in warm), min(c for _, c in warm))
        sweep = [*wb, "sweep", args.manoeuvre, "--set", "tilt.gain_per_s=1,2", "--quiet", "--out",
                 str(Path(tmp) / "sweep")]  # fmt: skip
        first_sweep = timed(sweep, env)
    print(f"cores: {os.cpu_count()}; load average at the end: {os.getloadavg()[0]:.1f}")
    print(f"first run (cache empty):  {first[0]:6.1f} s wall, {first[1]:6.1f} s CPU")
    print(f"second run (cache full):  {second[0]:6.1f} s wall, {second[1]:6.1f} s CPU (min of {len(warm)})")
    print(f"ratio first / second:     {first[0] / second[0]:6.2f} wall, {first[1] / second[1]:6.2f} CPU (aim <= 2)")
    print(f"first sweep after them:   {first_sweep[0]:6.1f} s wall, {first_sweep[1]:6.1f} s CPU")


if __name__ == "__main__":
    main()
