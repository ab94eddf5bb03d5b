"""Manoeuvre files: bundled files load, broken files give one clear line, the JSON Schema is usable."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import inprocess
import pytest
from flight_helpers import BUNDLED, manoeuvre_id

from washbench.errors import WashbenchError
from washbench.flight.json_schema import manoeuvre_json_schema
from washbench.flight.manoeuvre import Manoeuvre, load_manoeuvre
from washbench.io.paths import MANOEUVRES_DIR
from washbench.io.yamlio import read_yaml

BAD = Path(__file__).parent / "data" / "bad_manoeuvres"

#: file -> the error line after "washbench: error: FILE" (":LINE: field: problem" or ": problem").
EXPECTED = {
    "check_unknown_phase.yaml": ":15: checks[0].phases[0]: no phase named 'turnn'",
    "check_without_limit.yaml": ":15: checks[0]: give a 'min', a 'max' or both",
    "contradictory_lateral.yaml": (
        ":12: phases[1].hold.heading_deg: contradicts 'bank_deg' (one lateral target at a time)"
    ),
    "contradictory_pitch.yaml": ":12: phases[1].hold.altitude_ft: contradicts 'pitch_deg' (one pitch target at a time)",
    "duplicate_key.yaml": ":9: invalid YAML: duplicate key 'until' (first on line 8)",
    "duplicate_phase_name.yaml": ":9: phases[1].name: duplicate phase name 'level'",
    "empty.yaml": ": the file is empty",
    "missing_phase_end.yaml": ":9: phases[1].until: missing required field",
    "negative_duration.yaml": ":8: phases[0].until.duration_s: expected greater than 0, got -5",
    "never_ends_altitude_held.yaml": (
        ":8: phases[0].until.altitude_above_ft: the phase can never end: the altitude is held at 4000 ft"
    ),
    "never_ends_liftoff.yaml": (
        ":8: phases[0].until.event: the phase can never end: waits for lift-off but the aircraft is already flying"
    ),
    "never_ends_vne.yaml": (
        ":13: phases[1].until.airspeed_above_kts: the phase can never end: 300 kt is above c172p's VNE (158 kt)"
    ),
    "no_end_condition.yaml": ":13: phases[1].until: the phase can never end: give at least one end condition",
    "not_a_mapping.yaml": ":1: expected a mapping at the top level, got 'just a string'",
    "quoted_number.yaml": ":11: phases[1].hold.bank_deg: expected a number, got '30'",
    "runway_start_without_runway.yaml": ":4: start.runway: a runway start needs a top-level 'runway'",
    "start_below_stall.yaml": (":4: start.air.airspeed_kts: 30 kt is outside c172p's flight envelope (48..158 kt)"),
    "unknown_aircraft.yaml": ":2: aircraft: unknown aircraft 'c999x': no c999x/c999x.xml in the searched folders (",
    "unknown_key.yaml": ":11: phases[1].hold.bank_dge: unknown key (did you mean 'bank_deg'?)",
    "unknown_signal.yaml": (
        ":15: checks[0].signal: unknown signal 'bank' (a signal is a flight.parquet column, e.g. phi_deg)"
    ),
    "unreadable_yaml.yaml": ":8: invalid YAML: expected ',' or '}', but got ':'",
    "wrong_type.yaml": ":11: phases[1].hold.bank_deg: expected a number, got 'thirty'",
}


def cli(*args: str) -> subprocess.CompletedProcess[str]:
    return inprocess.washbench(*args, timeout=120)


def test_every_corpus_file_has_an_expected_message() -> None:
    assert sorted(p.name for p in BAD.glob("*.yaml")) == sorted(EXPECTED)


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_bad_file_gives_its_one_line_error(name: str) -> None:
    path = BAD / name
    with pytest.raises(WashbenchError) as info:
        load_manoeuvre(path)
    if name == "unknown_aircraft.yaml":  # the searched folders depend on the machine: tests/test_paths.py
        assert str(info.value).startswith(f"{path}{EXPECTED[name]}")
    else:
        assert str(info.value) == f"{path}{EXPECTED[name]}"


def test_validate_cli_reports_every_bad_file_on_one_line_each_and_exits_2() -> None:
    names = sorted(EXPECTED)
    out = cli("validate", *(str(BAD / n) for n in names))
    assert out.returncode == 2
    assert "Traceback" not in out.stderr
    lines = out.stderr.strip().splitlines()
    assert len(lines) == len(names)
    for line, n in zip(lines, names, strict=True):
        assert line.startswith(f"washbench: error: {BAD / n}{EXPECTED[n]}")
    assert out.stdout == ""


def test_validate_cli_mixed_good_and_bad() -> None:
    good = BUNDLED[0]
    out = cli("validate", str(good), str(BAD / "wrong_type.yaml"))
    assert out.returncode == 2
    assert out.stdout.strip() == f"{good}: OK"
    assert out.stderr.strip() == f"washbench: error: {BAD / 'wrong_type.yaml'}{EXPECTED['wrong_type.yaml']}"


@pytest.mark.parametrize("name", ["unknown_aircraft.yaml", "never_ends_liftoff.yaml", "unreadable_yaml.yaml"])
def test_fly_cli_rejects_bad_file_without_writing_anything(name: str, tmp_path: Path) -> None:
    out_dir = tmp_path / "out"
    out = cli("fly", str(BAD / name), "--out", str(out_dir))
    assert out.returncode == 2
    assert out.stderr.strip().startswith(f"washbench: error: {BAD / name}{EXPECTED[name]}")
    assert len(out.stderr.strip().splitlines()) == 1
    assert not out_dir.exists()


def test_missing_file_is_one_line(tmp_path: Path) -> None:
    out = cli("validate", str(tmp_path / "nope.yaml"))
    assert out.returncode == 2
    assert out.stderr.strip() == f"washbench: error: {tmp_path / 'nope.yaml'}: no such file"


@pytest.mark.parametrize("path", BUNDLED, ids=manoeuvre_id)
def test_bundled_manoeuvres_validate(path: Path) -> None:
    m = load_manoeuvre(path)
    assert m.name == path.stem
    assert m.aircraft == {"c172": "c172p", "columbia400": "columbia400"}[path.parent.name]


def test_validate_command_passes_every_bundled_manoeuvre() -> None:
    """One process for all of them (a process per file cost a second each)."""
    out = cli("validate", *map(str, BUNDLED))
    assert out.returncode == 0, out.stderr
    assert out.stdout.splitlines() == [f"{path}: OK" for path in BUNDLED]


def test_all_c172_manoeuvres_are_there() -> None:
    assert {p.stem for p in BUNDLED if p.parent.name == "c172"} >= {
        "coordinated_turn",
        "crosswind_landing",
        "takeoff",
        "spiral_dive",
        "stall_recovery",
        "elevator_doublet",
        "rudder_doublet",
        "aileron_3211",
        "steep_turn",
        "go_around",
    }


def _schema_accepts(schema: dict, node: dict, data: object, defs: dict) -> list[str]:
    """A small JSON Schema checker (types, required, additionalProperties, enums, refs, anyOf, bounds).

    Enough to show an editor using the schema would accept the bundled files and flag an unknown key.
    """
    if "$ref" in node:
        return _schema_accepts(schema, defs[node["$ref"].split("/")[-1]], data, defs)
    if "anyOf" in node:
        results = [_schema_accepts(schema, sub, data, defs) for sub in node["anyOf"]]
        return [] if any(not r for r in results) else results[0]
    errors: list[str] = []
    kind = node.get("type")
    types = {"object": dict, "array": list, "string": str, "boolean": bool, "null": type(None)}
    if kind == "number":
        if not isinstance(data, int | float) or isinstance(data, bool):
            return [f"{data!r} is not a number"]
    elif kind == "integer":
        if not isinstance(data, int) or isinstance(data, bool):
            return [f"{data!r} is not an integer"]
    elif kind in types and not isinstance(data, types[kind]):
        return [f"{data!r} is not {kind}"]
    if "enum" in node and data not in node["enum"]:
        errors.append(f"{data!r} not in {node['enum']}")
    if "const" in node and data != node["const"]:
        errors.append(f"{data!r} != {node['const']}")
    for key, test in (("minimum", float.__ge__), ("maximum", float.__le__)):
        if key in node and not test(float(data), float(node[key])):  # type: ignore[arg-type]
            errors.append(f"{data!r} violates {key}")
    if isinstance(data, dict):
        props = node.get("properties", {})
        errors += [f"missing {r}" for r in node.get("required", []) if r not in data]
        for k, v in data.items():
            if k not in props:
                if node.get("additionalProperties") is False:
                    errors.append(f"unknown key {k}")
                continue
            errors += _schema_accepts(schema, props[k], v, defs)
    if isinstance(data, list) and "items" in node:
        for item in data:
            errors += _schema_accepts(schema, node["items"], item, defs)
    return errors


def test_schema_command_prints_a_schema_that_accepts_the_bundled_files_and_flags_unknown_keys(tmp_path: Path) -> None:
    out = cli("schema")
    assert out.returncode == 0
    schema = json.loads(out.stdout)
    assert schema == json.loads(json.dumps(manoeuvre_json_schema()))
    assert schema["additionalProperties"] is False
    assert set(schema["required"]) == {"name", "aircraft", "start", "phases"}
    defs = schema["$defs"]
    for path in BUNDLED:
        data, _ = read_yaml(path)
        assert _schema_accepts(schema, schema, data, defs) == [], path
    bad, _ = read_yaml(BAD / "unknown_key.yaml")
    assert "unknown key bank_dge" in _schema_accepts(schema, schema, bad, defs)
    written = tmp_path / "schema.json"
    assert cli("schema", "--out", str(written)).returncode == 0
    assert json.loads(written.read_text()) == schema


def test_wind_is_from_direction_and_model_is_frozen() -> None:
    m = load_manoeuvre(MANOEUVRES_DIR / "c172" / "crosswind_landing.yaml")
    assert isinstance(m, Manoeuvre)
    assert m.environment.wind is not None and m.environment.wind.from_deg == 340.0
    with pytest.raises(Exception):  # noqa: B017 - pydantic raises its own ValidationError for frozen models
        m.name = "x"  # type: ignore[misc]


def test_no_turbulence_needs_no_seed(tmp_path: Path) -> None:
    """Issue 52, item 10: ``turbulence: {severity: none}`` was refused for a missing seed; any other severity still
    needs one (the same seed, the same gusts), said in one line with the file's line and field."""
    text = (MANOEUVRES_DIR / "c172" / "steep_turn.yaml").read_text()
    calm = tmp_path / "calm.yaml"
    calm.write_text(text + "environment:\n  turbulence: {severity: none}\n")
    assert load_manoeuvre(calm).environment.turbulence.seed is None
    gusty = tmp_path / "gusty.yaml"
    gusty.write_text(text + "environment:\n  turbulence: {severity: light}\n")
    line = len(text.splitlines()) + 2
    with pytest.raises(WashbenchError, match=rf"^{gusty}:{line}: environment\.turbulence\.seed: missing required field "
                       r"\(severity light needs a seed"):  # fmt: skip
        load_manoeuvre(gusty)
