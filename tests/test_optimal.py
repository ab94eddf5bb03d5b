"""The optimal washout: its LQ design against Riccati/Lyapunov identities, its per-step filter against the
transfer functions the design produced (scipy.signal), and its set points' signs against physics."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import linalg, signal
from scipy.spatial.transform import Rotation

from washbench.analysis.omct import fourier_coefficient
from washbench.cueing.algorithm import WashoutAlgorithm, WashoutContext
from washbench.cueing.optimal import OptimalParams, OptimalWashout, design
from washbench.platform.limits import load_platform_limits

G = 9.80665
DT = 1.0 / 120.0


@pytest.fixture(scope="module")
def context() -> WashoutContext:
    return WashoutContext(DT, G, load_platform_limits(), "steady", (0.0, 0.0, 0.0))


@pytest.fixture(scope="module")
def designs():
    return design(OptimalParams(), G)


def test_is_a_washout_algorithm(context):
    assert isinstance(OptimalWashout(None, context), WashoutAlgorithm)


@pytest.mark.parametrize("channel", ["pitch", "roll", "heave", "yaw"])
def test_riccati_solution_and_optimality(designs, channel):
    """P solves the CARE; the cost of the LQ gain (Lyapunov) equals x0' P x0 and any perturbed gain costs more."""
    d = designs[channel]
    A, B, Q = d.augmented()
    R = d.R
    K = np.hstack([d.K_x, d.K_r])
    S = d.S
    res = A.T @ d.P + d.P @ A - (d.P @ B + S) @ np.linalg.solve(R, B.T @ d.P + S.T) + Q
    assert np.max(np.abs(res)) < 1e-8 * max(1.0, np.max(np.abs(d.P)))

    def cost_matrix(gain):
        acl = A - B @ gain
        assert np.all(np.linalg.eigvals(acl).real < 0)
        return linalg.solve_continuous_lyapunov(acl.T, -(Q - S @ gain - gain.T @ S.T + gain.T @ R @ gain))

    p_opt = cost_matrix(K)
    np.testing.assert_allclose(p_opt, d.P, rtol=1e-6, atol=1e-9 * np.max(np.abs(d.P)))
    rng = np.random.default_rng(7)
    for _ in range(20):
        dk = 0.05 * rng.standard_normal(K.shape) * (np.abs(K) + 1e-3)
        try:
            p_pert = cost_matrix(K + dk)
        except AssertionError:
            continue  # an unstable perturbation costs infinitely much
        x0 = rng.standard_normal(A.shape[0])
        assert x0 @ p_pert @ x0 >= x0 @ d.P @ x0 * (1.0 - 1e-9)


def test_design_is_stable_and_rejects_a_free_state():
    with pytest.raises(ValueError, match="not stable"):
        # no weight on any platform state: the position integrator is left free, the design cannot be stable
        p = OptimalParams.model_validate(
            {"heave": {"force": 1.0, "position": 0.0, "velocity": 0.0, "position_integral": 0.0}}
        )
        design(p, G)


