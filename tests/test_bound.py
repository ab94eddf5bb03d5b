"""The oracle bound: its cost is at most every washout's on the same cost (a washout below it means one of them is
wrong), its motion keeps the platform's limits, and it is exact where the platform can reproduce the motion."""

from __future__ import annotations

import math

import numpy as np
import pytest

from washbench.analysis.bound import BoundParams, oracle_bound, trajectory_from_trace, washout_cost
from washbench.analysis.signals import SignalSpec, generate
from washbench.cueing.algorithm import WashoutContext
from washbench.cueing.bank import cue_trace
from washbench.cueing.mpc import MpcWashout
from washbench.cueing.optimal import OptimalWashout
from washbench.cueing.params import WASHOUT_NAMES
from washbench.cueing.variants import load_washout_params
from washbench.flight.fly import fly
from washbench.flight.manoeuvre import load_manoeuvre
from washbench.io.paths import MANOEUVRES_DIR
from washbench.platform.kinematics import track_axis, track_rotation
from washbench.platform.limits import PlatformLimits, load_platform_limits

G = 9.80665


def platform_trace(alg, f: np.ndarray, w: np.ndarray, limits: PlatformLimits, dt: float) -> dict[str, np.ndarray]:
    """Set points of a washout object tracked by the Atlas model (its own track_axis/track_rotation), at rest at the
    start set point: acc (N, 3), omega (N, 3), q (N, 4), pos (N, 3)."""
    t = limits.translation
    rot = limits.rotation
    p_sp, q_sp = alg.start(f[0], w[0])
    p = np.array(p_sp, dtype=float)
    v = np.zeros(3)
    q = tuple(float(x) for x in q_sp)
    om = (0.0, 0.0, 0.0)
    sp_prev = p.copy()
    q_prev_sp = q
    n = len(f)
    out = {"acc": np.empty((n, 3)), "omega": np.empty((n, 3)), "q": np.empty((n, 4)), "pos": np.empty((n, 3))}
    for k in range(n):
        p_sp, q_sp = alg.step(f[k], w[k])
        v_old = v.copy()
        for j in range(3):
            p[j], v[j], *_ = track_axis(p[j], v[j], sp_prev[j], float(p_sp[j]), t.position_limit_m.xyz[j],
                                        t.velocity_limit_mps.xyz[j], t.acceleration_limit_mps2.xyz[j],
                                        rot.catch_up_fraction, dt)  # fmt: skip
        qs = tuple(float(x) for x in q_sp / np.linalg.norm(q_sp))
        q, om, *_ = track_rotation(q, om, q_prev_sp, qs, math.radians(rot.rate_limit_degps),
                                   math.radians(rot.acceleration_limit_degps2), rot.catch_up_fraction, dt)  # fmt: skip
        sp_prev, q_prev_sp = np.array(p_sp, dtype=float), qs
        out["acc"][k] = (v - v_old) / dt
        out["omega"][k] = om
        out["q"][k] = q
        out["pos"][k] = p
    return out


def _all_costs(f: np.ndarray, w: np.ndarray, dt: float, limits: PlatformLimits) -> dict[str, float]:
    costs = {}
    for name, tr in cue_trace(f, w, dt, WASHOUT_NAMES, load_washout_params(), limits).items():
        costs[name] = washout_cost(trajectory_from_trace(tr.acc_mps2, tr.omega_radps, tr.q, dt), f, w, dt, G)
    ctx = WashoutContext(dt, G, limits, "steady", (0.0, 0.0, 0.0))
    for alg in (OptimalWashout(None, ctx), MpcWashout(None, ctx)):
        tr = platform_trace(alg, f, w, limits, dt)
        costs[alg.name] = washout_cost(trajectory_from_trace(tr["acc"], tr["omega"], tr["q"], dt), f, w, dt, G)
    return costs


