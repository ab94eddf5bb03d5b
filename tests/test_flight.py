"""Flying manoeuvres with real JSBSim: results files, physics of the recording, monitor, determinism."""

from __future__ import annotations

import json
import math
from pathlib import Path

import inprocess
import numpy as np
import pyarrow.parquet as pq
import pytest
from flight_helpers import BUNDLED, FT, manoeuvre_id, normal_gravity, phase_mask, write

from washbench.flight.columns import COLUMN_NAMES
from washbench.flight.fly import FlightResult, fly, write_flight
from washbench.flight.manoeuvre import load_manoeuvre
from washbench.io.paths import MANOEUVRES_DIR

C172 = MANOEUVRES_DIR / "c172"
CUE_COLUMNS = ("t_s", "f_x_mps2", "f_y_mps2", "f_z_mps2", "omega_x_degps", "omega_y_degps", "omega_z_degps")


@pytest.fixture(scope="module")
def flights() -> dict[str, FlightResult]:
    """Each bundled manoeuvre flown once (about 0.2 s of CPU each)."""
    return {manoeuvre_id(p): fly(load_manoeuvre(p)) for p in BUNDLED}


@pytest.mark.parametrize("path", BUNDLED, ids=manoeuvre_id)
def test_bundled_manoeuvre_flies_with_every_check_passing_and_files_read_back(
    path: Path, flights: dict[str, FlightResult], tmp_path: Path
) -> None:
    result = flights[manoeuvre_id(path)]
    assert result.status == "ok", result.reason
    assert result.checks and all(c[3] for c in result.checks), result.checks
    m = load_manoeuvre(path)
    assert [p[0] for p in result.phases] == [p.name for p in m.phases]
    duration = result.t_s[-1]
    assert 30.0 <= duration <= 120.0  # half a minute (excitations) to two minutes of flying
    write_flight(tmp_path, result, str(path))
    table = pq.read_table(tmp_path / "flight.parquet")
    assert table.column_names == list(COLUMN_NAMES)
    cols = {n: table.column(n).to_numpy() for n in table.column_names}
    n = len(cols["t_s"])
    assert np.array_equal(cols["t_s"], np.arange(n) * m.dt_s)  # t = k * dt exactly
    for name in CUE_COLUMNS:
        assert np.all(np.isfinite(cols[name])), name
        assert np.array_equal(cols[name], result.columns[name])
    assert set(np.unique(cols["wow"])) <= {0, 1}
    summary = json.loads((tmp_path / "flight.json").read_text())
    assert summary["status"] == "ok" and summary["name"] == m.name and summary["aircraft"] == m.aircraft
    assert summary["samples"] == n and summary["dt_s"] == m.dt_s
    assert [c["name"] for c in summary["checks"]] == [c.name for c in m.checks]
    assert all(c["passed"] for c in summary["checks"])
    assert not list(tmp_path.glob(".*tmp"))  # no temporary files left behind


def test_steady_turn_load_factor_and_turn_rate(flights: dict[str, FlightResult]) -> None:
    """Level coordinated turn: n = 1/cos(phi) and psi_dot = g tan(phi) / V (no wind: V = ground speed)."""
    r = flights["c172/coordinated_turn"]
    c = r.columns
    sel = phase_mask(r, "turn", skip_s=10.0)
    phi = np.radians(c["phi_deg"][sel])
    assert np.degrees(np.mean(np.abs(phi))) == pytest.approx(30.0, abs=1.0)
    n_expected = np.mean(1.0 / np.cos(phi))
    assert np.mean(c["nz"][sel]) == pytest.approx(n_expected, rel=0.02)
    g = normal_gravity(45.3, 4000 * FT)
    assert np.mean(-c["f_z_mps2"][sel]) / g == pytest.approx(n_expected, rel=0.02)
    psi = np.unwrap(np.radians(c["psi_deg"][sel]))
    psi_dot = np.gradient(psi, r.dt_s)
    v = c["gs_kts"][sel] * 1852.0 / 3600.0
    expected = -g * np.tan(np.abs(phi)) / v  # left turn: heading decreasing
    assert np.mean(psi_dot) == pytest.approx(np.mean(expected), rel=0.03)
    # the body yaw rate of a level turn is psi_dot cos(phi) cos(theta)
    theta = np.radians(c["theta_deg"][sel])
    r_body = np.radians(c["omega_z_degps"][sel])
    assert np.mean(r_body) == pytest.approx(np.mean(psi_dot * np.cos(phi) * np.cos(theta)), rel=0.02)


