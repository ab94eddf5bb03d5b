"""Input shapes as pure functions, oscillation and heading statistics, and the errors of open-loop inputs."""

from __future__ import annotations

import itertools
import json
import math
from pathlib import Path

import inprocess
import numpy as np
import pytest
import scipy.signal
from flight_helpers import write

from washbench.errors import WashbenchError
from washbench.flight.checks import evaluate, measure, oscillation
from washbench.flight.inputs import surface_deg, surface_norm, unit_shape
from washbench.flight.json_schema import manoeuvre_json_schema
from washbench.flight.manoeuvre import load_manoeuvre
from washbench.flight.manoeuvre_schema import Check

DT = 1.0 / 120.0


def shape(name: str, n: np.ndarray, **kw: float | str) -> np.ndarray:
    return np.array([unit_shape(name, k * DT, **kw) for k in n])  # type: ignore[arg-type]


def test_shapes_against_their_definitions() -> None:
    n = np.arange(1200)
    t = n * DT
    np.testing.assert_array_equal(shape("step", n, start_s=1.0), (n >= 120) * 1.0)
    np.testing.assert_array_equal(shape("pulse", n, start_s=1.0, duration_s=0.5), ((n >= 120) & (n < 180)) * 1.0)
    want = np.select([(n >= 60) & (n < 120), (n >= 120) & (n < 180)], [1.0, -1.0], 0.0)
    np.testing.assert_array_equal(shape("doublet", n, start_s=0.5, duration_s=1.0), want)
    u = 24  # 0.2 s units of a 1.4 s 3211 from 0.5 s
    edges = 60 + u * np.array([0, 3, 5, 6, 7])
    want = np.select([(n >= a) & (n < b) for a, b in itertools.pairwise(edges)], [1, -1, 1, -1], 0)
    np.testing.assert_array_equal(shape("3211", n, start_s=0.5, duration_s=1.4), want)
    np.testing.assert_allclose(shape("sine", n, start_s=0.0, period_s=0.8), np.sin(2 * np.pi * t / 0.8), atol=1e-12)
    for sweep in ("linear", "logarithmic"):
        got = shape("chirp", n, start_s=0.0, duration_s=10.0, start_hz=0.1, end_hz=3.0, sweep=sweep)
        ref = scipy.signal.chirp(t, 0.1, 10.0, 3.0, method=sweep, phi=-90)
        np.testing.assert_allclose(got, ref, atol=1e-9)


def test_surface_map_is_the_zero_centred_aerosurface_scale_and_its_inverse() -> None:
    u = np.linspace(-1, 1, 41)
    deg = np.array([surface_deg(x, -28.0, 23.0) for x in u])
    np.testing.assert_allclose(deg, np.interp(u, [-1, 0, 1], [-28, 0, 23]))
    np.testing.assert_allclose([surface_norm(d, -28.0, 23.0) for d in deg], u, atol=1e-15)
    assert surface_norm(40.0, -28.0, 23.0) == 1.0 and surface_deg(1.5, -28.0, 23.0) == 23.0


@pytest.mark.parametrize(("zeta", "wn"), [(0.05, 2.0), (0.19, 2.33), (0.35, 6.0)])
def test_oscillation_statistics_of_a_damped_sinusoid(zeta: float, wn: float) -> None:
    """x = A exp(-zeta wn t) sin(wd t) on a slowly drifting mean: period 2 pi / wd, the damping ratio, and the
    largest half peak-to-peak swing."""
    wd = wn * math.sqrt(1 - zeta**2)
    t = np.arange(round(30.0 / DT)) * DT
    x = 5.0 * np.exp(-zeta * wn * t) * np.sin(wd * t) + 1.0 + 0.02 * t
    osc = oscillation(x, DT)
    assert osc.period_s == pytest.approx(2 * math.pi / wd, rel=0.01)
    assert osc.damping_ratio == pytest.approx(zeta, abs=0.01)
    # extrema at tan(wd t) = wd / (zeta wn), where |sin(wd t)| = sqrt(1 - zeta^2): the first swing spans two
    t1 = np.arctan(wd / (zeta * wn)) / wd
    first = 5.0 * math.sqrt(1 - zeta**2) * (np.exp(-zeta * wn * t1) + np.exp(-zeta * wn * (t1 + np.pi / wd))) / 2
    assert osc.amplitude == pytest.approx(first, rel=0.02)


def test_oscillation_of_a_growing_or_absent_oscillation() -> None:
    t = np.arange(2400) * DT
    assert oscillation(np.exp(0.05 * t) * np.sin(3 * t), DT).damping_ratio < 0
    flat = oscillation(np.full(100, 2.0), DT)
    assert math.isnan(flat.period_s) and math.isnan(flat.damping_ratio)


