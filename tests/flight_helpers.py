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
