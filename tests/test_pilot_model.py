"""The pilot model's parts without JSBSim: the discrete model against its continuous transfer functions, the
per-sample vestibular models against the project's, the forcing functions, the loop algebra and Nyquist's criterion
against closed-loop poles, the crossover against a closed form, identification against a simulated loop, and the
published parameters' closed loop (docs/pilot-model.md)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import signal

from washbench.perception.vestibular import MODELS, CanalParams, canal_model, otolith_model
from washbench.pilot import frequency as fq
from washbench.pilot.adapt import LoopSetting, canal_response, predict
from washbench.pilot.forcing import Multisine, base_frequency, crest_factor, lowest_crest_phases, shaped_amplitudes
from washbench.pilot.identify import decompose, identify, window_spectrum
from washbench.pilot.model import PilotContext
from washbench.pilot.multimodal import MultimodalPilot
from washbench.pilot.params import PUBLISHED_PITCH, MultimodalParams
from washbench.pilot.response import Constant, Measured
from washbench.pilot.senses import AxisPerception

DT = 0.01
QUIET = MultimodalParams(visual_gain=2.5, lead_s=0.2, vestibular_gain=0.3, visual_noise_rad2s=0.0,
                         vestibular_noise_rad2ps=0.0)  # fmt: skip


def _steady_response(model: MultimodalPilot, x: np.ndarray, channel: str) -> np.ndarray:
    y = np.empty(len(x))
    for i, v in enumerate(x):
        y[i] = model.step(v, 0.0, 0.0) if channel == "visual" else model.step(0.0, v, 0.0)
    return y


@pytest.mark.parametrize("k", [7, 26, 223])  # 0.54, 2.0, 17.1 rad/s in a window of 8192 samples
@pytest.mark.parametrize(("channel", "lag_s"), [("visual", 0.0), ("visual", 0.5), ("vestibular", 0.0)])
def test_discrete_channels_follow_their_continuous_transfer_functions(k: int, channel: str, lag_s: float) -> None:
    """A sine through each channel, in steady state, against H_nms H_v (resp. -H_nms H_m) with the realised delay
    (the visual channel also with a lag T_I). A first-order hold of a sampled sine attenuates it by
    sinc^2(w dt / 2) ~ 1 - (w dt)^2 / 12: that is the whole tolerance on the magnitude (0.25 % at 17 rad/s); the
    phase agrees to 0.01 deg."""
    n = 8192
    w = 2.0 * math.pi * k / (n * DT)
    p = QUIET.model_copy(update={"lag_s": lag_s})
    model = MultimodalPilot(p, PilotContext(dt_s=DT, axis="roll", steps=2 * n, seed=0, motion_lag_samples=1))
    x = np.sin(w * np.arange(2 * n) * DT)
    y = _steady_response(model, x, channel)
    h = np.fft.rfft(y[n:])[k] / np.fft.rfft(x[n:])[k]
    wv = np.array([w])
    if channel == "visual":
        ref = fq.nms_frf(wv, p) * fq.visual_frf(wv, p, 0.22)
    else:  # the vestibular line is shortened by the perceived motion's lag (one sample)
        ref = -fq.nms_frf(wv, p) * fq.vestibular_frf(wv, p, 0.19 - DT)
    foh = (math.sin(w * DT / 2) / (w * DT / 2)) ** 2
    assert abs(abs(h) / abs(ref[0]) - foh) < 2e-4 * max(1.0, w)
    assert abs(math.degrees(np.angle(h / ref[0]))) < 0.01


def test_delays_are_whole_samples_and_the_remnant_is_seeded() -> None:
    """An impulse on the displayed error moves the control first 22 samples later (tau_v = 0.22 s at 100 Hz); the
    perception noises are the seed's: the same seed the same bits, their variance V / dt."""
    ctx = PilotContext(dt_s=DT, axis="roll", steps=100, seed=0)
    m = MultimodalPilot(QUIET, ctx)
    out = [m.step(1.0 if i == 0 else 0.0, 0.0, 0.0) for i in range(40)]
    assert np.all(np.array(out[:22]) == 0.0) and out[22] != 0.0
    noisy = MultimodalParams()
    a = MultimodalPilot(noisy, PilotContext(dt_s=DT, axis="roll", steps=200_000, seed=7))
    b = MultimodalPilot(noisy, PilotContext(dt_s=DT, axis="roll", steps=200_000, seed=7))
    assert a.visual_noise == b.visual_noise and a.rate_noise == b.rate_noise
    assert np.var(a.rate_noise) == pytest.approx(noisy.vestibular_noise_rad2ps / DT, rel=0.01)
    assert np.var(a.visual_noise) == pytest.approx(noisy.visual_noise_rad2s / DT, rel=0.01)


