"""Issue 38, item 9: the figures as a new user reads them.

- the "not felt" band and the phase shading are told apart (they were the same grey);
- the band lies around the resting value the cue classification uses, not the first sample (a JSBSim script
  starts untrimmed: the band sat beside the curves);
- with seven and with ten washouts every washout has a colour of its own, far from the others (CIE76 colour
  difference, computed here from the CIE formulas);
- the suite report's sentence on ties agrees in number ("1 of 3 rankings is", "1 has").
"""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest

from washbench.analysis.cues import dof_thresholds
from washbench.flight.scripts import bundled_script
from washbench.review import figures
from washbench.review.palette import AIRCRAFT_COLOR, colour_difference, washout_colors
from washbench.review.report import perception_thresholds
from washbench.review.result_data import load_result
from washbench.review.suite_report import tie_counts
from washbench.runs.options import load_options
from washbench.runs.outputs import Outputs
from washbench.runs.pipeline import run_script

SEVEN = ["small-angle", "large-angle", "unrestricted", "adaptive-large-angle", "optimal", "mpc", "bound"]
TEN = ["small-angle", "large-angle", "unrestricted", "adaptive", "adaptive-large-angle", "adaptive-unrestricted",
       "optimal", "mpc", "bound", "first-order"]  # fmt: skip


def _lab(rgb: np.ndarray) -> np.ndarray:
    """sRGB (0-255) -> CIE L*a*b* (D65), as the CIE defines it."""
    c = np.asarray(rgb, dtype=float) / 255.0
    c = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
    m = np.array([[0.4124, 0.3576, 0.1805], [0.2126, 0.7152, 0.0722], [0.0193, 0.1192, 0.9505]])
    xyz = m @ c / np.array([0.95047, 1.0, 1.08883])
    f = np.where(xyz > (6 / 29) ** 3, np.cbrt(xyz), xyz / (3 * (6 / 29) ** 2) + 4 / 29)
    return np.array([116 * f[1] - 16, 500 * (f[0] - f[1]), 200 * (f[1] - f[2])])


def _delta_e(a: tuple[float, ...], b: tuple[float, ...]) -> float:
    return float(np.linalg.norm(_lab(np.array(a)) - _lab(np.array(b))))


def _on_white(rgba: tuple[float, ...]) -> tuple[float, ...]:
    r, g, b, a = rgba
    return tuple(255.0 * (a * v + (1.0 - a)) for v in (r, g, b))


def test_the_not_felt_band_and_the_phase_shading_are_told_apart() -> None:
    band, phase = _on_white(figures._THRESHOLD_FILL), _on_white(figures._PHASE_SHADE)
    assert _delta_e(band, phase) > 10.0  # (the same grey before: 1.8)
    assert _delta_e(band, (255.0, 255.0, 255.0)) > 5.0 and _delta_e(phase, (255.0, 255.0, 255.0)) > 5.0


@pytest.mark.parametrize(("names", "least"), [(SEVEN, 35.0), (TEN, 25.0)], ids=["seven", "ten"])
def test_every_washout_has_a_colour_far_from_the_others(names: list[str], least: float) -> None:
    colours = {"aircraft": AIRCRAFT_COLOR, **washout_colors(names)}
    pairs = [(_delta_e(a, b), x, y) for (x, a), (y, b) in itertools.combinations(colours.items(), 2)]
    worst = min(pairs)
    assert worst[0] >= least, worst
    for d, x, y in pairs:  # the palette's own measure is the CIE76 difference
        assert colour_difference(colours[x], colours[y]) == pytest.approx(d, rel=1e-6, abs=1e-6)


def test_the_band_lies_where_the_cue_classification_puts_rest(tmp_path: Path) -> None:
    """JSBSim's c1723 starts untrimmed (perceived heave -10.2 m/s^2 at the first sample, not -g)."""
    opts = load_options(max_time_s=60.0, outputs=Outputs(recording=False, figures=False))
    (summary,) = run_script(bundled_script("c1723"), tmp_path, opts)
    data = load_result(summary.run_dir)
    thresholds, rest = perception_thresholds(data)
    assert (thresholds, rest) == tuple(tuple(v) for v in dof_thresholds())
    heave = data.perceived["aircraft"][:, 2]
    assert abs(heave[0] - rest[2]) > thresholds[2]  # the first sample lies outside the band
    assert abs(np.median(heave) - rest[2]) < thresholds[2]  # where the curve runs, the band is


def test_the_tie_sentence_reads_right_for_every_count() -> None:
    """No count to agree with a verb ("1 of 3 rankings are decided", "1 have a tie" before): counts of manoeuvres."""
    assert tie_counts(1, 3, 1) == ("First place shared (decided by less than that margin): 1 of 3 manoeuvres; a tie "
                                   "at some rank: 1 of 3.")  # fmt: skip
    assert "2 of 3 manoeuvres" in tie_counts(2, 3, 0) and "some rank: 0 of 3" in tie_counts(2, 3, 0)
