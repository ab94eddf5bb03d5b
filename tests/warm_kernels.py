"""Compile washbench's numba kernels once, before parallel test workers need them (``tests/conftest.py``).

    python tests/warm_kernels.py FOLDER

After a fresh clone or an upgrade the numba cache is empty, and each pytest-xdist worker would compile the same
kernels at the same time (about 20 s of CPU each). This script runs real commands side by side into ``FOLDER``
(numba compiles one kernel at a time in a process, so separate processes share the work): ``washbench fly`` of a
1 s flight (the flight step), the washout bank's lockstep and streaming steps, and a ``washbench cue`` of a 1 s
input with every compiled washout (streamed: the adaptive washouts, perception, metrics, the sickness models); once
the first two are done, a ``washbench run`` of the flight (what is left: the recording's thinning). Then it writes
``FOLDER/done`` with their exit statuses; the workers wait for that file before their first test.

What is left for the tests to compile (about 15 s of CPU: the whole-trace kernel ``bank_trace`` and the set-point
path through ``cue_trace``, a study's ``evaluate_batch``) is left to them: compiling it here as well (a ``cue_trace``
beside the first three, a ``sweep`` beside the ``run``) made a cold test run slower, 220 s against 202 s, since
the workers wait for the warm-up.
With the cache already filled, the commands load it (about 3 s in all). A failure here fails nothing: the tests
that need a kernel compile it themselves and report what is wrong.

First, where Python is told not to write bytecode (``PYTHONDONTWRITEBYTECODE``, set on these machines), it writes
washbench's ``.pyc`` files once (0.2 s): otherwise each of the test run's 300-odd ``washbench`` processes compiles
the modules it imports from source again (about 0.09 s of CPU each for a ``run``).
"""

from __future__ import annotations

import compileall
import importlib.util
import subprocess
import sys
from pathlib import Path

from hostile import short  # this script's folder, tests/, is first on sys.path

COMPILED_WASHOUTS = ("small-angle", "large-angle", "unrestricted", "adaptive", "adaptive-large-angle",
                     "adaptive-unrestricted")  # fmt: skip


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
    first = [  # side by side: the kernels compile in separate processes (numba compiles one at a time per process)
        [*washbench, "fly", str(folder / "warm.yaml"), "--out", str(folder / "fly"), "--quiet"],  # the flight step
        [sys.executable, "-c", block],  # the lockstep and streaming washout steps
        [*washbench, "cue", str(folder / "warm.csv"), "--out", str(folder / "cue"), "--no-figures", "--no-recording",
         *washouts],  # the streamed washouts, perception, metrics, sickness
    ]  # fmt: skip
    then = [*washbench, "run", str(folder / "warm.yaml"), "--out", str(folder / "run"), "--no-figures", "--quiet"]
    statuses: list[int | None] = []
    try:
        procs = [subprocess.Popen(c, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL) for c in first]
        statuses = [p.wait() for p in procs[:2]]  # what is left for a run (the recording's thinning): from the cache
        statuses.append(subprocess.run(then, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL).returncode)
        statuses.append(procs[2].wait())
    finally:
        (folder / "done").write_text(" ".join(map(str, statuses)) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(Path(sys.argv[1])))
