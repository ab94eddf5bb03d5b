"""Kinematic Atlas model: braking, limits never exceeded, exact tracking inside them, wheel speeds."""

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from washbench.errors import WashbenchError
from washbench.platform import load_platform_limits, wheel_geometry, wheel_jacobian
from washbench.platform.kinematics import brake_speed, track_axis, track_rotation, wheel_speeds

DT = 1.0 / 120.0


def brake_distance(v: float, a_max: float, dt: float) -> float:
    """Simulate the discrete stage: one step at v, then full braking until stopped; distance covered."""
    p = v * dt
    while v > 0.0:
        v = max(v - a_max * dt, 0.0)
        p += v * dt
    return p


@pytest.mark.parametrize("r", [0.0, 1e-6, 0.004, 0.05, 0.3, 1.0, 2.5])
@pytest.mark.parametrize("a_max", [0.5, 9.81])
def test_brake_speed_is_the_largest_safe_speed(r, a_max):
    v = brake_speed(r, a_max, DT)
    assert brake_distance(v, a_max, DT) <= r + 1e-12
    assert brake_distance(v * (1 + 1e-6) + 1e-9, a_max, DT) > r
    # continuous limit: v^2 / (2 a) ~ r for large r
    if r > 0.2:
        assert v == pytest.approx(math.sqrt(2 * a_max * r), rel=0.05)


def run_axis(sp: np.ndarray, p_max=1.0, v_max=1.5, a_max=5.0, catch_up=0.5):
    p = v = 0.0
    sp_prev = 0.0
    ps, vs, flags = [], [], []
    for s in sp:
        p, v, *f = track_axis(p, v, sp_prev, s, p_max, v_max, a_max, catch_up, DT)
        sp_prev = s
        ps.append(p)
        vs.append(v)
        flags.append(f)
    return np.array(ps), np.array(vs), np.array(flags)


def test_axis_follows_a_feasible_set_point_exactly():
    t = np.arange(1200) * DT
    sp = 0.3 * np.sin(0.8 * t) ** 3  # starts at rest, peak acceleration about 0.2 m/s^2
    p, _, flags = run_axis(sp)
    np.testing.assert_array_equal(p, sp)
    assert flags.sum() == 0


def test_axis_never_exceeds_any_limit_on_a_wild_set_point():
    rng = np.random.default_rng(3)
    sp = np.repeat(rng.uniform(-5, 5, 20), 240) + 0.01 * rng.normal(size=4800)
    p_max, v_max, a_max = 1.0, 1.5, 5.0
    p, v, flags = run_axis(sp, p_max, v_max, a_max)
    a = np.diff(np.concatenate(([0.0], v))) / DT
    assert np.abs(p).max() <= p_max
    assert np.abs(v).max() <= v_max + 1e-12
    assert np.abs(a).max() <= a_max * (1 + 1e-9)
    assert (flags.sum(axis=0) > 0).all()  # position, velocity and acceleration all bound at some step


def test_axis_brakes_in_time_for_a_set_point_beyond_travel():
    sp = np.full(600, 3.0)  # 3 m away, travel +-1 m
    p, v, flags = run_axis(sp, 1.0, 1.5, 2.0)
    assert p.max() <= 1.0
    assert p[-1] == pytest.approx(1.0, abs=1e-3)  # parked at the end stop, not short of it
    assert abs(v[-1]) < 1e-9
    assert flags[:, 0].sum() > 0


def test_axis_catches_up_without_overshoot_after_saturation():
    sp = np.concatenate((np.linspace(0, 0.8, 10), np.full(600, 0.8)))  # too fast: acceleration-limited
    p, _, flags = run_axis(sp, 1.0, 1.5, 5.0)
    assert flags[:10, 2].sum() > 0
    assert p.max() <= 0.8 + 1e-12
    assert p[-1] == pytest.approx(0.8, abs=1e-12)


