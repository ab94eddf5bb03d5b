"""Per-result figures: line styles and palettes, the reused layout, phase labels (synthetic traces, no flight)."""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest

from washbench.errors import WashbenchError
from washbench.review.figures import PlacedLabel, envelope_figure, perceived_figure, phase_label, place_phase_labels
from washbench.review.palette import (
    CB_WASHOUT_COLORS,
    PALETTES,
    WASHOUT_COLORS,
    palette_name,
    washout_colors,
    washout_dashes,
)

NAMES = ["small-angle", "large-angle", "unrestricted", "my-a", "my-b"]


def traces(n: int, seed: int) -> dict[str, np.ndarray]:
    rng = np.random.default_rng(seed)
    base = np.cumsum(rng.normal(size=(n, 6)), axis=0) * 0.01
    return {"aircraft": base, **{w: base + 0.1 * i for i, w in enumerate(NAMES[:3])}}


def draw(folder: Path, seed: int, n: int = 5000, washouts: tuple[str, ...] = tuple(NAMES[:3])) -> bytes:
    t = np.arange(n) / 120.0
    perceived = {k: v for k, v in traces(n, seed).items() if k == "aircraft" or k in washouts}
    phases = [("level", 0.0, 10.0), ("roll in", 10.0, 20.0), ("clean climb", 20.0, t[-1])]
    (png,) = perceived_figure(folder / "perceived", "test", t, perceived, phases=phases, thresholds=[0.1] * 6,
                              rest=list(perceived["aircraft"][0]))  # fmt: skip
    usage = {"position": {w: np.abs(perceived[w][:, 0]) for w in washouts}}
    saturated = {washouts[0]: {"pos": np.arange(n) % 500 < 3}}
    (env,) = envelope_figure(folder / "envelope", "test", t, usage, saturated, phases=phases)
    return png.read_bytes() + env.read_bytes()


def test_a_reused_layout_draws_the_same_pixels_as_a_fresh_one(tmp_path: Path) -> None:
    """The second figure of a process reuses the first one's axes; the third (the first's data again) must match
    the first byte for byte, so nothing of the second leaks into it."""
    first = draw(tmp_path, seed=1)
    other = draw(tmp_path, seed=2, n=3000)
    again = draw(tmp_path, seed=1)
    assert first == again
    assert other != first


def test_a_reused_layout_changes_its_legend_with_the_washouts(tmp_path: Path) -> None:
    """The legend stays on a reused layout only while its entries are the same: other washouts give the pixels a
    fresh layout gives them, and the first washouts again their first pixels."""
    from washbench.review import figures

    three, two = tuple(NAMES[:3]), ("large-angle", "unrestricted")
    first = draw(tmp_path, seed=1, washouts=three)
    other = draw(tmp_path, seed=1, washouts=two)
    again = draw(tmp_path, seed=1, washouts=three)
    figures._LAYOUT_CACHE.clear()
    fresh = draw(tmp_path, seed=1, washouts=two)
    assert first == again and other == fresh and other != first


def test_a_reused_envelope_layout_refitted_to_other_lanes_draws_a_fresh_ones_pixels(tmp_path: Path) -> None:
    """The envelope figure's height and left margin follow its limit lanes; a worker's layout is refitted to them.
    Each figure, drawn after one with other lanes (more, fewer, none, other labels), has the bytes of the same
    figure drawn on a fresh layout."""
    from washbench.review import figures

    n = 4000
    t = np.arange(n) / 120.0
    base = np.abs(traces(n, 3)["aircraft"])
    panels = ["position", "velocity", "acceleration", "sphere rate", "sphere ang. acc.", "wheel speed"]
    usage = {label: {w: base[:, i] * (1 + 0.2 * j) for j, w in enumerate(NAMES[:3])} for i, label in enumerate(panels)}
    pulse = np.arange(n) % 700 < 40
    lanes = [
        {},  # "no limit reached"
        {w: {"acc": pulse, "angacc": ~pulse, "tilt_rate": pulse} for w in NAMES[:3]},
        {NAMES[1]: {"rot_rate": pulse}},
    ]

    def envelope(saturated: dict[str, dict[str, np.ndarray]], name: str) -> bytes:
        (png,) = envelope_figure(tmp_path / name, "test", t, usage, saturated, phases=[("all", 0.0, t[-1])])
        return png.read_bytes()

    fresh = []
    for i, saturated in enumerate(lanes):
        figures._LAYOUT_CACHE.clear()
        fresh.append(envelope(saturated, f"fresh{i}"))
    assert len(set(fresh)) == len(lanes)
    figures._LAYOUT_CACHE.clear()
    for i in [1, 0, 2, 0]:  # nine lanes, none (the axes' view must be a fresh one's), one, none
        assert envelope(lanes[i], f"reused{i}") == fresh[i], i


