"""X-Plane's Data Output file (``Data.txt``): which columns hold the pilot's motion, and their signs.

X-Plane writes one line per frame, fields separated by ``|`` and padded with spaces, with headers of
the form ``name,unit`` padded with underscores (``_real,_time``, ``Gload,norml``, ``____P,rad/s``). The
rows needed are "Times" (index 1), "G-loads" (in "Mach, VVI, g-load", index 4) and "Angular velocities"
(index 16); tick them in X-Plane's Data Output screen ("disk (data.txt file)").

Conversion to washbench's frame (body x forward, y right, z down, specific force f = a - g):

- time: ``_real,_time`` (s since X-Plane started; ``_totl,_time`` if there is no real time);
- specific force: ``f_x = +axial``, ``f_y = +side``, ``f_z = -normal``, each times 9.80665 m/s^2. X-Plane's
  normal g-load is +1 in level flight (positive up, out of the seat), so its sign flips; the axial and
  side loads are taken as positive forward and right (a seat pushing the pilot forward or to the right).
  That convention was not checked against X-Plane itself here: if your recording shows f_x < 0 during a
  take-off run, override it with ``--columns`` (e.g. an input-format file ``f_x: "-Gload,axial:g"``);
- angular velocity: ``P``, ``Q``, ``R`` (roll, pitch, yaw rates, body axes, positive right wing down,
  nose up, nose right), in the unit the header names (``rad/s`` in X-Plane 10 and later, ``deg/s``
  before).
"""

from __future__ import annotations

from washbench.io.input_format import ColumnSource

_TIME = ("real,time", "totl,time")


def normalise(name: str) -> str:
    """A header name without padding underscores and spaces, lower case: ``'____P,rad/s'`` -> ``'p,rad/s'``."""
    parts = [p.strip().strip("_").strip().lower() for p in name.split(",")]
    return ",".join(parts)


def is_xplane_header(names: list[str], delimiter: str) -> bool:
    """True for a Data.txt header: pipe-separated with a ``_real,_time`` or ``_totl,_time`` column."""
    return delimiter == "|" and any(normalise(n) in _TIME for n in names)


def default_mapping(names: list[str]) -> dict[str, ColumnSource]:
    """The mapping of a Data.txt header (fields whose columns are absent are left out)."""
    by = {normalise(n): n for n in names}
    out: dict[str, ColumnSource] = {}
    for key in _TIME:
        if key in by:
            out["t"] = ColumnSource(by[key], "s")
            break
    for fname, key, sign in (("f_x", "gload,axial", 1.0), ("f_y", "gload,side", 1.0), ("f_z", "gload,norml", -1.0)):
        if key in by:
            out[fname] = ColumnSource(by[key], "g", sign)
    for fname, letter in (("omega_x", "p"), ("omega_y", "q"), ("omega_z", "r")):
        for unit in ("rad/s", "deg/s"):
            if f"{letter},{unit}" in by:
                out[fname] = ColumnSource(by[f"{letter},{unit}"], unit.replace("/s", "ps"))
                break
    return out
