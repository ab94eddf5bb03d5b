"""The Columbia-400-like model is the aircraft it claims to be, and the harness that measures it is right.

Every test flies real JSBSim. Published figures and tolerances are stated next to each assertion; the
sources are listed in aircraft/columbia400/README.md. The same harness (washbench.flight.airdata) is checked
against JSBSim's c172p and the Cessna 172P's published figures, independently of the new model.
"""

from __future__ import annotations

import math

import jsbsim
import pytest

from washbench.errors import WashbenchError
from washbench.flight import airdata
from washbench.io.paths import AIRCRAFT_DIR

C400 = "columbia400"
MAX_WEIGHT = airdata.Loading(gross_weight_lbs=3600.0, payload_pointmass=3)  # baggage point mass
MID_CRUISE = airdata.Loading(gross_weight_lbs=3420.0, payload_pointmass=1)  # front passenger point mass
C172_MAX = airdata.Loading(gross_weight_lbs=2400.0, payload_pointmass=3)  # c172p right passenger

PILOT_INPUTS = (
    "fcs/aileron-cmd-norm",
    "fcs/elevator-cmd-norm",
    "fcs/rudder-cmd-norm",
    "fcs/throttle-cmd-norm[0]",
    "fcs/mixture-cmd-norm[0]",
    "fcs/advance-cmd-norm[0]",
    "fcs/flap-cmd-norm",
    "fcs/left-brake-cmd-norm",
    "fcs/right-brake-cmd-norm",
    "fcs/steer-cmd-norm",
    "fcs/pitch-trim-cmd-norm",
    "accelerations/a-pilot-x-ft_sec2",
    "propulsion/engine[0]/engine-rpm",
)


def test_model_loads_with_pilot_inputs_structure_points_and_weights() -> None:
    fdm = airdata.make_fdm(C400)
    fdm.run_ic()
    pm = fdm.get_property_manager()
    missing = [name for name in PILOT_INPUTS if not pm.hasNode(name)]
    assert missing == []
    assert fdm["inertia/empty-weight-lbs"] == pytest.approx(2500.0)
    assert fdm["inertia/weight-lbs"] == pytest.approx(3600.0)  # default loading is maximum take-off
    # three gear units, then four airframe structure points a crash monitor can watch
    structure = [i for i in range(3, 7) if pm.hasNode(f"contact/unit[{i}]/WOW")]
    assert structure == [3, 4, 5, 6]
    # the eyepoint (a-pilot's reference) is the left-seat pilot's head: above and ahead of the CG
    assert fdm["metrics/eyepoint-x-in"] == pytest.approx(108.0)
    assert fdm["metrics/eyepoint-y-in"] < 0.0
    assert fdm["metrics/eyepoint-z-in"] > fdm["inertia/cg-z-in"] + 20.0


def test_unknown_aircraft_is_one_clear_error() -> None:
    with pytest.raises(WashbenchError, match=r"unknown aircraft .no_such_plane.: no no_such_plane/no_such_plane\.xml"):
        airdata.make_fdm("no_such_plane")


def test_limits_file_parses_and_matches_public_data() -> None:
    limits = airdata.load_limits(AIRCRAFT_DIR / C400 / "limits.yaml")
    assert (limits.vne_kias, limits.vno_kias, limits.va_kias) == (230, 181, 158)
    assert (limits.vs0_kias, limits.vx_kias, limits.vy_kias) == (59, 82, 110)
    assert (limits.n_max, limits.n_min) == (4.4, -1.76)
    # FAR 23.473: limit descent velocity 4.4 (W/S)^0.25 ft/s
    assert limits.max_sink_fps == pytest.approx(4.4 * (3600 / 141.2) ** 0.25, abs=0.05)


def test_starts_on_the_runway_at_rest() -> None:
    fdm = airdata.ground_start(C400)
    for _ in range(1200):  # 10 s, engine idling, brakes on
        fdm.run()
    assert fdm["velocities/vg-fps"] < 0.05
    assert [fdm[f"gear/unit[{i}]/WOW"] for i in range(3)] == [1.0, 1.0, 1.0]
    assert [fdm[f"contact/unit[{i}]/WOW"] for i in range(3, 7)] == [0.0] * 4
    assert abs(fdm["attitude/theta-deg"]) < 2.0
    assert fdm["accelerations/Nz"] == pytest.approx(1.0, abs=0.01)
    assert fdm["propulsion/engine[0]/engine-rpm"] > 600.0  # running at idle


def test_stall_speeds_at_maximum_weight() -> None:
    # published 59 KIAS flaps 40 deg (manufacturer); clean ~69 KIAS (estimated). Tolerance +-5 %.
    clean = airdata.stall_speed(C400, loading=MAX_WEIGHT, start_kcas=90.0)
    landing = airdata.stall_speed(C400, loading=MAX_WEIGHT, start_kcas=80.0, flaps_norm=1.0)
    assert clean == pytest.approx(69.0, rel=0.05)
    assert landing == pytest.approx(59.0, rel=0.05)


def test_level_speed_at_25000_ft_full_power() -> None:
    # published about 235 KTAS at 25,000 ft; tolerance +-4 %. Mid-cruise weight 3,420 lb.
    ktas, _ = airdata.level_speed(C400, 25000.0, loading=MID_CRUISE, start_kcas=150.0, throttle=1.0)
    assert ktas == pytest.approx(235.0, rel=0.04)