@pytest.mark.parametrize("axis", ["roll", "pitch"])
@pytest.mark.parametrize("model", ["young-meiry", "telban-cardullo"])
def test_per_sample_vestibular_models_are_the_projects(axis: str, model: str) -> None:
    """The canals and otoliths stepped one sample at a time give the bits of the project's whole-trace models."""
    rng = np.random.default_rng(3)
    n = 3000
    w = np.cumsum(rng.standard_normal(n)) * 1e-3
    f = -9.80665 + np.cumsum(rng.standard_normal(n)) * 1e-3 if axis == "pitch" else np.cumsum(rng.standard_normal(n))
    vp = MODELS[model]
    senses = AxisPerception(axis, DT, vp)
    got = np.array([senses.step(float(a), float(b)) for a, b in zip(w, f, strict=True)])
    assert np.array_equal(got[:, 0], canal_model(vp.canals, DT).apply(w))
    assert np.array_equal(got[:, 1], otolith_model(vp.otolith, DT).apply(f))


def test_multisine_sits_on_whole_bins_at_its_rms() -> None:
    """Each sine falls on one bin of the window's DFT (no leakage); the RMS is the one asked; the phases chosen
    give a lower crest factor than the median random set, and the same seed the same phases."""
    window = 81.92
    mult = np.array([5, 11, 23, 37, 51, 71, 101, 137, 171, 226])
    w = mult * base_frequency(window)
    a = shaped_amplitudes(w, math.radians(1.0), 0.1, 0.8)
    ph = lowest_crest_phases(w, a, window, seed=4)
    f = Multisine(mult, a, ph, window)
    x = f.at(np.arange(8192) * DT)
    spec = np.abs(np.fft.rfft(x))
    others = np.delete(spec, mult)
    assert others.max() < 1e-9 * spec[mult].max()
    assert math.sqrt(np.mean(x * x)) == pytest.approx(math.radians(1.0), rel=1e-9)
    assert np.array_equal(ph, lowest_crest_phases(w, a, window, seed=4))
    rng = np.random.default_rng(1)
    t = np.arange(2048) * (window / 2048)
    random_cf = [crest_factor(np.sin(np.outer(t, w) + rng.uniform(0, 2 * math.pi, 10)) @ a) for _ in range(50)]
    assert crest_factor(f.at(t)) < np.median(random_cf)


def _pade_poly(tau: float, order: int = 6) -> tuple[np.ndarray, np.ndarray]:
    """exp(-tau s) as its [order/order] Pade approximant: c_k = (2n-k)! n! / ((2n)! k! (n-k)!), numerator with
    (-tau s)^k, denominator with (tau s)^k (descending powers of s)."""
    n = order
    c = [math.factorial(2 * n - k) * math.factorial(n) / (math.factorial(2 * n) * math.factorial(k)
                                                         * math.factorial(n - k)) for k in range(n + 1)]  # fmt: skip
    num = np.array([c[k] * (-tau) ** k for k in range(n, -1, -1)])
    den = np.array([c[k] * tau**k for k in range(n, -1, -1)])
    return num, den


