"""Issue 38, item 4: a parameter file with only the sections it changes (a plugin's section, as docs/washouts.md
shows it) runs: the sections left out are the bundled CW1 set's, and the provenance says which and from where;
``washbench examples DIR`` copies a parameter and a platform file to start from."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import inprocess
import pytest

from washbench.analysis.signals import SignalSpec, generate
from washbench.cueing.params import DEFAULT_PARAMS_PATH
from washbench.cueing.variants import load_param_file
from washbench.errors import WashbenchError
from washbench.io.motion_file import write_motion
from washbench.io.yamlio import read_yaml
from washbench.platform.limits import DEFAULT_LIMITS_PATH

ROOT = Path(__file__).resolve().parent.parent
EXAMPLE = ROOT / "docs" / "examples" / "first_order_washout.py"


def _wb(*args: object) -> subprocess.CompletedProcess[str]:
    return inprocess.washbench(*args, timeout=240)


def test_only_a_plugins_section_runs_with_the_bundled_sections(tmp_path: Path) -> None:
    params = tmp_path / "my_cw.yaml"
    params.write_text("first-order:\n  scale: 0.6\n  tilt_rate_limit_degps: 4\n")  # as docs/washouts.md shows it
    motion = tmp_path / "sine.csv"
    sig = generate(SignalSpec("sine", "f_x", 1.0, 0.5, 4.0, 50.0, 0.0))
    write_motion(motion, sig.t_s, sig.f_mps2, sig.omega_radps)
    out = tmp_path / "cue"
    r = _wb("cue", motion, "--washout-plugin", f"{EXAMPLE}:FirstOrder", "--washout", "first-order", "--washout",
            "large-angle", "--params", params, "--out", out, "--no-recording", "--no-figures")  # fmt: skip
    assert r.returncode == 0, r.stderr
    prov = json.loads((out / "run.json").read_text())["provenance"]
    bundled, _ = read_yaml(DEFAULT_PARAMS_PATH)
    values = prov["params"]["values"]
    for key in ("gravity_mps2", "scale", "tilt", "rotational", "translational_highpass_wn_radps"):
        assert json.dumps(values[key], sort_keys=True) == json.dumps(bundled[key], sort_keys=True)  # CW1's, as filed
    assert values["name"] == "my_cw"
    assert "free_fall_threshold_mps2" in prov["params"]["defaults"]["sections"]
    assert "first-order" not in prov["params"]["defaults"]["sections"]
    (fo,) = [w for w in prov["washouts"] if w["name"] == "first-order"]
    assert fo["plugin"]["values"]["scale"] == 0.6 and fo["plugin"]["values"]["tilt_rate_limit_degps"] == 4.0
    assert "parameters not in that file" in (out / "report.md").read_text()


def test_a_section_given_is_taken_whole_and_checked(tmp_path: Path) -> None:
    """A section the file gives is not merged with CW1's: a missing key in it is still named, file and line."""
    params = tmp_path / "p.yaml"
    params.write_text("tilt:\n  gain_per_s: 0.5\n")
    with pytest.raises(WashbenchError) as err:
        load_param_file(params)
    assert str(params) in str(err.value) and "tilt.lowpass_wn_radps" in str(err.value)
    base, _ = load_param_file(DEFAULT_PARAMS_PATH)
    assert base.name == "CW1"  # the bundled file itself: nothing filled


def test_examples_copies_a_parameter_and_a_platform_file(tmp_path: Path) -> None:
    r = _wb("examples", tmp_path / "ex")
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "ex" / "params" / "cw1.yaml").read_bytes() == DEFAULT_PARAMS_PATH.read_bytes()
    assert (tmp_path / "ex" / "params" / "atlas.yaml").read_bytes() == DEFAULT_LIMITS_PATH.read_bytes()
    assert "--params" in r.stdout