def test_every_washout_has_its_own_colour_and_line_style_in_each_palette() -> None:
    for pal in PALETTES:
        colors = washout_colors(NAMES, pal)
        assert len(set(colors.values())) == len(NAMES)
    dashes = washout_dashes(NAMES)
    assert len({str(d) for d in dashes.values()}) == len(NAMES)
    assert washout_colors(NAMES)["large-angle"] == WASHOUT_COLORS["large-angle"]
    assert washout_colors(NAMES, "colorblind")["large-angle"] == CB_WASHOUT_COLORS["large-angle"]


def test_palette_from_the_environment_and_unknown_names(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("WASHBENCH_PALETTE", "colorblind")
    assert palette_name() == "colorblind" and palette_name("default") == "default"
    monkeypatch.setenv("WASHBENCH_PALETTE", "pastel")
    with pytest.raises(WashbenchError, match="WASHBENCH_PALETTE"):
        palette_name()


@pytest.mark.parametrize(
    ("name", "width_in", "expected"),
    [
        ("clean climb", 2.0, "clean climb"),
        ("clean climb", 0.35, "clean\nclimb"),
        ("approach", 0.3, "appr…"),
        ("approach", 0.1, ""),
    ],
)
def test_phase_labels_wrap_before_they_are_cut(name: str, width_in: float, expected: str) -> None:
    assert phase_label(name, width_in) == expected


def test_phase_names_too_long_for_their_box_are_staggered_whole() -> None:
    """The C172 take-off's phases on a 7.5-inch lane (what its figure has): 'rotate' (2.5 s) and 'initial climb'
    (4.3 s) do not fit their boxes; both are written whole, in different halves, and no two names on one half of
    the lane overlap (widths from the same mean character width the layout uses)."""
    ends = [("run up", 0.0, 4.0), ("roll", 4.0, 17.2), ("rotate", 17.2, 19.7), ("initial climb", 19.7, 24.0),
            ("climb", 24.0, 68.9), ("level off", 68.9, 88.9)]  # fmt: skip
    scale = 7.5 / 88.9
    boxes = [(n, a * scale, b * scale) for n, a, b in ends]
    placed = place_phase_labels(boxes, 7.5)
    assert [p.text.replace("\n", " ") for p in placed] == [n for n, _, _ in ends]  # every name, whole, in order
    rows = {p.text: p.row for p in placed}
    assert rows["rotate"] in (1, 2) and rows["initial climb"] in (1, 2) and rows["rotate"] != rows["initial climb"]
    char_in = 7.5 * 0.56 / 72.0

    def span(p: PlacedLabel) -> tuple[float, float]:
        half = 0.5 * max(map(len, p.text.split("\n"))) * char_in
        return p.x_in - half, p.x_in + half

    for half in (1, 2):
        mine = sorted(span(p) for p in placed if p.row in (0, half))
        assert all(a[1] <= b[0] for a, b in itertools.pairwise(mine)), mine
        assert all(lo >= 0.0 and hi <= 7.5 for lo, hi in mine)
    one_box = place_phase_labels([("a very long phase name indeed", 0.0, 0.3)], 0.3)
    assert one_box == [] or one_box[0].row == 0  # no room anywhere: shortened to its box (here dropped)


def test_swept_keys_carry_the_unit_of_their_name() -> None:
    from washbench.review.study_figures import key_label

    assert key_label("translational_highpass_wn_radps.x") == "translational_highpass_wn_radps.x (rad/s)"
    assert key_label("tilt.gain_per_s") == "tilt.gain_per_s (1/s)"
    assert key_label("rotational.saturation_degps") == "rotational.saturation_degps (deg/s)"
    assert key_label("scale.specific_force") == "scale.specific_force (-)"
    assert key_label("tilt.rate_limit_mode") == "tilt.rate_limit_mode"


def test_the_report_names_an_end_stop_next_to_the_score_it_dominates() -> None:
    from washbench.review.report import END_STOP_SHARE, end_stop_note
    from washbench.review.result_data import ResultData

    n = 1000
    pos = np.zeros(n, bool)
    pos[:540] = True
    below = np.arange(n) < END_STOP_SHARE * n - 1
    data = ResultData(folder=Path("."), title="t", washouts=["a", "b", "c"], metrics=[], t_s=np.arange(n) / 100.0,
                      dt_s=0.01, perceived={}, usage={}, motion={},
                      saturated={"a": {"pos": pos}, "b": {"pos": below}, "c": {}})  # fmt: skip
    note = end_stop_note(data, "a")
    assert note == "end stop: stage at its position limit for 5.40 s (54 %), the score reflects its hard stops"
    assert end_stop_note(data, "b") == "" and end_stop_note(data, "c") == ""


@pytest.mark.parametrize("alpha", [255, 128])
def test_png_bytes_decode_to_the_pixels_given(alpha: int) -> None:
    """The figures' PNG writer read back by Pillow (an independent decoder): same pixels, the resolution, RGB when
    every pixel is opaque, RGBA otherwise."""
    import io

    from PIL import Image

    from washbench.review.png import png_bytes

    rgba = np.random.default_rng(3).integers(0, 256, size=(37, 53, 4), dtype=np.uint8)
    rgba[:, :, 3] = 255
    rgba[5, 7, 3] = alpha
    image = Image.open(io.BytesIO(png_bytes(rgba, 110.0)))
    assert image.mode == ("RGB" if alpha == 255 else "RGBA")
    assert image.info["dpi"] == pytest.approx((110.0, 110.0), abs=0.01)
    back = np.asarray(image.convert("RGBA"))
    assert np.array_equal(back, rgba)


@pytest.mark.parametrize("with_nan", [False, True])
def test_minmax_decimation_is_each_buckets_first_minimum_and_maximum_in_time_order(with_nan: bool) -> None:
    """Against a plain loop over the buckets (ties on purpose: the first of equal values is kept), finite traces
    (the fast path) and traces with NaNs (kept out of the min/max) alike."""
    from washbench.review.figures import minmax_decimate

    rng = np.random.default_rng(7)
    for _ in range(60):
        n, buckets = int(rng.integers(3, 3000)), int(rng.integers(1, 400))
        t = np.cumsum(rng.random(n))
        y = rng.integers(-3, 4, n).astype(float)
        if with_nan:
            y[rng.random(n) < 0.2] = np.nan
        tt, yy = minmax_decimate(t, y, buckets)
        if n <= 2 * buckets:
            assert tt is t and yy is y
            continue
        size = -(-n // buckets)
        exp_t, exp_y = [], []
        for a in range(0, n, size):
            chunk = y[a : a + size]
            finite = [i for i in range(len(chunk)) if not np.isnan(chunk[i])]
            if not finite:  # a bucket of NaNs stays NaN
                exp_t += [t[a], t[a]]
                exp_y += [np.nan, np.nan]
                continue
            lo = min(finite, key=lambda i: (chunk[i], i))
            hi = min(finite, key=lambda i: (-chunk[i], i))
            for i in sorted((lo, hi)):
                exp_t.append(t[a + i])
                exp_y.append(chunk[i])
        assert np.array_equal(tt, exp_t)
        assert np.array_equal(yy, exp_y, equal_nan=True)


def _cells_figure(folder: Path, name: str, one_artist: bool, constrained: bool) -> list[Path]:
    """A heatmap with text in every cell (numbers, signs, a dash, a warning sign, bold ones, an empty one), drawn with
    one matplotlib Text per cell or with one CellTexts, PNG and PDF."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.font_manager import FontProperties

    from washbench.review.cell_text import CellTexts
    from washbench.review.figures import save_figure

    rng = np.random.default_rng(11)
    values = np.round(rng.standard_normal((9, 7)) * 300.0)
    fig = Figure(figsize=(6.3, 4.1), layout="constrained" if constrained else None)
    FigureCanvasAgg(fig)
    ax = fig.subplots()
    ax.imshow(values, cmap="RdYlGn", aspect="auto")
    ax.set_yticks(range(9), [f"row {r}" for r in range(9)])
    normal, bold = FontProperties(size=6.5), FontProperties(size=8, weight="bold")
    cells, texts, fonts = [], [], []
    for r, c in itertools.product(range(9), range(7)):
        v = values[r, c]
        text = "" if (r, c) == (4, 4) else "-" if (r, c) == (2, 3) else f"{v:+.0f}" + (" ⚠" if v > 250 else "")
        cells.append((c, r))
        texts.append(text)
        fonts.append(bold if (r + c) % 5 == 0 else normal)
    if one_artist:
        ax.add_artist(CellTexts(cells, texts, fonts))
    else:
        for (c, r), text, font in zip(cells, texts, fonts, strict=True):
            ax.text(c, r, text, ha="center", va="center", fontproperties=font, clip_on=False, in_layout=False)
    return save_figure(fig, folder / name, ("png", "pdf"))


@pytest.mark.parametrize("constrained", [False, True])
def test_cell_texts_draw_the_bytes_matplotlib_texts_draw(tmp_path: Path, constrained: bool) -> None:
    """The one-artist cell texts (Table 4's 792 numbers, the score heatmap's) give the same PNG and PDF bytes as one
    matplotlib Text per cell, centred, unclipped, outside the layout; with fixed margins and the constrained
    layout."""
    texts = _cells_figure(tmp_path, "texts", one_artist=False, constrained=constrained)
    cells = _cells_figure(tmp_path, "cells", one_artist=True, constrained=constrained)
    for a, b in zip(texts, cells, strict=True):
        assert a.read_bytes() == b.read_bytes(), b.name


def test_cell_texts_refuse_what_they_do_not_draw_as_a_text_would() -> None:
    from matplotlib.font_manager import FontProperties

    from washbench.review.cell_text import CellTexts

    font = FontProperties(size=8)
    with pytest.raises(ValueError, match="plain one-line"):
        CellTexts([(0, 0)], ["$x$"], font)
    with pytest.raises(ValueError, match="plain one-line"):
        CellTexts([(0, 0)], ["a\nb"], font)
    with pytest.raises(ValueError, match="2 points for 1 texts"):
        CellTexts([(0, 0), (1, 0)], ["a"], font)
    with pytest.raises(ValueError, match="1 fonts for 2 texts"):
        CellTexts([(0, 0), (1, 0)], ["a", "b"], [font])
