"""Compile washbench's numba kernels ahead of their first use: at install (``setup.py``) or by hand.

    python -m washbench.numerics.precompile [--lanes {1,2}]

Every compiled function a command calls, with the argument types the commands pass (:data:`KERNELS`), is compiled
into numba's on-disk cache (:mod:`washbench.numerics.jitcache` says where), so the first command after an install
loads machine code instead of compiling it (a first ``washbench run`` compiled for 22-28 s of CPU, measured on the
two-core development machine). Functions already in the cache are loaded, not compiled again (a few seconds in
all), so running it twice costs little.

When it runs by itself: building washbench (``pip install .``, ``pip install -e .``, ``python -m build``) runs it
on the built package (``setup.py``), so the wheel carries the cache and an editable install fills the source
tree's. numba keys each cached function on its source file's contents, its own version and the CPU it compiled
for (target, CPU name and features): on another machine, with another numba, or where the package folder is
read-only (the cache then goes to the user's cache folder), a kernel is compiled at its first use as before,
announced in one line (:func:`washbench.numerics.jitcache.announce_compile`). Run this module there to compile
them all at once.

The compiles run in two lanes, side by side in two processes where two CPUs are usable (``--lanes 1``: one after
the other in this process): the washout kernel's block step (the largest, about 18 s of CPU) and what builds on
it in one, everything else in the other.
"""

from __future__ import annotations

import argparse
import importlib
import subprocess
import sys
import time

from washbench.io.cpus import usable_cpus
from washbench.numerics.jitcache import cache_place
from washbench.numerics.lazyjit import LazyJit

#: numba type expressions (:mod:`numba.core.types`) of the arrays the commands pass: C-contiguous, writable.
F1, F2, F3 = "float64[::1]", "float64[:, ::1]", "float64[:, :, ::1]"
I1, I2 = "int64[::1]", "int64[:, ::1]"
RO1 = "Array(float64, 1, 'C', readonly=True)"
V3, Q4 = "UniTuple(float64, 3)", "UniTuple(float64, 4)"
F = "float64"
TRACE3 = f"Tuple(({F2}, {F1}, {F1}))"  # a bank's traces as evaluate_batch takes them


def _sig(*args: str) -> str:
    return f"({', '.join(args)},)"


#: Lane 0: the washout kernel's block step first (the streaming and whole-trace steps and a study's evaluation call
#: it), in the order they build on each other. (module, function, argument types), each a signature numba compiles.
LANE_BLOCK: tuple[tuple[str, str, str], ...] = (
    ("washbench.cueing.kernel", "bank_block", _sig(F2, F2, F2, F3, F2, I2, F3)),
    ("washbench.cueing.kernel", "bank_step", _sig(F1, F1, F2, F3, F2, I2, F2)),
    ("washbench.cueing.kernel", "bank_trace", _sig(F2, F2, F2, F3, F2, I2, F3)),
    ("washbench.analysis.evaluate", "evaluate_batch", _sig(F2, F2, F2, F3, TRACE3, TRACE3, F2, F, F3, I2, F3, F1, F)),
    ("washbench.analysis.evaluate", "evaluate_fields", _sig(F2, TRACE3, TRACE3, F2, F2, I1, F2, F1, F2, F)),
)
#: Lane 1: the flight step and the scripted pilot, perception, sickness, metrics, the recording's thinning, the
#: platforms' kinematics called from Python, then the set-point path (a washout computed outside the kernel, or
#: another platform), last: by then lane 0 has cached the platform step they share.
LANE_REST: tuple[tuple[str, str, str], ...] = (
    ("washbench.flight.stepper", "flight_step", _sig(F1, F2)),
    ("washbench.flight.pilot", "pilot_step", _sig(F1)),
    ("washbench.perception.svc", "_run", _sig(F1, F1, F2, F, F1, F, F1, F1)),
    ("washbench.perception.sections", "sections_apply", _sig(F2, F1, F1, F2)),
    ("washbench.perception.sections", "sections_apply_from", _sig(F2, F1, F1, F2, RO1)),
    ("washbench.perception.sections", "sections_run", _sig(F2, F1, F2, F1, F2)),
    ("washbench.perception.sickness", "_biquad", _sig(F, F, F, F, F, F1)),
    ("washbench.perception.sickness", "_sum_squares", _sig(F1)),
    ("washbench.analysis.metric_sums", "signal_metrics", _sig(F1, F1, F)),
    ("washbench.analysis.metric_sums", "finish", _sig(F1, F)),
    ("washbench.analysis.metric_sums", "felt_sums", _sig(F2, F2, F1, F, F2)),
    ("washbench.analysis.metric_sums", "felt_finish", _sig(F1, F)),
    ("washbench.analysis.metric_sums", "jolt_sums", _sig(F2, F2, F, F1)),
    ("washbench.cueing.references", "reference_block", _sig(F2, F2, F, F, F1, "boolean", "boolean", F1, F2, F2)),
    ("washbench.review.thinning", "_keep", _sig(F1, F2, F1, F)),
    ("washbench.review.thinning", "_changes", _sig(F2, F1, "int64")),
    ("washbench.cueing.filters", "run_filter", _sig(F1, F1, "boolean")),
    ("washbench.platform.hexapod_kinematics", "forward_kinematics", _sig(F1, F1, V3, Q4, F1)),
    ("washbench.platform.hexapod_kinematics", "reachable", _sig(F1, V3, Q4)),
    ("washbench.platform.hexapod_kinematics", "within", _sig(F1, V3, Q4)),
    ("washbench.platform.hexapod_kinematics", "leg", _sig(F1, "int64", V3, Q4)),
    ("washbench.platform.hexapod_kinematics", "scaled_pose", _sig(V3, V3, F)),
    ("washbench.platform.kinematics", "brake_speed", _sig(F, F, F)),
    ("washbench.platform.kinematics", "track_rotation", _sig(Q4, V3, Q4, Q4, F, F, F, F)),
    ("washbench.numerics.rotations", "qrotvec", _sig(Q4)),
    ("washbench.numerics.rotations", "quat_from_euler", _sig(F, F, F)),
    ("washbench.cueing.kernel", "setpoint_block", _sig(F2, F2, I2, F1, F2, F1, I1, F2)),
    ("washbench.cueing.kernel", "setpoint_trace", _sig(F2, F2, I2, F1, F2, F1, I1, F2)),
)
KERNELS = (LANE_BLOCK, LANE_REST)


