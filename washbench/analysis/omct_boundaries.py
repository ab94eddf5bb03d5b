"""The model of OMCT boundary files (``washbench omct --boundaries FILE``): gain and phase bounds per test.

Read by :func:`washbench.runs.omct.load_boundaries`; checked point by point by
:func:`washbench.analysis.omct.check_bounds`.

Format (YAML; every list of one test has one entry per frequency; any of the four bound lists may be left out,
leaving that side unbounded)::

    name: my simulator's acceptance boundaries     # label for the report
    source: where the numbers come from            # cited in the report
    tests:
      pitch_to_pitch:                              # a test name of washbench.analysis.omct.TEST_NAMES
        frequency_radps: [0.1, 1.0, 10.0]          # ascending, > 0
        gain_min: [0.2, 0.5, 0.5]                  # absolute gain, > 0
        gain_max: [1.0, 1.1, 1.3]
        phase_min_deg: [-20.0, -30.0, -60.0]       # degrees, continuous along frequency (as plotted)
        phase_max_deg: [90.0, 40.0, 20.0]

Between listed frequencies a bound is a straight line on the Bode plot (linear in log frequency, and in log
gain for the gain bounds); outside the listed range the test is not bounded. No boundary file is bundled: the
ICAO 9625 Attachment F boundaries are not reproduced in this project.
"""

from __future__ import annotations

import itertools
from typing import Annotated

from pydantic import Field, field_validator, model_validator

from washbench.analysis.omct import TEST_NAMES, Bounds
from washbench.io.yamlio import StrictModel

_DOF_AXES = {"surge": "f_x", "sway": "f_y", "heave": "f_z"}
PositiveFloat = Annotated[float, Field(gt=0.0, allow_inf_nan=False)]
FiniteFloat = Annotated[float, Field(allow_inf_nan=False)]


class TestBoundary(StrictModel):
    """The bounds of one test (lists in the order of ``frequency_radps``)."""

    frequency_radps: tuple[PositiveFloat, ...] = Field(min_length=1)
    gain_min: tuple[PositiveFloat, ...] | None = None
    gain_max: tuple[PositiveFloat, ...] | None = None
    phase_min_deg: tuple[FiniteFloat, ...] | None = None
    phase_max_deg: tuple[FiniteFloat, ...] | None = None

    @model_validator(mode="after")
    def _consistent(self) -> TestBoundary:
        f = self.frequency_radps
        if any(b <= a for a, b in itertools.pairwise(f)):
            raise ValueError("frequency_radps must be strictly ascending")
        lists = {k: getattr(self, k) for k in ("gain_min", "gain_max", "phase_min_deg", "phase_max_deg")}
        if all(v is None for v in lists.values()):
            raise ValueError("give at least one of gain_min, gain_max, phase_min_deg, phase_max_deg")
        for key, values in lists.items():
            if values is not None and len(values) != len(f):
                raise ValueError(f"{key} has {len(values)} entries, frequency_radps has {len(f)}")
        for lo, hi in (("gain_min", "gain_max"), ("phase_min_deg", "phase_max_deg")):
            a, b = lists[lo], lists[hi]
            if a is not None and b is not None:
                for i, (x, y) in enumerate(zip(a, b, strict=True)):
                    if x > y:
                        raise ValueError(f"{lo}[{i}] = {x} is above {hi}[{i}] = {y}")
        return self

    def bounds(self) -> Bounds:
        """As the analysis' :class:`washbench.analysis.omct.Bounds`."""
        return Bounds(
            frequency_radps=self.frequency_radps,
            gain_min=self.gain_min,
            gain_max=self.gain_max,
            phase_min_deg=self.phase_min_deg,
            phase_max_deg=self.phase_max_deg,
        )


class BoundaryFile(StrictModel):
    """A whole boundary file: a name, the source of its numbers, bounds per test."""

    name: str
    source: str
    tests: dict[str, TestBoundary] = Field(min_length=1)

    @field_validator("tests")
    @classmethod
    def _known_tests(cls, tests: dict[str, TestBoundary]) -> dict[str, TestBoundary]:
        """Test names as :data:`TEST_NAMES` spell them; the metrics' names surge, sway, heave are accepted for f_x,
        f_y, f_z (``surge_to_pitch`` is ``f_x_to_pitch``)."""
        out: dict[str, TestBoundary] = {}
        for name, tb in tests.items():
            parts = name.split("_to_")
            canonical = "_to_".join(_DOF_AXES.get(p, p) for p in parts) if len(parts) == 2 else name
            if canonical not in TEST_NAMES:
                raise ValueError(
                    f"unknown test {name!r} (valid: {', '.join(TEST_NAMES)}; surge, sway, heave name f_x, f_y, f_z)"
                )
            if canonical in out:
                raise ValueError(f"test {canonical!r} is given twice (as {name!r})")
            out[canonical] = tb
        return out

    def bounds(self) -> dict[str, Bounds]:
        """test name -> bounds."""
        return {name: tb.bounds() for name, tb in self.tests.items()}
