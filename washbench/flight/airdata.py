"""Figures of merit of any JSBSim aircraft, measured by flying it: the harness behind the aircraft checks.

Each measurement builds a fresh FDM, brings the aircraft to a steady start with a simple closed-loop
pilot (a *flying start*: initial conditions plus closed-loop settling), performs one standard flight-test
manoeuvre and returns the figure. The same code measures washbench's Columbia-400-like model and
JSBSim's own c172p, so the c172p's published figures check the harness independently.

Figures (units in the names, as at every washbench edge):

- :func:`level_trim`: controls and attitude in steady level flight at a given KCAS;
- :func:`stall_speed`: 1-g stall speed from a 1 kt/s deceleration with altitude held (FAR 23.49 style);
  the speed at the maximum lift coefficient, corrected to 1 g (V / sqrt(n_z)), in KCAS;
- :func:`level_speed`: steady level true airspeed at an altitude and throttle setting;
- :func:`climb_rate`: steady rate of climb at a given KCAS and throttle;
- :func:`roll_rate`: peak roll rate after a step of full aileron from wings level;
- :func:`doublet_damping`: damping ratio and natural frequency of the pitch response to an elevator
  doublet, from a least-squares fit of a damped sinusoid to the free pitch-rate response.

The JSBSim conventions used (checked on c172p and columbia400): +aileron rolls right, +elevator pitches
nose down; ``accelerations/Nz`` is +1 in level flight.
"""

from __future__ import annotations

import math
import os
import warnings
from dataclasses import dataclass
from pathlib import Path

import jsbsim
import numpy as np
from scipy.optimize import curve_fit

from washbench.errors import WashbenchError
from washbench.flight.jsbsim_xml import scratch_output_dir
from washbench.io.paths import find_aircraft
from washbench.io.yamlio import StrictModel, load_yaml_model

DT_S = 1.0 / 120.0


@dataclass(frozen=True)
class Loading:
    """How to load the aircraft: target gross weight (lb) reached by adjusting one payload point mass."""

    gross_weight_lbs: float
    payload_pointmass: int


def aircraft_root(name: str) -> Path:
    """Folder holding ``name/name.xml``: washbench's ``aircraft/`` first, then the jsbsim package's."""
    return find_aircraft(name)


def make_fdm(name: str, loading: Loading | None = None) -> jsbsim.FGFDMExec:
    """A loaded, silent FDM for aircraft ``name`` at dt = 1/120 s, optionally reloaded to a gross weight."""
    os.environ.setdefault("JSBSIM_DEBUG", "0")

    fdm = jsbsim.FGFDMExec(None)
    fdm.set_debug_level(0)
    fdm.set_output_path(scratch_output_dir())  # not the current folder (JSBSim's own files are thrown away)
    fdm.set_aircraft_path(str(aircraft_root(name)))
    if not fdm.load_model(name):
        raise WashbenchError(f"{name}: JSBSim could not load the model")
    fdm.set_dt(DT_S)
    if loading is not None:
        fdm.run_ic()  # mass properties are computed on the first pass
        idx = loading.payload_pointmass
        key = f"inertia/pointmass-weight-lbs[{idx}]"
        if not fdm.get_property_manager().hasNode(key):
            raise WashbenchError(f"{name}: no point mass {idx} to load")
        extra = loading.gross_weight_lbs - fdm["inertia/weight-lbs"]
        fdm[key] = fdm[key] + extra
        if fdm[key] < 0:
            raise WashbenchError(f"{name}: cannot reach {loading.gross_weight_lbs} lb with point mass {idx}")
    return fdm


