"""Imported by the suite's process server, besides :mod:`washbench.runs.preload`, when the runs draw figures.

matplotlib's Agg canvas is loaded and the perceived-motion figure laid out and drawn once
(:func:`washbench.review.figures.warm_up`), so each worker forked afterwards draws its first figure into a layout
already built, with the fonts loaded. Nothing here starts a thread, so forking stays safe.
"""

from __future__ import annotations

from washbench.review.figures import warm_up

warm_up()
