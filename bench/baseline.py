"""The baseline every benchmark divides by: bare JSBSim ``fdm.run()``, set up and timed the same way everywhere.

Imported by the scripts in this folder (``python bench/NAME.py`` puts the folder on ``sys.path``). Set-up (model
load, initial conditions, trim) is never timed; CPU time (``time.process_time``) counts this process only, which
is the steadier figure on a shared machine, wall time (``time.perf_counter``) what a user waits for.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

DT_S = 1.0 / 120.0


def c172p_in_air(altitude_ft: float = 4000.0, kcas: float = 100.0, dt_s: float = DT_S) -> Any:
    """JSBSim's own c172p in the air (untrimmed), engine running at 0.7 throttle: no washbench code involved."""
    os.environ.setdefault("JSBSIM_DEBUG", "0")
    import jsbsim

    fdm = jsbsim.FGFDMExec(jsbsim.get_default_root_dir())
    fdm.set_debug_level(0)
    fdm.load_model("c172p")
    fdm.set_dt(dt_s)
    fdm["ic/h-sl-ft"] = altitude_ft
    fdm["ic/vc-kts"] = kcas
    fdm.run_ic()
    fdm["propulsion/set-running"] = -1
    fdm["fcs/throttle-cmd-norm"] = 0.7
    return fdm


def manoeuvre_start(manoeuvre: Any) -> Any:
    """JSBSim set up at a manoeuvre's own start (a path or a loaded Manoeuvre), as the flight sets it up."""
    from washbench.flight.fdm import make_fdm
    from washbench.flight.manoeuvre import load_manoeuvre
    from washbench.flight.profile import load_profile

    m = load_manoeuvre(Path(manoeuvre)) if isinstance(manoeuvre, str | Path) else manoeuvre
    fdm, _ = make_fdm(m, load_profile(m.aircraft_files.profile))
    return fdm


def run_cpu_s(fdm: Any, steps: int) -> float:
    """CPU seconds of ``steps`` ``fdm.run()`` calls."""
    run = fdm.run
    t0 = time.process_time()
    for _ in range(steps):
        run()
    return time.process_time() - t0


def run_wall_s(fdm: Any, steps: int) -> float:
    """Wall seconds of ``steps`` ``fdm.run()`` calls."""
    run = fdm.run
    t0 = time.perf_counter()
    for _ in range(steps):
        run()
    return time.perf_counter() - t0


def manoeuvre_wall_s(path: str | Path, steps: int) -> float:
    """Wall seconds of ``steps`` bare steps from manoeuvre ``path``'s start (a top-level function: process pools)."""
    return run_wall_s(manoeuvre_start(path), steps)


def best_of(fn: Callable[[], object], repeat: int = 3) -> float:
    """The shortest wall time of ``repeat`` calls of ``fn``."""
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)
