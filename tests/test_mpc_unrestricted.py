"""The unrestricted MPC washout (``mpc-unrestricted``): its condensed QP against an independent step-by-step
simulation of the same linearised model (scipy's ZOH discretisation, scipy Rotation for the gravity Jacobian), its
set points against the Atlas's limits on stress signals, its start, and its preview."""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pytest
from ceiling_helpers import read_csv, washbench
from flight_helpers import short_rudder_doublet
from scipy import signal
from scipy.spatial.transform import Rotation
from test_mpc import STRESS, _check_limits, _far_limits, _run

from washbench.analysis.felt import DEFAULT_MEASURE, felt_errors, jolt
from washbench.analysis.signals import SignalSpec, generate
from washbench.cueing.algorithm import WashoutAlgorithm, WashoutContext
from washbench.cueing.condensed import blocking_matrix, default_blocks, siso_prediction
from washbench.cueing.mpc_unrestricted import MpcUnrestrictedParams, MpcUnrestrictedWashout, tilt_matched
from washbench.errors import WashbenchError
from washbench.io.paths import MANOEUVRES_DIR
from washbench.perception.vestibular import CanalParams, OtolithParams, VestibularModel, canal_tf, otolith_tf
from washbench.platform.limits import PlatformLimits, load_platform_limits

G = 9.80665
DT = 1.0 / 120.0


@pytest.fixture(scope="module")
def limits() -> PlatformLimits:
    return load_platform_limits()


def _context(limits: PlatformLimits, start: str = "steady") -> WashoutContext:
    return WashoutContext(DT, G, limits, start, (0.0, 0.0, 0.0))


def test_is_a_washout_algorithm(limits):
    assert isinstance(MpcUnrestrictedWashout(None, _context(limits)), WashoutAlgorithm)


def test_prediction_matrices_match_scipy_dlsim():
    """``y = F x0 + T u`` of the otolith and canal models over 0.1 s intervals equals scipy's own ZOH
    discretisation (cont2discrete) simulated by dlsim, for a random input and start state."""
    rng = np.random.default_rng(3)
    for num, den in (otolith_tf(OtolithParams()), canal_tf(CanalParams())):
        pred = siso_prediction(num, den, 0.1, 15)
        a, b, c, d = signal.tf2ss(num, den)
        ad, bd, cd, dd, _ = signal.cont2discrete((a, b, c, d), 0.1, method="zoh")
        u = rng.standard_normal(15)
        x0 = rng.standard_normal(a.shape[0])
        _, y, _ = signal.dlsim((ad, bd, cd, dd, 0.1), np.append(u, 0.0), x0=x0)
        np.testing.assert_allclose(pred.free @ x0 + pred.T @ u, y[1:, 0], rtol=1e-9, atol=1e-12)


def test_blocks_cover_the_horizon():
    for n in (1, 5, 20, 50):
        b = default_blocks(n)
        assert sum(b) == n and b[0] == 1
        m = blocking_matrix(b)
        assert m.shape == (n, len(b)) and np.all(m.sum(axis=1) == 1.0)
    assert default_blocks(20) == (1, 1, 1, 2, 2, 2, 3, 3, 5)


def _gravity_jacobian(q: np.ndarray) -> np.ndarray:
    """d f_B / d dtheta at dtheta = 0 for f_B = (R(q) Exp(dtheta))' (-g_I), by central differences of scipy
    Rotations (independent of the module's -[g_B]x)."""
    r0 = Rotation.from_quat(q[[1, 2, 3, 0]])
    out = np.empty((3, 3))
    h = 1e-6
    for i in range(3):
        e = np.zeros(3)
        e[i] = h
        fp = (r0 * Rotation.from_rotvec(e)).inv().apply([0.0, 0.0, -G])
        fm = (r0 * Rotation.from_rotvec(-e)).inv().apply([0.0, 0.0, -G])
        out[:, i] = (fp - fm) / (2 * h)
    return out


