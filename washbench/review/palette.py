"""Fixed colours and line styles of the review figures (and the report's words for them).

Two palettes, chosen by name (``washbench report --palette``, or the ``WASHBENCH_PALETTE`` environment variable for
the figures ``run``, ``cue`` and ``suite`` draw):

- ``default``: the rerun recording's colours. The three bundled washouts are small-angle blue, large-angle
  orange, unrestricted green (matplotlib's tab10); other washout names (user-named variants) take further distinct
  colours in the order they are listed; the aircraft pilot, the reference every washout is compared with, is the
  recording's strong magenta.
- ``colorblind``: Okabe & Ito's eight colours (Okabe and Ito 2008, "Color Universal Design"), distinguishable
  with the common colour-vision deficiencies: small-angle blue, large-angle vermillion, unrestricted bluish green,
  then sky blue, orange, reddish purple, yellow; the aircraft pilot black.

In both, each washout also has its own line style (small-angle solid, large-angle dashed, unrestricted dash-dot,
further names dotted and other dash patterns), so traces that lie on each other stay distinguishable and the figure
reads in grey print; the aircraft pilot is solid and drawn wider.
"""

from __future__ import annotations

import os
from collections.abc import Sequence

from washbench.errors import WashbenchError

RGB = tuple[int, int, int]
Dash = tuple[float, tuple[float, ...] | None]
"""A matplotlib line style: (offset, on-off sequence in points), ``(0, None)`` for solid."""

WASHOUT_COLORS: dict[str, RGB] = {
    "small-angle": (31, 119, 180),  # blue
    "large-angle": (255, 127, 14),  # orange
    "unrestricted": (44, 160, 44),  # green
}
EXTRA_COLORS: tuple[RGB, ...] = (
    (23, 190, 207),  # cyan
    (140, 86, 75),  # brown
    (188, 189, 34),  # olive
    (255, 200, 0),  # gold
    (40, 60, 140),  # navy
)
AIRCRAFT_COLOR: RGB = (200, 0, 160)  # magenta

CB_WASHOUT_COLORS: dict[str, RGB] = {
    "small-angle": (0, 114, 178),  # blue
    "large-angle": (213, 94, 0),  # vermillion
    "unrestricted": (0, 158, 115),  # bluish green
}
CB_EXTRA_COLORS: tuple[RGB, ...] = (
    (86, 180, 233),  # sky blue
    (230, 159, 0),  # orange
    (204, 121, 167),  # reddish purple
    (240, 228, 66),  # yellow
)
CB_AIRCRAFT_COLOR: RGB = (0, 0, 0)  # black

PALETTES = ("default", "colorblind")
PALETTE_ENV = "WASHBENCH_PALETTE"

WASHOUT_DASHES: dict[str, Dash] = {
    "small-angle": (0, None),  # solid
    "large-angle": (0, (5.0, 2.0)),  # dashed
    "unrestricted": (0, (6.0, 1.6, 1.2, 1.6)),  # dash-dot
}
EXTRA_DASHES: tuple[Dash, ...] = (
    (0, (1.2, 1.4)),  # dotted
    (0, (9.0, 2.5)),  # long dash
    (0, (3.0, 1.5, 1.0, 1.5, 1.0, 1.5)),  # dash-dot-dot
    (0, (2.0, 2.0)),  # short dash
)
AIRCRAFT_DASH: Dash = (0, None)


def palette_name(name: str | None = None) -> str:
    """The palette to draw with: ``name`` if given, else ``$WASHBENCH_PALETTE``, else ``default``.

    Raises :class:`washbench.errors.WashbenchError` (a ValueError's one-line message) naming the choices for an
    unknown name.
    """

    chosen = name or os.environ.get(PALETTE_ENV, "").strip() or "default"
    if chosen not in PALETTES:
        source = "" if name else f" (from ${PALETTE_ENV})"
        raise WashbenchError(f"unknown palette {chosen!r}{source}: choose {' or '.join(PALETTES)}")
    return chosen


def aircraft_color(palette: str = "default") -> RGB:
    """The aircraft pilot's colour in ``palette``."""
    return CB_AIRCRAFT_COLOR if palette == "colorblind" else AIRCRAFT_COLOR


def washout_colors(washouts: Sequence[str], palette: str = "default") -> dict[str, RGB]:
    """Colour of each washout: the fixed colour of a bundled name, else the next spare colour (cycling)."""
    fixed, extra = (CB_WASHOUT_COLORS, CB_EXTRA_COLORS) if palette == "colorblind" else (WASHOUT_COLORS, EXTRA_COLORS)
    out: dict[str, RGB] = {}
    spare = 0
    for w in washouts:
        if w in fixed:
            out[w] = fixed[w]
        elif w not in out:
            out[w] = extra[spare % len(extra)]
            spare += 1
    return out


def washout_dashes(washouts: Sequence[str]) -> dict[str, Dash]:
    """Line style of each washout: the fixed style of a bundled name, else the next spare style (cycling)."""
    out: dict[str, Dash] = {}
    spare = 0
    for w in washouts:
        if w in WASHOUT_DASHES:
            out[w] = WASHOUT_DASHES[w]
        elif w not in out:
            out[w] = EXTRA_DASHES[spare % len(EXTRA_DASHES)]
            spare += 1
    return out


def mpl(rgb: RGB) -> tuple[float, float, float]:
    """An 8-bit RGB triple as matplotlib's 0-1 floats."""
    return (rgb[0] / 255.0, rgb[1] / 255.0, rgb[2] / 255.0)
