"""Hostile input files: one clean line (file, line, field), exit 2, no traceback, no hang, nothing written.

Each family drives the real command in a subprocess under a time limit; the members of a family that need no
process of their own are checked in-process through the same loaders.
"""

from __future__ import annotations

import errno
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from hostile import SHORT, assert_clean_error, short, tree, washbench

from washbench.cueing import WASHOUT_NAMES, CueingBank, load_washout_params
from washbench.cueing.kernel import O_ACC, O_POS
from washbench.cueing.params import DEFAULT_PARAMS_PATH
from washbench.errors import WashbenchError
from washbench.flight.manoeuvre import Manoeuvre, load_manoeuvre
from washbench.io.atomic import atomic_path
from washbench.io.motion_file import read_motion
from washbench.io.names import IDENTIFIER_MAX_LENGTH
from washbench.io.paths import MANOEUVRES_DIR
from washbench.io.yamlio import MAX_DEPTH, MAX_NODES
from washbench.platform import load_platform_limits
from washbench.platform.limits import DEFAULT_LIMITS_PATH

BUNDLED = sorted(MANOEUVRES_DIR.glob("*/*.yaml"))


def motion_csv(path: Path, dt: float = 1 / 120, n: int = 50, fz: dict[int, float] | None = None) -> Path:
    """A level-flight input for ``washbench cue`` with optional odd f_z samples {row: value}."""
    rows = ["t_s,f_x_mps2,f_y_mps2,f_z_mps2,omega_x_degps,omega_y_degps,omega_z_degps"]
    for k in range(n):
        z = (fz or {}).get(k, -9.81)
        rows.append(f"{float(k * dt)!r},0.0,0.0,{float(z)!r},0.0,0.0,0.0")
    path.write_text("\n".join(rows) + "\n")
    return path


# --- names that would become paths ------------------------------------------------------------------------------


BAD_NAMES = {
    "absolute": "/tmp/washbench-victim",
    "parent": "../..",
    "dot": ".",
    "nul": '"a\\0b"',
    "long": "x" * 300,
    "space": '"my turn"',
}


def test_names_that_are_not_identifiers_are_refused_when_loaded(tmp_path: Path) -> None:
    files = [short(tmp_path, name=value, file=f"{key}.yaml") for key, value in BAD_NAMES.items()]
    files.append(tmp_path / "aircraft.yaml")
    files[-1].write_text(SHORT.format(name="ok", seconds=1, extra="").replace("aircraft: c172p", "aircraft: ../c172p"))
    proc = washbench("validate", *files, timeout=30)
    lines = assert_clean_error(proc, lines=len(files))
    for path, line in zip(files, lines, strict=True):
        field = "aircraft" if path.name == "aircraft.yaml" else "name"
        where = 2 if field == "aircraft" else 1
        assert line.startswith(f"washbench: error: {path}:{where}: {field}: expected a plain name"), line
    assert str(IDENTIFIER_MAX_LENGTH) in lines[0]


def test_run_with_a_path_as_name_touches_nothing_outside_out(tmp_path: Path) -> None:
    victim = tmp_path / "victim"
    victim.mkdir()
    (victim / "precious.txt").write_text("keep")
    out = tmp_path / "out"
    bad = short(tmp_path, name=str(victim), file="bad.yaml")
    proc = washbench("run", bad, "--out", out, timeout=60)
    assert_clean_error(proc, f"{bad}:1: name:")
    assert tree(victim) == ["precious.txt"] and (victim / "precious.txt").read_text() == "keep"
    assert not out.exists()  # created only for the run, removed again: nothing half-written


# --- numbers: NaN, infinity, absurd magnitudes, ranges ---------------------------------------------------------