def _simulated_cost(w: MpcUnrestrictedWashout, z: np.ndarray, f_air: np.ndarray, w_air: np.ndarray) -> float:
    """The plan's cost by stepping the linearised model interval by interval: otolith and canal error models
    discretised by scipy (cont2discrete, ZOH at tp) per body axis, the stage integrated exactly, the head force
    linearised with the scipy-Rotation Jacobian, the attitude change at each interval's midpoint; with the felt
    error's weight > 0, plus its prediction (:func:`_felt_part`)."""
    p = w.params
    tp, n_int, blocks = w.tp, w.N, w.blocks
    m = len(blocks)
    a_mv, w_mv = z[: 3 * m].reshape(m, 3), z[3 * m :].reshape(m, 3)
    idx = np.repeat(np.arange(m), blocks)
    a_int, w_int = a_mv[idx], w_mv[idx]
    r0 = Rotation.from_quat(w.q[[1, 2, 3, 0]])
    jac = _gravity_jacobian(w.q)
    f0 = r0.inv().apply([0.0, 0.0, -G])
    models = []
    for num, den in (otolith_tf(p.vestibular.otolith), canal_tf(p.vestibular.canals)):
        a, b, c, d = signal.tf2ss(num, den)
        models.append(signal.cont2discrete((a, b, c, d), tp, method="zoh")[:3])
    (ao, bo, co), (ac, bc, cc) = models
    xo, xc = w.xo.copy(), w.xc.copy()
    pos, vel = w.p.copy(), w.v.copy()
    dth = np.zeros(3)
    wo, wd, wc = (np.array(x.xyz) for x in (p.force, p.direct_force, p.rate))
    wp, wv = np.array(p.position.xyz), np.array(p.velocity.xyz)
    cost = 0.0
    xa_o, xa_c = w._air_o.copy(), w._air_c.copy()  # the aircraft pilot's own perception, for the false part
    ends = set(np.cumsum(blocks) - 1)
    nodes: list[np.ndarray] = []
    for j in range(n_int):
        mid = dth + 0.5 * tp * w_int[j]
        f_sim = r0.inv().apply(a_int[j]) + f0 + jac @ mid
        e_in = f_sim - f_air
        controls = p.acceleration * a_int[j] @ a_int[j] + p.angular_rate * w_int[j] @ w_int[j]
        cost += tp * (np.sum(wd * e_in**2) + controls)
        xo = ao @ xo + bo @ e_in[None, :]
        xc = ac @ xc + bc @ (w_int[j] - w_air)[None, :]
        pos = pos + vel * tp + 0.5 * a_int[j] * tp * tp
        vel = vel + a_int[j] * tp
        dth = dth + tp * w_int[j]
        e_o, e_c = (co @ xo)[0], (cc @ xc)[0]
        cost += tp * (np.sum(wo * e_o**2) + np.sum(wc * e_c**2) + np.sum(wp * pos**2) + np.sum(wv * vel**2))
        xa_o = ao @ xa_o + bo @ f_air[None, :]
        xa_c = ac @ xa_c + bc @ w_air[None, :]
        if j in ends:
            nodes.append(np.concatenate([e_o, e_c, (co @ xa_o)[0], (cc @ xa_c)[0]]))
    if p.felt_weight > 0.0:
        cost += _felt_part(w, np.array(nodes), a_mv[0], f_air)
    return float(cost)


def _felt_part(w: MpcUnrestrictedWashout, nodes: np.ndarray, a0: np.ndarray, f_air: np.ndarray) -> float:
    """The felt error of the plan by the ranking's own functions (``washbench.analysis.felt``): at each node (the
    end of each move), the perceived error beyond the threshold and the false part against the aircraft pilot's
    start, each node standing for its move's duration; the jolt of the first move; plus the slacks' small
    quadratic (``slack_regularisation``) at the slacks' optimal values (a false-part slack that costs nothing is
    left free: 0). ``nodes`` (K, 12): perceived error (force, rate; SI), then the aircraft pilot's perceived motion
    (SI). Each node's terms are the ranking's integrals over two samples, the aircraft pilot's start (where the
    simulator pilot feels the same) and the node, 2 w_k apart: the trapezoid rule gives w_k times the node's value."""
    p = w.params
    to_dof = np.array([1.0, 1.0, 1.0, *(3 * [180.0 / math.pi])])  # the measure's units: m/s^2, deg/s
    err = nodes[:, :6] * to_dof
    x = np.vstack([np.concatenate(w._air_0) * to_dof, nodes[:, 6:] * to_dof])  # row 0: the aircraft's start
    y = x + np.vstack([np.zeros(6), err])
    band = DEFAULT_MEASURE.bands()
    seconds = w.tp * np.array(w.blocks)
    t = np.maximum(np.abs(err) - band, 0.0) / band
    cost = 0.0
    for k, wk in enumerate(seconds):
        two = [0, k + 1]
        rad = np.array([1.0, 1.0, 1.0, *(3 * [math.pi / 180.0])])  # felt_errors takes rates in rad/s
        e_k, f_k = felt_errors(x[two, :3], x[two, 3:] * rad[3:], y[two, :3], y[two, 3:] * rad[3:], 2.0 * wk)
        cost += p.felt_weight * float(np.sum((e_k + p.false_weight * f_k) / band))
    v = (y - x[:1])[1:] / band
    cue = (x - x[:1])[1:] / band  # the aircraft pilot's cue: a false-part slack that costs nothing is left free (0)
    slacks = [t, np.where(cue > 1.0, 0.0, np.maximum(v - 1.0, 0.0)),
              np.where(cue < -1.0, 0.0, np.maximum(-v - 1.0, 0.0))]  # fmt: skip
    r0t = Rotation.from_quat(w.q[[1, 2, 3, 0]]).inv().as_matrix()
    jolts = jolt(np.array([np.zeros(3), r0t @ (a0 - w._a_prev)]), np.array([w._f_prev, f_air]), w.dt)
    cost += p.felt_weight * p.jolt_time_s * float(np.sum(jolts / band[:3]))
    return cost + p.slack_regularisation * (sum(float(np.sum(a * a)) for a in slacks) + float(jolts @ jolts))


