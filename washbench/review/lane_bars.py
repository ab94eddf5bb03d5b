"""The bars of the recording's state lanes (a washout's false cues, the limits it is held at), and the short words on
them.

A lane drawn one bar per change of its state (sway, then sway+heave, then heave, ...) broke into bars a few pixels
wide whose words the viewer cut to "sw", "sur" (it clips a bar's text to the bar). A bar here is a stretch: the
samples where the lane's state is not empty, stretches less than :data:`washbench.analysis.cues.MERGE_GAP_S` apart
joined (the rule that joins a DOF's false-cue events), named by everything the state held inside it, in short words
(:data:`DOF_CODES`) that a view's title explains. When exactly which DOF or limit held is in the events table and the
panels.
"""

from __future__ import annotations

import numpy as np

from washbench.analysis.cues import MERGE_GAP_S

__all__ = ["DOF_CODES", "bars", "code_text"]

DOF_CODES: dict[str, str] = {"surge": "Su", "sway": "Sw", "heave": "He", "roll": "Ro", "pitch": "Pi", "yaw": "Ya"}
"""The short word of each DOF on a false-cue bar (two letters: "Su Sw Ro" fits a bar of about 60 px)."""


def bars(mask: np.ndarray, dt_s: float, gap_s: float = MERGE_GAP_S) -> list[tuple[int, int, int]]:
    """The bars of a lane whose state at each sample is the bit mask ``mask`` (N,) (0: nothing): (first sample, last
    sample, the union of the masks between them) of each stretch of non-zero samples, stretches separated by more
    than ``gap_s`` (in whole samples of ``dt_s``, as :func:`washbench.analysis.cues.false_events`) apart, in order."""
    m = np.asarray(mask, dtype=np.int64)
    idx = np.flatnonzero(m)
    if idx.size == 0:
        return []
    gap = max(1, round(gap_s / dt_s)) if dt_s > 0 else 1
    breaks = np.flatnonzero(np.diff(idx) > gap)
    starts = np.concatenate([[idx[0]], idx[breaks + 1]])
    ends = np.concatenate([idx[breaks], [idx[-1]]])
    return [(int(s), int(e), int(np.bitwise_or.reduce(m[s : e + 1]))) for s, e in zip(starts, ends, strict=True)]


def code_text(mask: int, words: list[str], sep: str) -> str:
    """The words of the bits set in ``mask`` (bit j: ``words[j]``), joined by ``sep``."""
    return sep.join(w for j, w in enumerate(words) if mask >> j & 1)
