"""Size and write time of the rerun recording, per step, for one bundled manoeuvre.

    .venv/bin/python bench/recording_bench.py [--manoeuvre c172/takeoff] [--repeat 3]

Flies the manoeuvre once (``washbench run``), then rewrites its recording ``--repeat`` times from the same data and
prints: bytes per step of the .rrd, the uncompressed bytes per step by part (row ids, times, values; by entity
group), and the write time against bare JSBSim ``fdm.run()`` for the same number of steps, measured in this run.
"""

from __future__ import annotations

import argparse
import collections
import os
import tempfile
import time
from pathlib import Path

from washbench.io.paths import MANOEUVRES_DIR


def bare_jsbsim_s(steps: int) -> float:
    """Wall time of ``steps`` bare ``fdm.run()`` calls on c172p at 120 Hz (air start, untrimmed)."""
    os.environ.setdefault("JSBSIM_DEBUG", "0")
    import jsbsim

    fdm = jsbsim.FGFDMExec(jsbsim.get_default_root_dir())
    fdm.load_model("c172p")
    fdm.set_dt(1.0 / 120.0)
    fdm["ic/h-sl-ft"] = 4000.0
    fdm["ic/vc-kts"] = 100.0
    fdm.run_ic()
    start = time.perf_counter()
    for _ in range(steps):
        fdm.run()
    return time.perf_counter() - start


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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--manoeuvre", default="c172/takeoff", help="bundled manoeuvre, e.g. columbia400/aerobatics")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    import washbench.runs.pipeline as pipeline
    from washbench.review import rerun_log

    captured: list[tuple[Path, object]] = []
    original = rerun_log.write_recording

    def capture(path: Path, data: object, properties: dict[str, str] | None = None) -> None:
        captured.append((Path(path), data))
        original(path, data, properties)  # type: ignore[arg-type]

    rerun_log.write_recording = capture  # type: ignore[assignment]
    with tempfile.TemporaryDirectory() as tmp:
        summary = pipeline.run_manoeuvre(MANOEUVRES_DIR / f"{args.manoeuvre}.yaml", Path(tmp))
        rerun_log.write_recording = original
        (_, data) = captured[0]
        steps = summary.steps
        best = float("inf")
        out = Path(tmp) / "again.rrd"
        for _ in range(args.repeat):
            start = time.perf_counter()
            original(out, data)  # type: ignore[arg-type]
            best = min(best, time.perf_counter() - start)
        size = out.stat().st_size
        jsb = bare_jsbsim_s(steps)
        print(f"{args.manoeuvre}: {steps} steps")
        print(f"  recording: {size / 1e6:.2f} MB, {size / steps:.0f} B/step")
        print(f"  write time: {best:.3f} s (best of {args.repeat}) = {best / jsb:.2f}x bare JSBSim ({jsb:.3f} s)")
        breakdown(out, steps)


if __name__ == "__main__":
    main()
