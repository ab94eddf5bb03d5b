"""Why no convex relaxation can charge for the rotation a sustained tilt needs, measured on a real flight
(docs/yardstick.md, "What the ceiling cannot say").

On one flight (the bundled C172 go-around unless a manoeuvre is named), four platform motions flown through the
Atlas model, the stage held at its centre, and one that is not a motion:

- **roll-yaw**: the cockpit rolls right by the tilt angle, then yaws 90 deg to its left: gravity then leans it back
  (the specific force of a forward acceleration, as a nose-up pitch gives) with no pitch rotation at all;
- **its mirror image**: rolls left, yaws right: the same lean back, every lateral quantity of the opposite sign;
- **their midpoint**: the average of the two head motions (perception is linear in them): leaning back with no
  rotation about any axis. It lies in every convex set that holds the two motions (so in every convex relaxation
  of what the platform can do), and a convex measure rates it no worse than their average;
- **pitch**: the same lean back by pitching up at the roll's rate;
- **still**: the platform at its first pose.

Each scored by the ranking's felt error (the default rule) on the flight; and the flight's ceiling beside them.

    python tools/mirror_midpoint.py [MANOEUVRE.yaml] [--tilt-deg 8] [--rate-degps 10]
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

from washbench.analysis.best_motion import Yardstick
from washbench.analysis.ceiling import ceiling
from washbench.analysis.felt import DEFAULT_MEASURE
from washbench.analysis.ranking import perceived_motion
from washbench.cueing.bank import flyer
from washbench.cueing.variants import Washout, load_washout_params
from washbench.flight.fly import fly
from washbench.flight.manoeuvre import load_manoeuvre
from washbench.io.paths import MANOEUVRES_DIR
from washbench.platform.limits import load_platform_limits

G = 9.80665
START_S = 1.0
YAW_RATE_DEGPS = 30.0


def axis_quat(axis: int, angle: np.ndarray) -> np.ndarray:
    """Quaternions (N, 4), scalar first, of turns ``angle`` (N,) rad about body axis ``axis``."""
    q = np.zeros((len(angle), 4))
    q[:, 0] = np.cos(angle / 2)
    q[:, 1 + axis] = np.sin(angle / 2)
    return q


def qmul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    aw, ax, ay, az = a.T
    bw, bx, by, bz = b.T
    return np.column_stack([aw * bw - ax * bx - ay * by - az * bz, aw * bx + ax * bw + ay * bz - az * by,
                            aw * by - ax * bz + ay * bw + az * bx, aw * bz + ax * by - ay * bx + az * bw])  # fmt: skip


def ramp(t: np.ndarray, start: float, size: float, rate: float) -> np.ndarray:
    """0 before ``start``, then ``rate`` per second to ``size``, held (rad)."""
    return np.sign(size) * np.clip((t - start) * rate, 0.0, abs(size))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("manoeuvre", nargs="?", type=Path, default=MANOEUVRES_DIR / "c172" / "go_around.yaml")
    ap.add_argument("--tilt-deg", type=float, default=8.0)
    ap.add_argument("--rate-degps", type=float, default=10.0)
    args = ap.parse_args()
    res = fly(load_manoeuvre(args.manoeuvre))
    c = res.columns
    f = np.column_stack([c[f"f_{a}_mps2"] for a in "xyz"])
    w = np.radians(np.column_stack([c[f"omega_{a}_degps"] for a in "xyz"]))
    dt, n = res.dt_s, len(f)
    t = np.arange(n) * dt
    limits = load_platform_limits()
    fly_it = flyer(Washout("bound", "bound", load_washout_params()), limits, dt)
    yard = Yardstick(f, w, dt)
    tilt, rate = math.radians(args.tilt_deg), math.radians(args.rate_degps)
    rolled = START_S + tilt / rate  # the roll ends, the yaw starts
    yaw_rate = math.radians(YAW_RATE_DEGPS)
    level = np.array([1.0, 0.0, 0.0, 0.0])
    centre = np.zeros((n, 3))

    def flown(q: np.ndarray):
        return fly_it(np.zeros(3), level, centre, q)

    def roll_yaw(sign: float) -> np.ndarray:  # roll sign * tilt, then yaw -sign * 90 deg about the rolled body's z
        return qmul(axis_quat(0, ramp(t, START_S, sign * tilt, rate)),
                    axis_quat(2, ramp(t, rolled, -sign * math.pi / 2, yaw_rate)))  # fmt: skip

    a, b = flown(roll_yaw(1.0)), flown(roll_yaw(-1.0))
    pitch = flown(axis_quat(1, ramp(t, START_S, tilt, rate)))
    still = flown(np.tile(level, (n, 1)))
    mid_f = 0.5 * (np.asarray(a.head_f_mps2) + np.asarray(b.head_f_mps2))
    mid_w = 0.5 * (np.asarray(a.head_omega_radps) + np.asarray(b.head_omega_radps))
    ac = yard.aircraft
    ce = ceiling(ac.f_mps2, ac.omega_radps, dt, limits, G, f_mps2=f, omega_radps=w, measure=DEFAULT_MEASURE)
    print(f"{args.manoeuvre}: {n} samples ({n * dt:.1f} s); a lean back of {args.tilt_deg:g} deg from t = "
          f"{START_S:g} s, rolled or pitched at {args.rate_degps:g} deg/s, yawed at {YAW_RATE_DEGPS:g} deg/s")
    for name, tr in (("roll right, yaw left", a), ("roll left, yaw right (mirror)", b), ("pitch up", pitch),
                     ("still", still)):  # fmt: skip
        gam = -np.asarray(tr.head_f_mps2)[-1]
        print(f"  {name:32s} felt error {yard.value(tr.head_f_mps2, tr.head_omega_radps):.4f}   at the end: "
              f"f_x {-gam[0]:+.3f} m/s^2, max |omega| roll {np.degrees(np.abs(tr.head_omega_radps[:, 0]).max()):.1f}, "
              f"yaw {np.degrees(np.abs(tr.head_omega_radps[:, 2]).max()):.1f} deg/s")
    print(f"  {'midpoint of the two (not a motion)':32s} felt error {yard.value(mid_f, mid_w):.4f}   at the end: "
          f"f_x {mid_f[-1, 0]:+.3f} m/s^2, max |omega| roll {np.degrees(np.abs(mid_w[:, 0]).max()):.1f}, "
          f"yaw {np.degrees(np.abs(mid_w[:, 2]).max()):.1f} deg/s")
    print(f"  ceiling {ce.felt_score(perceived_motion(ac.f_mps2, ac.omega_radps, dt)):.4f}")


if __name__ == "__main__":
    main()
