"""Write the Columbia-400-like propeller tables (C_THRUST, C_POWER) from a blade-element estimate.

No public performance tables exist for the Hartzell 78 in three-blade constant-speed propeller, and
JSBSim's shipped constant-speed tables stop near advance ratio J = 1.4, below the J ~ 1.45 the aircraft
reaches at 235 KTAS. This script estimates the tables with blade-element / momentum theory:

- geometry: diameter 78 in, 3 blades (public data); constant chord c/D = 0.065 (activity factor ~100 per
  blade, estimated); constant geometric pitch (twist tan(beta(r)) = 0.75 R tan(beta75) / r); blade from
  0.2 R to the tip;
- section: a cambered Clark-Y-like section (estimated): lift slope 5.7 /rad, zero-lift angle -4 deg,
  cl_max 1.25 with a flat post-stall cl of 0.9, drag cd = 0.009 + 0.012 (cl - 0.4)^2 (+ stall drag);
- annulus momentum balance for the axial induced velocity with the Prandtl tip loss; swirl neglected
  (this overestimates efficiency by a few per cent);
- incompressible: no tip-Mach correction (the table is used at all altitudes).

The column variable is the blade angle at 0.75 R in degrees, the row variable the advance ratio
J = V / (n D). CT = T / (rho n^2 D^4), CP = P / (rho n^3 D^5). Run it from the project root:

    .venv/bin/python tools/columbia400_propeller.py

It rewrites ``aircraft/columbia400/Engines/prop_hartzell78in3v.xml``.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import brentq

from washbench.atomic import write_text_atomic
from washbench.paths import AIRCRAFT_DIR

BLADES = 3
CHORD_OVER_D = 0.065
HUB_R = 0.2
N_STATIONS = 40
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
    cd = 0.009 + 0.012 * (cl - 0.4) ** 2 + cd_stall
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
    for r0, r1 in zip(edges[:-1], edges[1:], strict=True):
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
    return thrust / (n**2 * diameter**4), 2 * np.pi * torque / (n**2 * diameter**5)


def table_xml(name: str, values: np.ndarray) -> str:
    """One JSBSim 2-D table: rows J, columns blade angle (deg)."""
    lines = [f'  <table name="{name}" type="internal">', "    <tableData>"]
    lines.append("          " + "".join(f"{p:9.1f}" for p in PITCHES_DEG))
    for j, row in zip(ADVANCE_RATIOS, values, strict=True):
        lines.append(f"    {j:5.2f} " + "".join(f"{v:9.4f}" for v in row))
    lines += ["    </tableData>", "  </table>"]
    return "\n".join(lines)


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
  (chord c/D {CHORD_OVER_D}, Clark-Y-like section, Prandtl tip loss, no swirl, incompressible).
  Generated file: edit the script, not this file.
-->
<propeller name="prop_hartzell78in3v">
  <ixx unit="SLUG*FT2"> 3.0 </ixx>
  <diameter unit="IN"> 78.0 </diameter>
  <numblades> {BLADES} </numblades>
  <minpitch> 12 </minpitch>
  <maxpitch> 50 </maxpitch>
  <minrpm> 2000 </minrpm>
  <maxrpm> 2600 </maxrpm>

{table_xml("C_THRUST", ct)}

{table_xml("C_POWER", cp)}

</propeller>
"""
    write_text_atomic(AIRCRAFT_DIR / "columbia400" / "Engines" / "prop_hartzell78in3v.xml", text)
    eta = np.where(cp > 1e-4, np.array(ADVANCE_RATIOS)[:, None] * ct / np.maximum(cp, 1e-9), 0.0)
    print("peak efficiency per blade angle:", dict(zip(PITCHES_DEG, np.round(eta.max(axis=0), 3), strict=True)))


if __name__ == "__main__":
    main()