def dispatcher(module: str, name: str) -> object:
    """The numba dispatcher of ``module.name``: through the module's own ``compiled_<name>()`` where it has one (the
    flight step's drops a cache made stale by the pilot's source first, and stamps it, as a command's call does:
    without the stamp the first command would drop the cache made here); else a lazily compiled function handed to
    numba, or the dispatcher itself."""
    mod = importlib.import_module(module)
    accessor = getattr(mod, f"compiled_{name}", None)
    if callable(accessor):
        return accessor()
    fn = getattr(mod, name)
    return fn.compiled() if isinstance(fn, LazyJit) else fn


def compile_lane(entries: tuple[tuple[str, str, str], ...]) -> None:
    """Compile (or load from the cache) each entry's signature."""
    from numba.core.sigutils import normalize_signature  # deferred: numba

    for module, name, signature in entries:
        args, _ = normalize_signature(signature)
        # a tuple of types, as a call passes them: numba keys its cache on the signature as given (a string would
        # be a key no call ever looks up)
        dispatcher(module, name).compile(tuple(args))


def _lanes_default() -> int:
    return min(len(KERNELS), max(1, usable_cpus()))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m washbench.numerics.precompile", description=__doc__.splitlines()[0]
    )
    parser.add_argument(
        "--lanes", type=int, choices=(1, len(KERNELS)), default=None,
        help=f"{len(KERNELS)}: the lanes in processes side by side; 1: one after the other in this process (default: "
        f"{len(KERNELS)} where as many CPUs are usable)",
    )  # fmt: skip
    parser.add_argument("--lane", type=int, default=None, help=argparse.SUPPRESS)  # one lane, in this process
    args = parser.parse_args(argv)
    if args.lane is not None:
        compile_lane(KERNELS[args.lane])
        return 0
    t0 = time.monotonic()
    lanes = args.lanes if args.lanes is not None else _lanes_default()
    if lanes <= 1:
        for lane in KERNELS:
            compile_lane(lane)
    else:
        command = [sys.executable, "-m", "washbench.numerics.precompile", "--lane"]
        procs = [subprocess.Popen([*command, str(i)]) for i in range(len(KERNELS))]
        failed = [i for i, p in enumerate(procs) if p.wait() != 0]
        if failed:
            print(f"washbench: precompiling lane(s) {failed} failed", file=sys.stderr)
            return 1
    n = sum(len(lane) for lane in KERNELS)
    print(f"washbench: {n} compiled functions in numba's cache ({cache_place()}) in {time.monotonic() - t0:.0f} s",
          file=sys.stderr)  # fmt: skip
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
