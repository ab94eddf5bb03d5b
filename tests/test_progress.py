"""The progress display's expected end against the true end of a simulated pool of workers (issue 39)."""

from __future__ import annotations

import heapq
import io

import pytest

from washbench.io.progress import Progress


def pool_schedule(durations: list[float], workers: int, start_s: float) -> list[tuple[float, float]]:
    """(end time, own duration) of each job, in the order they end, for a pool of ``workers`` that each take the
    next job when free, all ready at ``start_s`` (a discrete-event simulation, independent of the display)."""
    free = [start_s] * workers
    heapq.heapify(free)
    ends = []
    for d in durations:
        t = heapq.heappop(free)
        ends.append((t + d, d))
        heapq.heappush(free, t + d)
    return sorted(ends)


@pytest.mark.parametrize("start_s", [3.0, 60.0, 300.0])  # warm, a first compile, a first compile on a loaded machine
def test_the_suite_s_expected_end_leaves_out_the_start_and_holds_within_1_5x(start_s: float) -> None:
    durations = [4.0 + (7 * i) % 9 for i in range(22)]  # 22 manoeuvres, 4-12 s each
    ends = pool_schedule(durations, 2, start_s)
    last = ends[-1][0]
    now = [0.0]
    shown = Progress("suite", len(durations), "manoeuvres", stream=io.StringIO(), tty=False,
                     clock=lambda: now[0], wall=lambda: 0.0)  # fmt: skip
    for done, (t, own_s) in enumerate(ends[:-1], start=1):
        now[0] = t
        shown.timed(own_s)
        left, at = shown.expected_end(done)
        truth = last - t
        assert at == left
        if len(durations) - done >= 2:  # while every worker has a run still to start
            assert truth / 1.5 <= left <= 1.5 * truth, (done, left, truth)
        else:  # the last run, already under way: at most one run's time off
            assert abs(left - truth) <= max(durations), (done, left, truth)


def test_without_timed_units_the_straight_line_through_the_elapsed_time() -> None:
    now = [40.0]
    shown = Progress("cue", 100, stream=io.StringIO(), tty=False, clock=lambda: now[0], wall=lambda: 1000.0)
    shown.start = 0.0
    assert shown.expected_end(25) == (120.0, 1120.0)


def test_a_cue_s_first_print_leaves_out_what_its_first_chunk_paid_once() -> None:
    """A cue of 10 chunks, 1 s each, the first one 20 s longer (a first compile): each printed estimate within 1.5x
    of the true time left (the first chunk alone is not printed: the update after it comes within the quiet time
    of a fast start, or is the first point of the line)."""
    now = [0.0]
    stream = io.StringIO()
    shown = Progress("cue", 10_000, stream=stream, tty=False, clock=lambda: now[0], wall=lambda: 0.0)
    t = 20.0
    for chunk in range(1, 11):
        t += 1.0
        now[0] = t
        if chunk >= 2:
            left, _ = shown.expected_end(chunk * 1000)
            truth = 10 - chunk
            assert truth / 1.5 <= left <= 1.5 * truth or truth == 0 == left, (chunk, left, truth)
        shown.update(chunk * 1000)
    assert "expected end" in stream.getvalue()
