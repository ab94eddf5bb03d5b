"""Property-based: random, extreme and degenerate inputs never give non-finite output or a broken limit."""

import math

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from washbench.cueing import WASHOUT_NAMES, cue_trace, load_washout_params
from washbench.platform import load_platform_limits

G = 9.80665
DT = 1.0 / 120.0
PARAMS = load_washout_params()
LIMITS = load_platform_limits()
LIM = LIMITS.translation
P_MAX = np.array([LIM.position_limit_m.x, LIM.position_limit_m.y, LIM.position_limit_m.z])
V_MAX = np.array([LIM.velocity_limit_mps.x, LIM.velocity_limit_mps.y, LIM.velocity_limit_mps.z])
A_MAX = np.array([LIM.acceleration_limit_mps2.x, LIM.acceleration_limit_mps2.y, LIM.acceleration_limit_mps2.z])
W_MAX = math.radians(LIMITS.rotation.rate_limit_degps)
ALPHA = math.radians(LIMITS.rotation.acceleration_limit_degps2)

component = st.one_of(
    st.floats(-1e6, 1e6, allow_nan=False, allow_infinity=False),
    st.sampled_from([0.0, -0.0, G, -G, 1e-300, -1e-300, 1e6, -1e6]),
)
vec = st.tuples(component, component, component)
segment = st.tuples(vec, vec, st.integers(1, 120))  # (f, omega, samples held)


def build(segments):
    f = np.concatenate([np.tile(s[0], (s[2], 1)) for s in segments]).astype(float)
    w = np.concatenate([np.tile(s[1], (s[2], 1)) for s in segments]).astype(float)
    return f, w


def check(tr):
    for name in ("pos_m", "vel_mps", "acc_mps2", "q", "omega_radps", "head_f_mps2", "head_omega_radps"):
        assert np.isfinite(getattr(tr, name)).all(), name
    assert np.isfinite(tr.wheel_radps).all()
    np.testing.assert_allclose(np.linalg.norm(tr.q, axis=1), 1.0, atol=1e-9)
    np.testing.assert_allclose(np.linalg.norm(tr.sp_q, axis=1), 1.0, atol=1e-9)
    assert (np.abs(tr.pos_m) <= P_MAX).all()
    assert (np.abs(tr.vel_mps) <= V_MAX * (1 + 1e-12)).all()
    assert (np.abs(tr.acc_mps2) <= A_MAX * (1 + 1e-9)).all()
    assert (np.linalg.norm(tr.omega_radps, axis=1) <= W_MAX * (1 + 1e-12)).all()
    if len(tr.omega_radps) > 1:
        dw = np.linalg.norm(np.diff(tr.omega_radps, axis=0), axis=1) / DT
        assert dw.max() <= ALPHA * (1 + 1e-9)


@settings(max_examples=50, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(segment, min_size=1, max_size=6))
def test_random_and_extreme_inputs(segments):
    f, w = build(segments)
    for tr in cue_trace(f, w, DT, WASHOUT_NAMES, PARAMS, LIMITS).values():
        check(tr)


@settings(max_examples=30, deadline=None)
@given(
    pitch_deg=st.floats(80.0, 100.0),
    sign=st.sampled_from([1.0, -1.0]),
    q_rate=st.floats(-1.0, 1.0),
    roll_rate=st.floats(-1.0, 1.0),
)
def test_ninety_degree_pitch(pitch_deg, sign, q_rate, roll_rate):
    # an aircraft near vertical: specific force along the body x axis; the Euler-angle washout must stay finite
    th = math.radians(pitch_deg)
    n = 900
    f = np.tile([sign * G * math.sin(th), 0.0, -G * math.cos(th)], (n, 1))
    w = np.tile([roll_rate, q_rate, 0.0], (n, 1))
    f[: n // 3] = [0.0, 0.0, -G]  # start level, then pitch up
    for tr in cue_trace(f, w, DT, WASHOUT_NAMES, PARAMS, LIMITS).values():
        check(tr)


@settings(max_examples=10, deadline=None)
@given(rate=vec.filter(lambda v: 0.01 < math.sqrt(sum(x * x for x in v)) < 1e7))
def test_long_sustained_rotation(rate):
    n = int(120 / DT)
    f = np.tile([0.0, 0.0, -G], (n, 1))
    w = np.tile(rate, (n, 1))
    for tr in cue_trace(f, w, DT, WASHOUT_NAMES, PARAMS, LIMITS).values():
        check(tr)


@settings(max_examples=20, deadline=None)
@given(st.lists(segment, min_size=1, max_size=4))
def test_deterministic(segments):
    f, w = build(segments)
    a = cue_trace(f, w, DT, WASHOUT_NAMES, PARAMS, LIMITS)
    b = cue_trace(f, w, DT, WASHOUT_NAMES, PARAMS, LIMITS)
    for name in WASHOUT_NAMES:
        np.testing.assert_array_equal(a[name].head_f_mps2, b[name].head_f_mps2)
        np.testing.assert_array_equal(a[name].q, b[name].q)
