"""A table's cell texts drawn by one matplotlib artist: one short line of text centred on each of many points.

matplotlib's ``ax.text`` makes an artist per text, and each builds its font, its transforms and its layout again:
Table 4's 792 cell texts took 0.2 s of its 0.6 s when drawn again, 0.4 s of 0.85 s when drawn first (issue 21).
:class:`CellTexts` draws the same glyphs at the same pixels (``tests/test_figures.py`` compares the PNG and PDF
bytes with ``ax.text(x, y, s, ha="center", va="center", clip_on=False)``) by doing what ``Text.draw`` does for one
unrotated line centred on its anchor (matplotlib 3.10, ``text.py``: ``Text._get_layout`` and ``Text.draw``):

* the line's width ``w``, height ``h`` and descent ``d`` from the renderer, ``h`` and ``d`` at least those of
  ``"lp"`` (the font's full height);
* the box from ``ymin = -(h - d) - d`` to 0 and from 0 to ``w``, its centre put on the anchor (in display units):
  the line's origin at ``(-w / 2, -(h - d) - ymin / 2)`` from the anchor's display position;
* ``renderer.draw_text`` with a graphics context as ``Text.draw`` sets it (colour, antialiasing from
  ``text.antialiased``, no clip).

Only plain text (no ``$`` mathtext, no TeX, no rotation, no wrap): what a table's numbers need.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from matplotlib import rcParams
from matplotlib.artist import Artist


class CellTexts(Artist):
    """Texts ``texts[i]`` centred on ``xy[i]`` (data coordinates of the axes the artist is added to), drawn in that
    order, in a font (a ``matplotlib.font_manager.FontProperties``, or one per text) and a colour; outside the layout
    engine and never clipped."""

    zorder = 3  # as a Text

    def __init__(self, xy: Any, texts: Sequence[str], fontproperties: Any, color: Any = "black") -> None:
        super().__init__()
        self._xy = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
        self._texts = [str(t) for t in texts]
        if len(self._texts) != self._xy.shape[0]:
            raise ValueError(f"CellTexts: {self._xy.shape[0]} points for {len(self._texts)} texts")
        if any("$" in t or "\n" in t for t in self._texts):
            raise ValueError("CellTexts draws plain one-line texts (no $ mathtext, no line breaks)")
        each = fontproperties if isinstance(fontproperties, (list, tuple)) else [fontproperties] * len(self._texts)
        if len(each) != len(self._texts):
            raise ValueError(f"CellTexts: {len(each)} fonts for {len(self._texts)} texts")
        distinct: dict[int, Any] = {}
        self._fonts = [distinct.setdefault(id(f), f.copy()) for f in each]
        self._color = color
        self.set_in_layout(False)

    def draw(self, renderer: Any) -> None:
        """Draw every text (``Text.draw`` for each, module docstring)."""
        if not self.get_visible():
            return
        lp: dict[int, tuple[float, float, float]] = {}  # per font
        metrics: dict[tuple[int, str], tuple[float, float, float]] = {}
        anchors = self.get_transform().transform(self._xy)
        _, canvas_h = renderer.get_canvas_width_height()
        flip = renderer.flipy()
        gc = renderer.new_gc()
        gc.set_foreground(self._color)
        gc.set_alpha(self.get_alpha())
        gc.set_antialiased(rcParams["text.antialiased"])
        gc.set_clip_rectangle(None)
        gc.set_clip_path(None)
        for (px, py), text, font in zip(anchors, self._texts, self._fonts, strict=True):
            if not text or not (np.isfinite(px) and np.isfinite(py)):
                continue
            key = (id(font), text)
            if key not in metrics:
                metrics[key] = renderer.get_text_width_height_descent(text, font, ismath=False)
            if id(font) not in lp:
                lp[id(font)] = renderer.get_text_width_height_descent("lp", font, ismath=False)
            (w, h, d), (_, lp_h, lp_d) = metrics[key], lp[id(font)]
            h, d = max(h, lp_h), max(d, lp_d)
            top = -(h - d)  # the line's baseline below the box's top
            ymin = top - d
            x = (0.0 - (0.0 + w) / 2) + px
            y = (top - (ymin + 0.0) / 2) + py
            if flip:
                y = canvas_h - y
            renderer.draw_text(gc, x, y, text, font, 0.0, ismath=False, mtext=None)
        gc.restore()
        self.stale = False
