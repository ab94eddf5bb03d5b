"""Calibrate the pilot model's vestibular perception noise once (docs/pilot-model.md, "Calibration").

The one value of the built-in pilot model that no paper gives is the intensity of the noise on the perceived rate
(``vestibular_noise_rad2ps``): without it only the product of the vestibular gain and the motion gain matters and
the optimum jumps at motion gain 0. It is chosen so that the model adapted to the aircraft's own motion on the
bundled c172p roll task has the ratio ``K_m / K_v`` of the vestibular to the visual gain (s; free of the control's
units) that Pool et al. (2016) identified for trained pilots with motion: 0.10 s (their 0.05-0.12 s), and then kept
fixed for every condition, task and aircraft. This script measures the task's controlled element with JSBSim (the
calibration of :func:`washbench.pilot.measure.calibrate`), bisects the intensity in the frequency domain and prints
it with the ratio it gives; ``washbench/pilot/params.py`` holds the value (``CALIBRATED_VESTIBULAR_NOISE``).

    python tools/calibrate_pilot_noise.py            # about ten seconds
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

from washbench.io.paths import TASKS_DIR
from washbench.perception.vestibular import MODELS
from washbench.pilot.adapt import adapt
from washbench.pilot.measure import calibrate
from washbench.pilot.params import MultimodalParams
from washbench.pilot.response import Constant
from washbench.pilot.task import load_task

TARGET_RATIO_S = 0.10
VESTIBULAR_MODEL = "telban-cardullo"  # washbench track's default (docs/pilot-model.md, "Perception")


def ratio(vm: float, calib: object, task: object, vest: object) -> float:
    p = MultimodalParams(vestibular_noise_rad2ps=vm)
    chosen = adapt(p, calib.setting(task, Constant(1.0), vest), task.adaptation)[0]  # type: ignore[attr-defined]
    return chosen.vestibular_gain / chosen.visual_gain


def main() -> int:
    task, manoeuvre = load_task(Path(sys.argv[1]) if len(sys.argv) > 1 else TASKS_DIR / "c172" / "roll.yaml")
    vest = MODELS[VESTIBULAR_MODEL]
    vm = MultimodalParams().vestibular_noise_rad2ps
    for _ in range(2):  # the calibration's second pass flies the adapted pilot: measure again with the new value
        calib, _ = calibrate(task, manoeuvre, MultimodalParams(vestibular_noise_rad2ps=vm), vest, task.adaptation)
        lo, hi = math.log(1e-7), math.log(1e-2)  # the ratio falls as the noise grows
        for _ in range(30):
            mid = 0.5 * (lo + hi)
            if ratio(math.exp(mid), calib, task, vest) > TARGET_RATIO_S:
                lo = mid
            else:
                hi = mid
        vm = float(f"{math.exp(0.5 * (lo + hi)):.2g}")
        print(f"vestibular_noise_rad2ps = {vm:.2g} rad^2/s: K_m / K_v = {ratio(vm, calib, task, vest):.3f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