def test_nan_and_infinity_are_refused_in_every_yaml_file(tmp_path: Path) -> None:
    cases = {
        "duration.yaml": ("duration_s: 1", "duration_s: .inf", "8: phases[0].until.duration_s"),
        "timeout.yaml": ("duration_s: 1", "altitude_below_ft: 100, timeout_s: .inf", "8: phases[0].until.timeout_s"),
        "check.yaml": ("max: 50", "min: .nan", "10: checks[0].min"),
        "hold.yaml": ("{wings_level: true, altitude_ft: 3000", "{wings_level: true, altitude_ft: .NaN", "7: phases[0]"),
        "start.yaml": ("altitude_ft: 3000, airspeed_kts: 90, heading", "altitude_ft: -.inf, airspeed_kts: 90, heading",
                       "4: start.air.altitude_ft"),
    }  # fmt: skip
    files = []
    for file, (old, new, _) in cases.items():
        path = tmp_path / file
        text = SHORT.format(name="n", seconds=1, extra="")
        assert old in text
        path.write_text(text.replace(old, new, 1))
        files.append(path)
    lines = assert_clean_error(washbench("validate", *files, timeout=30), lines=len(files))
    for path, line, (_, _, where) in zip(files, lines, cases.values(), strict=True):
        assert line.startswith(f"washbench: error: {path}:{where}") and "expected a finite number" in line, line
    # the parameter and platform files, through the same loader
    params = tmp_path / "params.yaml"
    params.write_text(DEFAULT_PARAMS_PATH.read_text().replace("gain_per_s: 0.4", "gain_per_s: .nan"))
    with pytest.raises(WashbenchError, match=r"params.yaml:\d+: tilt.gain_per_s: expected a finite number"):
        load_washout_params(params)


@pytest.mark.parametrize(
    ("file", "old", "new", "field"),
    [
        ("params", "gravity_mps2: 9.80665", "gravity_mps2: 1e300", "gravity_mps2"),
        ("params", "specific_force: 1.0", "specific_force: 1.0e300", "scale.specific_force"),
        ("platform", "    x: 1.5\n    y: 1.5\n    z: 1.0", "    x: 1.0e300\n    y: 1.5\n    z: 1.0",
         "translation.position_limit_m.x"),
        ("platform", "    x: 9.81", "    x: 1e-300", "translation.acceleration_limit_mps2.x"),
    ],
)  # fmt: skip
def test_absurd_parameters_are_refused_with_the_accepted_range(
    tmp_path: Path, file: str, old: str, new: str, field: str
) -> None:
    source = DEFAULT_PARAMS_PATH if file == "params" else DEFAULT_LIMITS_PATH
    text = source.read_text()
    assert old in text
    path = tmp_path / f"{file}.yaml"
    path.write_text(text.replace(old, new, 1))
    load = load_washout_params if file == "params" else load_platform_limits
    with pytest.raises(WashbenchError, match=rf"{file}.yaml:\d+: {field}: expected (less|greater) than or equal to"):
        load(path)


def test_cue_refuses_absurd_inputs_without_hanging(tmp_path: Path) -> None:
    bad_inputs = {
        "fz35.csv": ({"fz": {10: 1e35}}, "fz35.csv:12: f_z_mps2: 1e+35 is beyond the accepted range"),
        "fz38.csv": ({"fz": {3: 3.4e38}}, "fz38.csv:5: f_z_mps2: 3.4e+38 is beyond"),
        "tiny_step.csv": ({"dt": 1e-21}, "tiny_step.csv: t_s: time step 1e-21 s is outside the accepted"),
        "huge_step.csv": ({"dt": 8e307, "n": 2}, "huge_step.csv: t_s: time step 8e+307 s is outside"),
        "subnormal.csv": ({"dt": 5e-324, "n": 3}, "subnormal.csv: t_s: time step 4.94066e-324 s is outside"),
    }
    for name, (kwargs, message) in bad_inputs.items():
        path = motion_csv(tmp_path / name, **kwargs)
        with pytest.raises(WashbenchError) as info:
            read_motion(path)
        assert str(info.value) == f"{tmp_path}/{message}" or str(info.value).startswith(f"{tmp_path}/{message}")
    out = tmp_path / "out"
    proc = washbench("cue", tmp_path / "fz35.csv", "--out", out, timeout=60)
    assert_clean_error(proc, "fz35.csv:12: f_z_mps2:")
    assert not out.exists()


