"""The suite's process server: what its workers find compiled when they are forked (issue 39)."""

from __future__ import annotations

from washbench.runs.pool import worker_pool

#: The serial kernels every run calls besides the cueing step (module, name), and the number of arguments each
#: takes: the flight step, the metric sums, the sickness models, the recording's thinning.
RUN_KERNELS = {
    ("washbench.flight.stepper", "flight_step"): 2,
    ("washbench.analysis.metric_sums", "signal_metrics"): 3,
    ("washbench.perception.svc", "_run"): 8,
    ("washbench.review.thinning", "_keep"): 4,
    ("washbench.review.thinning", "_changes"): 3,
}


def test_a_worker_finds_a_run_s_kernels_compiled_before_its_first_run() -> None:
    """A worker forked from the process server has each kernel a run calls already compiled, once, for float64
    arrays and scalars (after an install each worker compiled them itself in its first run, every worker at once):
    the dispatcher in the worker's memory holds one signature, before the worker has run anything."""
    with worker_pool(1) as pool:
        for (module, name), n_args in RUN_KERNELS.items():
            expr = f"[str(s) for s in getattr(__import__({module!r}, fromlist=['_']), {name!r}).signatures]"
            signatures = pool.submit(eval, expr).result(timeout=120)
            assert len(signatures) == 1, (name, signatures)
            (signature,) = signatures
            assert signature.count("float64") + signature.count("int64") == n_args, (name, signature)
