"""Issue 38, item 3: a plugin washout's identity and parameter values are in the provenance (``run.json``, the
Parquet metadata, ``report.md``): its file or module, class, SHA-256 of the code, the values it ran with, and an
installed entry point of the same name that a file plugin replaced."""

from __future__ import annotations

import hashlib
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from washbench.analysis.signals import SignalSpec, generate
from washbench.io.motion_file import write_motion
from washbench.io.provenance import read_parquet_provenance

ROOT = Path(__file__).resolve().parent.parent
EXAMPLE = ROOT / "docs" / "examples" / "first_order_washout.py"


def _wb(*args: object, env: dict[str, str] | None = None) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "washbench", *map(str, args)], capture_output=True, text=True,
                          timeout=240, env=env)  # fmt: skip


@pytest.fixture(scope="module")
def motion(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("plugin_prov") / "sine.csv"
    sig = generate(SignalSpec("sine", "f_x", 1.0, 0.5, 4.0, 50.0, 0.0))
    write_motion(path, sig.t_s, sig.f_mps2, sig.omega_radps)
    return path


@pytest.fixture(scope="module")
def entry_point_site(tmp_path_factory: pytest.TempPathFactory) -> tuple[dict[str, str], Path]:
    """An installed package ``myplugin 0.1`` whose entry point ``first-order`` is a copy of the example with a
    different default scale (so it is other code, with another hash)."""
    site = tmp_path_factory.mktemp("site")
    dist = site / "myplugin-0.1.dist-info"
    dist.mkdir()
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: myplugin\nVersion: 0.1\n")
    (dist / "entry_points.txt").write_text("[washbench.washouts]\nfirst-order = my_first_order:FirstOrder\n")
    module = site / "my_first_order.py"
    module.write_text(EXAMPLE.read_text().replace("scale: float = Field(0.5,", "scale: float = Field(0.25,"))
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(site), *filter(None, [os.environ.get("PYTHONPATH")])])}
    return env, module


def _plugin_record(out: Path, name: str) -> dict:
    prov = json.loads((out / "run.json").read_text())["provenance"]
    (rec,) = [w for w in prov["washouts"] if w["name"] == name]
    parquet = read_parquet_provenance(out / "traces.parquet")
    assert parquet is not None
    assert [w for w in parquet["washouts"] if w["name"] == name] == [rec]  # the same record in the Parquet file
    return rec["plugin"]


def test_a_file_plugin_is_recorded_with_its_file_hash_class_and_values(motion: Path, tmp_path: Path) -> None:
    out = tmp_path / "cue"
    r = _wb("cue", motion, "--washout-plugin", f"{EXAMPLE}:FirstOrder", "--washout", "first-order",
            "--variant", "fo_hi=first-order,first-order.scale=0.8", "--out", out, "--no-recording")  # fmt: skip
    assert r.returncode == 0, r.stderr
    rec = _plugin_record(out, "first-order")
    assert rec["from"] == "file" and rec["object"] == "FirstOrder"
    assert Path(rec["path"]) == EXAMPLE.resolve()
    assert rec["sha256"] == hashlib.sha256(EXAMPLE.read_bytes()).hexdigest()
    # the example's defaults, as the docs list them (docs/examples/first_order_washout.py)
    assert rec["values"] == {"scale": 0.5, "highpass_wn_radps": 1.0, "tilt_wn_radps": 0.5, "tilt_rate_limit_degps": 3.0}
    assert "shadows" not in rec
    assert _plugin_record(out, "fo_hi")["values"]["scale"] == 0.8  # a variant: its own values
    report = (out / "report.md").read_text()
    assert str(EXAMPLE.resolve()) in report and rec["sha256"] in report and "`scale=0.8`" in report


def test_an_entry_point_plugin_and_a_file_that_replaces_it(
    motion: Path, entry_point_site: tuple[dict[str, str], Path], tmp_path: Path
) -> None:
    env, module = entry_point_site
    out = tmp_path / "ep"
    r = _wb("cue", motion, "--washout", "first-order", "--out", out, "--no-recording", "--no-figures", env=env)
    assert r.returncode == 0, r.stderr
    rec = _plugin_record(out, "first-order")
    assert (rec["from"], rec["module"], rec["object"]) == ("entry point", "my_first_order", "FirstOrder")
    assert (rec["distribution"], rec["version"]) == ("myplugin", "0.1")
    assert rec["sha256"] == hashlib.sha256(module.read_bytes()).hexdigest() and rec["values"]["scale"] == 0.25

    out = tmp_path / "file"
    r = _wb("cue", motion, "--washout-plugin", f"{EXAMPLE}:FirstOrder", "--washout", "first-order", "--out", out,
            "--no-recording", "--no-figures", env=env)  # fmt: skip
    assert r.returncode == 0, r.stderr
    rec = _plugin_record(out, "first-order")
    assert rec["from"] == "file" and rec["sha256"] == hashlib.sha256(EXAMPLE.read_bytes()).hexdigest()
    assert rec["values"]["scale"] == 0.5  # the file's code and defaults ran, not the entry point's
    assert rec["shadows"] == "entry point my_first_order:FirstOrder (myplugin 0.1)"
    assert "replaces the installed entry point my_first_order:FirstOrder" in (out / "report.md").read_text()
