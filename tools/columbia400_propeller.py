"""Write the Columbia-400-like propeller tables (C_THRUST, C_POWER) from a blade-element estimate.

No public performance tables exist for the Hartzell 78 in three-blade constant-speed propeller, and
JSBSim's shipped constant-speed tables stop near advance ratio J = 1.4, below the J ~ 1.45 the aircraft
reaches at 235 KTAS. This script estimates the tables with blade-element / momentum theory:

- geometry: diameter 78 in, 3 blades (public data); constant chord c/D = 0.065 (activity factor ~100 per
  blade, estimated); constant geometric pitch (twist tan(beta(r)) = 0.75 R tan(beta75) / r); blade from
  0.2 R to the tip;
- section: a cambered Clark-Y-like section (estimated): lift slope 5.7 /rad, zero-lift angle -4 deg,
  cl_max 1.25 with a flat post-stall cl of 0.9, drag cd = 0.016 + 0.015 (cl - 0.4)^2 (+ stall drag);
- annulus momentum balance for the axial induced velocity with the Prandtl tip loss; swirl is not solved
  for, its loss is taken as a flat 3 % thrust reduction (SWIRL_THRUST_FACTOR, estimated: typical
  light-aircraft propellers lose 3-5 % to swirl);
- incompressible: no tip-Mach correction (the table is used at all altitudes).

The column variable is the blade angle at 0.75 R in degrees, the row variable the advance ratio
J = V / (n D). CT = T / (rho n^2 D^4), CP = P / (rho n^3 D^5). Run it from the project root:

    .venv/bin/python tools/columbia400_propeller.py

It rewrites ``aircraft/columbia400/Engines/prop_hartzell78in3v.xml`` and the governor's inverse table
``aircraft/columbia400/Systems/governor.xml`` (blade angle as a function of J and CP, the exact inverse of
the C_POWER table as JSBSim interpolates it, so the governor holds the commanded rpm with no drift).
"""

from __future__ import annotations

import itertools

import numpy as np
from scipy.optimize import brentq

from washbench.io.atomic import write_text_atomic
from washbench.io.paths import AIRCRAFT_DIR

BLADES = 3
CHORD_OVER_D = 0.065
HUB_R = 0.2
N_STATIONS = 40
SWIRL_THRUST_FACTOR = 0.97
PITCHES_DEG = (10.0, 15.0, 20.0, 25.0, 30.0, 35.0, 40.0, 45.0, 50.0, 55.0)
ADVANCE_RATIOS = tuple(round(0.1 * i, 2) for i in range(0, 31))


def section_coefficients(alpha_rad: float) -> tuple[float, float]:
    """Lift and drag coefficients of the estimated blade section at angle of attack ``alpha_rad``."""
    alpha0 = np.radians(-4.0)
    cl_lin = 5.7 * (alpha_rad - alpha0)
    cl_max, cl_min = 1.25, -0.8
    if cl_lin > cl_max:
        excess = cl_lin - cl_max
        cl = max(0.9, cl_max - 0.8 * excess)
        cd_stall = 0.6 * np.sin(alpha_rad - np.radians(11.0)) ** 2 + 0.05 * min(excess, 1.0)
    elif cl_lin < cl_min:
        cl = max(-0.8, cl_min + 0.3 * (cl_lin - cl_min))
        cd_stall = 0.6 * np.sin(alpha_rad - np.radians(-18.0)) ** 2
    else:
        cl = cl_lin
        cd_stall = 0.0
    cd = 0.016 + 0.015 * (cl - 0.4) ** 2 + cd_stall
    return float(cl), float(cd)


