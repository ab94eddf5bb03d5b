"""The three washouts with the Atlas model and head motion, against physics and closed forms."""

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from washbench.cueing import WASHOUT_NAMES, CueingBank, WashoutTrace, cue_trace, load_washout_params
from washbench.cueing.params import DEFAULT_PARAMS_PATH
from washbench.errors import WashbenchError
from washbench.platform import load_platform_limits

G = 9.80665
DT = 1.0 / 120.0
PARAMS = load_washout_params()
LIMITS = load_platform_limits()


def rest(n: int) -> tuple[np.ndarray, np.ndarray]:
    f = np.zeros((n, 3))
    f[:, 2] = -G
    return f, np.zeros((n, 3))


def euler_zyx(q: np.ndarray) -> np.ndarray:
    """(N, 3) yaw, pitch, roll in rad from scalar-first quaternions, via scipy."""
    return Rotation.from_quat(q[:, [1, 2, 3, 0]]).as_euler("ZYX")


def total_angle(q: np.ndarray) -> np.ndarray:
    """Accumulated rotation angle (rad) of successive attitudes: sum of the step angles."""
    rot = Rotation.from_quat(q[:, [1, 2, 3, 0]])
    steps = (rot[:-1].inv() * rot[1:]).magnitude()
    return np.concatenate(([0.0], np.cumsum(steps)))


@pytest.mark.parametrize("washout", WASHOUT_NAMES)
def test_rest_gives_rest(washout):
    tr = cue_trace(*rest(600), DT, [washout], PARAMS, LIMITS)[washout]
    assert np.abs(tr.pos_m).max() == 0.0
    np.testing.assert_allclose(tr.q, np.tile([1.0, 0, 0, 0], (600, 1)), atol=1e-15)
    np.testing.assert_allclose(tr.head_f_mps2, np.tile([0, 0, -G], (600, 1)), atol=1e-12)  # Table 2: rest
    assert np.abs(tr.head_omega_radps).max() < 1e-12
    assert all(v == 0 for v in tr.saturation_counts.values())


@pytest.mark.parametrize("washout", WASHOUT_NAMES)
@pytest.mark.parametrize(("f_z", "expected_head_f_z"), [(0.0, 0.0), (-2 * G, -2 * G)], ids=["free fall", "1 g up"])
def test_table2_onsets_and_head_specific_force_identity(washout, f_z, expected_head_f_z):
    f, w = rest(360)
    f[120:, 2] = f_z
    tr = cue_trace(f, w, DT, [washout], PARAMS, LIMITS)[washout]
    # Table 2: the platform's vertical acceleration at the onset reproduces a = f + g (free fall: a = +g,
    # 1 g up: a = -g), so the head feels f = a - g; bilinear high-pass: first sample within a few %.
    assert tr.head_f_mps2[120, 2] == pytest.approx(expected_head_f_z, abs=0.05 * G)
    assert tr.acc_mps2[120, 2] == pytest.approx(f_z + G, abs=0.05 * G)
    # everywhere: head f = L_SI (a_platform - g_I) (R_SS = 0), computed here with scipy
    rot = Rotation.from_quat(tr.q[:, [1, 2, 3, 0]])
    expected = rot.inv().apply(tr.acc_mps2 - np.array([0.0, 0.0, G]))
    np.testing.assert_allclose(tr.head_f_mps2, expected, atol=1e-9)


@pytest.mark.parametrize("washout", WASHOUT_NAMES)
@pytest.mark.parametrize("axis", ["surge", "sway"])
@pytest.mark.parametrize("magnitude", [0.5, 3.0])
def test_steady_state_tilt_is_atan_f_over_g(washout, axis, magnitude):
    n = int(90 / DT)
    f, w = rest(n)
    f[60:, 0 if axis == "surge" else 1] = magnitude
    tr = cue_trace(f, w, DT, [washout], PARAMS, LIMITS)[washout]
    yaw, pitch, roll = euler_zyx(tr.q).T
    expected = math.atan(magnitude / G)
    if axis == "surge":
        tilt, other = pitch, roll
    else:
        tilt, other = -roll, pitch  # a rightward specific force needs a roll to the left
        expected = math.atan(magnitude / G)
    assert tilt[-1] == pytest.approx(expected, abs=1e-6)
    assert tilt.max() <= expected + 1e-6  # aligns without overshoot
    assert np.abs(other).max() < 1e-9 and np.abs(yaw).max() < 1e-9
    # the tilt rate limit (3 deg/s) is honoured by the tilt alone
    assert np.abs(np.diff(tilt)).max() / DT <= math.radians(3.0) * (1 + 1e-6)
    # sustained: the head feels the specific force's direction, with |f| = g
    fh = tr.head_f_mps2[-1]
    assert math.atan2(abs(fh[0] + fh[1]), -fh[2]) == pytest.approx(expected, abs=1e-6)