def _run(wash: OptimalWashout, f: np.ndarray, om: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    wash.start(f[0], om[0])
    pos = np.empty((len(f), 3))
    q = np.empty((len(f), 4))
    for k in range(len(f)):
        pos[k], q[k] = wash.step(f[k], om[k])
    return pos, q


def _euler(q: np.ndarray) -> np.ndarray:
    """(roll, pitch, yaw) rad from scalar-first body->inertial quaternions (scipy, independent of the package)."""
    return Rotation.from_quat(q[:, [1, 2, 3, 0]]).as_euler("ZYX")[:, ::-1]


def _designed_tf(designs, channel: str, inp: int, out: str):
    """The designed transfer function from input ``inp`` to output ``out``, its numerator without the leading
    coefficients that are zero by structure: as many as the Markov parameters D, C B, C A B, ... that vanish (the
    relative degree: D = 0 and, for a position, C B = 0). ss2tf leaves them as 0 and ~1e-16 (rounding of an exact 0),
    and TransferFunction warned of badly conditioned coefficients (scipy's BadCoefficients) and stripped them."""
    d = designs[channel]
    c, dmat, names = d.outputs()
    row = names.index(out)
    num, den = signal.ss2tf(d.A_w, d.B_w, c[row : row + 1], dmat[row : row + 1], input=inp)
    b, cr = d.B_w[:, inp], c[row]
    powers = [np.linalg.matrix_power(d.A_w, k) for k in range(len(b))]
    markov = [(dmat[row, inp], 1.0), *((cr @ a @ b, np.linalg.norm(cr) * np.linalg.norm(a) * np.linalg.norm(b))
                                       for a in powers)]  # fmt: skip
    lead = next(i for i, (m, size) in enumerate(markov) if abs(m) > 1e-9 * size)  # each against its own size
    assert np.all(np.abs(num[0][:lead]) <= 1e-12 * np.max(np.abs(num[0])))  # zero but for rounding, as they must be
    return signal.TransferFunction(num[0][lead:], den)


def test_step_response_matches_the_designed_transfer_functions(context, designs):
    """A surge step, a sway step and a yaw-rate step through step() against scipy.signal.lsim of the transfer
    functions the design produced (continuous, the input linear between samples as in lsim)."""
    n = int(20 / DT)
    t = np.arange(n) * DT
    f = np.tile([0.0, 0.0, -G], (n, 1))
    om = np.zeros((n, 3))
    f[120:, 0] += 2.0  # surge onset at 1 s
    f[240:, 1] -= 1.5
    om[360:, 2] = 0.2
    f[480:, 2] -= 3.0
    pos, q = _run(OptimalWashout(None, context), f, om)
    eul = _euler(q)
    checks = [
        ("pitch", 0, "position_m", f[:, 0], pos[:, 0]),
        ("pitch", 0, "angle_rad", f[:, 0], eul[:, 1]),
        ("roll", 0, "position_m", f[:, 1], pos[:, 1]),
        ("roll", 0, "angle_rad", f[:, 1], eul[:, 0]),
        ("heave", 0, "position_m", f[:, 2] + G, pos[:, 2]),
        ("yaw", 0, "angle_rad", om[:, 2], eul[:, 2]),
    ]
    for channel, inp, out, u, y in checks:
        _, y_ref, _ = signal.lsim(_designed_tf(designs, channel, inp, out), u, t)
        scale = np.max(np.abs(y_ref))
        assert scale > 1e-3, (channel, out)
        np.testing.assert_allclose(y, y_ref, atol=1e-6 * scale, err_msg=f"{channel} {out}")


@pytest.mark.parametrize("w_radps", [0.5, 2.0, 8.0])
def test_frequency_response_matches_the_designed_transfer_function(context, designs, w_radps):
    """OMCT-style: a sine of f_x through step(), gain and phase of the tilt angle and position (Fourier fit over
    whole periods after 10 time constants of the non-canal poles) against freqresp of the designed TF."""
    periods = 4
    n = int((60.0 + periods * 2 * np.pi / w_radps) / DT) + 1
    t = np.arange(n) * DT
    amp = 0.5
    f = np.tile([0.0, 0.0, -G], (n, 1))
    f[:, 0] = amp * np.sin(w_radps * t)
    pos, q = _run(OptimalWashout(None, context), f, np.zeros((n, 3)))
    eul = _euler(q)
    for out, y in (("angle_rad", eul[:, 1]), ("position_m", pos[:, 0])):
        fit = fourier_coefficient(y, DT, w_radps, periods)
        _, h = signal.freqresp(_designed_tf(designs, "pitch", 0, out), [w_radps])
        measured = fit.c / (-1j * amp)  # the input amp sin(w t) = Re(-j amp e^{j w t})
        # the slowest poles (1/30 s^-1, the canal adaptation, weakly coupled) leave a transient of a few 1e-4
        assert abs(measured - h[0]) < 2e-3 * abs(h[0]) + 1e-6, (out, measured, h[0])


def test_sustained_specific_force_ends_as_tilt_with_the_platform_centred(context):
    """A sustained surge (sway) force pitches the nose up (rolls left), and the platform returns to the centre."""
    n = int(60 / DT)
    f = np.tile([0.0, 0.0, -G], (n, 1))
    f[60:, 0] += 1.0
    f[60:, 1] += 1.0
    pos, q = _run(OptimalWashout(None, context), f, np.zeros((n, 3)))
    eul = _euler(q)
    assert eul[-1, 1] > 0.5 * np.arctan(1.0 / G)  # nose up
    assert eul[-1, 0] < -0.5 * np.arctan(1.0 / G)  # roll left
    assert np.all(np.abs(pos[-1]) < 5e-3)
    assert np.max(np.abs(pos[:, 0])) > 0.02  # it did move during the onset


def test_params_section_validates():
    p = OptimalParams.model_validate({"input_break_radps": 0.5, "pitch": {"force": 2.0, "position": 1.0}})
    assert p.pitch.force == 2.0 and p.roll.force == OptimalParams().roll.force
    # a partial channel section keeps the channel's other defaults (not the field defaults of the weight model)
    assert p.pitch.angle == OptimalParams().pitch.angle and p.pitch.direct_force == OptimalParams().pitch.direct_force
    design(OptimalParams.model_validate({"pitch": {"direct_force": 0.0}}), G)  # stable: the other weights kept
    with pytest.raises(Exception, match="bogus"):
        OptimalParams.model_validate({"pitch": {"bogus": 1.0}})


@pytest.mark.parametrize("axis, amp", [(0, 2.0), (1, 2.0), (2, -4.9)])
def test_translational_cue_starts_in_the_direction_of_the_force(context, axis, amp):
    """A surge, sway or heave (pull-up) onset moves the platform with the force first (north, east, up), never
    against it: the direct force-error weight keeps the LQ design from starting with a sharp opposite move (it did,
    by up to 6 mm north and 0.14 m down for a pull-up, without it)."""
    n = int(3.0 / DT)
    f = np.tile([0.0, 0.0, -G], (n, 1))
    f[12:, axis] += amp
    pos, _ = _run(OptimalWashout(None, context), f, np.zeros((n, 3)))
    p = pos[:, axis] * np.sign(amp)
    assert p.min() > -1e-4, p.min()
    assert p[int(1.0 / DT)] > 0.02