def test_trimmed_level_flight_specific_force(flights: dict[str, FlightResult]) -> None:
    """Straight and level, unaccelerated: f = (g sin(theta), 0, -g cos(theta)) in body axes."""
    r = flights["c172/coordinated_turn"]
    c = r.columns
    sel = r.t_s <= 2.0
    theta = np.radians(c["theta_deg"][sel])
    g = normal_gravity(45.3, 4000 * FT)
    # within 0.5 % of g: the trimmed c172p flies with a little sideslip (propeller effects)
    np.testing.assert_allclose(c["f_x_mps2"][sel], g * np.sin(theta), atol=0.05)
    np.testing.assert_allclose(c["f_y_mps2"][sel], 0.0, atol=0.05)
    np.testing.assert_allclose(c["f_z_mps2"][sel], -g * np.cos(theta), atol=0.05)


def test_recorded_specific_force_is_aligned_with_the_motion(flights: dict[str, FlightResult]) -> None:
    """JSBSim's a-pilot lags one frame; the recorder removes the lag.

    Independent check: the vertical component of the recorded specific force, rotated to the
    local level frame with the recorded attitude, must equal the vertical acceleration from a
    central difference of the recorded climb rate, minus gravity. The recorded alignment must
    fit better than the series shifted one frame either way (the raw JSBSim alignment is the
    series delayed by one frame).
    """

    def residual_rms(result: FlightResult, shift: int) -> float:
        c = result.columns
        phi, theta = np.radians(c["phi_deg"]), np.radians(c["theta_deg"])
        f_down = -np.sin(theta) * c["f_x_mps2"] + np.sin(phi) * np.cos(theta) * c["f_y_mps2"]
        f_down += np.cos(phi) * np.cos(theta) * c["f_z_mps2"]
        v_down = -c["climb_fpm"] * FT / 60.0
        a_down = (v_down[2:] - v_down[:-2]) / (2 * result.dt_s)  # at samples 1..N-2
        g = normal_gravity(45.3, c["altitude_ft"][1:-1] * FT)
        f = f_down[1 + shift : len(f_down) - 1 + shift]
        return float(np.sqrt(np.mean((f + g - a_down)[2:-2] ** 2)))

    # smooth flight: the recorded force and the motion agree to a few mm/s^2
    assert residual_rms(flights["c172/stall_recovery"], 0) < 0.01
    # the touchdown (a sharp change of vertical force) tells the alignments apart
    rms = {s: residual_rms(flights["c172/crosswind_landing"], s) for s in (-1, 0, 1)}
    assert rms[0] < 0.7 * min(rms[-1], rms[1]), rms


TURBULENT = """\
name: turbulent_level
aircraft: c172p
start:
  air: {altitude_ft: 3000, airspeed_kts: 90, heading_deg: 45}
environment:
  wind: {from_deg: 300, speed_kts: 15}
  turbulence: {severity: moderate, seed: SEED}
phases:
  - name: level
    hold: {wings_level: true, altitude_ft: 3000, airspeed_kts: 90}
    until: {duration_s: 8}
"""


def test_same_file_flown_twice_is_bit_identical_with_turbulence(tmp_path: Path) -> None:
    path = write(tmp_path, "turb.yaml", TURBULENT.replace("SEED", "7"))
    a = fly(load_manoeuvre(path))
    b = fly(load_manoeuvre(path))
    assert a.status == b.status == "ok"
    for name in COLUMN_NAMES:
        assert a.columns[name].tobytes() == b.columns[name].tobytes(), name
    other = fly(load_manoeuvre(write(tmp_path, "turb2.yaml", TURBULENT.replace("SEED", "8"))))
    assert not np.array_equal(a.columns["f_z_mps2"], other.columns["f_z_mps2"])  # the seed matters
    assert np.std(a.columns["f_z_mps2"]) > 0.1  # and turbulence is really there


def test_wind_start_keeps_airspeed_and_tracks_the_runway(flights: dict[str, FlightResult]) -> None:
    """The landing starts crabbed into a 12 kt crosswind: no sideslip jump, track along the runway."""
    c = flights["c172/crosswind_landing"].columns
    assert abs(c["beta_deg"][0]) < 0.1
    assert c["vc_kts"][0] == pytest.approx(60.0, abs=0.2)
    crab = 70.0 - c["psi_deg"][0]
    tas = 60.0 * 1.01 * 1852 / 3600  # about 1% above calibrated at 740 ft
    assert crab == pytest.approx(math.degrees(math.asin(12 * 1852 / 3600 / tas)), abs=0.5)


