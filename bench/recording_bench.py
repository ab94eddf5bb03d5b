"""Size and write time of the rerun recording, per step: one bundled manoeuvre, or ``washbench cue`` on a long input.

    .venv/bin/python bench/recording_bench.py [--manoeuvre c172/takeoff] [--repeat 3]
    .venv/bin/python bench/recording_bench.py --cue-minutes 30 [--repeat 2]

Flies the manoeuvre once (``washbench run``), or runs ``washbench cue`` in this process on a ``--cue-minutes``
120 Hz input (the one of ``bench/cue_bench.py``: 216,000 rows for 30 minutes), then rewrites its recording
``--repeat`` times from the same data and prints: bytes per step of the .rrd, the uncompressed bytes per step by part
(row ids, times, values; by entity group), the write time (wall, best of the repeats) and its CPU time (user and
system, all threads: rerun encodes and writes on its own threads) against bare JSBSim ``fdm.run()`` for the same
number of steps, measured in this run; and the same for the command's own write (the first in the process: fresh
memory, which is what a user waits for).
"""

from __future__ import annotations

import argparse
import collections
import importlib.util
import resource
import tempfile
import time
from pathlib import Path

from baseline import c172p_in_air, run_wall_s

from washbench.io.paths import MANOEUVRES_DIR


def breakdown(path: Path, steps: int) -> None:
    from rerun.chunk import RrdReader

    by_part: collections.Counter[str] = collections.Counter()
    by_group: collections.Counter[str] = collections.Counter()
    for chunk in RrdReader(str(path)).stream():
        batch = chunk.to_record_batch()
        for name, col in zip(batch.schema.names, batch.columns, strict=True):
            part = "row ids" if name.startswith("rerun.controls") else "times" if ":" not in name else "values"
            by_part[part] += col.nbytes
            by_group[chunk.entity_path.split("/")[1] or "/"] += col.nbytes
    total = sum(by_part.values())
    print(f"  uncompressed: {total / steps:7.0f} B/step")
    for k, v in by_part.most_common():
        print(f"    {k:10s} {v / steps:7.0f} B/step")
    for k, v in by_group.most_common(6):
        print(f"    /{k:9s} {v / steps:7.0f} B/step")


def _cue_bench_write_input():
    spec = importlib.util.spec_from_file_location("cue_bench", Path(__file__).with_name("cue_bench.py"))
    module = importlib.util.module_from_spec(spec)  # type: ignore[arg-type]
    spec.loader.exec_module(module)  # type: ignore[union-attr]
    return module.write_input


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--manoeuvre", default="c172/takeoff", help="bundled manoeuvre, e.g. columbia400/aerobatics")
    parser.add_argument("--cue-minutes", type=float, default=None, help="instead: `washbench cue` on a 120 Hz input")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    import washbench.runs.pipeline as pipeline
    from washbench.review import rerun_log

    captured: list[tuple[Path, object]] = []
    first: list[tuple[float, float, float]] = []  # the command's own write: wall, user, system
    original = rerun_log.write_recording

    def capture(path: Path, data: object, properties: dict[str, str] | None = None) -> None:
        captured.append((Path(path), data))
        r0, start = resource.getrusage(resource.RUSAGE_SELF), time.perf_counter()
        original(path, data, properties)  # type: ignore[arg-type]
        r1 = resource.getrusage(resource.RUSAGE_SELF)
        first.append((time.perf_counter() - start, r1.ru_utime - r0.ru_utime, r1.ru_stime - r0.ru_stime))

    rerun_log.write_recording = capture  # type: ignore[assignment]
    with tempfile.TemporaryDirectory() as tmp:
        if args.cue_minutes is None:
            label = args.manoeuvre
            pipeline.run_manoeuvre(MANOEUVRES_DIR / f"{args.manoeuvre}.yaml", Path(tmp))
        else:
            from washbench.runs.cue import run_cue

            rows = round(args.cue_minutes * 60 * 120)
            label = f"washbench cue, {args.cue_minutes:g} min at 120 Hz"
            src = Path(tmp) / "input.csv"
            _cue_bench_write_input()(src, rows)
            run_cue(src, Path(tmp) / "cue")
        rerun_log.write_recording = original
        (_, data) = captured[0]
        steps = int(data.t_s.size)  # type: ignore[attr-defined]
        best, best_cpu = float("inf"), (float("inf"), float("inf"))
        out = Path(tmp) / "again.rrd"
        for _ in range(args.repeat):
            r0 = resource.getrusage(resource.RUSAGE_SELF)
            start = time.perf_counter()
            original(out, data)  # type: ignore[arg-type]
            wall = time.perf_counter() - start
            r1 = resource.getrusage(resource.RUSAGE_SELF)
            cpu = (r1.ru_utime - r0.ru_utime, r1.ru_stime - r0.ru_stime)
            if wall < best:
                best, best_cpu = wall, cpu
        size = out.stat().st_size
        jsb = run_wall_s(c172p_in_air(), steps)
        print(f"{label}: {steps} steps")
        print(f"  recording: {size / 1e6:.2f} MB, {size / steps:.0f} B/step")
        print(f"  write time: {best:.3f} s (best of {args.repeat}) = {best / jsb:.2f}x bare JSBSim ({jsb:.3f} s)")
        print(f"  write CPU: user {best_cpu[0]:.3f} s + system {best_cpu[1]:.3f} s = "
              f"{sum(best_cpu) / jsb:.2f}x bare JSBSim")  # fmt: skip
        wall, user, system = first[0]
        print(f"  the command's own (first) write: {wall:.3f} s = {wall / jsb:.2f}x bare JSBSim; CPU user {user:.3f} s "
              f"+ system {system:.3f} s")  # fmt: skip
        breakdown(out, steps)


if __name__ == "__main__":
    main()