def _columns(psi: np.ndarray) -> dict[str, np.ndarray]:
    return {"t_s": np.arange(psi.size) * DT, "psi_deg": psi % 360.0}


@pytest.mark.parametrize(
    ("stat", "want"), [("final", 10.0), ("initial", 350.0), ("min", 350.0), ("max", 10.0), ("mean", 0.0)]
)
def test_heading_statistics_do_not_break_at_north(stat: str, want: float) -> None:
    cols = _columns(np.linspace(350.0, 370.0, 201))  # recorded as 350..359.9, 0..10
    check = Check(name="h", signal="psi_deg", stat=stat, min=355.0, max=5.0)
    got = measure(check, cols, [], {}, DT)
    assert min(abs(got - want), 360 - abs(got - want)) < 1e-9
    dev = measure(Check(name="d", signal="psi_deg", stat="max_deviation", max=30.0), cols, [], {}, DT)
    assert dev == pytest.approx(20.0)


def test_heading_limits_are_an_arc_through_north() -> None:
    cols = _columns(np.linspace(350.0, 362.0, 50))  # ends on 2 deg
    passes = [r.passed for r in evaluate([
        Check(name="a", signal="psi_deg", stat="final", min=357.0, max=3.0),
        Check(name="b", signal="psi_deg", stat="final", min=3.0, max=357.0),
        Check(name="c", signal="psi_deg", stat="final", min=0.0, max=2.5),
    ], cols, [], {}, DT)]  # fmt: skip
    assert passes == [True, False, True]


BASE = """\
    name: bad
    aircraft: c172p
    start:
      air: {altitude_ft: 4000, airspeed_kts: 95, heading_deg: 90}
    phases:
      - name: kick
        hold: HOLD
        inputs:
          INPUT
        until: {duration_s: 10}
    checks:
      - {name: c, signal: phi_deg, stat: max_abs, max: LIMIT}
"""


def bad(tmp_path: Path, input_text: str, hold: str = "{altitude_ft: 4000}", limit: str = "10") -> str:
    text = BASE.replace("INPUT", input_text).replace("HOLD", hold).replace("LIMIT", limit)
    path = write(tmp_path, "bad.yaml", text)
    with pytest.raises(WashbenchError) as err:
        load_manoeuvre(path)
    return str(err.value)


@pytest.mark.parametrize(
    ("input_text", "hold", "message"),
    [
        (
            "rudder: {shape: doublet, amplitude_deg: 5}",
            None,
            ":9: phases[0].inputs.rudder.shape: a doublet needs 'duration_s'",
        ),
        (
            "rudder: {shape: doublet, amplitude_deg: 5, duration_s: 2, period_s: 1}",
            None,
            ":9: phases[0].inputs.rudder.period_s: not used by a doublet",
        ),
        ("rudder: {shape: pulse, duration_s: 1}", None, "phases[0].inputs.rudder.shape: a pulse needs an amplitude"),
        (
            "rudder: {shape: pulse, amplitude_deg: 1, amplitude_norm: 0.1, duration_s: 1}",
            None,
            "inputs.rudder.amplitude_deg: give either amplitude_norm or amplitude_deg",
        ),
        (
            "throttle: {shape: step, amplitude_deg: 1}",
            None,
            "inputs.throttle.amplitude_deg: the throttle has no surface",
        ),
        (
            "aileron: {free: true}",
            "{bank_deg: 20}",
            "inputs.aileron: the aileron is released, which contradicts 'hold.bank_deg'",
        ),
        ("throttle: {fixed_norm: 1.5}", None, "inputs.throttle.fixed_norm: outside the command range 0..1"),
        ("elevator: {fixed_deg: 40}", None, "inputs.elevator.fixed_deg: outside the surface travel"),
        (
            "aileron: {shape: sine, amplitude_norm: 0.1, period_s: 1, start_s: 5, duration_s: 6}",
            None,
            "inputs.aileron.start_s: the sine runs to 11 s, past the phase's duration_s of 10 s",
        ),
        ("aileron: {amplitude_norm: 0.1}", None, "inputs.aileron.amplitude_norm: an amplitude needs a 'shape'"),
        ("rudder: {shape: wobble, amplitude_norm: 0.1}", None, "inputs.rudder.shape:"),
        ("rudder: {}", None, "inputs.rudder: does nothing"),
        (
            "properties: [{property: fcs/rudder-cmd-norm, fixed: 0.1}]",
            None,
            "inputs.properties[0].property: 'fcs/rudder-cmd-norm' is written by the pilot: use the axis keys",
        ),
    ],
)
def test_bad_inputs_are_one_line_with_file_line_and_field(
    tmp_path: Path, input_text: str, hold: str | None, message: str
) -> None:
    text = bad(tmp_path, input_text, hold or "{altitude_ft: 4000}")
    assert message in text and "\n" not in text
    assert text.startswith(str(tmp_path / "bad.yaml"))


