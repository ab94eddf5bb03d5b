"""``washbench live`` and ``washbench send``: the pilot in the loop over UDP.

:mod:`~washbench.live.packets` (what each simulator sends, decoded into washbench units and axes, and encoded
again for ``washbench send``), :mod:`~washbench.live.link` (a real link's faults: loss, reordering, duplicates,
restarts; latency figures), :mod:`~washbench.live.commands` (the platform command packet sent out).
The commands themselves are in :mod:`washbench.runs.live` and :mod:`washbench.runs.send`.
"""

FORMATS = ("washbench", "xplane", "xplane-rref", "flightgear", "jsbsim")
"""The source formats of ``washbench live --format`` and ``washbench send --format`` (:mod:`washbench.live.packets`);
here, so the command line lists them without importing the codecs."""
