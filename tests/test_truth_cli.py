"""Issue 26, the command line: what a user types that was refused or answered wrongly, driven through ``main``."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from washbench.cli import main

G0 = 9.80665


def test_signal_accepts_the_metrics_axis_names(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """``--axis heave`` is f_z (metrics call the body z specific force heave): the same file, bit for bit, and a
    step of +1 m/s^2 on f = [0, 0, -g] from 1 s on."""
    a, b = tmp_path / "heave.csv", tmp_path / "fz.csv"
    assert main(["signal", "step", "--axis", "heave", "--amplitude", "1", "--duration-s", "2", "--out", str(a)]) == 0
    assert "step on heave (f_z)" in capsys.readouterr().out
    assert main(["signal", "step", "--axis", "f_z", "--amplitude", "1", "--duration-s", "2", "--out", str(b)]) == 0
    assert a.read_bytes() == b.read_bytes()
    data = np.genfromtxt(a, delimiter=",", names=True)
    late = data["t_s"] >= 1.0
    np.testing.assert_allclose(data["f_z_mps2"][late], -G0 + 1.0, rtol=0, atol=1e-9)
    np.testing.assert_allclose(data["f_z_mps2"][~late], -G0, rtol=0, atol=1e-9)
    assert main(["signal", "step", "--axis", "Surge", "--amplitude", "1", "--out", str(tmp_path / "s.csv")]) == 0
    assert main(["signal", "step", "--axis", "bob", "--amplitude", "1", "--out", str(tmp_path / "x.csv")]) == 2
    err = capsys.readouterr().err
    assert "unknown axis 'bob' (valid: f_x, f_y, f_z, roll, pitch, yaw, or surge, sway, heave" in err


@pytest.mark.parametrize("command", ["cue", "run", "suite", "fly", "omct", "sweep", "tune"])
def test_every_long_command_takes_quiet(command: str) -> None:
    """The README says run, suite and cue take --quiet; omct, sweep and tune are as long (issue 26 item 7)."""
    from washbench.cli import build_parser

    positional = {"cue": ["in.csv"], "run": ["m.yaml"], "fly": ["m.yaml"], "sweep": ["m.yaml"], "tune": ["m.yaml"]}
    extra = {"tune": ["--washout", "large-angle"]}
    args = build_parser().parse_args([command, *positional.get(command, []), "--out", "o", *extra.get(command, []),
                                      "--quiet"])  # fmt: skip
    assert args.quiet is True


def test_omct_shows_its_progress_unless_quiet(capsys: pytest.CaptureFixture[str], monkeypatch) -> None:
    from washbench.analysis import omct
    from washbench.cueing.variants import select_washouts
    from washbench.platform import load_platform_limits
    from washbench.runs.omct import measure

    monkeypatch.setattr("washbench.io.progress.QUIET_FOR_S", 0.0)
    entries, limits = select_washouts(["large-angle"], (), None), load_platform_limits(None)
    measure(entries, limits, tests=omct.TESTS[:1], frequencies_radps=[1.0, 2.0], progress=True)
    lines = capsys.readouterr().err.splitlines()
    assert lines[0].startswith("omct:  50% (1 of 2 test points), expected end ")
    assert lines[0].endswith(omct.TESTS[0].name)
    assert lines[1].startswith("omct: 100% (2 of 2 test points), done in ")
    measure(entries, limits, tests=omct.TESTS[:1], frequencies_radps=[1.0, 2.0], progress=False)
    assert capsys.readouterr().err == ""


def test_omct_boundary_files_accept_the_metrics_axis_names(tmp_path: Path) -> None:
    from washbench.errors import WashbenchError
    from washbench.runs.omct import load_boundaries

    f = tmp_path / "b.yaml"
    f.write_text("name: mine\nsource: test\ntests:\n  heave_to_heave: {frequency_radps: [1.0], gain_min: [0.5]}\n"
                 "  surge_to_pitch: {frequency_radps: [1.0], gain_max: [2.0]}\n")  # fmt: skip
    assert sorted(load_boundaries(f).tests) == ["f_x_to_pitch", "f_z_to_f_z"]
    f.write_text("name: mine\nsource: test\ntests:\n  heave_to_heave: {frequency_radps: [1.0], gain_min: [0.5]}\n"
                 "  f_z_to_f_z: {frequency_radps: [1.0], gain_max: [2.0]}\n")  # fmt: skip
    with pytest.raises(WashbenchError, match="test 'f_z_to_f_z' is given twice"):
        load_boundaries(f)