def test_the_plan_minimises_the_simulated_felt_error(limits):
    """With the felt error (the default cost): from a tilted cockpit with every error model, the aircraft pilot's
    perception and the stage away from rest (perceived errors beyond the thresholds, cues of both signs), the QP's
    plan minimises the cost simulated step by step with the ranking's own dead band, false part and jolt
    (:func:`_felt_part`): no move of any single decision, nor a random move, lowers it (it is convex)."""
    params = MpcUnrestrictedParams(reference_decay_per_s=0.0, rate_decay_per_s=0.0, terminal_rest=False,
                                   relinearise_deg=0.0)  # fmt: skip
    w = MpcUnrestrictedWashout(params, _context(_far_limits(limits)))
    rng = np.random.default_rng(11)
    w.start(np.array([0.0, 0.0, -G]), np.zeros(3))
    w.q = Rotation.from_euler("ZYX", [-30.0, 8.0, 15.0], degrees=True).as_quat()[[3, 0, 1, 2]]
    w.xo = 0.5 * rng.standard_normal(w.xo.shape)
    w.xc = 0.2 * rng.standard_normal(w.xc.shape)
    w._air_o = 0.5 * rng.standard_normal(w._air_o.shape)
    w._air_c = 0.2 * rng.standard_normal(w._air_c.shape)
    w._air_0 = (np.array([0.1, -0.1, -G]), np.zeros(3))
    w.p = np.array([0.2, -0.1, 0.05])
    w.v = np.array([-0.1, 0.2, 0.0])
    w._a_prev = np.array([0.5, -1.5, 0.2])
    w._f_prev = np.array([0.9, -0.2, -10.0])
    f_air = np.array([1.2, -0.5, -10.3])
    w_air = np.array([0.1, -0.05, 0.15])
    ok, a_mv, w_mv = w._plan(f_air, w_air)
    assert ok
    z = np.concatenate([a_mv.ravel(), w_mv.ravel()])
    j0 = _simulated_cost(w, z, f_air, w_air)
    assert j0 > 1.0  # the felt part is far from zero here
    for h in (3e-3,):
        for i in range(z.size):
            e = np.zeros_like(z)
            e[i] = h
            assert _simulated_cost(w, z + e, f_air, w_air) > j0 - 1e-9 * j0
            assert _simulated_cost(w, z - e, f_air, w_air) > j0 - 1e-9 * j0
    for _ in range(10):
        assert _simulated_cost(w, z + 0.02 * rng.standard_normal(z.size), f_air, w_air) > j0


