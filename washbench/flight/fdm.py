"""JSBSim set-up for a manoeuvre: model, initial conditions, environment, trim or ground start.

Wind: the manoeuvre gives the direction the wind blows FROM; JSBSim's
``atmosphere/wind-{north,east,down}-fps`` is the velocity of the air mass (blowing
TOWARDS), so the from-direction is turned round here and nowhere else.
"""

from __future__ import annotations

import math
import os
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from washbench.errors import WashbenchError
from washbench.flight.console import quiet_stdout
from washbench.flight.geo import DEFAULT_LATITUDE_DEG, DEFAULT_LONGITUDE_DEG, LocalFrame
from washbench.flight.jsbsim_xml import aircraft_for_jsbsim, scratch_output_dir
from washbench.flight.manoeuvre import Manoeuvre
from washbench.flight.manoeuvre_schema import Hold
from washbench.flight.pilot import Pilot
from washbench.flight.profile import PilotProfile
from washbench.io.paths import jsbsim_root

KT_TO_FPS = 1852.0 / 3600.0 / 0.3048
FT_TO_M = 0.3048

#: MIL-F-8785C: (probability-of-exceedance index of JSBSim's milspec table, wind at 20 ft in kt).
TURBULENCE = {"none": (0, 0.0), "light": (3, 15.0), "moderate": (4, 30.0), "severe": (6, 45.0)}


@dataclass(frozen=True)
class Setup:
    """Where the flight starts, in the local frame whose origin is the start point (or threshold)."""

    frame: LocalFrame
    threshold_ne_m: tuple[float, float] | None  # runway threshold, north/east of the origin
    runway_heading_rad: float | None
    runway_elevation_ft: float


