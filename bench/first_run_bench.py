"""The first ``washbench run`` after an install against the second, timed in the same run; and what the install's
compile costs, and the first run where nothing was compiled at install.

    .venv/bin/python bench/first_run_bench.py [--manoeuvre c172/takeoff] [--repeat 2]

Installing washbench compiles its kernels (``setup.py`` runs :mod:`washbench.numerics.precompile`). Here the cache
is a new empty folder (``NUMBA_CACHE_DIR``), so the installed package's own cache is left alone, and the steps are:

1. the first run with the cache empty (no compile at install: ``WASHBENCH_NO_PRECOMPILE``, another CPU, a
   read-only install), and the first ``sweep`` after it (a study's evaluation compiled on top of the run's
   kernels);
2. in a second empty cache, ``python -m washbench.numerics.precompile`` (what the install adds), then the first run
   after it, and the minimum of ``--repeat`` runs after that (warm).

Prints wall and CPU time (user + system, this command's processes) and the ratio of the first run after the
install to the warm one (issue 39's aim: at most 2). On a shared machine the CPU ratio is the steadier figure;
say how loaded the machine was with any figure.
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
        wb = [sys.executable, "-m", "washbench"]
        run = [*wb, "run", args.manoeuvre, "--quiet"]
        empty = {**os.environ, "NUMBA_CACHE_DIR": str(Path(tmp) / "numba-empty")}
        cold = timed([*run, "--out", str(Path(tmp) / "cold")], empty)
        sweep = [*wb, "sweep", args.manoeuvre, "--set", "tilt.gain_per_s=1,2", "--quiet", "--out",
                 str(Path(tmp) / "sweep")]  # fmt: skip
        cold_sweep = timed(sweep, empty)
        env = {**os.environ, "NUMBA_CACHE_DIR": str(Path(tmp) / "numba")}
        install = timed([sys.executable, "-m", "washbench.numerics.precompile"], env)
        first = timed([*run, "--out", str(Path(tmp) / "first")], env)
        warm = [timed([*run, "--out", str(Path(tmp) / f"warm{i}")], env) for i in range(max(args.repeat, 1))]
        second = (min(w for w, _ in warm), min(c for _, c in warm))
    print(f"cores: {os.cpu_count()}; load average at the end: {os.getloadavg()[0]:.1f}")
    print(f"nothing compiled at install: first run {cold[0]:6.1f} s wall, {cold[1]:6.1f} s CPU; "
          f"first sweep after it {cold_sweep[0]:.1f} s wall, {cold_sweep[1]:.1f} s CPU")  # fmt: skip
    print(f"the install's compile:       {install[0]:6.1f} s wall, {install[1]:6.1f} s CPU (precompile)")
    print(f"first run after the install: {first[0]:6.1f} s wall, {first[1]:6.1f} s CPU")
    print(f"warm run:                    {second[0]:6.1f} s wall, {second[1]:6.1f} s CPU (min of {len(warm)})")
    print(f"ratio first / warm:          {first[0] / second[0]:6.2f} wall, {first[1] / second[1]:6.2f} CPU (aim <= 2)")


if __name__ == "__main__":
    main()
