"""Cost of ``washbench cue`` on a 30-minute 120 Hz recording (216,000 rows), stage by stage.

    .venv/bin/python bench/cue_bench.py [--minutes 30]

Baselines measured in the same run, printed as ratios:

* reading the input: ``read_motion`` (with validation) against a bare ``pyarrow.csv.read_csv`` of the same file;
* vestibular models: one pilot's otolith + canal models (discretised parallel first-order sections,
  ``lfilter`` over axis 0) against ``scipy.signal.lsim`` of the continuous transfer functions on the same 6 axes;
* whole command: read + cue_trace + analyse + write against the bare CSV read;
* the ``washbench cue`` command itself (its own process, start-up included) against bare JSBSim ``fdm.run()``
  for as many steps as the input has rows (c172p in the air, this process), minimum of ``--repeat`` runs; as it
  is, without the recording, without the figures, without both; and the cost of one more row without both (an
  input twice as long minus this one, against bare JSBSim the same way: start-up cancels). Two ratios each:

  - wall time, what the user waits for (issue 39's aims: at most 2.0x with every output, at most 1.0x with
    ``--no-recording --no-figures``). The command writes the traces in a thread beside the cueing and draws the
    figures in child processes beside the cueing and the recording (:mod:`washbench.runs.beside`), so on two
    cores its wall time is less than its CPU time. Bare JSBSim runs on one core: its wall time is its CPU time
    (both are timed; the ratio is over its wall time). On a loaded machine wall times count other processes:
    run it on a quiet one.
  - CPU time (the command's process and its children), the work done, steadier on a shared machine.
"""

from __future__ import annotations

import argparse
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.csv as pacsv
import scipy.signal
from baseline import DT_S, best_of, c172p_in_air, run_cpu_s, run_wall_s

from washbench.cueing import WASHOUT_NAMES, cue_trace, load_washout_params
from washbench.cueing.variants import select_washouts
from washbench.io.motion_file import read_motion
from washbench.io.pages import small_pages
from washbench.perception import VestibularModel
from washbench.perception.vestibular import CanalParams, OtolithParams, canal_tf, otolith_tf
from washbench.platform import load_platform_limits
from washbench.runs.chain import analyse, stream_cue, write_results


def write_input(path: Path, n: int) -> None:
    t = np.arange(n) * DT_S
    cols = {
        "t_s": t,
        "f_x_mps2": 1.5 * np.sin(0.3 * t) + 0.3 * np.sin(7.1 * t),
        "f_y_mps2": 0.8 * np.sin(0.17 * t + 1.0),
        "f_z_mps2": -9.80665 * (1.0 + 0.3 * np.sin(0.11 * t)),
        "omega_x_degps": 15.0 * np.sin(0.5 * t),
        "omega_y_degps": 5.0 * np.sin(0.23 * t + 0.4),
        "omega_z_degps": 3.0 * np.sin(0.07 * t),
        "altitude_ft": 3000.0 + t,
    }
    pacsv.write_csv(pa.table(cols), path)