def make_fdm(m: Manoeuvre, profile: PilotProfile) -> tuple[Any, Setup]:
    """Create and initialise the FDM for manoeuvre ``m``; return it with the start geometry.

    Air start: trimmed straight and level at the given altitude, airspeed and heading.
    Runway start: at rest on the centreline at the resting height, engine running, brakes on.
    """
    os.environ["JSBSIM_DEBUG"] = "0"
    import jsbsim

    root = m.aircraft_files.root
    fdm = jsbsim.FGFDMExec(str(jsbsim_root()), None)
    fdm.set_output_path(scratch_output_dir())  # not JSBSim's root: its own files (write-state-file) are thrown away
    with tempfile.TemporaryDirectory(prefix="washbench-aircraft-") as tmp:  # the model without <output>
        fdm.set_aircraft_path(str(aircraft_for_jsbsim(root, m.aircraft, Path(tmp))))
        with quiet_stdout():
            try:
                loaded = fdm.load_model(m.aircraft)
                fdm.disable_output()  # the model's <output> directives, neutralised, write nothing (jsbsim_xml)
            except Exception as exc:  # JSBSim raises plain exceptions on broken models
                raise WashbenchError(m.located(("aircraft",), f"JSBSim could not load the model ({exc})")) from None
            if not loaded:
                raise WashbenchError(m.located(("aircraft",), f"JSBSim could not load the model {root / m.aircraft}"))
    fdm.set_dt(m.dt_s)

    rw = m.runway
    air = m.start.air
    if rw is not None:
        frame = LocalFrame(rw.latitude_deg, rw.longitude_deg)
        threshold = (0.0, 0.0)
        rw_heading = math.radians(rw.heading_deg)
        elevation = rw.elevation_ft
    else:
        lat = air.latitude_deg if air is not None and air.latitude_deg is not None else DEFAULT_LATITUDE_DEG
        lon = air.longitude_deg if air is not None and air.longitude_deg is not None else DEFAULT_LONGITUDE_DEG
        frame = LocalFrame(lat, lon)
        threshold, rw_heading, elevation = None, None, 0.0

    if air is not None:
        heading_deg = air.heading_deg if air.heading_deg is not None else rw.heading_deg  # type: ignore[union-attr]
        if air.latitude_deg is not None:
            lat, lon = air.latitude_deg, air.longitude_deg
        elif air.before_threshold_ft is not None and rw_heading is not None:
            d = -air.before_threshold_ft * FT_TO_M
            lat, lon = frame.to_latlon_deg(d * math.cos(rw_heading), d * math.sin(rw_heading))
        else:
            lat, lon = frame.to_latlon_deg(0.0, 0.0)
    else:
        assert rw is not None and m.start.runway is not None  # guaranteed by load_manoeuvre
        heading_deg = rw.heading_deg
        d = m.start.runway.past_threshold_ft * FT_TO_M
        lat, lon = frame.to_latlon_deg(d * math.cos(rw_heading), d * math.sin(rw_heading))  # type: ignore[arg-type]

    fdm["ic/lat-geod-deg"] = lat
    fdm["ic/long-gc-deg"] = lon
    fdm["ic/terrain-elevation-ft"] = elevation
    fdm["ic/psi-true-deg"] = heading_deg
    fdm["ic/phi-deg"] = 0.0
    wind_n = wind_e = 0.0
    env = m.environment
    if env.wind is not None and env.wind.speed_kts > 0:
        towards = math.radians(env.wind.from_deg) + math.pi
        wind_n = env.wind.speed_kts * KT_TO_FPS * math.cos(towards)
        wind_e = env.wind.speed_kts * KT_TO_FPS * math.sin(towards)
    if air is not None:
        fdm["ic/h-sl-ft"] = air.altitude_ft
        fdm["ic/vc-kts"] = air.airspeed_kts
        fdm["ic/gamma-deg"] = air.flight_path_deg
        fdm["fcs/flap-cmd-norm"] = air.flaps_deg / profile.limits.flaps_full_cmd_deg
    else:
        fdm["ic/h-agl-ft"] = profile.geometry.cg_height_on_ground_ft
        fdm["ic/vc-kts"] = 0.0
        fdm["ic/u-fps"] = 0.0
    fdm["propulsion/set-running"] = -1
    _set_engine_levers(fdm, m.aircraft, profile)
    seed = env.turbulence.seed if env.turbulence is not None and env.turbulence.seed is not None else 0
    fdm["simulation/randomseed"] = seed
    with quiet_stdout():
        fdm.run_ic()
    fdm["fcs/mixture-cmd-norm"] = 1.0

    if air is not None:
        fdm["fcs/flap-pos-deg"] = air.flaps_deg
        if profile.start.air == "flying":
            _flying_start(fdm, m, profile, heading_deg)
        else:
            try:
                with quiet_stdout():
                    fdm.do_trim(1)
            except RuntimeError as exc:
                raise WashbenchError(
                    m.located(
                        ("start", "air"),
                        f"{m.aircraft}: JSBSim could not trim straight flight at {air.airspeed_kts:g} kt, "
                        f"{air.altitude_ft:g} ft, flaps {air.flaps_deg:g} deg ({exc})",
                    )
                ) from None
        if wind_n or wind_e:
            crab = air.heading_deg is None  # on a runway's extended centreline: crab to track it
            _add_wind_to_trimmed_state(fdm, wind_n, wind_e, crab)
    else:
        fdm["fcs/throttle-cmd-norm"] = 0.0
        fdm["fcs/left-brake-cmd-norm"] = 1.0
        fdm["fcs/right-brake-cmd-norm"] = 1.0

    fdm["atmosphere/wind-north-fps"] = wind_n
    fdm["atmosphere/wind-east-fps"] = wind_e
    fdm["atmosphere/wind-down-fps"] = 0.0
    if env.turbulence is not None and env.turbulence.severity != "none":
        index, w20_kts = TURBULENCE[env.turbulence.severity]
        fdm["atmosphere/turb-type"] = 3  # MIL-F-8785C (Dryden) in JSBSim's milspec form
        fdm["atmosphere/turbulence/milspec/severity"] = index
        fdm["atmosphere/turbulence/milspec/windspeed_at_20ft_AGL-fps"] = w20_kts * KT_TO_FPS
    # recompute the derived values (airspeed, sideslip) for the wind without advancing time
    fdm.suspend_integration()
    fdm.run()
    fdm.resume_integration()
    if fdm["simulation/sim-time-sec"] != 0.0:  # guards the t = k * dt time base
        raise WashbenchError(m.located(("start",), "JSBSim advanced time while initialising"))
    return fdm, Setup(frame, threshold, rw_heading, elevation)