def coefficients(advance_ratio: float, pitch75_deg: float) -> tuple[float, float]:
    """(CT, CP) of the propeller at advance ratio J and 0.75 R blade angle (deg), unit n and D."""
    n, diameter = 1.0, 1.0
    radius = diameter / 2
    speed = advance_ratio * n * diameter
    omega = 2 * np.pi * n
    edges = np.linspace(HUB_R * radius, radius, N_STATIONS + 1)
    thrust = torque = 0.0
    tan75 = np.tan(np.radians(pitch75_deg))
    chord = CHORD_OVER_D * diameter
    for r0, r1 in itertools.pairwise(edges):
        r = 0.5 * (r0 + r1)
        dr = r1 - r0
        beta = np.arctan(0.75 * radius * tan75 / r)

        def loads(w: float, r: float = r, beta: float = beta) -> tuple[float, float, float, float]:
            vax = speed + w
            vt = omega * r
            phi = np.arctan2(vax, vt)
            cl, cd = section_coefficients(beta - phi)
            w2 = vax * vax + vt * vt
            cn = cl * np.cos(phi) - cd * np.sin(phi)
            ct = cl * np.sin(phi) + cd * np.cos(phi)
            sphi = max(abs(np.sin(phi)), 1e-6)
            f_tip = 2 / np.pi * np.arccos(np.exp(-BLADES * (radius - r) / (2 * r * sphi)))
            return w2, cn, ct, max(f_tip, 1e-4)

        def residual(w: float, r: float = r) -> float:
            w2, cn, _, f_tip = loads(w)
            return 4 * np.pi * r * f_tip * (speed + w) * w - 0.5 * w2 * BLADES * chord * cn

        lo, hi = (-0.49 * speed if speed > 0 else 0.0), 2.0 * omega * radius
        if residual(lo) * residual(hi) > 0:
            lo = 0.0
        w = brentq(residual, lo, hi, xtol=1e-10) if residual(lo) * residual(hi) < 0 else 0.0
        w2, cn, ct, _ = loads(w)
        thrust += 0.5 * w2 * BLADES * chord * cn * dr
        torque += 0.5 * w2 * BLADES * chord * ct * r * dr
    return SWIRL_THRUST_FACTOR * thrust / (n**2 * diameter**4), 2 * np.pi * torque / (n**2 * diameter**5)


def table_xml(name: str, values: np.ndarray) -> str:
    """One JSBSim 2-D table: rows J, columns blade angle (deg)."""
    lines = [f'  <table name="{name}" type="internal">', "    <tableData>"]
    lines.append("          " + "".join(f"{p:9.1f}" for p in PITCHES_DEG))
    for j, row in zip(ADVANCE_RATIOS, values, strict=True):
        lines.append(f"    {j:5.2f} " + "".join(f"{v:9.4f}" for v in row))
    lines += ["    </tableData>", "  </table>"]
    return "\n".join(lines)


CP_GRID = tuple(round(-0.04 + 0.01 * i, 2) for i in range(0, 45))
RPM_MIN, RPM_MAX = 2000.0, 2600.0
DIAMETER_FT = 78.0 / 12.0


def inverse_pitch_table(cp: np.ndarray) -> np.ndarray:
    """Blade angle (deg) for each (J, CP_GRID) so that C_POWER(J, angle) = CP, linear as JSBSim interpolates.

    CP is made non-decreasing in blade angle per row first (it is, except in deep stall at low J); CP
    values outside a row's range give the end blade angles.
    """
    pitches = np.array(PITCHES_DEG)
    out = np.zeros((cp.shape[0], len(CP_GRID)))
    for i, row in enumerate(cp):
        mono = np.maximum.accumulate(row)
        mono = mono + np.arange(len(mono)) * 1e-7  # strictly increasing for np.interp
        out[i] = np.interp(CP_GRID, mono, pitches)
    return out


