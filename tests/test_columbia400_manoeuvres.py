"""The Columbia 400 manoeuvres, checked against physics the pilot and the checks do not use.

Every bundled manoeuvre (both aircraft) is flown with its checks in ``tests/test_flight.py``;
here the Columbia's flying start, the aerobatic sequence's rotations (measured again from the
recorded attitude with scipy's Rotation, not from the body rates the pilot and the checks
integrate), the body-rate modes in inverted flight, the monitor, the new statistic and the new
validation messages.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from flight_helpers import FT, normal_gravity, phase_mask, write
from scipy.spatial.transform import Rotation

from washbench.errors import WashbenchError
from washbench.flight.checks import measure
from washbench.flight.fly import FlightResult, fly
from washbench.flight.manoeuvre import load_manoeuvre
from washbench.flight.manoeuvre_schema import Check
from washbench.io.paths import MANOEUVRES_DIR

COLUMBIA = MANOEUVRES_DIR / "columbia400"


@pytest.fixture(scope="module")
def aerobatics() -> FlightResult:
    return fly(load_manoeuvre(COLUMBIA / "aerobatics.yaml"))


@pytest.fixture(scope="module")
def turn() -> FlightResult:
    return fly(load_manoeuvre(COLUMBIA / "coordinated_turn.yaml"))


def attitudes(result: FlightResult, sel: np.ndarray) -> Rotation:
    """Body -> NED rotations from the recorded Euler angles (3-2-1: yaw psi, pitch theta, roll phi)."""
    c = result.columns
    return Rotation.from_euler("ZYX", np.column_stack([c["psi_deg"][sel], c["theta_deg"][sel], c["phi_deg"][sel]]),
                               degrees=True)  # fmt: skip


def rotated(result: FlightResult, signal: str, phase: str) -> float:
    """The ``rotated`` statistic (deg) of a body-rate signal over one phase, as a check measures it."""
    check = Check(name=phase, signal=signal, stat="rotated", phases=[phase], min=0.0)
    return measure(check, result.columns, result.phases, result.events, result.dt_s)


def test_all_columbia_manoeuvres_are_there() -> None:
    assert {p.stem for p in COLUMBIA.glob("*.yaml")} == {
        "coordinated_turn",
        "crosswind_landing",
        "takeoff",
        "spiral_dive",
        "stall_recovery",
        "aerobatics",
        "elevator_doublet",
        "rudder_doublet",
        "aileron_3211",
        "steep_turn",
        "go_around",
        "roll_sequence",
    }
    for path in COLUMBIA.glob("*.yaml"):
        assert load_manoeuvre(path).aircraft == "columbia400"


def test_flying_start_begins_at_t0_in_steady_level_flight(turn: FlightResult) -> None:
    """do_trim(1) fails for this model; the flying start must hand over unaccelerated level flight.

    Straight, level and unaccelerated: f = (g sin(theta), 0, -g cos(theta)) in body axes, airspeed and
    altitude as asked, no rates, and the clock starts at zero.
    """
    c = turn.columns
    assert c["t_s"][0] == 0.0
    sel = turn.t_s <= 3.0
    assert c["vc_kts"][0] == pytest.approx(130.0, abs=0.5)
    assert c["altitude_ft"][0] == pytest.approx(8000.0, abs=0.01)
    assert c["psi_deg"][0] == pytest.approx(90.0, abs=0.01)
    assert np.max(np.abs(c["climb_fpm"][sel])) < 60.0
    assert np.max(np.abs(np.column_stack([c["omega_x_degps"], c["omega_y_degps"], c["omega_z_degps"]])[sel])) < 0.3
    assert c["rpm"][0] == pytest.approx(2600.0, abs=15.0)  # the governor at take-off rpm (profile lever 1.0)
    theta = np.radians(c["theta_deg"][sel])
    g = normal_gravity(45.3225, 8000 * FT)
    np.testing.assert_allclose(c["f_x_mps2"][sel], g * np.sin(theta), atol=0.05)
    np.testing.assert_allclose(c["f_y_mps2"][sel], 0.0, atol=0.05)
    np.testing.assert_allclose(c["f_z_mps2"][sel], -g * np.cos(theta), atol=0.05)


def test_steady_turn_load_factor(turn: FlightResult) -> None:
    """Level coordinated turn: n = 1 / cos(phi)."""
    c = turn.columns
    sel = phase_mask(turn, "turn") & (turn.t_s > 20.0)
    phi = np.radians(c["phi_deg"][sel])
    assert np.mean(c["nz"][sel]) == pytest.approx(np.mean(1.0 / np.cos(phi)), rel=0.01)


def test_loop_is_a_full_pitch_rotation_measured_from_the_attitude(aerobatics: FlightResult) -> None:
    """The loop's rotation, measured geometrically: the nose direction (body x axis in NED, from the
    recorded Euler angles) turns about the wing axis through the same angle the body-rate integral says,
    passing through the vertical and inverted; the wings stay level with the loop plane."""
    r = aerobatics
    sel = phase_mask(r, "loop")
    att = attitudes(r, sel)
    nose = att.apply([1.0, 0.0, 0.0])
    wing0 = att[0].apply([0.0, 1.0, 0.0])
    # the loop plane is normal to the initial wing axis: measure the nose angle in it
    fwd0 = nose[0] - wing0 * (nose[0] @ wing0)
    fwd0 /= np.linalg.norm(fwd0)
    up0 = Rotation.from_rotvec(wing0 * math.pi / 2).apply(fwd0)  # the nose after +90 deg of pitch (q > 0)
    angle = np.unwrap(np.arctan2(nose @ up0, nose @ fwd0))
    pitched_geometric = math.degrees(angle[-1] - angle[0])
    assert pitched_geometric >= 330.0
    assert pitched_geometric == pytest.approx(rotated(r, "omega_y_degps", "loop"), abs=5.0)
    # the wing axis hardly moves: a loop, not a barrel roll (within 10 deg)
    wings = att.apply([0.0, 1.0, 0.0])
    assert np.degrees(np.arccos(np.clip(wings @ wing0, -1, 1))).max() < 10.0
    # straight up and inverted on the way
    assert np.max(r.columns["theta_deg"][sel]) > 80.0
    assert np.max(np.abs(r.columns["phi_deg"][sel])) > 170.0


def test_roll_is_a_full_rotation_about_the_longitudinal_axis(aerobatics: FlightResult) -> None:
    """The aileron roll measured from the attitude: the relative rotation between successive samples,
    projected on the body x axis, summed (the roll about the longitudinal axis, from the recorded
    attitude, not from the recorded p), agrees with the body-rate integral and exceeds 360 deg."""
    r = aerobatics
    sel = phase_mask(r, "roll")
    att = attitudes(r, sel)
    steps = (att[:-1].inv() * att[1:]).as_rotvec()  # body-frame increments
    rolled_geometric = math.degrees(np.sum(steps[:, 0]))
    rolled = rotated(r, "omega_x_degps", "roll")
    assert rolled_geometric >= 355.0
    assert rolled_geometric == pytest.approx(rolled, abs=3.0)
    assert rolled >= 360.0


def test_recorded_body_rates_integrate_to_the_recorded_attitude_through_the_loop(aerobatics: FlightResult) -> None:
    """Attitude propagated from the body rates (Rotation exponential, midpoint rates) over the loop,
    where the Euler angles jump, ends within 1.5 deg of the recorded attitude."""
    r = aerobatics
    sel = phase_mask(r, "loop")
    att = attitudes(r, sel)
    c = r.columns
    w = np.radians(np.column_stack([c["omega_x_degps"], c["omega_y_degps"], c["omega_z_degps"]])[sel])
    q = att[0]
    for k in range(len(w) - 1):
        q = q * Rotation.from_rotvec(0.5 * (w[k] + w[k + 1]) * r.dt_s)
    assert np.degrees((q.inv() * att[-1]).magnitude()) < 1.5


INVERTED = """\
name: inverted
aircraft: columbia400
start:
  air: {altitude_ft: 6000, airspeed_kts: 170, heading_deg: 0}