def _set_engine_levers(fdm: Any, aircraft: str, profile: PilotProfile) -> None:
    """Magnetos and propeller lever from the profile (checked to exist: JSBSim ignores unknown names)."""
    pm = fdm.get_property_manager()
    for name, value in (
        ("propulsion/magneto_cmd", profile.engine.magneto_cmd),
        ("fcs/advance-cmd-norm[0]", profile.engine.propeller_advance_norm),
    ):
        if value is None:
            continue
        if not pm.hasNode(name):
            raise WashbenchError(f"{aircraft}: the pilot profile sets {name}, which the JSBSim model lacks")
        fdm[name] = float(value)


#: Flying start: largest differences from the asked-for start after settling (kt, ft/s, rad/s).
SETTLED_KTS = 1.0
SETTLED_FPS = 1.0
SETTLED_RADPS = 0.005


def _flying_start(fdm: Any, m: Manoeuvre, profile: PilotProfile, heading_deg: float) -> None:
    """Bring the aircraft to the air start by flying it (for models ``do_trim(1)`` cannot trim).

    The scripted pilot holds the heading, the start's flight-path angle (as a climb rate) with the
    elevator and the airspeed with the throttle, in still air, for ``profile.start.settle_s``. The
    settled air-relative state (body velocities, bank and pitch) and the controls are then put back
    at the start position, altitude and heading with ``run_ic`` and the clock is reset to zero, so the
    manoeuvre starts in steady flight at t = 0. Raises WashbenchError if the flight has not settled.
    """
    air = m.start.air
    assert air is not None  # only called for air starts
    dt = m.dt_s
    with quiet_stdout():
        fdm.run_ic()
    fdm["fcs/mixture-cmd-norm"] = 1.0
    fdm["fcs/flap-cmd-norm"] = air.flaps_deg / profile.limits.flaps_full_cmd_deg
    fdm["fcs/throttle-cmd-norm"] = 0.5
    gamma = math.radians(air.flight_path_deg)
    vs_fpm = 60.0 * fdm["velocities/vt-fps"] * math.sin(gamma)
    pilot = Pilot(profile, None, dt)
    pilot.set_controls(fdm["fcs/aileron-cmd-norm"], fdm["fcs/elevator-cmd-norm"], fdm["fcs/rudder-cmd-norm"])
    hold = Hold(heading_deg=float(heading_deg) % 360.0, vertical_speed_fpm=vs_fpm, airspeed_kts=float(air.airspeed_kts))
    pilot.begin_phase(hold, fdm["attitude/theta-rad"], 0.5, air.flaps_deg)
    names = ("attitude/phi-rad", "attitude/theta-rad", "attitude/psi-rad", "velocities/p-rad_sec",
             "velocities/q-rad_sec", "velocities/r-rad_sec", "aero/beta-rad", "velocities/vc-kts",
             "velocities/vg-fps", "flight-path/psi-gt-rad", "velocities/h-dot-fps", "position/h-sl-ft",
             "position/h-agl-ft")  # fmt: skip
    pm = fdm.get_property_manager()
    gets = [pm.get_node(n).get_double_value for n in names]
    nz = pm.get_node("accelerations/Nz").get_double_value
    alpha = pm.get_node("aero/alpha-rad").get_double_value
    vt = pm.get_node("velocities/vtrue-kts").get_double_value
    writes = [pm.get_node(n).set_double_value for n in (
        "fcs/aileron-cmd-norm", "fcs/elevator-cmd-norm", "fcs/rudder-cmd-norm", "fcs/throttle-cmd-norm")]  # fmt: skip
    for _ in range(round(profile.start.settle_s / dt)):
        phi, theta, psi, p, q, r, beta, vc, vg, trk, hdot, h, agl = (g() for g in gets)
        pilot.step(phi, theta, psi, p, q, r, beta, vc, vg, trk, hdot, h, agl, 0.0, 0.0, False, nz(), alpha(), vt())
        for w, value in zip(writes, (pilot.aileron, pilot.elevator, pilot.rudder, pilot.throttle), strict=True):
            w(value)
        fdm.run()
    phi, theta, psi, p, q, r, beta, vc, vg, trk, hdot, h, agl = (g() for g in gets)
    off = (abs(vc - air.airspeed_kts), abs(hdot - vs_fpm / 60.0), max(abs(p), abs(q), abs(r)))
    if off[0] > SETTLED_KTS or off[1] > SETTLED_FPS or off[2] > SETTLED_RADPS:
        raise WashbenchError(
            m.located(
                ("start", "air"),
                f"{m.aircraft}: the flying start did not settle at {air.airspeed_kts:g} kt, {air.altitude_ft:g} ft, "
                f"flight path {air.flight_path_deg:g} deg in {profile.start.settle_s:g} s (airspeed off by "
                f"{off[0]:.1f} kt, climb rate by {off[1]:.1f} ft/s, body rates up to {off[2]:.3f} rad/s)",
            )
        )
    u, v, w = fdm["velocities/u-fps"], fdm["velocities/v-fps"], fdm["velocities/w-fps"]
    fdm["ic/h-sl-ft"] = air.altitude_ft
    fdm["ic/psi-true-deg"] = heading_deg
    fdm["ic/phi-rad"] = phi
    fdm["ic/theta-rad"] = theta
    fdm["ic/u-fps"] = u
    fdm["ic/v-fps"] = v
    fdm["ic/w-fps"] = w
    fdm["ic/p-rad_sec"] = 0.0
    fdm["ic/q-rad_sec"] = 0.0
    fdm["ic/r-rad_sec"] = 0.0
    with quiet_stdout():
        fdm.run_ic()
    fdm.set_sim_time(0.0)