def test_the_plan_minimises_the_independently_simulated_cost(limits):
    """The quadratic part alone (no felt error): from a banked, pitched and yawed cockpit with the error models, the
    stage and the rate away from rest and the limits out of reach (no constraint active but the plan's end at rest,
    dropped here), the QP's plan is the minimiser of the cost simulated step by step: its gradient there, by central
    differences, vanishes against the cost's scale, and random moves away from it cost more."""
    params = MpcUnrestrictedParams(
        reference_decay_per_s=0.0, rate_decay_per_s=0.0, terminal_rest=False, relinearise_deg=0.0, felt_weight=0.0
    )
    w = MpcUnrestrictedWashout(params, _context(_far_limits(limits)))
    rng = np.random.default_rng(7)
    w.start(np.array([0.0, 0.0, -G]), np.zeros(3))
    w.q = Rotation.from_euler("ZYX", [40.0, 12.0, -25.0], degrees=True).as_quat()[[3, 0, 1, 2]]
    w.xo = 0.3 * rng.standard_normal(w.xo.shape)
    w.xc = 0.02 * rng.standard_normal(w.xc.shape)
    w.p = np.array([0.1, -0.05, 0.02])
    w.v = np.array([0.05, 0.1, -0.02])
    f_air = np.array([1.5, -0.8, -10.5])
    w_air = np.array([0.05, -0.1, 0.2])
    ok, a_mv, w_mv = w._plan(f_air, w_air)
    assert ok
    z = np.concatenate([a_mv.ravel(), w_mv.ravel()])
    j0 = _simulated_cost(w, z, f_air, w_air)
    h = 1e-4
    grad = np.empty_like(z)
    for i in range(z.size):
        e = np.zeros_like(z)
        e[i] = h
        grad[i] = (_simulated_cost(w, z + e, f_air, w_air) - _simulated_cost(w, z - e, f_air, w_air)) / (2 * h)
    # the scale: the gradient at the zero plan
    g_zero = np.empty_like(z)
    for i in range(z.size):
        e = np.zeros_like(z)
        e[i] = h
        g_zero[i] = (_simulated_cost(w, e, f_air, w_air) - _simulated_cost(w, -e, f_air, w_air)) / (2 * h)
    assert np.linalg.norm(grad) < 1e-6 * np.linalg.norm(g_zero), (np.linalg.norm(grad), np.linalg.norm(g_zero))
    for _ in range(5):
        d = 0.01 * rng.standard_normal(z.size)
        assert _simulated_cost(w, z + d, f_air, w_air) > j0


@pytest.mark.parametrize("spec", STRESS, ids=lambda s: f"{s.kind}-{s.axis}")
def test_set_points_stay_within_the_platform_limits_on_stress_signals(limits, spec):
    sig = generate(spec)
    w = MpcUnrestrictedWashout(None, _context(limits))
    pos, q = _run(w, sig.f_mps2, sig.omega_radps)
    _check_limits(pos, q, limits)
    rep = w.report()
    assert rep["solves"] == len(sig.f_mps2)
    assert rep["fallbacks"] <= 0.01 * rep["solves"], rep


def test_it_follows_a_sustained_yaw_rate_without_limit(limits):
    """A 90 deg/s yaw step held 6 s: the sphere yaws on through more than twice a hexapod's yaw travel (about
    +-30 deg), level (no false tilt), while the canals still feel the turn (they adapt within seconds: so does the
    plan)."""
    sig = generate(SignalSpec("step", "yaw", 90.0, duration_s=6.0, start_s=0.5))
    w = MpcUnrestrictedWashout(None, _context(limits))
    _, q = _run(w, sig.f_mps2, sig.omega_radps)
    rot = Rotation.from_quat(q[:, [1, 2, 3, 0]])
    rates = (rot[:-1].inv() * rot[1:]).as_rotvec() / DT
    turned = np.degrees(np.sum(rates[:, 2]) * DT)
    assert turned > 60.0, turned
    tilt = np.degrees(np.arccos(np.clip(rot.apply([0.0, 0.0, 1.0])[:, 2], -1.0, 1.0)))
    assert tilt.max() < 2.0  # about the vertical: no false tilt


def test_a_steady_tilted_start_holds_still(limits):
    """A steady climb (specific force tilted 6 deg nose up, |f| = g): the washout starts tilted to match and stays
    there: under a millimetre and 0.01 deg/s over 5 s (the linear MPC used to make a start-up move)."""
    th = math.radians(6.0)
    f = np.tile([G * math.sin(th), 0.0, -G * math.cos(th)], (600, 1))
    om = np.zeros((600, 3))
    w = MpcUnrestrictedWashout(None, _context(limits))
    _, q0 = w.start(f[0], om[0])
    assert np.allclose(Rotation.from_quat(q0[[1, 2, 3, 0]]).inv().apply([0, 0, -G]), f[0], atol=1e-9)
    pos, q = _run(w, f, om)
    assert np.abs(pos).max() < 1e-3
    rot = Rotation.from_quat(q[:, [1, 2, 3, 0]])
    rates = np.degrees(np.linalg.norm((rot[:-1].inv() * rot[1:]).as_rotvec(), axis=1) / DT)
    assert rates.max() < 0.01


def test_tilt_matched_gives_gravity_the_direction_of_the_force():
    rng = np.random.default_rng(1)
    for _ in range(20):
        f = rng.standard_normal(3) * 4.0 + np.array([0.0, 0.0, -G])
        q = tilt_matched(f)
        g_b = Rotation.from_quat(q[[1, 2, 3, 0]]).inv().apply([0.0, 0.0, -G])
        np.testing.assert_allclose(g_b / G, f / np.linalg.norm(f), atol=1e-12)


