"""JSBSim's own CSV output (``<output type="CSV">``) as a motion input: which columns hold what.

JSBSim writes ``Time`` and each ``<property>`` under its name (``accelerations/a-pilot-x-ft_sec2``, or
with the ``/fdm/jsbsim/`` prefix), and the ``<rates>`` group as ``P (deg/s)``, ``Q (deg/s)``, ``R (deg/s)``.
Its pilot accelerations lag the other columns by one frame (:func:`washbench.io.readers.shift_jsbsim_lag`).
"""

from __future__ import annotations

from washbench.io.input_format import ColumnSource

JSBSIM_F = tuple(f"accelerations/a-pilot-{a}-ft_sec2" for a in "xyz")
_JSBSIM_RATES = (
    (tuple(f"velocities/{r}-rad_sec" for r in "pqr"), "radps"),
    (("P (deg/s)", "Q (deg/s)", "R (deg/s)"), "degps"),
    (("P_{Body} (deg/s)", "Q_{Body} (deg/s)", "R_{Body} (deg/s)"), "degps"),
)


def _jsbsim_column(names: list[str], prop: str) -> str | None:
    """The header of property ``prop`` in a JSBSim CSV (written as given or with the ``/fdm/jsbsim/`` prefix)."""
    for n in (prop, f"/fdm/jsbsim/{prop}"):
        if n in names:
            return n
    return None


def is_jsbsim_header(names: list[str]) -> bool:
    return "Time" in names and all(_jsbsim_column(names, c) for c in JSBSIM_F)


def jsbsim_mapping(names: list[str]) -> dict[str, ColumnSource]:
    """JSBSim CSV output: ``Time`` [s], the pilot accelerations [ft/s^2] and the body rates."""
    out = {"t": ColumnSource("Time", "s")}
    for a, prop in zip("xyz", JSBSIM_F, strict=True):
        col = _jsbsim_column(names, prop)
        if col is not None:
            out[f"f_{a}"] = ColumnSource(col, "ftps2")
    for cols, unit in _JSBSIM_RATES:
        found = [_jsbsim_column(names, c) for c in cols]
        if all(found):
            out |= {f"omega_{a}": ColumnSource(str(c), unit) for a, c in zip("xyz", found, strict=True)}
            break
    return out
