"""Helpers shared by the flight tests: bundled files, an independent gravity model, phase selection, file writing."""

from __future__ import annotations

import math
from pathlib import Path
from textwrap import dedent

import numpy as np

from washbench.flight.fly import FlightResult
from washbench.io.paths import MANOEUVRES_DIR

FT = 0.3048  # m per ft

#: Every bundled manoeuvre, of every aircraft (manoeuvres/<aircraft>/<name>.yaml).
BUNDLED = sorted(MANOEUVRES_DIR.glob("*/*.yaml"))


def manoeuvre_id(path: Path) -> str:
    """``folder/name`` of a bundled manoeuvre (the same name is flown by several aircraft)."""
    return f"{path.parent.name}/{path.stem}"


def normal_gravity(lat_deg: float, h_m: float) -> float:
    """WGS-84 normal gravity (Somigliana) with the free-air correction, m/s^2."""
    s2 = math.sin(math.radians(lat_deg)) ** 2
    g0 = 9.7803253359 * (1 + 0.00193185265241 * s2) / math.sqrt(1 - 0.00669437999013 * s2)
    return g0 - 3.086e-6 * h_m


def phase_mask(result: FlightResult, name: str, skip_s: float = 0.0) -> np.ndarray:
    """Samples of phase ``name`` (start and end included), after skipping its first ``skip_s`` seconds."""
    (t0, t1) = next((a, b) for n, a, b in result.phases if n == name)
    half = 0.5 * result.dt_s
    return (result.t_s >= t0 + skip_s - half) & (result.t_s <= t1 + half)


def write(tmp_path: Path, name: str, text: str) -> Path:
    """Write a (dedented) manoeuvre file into ``tmp_path``; return its path."""
    path = tmp_path / name
    path.write_text(dedent(text))
    return path


def short_rudder_doublet(name: str, free_s: float) -> str:
    """The bundled C172 rudder doublet shortened (settle 1 s, doublet 2.8 s, free oscillation ``free_s`` s), as the
    text of a manoeuvre file named ``name``."""
    return f"""\
name: {name}
description: the C172 rudder doublet, shortened (settle 1 s, doublet 2.8 s, free oscillation {free_s:g} s)
aircraft: c172p
start:
  air: {{altitude_ft: 4000, airspeed_kts: 95, heading_deg: 90}}
phases:
  - name: settle
    hold: {{wings_level: true, altitude_ft: 4000, airspeed_kts: 95}}
    until: {{duration_s: 1}}
  - name: doublet
    hold: {{altitude_ft: 4000, airspeed_kts: 95}}
    inputs:
      rudder: {{shape: doublet, amplitude_deg: 5, duration_s: 2.8, free: true}}
      aileron: {{free: true}}
    until: {{duration_s: 2.8}}
  - name: free oscillation
    hold: {{altitude_ft: 4000, airspeed_kts: 95}}
    inputs:
      rudder: {{free: true}}
      aileron: {{free: true}}
    until: {{duration_s: {free_s:g}}}
"""