def test_unknown_jsbsim_property_is_refused_at_start_up_by_the_cli(tmp_path: Path) -> None:
    typo = "properties: [{property: fcs/speedbrak-cmd-norm, shape: step, amplitude: 1}]"
    path = write(tmp_path, "bad.yaml", BASE.replace("INPUT", typo).replace("HOLD", "{}").replace("LIMIT", "10"))
    out = inprocess.washbench("fly", path, "--out", tmp_path / "o", timeout=120)
    assert out.returncode == 2 and "Traceback" not in out.stderr
    assert out.stderr.strip() == (
        f"washbench: error: {path}:9: phases[0].inputs.properties[0].property: unknown JSBSim property "
        "'fcs/speedbrak-cmd-norm' (not in the c172p model)"
    )
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("limit", [".nan", ".inf", "-.inf"])
def test_check_limits_refuse_nan_and_infinity(tmp_path: Path, limit: str) -> None:
    text = bad(tmp_path, "aileron: {free: true}", limit=limit)
    assert ":12: checks[0].max:" in text


def test_a_heading_check_may_span_north_but_other_limits_may_not(tmp_path: Path) -> None:
    base = BASE.replace("INPUT", "aileron: {free: true}").replace("HOLD", "{altitude_ft: 4000}")
    good = base.replace("{name: c, signal: phi_deg, stat: max_abs, max: LIMIT}",
                        "{name: c, signal: psi_deg, stat: final, min: 350, max: 10}")  # fmt: skip
    load_manoeuvre(write(tmp_path, "good.yaml", good))
    with pytest.raises(WashbenchError, match="greater than max"):
        load_manoeuvre(write(tmp_path, "b.yaml", good.replace("psi_deg", "phi_deg")))


def _properties(schema: dict) -> list[tuple[str, dict]]:
    """(model.key, key schema) of the top level and of every model in $defs."""
    out = [(f"Manoeuvre.{k}", v) for k, v in schema["properties"].items()]
    for name, model in schema["$defs"].items():
        out += [(f"{name}.{k}", v) for k, v in model.get("properties", {}).items()]
    return out


def test_every_schema_key_has_a_plain_description() -> None:
    """Editor hover text: every key of every object described, without reStructuredText markup."""
    schema = manoeuvre_json_schema()
    props = list(_properties(schema))
    assert len(props) > 100
    missing = [p for p, sub in props if not sub.get("description")]
    assert not missing, missing
    text = json.dumps(schema)
    assert "``" not in text and ":func:" not in text and ":class:" not in text
    assert "ControlInput" in schema["$defs"] and "chirp" in json.dumps(schema["$defs"]["ControlInput"])


@pytest.mark.parametrize("aircraft", ["c172p", "columbia400"])
def test_profile_surface_travel_is_the_models(aircraft: str) -> None:
    """The profile's surface travel (used for inputs in degrees) is what the model's flight-control system gives
    at command -1 and +1 (JSBSim runs its FCS at run_ic), to 1e-3 deg."""
    import os

    import jsbsim

    from washbench.flight.manoeuvre import aircraft_path, pilot_profile_path
    from washbench.flight.profile import load_profile
    from washbench.io.paths import jsbsim_root

    os.environ["JSBSIM_DEBUG"] = "0"
    surfaces = load_profile(pilot_profile_path(aircraft)).surfaces
    assert surfaces is not None
    fdm = jsbsim.FGFDMExec(str(jsbsim_root()), None)
    fdm.set_aircraft_path(str(aircraft_path(aircraft)))
    fdm.load_model(aircraft)
    for axis in ("elevator", "aileron", "rudder"):
        surface = getattr(surfaces, axis)
        for u, want in ((-1.0, surface.min_deg), (1.0, surface.max_deg)):
            fdm[f"fcs/{axis}-cmd-norm"] = u
            fdm.run_ic()
            assert fdm[surface.property] == pytest.approx(want, abs=1e-3), (axis, u)
        fdm[f"fcs/{axis}-cmd-norm"] = 0.0


def test_an_unquoted_3211_is_the_3211_shape(tmp_path: Path) -> None:
    text = BASE.replace("INPUT", "aileron: {shape: 3211, amplitude_norm: 0.1, duration_s: 2.1, free: true}")
    m = load_manoeuvre(write(tmp_path, "m.yaml", text.replace("HOLD", "{altitude_ft: 4000}").replace("LIMIT", "10")))
    inputs = m.phases[0].inputs
    assert inputs is not None and inputs.aileron is not None and inputs.aileron.shape == "3211"