def test_preview_anticipates_and_no_preview_is_causal(limits):
    """A surge step at t = 2 s: without preview nothing moves before it (and ``trace`` gives the steps' numbers bit
    for bit); with 1 s of preview the stage is already moving forward before the step."""
    sig = generate(SignalSpec("step", "f_x", 2.0, duration_s=4.0, start_s=2.0))
    f, om = sig.f_mps2, sig.omega_radps
    before = round(1.95 / DT)
    plain = MpcUnrestrictedWashout(None, _context(limits))
    pos_s, q_s = _run(plain, f, om)
    again = MpcUnrestrictedWashout(None, _context(limits))
    again.start(f[0], om[0])
    pos_t, q_t = again.trace(f, om)
    assert np.array_equal(pos_s, pos_t) and np.array_equal(q_s, q_t)
    assert np.abs(pos_s[:before]).max() < 1e-9
    seeing = MpcUnrestrictedWashout(MpcUnrestrictedParams(preview_s=1.0), _context(limits))
    seeing.start(f[0], om[0])
    pos_p, _ = seeing.trace(f, om)
    assert np.abs(pos_p[:before]).max() > 1e-3
    _check_limits(pos_p, q_s, limits)


def test_preview_in_a_live_stream_is_refused(limits):
    w = MpcUnrestrictedWashout(MpcUnrestrictedParams(preview_s=0.5), _context(limits))
    w.start(np.array([0.0, 0.0, -G]), np.zeros(3))
    with pytest.raises(WashbenchError, match="preview_s"):
        w.step(np.array([0.0, 0.0, -G]), np.zeros(3))


def test_it_cannot_drive_a_hexapod():
    from washbench.cueing.variants import builtin, load_param_file, platform_refusal
    from washbench.io.paths import DATA_DIR
    from washbench.platform.model import load_platform_model

    platform = load_platform_model(DATA_DIR / "hexapod.yaml")
    spec = builtin(["mpc-unrestricted"], load_param_file(None)[0])[0]
    why = platform_refusal(spec, platform)
    assert why is not None and "mpc-unrestricted" in why and "\n" not in why


def test_run_with_only_preview_washouts_cues_them_after_the_flight(tmp_path):
    """``washbench run`` whose every washout needs the recording in advance (the MPC washouts with preview): the
    flight is flown alone and they are cued on it (before: "no washout selected"); both rank, and both start still
    on a steady level cruise (real JSBSim)."""
    import pyarrow.parquet as pq
    from ceiling_helpers import washbench
    from test_ceiling import CRUISE

    (tmp_path / "level_cruise.yaml").write_text(CRUISE)
    params = tmp_path / "p.yaml"
    params.write_text("mpc:\n  preview_s: 1.0\nmpc-unrestricted:\n  preview_s: 1.0\n")
    out = tmp_path / "o"
    proc = washbench("run", tmp_path / "level_cruise.yaml", "--out", out, "--washout", "mpc", "--washout",
                     "mpc-unrestricted", "--params", params, "--no-recording", "--no-figures", "--quiet")  # fmt: skip
    assert proc.returncode == 0, proc.stdout + proc.stderr
    run = out / "c172p" / "level_cruise"
    ranked = (run / "ranking.csv").read_text()
    assert ",mpc," in ranked and ",mpc-unrestricted," in ranked
    table = pq.read_table(run / "traces.parquet")
    for w in ("mpc", "mpc-unrestricted"):
        pos = np.column_stack([table.column(f"{w}.pos_{a}_m").to_numpy() for a in "xyz"])
        assert np.abs(pos).max() < 0.005, (w, np.abs(pos).max(0))  # no start-up move (it was 45 mm)


def test_an_axis_given_in_part_keeps_the_other_defaults():
    p = MpcUnrestrictedParams.model_validate({"rate": {"z": 2.0}, "position": {"x": 1.0}})
    d = MpcUnrestrictedParams()
    assert p.rate.xyz == (d.rate.x, d.rate.y, 2.0)
    assert p.position.xyz == (1.0, d.position.y, d.position.z)
    with pytest.raises(Exception, match="w"):
        MpcUnrestrictedParams.model_validate({"rate": {"w": 2.0}})