def _closed_loop_stable(p: MultimodalParams, plant: tuple[list, list], canal: tuple[np.ndarray, np.ndarray],
                        motion_gain: float) -> bool:  # fmt: skip
    """Independent check: the closed loop's poles with the delays as 6th-order Pade approximants (polynomials)."""
    gn, gd = np.asarray(plant[0], float), np.asarray(plant[1], float)
    wn = p.nms_frequency_radps
    nms = (np.array([wn * wn]), np.array([1.0, 2 * p.nms_damping * wn, wn * wn]))
    dv, dm = _pade_poly(p.visual_delay_s), _pade_poly(p.vestibular_delay_s)
    # A = K_v (T_L s + 1) Dv NMS; B = K_m Dm NMS Hscc s * motion_gain; 1 + (A + B) G = 0
    an = np.polymul(np.polymul([p.visual_gain * p.lead_s, p.visual_gain], dv[0]), nms[0])
    ad = np.polymul(dv[1], nms[1])
    bn = np.polymul(np.polymul(np.polymul([p.vestibular_gain * motion_gain], dm[0]), nms[0]),
                    np.polymul(canal[0], [1.0, 0.0]))  # fmt: skip
    bd = np.polymul(np.polymul(dm[1], nms[1]), canal[1])
    num = np.polyadd(np.polymul(an, bd), np.polymul(bn, ad))  # (A + B) numerator over ad bd
    den = np.polymul(ad, bd)
    char = np.polyadd(np.polymul(den, gd), np.polymul(num, gn))
    return bool(np.all(np.roots(char).real < 0))


ROLL_PLANT = ([1.0], [0.111, 1.0, 0.0])  # the c172p's roll, a unit gain and 0.111 s roll mode (delay left out)


@pytest.mark.parametrize("gain", [1.0, 2.0, 3.5, 5.5, 9.0])  # the boundaries: 4.25 (K_m 0), 2.75 (0.5)
@pytest.mark.parametrize("vestibular", [0.0, 0.5])
def test_nyquist_criterion_agrees_with_the_closed_loop_poles(gain: float, vestibular: float) -> None:
    """frequency.stable on the frequency response against the roots of the characteristic polynomial (delays as
    Pade approximants), across the stability boundary."""
    from washbench.perception.vestibular import canal_tf

    vp = MODELS["telban-cardullo"].canals
    p = QUIET.model_copy(update={"visual_gain": gain, "vestibular_gain": vestibular})
    w = fq.stability_grid()
    s = 1j * w
    g = np.polyval(ROLL_PLANT[0], s) / np.polyval(ROLL_PLANT[1], s)
    path = canal_response(vp)(w) * s
    got = fq.stable(w, fq.loop(w, p, g, path).disturbance_open_loop)
    assert got == _closed_loop_stable(p, ROLL_PLANT, canal_tf(vp), 1.0)


def test_crossover_interpolates_a_closed_form() -> None:
    """L = w_c exp(-j w tau) / (j w): crossover w_c, phase margin 90 - w_c tau (deg), exactly; from 20 points."""
    wc, tau = 2.7, 0.25
    w = np.geomspace(0.3, 20.0, 20)
    c = fq.crossover(w, wc * np.exp(-1j * w * tau) / (1j * w))
    assert c.frequency_radps == pytest.approx(wc, rel=1e-12)
    # the phase is linear in w, interpolated linearly in log w between the two neighbours: within 1 deg here
    assert c.phase_margin_deg == pytest.approx(90.0 - math.degrees(wc * tau), abs=1.0)


