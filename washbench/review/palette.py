"""Fixed colours and line styles of the review figures (and the report's words for them).

Two palettes, chosen by name (``washbench report --palette``, or the ``WASHBENCH_PALETTE`` environment variable for
the figures ``run``, ``cue`` and ``suite`` draw):

- ``default``: the rerun recording's colours. The three bundled washouts are small-angle blue, large-angle
  orange, unrestricted green (matplotlib's tab10), the oracle bound grey (a reference, not a washout); other
  washout names (the adaptive, optimal and MPC washouts, plugins, variants) take further distinct colours in the
  order they are listed (:data:`EXTRA_COLORS`); the aircraft pilot, the reference every washout is compared with, is the
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
    "bound": (120, 120, 120),  # grey: the oracle bound is a reference, not a washout
}
EXTRA_COLORS: tuple[RGB, ...] = (
    (190, 30, 70),  # crimson
    (100, 200, 170),  # mint
    (188, 189, 34),  # olive
    (120, 70, 200),  # violet
    (200, 150, 80),  # tan
    (247, 129, 191),  # pink
    (23, 190, 207),  # cyan
)
"""Colours of further washouts, in the order they are listed: each chosen (greedily) as far as could be from the
fixed ones, the aircraft's and the ones before it (CIE76 colour difference at least 38 among the first five and the
fixed ones, :func:`colour_difference`), and of middle lightness so it shows on white paper and on the viewer's dark
background alike (the cyan close to small-angle's blue, and a gold close to large-angle's orange, came first before)."""
AIRCRAFT_COLOR: RGB = (200, 0, 160)  # magenta
THRESHOLD_COLOR: RGB = (184, 140, 46)  # sand
"""The perception thresholds' lines (the figures' not-felt band's edges, the recording's threshold lines): apart from
the bound's grey (CIE76 difference 55) and every bundled washout's colour, at least 3:1 (WCAG) against white and
the viewer's near-black alike."""

CB_WASHOUT_COLORS: dict[str, RGB] = {
    "small-angle": (0, 114, 178),  # blue
    "large-angle": (213, 94, 0),  # vermillion
    "unrestricted": (0, 158, 115),  # bluish green
    "bound": (120, 120, 120),  # grey
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
    "bound": (0, (2.0, 2.0)),  # short dash
}
EXTRA_DASHES: tuple[Dash, ...] = (
    (0, (1.2, 1.4)),  # dotted
    (0, (9.0, 2.5)),  # long dash
    (0, (3.0, 1.5, 1.0, 1.5, 1.0, 1.5)),  # dash-dot-dot
    (0, (7.0, 1.5, 2.0, 1.5)),  # long dash, short dash
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


def colour_difference(a: RGB, b: RGB) -> float:
    """CIE76 colour difference (Delta E*ab: the distance in CIE L*a*b*, D65 white) of two sRGB colours; about 2 is
    just noticeable, beyond 40 the two read as different colours at a glance."""

    def lab(rgb: RGB) -> tuple[float, float, float]:
        lin = [c / 255.0 for c in rgb]
        lin = [c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4 for c in lin]
        x = (0.4124 * lin[0] + 0.3576 * lin[1] + 0.1805 * lin[2]) / 0.95047
        y = 0.2126 * lin[0] + 0.7152 * lin[1] + 0.0722 * lin[2]
        z = (0.0193 * lin[0] + 0.1192 * lin[1] + 0.9505 * lin[2]) / 1.08883
        fx, fy, fz = (v ** (1.0 / 3.0) if v > 0.008856 else 7.787 * v + 16.0 / 116.0 for v in (x, y, z))
        return 116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)

    la, lb = lab(a), lab(b)
    return sum((p - q) ** 2 for p, q in zip(la, lb, strict=True)) ** 0.5


def mpl(rgb: RGB) -> tuple[float, float, float]:
    """An 8-bit RGB triple as matplotlib's 0-1 floats."""
    return (rgb[0] / 255.0, rgb[1] / 255.0, rgb[2] / 255.0)