class Pilot:
    """A minimal closed-loop pilot: wings level, pitch attitude from an altitude or a speed loop, throttle.

    Gains are in normalised control units per radian (attitude) or per foot / knot; they suit light
    singles from 50 to 240 kt. Call :meth:`step` once per FDM frame before ``fdm.run()``.
    """

    def __init__(self, fdm: jsbsim.FGFDMExec) -> None:
        self.fdm = fdm
        self.h_ref_ft = fdm["position/h-sl-ft"]
        self.v_ref_kcas: float | None = None  # speed held with the elevator (climb) when set
        self.throttle_v_ref_kcas: float | None = None  # speed held with the throttle when set
        self.theta_int = fdm["attitude/theta-rad"]
        self.elev_int = fdm["fcs/elevator-cmd-norm"]
        self.thr_int = fdm["fcs/throttle-cmd-norm[0]"]
        self.hold_elevator = False
        self.hold_aileron = False

    def step(self) -> None:
        f = self.fdm
        theta, q = f["attitude/theta-rad"], f["velocities/q-rad_sec"]
        v = f["velocities/vc-kts"]
        if not self.hold_elevator:
            if self.v_ref_kcas is not None:
                err = v - self.v_ref_kcas  # too fast -> pitch up
                self.theta_int += 0.003 * err * DT_S
                theta_cmd = self.theta_int + 0.02 * err
            else:
                err = self.h_ref_ft - f["position/h-sl-ft"]
                self.theta_int += 0.00015 * err * DT_S
                theta_cmd = self.theta_int + 0.002 * err - 0.012 * f["velocities/h-dot-fps"]
            theta_cmd = min(max(theta_cmd, -0.35), 0.45)
            e_theta = theta_cmd - theta
            self.elev_int = min(max(self.elev_int - 0.8 * e_theta * DT_S, -1.0), 1.0)
            f["fcs/elevator-cmd-norm"] = min(max(self.elev_int - 2.0 * e_theta + 0.6 * q, -1.0), 1.0)
        if not self.hold_aileron:
            f["fcs/aileron-cmd-norm"] = min(max(-1.5 * f["attitude/phi-rad"] - 0.3 * f["velocities/p-rad_sec"], -1), 1)
        if self.throttle_v_ref_kcas is not None:
            err = self.throttle_v_ref_kcas - v
            self.thr_int = min(max(self.thr_int + 0.01 * err * DT_S, 0.0), 1.0)
            f["fcs/throttle-cmd-norm[0]"] = min(max(self.thr_int + 0.05 * err, 0.0), 1.0)

    def fly(self, seconds: float) -> None:
        """Step the pilot and the FDM for ``seconds`` (rounded to whole frames)."""
        for _ in range(round(seconds / DT_S)):
            self.step()
            self.fdm.run()


def flying_start(
    name: str,
    altitude_ft: float,
    kcas: float,
    *,
    loading: Loading | None = None,
    flaps_norm: float = 0.0,
    throttle: float | None = None,
    advance_norm: float = 1.0,
    settle_s: float = 20.0,
    latitude_deg: float = 45.0,
) -> tuple[jsbsim.FGFDMExec, Pilot]:
    """Start ``name`` in level flight and settle it with the pilot.

    Without ``throttle`` the pilot holds ``kcas`` with the throttle and the altitude with the elevator;
    with a fixed ``throttle`` it holds the altitude only. Mixture full rich (the columbia400 meters fuel
    to deck pressure; c172p needs no leaning below 8,000 ft), propeller lever ``advance_norm``.
    """
    fdm = make_fdm(name, loading)
    fdm["ic/h-sl-ft"] = altitude_ft
    fdm["ic/vc-kts"] = kcas
    fdm["ic/gamma-deg"] = 0.0
    fdm["ic/lat-geod-deg"] = latitude_deg
    fdm["fcs/flap-cmd-norm"] = flaps_norm
    fdm.run_ic()
    fdm["propulsion/set-running"] = -1
    fdm["propulsion/magneto_cmd"] = 3
    fdm["fcs/mixture-cmd-norm[0]"] = 1.0
    fdm["fcs/advance-cmd-norm[0]"] = advance_norm
    fdm["fcs/throttle-cmd-norm[0]"] = 0.7 if throttle is None else throttle
    fdm.run()
    pilot = Pilot(fdm)
    pilot.h_ref_ft = altitude_ft
    pilot.throttle_v_ref_kcas = kcas if throttle is None else None
    pilot.fly(settle_s)
    return fdm, pilot


@dataclass(frozen=True)
class LevelTrim:
    """Steady level flight: controls (normalised), attitude and engine."""

    kcas: float
    ktas: float
    altitude_ft: float
    throttle_norm: float
    elevator_norm: float
    alpha_deg: float
    theta_deg: float
    rpm: float
    power_hp: float
    vertical_speed_fpm: float


def level_trim(
    name: str, altitude_ft: float, kcas: float, *, loading: Loading | None = None, settle_s: float = 60.0
) -> LevelTrim:
    """Fly level at ``kcas`` and report the settled controls (flying-start trim)."""
    fdm, _ = flying_start(name, altitude_ft, kcas, loading=loading, settle_s=settle_s, advance_norm=0.83)
    return LevelTrim(
        kcas=fdm["velocities/vc-kts"],
        ktas=fdm["velocities/vtrue-kts"],
        altitude_ft=fdm["position/h-sl-ft"],
        throttle_norm=fdm["fcs/throttle-cmd-norm[0]"],
        elevator_norm=fdm["fcs/elevator-cmd-norm"],
        alpha_deg=fdm["aero/alpha-deg"],
        theta_deg=math.degrees(fdm["attitude/theta-rad"]),
        rpm=fdm["propulsion/engine[0]/engine-rpm"],
        power_hp=fdm["propulsion/engine[0]/power-hp"],
        vertical_speed_fpm=60.0 * fdm["velocities/h-dot-fps"],
    )