def test_turbocharged_engine_keeps_rated_power_to_25000_ft_without_leaning() -> None:
    # 310 hp to 25,000 ft with the mixture lever full rich (fuel metered to deck pressure); +-5 %.
    for altitude_ft in (0.0, 12000.0, 25000.0):
        fdm, _ = airdata.flying_start(C400, altitude_ft, 150.0, throttle=1.0, advance_norm=1.0, settle_s=5.0)
        assert fdm["propulsion/engine[0]/power-hp"] == pytest.approx(310.0, rel=0.05), altitude_ft
        assert fdm["propulsion/engine[0]/engine-rpm"] == pytest.approx(2600.0, abs=15.0)


def test_climb_rate_at_vy_sea_level_maximum_weight() -> None:
    # manufacturer's published figure: about 1,400 ft/min at Vy 110 KIAS; tolerance +-10 %.
    assert airdata.climb_rate(C400, 110.0, loading=MAX_WEIGHT) == pytest.approx(1400.0, rel=0.10)


def test_roll_rate_full_aileron_is_that_of_a_light_single() -> None:
    # light singles at full aileron: 60-90 deg/s (at 130 KCAS here).
    assert 60.0 <= airdata.roll_rate(C400, 130.0, loading=MAX_WEIGHT) <= 90.0


def test_trims_level_at_typical_cruise() -> None:
    # 8,000 ft, 155 KCAS (about 175 KTAS, 65-70 % power), 2,500 rpm: a settled flying start must need
    # part throttle and little elevator.
    trim = airdata.level_trim(C400, 8000.0, 155.0, loading=MAX_WEIGHT)
    assert trim.kcas == pytest.approx(155.0, abs=1.0)
    assert abs(trim.vertical_speed_fpm) < 30.0
    assert 0.5 < trim.throttle_norm < 1.0
    assert abs(trim.elevator_norm) < 0.3
    assert -2.0 < trim.alpha_deg < 4.0
    assert trim.rpm == pytest.approx(2498.0, abs=10.0)


def test_elevator_doublet_response_is_stable_and_well_damped() -> None:
    # MIL-F-8785C level 1 (category B) short period: damping ratio 0.3 to 2.0; we ask 0.35-1.0 and a
    # response that has died out (< 5 % of the peak) within 4 s.
    resp = airdata.doublet_damping(C400, 150.0, loading=MAX_WEIGHT)
    assert 0.35 <= resp.damping_ratio <= 1.0
    assert 1.0 < resp.natural_frequency_rad_s < 10.0
    assert resp.residual_q_degps < 0.05 * resp.peak_q_degps


@pytest.mark.xfail(strict=True, reason="JSBSim's steady-state engine solver fails with this propeller; see README")
def test_do_trim_full_in_cruise() -> None:
    fdm, _ = airdata.flying_start(C400, 8000.0, 170.0, settle_s=2.0, advance_norm=0.83)
    fdm.do_trim(1)


# --- the harness against JSBSim's c172p and the Cessna 172P's published figures (independent check) ---


def test_harness_c172p_stall_speed_matches_poh() -> None:
    # Cessna 172P POH: about 48 KIAS flaps up at 2,400 lb (brief); tolerance +-15 % for KIAS vs KCAS.
    assert airdata.stall_speed("c172p", loading=C172_MAX, start_kcas=70.0) == pytest.approx(48.0, rel=0.15)


def test_harness_c172p_roll_rate_and_doublet() -> None:
    assert 45.0 <= airdata.roll_rate("c172p", 100.0, loading=C172_MAX) <= 90.0
    resp = airdata.doublet_damping("c172p", 100.0, loading=C172_MAX)
    assert 0.35 <= resp.damping_ratio <= 1.0


def test_harness_climb_rate_equals_specific_excess_power() -> None:
    # Independent of the altitude differencing in climb_rate: along the flight path
    # dh/dt = V sin(gamma) = V [(T cos(alpha) - D) / W - (dV/dt) / g]. The same climb is flown again
    # (same start, same pilot: deterministic) and the identity is averaged over the measuring window.
    measured = airdata.climb_rate("c172p", 74.0, loading=C172_MAX)
    fdm, pilot = airdata.flying_start("c172p", 200.0, 74.0, loading=C172_MAX, settle_s=5.0)
    pilot.throttle_v_ref_kcas = None
    pilot.v_ref_kcas = 74.0
    fdm["fcs/throttle-cmd-norm[0]"] = 1.0
    pilot.fly(30.0)
    n = round(30.0 / airdata.DT_S)
    total = 0.0
    v_prev = fdm["velocities/vtrue-fps"]
    for _ in range(n):
        pilot.step()
        fdm.run()
        v = fdm["velocities/vtrue-fps"]
        thrust = fdm["propulsion/engine[0]/thrust-lbs"] * math.cos(fdm["aero/alpha-rad"])
        drag = fdm["forces/fwx-aero-lbs"]  # JSBSim reports the wind-axis x force as drag, positive aft
        vdot = (v - v_prev) / airdata.DT_S
        v_prev = v
        total += v * ((thrust - drag) / fdm["inertia/weight-lbs"] - vdot / 32.174)
    identity_fpm = 60.0 * total / n
    assert measured == pytest.approx(identity_fpm, rel=0.03)


def test_aircraft_root_finds_package_models() -> None:
    assert (airdata.aircraft_root("c172p") / "c172p" / "c172p.xml").is_file()
    assert airdata.aircraft_root(C400) == AIRCRAFT_DIR
    assert jsbsim.__version__.startswith("1.3")
