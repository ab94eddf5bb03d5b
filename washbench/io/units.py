"""Units and axes of recorded motion: the one conversion table every reader uses.

Inside washbench a motion trace is time in s, specific force in m/s^2 and angular velocity in deg/s
(the ``washbench cue`` file convention; :class:`washbench.io.motion.Motion` turns the rates into rad/s),
body axes x forward, y right, z down. A recording made another way names its units per column
(``--columns t=Time:ms,f_x=ax:g,...``) and its sensor axes (``--axes flu``); :func:`unit_factor` and
:func:`axes_matrix` give the conversions.

Units (case-insensitive, aliases in parentheses):

- time: ``s``, ``ms``, ``us`` (``µs``), ``ns``, ``min``; ``timestamp``: a date-time column (Parquet
  timestamp or ISO 8601 text), measured from its first sample;
- specific force: ``mps2`` (``m/s^2``, ``m/s2``), ``ftps2`` (``ft/s^2``, ``ft/s2``), ``g`` (9.80665 m/s^2,
  standard gravity);
- angular velocity: ``degps`` (``deg/s``), ``radps`` (``rad/s``).

Axes: three letters naming the body directions of the sensor's x, y and z axes: ``f``/``b`` forward/back,
``r``/``l`` right/left, ``d``/``u`` down/up. ``frd`` is washbench's own frame; ``flu`` is a z-up, y-left
sensor (x forward); ``rfu`` an east-north-up style mount with x to the right. Left-handed sets are
refused (an angular velocity has no meaning in them).
"""

from __future__ import annotations

import math

import numpy as np

G0_MPS2 = 9.80665
"""Standard gravity [m/s^2]: the value of one ``g``."""

FT_M = 0.3048

TIME, FORCE, RATE = "time", "specific force", "angular velocity"

_UNITS: dict[str, dict[str, float]] = {
    TIME: {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9, "min": 60.0, "timestamp": 1.0},
    FORCE: {"mps2": 1.0, "ftps2": FT_M, "g": G0_MPS2},
    RATE: {"degps": 1.0, "radps": 180.0 / math.pi},
}
_ALIASES = {
    "sec": "s",
    "µs": "us",
    "m/s^2": "mps2",
    "m/s2": "mps2",
    "m/s/s": "mps2",
    "ft/s^2": "ftps2",
    "ft/s2": "ftps2",
    "ft_sec2": "ftps2",
    "deg/s": "degps",
    "deg/sec": "degps",
    "rad/s": "radps",
    "rad/sec": "radps",
    "rad_sec": "radps",
}

CANONICAL_UNIT = {TIME: "s", FORCE: "mps2", RATE: "degps"}


def normalise_unit(unit: str) -> str:
    """The canonical spelling of ``unit`` (lower case, aliases resolved); unknown units are returned as given."""
    u = unit.strip().lower()
    return _ALIASES.get(u, u)


def units_of(quantity: str) -> tuple[str, ...]:
    """The unit names accepted for ``quantity`` (``TIME``, ``FORCE`` or ``RATE``)."""
    return tuple(_UNITS[quantity])


def unit_factor(quantity: str, unit: str) -> float:
    """Factor that turns a value in ``unit`` into the canonical unit of ``quantity`` (s, m/s^2, deg/s).

    Raises ValueError naming the accepted units for an unknown one.
    """
    u = normalise_unit(unit)
    table = _UNITS[quantity]
    if u not in table:
        raise ValueError(f"unknown {quantity} unit {unit!r} (valid: {', '.join(table)})")
    return table[u]


_DIRECTIONS = {"f": (0, 1.0), "b": (0, -1.0), "r": (1, 1.0), "l": (1, -1.0), "d": (2, 1.0), "u": (2, -1.0)}


def axes_matrix(spec: str) -> np.ndarray:
    """3x3 matrix M with ``v_body = M @ v_sensor`` for the sensor axes ``spec`` (e.g. ``"flu"``).

    Raises ValueError for a malformed or left-handed set.
    """
    s = spec.strip().lower()
    if len(s) != 3 or any(c not in _DIRECTIONS for c in s):
        raise ValueError(
            f"axes {spec!r}: expected three letters from f/b (forward/back), r/l (right/left), d/u (down/up), "
            "one per sensor axis x, y, z, e.g. 'frd' (washbench's own) or 'flu' (z up, y left)"
        )
    m = np.zeros((3, 3))
    for col, c in enumerate(s):
        row, sign = _DIRECTIONS[c]
        if np.any(m[row] != 0.0):
            raise ValueError(f"axes {spec!r}: two sensor axes point along the same body axis")
        m[row, col] = sign
    if np.linalg.det(m) < 0.0:
        raise ValueError(f"axes {spec!r} form a left-handed set: angular velocity is undefined in it")
    return m


def is_identity_axes(spec: str) -> bool:
    """True for washbench's own axes (``frd``)."""
    return spec.strip().lower() == "frd"