def test_the_share_figure_splits_the_force_into_stage_and_tilt_exactly(tmp_path):
    """``tools/mpc_share_figure.py`` (docs/optimal-mpc.md, "How it shares a cue"): on a real ``washbench cue`` of a
    sway doublet with ``mpc-unrestricted``, the head's specific force in ``traces.parquet`` is the stage's
    acceleration and gravity seen in the cockpit (scipy's rotation of the recorded attitude), with nothing left
    over on the bundled Atlas; gravity's part has the magnitude g; the tool writes its figure."""
    import subprocess
    import sys
    from pathlib import Path

    import pyarrow.parquet as pq
    from ceiling_helpers import washbench

    root = Path(__file__).resolve().parents[1]
    sys.path.insert(0, str(root / "tools"))
    from mpc_share_figure import split_force

    sig = tmp_path / "in.csv"
    proc = washbench("signal", "doublet", "--axis", "f_y", "--amplitude", "3", "--frequency-hz", "0.2",
                     "--duration-s", "12", "--rate-hz", "60", "--out", sig)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    out = tmp_path / "c"
    proc = washbench("cue", sig, "--out", out, "--washout", "small-angle", "--washout", "mpc-unrestricted",
                     "--no-recording", "--no-figures", "--quiet")  # fmt: skip
    assert proc.returncode == 0, proc.stdout + proc.stderr
    table = pq.read_table(out / "traces.parquet")
    parts = split_force(table, "mpc-unrestricted")
    assert np.abs(parts["rotation"]).max() < 1e-9
    np.testing.assert_allclose(np.linalg.norm(parts["tilt"], axis=1), G, rtol=1e-12)
    assert np.abs(parts["translation"][:, 1]).max() > 0.1  # the stage does move in sway
    png = tmp_path / "share.png"
    done = subprocess.run([sys.executable, str(root / "tools" / "mpc_share_figure.py"), str(png), str(out)],
                          capture_output=True, text=True, timeout=120)  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def _head_motion(pos: np.ndarray, q: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """The simulator pilot's head specific force and body rates (N, 3) of set points the Atlas reproduces exactly
    (the bundled Atlas: the head at the sphere's centre), independently of the washout: the stage's acceleration
    by the platform's own finite differences from rest at the centre, gravity and the rates by scipy Rotation."""
    p = np.vstack([np.zeros((2, 3)), pos])
    acc = (p[2:] - 2.0 * p[1:-1] + p[:-2]) / (dt * dt)
    rot = Rotation.from_quat(q[:, [1, 2, 3, 0]])
    f = rot.inv().apply(acc - np.array([0.0, 0.0, G]))
    w = np.vstack([np.zeros(3), (rot[:-1].inv() * rot[1:]).as_rotvec() / dt])
    return f, w


SWAY = SignalSpec("doublet", "f_y", 12.0, frequency_hz=0.5, duration_s=20.0)
"""The issue's sway doublet (``washbench signal doublet --axis f_y --amplitude 12 --frequency-hz 0.5 --duration-s
20``): +12 m/s^2 from 1 to 2 s, -12 from 2 to 3 s, then level flight to 20 s."""

SETTLE_S = 5.0
"""After a cue ends, mpc-unrestricted is level again (within 1 deg: gravity's sway within the threshold) and gives
no false cue beyond the thresholds within this time (measured: 3.5 s without preview, 2.8 s with 1 s)."""


@pytest.mark.parametrize("preview_s", [0.0, 1.0])
def test_after_a_sway_doublet_it_returns_to_level_and_gives_no_false_cue(limits, preview_s):
    """The issue's sway doublet, whose cue ends at t = 3 s: from 3 + SETTLE_S s on, the cockpit is within 1 deg of
    level (before: 4-7 deg held to the end, and 34-52 deg with 1 s of preview) and the simulator pilot feels no
    false cue beyond the thresholds (the ranking's false part, on the project's perception of the head motion
    computed here from the set points, is zero there), and no error beyond the thresholds at all in the last 5 s."""
    sig = generate(SWAY)
    dt = sig.dt_s
    w = MpcUnrestrictedWashout(MpcUnrestrictedParams(preview_s=preview_s), _context(limits))
    w.start(sig.f_mps2[0], sig.omega_radps[0])
    pos, q = w.trace(sig.f_mps2, sig.omega_radps)
    _check_limits(pos, q, limits)
    t = sig.t_s
    after = t >= 3.0 + SETTLE_S
    up = Rotation.from_quat(q[:, [1, 2, 3, 0]]).apply([0.0, 0.0, 1.0])
    tilt = np.degrees(np.arccos(np.clip(up[:, 2], -1.0, 1.0)))
    assert tilt[(t > 1.5) & (t < 3.5)].max() > 5.0  # it does tilt for the cue
    assert tilt[after].max() < 1.0, tilt[after].max()
    f, om = _head_motion(pos, q, dt)
    model = VestibularModel(dt)
    x = model.perceive(sig.f_mps2, sig.omega_radps)
    y = model.perceive(f, om)
    cols = lambda p: np.column_stack([p.f_mps2, np.degrees(p.omega_radps)])  # noqa: E731
    band = DEFAULT_MEASURE.bands()
    # the ranking's false part over what follows, against the aircraft pilot's start (prepended: the simulator pilot
    # is taken to feel the same there, so it adds nothing)
    x_after = np.vstack([cols(x)[:1], cols(x)[after]])
    y_after = np.vstack([cols(x)[:1], cols(y)[after]])
    rad = np.radians
    _, false = felt_errors(x_after[:, :3], rad(x_after[:, 3:]), y_after[:, :3], rad(y_after[:, 3:]), dt)
    assert np.all(false == 0.0), false
    last = t >= t[-1] - 5.0
    assert np.all(np.abs(cols(y) - cols(x))[last] < band)


def test_a_climb_is_followed_to_the_exact_gravity_direction(limits):
    """The aircraft pitches up at 5 deg/s (above the canal threshold) for 2 s and holds the 10 deg climb,
    unaccelerated (its specific force is gravity in its tilted body axes). mpc-unrestricted pitches with it (the
    perceived pitch-rate error stays within the threshold; the stage makes up the force while the pitch lags, the
    force being predicted to return to its recent mean) and settles on the climb's attitude, so that gravity alone
    gives the aircraft's specific force: 10 deg of pitch to 0.05 deg and the head's force to 0.01 m/s^2 after 40 s,
    the stage back within 2 cm of its centre, and within the thresholds from 6 s on."""
    dt = DT
    n = round(40.0 / dt) + 1
    t = np.arange(n) * dt
    theta = np.radians(5.0) * np.clip(t - 1.0, 0.0, 2.0)
    q_rate = np.where((t > 1.0) & (t <= 3.0), np.radians(5.0), 0.0)
    f = np.column_stack([G * np.sin(theta), np.zeros(n), -G * np.cos(theta)])
    om = np.column_stack([np.zeros(n), q_rate, np.zeros(n)])
    w = MpcUnrestrictedWashout(None, _context(limits))
    w.start(f[0], om[0])
    pos, q = w.trace(f, om)
    _check_limits(pos, q, limits)
    pitch = Rotation.from_quat(q[-1, [1, 2, 3, 0]]).as_euler("ZYX", degrees=True)[1]
    assert pitch == pytest.approx(10.0, abs=0.05)
    head, rates = _head_motion(pos, q, dt)
    np.testing.assert_allclose(head[-1], f[-1], atol=0.01)
    assert np.abs(pos[-1]).max() < 0.02
    model = VestibularModel(dt)
    err = np.degrees(model.perceive(head, rates).omega_radps - model.perceive(f, om).omega_radps)
    assert np.abs(err[:, 1]).max() < DEFAULT_MEASURE.units()[4], np.abs(err[:, 1]).max()
    f_err = np.abs(model.perceive(head, rates).f_mps2 - model.perceive(f, om).f_mps2)
    assert np.all(f_err[t > 6.0] < DEFAULT_MEASURE.units()[:3])


def test_a_pure_yaw_is_followed(limits):
    """A yaw rate of 10 deg/s held 4 s at level flight (gravity along the yaw axis: turning about it changes no
    force): the sphere turns with it, within 0.5 deg/s once the onset is past (its angular acceleration limit), by
    the same 40 deg of heading to 1 deg, and stays level."""
    sig = generate(SignalSpec("step", "yaw", 10.0, duration_s=6.0, start_s=1.0))
    w = MpcUnrestrictedWashout(None, _context(limits))
    w.start(sig.f_mps2[0], sig.omega_radps[0])
    pos, q = w.trace(sig.f_mps2, sig.omega_radps)
    _, rates = _head_motion(pos, q, sig.dt_s)
    t = sig.t_s
    steady = (t > 1.3) & (t < 5.0)
    assert np.abs(np.degrees(rates[steady, 2]) - 10.0).max() < 0.5
    turned = Rotation.from_quat(q[-1, [1, 2, 3, 0]]).as_euler("ZYX", degrees=True)
    assert turned[0] == pytest.approx(50.0, abs=1.0) and np.abs(turned[1:]).max() < 0.5


SHORT_MANOEUVRES = {
    "rudder_doublet_short": short_rudder_doublet("rudder_doublet_short", 8),
    "aileron_3211_short": """\
name: aileron_3211_short
description: the Columbia 400 aileron 3-2-1-1, shortened (settle 1 s, multistep 2.8 s, response 5 s, level 3 s)
aircraft: columbia400
start:
  air: {altitude_ft: 8000, airspeed_kts: 130, heading_deg: 90}
phases:
  - name: settle
    hold: {wings_level: true, altitude_ft: 8000, airspeed_kts: 130}
    until: {duration_s: 1}
  - name: multistep
    hold: {altitude_ft: 8000, airspeed_kts: 130}
    inputs:
      aileron: {shape: "3211", amplitude_deg: 5, duration_s: 2.8, free: true}
    until: {duration_s: 2.8}
  - name: response
    hold: {altitude_ft: 8000, airspeed_kts: 130}
    inputs:
      aileron: {free: true}
    until: {duration_s: 5}
  - name: level
    hold: {wings_level: true, altitude_ft: 8000, airspeed_kts: 130}
    until: {duration_s: 3}
""",
}
"""Two bundled manoeuvres on which mpc-unrestricted lost to a naive reference before (replay-rotation on the C172
rudder doublet, still on the Columbia aileron 3211), shortened to their inputs and response."""

REFERENCES = ("replay", "replay-rotation", "still")


def _felt_errors(run: Path) -> dict[str, float]:
    """washout -> its felt error, from a result folder's ranking.csv (ranked by the felt error)."""
    rows = read_csv(run / "ranking.csv")
    assert {r["rule"] for r in rows} == {"felt"}
    return {r["washout"]: float(r["score"]) for r in rows}


def test_it_beats_the_naive_references_on_two_short_real_manoeuvres(tmp_path):
    """``washbench suite`` (real JSBSim flights, the outputs a user reads): on both, mpc-unrestricted's felt error
    is below every naive reference's by at least a third (measured: 0.345 against replay-rotation's 0.730, and
    0.498 against still's 0.995; before, 0.944 and 1.527: both lost)."""
    for name, text in SHORT_MANOEUVRES.items():
        (tmp_path / f"{name}.yaml").write_text(text)
    out = tmp_path / "s"
    proc = washbench("suite", *[tmp_path / f"{n}.yaml" for n in SHORT_MANOEUVRES], "--out", out,
                     "--washout", "mpc-unrestricted", *[a for r in REFERENCES for a in ("--washout", r)],
                     "--no-recording", "--no-figures", "--quiet")  # fmt: skip
    assert proc.returncode == 0, proc.stdout + proc.stderr
    runs = sorted(p.parent for p in out.glob("*/*/ranking.csv"))
    assert len(runs) == 2
    for run in runs:
        felt = _felt_errors(run)
        best = min(felt[r] for r in REFERENCES)
        assert felt["mpc-unrestricted"] < 0.67 * best, (run.name, felt)


@pytest.mark.skipif(not (os.environ.get("WASHBENCH_MPCU_SUITE") or os.environ.get("WASHBENCH_SLOW")),
                    reason="every bundled manoeuvre: WASHBENCH_MPCU_SUITE=<suite folder> or WASHBENCH_SLOW=1 "
                    "(minutes; .ci/run runs it)")  # fmt: skip
def test_it_beats_every_naive_reference_on_every_bundled_manoeuvre(tmp_path):
    """On each of the 22 bundled manoeuvres, mpc-unrestricted's felt error is below that of every naive reference
    (replay, replay-rotation, still); a suite folder run with them (``WASHBENCH_MPCU_SUITE``) is checked as is."""
    given = os.environ.get("WASHBENCH_MPCU_SUITE")
    out = Path(given) if given else tmp_path / "suite"
    if not given:
        proc = washbench("suite", "--out", out, "--washout", "mpc-unrestricted",
                         *[a for r in REFERENCES for a in ("--washout", r)], "--no-recording", "--no-figures",
                         "--quiet")  # fmt: skip
        assert proc.returncode == 0, proc.stdout + proc.stderr
    bundled = sorted(p.relative_to(MANOEUVRES_DIR).with_suffix("") for p in MANOEUVRES_DIR.rglob("*.yaml"))
    runs = sorted(p.parent for p in out.glob("*/*/ranking.csv"))
    assert len(runs) == len(bundled)
    lost = []
    for run in runs:
        felt = _felt_errors(run)
        best = min(felt[r] for r in REFERENCES)
        if not felt["mpc-unrestricted"] < best:
            lost.append((f"{run.parent.name}/{run.name}", felt["mpc-unrestricted"], best))
    assert not lost, lost