def stall_speed(
    name: str,
    *,
    loading: Loading | None = None,
    flaps_norm: float = 0.0,
    start_kcas: float,
    altitude_ft: float = 5000.0,
    decel_kt_s: float = 1.0,
) -> float:
    """1-g stall speed (KCAS) from a ``decel_kt_s`` deceleration with altitude held.

    The throttle follows a speed schedule falling at ``decel_kt_s`` (it goes to idle when drag alone
    decelerates faster); the elevator holds the altitude. The lift coefficient n_z W / (q S) is logged
    and the stall speed is V / sqrt(n_z) at its maximum (the 1-g speed for the maximum lift coefficient).
    """
    fdm, pilot = flying_start(name, altitude_ft, start_kcas, loading=loading, flaps_norm=flaps_norm, settle_s=15.0)
    weight = fdm["inertia/weight-lbs"]
    area = fdm["metrics/Sw-sqft"]
    best_cl, v_at_best = -1.0, float("nan")
    v0 = fdm["velocities/vc-kts"]
    n_steps = round((start_kcas / decel_kt_s) / DT_S)
    for k in range(n_steps):
        pilot.throttle_v_ref_kcas = v0 - decel_kt_s * k * DT_S
        pilot.step()
        fdm.run()
        qbar = fdm["aero/qbar-psf"]
        nz = fdm["accelerations/Nz"]
        if qbar > 1.0 and nz > 0.3:
            cl = nz * weight / (qbar * area)
            if cl > best_cl:
                best_cl, v_at_best = cl, fdm["velocities/vc-kts"] / math.sqrt(nz)
        if fdm["aero/alpha-deg"] > 30.0 or fdm["position/h-sl-ft"] < altitude_ft - 150.0:
            break
    return v_at_best


def level_speed(
    name: str,
    altitude_ft: float,
    *,
    loading: Loading | None = None,
    start_kcas: float,
    throttle: float = 1.0,
    advance_norm: float = 1.0,
    duration_s: float = 300.0,
) -> tuple[float, float]:
    """Steady level (KTAS, KCAS) at ``altitude_ft`` with a fixed throttle, altitude held by the elevator."""
    fdm, _ = flying_start(
        name,
        altitude_ft,
        start_kcas,
        loading=loading,
        throttle=throttle,
        advance_norm=advance_norm,
        settle_s=duration_s,
    )
    return fdm["velocities/vtrue-kts"], fdm["velocities/vc-kts"]


def climb_rate(
    name: str,
    kcas: float,
    *,
    loading: Loading | None = None,
    altitude_ft: float = 200.0,
    throttle: float = 1.0,
    advance_norm: float = 1.0,
    settle_s: float = 30.0,
    measure_s: float = 30.0,
) -> float:
    """Steady rate of climb (ft/min) at ``kcas`` with a fixed throttle; speed held with pitch.

    The climb starts at ``altitude_ft`` after a level flying start; the rate is the mean over
    ``measure_s`` after ``settle_s`` of climbing.
    """
    fdm, pilot = flying_start(name, altitude_ft, kcas, loading=loading, advance_norm=advance_norm, settle_s=5.0)
    pilot.throttle_v_ref_kcas = None
    pilot.v_ref_kcas = kcas
    fdm["fcs/throttle-cmd-norm[0]"] = throttle
    pilot.fly(settle_s)
    h0 = fdm["position/h-sl-ft"]
    pilot.fly(measure_s)
    return 60.0 * (fdm["position/h-sl-ft"] - h0) / (round(measure_s / DT_S) * DT_S)


def roll_rate(name: str, kcas: float, *, loading: Loading | None = None, altitude_ft: float = 5000.0) -> float:
    """Peak roll rate (deg/s) after a step of full right aileron from trimmed wings-level flight.

    The run stops when the bank reaches 90 deg or after 4 s; the elevator is frozen at its trim value.
    """
    fdm, pilot = flying_start(name, altitude_ft, kcas, loading=loading, settle_s=20.0, advance_norm=0.83)
    pilot.hold_elevator = pilot.hold_aileron = True
    fdm["fcs/aileron-cmd-norm"] = 1.0
    peak = 0.0
    for _ in range(round(4.0 / DT_S)):
        fdm.run()
        peak = max(peak, fdm["velocities/p-rad_sec"])
        if fdm["attitude/phi-rad"] > math.radians(90.0):
            break
    return math.degrees(peak)


@dataclass(frozen=True)
class DoubletResponse:
    """Pitch response to an elevator doublet: fitted second-order free response of pitch rate."""

    damping_ratio: float
    natural_frequency_rad_s: float
    peak_q_degps: float
    residual_q_degps: float  # max |q| in the last second of the record


