"""Fixed colours of the review (figures and report), the same as the rerun recording's.

The three bundled washouts keep their colours everywhere (small-angle blue, large-angle orange, unrestricted
green: matplotlib's tab10) and other washout names (user-named variants) take further distinct colours in the order
they are listed, as in the rerun recording; the aircraft pilot, the reference every washout is compared with, is
the recording's strong magenta, readable on white and on dark backgrounds and distinct from every washout colour.
"""

from __future__ import annotations

from collections.abc import Sequence

RGB = tuple[int, int, int]

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


def washout_colors(washouts: Sequence[str]) -> dict[str, RGB]:
    """Colour of each washout: the fixed colour of a bundled name, else the next spare colour (cycling)."""
    out: dict[str, RGB] = {}
    spare = 0
    for w in washouts:
        if w in WASHOUT_COLORS:
            out[w] = WASHOUT_COLORS[w]
        elif w not in out:
            out[w] = EXTRA_COLORS[spare % len(EXTRA_COLORS)]
            spare += 1
    return out


def mpl(rgb: RGB) -> tuple[float, float, float]:
    """An 8-bit RGB triple as matplotlib's 0-1 floats."""
    return (rgb[0] / 255.0, rgb[1] / 255.0, rgb[2] / 255.0)