phases:
  - name: pull up
    hold: {wings_level: true, pitch_deg: 15, throttle: 1}
    until: {pitch_above_deg: 12, timeout_s: 10}
  - name: half roll
    hold: {roll_rate_degps: 60, load_factor: 1.0, throttle: 1}
    until: {rolled_deg: 180, timeout_s: 10}
  - name: inverted
    hold: {roll_rate_degps: 0, load_factor: -1.0, throttle: 0.5}
    until: {duration_s: 5}
  - name: half roll back
    hold: {roll_rate_degps: 60, load_factor: 1.0, throttle: 1}
    until: {rolled_deg: 180, timeout_s: 10}
  - name: level
    hold: {wings_level: true, pitch_deg: 0, throttle: 1}
    until: {duration_s: 5}
"""

INVERTED_INTO_THE_GROUND = """\
name: inverted_low
aircraft: columbia400
start:
  air: {altitude_ft: 300, airspeed_kts: 150, heading_deg: 0}
phases:
  - name: half roll
    hold: {roll_rate_degps: 60, load_factor: 1.0, throttle: 1}
    until: {rolled_deg: 180, timeout_s: 10}
  - name: inverted
    hold: {roll_rate_degps: 0, load_factor: 1.0, throttle: 1}
    until: {duration_s: 30}
