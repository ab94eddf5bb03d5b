"""The ceiling (washbench.analysis.ceiling): its programmes against an independent formulation, its physics, and no
washout below it on stress inputs the project has never flown.

Independent formulation: the perceived signal as an explicit linear map of the platform's input, built column by
column with scipy.signal.lsim (linear interpolation between samples, the steady state of the first sample as its
initial state), and the linear programme solved by scipy's HiGHS, not by Clarabel over the bench's sections.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from ceiling_helpers import check_ceiling_below_every_washout, response_matrix, trapezoid, washbench
from flight_helpers import short_rudder_doublet
from scipy.optimize import linprog

from washbench.analysis.ceiling import EXACT, ceiling, rotational_floor, translational_floor
from washbench.perception.vestibular import (
    VestibularModel,
    VestibularParams,
    canal_model,
    canal_tf,
    otolith_model,
    otolith_tf,
)
from washbench.platform.limits import load_platform_limits

DT = 1.0 / 60.0
G = 9.80665


@pytest.fixture(scope="module")
def limits():
    return load_platform_limits()


def rotation_lp(h: np.ndarray, ref: np.ndarray, w_max: float, dw: float, dt: float) -> float:
    """min sum_k c_k |H w - ref|_k over |w| <= w_max, |w_k - w_k-1| <= dw (HiGHS)."""
    n = len(ref)
    d = np.eye(n)[1:] - np.eye(n)[:-1]  # w_k - w_{k-1}
    eye = np.eye(n)
    zero = np.zeros((n - 1, n))
    a_ub = np.vstack([np.hstack([h, -eye]), np.hstack([-h, -eye]), np.hstack([d, zero]), np.hstack([-d, zero])])
    b_ub = np.concatenate([ref, -ref, np.full(n - 1, dw), np.full(n - 1, dw)])
    c = np.concatenate([np.zeros(n), trapezoid(n, dt)])
    bounds = [(-w_max, w_max)] * n + [(0, None)] * n
    res = linprog(c, A_ub=a_ub, b_ub=b_ub, bounds=bounds, method="highs")
    assert res.status == 0
    return float(res.fun)


def test_rotational_floor_equals_an_independent_lp(limits) -> None:
    """A 60 deg/s roll-rate pulse (above the sphere's 32.2 deg/s): the floor in deg equals the LP built from
    scipy.signal.lsim's response and solved by HiGHS."""
    n = 240
    t = np.arange(n) * DT
    w_air = np.radians(60.0) * ((t > 0.5) & (t < 2.5))
    vest = VestibularParams()
    ref = VestibularModel(DT, vest).perceive(np.zeros((n, 3)), np.column_stack([w_air, 0 * t, 0 * t])).omega_radps[:, 0]
    ours, status = rotational_floor(ref, DT, limits, canal_model(vest.canals, DT), False)
    assert status == "Solved"
    rot = limits.rotation
    h = response_matrix(*canal_tf(vest.canals), n, DT)
    theirs = rotation_lp(h, ref, math.radians(rot.rate_limit_degps), math.radians(rot.acceleration_limit_degps2) * DT,
                         DT)  # fmt: skip
    assert math.degrees(theirs) > 1.0  # the limit binds: a real floor
    assert ours == pytest.approx(math.degrees(theirs), rel=1e-5)


def test_translational_floor_equals_an_independent_lp(limits) -> None:
    """A heave pull to 2.2 g for 2 s: the floor (m/s^2*s) equals the relaxation's LP written out independently
    (gravity's component, the stage in the turning frame, lsim's otolith) and solved by HiGHS."""
    n = 240
    t = np.arange(n) * DT
    f_z = -G * (1.0 + 1.2 * ((t > 1.0) & (t < 3.0)))
    vest = VestibularParams()
    f = np.column_stack([0 * t, 0 * t, f_z])
    ref = VestibularModel(DT, vest).perceive(f, np.zeros((n, 3))).f_mps2[:, 2]
    ours, status = translational_floor(ref, 2, DT, limits, G, otolith_model(vest.otolith, DT), False)
    assert status == "Solved"
    tr, rot = limits.translation, limits.rotation
    chord = 2.0 * math.sin(math.radians(rot.rate_limit_degps) * DT / 2.0)
    a_bar, v_bar, p_bar = (math.hypot(*x.xyz) for x in (tr.acceleration_limit_mps2, tr.velocity_limit_mps,
                                                         tr.position_limit_m))  # fmt: skip
    h = response_matrix(*otolith_tf(vest.otolith), n, DT)
    # variables: f, gam, V, P, t (n each)
    z = np.zeros((n, n))
    eye = np.eye(n)
    d = np.eye(n) - np.eye(n, k=-1)  # x_k - x_{k-1}, x_{-1} = 0
    rows, rhs = [], []

    def le(blocks: list[np.ndarray], b: np.ndarray) -> None:
        rows.append(np.hstack(blocks))
        rhs.append(b)

    le([h, z, z, z, -eye], ref)
    le([-h, z, z, z, -eye], -ref)
    dg = d[1:]
    le([z[1:], dg, z[1:], z[1:], z[1:]], np.full(n - 1, G * chord))
    le([z[1:], -dg, z[1:], z[1:], z[1:]], np.full(n - 1, G * chord))
    le([eye, eye, z, z, z], np.full(n, a_bar))
    le([-eye, -eye, z, z, z], np.full(n, a_bar))
    le([-DT * eye, -DT * eye, d, z, z], np.full(n, chord * v_bar))  # V_k - V_k-1 - dt b_k <= e
    le([DT * eye, DT * eye, -d, z, z], np.full(n, chord * v_bar))
    le([z, z, -DT * eye, d, z], np.full(n, chord * p_bar))
    le([z, z, DT * eye, -d, z], np.full(n, chord * p_bar))
    a_ub = np.vstack(rows)
    b_ub = np.concatenate(rhs)
    # the first step from rest: V_0 = dt b_0, P_0 = dt V_0 (no turning term yet)
    a_eq = np.zeros((2, 5 * n))
    a_eq[0, [0, n, 2 * n]] = [-DT, -DT, 1.0]
    a_eq[1, [2 * n, 3 * n]] = [-DT, 1.0]
    c = np.concatenate([np.zeros(4 * n), trapezoid(n, DT)])
    bounds = [(None, None)] * n + [(-G, G)] * n + [(-v_bar, v_bar)] * n + [(-p_bar, p_bar)] * n + [(0, None)] * n
    res = linprog(c, A_ub=a_ub, b_ub=b_ub, A_eq=a_eq, b_eq=np.zeros(2), bounds=bounds, method="highs")
    assert res.status == 0
    assert res.fun > 0.5  # 2.2 g cannot be held: a real floor
    assert ours == pytest.approx(res.fun, rel=1e-5)


def test_what_the_platform_can_follow_has_the_ceiling_zero_and_the_shortcut_agrees(limits) -> None:
    """A 20 deg/s yaw doublet and a 2 m/s^2 surge step (within the sphere's rates and gravity's reach): the LPs find
    0, and the exact shortcut (no LP) says so too."""
    n = 600
    t = np.arange(n) * DT
    w = np.column_stack([0 * t, 0 * t, np.radians(20.0) * np.sin(2 * np.pi * 0.3 * t)])
    f = np.column_stack([2.0 * (t > 1.0) * np.minimum(1.0, t - 1.0), 0 * t, np.full(n, -G)])
    p = VestibularModel(DT).perceive(f, w)
    lp = ceiling(p.f_mps2, p.omega_radps, DT, limits, G)
    short = ceiling(p.f_mps2, p.omega_radps, DT, limits, G, f_mps2=f, omega_radps=w)
    assert max(lp.floor.values()) < 1e-6
    assert short.floor == dict.fromkeys(short.floor, 0.0)
    assert short.status["yaw"] == EXACT and short.status["surge"] == EXACT


def test_ceiling_is_below_a_feasible_motion_and_a_still_platform(limits) -> None:
    """A 60 deg/s roll step: the floor is above 0 and below the error of one motion the sphere can make (the rate
    limited and rate-clipped), itself below a still platform's (the aircraft pilot's own perceived motion)."""
    n = 480
    t = np.arange(n) * DT
    w_air = np.radians(60.0) * (t > 1.0)
    model = VestibularModel(DT)
    zeros = np.zeros((n, 3))
    ref = model.perceive(zeros, np.column_stack([w_air, 0 * t, 0 * t])).omega_radps[:, 0]
    floor, _ = rotational_floor(ref, DT, limits, model.canals, False)
    rot = limits.rotation
    w_max, dw = math.radians(rot.rate_limit_degps), math.radians(rot.acceleration_limit_degps2) * DT
    cand = np.zeros(n)
    for k in range(1, n):
        cand[k] = min(cand[k - 1] + dw, w_max, w_air[k]) if w_air[k] > cand[k - 1] else max(cand[k - 1] - dw, w_air[k])
    sim = model.perceive(zeros, np.column_stack([cand, 0 * t, 0 * t])).omega_radps[:, 0]
    e_cand = math.degrees(float(np.sum(trapezoid(n, DT) * np.abs(sim - ref))))
    e_still = math.degrees(float(np.sum(trapezoid(n, DT) * np.abs(ref - ref[0]))))
    assert 0.0 < floor <= e_cand * (1 + 1e-9) < e_still


def test_thresholds_are_refused(limits) -> None:
    from washbench.perception.thresholds import ZACHARIAS

    p = VestibularModel(DT).perceive(np.tile([0.0, 0.0, -G], (10, 1)), np.zeros((10, 3)))
    with pytest.raises(ValueError, match="thresholds"):
        ceiling(p.f_mps2, p.omega_radps, DT, limits, G, VestibularParams(thresholds=ZACHARIAS))



@pytest.mark.parametrize(
    "shape, axis, amplitude",
    [("step", "roll", "70"), ("doublet", "f_z", "-12"), ("pulse", "yaw", "45")],
)
def test_no_washout_below_the_ceiling_on_stress_inputs(tmp_path: Path, shape: str, axis: str, amplitude: str) -> None:
    """``washbench signal`` inputs beyond the platform (a 70 deg/s roll step, a 2.2 g heave doublet, a 45 deg/s
    yaw pulse) cued with classical, unrestricted, optimal washouts and the bound: no score and no relative error
    below the ceiling, and the ceiling above 0 where the input leaves the platform's reach."""
    sig = tmp_path / "in.csv"
    proc = washbench("signal", shape, "--axis", axis, "--amplitude", amplitude, "--frequency-hz", "0.3",
                     "--duration-s", "8", "--rate-hz", "60", "--out", sig)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    out = tmp_path / "c"
    washouts = [a for w in ("small-angle", "unrestricted", "optimal", "bound") for a in ("--washout", w)]
    proc = washbench("cue", sig, "--out", out, *washouts, "--no-recording", "--no-figures", "--quiet")
    assert proc.returncode == 0, proc.stdout + proc.stderr
    scores = check_ceiling_below_every_washout(out)
    assert set(scores) == {"small-angle", "unrestricted", "optimal", "bound"}
    doc = json.loads((out / "run.json").read_text())["bound"]
    dof = {"roll": "roll", "yaw": "yaw", "f_z": "heave"}[axis]
    assert doc["ceiling"][dof] > 0.0  # beyond the platform: not even the best motion follows it


RUDDER = short_rudder_doublet("short_rudder", 5)

CRUISE = """\
name: level_cruise
description: straight and level at 95 KIAS and 4000 ft for 6 s
aircraft: c172p
start:
  air: {altitude_ft: 4000, airspeed_kts: 95, heading_deg: 90}
phases:
  - name: cruise
    hold: {wings_level: true, altitude_ft: 4000, airspeed_kts: 95}
    until: {duration_s: 6}
"""


@pytest.fixture(scope="module")
def replay_suite(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A real JSBSim suite of two short flights the project does not bundle, with small-angle, unrestricted and the
    bound."""
    folder = tmp_path_factory.mktemp("m")
    (folder / "short_rudder.yaml").write_text(RUDDER)
    (folder / "level_cruise.yaml").write_text(CRUISE)
    out = tmp_path_factory.mktemp("suite")
    proc = washbench("suite", folder, "--out", out, "--jobs", "1", "--no-recording", "--no-figures", "--quiet",
                     "--washout", "small-angle", "--washout", "unrestricted", "--washout", "bound")  # fmt: skip
    assert proc.returncode == 0, proc.stdout + proc.stderr
    return out


def columns(run: Path, names: list[str]) -> dict[str, np.ndarray]:
    import pyarrow.parquet as pq

    table = pq.read_table(run / "traces.parquet", columns=names)
    return {n: table.column(n).to_numpy() for n in names}


def test_the_replay_yaws_with_the_aircraft_on_a_rudder_doublet(replay_suite: Path) -> None:
    """The replay's cockpit yaws: its head yaw rate reaches the aircraft's peak within 25 % (it stayed below 2 % of
    it before), and its relative yaw error is below the small-angle washout's (CW1 passes yaw onsets through its
    high-pass)."""
    run = replay_suite / "c172p" / "short_rudder"
    check_ceiling_below_every_washout(run)
    c = columns(run, ["aircraft.omega_z_degps", "bound.omega_z_degps", "small-angle.omega_z_degps"])
    peak = np.abs(c["aircraft.omega_z_degps"]).max()
    assert peak > 5.0  # the doublet yaws the aircraft
    assert np.abs(c["bound.omega_z_degps"]).max() == pytest.approx(peak, rel=0.25)
    rel = {w: r for w, r in json.loads((run / "run.json").read_text())["bound"]["relative_error"].items()}
    assert rel["bound"]["yaw"] < rel["small-angle"]["yaw"]
    assert rel["bound"]["yaw"] < 0.2


def test_the_replay_holds_still_in_level_flight(replay_suite: Path) -> None:
    """Straight and level (the input varies by millimetres per second squared): the replay's stage stays within
    10 cm of the centre (of 1.5 m), accelerates at under 0.25 m/s^2 and never reverses its acceleration sample to
    sample by more than 0.01 m/s^2 (the old replay ran through the whole travel and chattered at up to 9.8 m/s^2)."""
    run = replay_suite / "c172p" / "level_cruise"
    names = [f"bound.{q}_{a}_{u}" for q, u in (("pos", "m"), ("acc", "mps2")) for a in "xyz"]
    c = columns(run, names)
    pos = np.column_stack([c[f"bound.pos_{a}_m"] for a in "xyz"])
    acc = np.column_stack([c[f"bound.acc_{a}_mps2"] for a in "xyz"])
    assert np.abs(pos).max() < 0.1
    assert np.abs(acc).max() < 0.25
    flips = (np.sign(acc[1:]) * np.sign(acc[:-1]) < 0) & (np.abs(acc[1:] - acc[:-1]) > 0.01)
    assert not flips.any()


def test_the_suite_report_opens_with_a_verdict_whose_counts_add_up(replay_suite: Path) -> None:
    text = (replay_suite / "report.md").read_text()
    assert text.index("## Verdict") < text.index("## Summary") < text.index("## How to read the numbers")
    verdict = text[text.index("## Verdict") : text.index("## Summary")]
    assert "gain over small-angle" in verdict and "| ceiling | best achieved | bracket's width |" in verdict
    assert "**Not compared**" in verdict and "--washout all" in verdict  # it says what it did not compare
    line = next(x for x in verdict.splitlines() if x.startswith("First place alone among the washouts:"))
    counts = [int(n) for n in __import__("re").findall(r" (\d+)[,;]", line.split("together")[0])]
    total = int(line.split("together ")[1].split(" of ")[0])
    assert sum(counts) == total == 2 and line.rstrip().endswith("of 2 manoeuvres.")
    rows = [x for x in verdict.splitlines() if x.startswith("| c172p / ")]
    assert [r.split(" | ")[0] for r in rows] == ["| c172p / short_rudder", "| c172p / level_cruise"] or [
        r.split(" | ")[0] for r in rows
    ] == ["| c172p / level_cruise", "| c172p / short_rudder"]
    # the per-manoeuvre detail does not repeat the explanations the page states once
    assert text.count("The ceiling is the least relative error") == 1
    assert text.count("Percent of the manoeuvre's time") == 1
