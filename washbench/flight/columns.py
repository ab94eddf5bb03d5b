"""The columns of ``flight.parquet``: names, units and meaning (one place that knows them).

Every column is sampled on the time base ``t_s = k * dt`` (integer step counter ``k``).
Body axes are x forward, y right, z down; the specific force is ``f = a - g`` at the
pilot's eyepoint (at rest ``f = [0, 0, -g]``).
"""

from __future__ import annotations

#: (name, description) in the order they are written.
FLIGHT_COLUMNS: tuple[tuple[str, str], ...] = (
    ("t_s", "time since the start, s (k * dt)"),
    ("f_x_mps2", "specific force at the pilot's eyepoint, body x (forward), m/s^2"),
    ("f_y_mps2", "specific force at the pilot's eyepoint, body y (right), m/s^2"),
    ("f_z_mps2", "specific force at the pilot's eyepoint, body z (down), m/s^2"),
    ("omega_x_degps", "body angular velocity p (roll rate), deg/s"),
    ("omega_y_degps", "body angular velocity q (pitch rate), deg/s"),
    ("omega_z_degps", "body angular velocity r (yaw rate), deg/s"),
    ("phi_deg", "bank angle, deg"),
    ("theta_deg", "pitch angle, deg"),
    ("psi_deg", "true heading, deg in [0, 360)"),
    ("alpha_deg", "angle of attack, deg"),
    ("beta_deg", "sideslip angle (positive: air from the right), deg"),
    ("vc_kts", "calibrated airspeed, kt"),
    ("gs_kts", "ground speed, kt"),
    ("altitude_ft", "altitude above mean sea level, ft"),
    ("h_agl_ft", "height of the centre of gravity above the ground, ft"),
    ("climb_fpm", "rate of climb (negative: descent), ft/min"),
    ("north_m", "position north of the reference point (the runway threshold, else the start), m"),
    ("east_m", "position east of the reference point (the runway threshold, else the start), m"),
    ("lat_deg", "geodetic latitude, deg"),
    ("lon_deg", "longitude, deg"),
    ("runway_x_m", "distance along the runway centreline past the threshold, m (NaN without a runway)"),
    ("runway_y_m", "distance right of the runway centreline, m (NaN without a runway)"),
    ("nz", "load factor at the centre of gravity, g (+1 in level flight)"),
    ("aileron", "aileron command, -1..1 (+ rolls right)"),
    ("elevator", "elevator command, -1..1 (+ pitches nose down), excluding pitch trim"),
    ("rudder", "rudder command, -1..1 (+ yaws nose left)"),
    ("throttle", "throttle command, 0..1"),
    ("flaps_deg", "flap position, deg"),
    ("brakes", "brake command, 0..1"),
    ("rpm", "engine speed, rev/min"),
    ("wow", "1 while any landing gear touches the ground, else 0"),
    ("phase", "index of the phase being flown (0-based)"),
)

COLUMN_NAMES: tuple[str, ...] = tuple(name for name, _ in FLIGHT_COLUMNS)

#: Columns that are NaN unless the manoeuvre defines a runway.
RUNWAY_COLUMNS: frozenset[str] = frozenset({"runway_x_m", "runway_y_m"})
