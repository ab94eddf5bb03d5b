"""The MPC washout: against the unconstrained discrete LQ solution of the same cost (scipy's DARE), its set points
against the platform's limits on stress signals (rates from scipy Rotation), a provoked solver failure, its steady
start, and its preview."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from scipy import linalg
from scipy.spatial.transform import Rotation

from washbench.analysis.signals import SignalSpec, generate
from washbench.cueing.algorithm import WashoutAlgorithm, WashoutContext
from washbench.cueing.mpc import MpcParams, MpcWashout, stacked_inputs
from washbench.platform.limits import PlatformLimits, load_platform_limits

G = 9.80665
DT = 1.0 / 120.0


@pytest.fixture(scope="module")
def limits() -> PlatformLimits:
    return load_platform_limits()


def _context(limits: PlatformLimits) -> WashoutContext:
    return WashoutContext(DT, G, limits, "steady", (0.0, 0.0, 0.0))


def _far_limits(limits: PlatformLimits) -> PlatformLimits:
    d = limits.model_dump()
    d["translation"] = {
        "position_limit_m": {"x": 100.0, "y": 100.0, "z": 100.0},
        "velocity_limit_mps": {"x": 100.0, "y": 100.0, "z": 100.0},
        "acceleration_limit_mps2": {"x": 1000.0, "y": 1000.0, "z": 1000.0},
    }
    d["rotation"] = {**d["rotation"], "rate_limit_degps": 3600.0, "acceleration_limit_degps2": 1e5}
    return PlatformLimits.model_validate(d)


def _run(w: MpcWashout, f: np.ndarray, om: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    w.start(f[0], om[0])
    pos = np.empty((len(f), 3))
    q = np.empty((len(f), 4))
    for k in range(len(f)):
        pos[k], q[k] = w.step(f[k], om[k])
    return pos, q


def test_is_a_washout_algorithm(limits):
    assert isinstance(MpcWashout(None, _context(limits)), WashoutAlgorithm)


def test_unconstrained_mpc_approaches_the_lq_solution_as_the_horizon_grows(limits):
    """Constraints far away, no tilt-rate limit, no terminal constraint: the first move of the QP tends to the
    infinite-horizon discrete LQ law of the same model and cost (DARE of the system augmented with the
    reference model r_{k+1} = rho r_k), and the gap shrinks with the horizon."""
    far = _far_limits(limits)
    base = {
        "prediction_step_s": 0.1,
        "reference_decay_per_s": 0.5,
        "tilt_rate_limit_degps": None,
        "terminal_rest": False,
        "limit_margin": 1.0,
        # the LQ comparison uses the standard stage cost x' Q x + u' R u (no direct force term)
        **{ch: {"direct_force": 0.0} for ch in ("pitch", "roll", "heave")},
    }
    # a state reached on a real signal: a surge doublet and a roll-rate doublet through the long-horizon MPC
    sig_f = generate(SignalSpec("doublet", "f_x", 3.0, frequency_hz=0.5, duration_s=3.0))
    sig_r = generate(SignalSpec("doublet", "roll", 15.0, frequency_hz=0.5, duration_s=3.0))
    f = sig_f.f_mps2 + sig_r.f_mps2 - np.array([0.0, 0.0, -G])
    om = sig_r.omega_radps
    ref = MpcWashout(MpcParams.model_validate({**base, "horizon_steps": 20}), _context(far))
    _run(ref, f[::2], om[::2])  # every other sample: a state is all it needs
    x0, r0 = ref.x.copy(), stacked_inputs(f[-1], om[-1], G)

    tp = 0.1
    phi_a = np.block([[ref.phi_p, ref.gam_rp], [np.zeros((6, ref.n)), ref.rho * np.eye(6)]])
    gam_a = np.vstack([ref.gam_p, np.zeros((6, ref.m))])
    q_a = linalg.block_diag(ref.model.Q * tp, np.zeros((6, 6)))
    r_w = ref.model.R * tp
    p_inf = linalg.solve_discrete_are(phi_a, gam_a, q_a, r_w)
    k_lq = np.linalg.solve(r_w + gam_a.T @ p_inf @ gam_a, gam_a.T @ p_inf @ phi_a)
    u_lq = -k_lq @ np.concatenate([x0, r0])
    assert np.linalg.norm(u_lq) > 0.05  # a state with something to do

    gaps = []
    for n in (5, 10, 20, 40, 80):
        w = MpcWashout(MpcParams.model_validate({**base, "horizon_steps": n}), _context(far))
        w.x = x0.copy()
        w.r_mean = np.zeros(6)  # the input predicted as r0 rho^k: the reference model of the DARE above
        ok, plan = w.plan(r0)
        assert ok
        gaps.append(np.linalg.norm(plan[0] - u_lq) / np.linalg.norm(u_lq))
    assert all(b < a for a, b in itertools.pairwise(gaps)), gaps
    assert gaps[-1] < 0.02, gaps
    assert gaps[0] > 5 * gaps[-1], gaps


STRESS = [
    SignalSpec("step", "f_x", 9.0, duration_s=4.0, start_s=0.5),
    SignalSpec("doublet", "f_y", 12.0, frequency_hz=0.4, duration_s=4.0, start_s=0.5),
    SignalSpec("step", "f_z", -9.0, duration_s=4.0, start_s=0.5),
    SignalSpec("chirp", "roll", 60.0, frequency_hz=2.0, duration_s=4.0, start_s=0.5),
    SignalSpec("step", "yaw", 90.0, duration_s=4.0, start_s=0.5),
    SignalSpec("doublet", "pitch", 50.0, frequency_hz=0.5, duration_s=4.0, start_s=0.5),
]


def _check_limits(pos: np.ndarray, q: np.ndarray, limits: PlatformLimits, margin: float = 1.0) -> None:
    """Set points within the platform's limits, with the platform's own finite differences (m, m/s, m/s^2;
    body rates from successive attitudes by scipy Rotation)."""
    t = limits.translation
    p_max = np.array(t.position_limit_m.xyz)
    v_max = np.array(t.velocity_limit_mps.xyz)
    a_max = np.array(t.acceleration_limit_mps2.xyz)
    assert np.all(np.isfinite(pos)) and np.all(np.isfinite(q))
    p = np.vstack([np.zeros(3), pos])  # the platform starts centred at rest
    v = np.diff(p, axis=0) / DT
    a = np.diff(np.vstack([np.zeros(3), v]), axis=0) / DT
    tol = 1e-9
    assert np.all(np.abs(pos) <= p_max * margin + tol), np.abs(pos).max(0)
    assert np.all(np.abs(v) <= v_max * margin + tol), np.abs(v).max(0)
    assert np.all(np.abs(a) <= a_max * margin + 1e-6), np.abs(a).max(0)
    rot = Rotation.from_quat(q[:, [1, 2, 3, 0]])
    w = (rot[:-1].inv() * rot[1:]).as_rotvec() / DT
    w_max = math.radians(limits.rotation.rate_limit_degps)
    assert np.all(np.linalg.norm(w, axis=1) <= w_max * (1 + 1e-6)), np.linalg.norm(w, axis=1).max()


@pytest.mark.parametrize("spec", STRESS, ids=lambda s: f"{s.kind}-{s.axis}")
def test_set_points_stay_within_the_platform_limits_on_stress_signals(limits, spec):
    sig = generate(spec)
    w = MpcWashout(None, _context(limits))
    pos, q = _run(w, sig.f_mps2, sig.omega_radps)
    _check_limits(pos, q, limits)
    rep = w.report()
    assert rep["solves"] == len(sig.f_mps2)
    # failed solves (at the iteration limit after a jump of the input) continue the previous plan: never braking
    assert rep["brakes"] == 0, rep
    assert rep["fallbacks"] <= 0.02 * rep["solves"], rep


def test_solver_failure_falls_back_to_braking_without_nan(limits):
    """One DAQP iteration: no solve ends (DAQP needs a second to confirm its active set); every step falls back
    (counted), nothing is NaN, no limit is broken, and the platform stays at rest."""
    sig = generate(SignalSpec("doublet", "f_x", 8.0, frequency_hz=0.5, duration_s=2.5, start_s=0.2))
    good = MpcWashout(None, _context(limits))
    pos_g, _ = _run(good, sig.f_mps2, sig.omega_radps)
    assert np.max(np.abs(pos_g[:, 0])) > 0.05
    w = MpcWashout(MpcParams.model_validate({"solver": {"iter_limit": 1}}), _context(limits))
    pos, q = _run(w, sig.f_mps2, sig.omega_radps)
    rep = w.report()
    assert rep["fallbacks"] == len(sig.f_mps2), rep
    _check_limits(pos, q, limits)
    assert np.max(np.abs(pos)) < 1e-12  # it started at rest and braking keeps it there


def test_failure_mid_motion_brakes_to_rest_within_the_limits(limits):
    """Solves succeed while the platform moves, then fail: the platform decelerates at its limits and stops."""
    sig = generate(SignalSpec("step", "f_x", 6.0, duration_s=3.0, start_s=0.2))
    w = MpcWashout(None, _context(limits))
    f, om = sig.f_mps2, sig.omega_radps
    w.start(f[0], om[0])
    pos = []
    q = []
    for k in range(len(f)):
        if k == 60:  # 0.5 s in: the platform is moving; from now on the solver gets one iteration
            w.qp.set_iter_limit(1)
        p_k, q_k = w.step(f[k], om[k])
        pos.append(p_k)
        q.append(q_k)
    pos_a, q_a = np.array(pos), np.array(q)
    _check_limits(pos_a, q_a, limits)
    v = np.diff(pos_a[:, 0]) / DT
    assert np.max(np.abs(v[50:60])) > 0.05  # it was moving
    assert np.max(np.abs(v[-60:])) < 1e-9  # and has stopped
    rep = w.report()
    assert rep["fallbacks"] >= len(f) - 60
    assert rep["brakes"] > 0  # the previous plan ran out (its end is at rest) or was not safe


def test_params_reject_a_prediction_step_shorter_than_the_sample(limits):
    with pytest.raises(ValueError, match="prediction_step_s"):
        MpcWashout(MpcParams.model_validate({"prediction_step_s": 0.001}), _context(limits))
    with pytest.raises(Exception, match="bogus"):
        MpcParams.model_validate({"solver": {"bogus": 1}})
    with pytest.raises(Exception, match="iter_limit"):
        MpcParams.model_validate({"horizon_steps": 500, "solver": {"iter_limit": 50_000}})
    p = MpcParams.model_validate({"heave": {"force": 2.0}})
    assert p.heave.force == 2.0 and p.heave.position == MpcParams().heave.position  # the channel's default kept


@pytest.mark.parametrize("axis, amp", [(0, 2.0), (1, 2.0), (2, -4.9)])
def test_translational_cue_starts_in_the_direction_of_the_force(limits, axis, amp):
    """A surge, sway or heave (pull-up) onset moves the platform with the force first (north, east, up). With the
    input held over the horizon and no direct force term, a pull-up moved it down (docs/optimal-mpc.md)."""
    n = int(2.0 / DT)
    f = np.tile([0.0, 0.0, -G], (n, 1))
    f[12:, axis] += amp
    pos, _ = _run(MpcWashout(None, _context(limits)), f, np.zeros((n, 3)))
    p = pos[:, axis] * np.sign(amp)
    assert p.min() > -1e-4, p.min()
    assert p[int(1.0 / DT)] > 0.02


def test_a_steady_tilted_start_holds_still(limits):
    """A steady climb (specific force 4 deg nose up, |f| = g) from the first sample: the MPC starts tilted at its
    steady state and stays: under a millimetre and 0.01 deg/s over 5 s (it used to make a 45 mm, 2 deg/s start-up
    move on a level cruise), its tilt towards the force (the same sign as the classical tilt coordination)."""
    th = math.radians(4.0)
    f = np.tile([G * math.sin(th), 0.0, -G * math.cos(th)], (600, 1))
    om = np.zeros((600, 3))
    w = MpcWashout(None, _context(limits))
    _, q0 = w.start(f[0], om[0])
    pitch0 = Rotation.from_quat(q0[[1, 2, 3, 0]]).as_euler("ZYX")[1]
    assert 0.5 * th < pitch0 <= th * 1.001
    pos, q = _run(w, f, om)
    assert np.abs(pos).max() < 1e-3
    rot = Rotation.from_quat(q[:, [1, 2, 3, 0]])
    rates = np.degrees(np.linalg.norm((rot[:-1].inv() * rot[1:]).as_rotvec(), axis=1) / DT)
    assert rates.max() < 0.01


def test_preview_anticipates_and_no_preview_is_causal(limits):
    """A surge step at t = 2 s: without preview nothing moves before it, and ``trace`` gives the steps' numbers bit
    for bit; with 1 s of preview the platform already moves before the step (it backs up to gain travel), within its
    limits."""
    sig = generate(SignalSpec("step", "f_x", 2.0, duration_s=4.0, start_s=2.0))
    f, om = sig.f_mps2, sig.omega_radps
    before = round(1.95 / DT)
    pos_s, q_s = _run(MpcWashout(None, _context(limits)), f, om)
    again = MpcWashout(None, _context(limits))
    again.start(f[0], om[0])
    pos_t, q_t = again.trace(f, om)
    assert np.array_equal(pos_s, pos_t) and np.array_equal(q_s, q_t)
    assert np.abs(pos_s[:before]).max() < 1e-9
    seeing = MpcWashout(MpcParams(preview_s=1.0), _context(limits))
    seeing.start(f[0], om[0])
    pos_p, q_p = seeing.trace(f, om)
    assert np.abs(pos_p[:before]).max() > 1e-3
    _check_limits(pos_p, q_p, limits)
    with pytest.raises(Exception, match="preview_s"):
        MpcWashout(MpcParams(preview_s=1.0), _context(limits)).step(f[0], om[0])
