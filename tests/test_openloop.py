"""Open-loop inputs: each shape reaches the JSBSim surface as specified, the other axes stay closed-loop,
the pilot fights a signal added on top of its own command, and the Dutch roll flown after a rudder doublet
matches the linearised lateral model of the same aircraft (JSBSim's FGLinearization)."""

from __future__ import annotations

import math
from pathlib import Path

import jsbsim
import numpy as np
import pytest
import scipy.signal
from flight_helpers import phase_mask, write

from washbench.flight.checks import measure
from washbench.flight.fdm import make_fdm
from washbench.flight.fly import FlightResult, fly
from washbench.flight.manoeuvre import load_manoeuvre, pilot_profile_path
from washbench.flight.profile import load_profile
from washbench.io.paths import MANOEUVRES_DIR

RATE = 120  # Hz: every window edge below is a whole number of steps
SHAPES_FLIGHT = """\
    name: input_shapes
    aircraft: c172p
    start:
      air: {altitude_ft: 4000, airspeed_kts: 95, heading_deg: 90}
    phases:
      - name: settle
        hold: {wings_level: true, altitude_ft: 4000, airspeed_kts: 95}
        until: {duration_s: 3}
      - name: step
        hold: {wings_level: true, airspeed_kts: 95}
        inputs:
          elevator: {shape: step, amplitude_deg: -1, start_s: 0.5, free: true}
        until: {duration_s: 2}
      - name: pulse
        hold: {wings_level: true, altitude_ft: 4000}
        inputs:
          throttle: {shape: pulse, amplitude_norm: -0.2, start_s: 0.25, duration_s: 1, free: true}
        until: {duration_s: 2}
      - name: doublet
        hold: {wings_level: true, altitude_ft: 4000, airspeed_kts: 95}
        inputs:
          rudder: {shape: doublet, amplitude_deg: 2, start_s: 0.5, duration_s: 2, free: true}
        until: {duration_s: 3}
      - name: level again
        hold: {wings_level: true, altitude_ft: 4000, airspeed_kts: 95}
        until: {duration_s: 4}
      - name: multistep
        hold: {altitude_ft: 4000, airspeed_kts: 95}
        inputs:
          aileron: {shape: "3211", amplitude_deg: 3, start_s: 0.3, duration_s: 2.1, free: true}
        until: {duration_s: 3}
      - name: sine
        hold: {altitude_ft: 4000, airspeed_kts: 95}
        inputs:
          aileron: {shape: sine, amplitude_deg: 2, period_s: 1.5, free: true}
        until: {duration_s: 3}
      - name: log chirp
        hold: {wings_level: true, altitude_ft: 4000, airspeed_kts: 95}
        inputs:
          rudder: {shape: chirp, amplitude_deg: 1.5, duration_s: 4, start_hz: 0.2, end_hz: 2, sweep: logarithmic,
                   free: true}
        until: {duration_s: 4}
      - name: linear chirp
        hold: {wings_level: true, airspeed_kts: 95}
        inputs:
          elevator: {shape: chirp, amplitude_norm: 0.03, duration_s: 3, start_hz: 0.5, end_hz: 1.5, free: true}
          properties:
            - {property: fcs/yaw-trim-cmd-norm, shape: sine, amplitude: 0.05, period_s: 1}
        until: {duration_s: 3}
      - name: level before the step
        hold: {wings_level: true, altitude_ft: 4000, airspeed_kts: 95}
        until: {duration_s: 5}
      - name: added step
        hold: {wings_level: true, altitude_ft: 4000, airspeed_kts: 95}
        inputs:
          elevator: {shape: step, amplitude_norm: 0.05}
        until: {duration_s: 15}
      - name: level
        hold: {wings_level: true, altitude_ft: 4000, airspeed_kts: 95}
        until: {duration_s: 3}
"""
PROBES = (
    "fcs/elevator-pos-deg",
    "fcs/left-aileron-pos-deg",
    "fcs/rudder-pos-deg",
    "fcs/throttle-pos-norm",
    "fcs/yaw-trim-cmd-norm",
)


@pytest.fixture(scope="module")
def shapes(tmp_path_factory: pytest.TempPathFactory) -> FlightResult:
    path = write(tmp_path_factory.mktemp("shapes"), "input_shapes.yaml", SHAPES_FLIGHT)
    result = fly(load_manoeuvre(path), probes=PROBES)
    assert result.status == "ok", result.reason
    return result


def _window(n: np.ndarray, start_s: float, duration_s: float) -> np.ndarray:
    """Samples n (steps since the phase start) inside [start, start + duration), counted in whole steps."""
    a = round(start_s * RATE)
    return (n >= a) & (n < a + round(duration_s * RATE))


