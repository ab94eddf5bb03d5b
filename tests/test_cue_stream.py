"""washbench cue in chunks (stream_cue): the table, metrics and saturations of the whole-trace path, bit for bit."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

from washbench.cueing.variants import select_washouts
from washbench.io.motion import Motion
from washbench.io.progress import Progress
from washbench.platform import load_platform_limits
from washbench.runs.chain import cue_motion, stream_cue

DT_S = 1.0 / 120.0


def motion(n: int) -> Motion:
    """A manoeuvre-like input that drives the washouts into their limits (tilt rate, stage position)."""
    t = np.arange(n) * DT_S
    f = np.column_stack([1.5 * np.sin(0.3 * t) + 0.3 * np.sin(7.1 * t), 0.8 * np.sin(0.17 * t + 1.0),
                         -9.80665 * (1.0 + 0.3 * np.sin(0.11 * t))])  # fmt: skip
    w = np.radians(np.column_stack([15.0 * np.sin(0.5 * t), 5.0 * np.sin(0.23 * t + 0.4), 3.0 * np.sin(0.07 * t)]))
    return Motion(t_s=t, dt_s=DT_S, f_mps2=f, omega_radps=w, extra={"altitude_ft": 3000.0 + t})


@pytest.mark.parametrize("filter_start", ["steady", "rest"])
def test_chunks_give_the_whole_trace_bit_for_bit(tmp_path: Path, filter_start: str) -> None:
    m = motion(6000)
    specs = select_washouts(None, (), None)
    limits = load_platform_limits(None)
    whole = cue_motion(m, specs, None, limits, filter_start=filter_start)
    path = tmp_path / "traces.parquet"
    streamed = stream_cue(m, specs, limits, path, filter_start=filter_start, chunk_rows=777)  # uneven chunks
    table = pq.read_table(path)
    assert table.num_rows == m.n
    assert pq.ParquetFile(path).num_row_groups == math.ceil(m.n / 777)
    expected = whole.columns()
    assert table.column_names == list(expected)
    for name, values in expected.items():
        x, y = table.column(name).to_numpy(), np.ma.filled(values, np.nan)  # (an empty tilt rate: NaN)
        assert np.array_equal(x, y, equal_nan=x.dtype.kind == "f"), name
    assert [(r.washout, r.dof) for r in streamed.metrics] == [(r.washout, r.dof) for r in whole.metrics]
    for a, b in zip(streamed.metrics, whole.metrics, strict=True):
        for attr in ("npc", "integral_error", "max_error", "msdv_mps15", "msi_pct", "msi_aircraft_pct"):
            x, y = getattr(a, attr), getattr(b, attr)
            assert x == y or (math.isnan(x) and math.isnan(y)), (a, attr)
    counts = {w: dict(tr.saturation_counts) for w, tr in whole.traces.items()}
    assert {w: dict(tr.saturation_counts) for w, tr in streamed.traces.items()} == counts
    assert counts["small-angle"]["tilt_rate"] > 0 and counts["unrestricted"]["pos"] > 0  # limits exercised
    for w, tr in whole.traces.items():  # what the recording and the report are given
        for field in ("head_f_mps2", "head_omega_radps", "q", "pos_m", "vel_mps", "acc_mps2", "wheel_radps"):
            assert np.array_equal(getattr(streamed.traces[w], field), getattr(tr, field)), (w, field)
        for kind, flags in tr.saturated.items():
            assert np.array_equal(streamed.traces[w].saturated[kind], flags), (w, kind)
    assert streamed.review_table().keys() == whole.review_table().keys()


def test_one_row_chunks_written_beside_the_next_one_are_not_overwritten(tmp_path: Path) -> None:
    """Rows of one sample are contiguous views into the chunk buffer, which pyarrow takes without a copy; the
    traces' writer thread still reads a chunk while the next is cued (write_trace_chunks), so a buffer reused at
    once would be written over. The table must still be the whole-trace path's."""
    m = motion(40)
    specs = select_washouts(None, (), None)
    limits = load_platform_limits(None)
    path = tmp_path / "traces.parquet"
    stream_cue(m, specs, limits, path, chunk_rows=1)
    table = pq.read_table(path)
    assert pq.ParquetFile(path).num_row_groups == m.n
    for name, values in cue_motion(m, specs, None, limits).columns().items():
        x, y = table.column(name).to_numpy(), np.ma.filled(values, np.nan)  # (an empty tilt rate: NaN)
        assert np.array_equal(x, y, equal_nan=x.dtype.kind == "f"), name


def test_progress_lines_when_stderr_is_not_a_terminal(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """In a log, a plain line per tenth of the work, with the expected end (:mod:`washbench.io.progress`); the
    clock here advances 1 s per reading: the first 1000 rows took 2 s when the line is made, so 2000 take 4 s."""
    monkeypatch.setattr("washbench.io.progress.QUIET_FOR_S", 0.0)
    m = motion(3000)
    ticks = iter(range(100))
    shown = Progress("cue", m.n, clock=lambda: float(next(ticks)), wall=lambda: 0.0, tty=False)
    stream_cue(m, select_washouts(None, (), None), load_platform_limits(None), tmp_path / "t.parquet",
               chunk_rows=1000, progress=shown)  # fmt: skip
    shown.close()
    lines = capsys.readouterr().err.splitlines()
    assert [line.split(",")[0] for line in lines] == ["cue:  33% (1", "cue:  67% (2", "cue: 100% (3"]
    assert lines[0].startswith("cue:  33% (1,000 of 3,000 rows), expected end ") and lines[0].endswith("(in 4 s)")
    assert lines[-1].endswith("done in 6 s")