@pytest.mark.parametrize("axis", [0, 2], ids=["roll", "yaw"])
def test_unrestricted_keeps_sustained_rotation_others_wash_it_out(axis):
    n = int(60 / DT)
    f, w = rest(n)
    w[60:, axis] = math.radians(20.0)
    traces = cue_trace(f, w, DT, WASHOUT_NAMES, PARAMS, LIMITS)
    turned = {name: math.degrees(total_angle(tr.q)[-1]) for name, tr in traces.items()}
    assert turned["unrestricted"] > 360.0
    # head angular velocity of the unrestricted washout = the aircraft's rate (minus the tilt counter-roll)
    head = traces["unrestricted"].head_omega_radps[-1, axis]
    assert math.degrees(head) == pytest.approx(20.0 if axis == 2 else 17.0, abs=0.05)
    for name in ("small-angle", "large-angle"):
        tr = traces[name]
        angle = np.degrees(Rotation.from_quat(tr.q[:, [1, 2, 3, 0]]).magnitude())
        # first-order high-pass then integration: the attitude settles at rate / wn = 40 deg at most
        assert angle.max() < 41.0
        assert abs(math.degrees(tr.head_omega_radps[-1, axis])) < 0.01  # the sustained rate is washed out
        if axis == 0:
            assert angle[-1] < 1.0  # the tilt coordination brings a roll back to level (gravity aligned)


def test_head_offset_gives_centripetal_specific_force():
    params = PARAMS.model_copy(update={"head": PARAMS.head.model_copy(update={"offset_m": (1.0, 0.0, 0.0)})})
    n = int(20 / DT)
    f, w = rest(n)
    rate = math.radians(20.0)
    w[:, 2] = rate  # already turning at the first sample: steady state
    tr = cue_trace(f, w, DT, ["unrestricted"], params, LIMITS)["unrestricted"]
    # head 1 m ahead of the centre of a sphere yawing at r: a = -r^2 R (towards the centre)
    np.testing.assert_allclose(tr.head_f_mps2[-1], [-(rate**2), 0.0, -G], atol=1e-6)


@pytest.mark.parametrize("washout", WASHOUT_NAMES)
def test_platform_follows_set_points_exactly_inside_limits(washout):
    n = int(30 / DT)
    t = np.arange(n) * DT
    f, w = rest(n)
    f[:, 0] = 0.8 * np.sin(0.4 * t) ** 3
    f[:, 1] = 0.5 * np.sin(0.3 * t) ** 3
    w[:, 0] = 0.1 * np.sin(0.5 * t) ** 3
    w[:, 2] = 0.05 * np.sin(0.2 * t) ** 3
    tr = cue_trace(f, w, DT, [washout], PARAMS, LIMITS)[washout]
    assert sum(tr.saturation_counts[k] for k in ("pos", "vel", "acc", "rate", "angacc")) == 0
    np.testing.assert_array_equal(tr.pos_m, tr.sp_pos_m)
    np.testing.assert_array_equal(tr.q, tr.sp_q)
    assert np.abs(tr.pos_m).max() > 0.01  # something happened