"""


def test_inverted_flight_does_not_trip_the_monitor(tmp_path: Path) -> None:
    """Sustained inverted flight at -1 g: nothing in the monitor or the pilot misfires."""
    result = fly(load_manoeuvre(write(tmp_path, "inverted.yaml", INVERTED)))
    assert result.status == "ok", result.reason
    c = result.columns
    sel = phase_mask(result, "inverted")
    # inverted throughout: stopping a 60 deg/s roll, the aileron feed-forward comes off at once, so the roll
    # overshoots less than 25 deg (about 0.4 s of the roll: the surface rate limit and the roll mode's lag)
    assert np.min(np.abs(c["phi_deg"][sel])) > 155.0
    assert abs(c["phi_deg"][sel][-1]) > 170.0
    assert np.mean(c["nz"][sel & (result.t_s > result.phases[2][1] + 1.5)]) == pytest.approx(-1.0, abs=0.1)
    assert abs(c["phi_deg"][-1]) < 5.0


def test_monitor_still_stops_an_inverted_flight_into_the_ground(tmp_path: Path) -> None:
    """Inverted at 1 g (pulling towards the ground) from 300 ft: the monitor must end it."""
    result = fly(load_manoeuvre(write(tmp_path, "low.yaml", INVERTED_INTO_THE_GROUND)))
    assert result.status == "failed"
    assert any(
        cause in result.reason
        for cause in ("the airframe touched the ground", "hard landing", "gear has collapsed", "load factor")
    ), result.reason
    assert result.t_s[-1] < 30.0


def test_rotated_statistic_closed_form() -> None:
    """Constant rates integrate exactly; two separate phases add; the unselected gap does not count."""
    dt = 0.01
    n = 1001
    t = np.arange(n) * dt
    omega = np.where(t <= 4.0 + 1e-9, 30.0, np.where(t >= 6.0 - 1e-9, -45.0, 0.0))  # constant over each phase
    columns = {"t_s": t, "omega_x_degps": omega}
    phases = [("a", 0.0, 2.0), ("b", 2.0, 4.0), ("gap", 4.0, 6.0), ("c", 6.0, 10.0)]

    def rotated(names: list[str]) -> float:
        check = Check(name="x", signal="omega_x_degps", stat="rotated", phases=names, min=0.0)
        return measure(check, columns, phases, {}, dt)

    assert rotated(["a"]) == pytest.approx(60.0, abs=1e-9)
    assert rotated(["a", "b"]) == pytest.approx(120.0, abs=1e-9)
    assert rotated(["c"]) == pytest.approx(180.0, abs=1e-9)  # magnitude of -180
    assert rotated(["a", "c"]) == pytest.approx(120.0, abs=1e-9)  # 60 - 180, the gap excluded


BASE = """\
name: bad
aircraft: columbia400
start:
  air: {altitude_ft: 6000, airspeed_kts: 150, heading_deg: 0}
phases:
  - name: one
    hold: HOLD
    until: UNTIL
checks:
  - {name: c, signal: SIGNAL, stat: STAT, max: 1}
"""


@pytest.mark.parametrize(
    ("hold", "until", "signal", "stat", "expected"),
    [
        (
            "{wings_level: true}",
            "{rolled_deg: 360}",
            "nz",
            "max",
            ":8: phases[0].until.rolled_deg: the phase can never end: no roll rate is held, so the aircraft "
            "does not keep rolling",
        ),
        (
            "{roll_rate_degps: 0, load_factor: 5}",
            "{duration_s: 3}",
            "nz",
            "max",
            ":7: phases[0].hold.load_factor: 5 g is outside columbia400's load-factor limits (-1.76..4.4 g)",
        ),
        (
            "{roll_rate_degps: 30}",
            "{rolled_deg: 90}",
            "phi_deg",
            "rotated",
            ":10: checks[0].stat: 'rotated' integrates a body rate: omega_x_degps, omega_y_degps, omega_z_degps",
        ),
        (
            "{pitch_deg: 5, load_factor: 2}",
            "{pitched_deg: 90}",
            "nz",
            "max",
            ":7: phases[0].hold.load_factor: contradicts 'pitch_deg' (one pitch target at a time)",
        ),
    ],
    ids=["rolled-without-roll-rate", "load-factor-beyond-limit", "rotated-on-an-angle", "two-pitch-targets"],
)
def test_new_keys_are_validated_with_one_line_errors(
    hold: str, until: str, signal: str, stat: str, expected: str, tmp_path: Path
) -> None:
    text = BASE.replace("HOLD", hold).replace("UNTIL", until).replace("SIGNAL", signal).replace("STAT", stat)
    path = write(tmp_path, "bad.yaml", text)
    with pytest.raises(WashbenchError) as info:
        load_manoeuvre(path)
    assert str(info.value) == f"{path}{expected}"


def test_flying_start_and_aerobatics_are_bit_for_bit_repeatable(aerobatics: FlightResult) -> None:
    again = fly(load_manoeuvre(COLUMBIA / "aerobatics.yaml"))
    assert again.columns.keys() == aerobatics.columns.keys()
    for name, column in aerobatics.columns.items():
        assert again.columns[name].tobytes() == column.tobytes(), name