def test_rotation_limits_and_exact_tracking():
    w_max, alpha = math.radians(32.2), math.radians(100.0)
    q = q_sp_prev = (1.0, 0.0, 0.0, 0.0)
    w = (0.0, 0.0, 0.0)
    rot = Rotation.identity()
    ws, sats = [], []
    body = np.array([0.3, -1.0, 2.0])  # 128 deg/s: far beyond the rate limit
    for k in range(600):
        rate = body if k < 300 else np.array([0.0, 0.0, 0.0])
        rot = rot * Rotation.from_rotvec(rate * DT)
        x, y, z, s = rot.as_quat()
        q_sp = (s, x, y, z)
        q, w, sr, sa = track_rotation(q, w, q_sp_prev, q_sp, w_max, alpha, 0.5, DT)
        q_sp_prev = q_sp
        ws.append(w)
        sats.append((sr, sa))
    ws = np.array(ws)
    assert np.linalg.norm(ws, axis=1).max() <= w_max * (1 + 1e-12)
    dw = np.linalg.norm(np.diff(np.vstack(([0, 0, 0], ws)), axis=0), axis=1) / DT
    assert dw.max() <= alpha * (1 + 1e-9)
    sats = np.array(sats)
    assert sats[:, 0].sum() > 0 and sats[:, 1].sum() > 0
    # a slow set point inside the limits is followed exactly
    q = q_sp_prev = (1.0, 0.0, 0.0, 0.0)
    w = (0.0, 0.0, 0.0)
    rot = Rotation.identity()
    for k in range(240):
        rot = rot * Rotation.from_rotvec(np.array([0.0, 0.0, 0.1]) * min(k * DT, 1.0) * DT)
        x, y, z, s = rot.as_quat()
        q_sp = (s, x, y, z)
        q, w, sr, sa = track_rotation(q, w, q_sp_prev, q_sp, w_max, alpha, 0.5, DT)
        q_sp_prev = q_sp
        assert q == q_sp and sr + sa == 0


def test_wheel_speeds_equal_contact_surface_speed():
    limits = load_platform_limits()
    jac = wheel_jacobian(limits)
    r, d = wheel_geometry(limits)
    rng = np.random.default_rng(11)
    for _ in range(10):
        w = rng.normal(size=3)
        h = 1e-6
        # surface velocity of the sphere point at each contact, by finite differences of a scipy rotation
        moved = Rotation.from_rotvec(w * h).apply(r)
        back = Rotation.from_rotvec(-w * h).apply(r)
        surface_speed = np.einsum("ij,ij->i", (moved - back) / (2 * h), d)
        expected = surface_speed / limits.wheels.radius_m
        np.testing.assert_allclose(wheel_speeds(jac.ravel(), tuple(w)), expected, rtol=1e-7, atol=1e-9)
    # the geometry is documented: contacts on the 2.9 m sphere, Jacobian invertible (orthogonal rows here)
    np.testing.assert_allclose(np.linalg.norm(r, axis=1), 1.45)
    assert abs(np.linalg.det(jac)) > 1.0


def test_limits_yaml_rejects_unknown_key(tmp_path):
    text = (load_platform_limits.__globals__["DEFAULT_LIMITS_PATH"]).read_text()
    bad = tmp_path / "atlas.yaml"
    bad.write_text(text.replace("  rate_limit_degps: 32.2", "  rate_limit_degps: 32.2\n  rate_limt_degps: 30"))
    with pytest.raises(WashbenchError) as info:
        load_platform_limits(bad)
    msg = str(info.value)
    assert "\n" not in msg
    assert msg.startswith(f"{bad}:")
    assert "rotation.rate_limt_degps: unknown key" in msg


def test_limits_yaml_rejects_a_negative_limit(tmp_path):
    text = (load_platform_limits.__globals__["DEFAULT_LIMITS_PATH"]).read_text()
    bad = tmp_path / "atlas.yaml"
    bad.write_text(text.replace("    z: 1.0\n", "    z: -1.0\n", 1))
    with pytest.raises(WashbenchError, match=r"atlas.yaml:\d+: translation.position_limit_m.z: "):
        load_platform_limits(bad)