def governor_xml(beta: np.ndarray) -> str:
    """The JSBSim system that sets the blade angle from the commanded rpm (fcs/advance-cmd-norm[0])."""
    rows = ["          " + "".join(f"{c:8.2f}" for c in CP_GRID)]
    for j, row in zip(ADVANCE_RATIOS, beta, strict=True):
        rows.append(f"    {j:5.2f} " + "".join(f"{v:8.2f}" for v in row))
    table = "\n".join(rows)
    d5 = DIAMETER_FT**5
    return f"""<?xml version="1.0"?>
<!--
  Constant-speed propeller governor of the washbench Columbia-400-like model. GENERATED by
  tools/columbia400_propeller.py: edit the script, not this file.

  JSBSim's own governor (pitch -= rpm error * dt) is an undamped integrator that oscillates with this
  propeller and defeats do_trim at cruise speeds, so the propeller runs in manual-pitch mode and this
  system sets the blade angle directly:
    rpm_cmd = {RPM_MIN:.0f} + {RPM_MAX - RPM_MIN:.0f} * fcs/advance-cmd-norm[0]
    J_cmd   = u_aero / (n_cmd D)
    CP_req  = engine power / (rho n_cmd^3 D^5)
    blade angle = beta(J_cmd, CP_req)   (inverse of the propeller's C_POWER table)
                + 0.02 deg/rpm * (rpm - rpm_cmd)   (damping)
  At rpm = rpm_cmd the propeller absorbs exactly the engine power, so the rpm holds without drift.
-->
<system name="governor">
  <channel name="Governor">
    <fcs_function name="systems/governor/rpm-cmd">
      <function>
        <sum>
          <value> {RPM_MIN:.1f} </value>
          <product> <value> {RPM_MAX - RPM_MIN:.1f} </value> <property> fcs/advance-cmd-norm[0] </property> </product>
        </sum>
      </function>
    </fcs_function>
    <fcs_function name="systems/governor/j-cmd">
      <function>
        <quotient>
          <product> <value> 60.0 </value> <property> velocities/u-aero-fps </property> </product>
          <product> <value> {DIAMETER_FT:.6f} </value> <property> systems/governor/rpm-cmd </property> </product>
        </quotient>
      </function>
    </fcs_function>
    <fcs_function name="systems/governor/cp-req">
      <function>
        <quotient>
          <product> <value> 550.0 </value> <property> propulsion/engine[0]/power-hp </property> </product>
          <product>
            <property> atmosphere/rho-slugs_ft3 </property>
            <pow> <quotient> <property> systems/governor/rpm-cmd </property> <value> 60.0 </value> </quotient>
                  <value> 3.0 </value> </pow>
            <value> {d5:.4f} </value>
          </product>
        </quotient>
      </function>
    </fcs_function>
    <fcs_function name="systems/governor/blade-angle-deg">
      <function>
        <sum>
          <table>
            <independentVar lookup="row"> systems/governor/j-cmd </independentVar>
            <independentVar lookup="column"> systems/governor/cp-req </independentVar>
            <tableData>
{table}
            </tableData>
          </table>
          <product>
            <value> 0.02 </value>
            <difference>
              <property> propulsion/engine[0]/engine-rpm </property>
              <property> systems/governor/rpm-cmd </property>
            </difference>
          </product>
        </sum>
      </function>
      <clipto> <min> {PITCHES_DEG[0]:.1f} </min> <max> {PITCHES_DEG[-1]:.1f} </max> </clipto>
      <output> propulsion/engine[0]/blade-angle </output>
    </fcs_function>
  </channel>
</system>
"""


def main() -> None:
    ct = np.zeros((len(ADVANCE_RATIOS), len(PITCHES_DEG)))
    cp = np.zeros_like(ct)
    for i, j in enumerate(ADVANCE_RATIOS):
        for k, p in enumerate(PITCHES_DEG):
            ct[i, k], cp[i, k] = coefficients(j, p)
    text = f"""<?xml version="1.0"?>
<!--
  Columbia-400-like propeller: Hartzell-type 78 in, 3-blade, constant speed.
  Tables ESTIMATED by blade-element / momentum theory in tools/columbia400_propeller.py
  (chord c/D {CHORD_OVER_D}, Clark-Y-like section, Prandtl tip loss, swirl as a 3 % thrust loss, incompressible).
  Generated file: edit the script, not this file.
-->
<propeller name="prop_hartzell78in3v">
  <ixx unit="SLUG*FT2"> 6.0 </ixx> <!-- propeller plus crankshaft, estimated -->
  <diameter unit="IN"> 78.0 </diameter>
  <numblades> {BLADES} </numblades>
  <minpitch> {PITCHES_DEG[0]:.0f} </minpitch>
  <maxpitch> {PITCHES_DEG[-1]:.0f} </maxpitch>
  <!-- manual-pitch mode: the blade angle is set by Systems/governor.xml -->
  <constspeed> 0 </constspeed>

{table_xml("C_THRUST", ct)}

{table_xml("C_POWER", cp)}

</propeller>
"""
    write_text_atomic(AIRCRAFT_DIR / "columbia400" / "Engines" / "prop_hartzell78in3v.xml", text)
    write_text_atomic(AIRCRAFT_DIR / "columbia400" / "Systems" / "governor.xml", governor_xml(inverse_pitch_table(cp)))
    eta = np.where(cp > 1e-4, np.array(ADVANCE_RATIOS)[:, None] * ct / np.maximum(cp, 1e-9), 0.0)
    print("peak efficiency per blade angle:", dict(zip(PITCHES_DEG, np.round(eta.max(axis=0), 3), strict=True)))


if __name__ == "__main__":
    main()