def _phase_steps(result: FlightResult, name: str) -> tuple[int, int]:
    """First sample of the phase and the first of the next one (the end sample starts the next phase)."""
    t0, t1 = next((a, b) for n, a, b in result.phases if n == name)
    return round(t0 * RATE), round(t1 * RATE)


def _response(result: FlightResult, name: str, probe: str) -> tuple[np.ndarray, np.ndarray]:
    """(steps since the phase start, probe value minus its value before the phase) over the phase."""
    k0, k1 = _phase_steps(result, name)
    x = result.probes[probe]
    return np.arange(k1 - k0), x[k0:k1] - x[k0 - 1]


def expected(name: str, n: np.ndarray) -> np.ndarray:
    """The shapes from their definitions (flight-test conventions; chirps from scipy.signal.chirp)."""
    tau = n / RATE
    if name == "step":
        return -1.0 * (n >= 60)
    if name == "pulse":
        return -0.2 * _window(n, 0.25, 1.0)
    if name == "doublet":
        return 2.0 * (_window(n, 0.5, 1.0).astype(float) - _window(n, 1.5, 1.0))
    if name == "multistep":  # 3-2-1-1 of 0.3 s units from 0.3 s: + + + - - + -
        u = 0.3
        return 3.0 * (
            _window(n, u, 3 * u) * 1.0 - _window(n, 4 * u, 2 * u) + _window(n, 6 * u, u) - _window(n, 7 * u, u)
        )
    if name == "sine":
        return 2.0 * np.sin(2 * np.pi * tau / 1.5)
    if name == "log chirp":
        return 1.5 * scipy.signal.chirp(tau, 0.2, 4.0, 2.0, method="logarithmic", phi=-90) * _window(n, 0, 4)
    raise KeyError(name)


@pytest.mark.parametrize(
    ("phase", "probe"),
    [
        ("step", "fcs/elevator-pos-deg"),
        ("pulse", "fcs/throttle-pos-norm"),
        ("doublet", "fcs/rudder-pos-deg"),
        ("multistep", "fcs/left-aileron-pos-deg"),
        ("sine", "fcs/left-aileron-pos-deg"),
        ("log chirp", "fcs/rudder-pos-deg"),
    ],
)
def test_each_shape_reaches_the_surface_as_specified(shapes: FlightResult, phase: str, probe: str) -> None:
    """The JSBSim surface (read back after each step) moves by the specified signal, in degrees of surface."""
    n, moved = _response(shapes, phase, probe)
    want = expected(phase, n)
    assert np.max(np.abs(want)) > 0.1
    # the profile's travel is the model's to 4 decimals: 2e-3 deg of 23 deg full travel
    np.testing.assert_allclose(moved, want, atol=2e-3)


def test_a_linear_chirp_in_norm_and_a_property_input(shapes: FlightResult) -> None:
    """Normalised amplitude: the elevator moves by 0.03 of its travel on the side it deflects to (zero-centred
    scale, 23 deg down, 28 deg up); a property input writes the property itself."""
    k0, k1 = _phase_steps(shapes, "linear chirp")
    n = np.arange(k1 - k0)
    s = 0.03 * scipy.signal.chirp(n / RATE, 0.5, 3.0, 1.5, method="linear", phi=-90)
    trim = 0.0  # pitch trim plus the command at the phase start, from the surface before the phase
    before = shapes.probes["fcs/elevator-pos-deg"][k0 - 1]
    trim = before / 22.9957 if before >= 0 else before / 27.9947
    u = trim + s
    want = np.where(u >= 0, u * 22.9957, u * 27.9947)
    np.testing.assert_allclose(shapes.probes["fcs/elevator-pos-deg"][k0:k1], want, atol=2e-3)
    yaw_trim = shapes.probes["fcs/yaw-trim-cmd-norm"][k0:k1]
    np.testing.assert_allclose(yaw_trim, 0.05 * np.sin(2 * np.pi * n / RATE), atol=1e-12)
    # after the phase the property keeps the last value written
    assert shapes.probes["fcs/yaw-trim-cmd-norm"][k1 + 10] == pytest.approx(yaw_trim[-1], abs=1e-12)


def test_the_other_axes_stay_closed_loop(shapes: FlightResult) -> None:
    """While the ailerons fly the 3211 open-loop, the elevator holds the altitude and the rudder the sideslip:
    the pilot's commands move, the state they hold does not."""
    c = shapes.columns
    sel = phase_mask(shapes, "multistep")
    assert np.ptp(c["phi_deg"][sel]) > 5.0  # the open-loop ailerons did roll the aircraft
    assert np.ptp(c["rudder"][sel]) > 0.02 and np.ptp(c["elevator"][sel]) > 0.002
    assert np.max(np.abs(c["beta_deg"][sel])) < 2.0
    assert np.max(np.abs(c["altitude_ft"][sel] - 4000.0)) < 10.0
    # the freed aileron is recorded as sent: constant between the 3211's steps (no pilot in it)
    k0, _ = _phase_steps(shapes, "multistep")
    a = c["aileron"][k0 + 1 : k0 + 36]
    assert np.ptp(a) == 0.0