def _check_bound_motion(res, limits: PlatformLimits, dt: float) -> None:
    tr = res.trajectory
    t = limits.translation
    tol = 1e-6
    assert np.all(np.abs(tr.pos) <= np.array(t.position_limit_m.xyz) * (1 + tol))
    assert np.all(np.abs(tr.vel) <= np.array(t.velocity_limit_mps.xyz) * (1 + tol))
    assert np.all(np.abs(tr.acc) <= np.array(t.acceleration_limit_mps2.xyz) * (1 + tol))
    w_max = math.radians(limits.rotation.rate_limit_degps)
    assert np.all(np.abs(tr.omega) <= w_max * (1 + tol))
    assert np.all(
        np.abs(np.diff(tr.omega, axis=0)) <= math.radians(limits.rotation.acceleration_limit_degps2) * dt * 1.001
    )
    # the recursions the bound's QP was built on, checked on its result
    np.testing.assert_allclose(np.diff(tr.vel, axis=0), tr.acc[1:] * dt, atol=1e-7)
    np.testing.assert_allclose(np.diff(tr.pos, axis=0), tr.vel[1:] * dt, atol=1e-7)


@pytest.fixture(scope="module")
def limits() -> PlatformLimits:
    return load_platform_limits()


def test_bound_is_exact_where_the_platform_can_follow(limits):
    """A small yaw-rate sine (10 deg/s, 0.5 Hz: 31 deg/s^2, within every limit): the platform can copy it, the
    bound's cost is ~0 (a doublet could not be copied: its rate jumps faster than the angular-acceleration limit)."""
    sig = generate(SignalSpec("sine", "yaw", 10.0, frequency_hz=0.5, duration_s=4.0))
    res = oracle_bound(sig.f_mps2, sig.omega_radps, sig.dt_s, limits, G)
    assert res.cost < 1e-6 * res.cost_still
    assert res.recovered(res.cost) == pytest.approx(1.0)


def test_bound_below_every_washout_on_a_stress_signal(limits):
    a = generate(SignalSpec("doublet", "f_x", 4.0, frequency_hz=0.3, duration_s=6.0, start_s=0.5))
    b = generate(SignalSpec("doublet", "roll", 20.0, frequency_hz=0.4, duration_s=6.0, start_s=1.5))
    f = a.f_mps2 + b.f_mps2 - np.array([0.0, 0.0, -G])
    w = b.omega_radps
    res = oracle_bound(f, w, a.dt_s, limits, G)
    assert set(res.statuses.values()) == {"Solved"}
    _check_bound_motion(res, limits, a.dt_s)
    assert washout_cost(res.trajectory, f, w, a.dt_s, G) == pytest.approx(res.cost)
    costs = _all_costs(f, w, a.dt_s, limits)
    for name, cost in costs.items():
        assert res.cost <= cost * (1 + 1e-7), (name, cost, res.cost)
    assert res.cost < 0.5 * min(costs.values())  # the future known is worth something here


def test_bound_below_every_washout_on_a_real_flight(limits):
    """The C172 elevator doublet flown by JSBSim (its first 10 s: settle, doublet, start of the response)."""
    flight = fly(load_manoeuvre(MANOEUVRES_DIR / "c172" / "elevator_doublet.yaml"))
    c = flight.columns
    n = round(10.0 / flight.dt_s)
    f = np.column_stack([c[f"f_{a}_mps2"][:n] for a in "xyz"])
    w = np.radians(np.column_stack([c[f"omega_{a}_degps"][:n] for a in "xyz"]))
    res = oracle_bound(f, w, flight.dt_s, limits, G)
    assert set(res.statuses.values()) == {"Solved"}
    _check_bound_motion(res, limits, flight.dt_s)
    for name, cost in _all_costs(f, w, flight.dt_s, limits).items():
        assert res.cost <= cost * (1 + 1e-7), (name, cost, res.cost)
        assert res.recovered(cost) <= 1.0 + 1e-6