def _damped(t: np.ndarray, amp: float, zeta: float, wn: float, phase: float, offset: float) -> np.ndarray:
    zeta_c = min(abs(zeta), 0.999)
    wd = wn * math.sqrt(1.0 - zeta_c * zeta_c)
    return amp * np.exp(-zeta_c * wn * t) * np.sin(wd * t + phase) + offset


def doublet_damping(
    name: str,
    kcas: float,
    *,
    loading: Loading | None = None,
    altitude_ft: float = 5000.0,
    amplitude_norm: float = 0.1,
    half_period_s: float = 0.5,
    record_s: float = 4.0,
) -> DoubletResponse:
    """Elevator doublet (+a for T, -a for T, back to trim) and a damped-sinusoid fit to the free q(t).

    Throttle and all controls are frozen at their settled values; the fit covers ``record_s`` after the
    doublet, which the slow phugoid barely touches for light aircraft (short period of 1-3 s).
    """
    fdm, pilot = flying_start(name, altitude_ft, kcas, loading=loading, settle_s=30.0, advance_norm=0.83)
    pilot.hold_elevator = True
    pilot.throttle_v_ref_kcas = None
    trim = fdm["fcs/elevator-cmd-norm"]
    n_half = round(half_period_s / DT_S)
    peak = 0.0
    for k in range(2 * n_half):
        fdm["fcs/elevator-cmd-norm"] = trim + (amplitude_norm if k < n_half else -amplitude_norm)
        pilot.step()
        fdm.run()
        peak = max(peak, abs(fdm["velocities/q-rad_sec"]))
    fdm["fcs/elevator-cmd-norm"] = trim
    n = round(record_s / DT_S)
    t = np.arange(n) * DT_S  # k * dt, integer step counter
    q = np.empty(n)
    for k in range(n):
        pilot.step()
        fdm.run()
        q[k] = fdm["velocities/q-rad_sec"]
    peak = max(peak, float(np.max(np.abs(q))))
    guesses = [(q[0] if abs(q[0]) > 1e-6 else 1e-3, 0.5, w, 1.5, 0.0) for w in (2.0, 4.0, 7.0)]
    best = None
    for p0 in guesses:
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # covariance not needed, only the fitted parameters
                popt, _ = curve_fit(_damped, t, q, p0=p0, maxfev=20000)
        except RuntimeError:
            continue
        err = float(np.sum((_damped(t, *popt) - q) ** 2))
        if best is None or err < best[0]:
            best = (err, popt)
    if best is None:
        raise WashbenchError(f"{name}: doublet response could not be fitted")
    popt = best[1]
    tail = q[t > record_s - 1.0]
    return DoubletResponse(
        damping_ratio=min(abs(float(popt[1])), 0.999),
        natural_frequency_rad_s=abs(float(popt[2])),
        peak_q_degps=math.degrees(peak),
        residual_q_degps=math.degrees(float(np.max(np.abs(tail)))),
    )


class AircraftLimits(StrictModel):
    """An aircraft's operating limits (``aircraft/<name>/limits.yaml``); speeds in KIAS, load factors in g."""

    aircraft: str
    vne_kias: float
    vno_kias: float
    va_kias: float
    vs0_kias: float
    vs1_kias: float
    vx_kias: float
    vy_kias: float
    vr_kias: float
    n_max: float
    n_min: float
    max_sink_fps: float
    mass_empty_lbs: float
    mass_max_lbs: float
    mass_max_landing_lbs: float
    flaps_takeoff_norm: float
    flaps_landing_norm: float
    advance_cruise_norm: float


def load_limits(path: Path) -> AircraftLimits:
    """Read an aircraft limits file; a bad file raises WashbenchError naming file, line and field."""
    return load_yaml_model(path, AircraftLimits)


def ground_start(name: str, *, loading: Loading | None = None, altitude_ft: float = 0.0) -> jsbsim.FGFDMExec:
    """The aircraft at rest on a runway at ``altitude_ft``: ground trim, engine at idle, brakes on."""
    fdm = make_fdm(name, loading)
    fdm["ic/terrain-elevation-ft"] = altitude_ft
    fdm["ic/h-agl-ft"] = 5.0
    fdm["ic/vc-kts"] = 0.0
    fdm["ic/lat-geod-deg"] = 45.0
    fdm.run_ic()
    fdm.do_trim(2)
    fdm["propulsion/set-running"] = -1
    fdm["propulsion/magneto_cmd"] = 3
    fdm["fcs/mixture-cmd-norm[0]"] = 1.0
    fdm["fcs/throttle-cmd-norm[0]"] = 0.0
    fdm["fcs/left-brake-cmd-norm"] = 1.0
    fdm["fcs/right-brake-cmd-norm"] = 1.0
    return fdm
