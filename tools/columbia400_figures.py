"""Measure the Columbia-400-like model (and c172p, to check the harness) and rewrite the README table.

    .venv/bin/python tools/columbia400_figures.py

Flies real JSBSim with :mod:`washbench.flight.airdata` and replaces the text between the markers
``<!-- figures:begin -->`` and ``<!-- figures:end -->`` in ``aircraft/columbia400/README.md``.
The tolerances are the ones tests/test_columbia400.py asserts.
"""

from __future__ import annotations

from washbench.errors import WashbenchError
from washbench.flight import airdata
from washbench.io.atomic import write_text_atomic
from washbench.io.paths import AIRCRAFT_DIR

BEGIN, END = "<!-- figures:begin -->", "<!-- figures:end -->"
MAX_WEIGHT = airdata.Loading(3600.0, 3)
MID_CRUISE = airdata.Loading(3420.0, 1)
C172_MAX = airdata.Loading(2400.0, 3)


def rows() -> list[tuple[str, str, str, str, str]]:
    """(figure, model, published, tolerance, source) for every checked figure."""
    c4 = "columbia400"
    trim = airdata.level_trim(c4, 8000.0, 155.0, loading=MAX_WEIGHT)
    doublet = airdata.doublet_damping(c4, 150.0, loading=MAX_WEIGHT)
    c172_doublet = airdata.doublet_damping("c172p", 100.0, loading=C172_MAX)
    vmax, _ = airdata.level_speed(c4, 25000.0, loading=MID_CRUISE, start_kcas=150.0)
    return [
        (
            "Stall, flaps 40 deg, 3,600 lb (KCAS, 1 g)",
            f"{airdata.stall_speed(c4, loading=MAX_WEIGHT, start_kcas=80.0, flaps_norm=1.0):.1f}",
            "59 KIAS",
            "+-5 %",
            "manufacturer's published figure",
        ),
        (
            "Stall, flaps up, 3,600 lb (KCAS, 1 g)",
            f"{airdata.stall_speed(c4, loading=MAX_WEIGHT, start_kcas=90.0):.1f}",
            "about 69 KIAS",
            "+-5 %",
            "estimated (brief; CLmax 1.58)",
        ),
        (
            "Level speed, 25,000 ft, full throttle, 2,600 rpm, 3,420 lb (KTAS)",
            f"{vmax:.1f}",
            "about 235 KTAS",
            "+-4 %",
            "manufacturer's published figure",
        ),
        (
            "Climb at Vy 110 KCAS, sea level, 3,600 lb, full power (ft/min)",
            f"{airdata.climb_rate(c4, 110.0, loading=MAX_WEIGHT):.0f}",
            "about 1,400",
            "+-10 %",
            "manufacturer's published figure",
        ),
        (
            "Roll rate, full aileron, 130 KCAS (deg/s)",
            f"{airdata.roll_rate(c4, 130.0, loading=MAX_WEIGHT):.0f}",
            "60-90",
            "range",
            "typical light single",
        ),
        (
            "Cruise 8,000 ft, 155 KCAS: throttle / elevator / alpha",
            f"{trim.throttle_norm:.2f} / {trim.elevator_norm:+.2f} / {trim.alpha_deg:.1f} deg",
            "-",
            "throttle 0.5-1, abs(elevator) < 0.3",
            "flying-start trim",
        ),
        (
            "Elevator doublet, 150 KCAS: damping ratio / frequency",
            f"{doublet.damping_ratio:.2f} / {doublet.natural_frequency_rad_s:.1f} rad/s",
            "0.35-1.0",
            "range",
            "MIL-F-8785C level 1 short period (0.3-2.0)",
        ),
        (
            "Harness check: c172p stall flaps up, 2,400 lb (KCAS)",
            f"{airdata.stall_speed('c172p', loading=C172_MAX, start_kcas=70.0):.1f}",
            "about 48 KIAS",
            "+-15 %",
            "Cessna 172P POH",
        ),
        (
            "Harness check: c172p climb at 74 KCAS, sea level, 2,400 lb (ft/min)",
            f"{airdata.climb_rate('c172p', 74.0, loading=C172_MAX):.0f}",
            "700",
            "not asserted",
            "Cessna 172P POH (JSBSim's c172p out-climbs it)",
        ),
        (
            "Harness check: c172p roll rate 100 KCAS (deg/s) / doublet damping",
            f"{airdata.roll_rate('c172p', 100.0, loading=C172_MAX):.0f} / {c172_doublet.damping_ratio:.2f}",
            "45-90 / 0.35-1.0",
            "range",
            "typical light single",
        ),
    ]


def table(data: list[tuple[str, str, str, str, str]]) -> str:
    lines = ["| Figure | Model | Published | Test tolerance | Source |", "|---|---|---|---|---|"]
    lines += [f"| {a} | {b} | {c} | {d} | {e} |" for a, b, c, d, e in data]
    return "\n".join(lines)


def main() -> None:
    readme = AIRCRAFT_DIR / "columbia400" / "README.md"
    text = readme.read_text(encoding="utf-8")
    if BEGIN not in text or END not in text:
        raise WashbenchError(f"{readme}: markers {BEGIN} / {END} not found")
    head, rest = text.split(BEGIN, 1)
    _, tail = rest.split(END, 1)
    body = table(rows())
    write_text_atomic(readme, f"{head}{BEGIN}\n{body}\n{END}{tail}")
    print(body)


if __name__ == "__main__":
    main()
