"""Quaternion and Euler kinematics against scipy.spatial.transform.Rotation and closed forms."""

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from washbench.numerics import rotations as r

RNG = np.random.default_rng(7)
ROTS = Rotation.random(20, random_state=3)
VECS = RNG.normal(size=(20, 3))


def wxyz(rot: Rotation) -> tuple:
    x, y, z, w = rot.as_quat()
    return (w, x, y, z)


def as_rot(q) -> Rotation:
    return Rotation.from_quat([q[1], q[2], q[3], q[0]])


def same_rotation(q, rot: Rotation, atol=1e-12):
    q = np.array(q)
    ref = np.array(wxyz(rot))
    assert min(np.abs(q - ref).max(), np.abs(q + ref).max()) < atol


@pytest.mark.parametrize("i", range(10))
def test_product_composes_rotations(i):
    a, b = ROTS[i], ROTS[i + 10]
    same_rotation(r.qmul(wxyz(a), wxyz(b)), a * b)


@pytest.mark.parametrize("i", range(20))
def test_rotation_eq15_matches_scipy_and_the_literal_product(i):
    q = wxyz(ROTS[i])
    v = tuple(VECS[i])
    np.testing.assert_allclose(r.qrot(q, v), ROTS[i].apply(v), atol=1e-12)
    np.testing.assert_allclose(r.qrot_inv(q, v), ROTS[i].inv().apply(v), atol=1e-12)
    # Eq. 15 literally: (-q) (x) [0, f] (x) (-q*)
    mq = tuple(-x for x in q)
    lit = r.qmul(r.qmul(mq, (0.0, *v)), r.qconj(mq))
    assert abs(lit[0]) < 1e-12
    np.testing.assert_allclose(lit[1:], r.qrot(q, v), atol=1e-12)


@pytest.mark.parametrize("i", range(20))
def test_euler_zyx_round_trip_and_matrix(i):
    psi, theta, phi = ROTS[i].as_euler("ZYX")
    same_rotation(r.quat_from_euler(phi, theta, psi), ROTS[i])
    np.testing.assert_allclose(r.euler_from_quat(wxyz(ROTS[i])), (phi, theta, psi), atol=1e-10)
    v = tuple(VECS[i])
    np.testing.assert_allclose(r.rot_euler(phi, theta, psi, v), ROTS[i].as_matrix() @ VECS[i], atol=1e-12)
    np.testing.assert_allclose(r.rot_euler_inv(phi, theta, psi, v), ROTS[i].as_matrix().T @ VECS[i], atol=1e-12)


@pytest.mark.parametrize("i", range(20))
def test_integrator_eq17_matches_rotvec_composition(i):
    w = tuple(VECS[i])
    dt = 0.37
    q1 = r.qintegrate(wxyz(ROTS[i]), w, dt)
    same_rotation(q1, ROTS[i] * Rotation.from_rotvec(np.array(w) * dt))
    assert math.isclose(sum(x * x for x in q1), 1.0, abs_tol=1e-15)


def test_integrator_at_rest_and_tiny_rates():
    assert r.qintegrate(r.IDENTITY, (0.0, 0.0, 0.0), 0.01) == (1.0, 0.0, 0.0, 0.0)
    w = (1e-12, -2e-12, 3e-12)
    same_rotation(r.qintegrate(r.IDENTITY, w, 0.01), Rotation.from_rotvec(np.array(w) * 0.01), atol=1e-20)


@pytest.mark.parametrize("i", range(20))
def test_body_rate_eq18_19_of_a_constant_rotation(i):
    w = VECS[i]
    dt = 1.0 / 120.0
    q0 = wxyz(ROTS[i])
    q1 = wxyz(ROTS[i] * Rotation.from_rotvec(w * dt))
    est = np.array(r.qrate_body(q1, q0, dt))
    n = np.linalg.norm(w)
    np.testing.assert_allclose(est, 2 * math.sin(n * dt / 2) / dt * w / n, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(est, w, rtol=n**2 * dt**2 / 20 + 1e-9)
    # a sign flip of either quaternion (same attitude) changes nothing
    np.testing.assert_allclose(r.qrate_body(q1, tuple(-x for x in q0), dt), est, atol=1e-9)


@pytest.mark.parametrize("i", range(20))
def test_rotvec_is_shortest_rotation(i):
    q = wxyz(ROTS[i])
    np.testing.assert_allclose(r.qrotvec(q), ROTS[i].as_rotvec(), atol=1e-10)
    np.testing.assert_allclose(r.qrotvec(tuple(-x for x in q)), ROTS[i].as_rotvec(), atol=1e-10)


@pytest.mark.parametrize("i", range(20))
def test_euler_rates_are_the_derivative_of_euler_angles(i):
    # pitch kept within +-69 deg: finite differences of Euler angles are ill-conditioned at gimbal lock
    rng = np.random.default_rng(100 + i)
    phi, theta, psi = rng.uniform(-3.0, 3.0), rng.uniform(-1.2, 1.2), rng.uniform(-3.0, 3.0)
    rot = Rotation.from_euler("ZYX", [psi, theta, phi])
    w = VECS[i]
    h = 1e-6
    fwd = (rot * Rotation.from_rotvec(w * h)).as_euler("ZYX")
    bwd = (rot * Rotation.from_rotvec(-w * h)).as_euler("ZYX")
    dpsi, dtheta, dphi = (fwd - bwd) / (2 * h)
    rates = r.euler_rates(phi, theta, tuple(w), 1e-3)
    np.testing.assert_allclose(rates, (dphi, dtheta, dpsi), rtol=1e-6, atol=1e-6)
    np.testing.assert_allclose(r.body_rates(phi, theta, rates), w, atol=1e-12)


def test_euler_rates_stay_finite_at_90_deg_pitch():
    rates = r.euler_rates(0.3, math.pi / 2, (0.1, 0.2, 0.3), 0.0174524)
    assert all(math.isfinite(x) for x in rates)
    assert max(abs(x) for x in rates) < 0.5 / 0.0174524


@pytest.mark.parametrize(
    ("angle", "ref", "expected"),
    [(3.1, -3.1, 3.1 - 2 * math.pi), (-3.1, 3.1, 2 * math.pi - 3.1), (0.5, 12.0, 0.5 + 4 * math.pi), (1.0, 1.2, 1.0)],
)
def test_wrap_near(angle, ref, expected):
    assert r.wrap_near(angle, ref) == pytest.approx(expected, abs=1e-12)
