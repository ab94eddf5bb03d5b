"""CPU time of each per-run figure (perceived motion, cue lanes, platform envelope, and a cue result's input),
drawn from a result folder's files.

    .venv/bin/python bench/figure_bench.py RESULT_FOLDER [RESULT_FOLDER ...] [--repeat 5]

A result folder is what ``washbench run`` writes (e.g. ``washbench run c172/takeoff --out /tmp/r`` then
``/tmp/r/c172p/takeoff``) or ``washbench cue`` (``--out`` itself; it adds ``figures/input.png``). The folder's files
are read once; the figures are then drawn and written in the order ``washbench run``/``cue`` draws them, into a
scratch folder (not the result's own). For each figure the first drawing in this process is printed (what a
``washbench run`` pays: the first figure also pays for loading fonts and laying out the first texts) and the
minimum CPU time (``time.process_time``) of ``--repeat`` more (what a suite worker pays, drawing many results);
matplotlib's imports are printed apart (paid once per process). The aim (issue 21) is at most 0.1 s of CPU per
figure. The figures land in the scratch folder named on the last line, to be looked at.
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from collections.abc import Callable
from pathlib import Path


def _input_draw(folder: Path, out: Path) -> Callable[[], object] | None:
    """Drawing a cue result's input figure from its files (read here, once), or None for a run result."""
    import numpy as np
    import pyarrow.parquet as pq

    from washbench.io.columns import AIRCRAFT, TIME_COLUMN, f_columns, omega_columns
    from washbench.io.result_files import FIGURES_DIR, RUN_FILE, TRACES_FILE
    from washbench.review.input_figure import INPUT_STEM, input_figure

    if not (folder / FIGURES_DIR / f"{INPUT_STEM}.png").is_file():
        return None
    doc = json.loads((folder / RUN_FILE).read_text())
    cols = [TIME_COLUMN, *f_columns(AIRCRAFT), *omega_columns(AIRCRAFT)]
    table = pq.read_table(folder / TRACES_FILE, columns=cols)
    a = np.column_stack([table[c].to_numpy().astype(np.float64) for c in cols])
    title = f"{Path(str(doc.get('input', 'input'))).name} {doc.get('segment', '')}".strip()
    labels, notes = doc["input_labels"], doc.get("conversions", [])
    return lambda: input_figure(out / INPUT_STEM, title, a[:, 0], a[:, 1:4], a[:, 4:7], labels, notes)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("folders", nargs="+", type=Path)
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()

    t0 = time.process_time()
    import matplotlib.figure  # noqa: F401

    from washbench.review.cue_figures import cue_classes, cue_lane_figure
    from washbench.review.figures import envelope_figure, perceived_figure
    from washbench.review.report import perception_thresholds
    from washbench.review.result_data import load_result

    print(f"imports (matplotlib, figures): {time.process_time() - t0:.3f} s CPU, once per process")
    scratch = Path(tempfile.mkdtemp(prefix="figure_bench_"))
    worst_first, worst_best = 0.0, 0.0
    for folder in args.folders:
        data = load_result(folder)
        thresholds, rest = perception_thresholds(data)
        out = scratch / folder.name
        out.mkdir(parents=True, exist_ok=True)
        classes = cue_classes(data.perceived, data.washouts) if data.washouts else {}

        def perceived(data=data, out=out, thresholds=thresholds, rest=rest) -> None:  # type: ignore[no-untyped-def]
            perceived_figure(out / "perceived", data.title, data.t_s, data.perceived, phases=data.phases,
                             thresholds=thresholds, rest=rest)  # fmt: skip

        def cues(data=data, out=out, classes=classes) -> None:  # type: ignore[no-untyped-def]
            cue_lane_figure(out / "cues", data.title, data.t_s, classes)

        def envelope(data=data, out=out) -> None:  # type: ignore[no-untyped-def]
            envelope_figure(out / "envelope", data.title, data.t_s, data.usage, data.saturated, phases=data.phases)

        draws: dict[str, Callable[[], object]] = {}
        draw_input = _input_draw(folder, out)
        if draw_input is not None:  # a cue result draws its input figure first
            draws["input"] = draw_input
        draws["perceived"] = perceived
        if classes:
            draws["cues"] = cues
        if data.usage:
            draws["envelope"] = envelope
        firsts = {}
        for name, draw in draws.items():  # first drawings in the order the command draws them
            t0 = time.process_time()
            draw()
            firsts[name] = time.process_time() - t0
        for name, draw in draws.items():
            best = float("inf")
            for _ in range(args.repeat):
                t0 = time.process_time()
                draw()
                best = min(best, time.process_time() - t0)
            worst_first, worst_best = max(worst_first, firsts[name]), max(worst_best, best)
            print(f"{data.title:32s} {data.n:7d} samples  {name:9s} first {firsts[name]:.3f} s, best {best:.3f} s CPU")
    print(f"slowest figure: first {worst_first:.3f} s, best {worst_best:.3f} s CPU (aim: at most 0.1 s)")
    print(f"figures in {scratch}")


if __name__ == "__main__":
    main()