def test_extreme_samples_reaching_the_kernel_from_python_end_within_the_limits() -> None:
    """The streaming step checks nothing (it is the hot path); fed absurd samples it still returns at once and the
    platform stays within its limits (the range check is at the file edge, ``read_motion``)."""
    params, limits = load_washout_params(), load_platform_limits()
    p_max = np.array(limits.translation.position_limit_m.xyz)
    a_max = np.array(limits.translation.acceleration_limit_mps2.xyz)
    n = 120
    for value in (1e35, 3.4e38, 1e300, -1e300, 5e-324):
        bank = CueingBank(WASHOUT_NAMES, params, limits, 1 / 120)
        for k in range(n):
            f = np.array([0.0, 0.0, value if k == 40 else -9.81])
            w = np.array([0.0, value if k == 20 else 0.0, 0.0])
            rows = bank.step(f, w)
            pos = rows[:, O_POS : O_POS + 3]
            acc = rows[:, O_ACC : O_ACC + 3]
            assert np.all(np.abs(pos) <= p_max) and np.all(np.abs(acc) <= a_max), (value, k)



def test_a_manoeuvre_has_a_documented_ceiling_on_its_length(tmp_path: Path) -> None:
    long_phase = short(tmp_path, name="long", seconds=4000)
    many_steps = short(tmp_path, name="steps", seconds=600, extra="rate_hz: 1000\n")
    timeouts = tmp_path / "timeouts.yaml"
    phases = "".join(
        f"  - name: p{i}\n    hold: {{wings_level: true, altitude_ft: 3000, airspeed_kts: 90}}\n"
        f"    until: {{airspeed_below_kts: 50, timeout_s: 3000}}\n"
        for i in range(2)
    )
    text = SHORT.format(name="t", seconds=1, extra="")
    timeouts.write_text(text[: text.index("phases:\n") + len("phases:\n")] + phases)
    lines = assert_clean_error(washbench("validate", long_phase, many_steps, timeouts, timeout=30), lines=3)
    assert lines[0].endswith("phases[0].until.duration_s: expected less than or equal to 3600, got 4000")
    assert f"{many_steps}:6: phases: the manoeuvre may last 600 s" in lines[1] and "432000 steps" in lines[1]
    assert f"{timeouts}:5: phases: the manoeuvre may last 6000 s" in lines[2] and "3600 s" in lines[2]


# --- YAML structure -------------------------------------------------------------------------------------------


def test_yaml_bombs_and_odd_structures_are_one_line_each(tmp_path: Path) -> None:
    levels = "".join(f"l{i}: &l{i} [{', '.join([f'*l{i - 1}'] * 9)}]\n" for i in range(1, 10))
    cases = {
        "bomb.yaml": ("l0: &l0 [lol, lol, lol, lol, lol, lol, lol, lol, lol]\n" + levels,
                      f"aliases expand to more than {MAX_NODES} values"),
        "deep.yaml": ("name: " + "[" * 5000 + "]" * 5000 + "\n", f"nested deeper than {MAX_DEPTH} levels"),
        "chain.yaml": ("a0: &a0 [1]\n" + "".join(f"a{i}: &a{i} [*a{i - 1}]\n" for i in range(1, 100)),
                       f"aliases nest deeper than {MAX_DEPTH} levels"),
        "recursive.yaml": ("name: &a [*a]\n", "an alias refers to a value that contains it"),
        "complex_key.yaml": ("? [a, b]\n: 1\n", "a mapping key must be plain text"),
        "dict_key.yaml": ("{a: 1}: 2\n", "a mapping key must be plain text"),
        "big_int.yaml": ("name: x\nrate_hz: " + "9" * 5000 + "\n", "is too large"),
    }  # fmt: skip
    files = []
    for name, (text, _) in cases.items():
        (tmp_path / name).write_text(text)
        files.append(tmp_path / name)
    lines = assert_clean_error(washbench("validate", *files, timeout=30), lines=len(files))
    for path, line, (_, problem) in zip(files, lines, cases.values(), strict=True):
        assert line.startswith(f"washbench: error: {path}:") and problem in line, line