@pytest.mark.parametrize("washout", WASHOUT_NAMES)
def test_huge_inputs_saturate_without_exceeding_any_limit(washout):
    rng = np.random.default_rng(5)
    n = int(40 / DT)
    f = np.repeat(rng.uniform(-60, 60, (40, 3)), n // 40, axis=0)
    w = np.repeat(rng.uniform(-3, 3, (40, 3)), n // 40, axis=0)
    tr = cue_trace(f, w, DT, [washout], PARAMS, LIMITS)[washout]
    lim = LIMITS.translation
    assert (np.abs(tr.pos_m) <= [lim.position_limit_m.x, lim.position_limit_m.y, lim.position_limit_m.z]).all()
    vmax = np.array([lim.velocity_limit_mps.x, lim.velocity_limit_mps.y, lim.velocity_limit_mps.z])
    assert (np.abs(tr.vel_mps) <= vmax * (1 + 1e-12)).all()
    amax = np.array([lim.acceleration_limit_mps2.x, lim.acceleration_limit_mps2.y, lim.acceleration_limit_mps2.z])
    assert (np.abs(tr.acc_mps2) <= amax * (1 + 1e-9)).all()
    w_norm = np.linalg.norm(tr.omega_radps, axis=1)
    assert w_norm.max() <= math.radians(LIMITS.rotation.rate_limit_degps) * (1 + 1e-12)
    dw = np.linalg.norm(np.diff(tr.omega_radps, axis=0), axis=1) / DT
    assert dw.max() <= math.radians(LIMITS.rotation.acceleration_limit_degps2) * (1 + 1e-9)
    for kind, count in tr.saturation_counts.items():
        assert count > 0, kind
        assert count == tr.saturated[kind].sum()
    np.testing.assert_allclose(np.linalg.norm(tr.q, axis=1), 1.0, atol=1e-12)


def test_streaming_and_whole_trace_identical_bit_for_bit():
    rng = np.random.default_rng(9)
    n = 3000
    f = rest(n)[0] + np.repeat(rng.normal(0, 4, (30, 3)), n // 30, axis=0) + rng.normal(0, 0.3, (n, 3))
    w = np.repeat(rng.normal(0, 0.5, (30, 3)), n // 30, axis=0)
    traces = cue_trace(f, w, DT, WASHOUT_NAMES, PARAMS, LIMITS)
    bank = CueingBank(WASHOUT_NAMES, PARAMS, LIMITS, DT)
    rows = np.empty((len(WASHOUT_NAMES), n, len(CueingBank.FIELDS)))
    for k in range(n):
        rows[:, k] = bank.step(f[k], w[k])
    for i, name in enumerate(WASHOUT_NAMES):
        streamed = WashoutTrace.from_rows(rows[i])
        whole = traces[name]
        for field in ("pos_m", "vel_mps", "acc_mps2", "q", "omega_radps", "head_f_mps2", "head_omega_radps"):
            np.testing.assert_array_equal(getattr(streamed, field), getattr(whole, field), err_msg=field)
        np.testing.assert_array_equal(streamed.wheel_radps, whole.wheel_radps)
        assert streamed.saturation_counts == whole.saturation_counts == bank.saturation_counts()[name]
    # blocks of samples (CueingBank.steps, what washbench run uses), mixed with single steps: the same bits
    blocked = CueingBank(WASHOUT_NAMES, PARAMS, LIMITS, DT)
    parts = [blocked.steps(f[:1000], w[:1000]), blocked.step(f[1000], w[1000])[:, None].copy()]
    parts.append(blocked.steps(f[1001:1001], w[1001:1001]))
    parts.append(blocked.steps(f[1001:], w[1001:]))
    np.testing.assert_array_equal(np.concatenate(parts, axis=1), rows)
    assert blocked.saturation_counts() == bank.saturation_counts()
    with pytest.raises(ValueError, match="non-finite"):
        blocked.steps(np.full((2, 3), np.nan), np.zeros((2, 3)))


def test_step_accepts_lists_and_reuses_its_output():
    bank = CueingBank(["large-angle"], PARAMS, LIMITS, DT)
    out1 = bank.step([0.0, 0.0, -G], [0.0, 0.0, 0.0])
    out2 = bank.step(np.array([1.0, 0.0, -G]), np.zeros(3))
    assert out1 is out2 and out1.shape == (1, len(CueingBank.FIELDS))
    with pytest.raises(ValueError, match="non-finite"):
        bank.step(np.array([np.nan, 0.0, -G]), np.zeros(3))


def test_fields_are_documented_names():
    fields = CueingBank.FIELDS
    assert len(set(fields)) == len(fields)
    assert fields[:3] == ("pos_x_m", "pos_y_m", "pos_z_m")
    assert {"head_f_z_mps2", "head_omega_x_radps", "wheel_3_radps", "sat_rot_rate", "sat_tilt_rate"} <= set(fields)


def test_bad_washout_name_and_bad_input_are_one_line_errors():
    with pytest.raises(WashbenchError, match="unknown washout 'tiny-angle'"):
        CueingBank(["tiny-angle"], PARAMS, LIMITS, DT)
    f, w = rest(10)
    f[4, 1] = np.inf
    with pytest.raises(WashbenchError, match=r"non-finite .* at sample 4"):
        cue_trace(f, w, DT, ["small-angle"], PARAMS, LIMITS)
    with pytest.raises(WashbenchError, match="positive"):
        cue_trace(*rest(10), 0.0, ["small-angle"], PARAMS, LIMITS)


def test_params_yaml_bad_key_is_one_line_error(tmp_path):
    bad = tmp_path / "cw1.yaml"
    bad.write_text(DEFAULT_PARAMS_PATH.read_text().replace("  gain_per_s: 0.4", "  gain_per_s: 0.4\n  gian: 1"))
    with pytest.raises(WashbenchError) as info:
        load_washout_params(bad)
    msg = str(info.value)
    assert "\n" not in msg
    line = next(i for i, s in enumerate(bad.read_text().splitlines(), 1) if s.startswith("  gian:"))
    assert msg.startswith(f"{bad}:{line}: tilt.gian: unknown key")


def test_params_yaml_rejects_text_for_a_number(tmp_path):
    bad = tmp_path / "cw1.yaml"
    bad.write_text(DEFAULT_PARAMS_PATH.read_text().replace("  x: 1.5   ", "  x: fast   ", 1))
    with pytest.raises(WashbenchError, match=r"cw1.yaml:\d+: translational_highpass_wn_radps.x: expected a number"):
        load_washout_params(bad)


def test_bundled_cw1_values():
    assert PARAMS.translational_highpass_wn_radps.x == 1.5
    assert PARAMS.translational_highpass_wn_radps.y == PARAMS.translational_highpass_wn_radps.z == 3.5
    assert PARAMS.rotational.highpass_wn_radps.roll == 0.5
    assert PARAMS.tilt.rate_limit_degps == 3.0 and PARAMS.rotational.saturation_degps == 32.2