def test_a_signal_added_to_a_closed_loop_axis_is_fought_by_the_pilot(shapes: FlightResult) -> None:
    """A 0.05 elevator step on top of the altitude hold: the surface first jumps by 0.05 of its travel, then the
    pilot takes it back out (its own command moves by -0.05) and the altitude returns."""
    k0, k1 = _phase_steps(shapes, "added step")
    pos = shapes.probes["fcs/elevator-pos-deg"]
    jump = pos[k0] - pos[k0 - 1]
    assert jump == pytest.approx(0.05 * (22.9957 if pos[k0] > 0 else 27.9947), abs=0.02)  # the pilot, in one step
    assert abs(pos[k1 - 1] - pos[k0 - 1]) < 0.25 * abs(jump)
    q = shapes.columns["omega_y_degps"][k0:k1]
    assert np.min(q) < -0.5  # it did push the nose down (+elevator: nose down) before the pilot caught it
    assert np.max(np.abs(shapes.columns["altitude_ft"][k0:k1] - 4000.0)) < 3.0


def test_a_freed_axis_comes_back_to_the_pilot_without_a_jump(shapes: FlightResult) -> None:
    """Bumpless: the pilot's first command after an open-loop phase moves no more than its surface rate limit."""
    profile = load_profile(pilot_profile_path("c172p"))
    limit = profile.gains.surface_rate_per_s / RATE + 1e-12
    for phase, column in (("sine", "aileron"), ("log chirp", "rudder"), ("pulse", "throttle")):
        _, k1 = _phase_steps(shapes, phase)
        step = abs(shapes.columns[column][k1] - shapes.columns[column][k1 - 1])
        assert step <= (limit if column != "throttle" else profile.gains.path.throttle_rate_per_s / RATE + 1e-12)


# --- the Dutch roll against the linearised lateral model ------------------------------------------------------


def lateral_dutch_roll(path: Path) -> tuple[float, float]:
    """(period s, damping ratio) of the Dutch roll of JSBSim's linearisation at the manoeuvre's start.

    FGLinearization differentiates the full model numerically about the start state (trimmed, or the flying
    start); the lateral-directional block (beta, phi, p, r) holds the Dutch roll as its complex pair.
    """
    m = load_manoeuvre(path)
    fdm, _ = make_fdm(m, load_profile(pilot_profile_path(m.aircraft)))
    lin = jsbsim.FGLinearization(fdm)
    names = list(lin.x_names)
    idx = [names.index(n) for n in ("Beta", "Phi", "P", "R")]
    a = np.array(lin.system_matrix)[np.ix_(idx, idx)]
    (pair,) = [e for e in np.linalg.eigvals(a) if e.imag > 0]
    return 2 * math.pi / pair.imag, -pair.real / abs(pair)


def test_dutch_roll_from_the_flight_matches_the_linearised_lateral_model() -> None:
    """c172p rudder doublet with ailerons and rudder fixed: the free yaw-rate oscillation's period within 3 % and
    its damping ratio within 0.02 of the linear model's (measured 2.73 s / 0.177 against 2.74 s / 0.187: the flight
    is nonlinear and the elevator loop stays closed, so they are not equal). The Columbia's linearisation takes
    minutes of CPU; tools/linear_modes.py gives it (2.57 s / 0.121; its bundled doublet flies 2.57 s / 0.115)."""
    path = MANOEUVRES_DIR / "c172" / "rudder_doublet.yaml"
    m = load_manoeuvre(path)
    result = fly(m)
    assert result.status == "ok", result.reason
    period, zeta = lateral_dutch_roll(path)
    measured = {}
    for stat in ("oscillation_period", "damping_ratio"):
        check = next(c for c in m.checks if c.stat == stat)
        measured[stat] = measure(check, result.columns, result.phases, result.events, result.dt_s)
    assert measured["oscillation_period"] == pytest.approx(period, rel=0.03)
    assert measured["damping_ratio"] == pytest.approx(zeta, abs=0.02)
    # and the bundled checks bracket the linear model's values
    lin = {"oscillation_period": period, "damping_ratio": zeta}
    for check in m.checks:
        if check.stat in lin:
            assert check.min is not None and check.max is not None
            assert check.min < lin[check.stat] < check.max