def test_published_pitch_parameters_close_a_stable_loop() -> None:
    """Pool et al. (2016)'s trained pilots with motion on the Cessna Citation's pitch dynamics (their visual
    double lead and lag, their vestibular s^2 H_scc K_m with Hosman's H_scc = (0.11 s + 1)/(5.9 s + 1)): a stable
    closed loop, by the poles (Pade) and by Nyquist's criterion, with a positive phase margin."""
    pp = PUBLISHED_PITCH
    ks = pp["stick_gain"]
    plant = ([ks * 10.62, ks * 10.62 * 0.99], [1.0, 2.58, 7.61, 0.0])
    w = fq.stability_grid()
    s = 1j * w
    g = np.polyval(plant[0], s) / np.polyval(plant[1], s)
    nms = pp["nms_frequency_radps"] ** 2 / (s * s + 2 * pp["nms_damping"] * pp["nms_frequency_radps"] * s
                                            + pp["nms_frequency_radps"] ** 2)  # fmt: skip
    hv = pp["visual_gain"] * (pp["lead_s"] * s + 1) ** 2 / (pp["lag_s"] * s + 1) * np.exp(-s * pp["visual_delay_s"])
    hscc = (0.11 * s + 1) / (5.9 * s + 1)
    hm = s * s * hscc * pp["vestibular_gain"] * np.exp(-s * pp["vestibular_delay_s"])
    open_loop = (hv + hm) * nms * g
    assert fq.stable(w, open_loop)
    c = fq.crossover(w, open_loop)
    assert 1.0 < c.frequency_radps < 8.0 and c.phase_margin_deg > 10.0
    # the same loop by its poles: double lead / lag and s^2 Hscc as polynomials, delays as Pade approximants
    dv, dm = _pade_poly(pp["visual_delay_s"]), _pade_poly(pp["vestibular_delay_s"])
    wn2 = pp["nms_frequency_radps"] ** 2
    nd = [1.0, 2 * pp["nms_damping"] * pp["nms_frequency_radps"], wn2]
    an = np.polymul(np.polymul(np.polymul([pp["lead_s"], 1.0], [pp["lead_s"], 1.0]), dv[0]), [pp["visual_gain"] * wn2])
    ad = np.polymul(np.polymul([pp["lag_s"], 1.0], dv[1]), nd)
    bn = np.polymul(np.polymul([pp["vestibular_gain"] * wn2 * 0.11, pp["vestibular_gain"] * wn2, 0.0, 0.0], dm[0]), [1])
    bd = np.polymul(np.polymul([5.9, 1.0], dm[1]), nd)
    num = np.polyadd(np.polymul(an, bd), np.polymul(bn, ad))
    char = np.polyadd(np.polymul(np.polymul(ad, bd), plant[1]), np.polymul(num, plant[0]))
    assert np.all(np.roots(char).real < 0)


def _simulate_loop(p: MultimodalParams, target: Multisine, disturbance: Multisine, runs: int, n_in: int) -> list:
    """The discrete pilot in closed loop with the roll plant of ROLL_PLANT (zero-order hold, scipy), the aircraft's
    own motion felt through the canals (telban-cardullo): the signals :func:`identify` takes."""
    plant = signal.cont2discrete(signal.tf2ss(*ROLL_PLANT), DT, method="zoh")
    a, b, c, _ = (np.asarray(m) for m in plant[:4])
    n = n_in + 8192
    t = np.arange(n) * DT
    ft, fd = target.at(t), disturbance.at(t)
    vest = MODELS["telban-cardullo"]
    out = []
    for r in range(runs):
        pilot = MultimodalPilot(p, PilotContext(dt_s=DT, axis="roll", steps=n, seed=100 + r, motion_lag_samples=1))
        senses = AxisPerception("roll", DT, vest)
        x = np.zeros((a.shape[0], 1))
        sig = {k: np.zeros(n) for k in ("error", "control", "attitude", "disturbance", "aircraft_rate", "head_rate")}
        felt = 0.0
        for k in range(n):
            att = float((c @ x)[0, 0])
            e = ft[k] - att
            u = pilot.step(e, felt, 0.0)
            x = a @ x + b * (u + fd[k])
            rate = (float((c @ x)[0, 0]) - att) / DT  # the attitude's rate over the step: what the canals feel
            felt = senses.step(rate, 0.0)[0]
            sig["error"][k], sig["control"][k], sig["attitude"][k], sig["disturbance"][k] = e, u, att, fd[k]
            sig["aircraft_rate"][k] = sig["head_rate"][k] = rate
        out.append(sig)
    return out


