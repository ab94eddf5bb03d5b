"""The naive references (washbench.cueing.references) against scipy's rotations, and the felt error ranking them
for the right reasons on real cues (``washbench signal`` inputs through ``washbench cue``: the references driven
through the real Atlas model, perceived by the real vestibular models).

Also: Sinacori's and Schroeder's ordering of motion fidelity (gain towards 1 and phase distortion towards 0 at
1 rad/s is better) reproduced by the felt error on a sine perceived by the vestibular models.
"""

from __future__ import annotations

import csv
import itertools
import math
from pathlib import Path

import inprocess
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from washbench.analysis.felt import felt_errors, felt_motion, felt_score, jolt
from washbench.cueing.algorithm import WashoutContext
from washbench.cueing.references import ReplayRotationWashout, ReplayWashout, StillWashout, tilt_of
from washbench.perception.vestibular import VestibularModel
from washbench.platform.limits import load_platform_limits

G = 9.80665
DT = 1.0 / 120.0


def _context() -> WashoutContext:
    return WashoutContext(dt_s=DT, gravity_mps2=G, limits=load_platform_limits(None), filter_start="steady",
                          head_offset_m=(0.0, 0.0, 0.0))  # fmt: skip


def _scipy(q: np.ndarray) -> Rotation:
    return Rotation.from_quat([q[1], q[2], q[3], q[0]])  # scipy is scalar last


@pytest.mark.parametrize("f", [[0.0, 0.0, -G], [-3.0, 0.0, -9.3], [0.0, 4.0, -8.9], [2.0, -2.0, -9.0]])
def test_the_first_pose_is_the_tilt_that_gravity_needs(f: list[float]) -> None:
    q = tilt_of(np.array(f))
    body_gravity = _scipy(q).inv().apply([0.0, 0.0, -1.0])  # f = R' (0 - g_I) at rest, per unit g
    assert body_gravity == pytest.approx(np.array(f) / np.linalg.norm(f), abs=1e-12)


def test_the_replay_rotation_turns_at_the_aircraft_s_body_rates() -> None:
    rng = np.random.default_rng(3)
    w = rng.normal(0.0, 0.4, (600, 3))
    f = np.tile([0.0, 0.0, -G], (600, 1))
    ref = ReplayRotationWashout(None, _context())
    _, q0 = ref.start(f[0], w[0])
    pos, q = ref.trace(f, w)
    expected = _scipy(q0)
    for k in range(600):
        expected = expected * Rotation.from_rotvec(w[k] * DT)  # body rates: composed on the right
    assert np.allclose(pos, 0.0)
    assert (expected.inv() * _scipy(q[-1])).magnitude() < 1e-9


def test_the_replay_stage_integrates_what_rotation_leaves_and_stops_at_the_travel() -> None:
    limits = load_platform_limits(None)
    travel = limits.translation.position_limit_m.x
    n = 480
    f = np.tile([1.0, 0.0, -G], (n, 1))  # 1 m/s^2 of surge, level: the stage accelerates forward at 1 m/s^2
    w = np.zeros((n, 3))
    ref = ReplayWashout(None, _context())
    ref.start(np.array([0.0, 0.0, -G]), w[0])
    pos, _ = ref.trace(f, w)
    t = DT * np.arange(1, n + 1)
    # explicit integration (v then p), the closed form 1/2 t^2 within the step's order, then clipped
    assert pos[:, 0] == pytest.approx(np.minimum(0.5 * t * (t + DT), travel), abs=1e-9)
    assert np.allclose(pos[:, 1:], 0.0)
    still = StillWashout(None, _context())
    still.start(f[0], w[0])
    p, q = still.trace(f, w)
    assert np.all(p == 0.0) and np.all(q == q[0])


def _washbench(*args: str | Path) -> None:
    proc = inprocess.washbench(*args, timeout=600)
    assert proc.returncode == 0, proc.stdout + proc.stderr


@pytest.fixture(scope="module")
def surge_step(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A sustained 3 m/s^2 surge step (8 s, 60 Hz) cued with the references and the classical washouts: the
    replay's stage runs into its stop and brakes there."""
    d = tmp_path_factory.mktemp("surge")
    _washbench("signal", "step", "--axis", "f_x", "--amplitude", "3", "--duration-s", "8", "--rate-hz", "60",
               "--out", d / "in.csv")  # fmt: skip
    washouts = [a for w in ("small-angle", "replay", "replay-rotation", "still") for a in ("--washout", w)]
    _washbench("cue", d / "in.csv", "--out", d / "o", *washouts, "--no-recording", "--no-figures", "--quiet")
    return d / "o"


def _ranking(out: Path) -> dict[str, float]:
    with (out / "ranking.csv").open(newline="") as f:
        return {r["washout"]: float(r["score"]) for r in csv.DictReader(f)}


def test_a_motion_pinned_at_its_stops_ranks_below_the_same_motion_without_them(surge_step: Path) -> None:
    scores = _ranking(surge_step)
    assert scores["still"] == pytest.approx(1.0, abs=1e-9)  # the measure's 1
    assert scores["replay"] > scores["replay-rotation"]
    with (surge_step / "metrics.csv").open(newline="") as f:
        rows = {(r["washout"], r["dof"]): r for r in csv.DictReader(f)}
    # the replay's surge jolts: it runs into its stop and brakes there, more than twice the input's own 3 m/s^2 step
    assert float(rows[("replay", "surge")]["jolt"]) > 6.0
    assert float(rows[("replay-rotation", "surge")]["jolt"]) == 0.0


@pytest.mark.parametrize("phase_deg", [0.0, 20.0, 40.0])
def test_sinacori_ordering(phase_deg: float) -> None:
    """Sinacori's and Schroeder's criteria (NASA/TP-1999-208766) grade a motion filter by its gain and phase
    distortion at 1 rad/s: fidelity rises as the gain goes to 1 and the phase distortion to 0. A sway sine of
    2 m/s^2 at 1 rad/s given at gain K and a phase lag: the felt error falls as K rises from 0 (to 0.75; with a lag
    phi the least error of any measure of the difference is near K = cos phi, not 1), rises with the phase lag at
    gain 1, and is 0 for a gain deficit the threshold hides."""
    model = VestibularModel(DT)
    t = DT * np.arange(int(60.0 / DT))
    rest = np.tile([0.0, 0.0, -G], (len(t), 1))
    air = rest.copy()
    air[:, 1] = 2.0 * np.sin(t)
    w0 = np.zeros((len(t), 3))
    pa = model.perceive(air, w0)
    m = felt_motion(pa.f_mps2, pa.omega_radps, DT)

    def score(gain: float, lag_deg: float) -> float:
        sim = rest.copy()
        sim[:, 1] = gain * 2.0 * np.sin(t - math.radians(lag_deg))
        ps = model.perceive(sim, w0)
        e, fa = felt_errors(pa.f_mps2, pa.omega_radps, ps.f_mps2, ps.omega_radps, DT)
        return felt_score(e, fa, jolt(sim, air, DT), m)

    values = [score(k, phase_deg) for k in (0.0, 0.25, 0.5, 0.75)]
    assert all(a > b for a, b in itertools.pairwise(values)), values
    assert score(1.0, phase_deg + 20.0) > score(1.0, phase_deg)
    if phase_deg == 0.0:
        assert values[-1] > score(1.0, 0.0) == 0.0
        assert score(0.95, 0.0) == 0.0  # 0.1 m/s^2 short of a 2 m/s^2 sine: below the 0.17 m/s^2 threshold
