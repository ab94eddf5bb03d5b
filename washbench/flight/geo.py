"""Flat-earth local coordinates around a reference point, and the runway frame.

Good to well under a metre over the few kilometres a manoeuvre covers. North/east in
metres from the reference latitude/longitude (WGS-84 radii of curvature at the reference
latitude). Runway frame: x along the centreline past the threshold, y to the right of it.
The fly loop converts each sample to north/east and the runway frame inline (per-step hot
path), from the radii held here.
"""

from __future__ import annotations

import math

_A = 6378137.0  # WGS-84 semi-major axis, m
_E2 = 6.69437999014e-3  # WGS-84 first eccentricity squared

DEFAULT_LATITUDE_DEG = 45.3225  # near Ottawa (Carleton University's Atlas simulator), when nothing is given
DEFAULT_LONGITUDE_DEG = -75.6692


class LocalFrame:
    """North/east metres about (lat0, lon0): ``north = (lat - lat0) * m_per_rad_lat``, likewise east."""

    def __init__(self, lat0_deg: float, lon0_deg: float) -> None:
        self.lat0 = math.radians(lat0_deg)
        self.lon0 = math.radians(lon0_deg)
        s = math.sin(self.lat0)
        w = math.sqrt(1.0 - _E2 * s * s)
        self.m_per_rad_lat = _A * (1.0 - _E2) / (w * w * w)  # meridional radius
        self.m_per_rad_lon = _A / w * math.cos(self.lat0)  # prime-vertical radius times cos(lat)

    def to_latlon_deg(self, north_m: float, east_m: float) -> tuple[float, float]:
        """(lat_deg, lon_deg) of a local point."""
        return (
            math.degrees(self.lat0 + north_m / self.m_per_rad_lat),
            math.degrees(self.lon0 + east_m / self.m_per_rad_lon),
        )


def wrap_pi(angle_rad: float) -> float:
    """Angle wrapped to [-pi, pi)."""
    return (angle_rad + math.pi) % (2.0 * math.pi) - math.pi
