"""CPU time of each per-run figure (perceived motion, platform envelope), drawn from a result folder's files.

    .venv/bin/python bench/figure_bench.py RESULT_FOLDER [RESULT_FOLDER ...] [--repeat 5]

A result folder is what ``washbench run`` writes (e.g. ``washbench run manoeuvres/c172/takeoff.yaml --out /tmp/r``
then ``/tmp/r/c172p/takeoff``). The folder's files are read once; each figure is then drawn and written
``--repeat`` times into a scratch folder (not the result's own) after one warm-up drawing (matplotlib's imports and
font cache, paid once per process, are reported apart), and the minimum CPU time (``time.process_time``) is printed.
The aim (issue 21) is at most 0.1 s of CPU per figure. The figures land in the scratch folder named on the last line,
to be looked at.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("folders", nargs="+", type=Path)
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()

    t0 = time.process_time()
    import matplotlib.figure  # noqa: F401

    from washbench.review.figures import envelope_figure, perceived_figure
    from washbench.review.report import perception_thresholds
    from washbench.review.result_data import load_result

    print(f"imports (matplotlib, figures): {time.process_time() - t0:.3f} s CPU, once per process")
    scratch = Path(tempfile.mkdtemp(prefix="figure_bench_"))
    for folder in args.folders:
        data = load_result(folder)
        thresholds, rest = perception_thresholds(data)
        out = scratch / folder.name
        out.mkdir(parents=True, exist_ok=True)

        def perceived(data=data, out=out, thresholds=thresholds, rest=rest) -> None:  # type: ignore[no-untyped-def]
            perceived_figure(out / "perceived", data.title, data.t_s, data.perceived, phases=data.phases,
                             thresholds=thresholds, rest=rest)  # fmt: skip

        def envelope(data=data, out=out) -> None:  # type: ignore[no-untyped-def]
            envelope_figure(out / "envelope", data.title, data.t_s, data.usage, data.saturated, phases=data.phases)

        draws = {"perceived": perceived}
        if data.usage:
            draws["envelope"] = envelope
        for name, draw in draws.items():
            t0 = time.process_time()
            draw()
            first = time.process_time() - t0
            best = float("inf")
            for _ in range(args.repeat):
                t0 = time.process_time()
                draw()
                best = min(best, time.process_time() - t0)
            print(f"{data.title:32s} {data.n:7d} samples  {name:9s} first {first:.3f} s, best {best:.3f} s CPU")
    print(f"figures in {scratch}")


if __name__ == "__main__":
    main()