def test_identification_and_prediction_of_a_simulated_loop() -> None:
    """The discrete pilot flies a linear roll plant (no JSBSim): the responses identified at the forcing
    frequencies and the variances measured agree with the frequency-domain prediction of the same loop, and the
    plant is recovered at every forcing frequency."""
    window = 81.92
    wb = base_frequency(window)
    kt = np.array([6, 13, 27, 41, 53, 73, 103, 139, 194, 229])
    kd = np.array([5, 11, 23, 37, 51, 71, 101, 137, 171, 226])
    at = shaped_amplitudes(kt * wb, math.radians(1.0), 0.1, 0.8)
    ad = shaped_amplitudes(kd * wb, math.radians(1.0), 0.1, 0.8) * (kd * wb)  # through the unit integrator
    target = Multisine(kt, at, lowest_crest_phases(kt * wb, at, window, 1), window)
    disturbance = Multisine(kd, ad, lowest_crest_phases(kd * wb, ad, window, 2), window)
    p = MultimodalParams(visual_gain=2.4, lead_s=0.15, vestibular_gain=0.24)
    quiet = p.model_copy(update={"visual_noise_rad2s": 0.0, "vestibular_noise_rad2ps": 0.0})
    runs = _simulate_loop(quiet, target, disturbance, runs=1, n_in=1500)
    found = identify(runs, 8192, wb, kt, kd)
    w, h = found.plant()
    # without remnant the plant is the discrete one (zero-order hold), at every forcing frequency, to 1e-3 (what
    # is left of the start's transient: the canals adapt with an 80 s time constant; measured 2e-4)
    sysd = signal.cont2discrete(signal.tf2ss(*ROLL_PLANT), DT, method="zoh")
    a, b, c = (np.asarray(m) for m in sysd[:3])
    z = np.exp(1j * w * DT)
    exact = np.array([(c @ np.linalg.solve(zi * np.eye(a.shape[0]) - a, b))[0, 0] for zi in z])
    assert np.max(np.abs(h / exact - 1.0)) < 1e-3
    setting = LoopSetting(target.frequencies_radps, target.amplitudes, disturbance.frequencies_radps,
                          disturbance.amplitudes, Measured(w, h), Constant(1.0),
                          canal_response(MODELS["telban-cardullo"].canals), DT)  # fmt: skip
    # the forcing functions' parts and the crossovers: within 2 % (the canals feel the attitude's difference over
    # a step, the prediction its derivative; measured 1.4 % at most)
    pred = predict(quiet, setting)
    err = decompose([window_spectrum(r["error"], 8192) for r in runs], 8192, kt, kd)
    ctl = decompose([window_spectrum(r["control"], 8192) for r in runs], 8192, kt, kd)
    for got, want in ((err.target, pred.error_target), (err.disturbance, pred.error_disturbance),
                      (ctl.target, pred.control_target), (ctl.disturbance, pred.control_disturbance)):  # fmt: skip
        assert got == pytest.approx(want, rel=0.02)
    assert err.remnant < 1e-6 * err.total  # nothing else without noise
    assert found.disturbance_crossover.frequency_radps == pytest.approx(pred.disturbance.frequency_radps, rel=0.02)
    assert found.target_crossover.frequency_radps == pytest.approx(pred.target.frequency_radps, rel=0.02)
    # with the perception noises, two runs: the remnant as predicted within 25 % (two runs of noise), the total
    # error variance within 5 %
    noisy = decompose([window_spectrum(r["error"], 8192) for r in _simulate_loop(p, target, disturbance, 2, 500)],
                      8192, kt, kd)  # fmt: skip
    pred = predict(p, setting)
    assert noisy.remnant == pytest.approx(pred.error_remnant, rel=0.25)
    assert noisy.total == pytest.approx(pred.error_variance, rel=0.05)


def test_measured_response_is_exact_at_its_points_and_extends_as_an_integrator() -> None:
    """Measured: the given values at the given frequencies; below the lowest, magnitude falling with 1/w and the
    phase reaching -90 deg a decade down; between points, log-magnitude linear in log frequency."""
    w = np.array([0.5, 1.0, 2.0, 4.0])
    h = 1.0 / (1j * w * (0.2j * w + 1.0))
    m = Measured(w, h)
    assert np.allclose(m(w), h, rtol=1e-12)
    low = m(np.array([0.05]))[0]
    assert abs(low) == pytest.approx(abs(h[0]) * 10.0, rel=1e-9)
    assert math.degrees(np.angle(low)) == pytest.approx(-90.0, abs=1e-9)
    mid = m(np.array([math.sqrt(2.0)]))[0]
    assert abs(mid) == pytest.approx(math.sqrt(abs(h[1]) * abs(h[2])), rel=1e-9)
    assert isinstance(CanalParams(), CanalParams)  # the canal parameters the tests build on exist unchanged