def test_step_hook_sees_every_final_sample_in_order(tmp_path: Path) -> None:
    path = write(tmp_path, "turb.yaml", TURBULENT.replace("SEED", "3"))
    seen: list[tuple[int, np.ndarray, np.ndarray]] = []
    blocks: list[tuple[int, np.ndarray, np.ndarray]] = []
    result = fly(
        load_manoeuvre(path),
        step_hook=lambda k, f, w: seen.append((k, f.copy(), w.copy())),
        block_hook=lambda k0, f, w: blocks.append((k0, f, w)),
        block_size=50,
    )
    assert [k for k, _, _ in seen] == list(range(len(result.t_s)))
    # the block hook: the same samples, 50 at a time (the last block shorter), same bits
    assert [k0 for k0, _, _ in blocks] == list(range(0, len(result.t_s), 50))
    np.testing.assert_array_equal(np.concatenate([b[1] for b in blocks]), np.array([s[1] for s in seen]))
    np.testing.assert_array_equal(np.concatenate([b[2] for b in blocks]), np.array([s[2] for s in seen]))
    f = np.array([s[1] for s in seen])
    w = np.array([s[2] for s in seen])
    c = result.columns
    np.testing.assert_array_equal(f, np.column_stack([c["f_x_mps2"], c["f_y_mps2"], c["f_z_mps2"]]))
    np.testing.assert_allclose(
        np.degrees(w), np.column_stack([c["omega_x_degps"], c["omega_y_degps"], c["omega_z_degps"]]), rtol=1e-12
    )


DIVE = """\
name: dive
aircraft: c172p
start:
  air: {altitude_ft: 5000, airspeed_kts: 110, heading_deg: 0}
phases:
  - name: dive
    hold: {wings_level: true, pitch_deg: -35, throttle: 1}
    until: {altitude_below_ft: 0, timeout_s: 100}
"""

INTO_THE_GROUND = """\
name: into_the_ground
aircraft: c172p
start:
  air: {altitude_ft: 300, airspeed_kts: 80, heading_deg: 0}
phases:
  - name: descend
    hold: {wings_level: true, pitch_deg: -12, throttle: 0.5}
    until: {duration_s: 60}
"""

NEVER = """\
name: never
aircraft: c172p
start:
  air: {altitude_ft: 4000, airspeed_kts: 90, heading_deg: 0}
phases:
  - name: slow
    hold: {wings_level: true, altitude_ft: 4000, throttle: 0.2}
    until: {airspeed_above_kts: 150, timeout_s: 5}
"""


@pytest.mark.parametrize(
    ("text", "cause"),
    [
        (DIVE, "beyond VNE 158 kt"),
        (INTO_THE_GROUND, "hard landing: sink rate"),
        (NEVER, "phase 'slow' did not reach its end condition within 5 s"),
    ],
    ids=["vne", "ground", "timeout"],
)
def test_monitor_stops_the_flight_keeps_the_record_and_fails(text: str, cause: str, tmp_path: Path) -> None:
    path = write(tmp_path, "bad_flight.yaml", text)
    out_dir = tmp_path / "out"
    proc = inprocess.washbench("fly", path, "--out", out_dir, timeout=120)
    assert proc.returncode == 1
    assert "Traceback" not in proc.stderr
    summary = json.loads((out_dir / "flight.json").read_text())
    assert summary["status"] == "failed"
    assert summary["reason"].startswith("t=") and cause in summary["reason"], summary["reason"]
    t_fail = float(summary["reason"][2:].split(" s:")[0])
    table = pq.read_table(out_dir / "flight.parquet")
    t = table.column("t_s").to_numpy()
    assert len(t) > 100 and t[-1] <= t_fail
    assert summary["phases"][-1]["t_end_s"] == pytest.approx(t[-1])
    assert cause in proc.stdout and "failed" in proc.stdout


def test_fly_cli_writes_files_and_prints_one_summary_line(tmp_path: Path) -> None:
    out_dir = tmp_path / "turn"
    proc = inprocess.washbench("fly", C172 / "coordinated_turn.yaml", "--out", out_dir, timeout=120)
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.strip().splitlines()
    n_checks = len(load_manoeuvre(C172 / "coordinated_turn.yaml").checks)
    assert len(lines) == 1 and lines[0].startswith(f"coordinated_turn (c172p): ok, {n_checks}/{n_checks} checks passed")
    # not a terminal: progress, if the flight takes more than 5 s of wall time, is plain lines without escapes
    assert "\033" not in proc.stderr and "\r" not in proc.stderr
    assert all(line.startswith("coordinated_turn: phase ") for line in proc.stderr.splitlines())
    assert (out_dir / "flight.parquet").is_file() and (out_dir / "flight.json").is_file()