def command_s(src: Path, out: Path, *extra: str) -> tuple[float, float]:
    """(wall, CPU) time of one ``washbench cue`` process on ``src`` (``extra``: more options); CPU: user + system,
    of the command and the children it waited for (its figures' processes)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-m", "washbench", "cue", str(src), "--out", str(out), *extra], check=True,
                   stdout=subprocess.DEVNULL)  # fmt: skip
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def best(runs: list[tuple[float, float]]) -> tuple[float, float]:
    """The shortest wall time and the least CPU time of several runs (each its own minimum)."""
    return min(w for w, _ in runs), min(c for _, c in runs)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--minutes", type=float, default=30.0)
    ap.add_argument("--repeat", type=int, default=3, help="runs of the command and of bare JSBSim (minimum)")
    args = ap.parse_args()
    small_pages()  # as a washbench command does (washbench.io.pages): the stages timed in this process
    n = round(args.minutes * 60 / DT_S)
    params, limits = load_washout_params(None), load_platform_limits(None)
    with tempfile.TemporaryDirectory() as tmp:
        src = Path(tmp) / "in.csv"
        write_input(src, n)
        t_bare = best_of(lambda: pacsv.read_csv(src))
        t_read = best_of(lambda: read_motion(src))
        motion = read_motion(src)
        cue_trace(motion.f_mps2[:10], motion.omega_radps[:10], DT_S, WASHOUT_NAMES, params, limits)  # compile
        t_cue = best_of(lambda: cue_trace(motion.f_mps2, motion.omega_radps, DT_S, WASHOUT_NAMES, params, limits), 1)
        traces = cue_trace(motion.f_mps2, motion.omega_radps, DT_S, WASHOUT_NAMES, params, limits)
        t_analyse = best_of(lambda: analyse(motion, traces))
        result = analyse(motion, traces)
        t_write = best_of(lambda: write_results(Path(tmp) / "out", result), 1)
        specs = select_washouts(None, (), None)
        short = read_motion(src)
        stream_cue(short, specs, limits, Path(tmp) / "warm.parquet", chunk_rows=100)  # kernels loaded
        t_stream = best_of(lambda: stream_cue(motion, specs, limits, Path(tmp) / "s.parquet", recording=False,
                                              figures=False), 1)  # fmt: skip

        vm = VestibularModel(DT_S)
        t_vest = best_of(lambda: vm.perceive(motion.f_mps2, motion.omega_radps))
        t = motion.t_s - motion.t_s[0]
        oto, can = otolith_tf(OtolithParams()), canal_tf(CanalParams())

        def lsim_all() -> None:
            for i in range(3):
                scipy.signal.lsim(oto, motion.f_mps2[:, i], t)
                scipy.signal.lsim(can, motion.omega_radps[:, i], t)

        t_lsim = best_of(lsim_all, 1)
        commands = {
            "with recording, report and figures": (),
            "the same, --no-recording": ("--no-recording",),
            "the same, --no-figures": ("--no-figures",),
            "the same, both": ("--no-recording", "--no-figures"),
        }
        timed = {k: best([command_s(src, Path(tmp) / f"c{j}_{i}", *extra) for i in range(args.repeat)])
                 for j, (k, extra) in enumerate(commands.items())}  # fmt: skip
        bare_wall = min(run_wall_s(c172p_in_air(), n) for _ in range(args.repeat))
        bare = min(run_cpu_s(c172p_in_air(), n) for _ in range(args.repeat))
        # the cost of more rows: the lean command on an input twice as long, minus the one above (start-up cancels)
        src2 = Path(tmp) / "in2.csv"
        write_input(src2, 2 * n)
        lean2 = best([command_s(src2, Path(tmp) / f"lean2_{i}", "--no-recording", "--no-figures")
                      for i in range(args.repeat)])  # fmt: skip
        bare2 = min(run_cpu_s(c172p_in_air(), 2 * n) for _ in range(args.repeat))

    total = t_read + t_cue + t_analyse + t_write
    print(f"{n} rows ({args.minutes:g} min at 120 Hz), 3 washouts")
    print(f"  bare pyarrow CSV read        {t_bare:7.3f} s   (baseline)")
    print(f"  read_motion (validated)      {t_read:7.3f} s   {t_read / t_bare:6.2f} x baseline")
    print(f"  cue_trace (3 washouts)       {t_cue:7.3f} s   {t_cue / t_bare:6.2f} x baseline   (whole-trace API)")
    print(f"  analyse (4 pilots, metrics)  {t_analyse:7.3f} s   {t_analyse / t_bare:6.2f} x baseline")
    print(f"  write traces + metrics       {t_write:7.3f} s   {t_write / t_bare:6.2f} x baseline")
    print(f"  total                        {total:7.3f} s   {total / t_bare:6.2f} x baseline")
    print(f"  the command's path: stream_cue (the same in 8,192-row chunks, traces.parquet as it goes) "
          f"{t_stream:.3f} s, {t_stream / t_bare:.2f} x baseline")  # fmt: skip
    print(f"  vestibular, one pilot        {t_vest:7.3f} s   (baseline: scipy.signal.lsim {t_lsim:.3f} s,", end=" ")
    print(f"{t_lsim / t_vest:.1f}x slower)")
    print(f"bare JSBSim, {n} steps: {bare_wall:.3f} s wall, {bare:.3f} s CPU (the baselines)")
    print("washbench cue command                     wall      x bare      CPU      x bare")
    for label, (wall, cpu) in timed.items():
        print(f"  {label:<38} {wall:7.3f} s {wall / bare_wall:6.2f} x  {cpu:7.3f} s {cpu / bare:6.2f} x")
    print("  aims (wall): at most 2.0x with every output, at most 1.0x with both left out")
    lean = timed["the same, both"][1]
    per_row, per_step = (lean2[1] - lean) / n, (bare2 - bare) / n
    print(f"  both, one more row  {per_row * 1e6:7.3f} us CPU {per_row / per_step:6.2f} x bare JSBSim per step "
          f"({2 * n} rows minus {n}: start-up cancels)")  # fmt: skip


if __name__ == "__main__":
    main()