def test_merge_keys_and_scientific_notation_are_accepted(tmp_path: Path) -> None:
    path = tmp_path / "merged.yaml"
    path.write_text(
        "name: merged\naircraft: c172p\n"
        "start:\n  air: {altitude_ft: 3.0e3, airspeed_kts: 9E1, heading_deg: 360}\n"
        "phases:\n"
        "  - name: level\n    hold: &cruise {wings_level: true, altitude_ft: 3000, airspeed_kts: 90}\n"
        "    until: {duration_s: 1e1}\n"
        "  - name: bank\n    hold: {<<: *cruise, wings_level: null, bank_deg: 1e1}\n    until: {duration_s: 5}\n"
    )
    proc = washbench("validate", path, timeout=30)
    assert proc.returncode == 0 and proc.stdout.strip() == f"{path}: OK", proc.stderr
    m = load_manoeuvre(path)
    assert m.start.air is not None and m.start.air.altitude_ft == 3000.0 and m.start.air.heading_deg == 360.0
    assert m.phases[0].until.duration_s == 10.0
    bank = m.phases[1].hold
    assert (bank.bank_deg, bank.altitude_ft, bank.airspeed_kts, bank.wings_level) == (10.0, 3000.0, 90.0, None)
    params = tmp_path / "params.yaml"
    text = DEFAULT_PARAMS_PATH.read_text()
    params.write_text(text.replace("free_fall_threshold_mps2: 1.0e-6", "free_fall_threshold_mps2: 1e-6"))
    assert load_washout_params(params).free_fall_threshold_mps2 == 1e-6


def test_every_problem_of_a_file_is_reported_on_its_own_line(tmp_path: Path) -> None:
    text = SHORT.format(name="many", seconds=1, extra="")
    text = text.replace("airspeed_kts: 90, heading_deg: 360", "airspeed_kts: fast, heading_deg: 361")
    text = text.replace("max_deviation, max: 50", "max_deviation, maxx: 50")
    path = tmp_path / "many.yaml"
    path.write_text(text)
    lines = assert_clean_error(washbench("validate", path, timeout=30), lines=3)
    assert lines == [
        f"washbench: error: {path}:4: start.air.airspeed_kts: expected a number, got 'fast'",
        f"washbench: error: {path}:4: start.air.heading_deg: expected less than or equal to 360, got 361",
        f"washbench: error: {path}:10: checks[0].maxx: unknown key (did you mean 'max'?)",
    ]
    # any other command reports the first problem on one line and says how many more there are
    proc = washbench("run", path, "--out", tmp_path / "out", timeout=60)
    (line,) = assert_clean_error(proc, "(and 2 more problems)")
    assert line.startswith(lines[0])


def test_air_start_altitudes_are_checked_when_loaded(tmp_path: Path) -> None:
    files = []
    for alt in ("0", "-100", "80000", "20000"):
        path = tmp_path / f"alt{alt}.yaml"
        text = SHORT.format(name="a", seconds=1, extra="")
        path.write_text(text.replace("altitude_ft: 3000, airspeed", f"altitude_ft: {alt}, airspeed", 1))
        files.append(path)
    lines = assert_clean_error(washbench("validate", *files, timeout=30), lines=4)
    for path, line in zip(files, lines, strict=True):
        assert line.startswith(f"washbench: error: {path}:4: start.air.altitude_ft: "), line
    assert "outside c172p's air-start range (100..13000 ft" in lines[0]
    assert "expected less than or equal to 60000" in lines[2]


def test_a_flight_time_error_names_the_file_and_field(tmp_path: Path) -> None:
    path = tmp_path / "slow.yaml"
    path.write_text(SHORT.format(name="slow", seconds=1, extra="").replace(
        "altitude_ft: 3000, airspeed_kts: 90, heading", "altitude_ft: 13000, airspeed_kts: 49, heading"))  # fmt: skip
    out = tmp_path / "out"
    proc = washbench("fly", path, "--out", out, timeout=60)
    assert_clean_error(proc, f"{path}:4: start.air: c172p: JSBSim could not trim")
    assert not out.exists()


# --- output places, pipes, arguments ----------------------------------------------------------------------------


