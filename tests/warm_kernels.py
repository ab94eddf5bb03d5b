"""Compile washbench's numba kernels once, before parallel test workers need them (``tests/conftest.py``).

    python tests/warm_kernels.py FOLDER

After a fresh clone or an upgrade the numba cache is empty, and each pytest-xdist worker (and each ``washbench``
process a test starts) would compile the kernels it needs itself, several at the same time: numba has no lock
between processes, so a kernel two processes need at once is compiled twice. This script compiles each kernel the
tests need once, in two lanes side by side (two cores), each lane one process after another into ``FOLDER``:

- lane 1: the washout kernel's block step and streaming step (``bank_block``, ``bank_step``: the largest, about
  19 s of CPU, on which the whole-trace step and a study's evaluation build), then the whole-trace step
  (``bank_trace``, through ``cue_trace``) and a ``washbench run`` of a 1 s flight (the recording's thinning);
- lane 2, while lane 1 compiles the block step: ``washbench fly`` of the flight (the flight step), then the
  set-point path (a washout computed outside the kernel, or another platform: ``setpoint_block``,
  ``setpoint_trace``); once lane 1's block step is in the cache (started earlier, these would compile it a second
  time), a study's evaluation (``evaluate_batch``, through ``FlightEvaluator``) and a ``washbench cue`` of a 1 s
  input with every compiled washout (the adaptive washouts, perception, metrics, the sickness models).

Then it writes ``FOLDER/done`` with their exit statuses; the workers wait for that file before their first test.
The previous warm-up ran the whole-trace step and the evaluation one after the other behind the block step, and
the set-point path last, while the other lane waited for the block step with nothing to do (34 s on two idle
cores).
With the cache already filled, the commands load it (a few seconds in all). A failure here fails nothing: the
tests that need a kernel compile it themselves and report what is wrong.

First, where Python is told not to write bytecode (``PYTHONDONTWRITEBYTECODE``, set on these machines), it writes
washbench's ``.pyc`` files once (0.2 s): otherwise each of the test run's 300-odd ``washbench`` processes compiles
the modules it imports from source again (about 0.09 s of CPU each for a ``run``).
"""

from __future__ import annotations

import compileall
import importlib.util
import subprocess
import sys
import threading
from pathlib import Path

from hostile import short  # this script's folder, tests/, is first on sys.path

COMPILED_WASHOUTS = ("small-angle", "large-angle", "unrestricted", "adaptive", "adaptive-large-angle",
                     "adaptive-unrestricted")  # fmt: skip

#: After the block step: the whole-trace step (lane 1) and a study's evaluation (lane 2), with the argument types
#: ``cue``, ``omct``, the bound and ``sweep``/``tune`` pass (C-contiguous float64 arrays from the public functions).
_INPUT = """\
import numpy as np
from washbench.cueing import WASHOUT_NAMES, cue_trace, load_washout_params
from washbench.cueing.variants import as_washouts
from washbench.platform.model import load_platform_model
limits, params = load_platform_model(), load_washout_params()
k = np.arange(240)
f = np.column_stack([0.5 * (k > 30), 0.0 * k, -9.80665 + 0.0 * k])
om = np.column_stack([np.radians(2.0) * (k > 60), 0.0 * k, 0.0 * k])
"""
TRACE = _INPUT + "cue_trace(f, om, 1 / 120, list(WASHOUT_NAMES), params, limits)\n"
EVALUATION = _INPUT + """\
from washbench.analysis.evaluate import FlightEvaluator
FlightEvaluator(f, om, 1 / 120, limits).evaluate(as_washouts(list(WASHOUT_NAMES), params))
"""

#: Lane 2 last: the set-point path (a washout computed outside the kernel, or another platform), block and trace
#: forms, with the argument types :meth:`CueingBank.steps` and ``cue_trace`` pass (one washout's rows of the bank's
#: C-contiguous arrays), on no samples.
SETPOINT = """\
import numpy as np
from washbench.cueing import filters
from washbench.cueing.kernel import NCFG, NFIELDS, NFILT, NSTATE, SAT_KINDS, setpoint_block, setpoint_trace
cfg, coef = np.zeros((1, NCFG)), np.zeros((1, NFILT, filters.NCOEF))
state, counts = np.zeros((1, NSTATE)), np.zeros((1, len(SAT_KINDS)), dtype=np.int64)
pos, q, flags = np.zeros((0, 3)), np.zeros((0, 4)), np.zeros((0, 2), dtype=np.int64)
setpoint_block(pos, q, flags, cfg[0], coef[0], state[0], counts[0], np.zeros((1, 0, NFIELDS))[0])
setpoint_trace(pos, q, flags, cfg[0], coef[0], state[0], counts[0], np.zeros((1, NFIELDS, 0))[0])
"""


def main(folder: Path) -> int:
    if sys.dont_write_bytecode:  # Python reads .pyc files all the same; compileall writes them regardless
        spec = importlib.util.find_spec("washbench")
        if spec is not None and spec.origin is not None:
            compileall.compile_dir(Path(spec.origin).parent, quiet=2)
    folder.mkdir(parents=True, exist_ok=True)
    short(folder, name="warm", seconds=1)  # warm.yaml, the tests' short level flight
    rows = ["t_s,f_x_mps2,f_y_mps2,f_z_mps2,omega_x_degps,omega_y_degps,omega_z_degps"]
    rows += [f"{k / 120!r},{0.5 if k > 30 else 0.0},0.0,-9.80665,{2.0 if k > 60 else 0.0},0.0,0.0" for k in range(120)]
    (folder / "warm.csv").write_text("\n".join(rows) + "\n")
    washbench = [sys.executable, "-m", "washbench"]
    washouts = [a for w in COMPILED_WASHOUTS for a in ("--washout", w)]
    block = "from washbench.cueing.bank import _warm_up, warm_up_block; warm_up_block(); _warm_up()"
    lane1 = [
        [sys.executable, "-c", block],  # the block and streaming washout steps
        [sys.executable, "-c", TRACE],
        [*washbench, "run", str(folder / "warm.yaml"), "--out", str(folder / "run"), "--no-figures", "--quiet"],
    ]
    lane2_first = [
        [*washbench, "fly", str(folder / "warm.yaml"), "--out", str(folder / "fly"), "--quiet"],
        [sys.executable, "-c", SETPOINT],
    ]
    lane2_then = [
        [sys.executable, "-c", EVALUATION],
        [*washbench, "cue", str(folder / "warm.csv"), "--out", str(folder / "cue"), "--no-figures", "--no-recording",
         *washouts],  # the streamed washouts, perception, metrics, sickness
    ]  # fmt: skip
    order = [*lane1, *lane2_first, *lane2_then]  # each command's number in FOLDER/done
    statuses: dict[int, int] = {}
    block_done = threading.Event()

    def run(command: list[str]) -> None:
        statuses[order.index(command)] = subprocess.run(command, stdout=subprocess.DEVNULL,
                                                        stderr=subprocess.DEVNULL).returncode  # fmt: skip

    def first_lane() -> None:
        try:
            run(lane1[0])
        finally:
            block_done.set()
        for command in lane1[1:]:
            run(command)

    def second_lane() -> None:
        for command in lane2_first:
            run(command)
        block_done.wait()
        for command in lane2_then:
            run(command)

    try:
        lanes = [threading.Thread(target=first_lane), threading.Thread(target=second_lane)]
        for lane in lanes:
            lane.start()
        for lane in lanes:
            lane.join()
    finally:
        (folder / "done").write_text(" ".join(str(statuses.get(i)) for i in range(len(order))) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(Path(sys.argv[1])))
