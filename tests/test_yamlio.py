"""YAML loading: typed models, one-line errors naming file, line and field."""

from pathlib import Path
from typing import Literal

import pytest

from washbench.errors import WashbenchError
from washbench.io.yamlio import StrictModel, load_yaml_model


class Hold(StrictModel):
    bank_deg: float | None = None
    heading_deg: float | None = None


class Phase(StrictModel):
    name: str
    hold: Hold
    until: Literal["time", "touchdown"] = "time"


class Doc(StrictModel):
    aircraft: str
    gain: tuple[float, float] = (1.0, 2.0)
    phases: list[Phase]


def load(tmp_path: Path, text: str) -> Doc:
    f = tmp_path / "m.yaml"
    f.write_text(text)
    return load_yaml_model(f, Doc)


def error(tmp_path: Path, text: str) -> str:
    with pytest.raises(WashbenchError) as info:
        load(tmp_path, text)
    msg = str(info.value)
    assert "\n" not in msg
    return msg.replace(str(tmp_path / "m.yaml"), "m.yaml")


GOOD = """\
aircraft: c172p
gain: [3, 4.5]
phases:
  - name: roll in
    hold:
      bank_deg: 30
  - name: level
    hold:
      heading_deg: 90
    until: touchdown
"""


def test_good_file_loads_with_list_to_tuple_and_int_to_float(tmp_path: Path) -> None:
    doc = load(tmp_path, GOOD)
    assert doc.gain == (3.0, 4.5)
    assert doc.phases[1].until == "touchdown"
    assert doc.phases[0].hold.bank_deg == 30.0


def test_wrong_type_names_line_and_field(tmp_path: Path) -> None:
    msg = error(tmp_path, GOOD.replace("bank_deg: 30", "bank_deg: thirty"))
    assert msg == "m.yaml:6: phases[0].hold.bank_deg: expected a number, got 'thirty'"


def test_quoted_number_is_not_a_number(tmp_path: Path) -> None:
    msg = error(tmp_path, GOOD.replace("bank_deg: 30", 'bank_deg: "30"'))
    assert msg == "m.yaml:6: phases[0].hold.bank_deg: expected a number, got '30'"


def test_unknown_key_suggests_the_close_one(tmp_path: Path) -> None:
    msg = error(tmp_path, GOOD.replace("heading_deg: 90", "headng_deg: 90"))
    assert msg == "m.yaml:9: phases[1].hold.headng_deg: unknown key (did you mean 'heading_deg'?)"


def test_missing_field(tmp_path: Path) -> None:
    msg = error(tmp_path, GOOD.replace("aircraft: c172p\n", ""))
    assert msg.endswith("aircraft: missing required field")


def test_bad_literal(tmp_path: Path) -> None:
    msg = error(tmp_path, GOOD.replace("until: touchdown", "until: liftof"))
    assert msg.startswith("m.yaml:10: phases[1].until: expected 'time' or 'touchdown'")


def test_malformed_yaml_names_line(tmp_path: Path) -> None:
    msg = error(tmp_path, "aircraft: c172p\nphases: [\n  - : :\n")
    assert msg.startswith("m.yaml:") and "invalid YAML" in msg


def test_duplicate_key(tmp_path: Path) -> None:
    msg = error(tmp_path, "aircraft: c172p\naircraft: c182\nphases: []\n")
    assert msg == "m.yaml:2: invalid YAML: duplicate key 'aircraft' (first on line 1)"


def test_empty_and_missing_files(tmp_path: Path) -> None:
    assert error(tmp_path, "").endswith("m.yaml: the file is empty")
    with pytest.raises(WashbenchError, match="no such file"):
        load_yaml_model(tmp_path / "nope.yaml", Doc)


def test_top_level_must_be_mapping(tmp_path: Path) -> None:
    assert error(tmp_path, "- 1\n- 2\n") == "m.yaml:1: expected a mapping at the top level, got a list"


def test_misspelt_required_key_is_reported_as_unknown(tmp_path: Path) -> None:
    msg = error(tmp_path, GOOD.replace("phases:", "phasez:"))
    assert msg == "m.yaml:3: phasez: unknown key (did you mean 'phases'?)"