def test_a_bad_output_place_is_one_line_before_any_work(tmp_path: Path) -> None:
    good = short(tmp_path)
    a_file = tmp_path / "a_file"
    a_file.write_text("not a folder")
    motion = motion_csv(tmp_path / "motion.csv")
    commands = [
        ("run", good, "--out", a_file),
        ("suite", good, "--out", a_file / "under"),
        ("cue", motion, "--out", a_file / "under"),
        ("schema", "--out", tmp_path),
    ]
    for args in commands:
        proc = washbench(*args, timeout=60)
        assert_clean_error(proc, str(a_file) if args[-1] != tmp_path else "is a folder")
        assert proc.stdout == ""
    assert a_file.read_text() == "not a folder"
    assert tree(tmp_path) == ["a_file", "motion.csv", "short.yaml"]


def test_a_closed_pipe_ends_the_command_quietly() -> None:
    proc = subprocess.Popen(
        [sys.executable, "-m", "washbench", "validate", *([str(p) for p in BUNDLED] * 20)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    assert proc.stdout is not None and proc.stderr is not None
    first = proc.stdout.readline()
    proc.stdout.close()  # like `| head -1`
    err = proc.stderr.read()
    assert proc.wait(timeout=60) == 141
    assert first.endswith(": OK\n") and err == ""


def test_jobs_must_be_a_positive_whole_number(tmp_path: Path) -> None:
    for jobs in ("0", "-3"):
        proc = washbench("suite", "--out", tmp_path / "o", "--jobs", jobs, timeout=30)
        assert_clean_error(proc, f"--jobs: expected at least 1 process, got {int(jobs)}")
    assert not (tmp_path / "o").exists()


# --- the Python API builds no invalid object ----------------------------------------------------------------------


def test_python_api_cannot_build_an_invalid_object() -> None:
    m = load_manoeuvre(MANOEUVRES_DIR / "c172" / "coordinated_turn.yaml")
    data = m.model_dump(exclude_unset=True)
    with pytest.raises(ValueError, match="unknown aircraft 'c999x'"):
        Manoeuvre.model_validate({**data, "aircraft": "c999x"})
    with pytest.raises(ValueError, match="expected a plain name"):
        m.model_copy(update={"name": "../elsewhere"})
    with pytest.raises(ValueError, match="finite number"):
        Manoeuvre.model_validate({**data, "rate_hz": 120, "checks": [{**data["checks"][0], "min": math.nan}]})
    params = load_washout_params()
    with pytest.raises(ValueError, match="greater than or equal to 1"):
        params.model_copy(update={"gravity_mps2": -9.81})
    with pytest.raises(ValueError, match="greater than 0"):
        params.tilt.model_copy(update={"gain_per_s": -1.0})
    assert params.model_copy(update={"name": "copy"}).name == "copy"
    # heading 360 is north, as a pilot says it
    assert Manoeuvre.model_validate(
        {**data, "start": {"air": {**data["start"]["air"], "heading_deg": 360.0}}}
    ).start.air.heading_deg == 360.0  # fmt: skip


def test_a_file_system_failure_while_writing_is_one_line_and_leaves_nothing(tmp_path: Path) -> None:
    """What a full disk does to any writer (os.write raising ENOSPC): one line naming the file, no temporary left."""
    dest = tmp_path / "flight.parquet"
    dest.write_bytes(b"the previous result")
    with pytest.raises(WashbenchError) as info, atomic_path(dest) as tmp:
        with tmp.open("wb") as fh:
            fh.write(b"half")
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
    assert str(info.value) == f"{dest}: cannot write: No space left on device"
    assert tree(tmp_path) == ["flight.parquet"] and dest.read_bytes() == b"the previous result"


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into read-only folders")
def test_a_read_only_output_folder_is_one_line_before_flying(tmp_path: Path) -> None:
    out = tmp_path / "ro"
    out.mkdir()
    out.chmod(0o555)
    try:
        proc = washbench("run", short(tmp_path), "--out", out, timeout=60)
        assert_clean_error(proc, f"{out}: cannot write into the output folder")
    finally:
        out.chmod(0o755)
