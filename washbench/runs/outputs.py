"""Which optional files a result folder gets: the one switch passed from the command line to every run."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Outputs:
    """The optional parts of a result folder (everything else is always written).

    ``recording``: ``recording.rrd`` (rerun; its writer and rerun itself are not even imported without it);
    ``figures``: the report's PNG figures under ``figures/`` (matplotlib is not imported without them; the report
    then says so, and ``washbench report`` on the folder draws them later from its files).
    """

    recording: bool = True
    figures: bool = True


DEFAULT_OUTPUTS = Outputs()