def test_progress_when_asked(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = write(tmp_path, "turb.yaml", TURBULENT.replace("SEED", "1"))
    fly(load_manoeuvre(path), progress=True)
    err = capsys.readouterr().err
    assert "turbulent_level: phase 1/1 'level'" in err


def test_the_documented_example_flies_with_its_checks_passing(tmp_path: Path) -> None:
    page = (Path(__file__).resolve().parents[1] / "docs" / "how-to" / "own-manoeuvre.md").read_text()
    section = page.split("## A worked example", 1)[1]
    example = section.split("```yaml\n", 1)[1].split("```", 1)[0]
    result = fly(load_manoeuvre(write(tmp_path, "example.yaml", example)))
    assert result.status == "ok", result.reason


def test_pilot_without_load_factor_limits_commands_as_with_limits_that_never_bind(
    flights: dict[str, FlightResult],
) -> None:
    """The pilot skips its load-factor protection when the profile sets no limits: limits of +-1e6 g, which no
    pull reaches, must give the same commands bit for bit, step by step, on a real flight's states (c172p)."""
    from washbench.flight.pilot import Pilot
    from washbench.flight.profile import load_profile

    m = load_manoeuvre(C172 / "steep_turn.yaml")
    profile = load_profile(m.aircraft_files.profile)
    assert profile.gains.pitch.nz_pull_max is None and profile.gains.pitch.nz_push_min is None
    pitch = profile.gains.pitch.model_copy(update={"nz_pull_max": 1e6, "nz_push_min": -1e6})
    far = profile.model_copy(update={"gains": profile.gains.model_copy(update={"pitch": pitch})})
    c = flights[manoeuvre_id(C172 / "steep_turn.yaml")].columns
    pilots = [Pilot(pr, m.runway, m.dt_s) for pr in (profile, far)]
    rad = {k: np.radians(c[k]) for k in ("phi_deg", "theta_deg", "psi_deg", "alpha_deg", "beta_deg")}
    w = {k: np.radians(c[k]) for k in ("omega_x_degps", "omega_y_degps", "omega_z_degps")}
    phase = -1
    for k in range(len(c["t_s"])):
        if c["phase"][k] != phase:
            phase = int(c["phase"][k])
            for pilot in pilots:
                pilot.begin_phase(m.phases[phase].hold, float(rad["theta_deg"][k]), float(c["throttle"][k]), 0.0)
        state = (rad["phi_deg"][k], rad["theta_deg"][k], rad["psi_deg"][k], w["omega_x_degps"][k],
                 w["omega_y_degps"][k], w["omega_z_degps"][k], rad["beta_deg"][k], c["vc_kts"][k],
                 c["gs_kts"][k] * 1.68781, math.radians(90.0), c["climb_fpm"][k] / 60.0, c["altitude_ft"][k],
                 c["h_agl_ft"][k], math.nan, math.nan, bool(c["wow"][k]), c["nz"][k], rad["alpha_deg"][k],
                 c["vc_kts"][k] * 1.06, c["f_y_mps2"][k])  # fmt: skip
        outs = []
        for pilot in pilots:
            pilot.step(*(float(x) for x in state))
            outs.append((pilot.aileron, pilot.elevator, pilot.rudder, pilot.steer, pilot.throttle))
        assert outs[0] == outs[1], f"step {k}"
    assert not c["wow"].any() and c["nz"].max() > 1.3  # in the air throughout (protection on), pulling in the turn


def test_the_compiled_pilot_step_gives_the_bits_of_the_interpreted_one(flights: dict[str, FlightResult]) -> None:
    """numba must not change a command by one bit (no fused multiply-add, libm's pow, sin, tan, asin and Python's
    float modulo): every bundled flight's recorded states, phase by phase, go through the compiled step and through
    the same function interpreted by CPython on a list of Python floats; every slot (commands, integrators,
    filters) must be equal bit for bit after every step."""
    from washbench.flight.pilot import STATE, X_PHI, Pilot, compiled_step
    from washbench.flight.profile import load_profile

    interpreted = compiled_step().py_func
    covered: set[str] = set()
    for path in BUNDLED:
        m = load_manoeuvre(path)
        profile = load_profile(m.aircraft_files.profile)
        c = flights[manoeuvre_id(path)].columns
        compiled, plain = Pilot(profile, m.runway, m.dt_s), Pilot(profile, m.runway, m.dt_s)
        for pilot in (compiled, plain):
            pilot.set_controls(float(c["aileron"][0]), float(c["elevator"][0]), float(c["rudder"][0]))
        rad = {k: np.radians(c[k]) for k in ("phi_deg", "theta_deg", "psi_deg", "alpha_deg", "beta_deg")}
        w = {k: np.radians(c[k]) for k in ("omega_x_degps", "omega_y_degps", "omega_z_degps")}
        phase = -1
        for k in range(len(c["t_s"])):
            if c["phase"][k] != phase:
                phase = int(c["phase"][k])
                for pilot in (compiled, plain):
                    pilot.begin_phase(m.phases[phase].hold, float(rad["theta_deg"][k]), float(c["throttle"][k]),
                                      float(c["flaps_deg"][k]))  # fmt: skip
                covered.add(f"lat{compiled.lat_mode:g} pitch{compiled.pitch_mode:g} wow{c['wow'][k]}")
            state = [float(x) for x in (
                rad["phi_deg"][k], rad["theta_deg"][k], rad["psi_deg"][k], w["omega_x_degps"][k],
                w["omega_y_degps"][k], w["omega_z_degps"][k], rad["beta_deg"][k], c["vc_kts"][k],
                c["gs_kts"][k] * 1.68781, rad["psi_deg"][k], c["climb_fpm"][k] / 60.0, c["altitude_ft"][k],
                c["h_agl_ft"][k], c["runway_x_m"][k] / FT, c["runway_y_m"][k] / FT, c["wow"][k], c["nz"][k],
                rad["alpha_deg"][k], c["vc_kts"][k] * 1.06, c["f_y_mps2"][k])]  # fmt: skip
            compiled.step(*state[:15], bool(state[15]), *state[16:])
            slots = plain.w.tolist()  # Python floats: CPython's arithmetic
            slots[X_PHI:] = state
            interpreted(slots)
            plain.w[:] = slots
            if compiled.w.tobytes() != plain.w.tobytes():
                differ = [n for n in STATE if getattr(compiled, n) != getattr(plain, n)]
                raise AssertionError(f"{manoeuvre_id(path)} step {k}: {', '.join(differ)} differ")
    # the flights exercise every lateral mode and every pitch mode but the pitch-rate one (no bundled manoeuvre
    # holds a pitch rate), in the air and on the ground
    assert {s.split()[0] for s in covered} == {f"lat{i}" for i in range(5)}, covered
    assert {s.split()[1] for s in covered} == {f"pitch{i}" for i in (1, 2, 3, 4, 6, 7, 8)}, covered
    assert {s.split()[2] for s in covered} == {"wow0", "wow1"}, covered


def test_a_flight_longer_than_the_rows_first_allocated_records_the_same_bits(
    flights: dict[str, FlightResult], monkeypatch: pytest.MonkeyPatch
) -> None:
    """The recorded rows grow (doubling) when a flight outlasts the first allocation: flown again with room for 100
    rows at first (six doublings), the same manoeuvre records the same columns and summary, bit for bit."""
    import washbench.flight.fly as fly_module

    path = C172 / "elevator_doublet.yaml"
    monkeypatch.setattr(fly_module, "_ROWS_FIRST", 100)
    again = fly(load_manoeuvre(path))
    before = flights[manoeuvre_id(path)]
    assert len(again.t_s) > 100 * 2**5
    assert list(again.columns) == list(before.columns)
    for name, column in before.columns.items():
        assert again.columns[name].dtype == column.dtype and again.columns[name].tobytes() == column.tobytes(), name
    assert (again.status, again.phases, again.checks, again.events) == (before.status, before.phases, before.checks,
                                                                         before.events)  # fmt: skip


def test_the_compiled_step_uses_the_loops_unit_factors_and_the_monitors_bound() -> None:
    """flight.stepper keeps its own copies of fly's unit factors (fly imports it): they must not drift."""
    import washbench.flight.fly as fly_module
    import washbench.flight.monitor as monitor
    import washbench.flight.stepper as stepper

    assert (stepper.FT_S2_TO_M_S2, stepper.R2D, stepper.FPS_TO_KT) == (
        fly_module.FT_S2_TO_M_S2, fly_module.R2D, fly_module.FPS_TO_KT)  # fmt: skip
    assert stepper.BIG == monitor.BIG
    assert len(stepper.SLOTS) == stepper.NSLOTS and stepper.I_STRUCT3 == stepper.NSLOTS - 1