def _add_wind_to_trimmed_state(fdm: Any, wind_n: float, wind_e: float, crab: bool) -> None:
    """Re-initialise a state trimmed in still air so that it flies the same air-relative state in the wind.

    JSBSim's own initial-condition wind (``ic/vw-*``) does not keep the airspeed and sideslip
    it is given (measured on 1.3.3), so the trim is done in still air and the wind is added
    here: body ground velocity = trimmed air velocity + wind in body axes. With ``crab`` the
    heading is turned into the wind so the ground track stays the trimmed heading.
    """
    u, v, w = fdm["velocities/u-fps"], fdm["velocities/v-fps"], fdm["velocities/w-fps"]
    phi, theta, psi = fdm["attitude/phi-rad"], fdm["attitude/theta-rad"], fdm["attitude/psi-rad"]
    if crab:
        right = -wind_n * math.sin(psi) + wind_e * math.cos(psi)  # wind component to the right of the track
        vt = fdm["velocities/vt-fps"]
        psi -= math.asin(max(-0.9, min(0.9, right / vt)))
    cps, sps, cth, sth = math.cos(psi), math.sin(psi), math.cos(theta), math.sin(theta)
    cph, sph = math.cos(phi), math.sin(phi)
    # NED -> body (3-2-1 Euler angles), applied to the wind (down component zero)
    xb = cth * cps * wind_n + cth * sps * wind_e
    yb = (sph * sth * cps - cph * sps) * wind_n + (sph * sth * sps + cph * cps) * wind_e
    zb = (cph * sth * cps + sph * sps) * wind_n + (cph * sth * sps - sph * cps) * wind_e
    fdm["ic/phi-rad"] = phi
    fdm["ic/theta-rad"] = theta
    fdm["ic/psi-true-rad"] = psi
    fdm["ic/u-fps"] = u + xb
    fdm["ic/v-fps"] = v + yb
    fdm["ic/w-fps"] = w + zb
    with quiet_stdout():
        fdm.run_ic()