def test_bound_params_validate():
    assert BoundParams.model_validate({"rate_weight": 2.0}).rate_weight == 2.0
    with pytest.raises(Exception, match="bogus"):
        BoundParams.model_validate({"bogus": 1})


def test_bound_replayed_as_a_washout_through_the_platform(limits):
    """Kind ``bound`` through the bench's whole-trace path (cue_trace: Atlas model, head motion): the platform
    tracks its set points without touching a translational limit (the plan keeps every limit and can always brake
    within the travel), and on the ranking's measure (the score, computed here from the head motions with the
    vestibular model and the rule's formula) it beats the large-angle washout and a still platform."""
    from washbench.analysis.metrics import integral_abs_error
    from washbench.analysis.ranking import DOFS, dof_weights, perceived_motion, score_of
    from washbench.perception.vestibular import VestibularModel

    a = generate(SignalSpec("doublet", "f_x", 4.0, frequency_hz=0.25, duration_s=6.0, start_s=0.5))
    b = generate(SignalSpec("doublet", "roll", 15.0, frequency_hz=0.3, duration_s=6.0, start_s=1.0))
    f = a.f_mps2 + b.f_mps2 - np.array([0.0, 0.0, -G])
    w = b.omega_radps
    dt = a.dt_s
    traces = cue_trace(f, w, dt, ["bound", "large-angle"], load_washout_params(), limits)
    tb = traces["bound"]
    for kind in ("pos", "vel", "acc"):
        assert int(np.sum(tb.saturated[kind])) == 0, kind
    model = VestibularModel(dt)
    air = model.perceive(f, w)
    motion = perceived_motion(air.f_mps2, air.omega_radps, dt)
    weights = dof_weights(motion)

    def score(tr) -> float:
        sim = model.perceive(tr.head_f_mps2, tr.head_omega_radps)
        pa = np.column_stack([air.f_mps2, np.degrees(air.omega_radps)])
        ps = np.column_stack([sim.f_mps2, np.degrees(sim.omega_radps)])
        errors = np.array([integral_abs_error(ps[:, j], pa[:, j], dt) for j in range(len(DOFS))])
        return float(score_of(errors, weights, motion))

    replay, large = score(tb), score(traces["large-angle"])
    assert replay < 0.5 * large < 0.5 * sum(weights.values())  # a still platform scores the sum of the weights


def test_bank_with_the_future_steps_a_whole_only_washout_like_the_whole_trace(limits):
    """``CueingBank(..., future=...)``: the bound's set points computed once from the whole input, then tracked
    sample by sample (``step``) or in blocks (``steps``): the same bits as ``cue_trace``; without the future the
    bank refuses it in one line."""
    from washbench.cueing.bank import CueingBank
    from washbench.errors import WashbenchError

    a = generate(SignalSpec("doublet", "f_x", 3.0, frequency_hz=0.5, duration_s=2.5, start_s=0.2))
    f = a.f_mps2
    w = a.omega_radps + np.array([0.0, 0.0, 0.05])
    params = load_washout_params()
    whole = cue_trace(f, w, a.dt_s, ["small-angle", "bound"], params, limits)
    by_step = CueingBank(["small-angle", "bound"], params, limits, a.dt_s, future=(f, w))
    rows = np.stack([by_step.step(f[k], w[k]).copy() for k in range(len(f))], axis=1)
    by_block = CueingBank(["small-angle", "bound"], params, limits, a.dt_s, future=(f, w))
    blocks = np.concatenate([by_block.steps(f[i : i + 100], w[i : i + 100]) for i in range(0, len(f), 100)], axis=1)
    for i, name in enumerate(("small-angle", "bound")):
        np.testing.assert_array_equal(rows[i], blocks[i])
        np.testing.assert_array_equal(whole[name].pos_m, rows[i][:, 0:3])
    assert by_step.saturation_counts() == by_block.saturation_counts()
    with pytest.raises(WashbenchError, match="needs the whole recording"):
        CueingBank(["bound"], params, limits, a.dt_s)
